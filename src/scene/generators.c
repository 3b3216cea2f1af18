/* generators.c: procedural meshes for JSON and built-in scenes
 * (rl_scene_add_generated). Each generator adds one mesh named after it.
 *
 * Parameters ("key=value", separated by commas or spaces; unknown keys are
 * RL_ERR_INVALID_ARG, values outside the range likewise):
 *
 * | generator | key      | default | range         | meaning                                   |
 * |-----------|----------|---------|---------------|-------------------------------------------|
 * | box       | size     | 1       | (0, 1e6]      | edge lengths: one number (cube) or three   |
 * |           |          |         |               | joined by 'x' or ':' ("2x1x0.5")           |
 * |           | sx,sy,sz | size    | (0, 1e6]      | edge length along one axis (overrides size)|
 * |           |          |         |               | 12 triangles, centred on the origin, flat  |
 * |           |          |         |               | normals, uv 0..1 per face                  |
 * | quad      | sx, sz   | 1       | (0, 1e6]      | extent along x and z; the plane y = 0,     |
 * |           |          |         |               | centred, facing +y, 2 triangles            |
 * |           | repeat   | 1       | [1e-3, 1e4]   | uv runs 0..repeat (texture tiling)         |
 * | sphere    | radius   | 1       | (0, 1e6]      | UV sphere centred on the origin            |
 * |           | segments | 32      | [3, 4096]     | divisions around y (longitude)             |
 * |           | rings    | 16      | [2, 4096]     | divisions pole to pole (latitude);         |
 * |           |          |         |               | 2*segments*(rings-1) triangles, smooth     |
 * |           |          |         |               | normals, u = longitude, v = latitude       |
 * | cylinder  | radius   | 1       | (0, 1e6]      | circular cylinder around y, centred        |
 * |           | height   | 2       | (0, 1e6]      | y from -height/2 to +height/2              |
 * |           | segments | 32      | [3, 65536]    | divisions around y; smooth side normals    |
 * |           | caps     | true    | bool          | close top and bottom with flat discs       |
 * | teapot    | triangles| 15704   | [1, 4000000]  | target count; the per-patch grid closest   |
 * |           |          |         |               | to it is used (minimum 56). 15704 is       |
 * |           |          |         |               | Schröder 2017's teapot (13 x 19 per patch) |
 * |           | size     | 1       | (0, 1e6]      | height; stands on y = 0 around the y axis, |
 * |           |          |         |               | spout towards +x, width about 2.04 * size  |
 * | blob      | triangles| 20000   | even, [4, 16e6]| exactly this many triangles; closed,      |
 * |           |          |         |               | genus 0, outward (blob.c); odd is an error |
 * |           | seed     | 1       | [0, 2^53]     | lump placement                             |
 * |           | scale    | 1       | (0, 1e6]      | radius of the sphere before the lumps      |
 * |           | lumps    | 6       | [0, 64]       | smooth bumps and dents                     |
 *
 * The teapot is Newell's 32-patch Utah teapot (teapot.c). The blob
 * (blob.c) stands in for the bunny and dragon of Schröder 2017, Sec. 9.3. */
#include "scene/generators.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/params.h"
#include "scene/blob.h"

#define GEN_MAX_SIZE 1e6

void rl_gen_box(rl_meshbuf *b, rl_vec3 size)
{
    rl_vec3 h = rl_scale(size, 0.5f);
    rl_meshbuf_box(b, rl_neg(h), h);
}

void rl_gen_quad(rl_meshbuf *b, float sx, float sz, float repeat)
{
    float x = 0.5f * sx, z = 0.5f * sz;
    /* Counter-clockwise seen from +y so the normal is +y; uv u along +x,
     * v along -z (towards the back, as a texture lies on the floor). */
    rl_meshbuf_quad(b, rl_v3(-x, 0.0f, z), rl_v3(x, 0.0f, z), rl_v3(x, 0.0f, -z),
                    rl_v3(-x, 0.0f, -z), rl_v2(repeat, repeat));
}

void rl_gen_sphere(rl_meshbuf *b, float radius, uint32_t segments, uint32_t rings)
{
    /* (segments+1) x (rings+1) vertices: the seam column is duplicated for
     * continuous u, and each pole gets one vertex per segment so that the
     * pole triangles have their own u; those rings emit one triangle per
     * segment instead of a degenerate quad. */
    if (!rl_meshbuf_reserve(b, (uint64_t)(segments + 1) * (rings + 1),
                            2ull * segments * (rings - 1)))
        return;
    uint32_t base = b->num_vertices;
    for (uint32_t r = 0; r <= rings; ++r) {
        float v = (float)r / (float)rings;
        float theta = v * RL_PI;                   /* from +y down */
        float st = sinf(theta), ct = cosf(theta);
        if (r == 0 || r == rings)
            st = 0.0f;                             /* exact poles */
        for (uint32_t s = 0; s <= segments; ++s) {
            float u = (float)s / (float)segments;
            float phi = u * 2.0f * RL_PI;
            rl_vec3 n = rl_v3(st * cosf(phi), ct, -st * sinf(phi));
            rl_meshbuf_vertex(b, rl_scale(n, radius), n, rl_v2(u, 1.0f - v));
        }
    }
    uint32_t row = segments + 1;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t a = base + r * row + s, c = a + 1;      /* upper ring */
            uint32_t d = a + row, e = d + 1;                 /* lower ring */
            /* phi grows towards -z, i.e. counter-clockwise seen from +y. */
            if (r != 0)
                rl_meshbuf_triangle(b, a, d, c);
            if (r != rings - 1)
                rl_meshbuf_triangle(b, c, d, e);
        }
    }
}

void rl_gen_cylinder(rl_meshbuf *b, float radius, float height, uint32_t segments, bool caps)
{
    float h = 0.5f * height;
    uint64_t nv = 2ull * (segments + 1) + (caps ? 2ull * (segments + 1) : 0);
    uint64_t nt = 2ull * segments + (caps ? 2ull * segments : 0);
    if (!rl_meshbuf_reserve(b, nv, nt))
        return;
    uint32_t side = b->num_vertices;
    for (uint32_t s = 0; s <= segments; ++s) {
        float u = (float)s / (float)segments;
        float phi = u * 2.0f * RL_PI;
        rl_vec3 n = rl_v3(cosf(phi), 0.0f, -sinf(phi));
        rl_vec3 p = rl_scale(n, radius);
        rl_meshbuf_vertex(b, rl_v3(p.x, -h, p.z), n, rl_v2(u, 0.0f));
        rl_meshbuf_vertex(b, rl_v3(p.x, h, p.z), n, rl_v2(u, 1.0f));
    }
    for (uint32_t s = 0; s < segments; ++s) {
        uint32_t a = side + 2 * s;     /* bottom, top at a+1; next column a+2 */
        rl_meshbuf_triangle(b, a, a + 2, a + 3);
        rl_meshbuf_triangle(b, a, a + 3, a + 1);
    }
    if (!caps)
        return;
    for (int top = 0; top < 2; ++top) {
        float y = top ? h : -h;
        rl_vec3 n = rl_v3(0.0f, top ? 1.0f : -1.0f, 0.0f);
        uint32_t centre = rl_meshbuf_vertex(b, rl_v3(0.0f, y, 0.0f), n, rl_v2(0.5f, 0.5f));
        uint32_t rim = b->num_vertices;
        for (uint32_t s = 0; s < segments; ++s) {
            float phi = (float)s / (float)segments * 2.0f * RL_PI;
            float c = cosf(phi), sn = sinf(phi);
            rl_meshbuf_vertex(b, rl_v3(radius * c, y, -radius * sn), n,
                              rl_v2(0.5f + 0.5f * c, 0.5f + 0.5f * sn));
        }
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t p = rim + s, q = rim + (s + 1) % segments;
            /* The rim runs counter-clockwise seen from +y. */
            if (top)
                rl_meshbuf_triangle(b, centre, p, q);
            else
                rl_meshbuf_triangle(b, centre, q, p);
        }
    }
}

/* "2", "2x1x3" or "2:1:3" -> edge lengths. */
static rl_status parse_size(const char *text, rl_vec3 *out)
{
    char buf[128];
    size_t len = strlen(text);
    if (len >= sizeof buf)
        return rl_error(RL_ERR_INVALID_ARG, "box: size \"%.32s...\" is too long", text);
    memcpy(buf, text, len + 1);
    double v[3];
    int n = 0;
    char *start = buf;
    for (char *c = buf;; ++c) {
        bool end = *c == '\0';
        if (end || *c == 'x' || *c == 'X' || *c == ':') {
            *c = '\0';
            if (n == 3 || !rl_parse_float(start, &v[n]) || !(v[n] > 0.0) || v[n] > GEN_MAX_SIZE)
                return rl_error(RL_ERR_INVALID_ARG,
                                "box: size \"%s\": expected one or three numbers in (0, 1e6] "
                                "joined by 'x' or ':'", text);
            ++n;
            start = c + 1;
            if (end)
                break;
        }
    }
    if (n == 2)
        return rl_error(RL_ERR_INVALID_ARG, "box: size \"%s\": expected one or three numbers",
                        text);
    *out = n == 1 ? rl_v3s((float)v[0]) : rl_v3((float)v[0], (float)v[1], (float)v[2]);
    return RL_OK;
}

static rl_status build_box(rl_meshbuf *b, rl_params *p)
{
    rl_vec3 size = rl_v3s(1.0f);
    const char *text = rl_params_get(p, "size");
    rl_status s = text ? parse_size(text, &size) : RL_OK;
    double sx = size.x, sy = size.y, sz = size.z;
    if (!s) s = rl_params_float(p, "box", "sx", 1e-30, GEN_MAX_SIZE, &sx);
    if (!s) s = rl_params_float(p, "box", "sy", 1e-30, GEN_MAX_SIZE, &sy);
    if (!s) s = rl_params_float(p, "box", "sz", 1e-30, GEN_MAX_SIZE, &sz);
    if (!s) s = rl_params_check_unused(p, "box", "size, sx, sy, sz");
    if (!s)
        rl_gen_box(b, rl_v3((float)sx, (float)sy, (float)sz));
    return s;
}

static rl_status build_quad(rl_meshbuf *b, rl_params *p)
{
    double sx = 1.0, sz = 1.0, repeat = 1.0;
    rl_status s = rl_params_float(p, "quad", "sx", 1e-30, GEN_MAX_SIZE, &sx);
    if (!s) s = rl_params_float(p, "quad", "sz", 1e-30, GEN_MAX_SIZE, &sz);
    if (!s) s = rl_params_float(p, "quad", "repeat", 1e-3, 1e4, &repeat);
    if (!s) s = rl_params_check_unused(p, "quad", "sx, sz, repeat");
    if (!s)
        rl_gen_quad(b, (float)sx, (float)sz, (float)repeat);
    return s;
}

static rl_status build_sphere(rl_meshbuf *b, rl_params *p)
{
    double radius = 1.0;
    long long segments = 32, rings = 16;
    rl_status s = rl_params_float(p, "sphere", "radius", 1e-30, GEN_MAX_SIZE, &radius);
    if (!s) s = rl_params_int(p, "sphere", "segments", 3, 4096, &segments);
    if (!s) s = rl_params_int(p, "sphere", "rings", 2, 4096, &rings);
    if (!s) s = rl_params_check_unused(p, "sphere", "radius, segments, rings");
    if (!s)
        rl_gen_sphere(b, (float)radius, (uint32_t)segments, (uint32_t)rings);
    return s;
}

static rl_status build_cylinder(rl_meshbuf *b, rl_params *p)
{
    double radius = 1.0, height = 2.0;
    long long segments = 32;
    bool caps = true;
    rl_status s = rl_params_float(p, "cylinder", "radius", 1e-30, GEN_MAX_SIZE, &radius);
    if (!s) s = rl_params_float(p, "cylinder", "height", 1e-30, GEN_MAX_SIZE, &height);
    if (!s) s = rl_params_int(p, "cylinder", "segments", 3, 65536, &segments);
    if (!s) s = rl_params_bool(p, "cylinder", "caps", &caps);
    if (!s) s = rl_params_check_unused(p, "cylinder", "radius, height, segments, caps");
    if (!s)
        rl_gen_cylinder(b, (float)radius, (float)height, (uint32_t)segments, caps);
    return s;
}

static rl_status build_teapot(rl_meshbuf *b, rl_params *p)
{
    long long triangles = RL_TEAPOT_DEFAULT_TRIANGLES;
    double size = 1.0;
    rl_status s = rl_params_int(p, "teapot", "triangles", 1, RL_TEAPOT_MAX_TRIANGLES, &triangles);
    if (!s) s = rl_params_float(p, "teapot", "size", 1e-30, GEN_MAX_SIZE, &size);
    if (!s) s = rl_params_check_unused(p, "teapot", "triangles, size");
    if (!s)
        rl_gen_teapot(b, (uint32_t)triangles, (float)size);
    return s;
}

static rl_status build_blob(rl_meshbuf *b, rl_params *p)
{
    long long triangles = RL_BLOB_DEFAULT_TRIANGLES, seed = 1, lumps = 6;
    double scale = 1.0;
    rl_status s = rl_params_int(p, "blob", "triangles", RL_BLOB_MIN_TRIANGLES,
                                RL_BLOB_MAX_TRIANGLES, &triangles);
    if (!s) s = rl_params_int(p, "blob", "seed", 0, 1ll << 53, &seed);
    if (!s) s = rl_params_float(p, "blob", "scale", 1e-30, GEN_MAX_SIZE, &scale);
    if (!s) s = rl_params_int(p, "blob", "lumps", 0, RL_BLOB_MAX_LUMPS, &lumps);
    if (!s) s = rl_params_check_unused(p, "blob", "triangles, seed, scale, lumps");
    if (!s)
        s = rl_gen_blob(b, &(rl_blob_desc){ .triangles = (uint32_t)triangles,
                                            .seed = (uint64_t)seed, .scale = (float)scale,
                                            .lumps = (int)lumps });
    return s;
}

typedef struct generator {
    const char *name;
    rl_status (*build)(rl_meshbuf *b, rl_params *p);
} generator;

static const generator generators[] = {
    { "box", build_box },
    { "quad", build_quad },
    { "sphere", build_sphere },
    { "cylinder", build_cylinder },
    { "teapot", build_teapot },
    { "blob", build_blob },
};
#define NUM_GENERATORS (sizeof generators / sizeof generators[0])

static const char *const generator_names[NUM_GENERATORS + 1] = {
    "box", "quad", "sphere", "cylinder", "teapot", "blob", NULL
};

const char *const *rl_generator_names(size_t *count)
{
    if (count)
        *count = NUM_GENERATORS;
    return generator_names;
}

rl_status rl_scene_add_generated(rl_scene *scene, const char *generator_name,
                                 const char *params, uint32_t material, uint32_t *mesh_id)
{
    if (!scene || !generator_name)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_generated: scene and generator "
                                            "must not be NULL");
    const generator *g = NULL;
    for (size_t i = 0; i < NUM_GENERATORS; ++i)
        if (strcmp(generators[i].name, generator_name) == 0)
            g = &generators[i];
    if (!g)
        return rl_error(RL_ERR_NOT_FOUND, "unknown generator \"%s\" (known: box, quad, "
                                          "sphere, cylinder, teapot, blob)", generator_name);
    rl_params p;
    rl_status s = rl_params_parse(params, &p);
    if (s)
        return s;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = material;
    s = g->build(&b, &p);
    if (!s)
        s = rl_meshbuf_add_to_scene(scene, &b, g->name, mesh_id);
    rl_meshbuf_free(&b);
    rl_params_free(&p);
    return s;
}
