/* generators.h: internal mesh building for procedural meshes and the
 * built-in scenes (generators.c, teapot.c, builtin_*.c).
 *
 * An rl_meshbuf is a growable triangle mesh with a sticky status: appends
 * after a failed allocation do nothing, and the first failure comes back from
 * rl_meshbuf_add_to_scene(). Builders therefore append freely and check once,
 * which keeps geometry code readable. */
#ifndef RL_SCENE_GENERATORS_H
#define RL_SCENE_GENERATORS_H

#include "rl/rl_scene.h"

typedef struct rl_meshbuf {
    rl_vec3 *positions, *normals;
    rl_vec2 *uvs;
    uint32_t *indices;          /* 3 per triangle */
    uint32_t *materials;        /* per triangle */
    uint32_t num_vertices, num_triangles;
    uint32_t cap_vertices, cap_triangles;
    uint32_t material;          /* given to triangles appended from now on */
    rl_status status;           /* first failure, sticky */
} rl_meshbuf;

/* Zeroed buffer; material starts as RL_NONE (the caller sets it). */
void rl_meshbuf_init(rl_meshbuf *b);
void rl_meshbuf_free(rl_meshbuf *b);
/* Makes room for this many more vertices and triangles; false on failure
 * (RL_ERR_LIMIT beyond RL_SCENE_MAX_TRIANGLES, RL_ERR_OUT_OF_MEMORY). */
bool rl_meshbuf_reserve(rl_meshbuf *b, uint64_t more_vertices, uint64_t more_triangles);
/* Appends a vertex and returns its index (0 after a failure). */
uint32_t rl_meshbuf_vertex(rl_meshbuf *b, rl_vec3 p, rl_vec3 n, rl_vec2 uv);
void rl_meshbuf_triangle(rl_meshbuf *b, uint32_t a, uint32_t c, uint32_t d);
/* Flat quad p0 p1 p2 p3 (counter-clockwise seen from the front, normal
 * cross(p1-p0, p3-p0)); uv (0,0) (u,0) (u,v) (0,v) scaled by uv_scale. */
void rl_meshbuf_quad(rl_meshbuf *b, rl_vec3 p0, rl_vec3 p1, rl_vec3 p2, rl_vec3 p3,
                     rl_vec2 uv_scale);
/* Axis-aligned box lo..hi with outward flat faces (12 triangles). */
void rl_meshbuf_box(rl_meshbuf *b, rl_vec3 lo, rl_vec3 hi);
/* Adds the buffer as a scene mesh (per-triangle materials only when they
 * differ). Returns the buffer's sticky failure first. */
rl_status rl_meshbuf_add_to_scene(rl_scene *scene, const rl_meshbuf *b, const char *name,
                                  uint32_t *mesh_id);

/* Generators (see the table at the top of generators.c). All centred on the
 * origin except the teapot, which stands on y = 0 around the y axis. */
void rl_gen_box(rl_meshbuf *b, rl_vec3 size);
void rl_gen_quad(rl_meshbuf *b, float sx, float sz, float repeat);
void rl_gen_sphere(rl_meshbuf *b, float radius, uint32_t segments, uint32_t rings);
void rl_gen_cylinder(rl_meshbuf *b, float radius, float height, uint32_t segments, bool caps);

/* Utah teapot (teapot.c, data in teapot_data.c). */
#define RL_TEAPOT_PATCHES 32
#define RL_TEAPOT_POINTS 306
#define RL_TEAPOT_DEFAULT_TRIANGLES 15704  /* Schröder 2017's teapot (13 x 19 grid) */
#define RL_TEAPOT_MAX_TRIANGLES 4000000
extern const uint16_t rl_teapot_patches[RL_TEAPOT_PATCHES][16];
extern const float rl_teapot_points[RL_TEAPOT_POINTS][3];   /* z-up, height 3.15 */
/* Per-patch grid (nu x nv quads) whose triangle count without the
 * degenerate ones is closest to `triangles`; returns that count. */
uint32_t rl_teapot_grid(uint32_t triangles, uint32_t *nu, uint32_t *nv);
/* Tessellates with rl_teapot_grid(triangles); y-up, height `size`. */
void rl_gen_teapot(rl_meshbuf *b, uint32_t triangles, float size);

#endif
