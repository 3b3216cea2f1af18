/* rl_vt.h: what the Vertex Tracing renderer "vt" (Ullmann 2003) reports
 * beyond the common rl_renderer interface: per-frame statistics for the
 * Ch. 5 measurements, the refined mesh, and progressive updates.
 *
 * Vertex Tracing in one paragraph: the visible vertices of the VT objects'
 * meshes are ray traced directly (the primary ray hits the vertex, eq. 3.1);
 * the edges between them, longest first, are split at their midpoints
 * wherever the two ends' samples differ by the chosen criteria (RGB, HSV,
 * ray tree) until a minimum projected length; over-compressed triangles are
 * split too (forced refinement); the radiance is reconstructed by Gouraud
 * interpolation of the vertex samples through the rasterizer, together with
 * the rasterized non-VT objects (hybrid rendering). See src/render/vt.c for
 * the options and the section of the thesis each one follows. */
#ifndef RL_VT_H
#define RL_VT_H

#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_render.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_VT_MAX_THREADS 64

typedef struct rl_vt_stats {
    uint32_t vt_objects;               /* objects vertex traced */
    uint64_t primary_vertices;         /* of the VT meshes, after welding */
    uint64_t primary_faces;
    uint64_t visible_primary_faces;    /* passed the ID-buffer test (Sec. 3.4.1) */
    uint64_t vertices_sampled;         /* vertices that cast rays this frame */
    uint64_t vertices_generated;       /* new vertices made by refinement */
    uint64_t splits_rgb, splits_hsv, splits_tree;  /* an edge may fire several */
    uint64_t splits_forced;            /* forced refinement (Sec. 3.3.2) */
    uint64_t edges_tested;             /* criterion tests */
    uint64_t edges_culled_z;           /* new edges dropped by the z test */
    uint64_t edges_culled_viewport;    /* new edges dropped by the viewport test */
    uint64_t faces_drawn;              /* VT faces rasterized in the final image */
    uint64_t feelers_reused;           /* shadow feelers answered by temporal coherence */
    uint64_t vertices_merged;          /* primary vertices that took a neighbour's sample
                                        * instead of casting rays (merge_px, Sec. 6.2.1) */
    uint32_t stages;                   /* refinement stages run */
    double time_visibility_ms;         /* ID/Z pre-pass and face flags */
    double time_sampling_ms;           /* ray tracing of vertices (wall) */
    double time_refine_ms;             /* criteria, splits, edge list (serial) */
    double time_draw_ms;               /* reconstruction (non-VT objects + VT faces) */
    double time_preview_ms;            /* from the start until the preview (the
                                        * primary vertices only) was drawn */
    uint32_t threads;
    uint64_t thread_rays[RL_VT_MAX_THREADS];   /* rays traced per thread (Fig. 5.15b) */
    double thread_busy_ms[RL_VT_MAX_THREADS];  /* sampling time per thread */
    uint64_t mesh_bytes;               /* the refined mesh at the frame's end:
                                        * its vertices, samples, edges, faces
                                        * and deferred layers, as used (the
                                        * arrays' spare room not counted) */
    uint64_t splits_nonlinear;         /* edges split by option nonlinear (Sec. 6.1.1) */
    uint64_t splits_shaft;             /* edges split by option shaft_cull (Sec. 6.1.2) */
    uint64_t shaft_faces_tested;       /* faces whose shafts were built and tested */
    /* Sec. 6.2.2, option hint: rays of refined vertices tested first
     * against a triangle their parent vertices' rays hit in the same slot
     * of the ray tree, and of those the rays where a hinted triangle was
     * hit (a shadow feeler ended there, or the search stopped at it). */
    uint64_t hint_tests, hint_hits;
    /* rl --dist with option dist_postpass, the master's drawing (Ullmann
     * 2003, Sec. 6.1.3; docs/distributed.md): the post-pass replays one
     * process' refinement over the packages' samples; vertices whose
     * sample a part carried, and vertices it traced itself: the places
     * where the merged packages differ from one process. */
    uint64_t postpass_reused, postpass_traced;
    /* option pixel_split: edges at or below min_edge split because a
     * criterion fired and a pixel centre shows the split */
    uint64_t splits_pixel;
} rl_vt_stats;

/* Statistics of the last frame rendered by r. RL_ERR_INVALID_ARG when r is
 * not a "vt" renderer or has rendered nothing yet. */
RL_API rl_status rl_vt_get_stats(const rl_renderer *r, rl_vt_stats *out);

/* One vertex of the refined mesh of the last frame, in screen space. */
typedef struct rl_vt_vertex_info {
    float x, y;                        /* pixels, y down */
    uint16_t stage;                    /* 0 = primary */
    uint8_t sampled;                   /* cast rays */
    uint8_t reason;                    /* why it exists: 0 primary, else the
                                        * bits 1 rgb, 2 hsv, 4 tree, 8 forced,
                                        * 16 nonlinear, 32 shaft (Sec. 6.1) */
} rl_vt_vertex_info;

/* The vertices and the leaf faces (3 vertex indices each) of the last frame.
 * The arrays stay valid until the next render or release. */
RL_API rl_status rl_vt_get_mesh(const rl_renderer *r, const rl_vt_vertex_info **vertices,
                                size_t *num_vertices, const uint32_t **faces, size_t *num_faces);

/* Progressive display (Sec. 3.5.1): called with the current image after the
 * preview (stage 0) and after every k-th refinement stage (option
 * update_every), drawn by overdraw or redraw (option progressive), and once
 * more with final = true. Returning false stops the refinement there (the
 * image is then the last update). fn NULL removes the callback. */
typedef bool (*rl_vt_update_fn)(void *user, const rl_image *image, uint32_t stage, bool final);
RL_API rl_status rl_vt_set_update_callback(rl_renderer *r, rl_vt_update_fn fn, void *user);

/* Distributed Vertex Tracing (Ullmann 2003, Sec. 4.3; rl_dist.h runs it
 * over MPI ranks). A frame is split by primary faces: the master takes the
 * visible primary faces of the ID pre-pass (rl_vt_prepare), hands them out
 * in packages, every rank refines its packages (rl_vt_refine_faces) into
 * parts, and the master draws the frame from all parts (rl_vt_draw_parts).
 * Every rank needs the same scene, options, camera and image size.
 *
 * A package's faces start the refinement; splits spread into neighbouring
 * faces as in one process, and with the option dist_halo (default) the
 * visible faces sharing an edge with the package are flagged visible too,
 * so that forced refinement (Sec. 3.3.2) crosses the package's border as
 * in one process. A part holds the package's refined leaf faces only:
 * neighbours are drawn from their own packages (docs/distributed.md).
 * With the option dist_postpass (Sec. 6.1.3) a part also carries every
 * sample its package traced, and rl_vt_draw_parts replays one process'
 * refinement over them, tracing only the vertices no part has: the image
 * is then the one-process image bit for bit (rl_vt_stats.postpass_*). */

/* The ID pre-pass for cam at image's size (it draws the rasterized half
 * of the frame into image): *faces receives the visible primary faces in
 * ascending order, *count of them, owned by r until its next call. */
RL_API rl_status rl_vt_prepare(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                               const uint32_t **faces, size_t *count);
/* Refines the primary faces faces[0..count) (any primary faces; the
 * invisible ones add nothing) of cam's frame and writes the part: a
 * malloc'd buffer for free() into *part, *part_size bytes. Runs the
 * pre-pass first unless r ran it last for the same scene, camera, size
 * and options (image is its scratch then). stats: rays and samples. */
RL_API rl_status rl_vt_refine_faces(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                    const uint32_t *faces, size_t count, void **part, size_t *part_size,
                                    rl_render_stats *stats);
/* The pre-compute balancer's cost estimate b_f of every primary face
 * faces[0..count) of cam's frame (Ullmann 2003, Sec. 4.3.3, eq. 4.4-4.5):
 * the face's primary vertices are sampled, and b_f is the mean over its
 * edges of the ends' sample difference (1 for different ray trees, else
 * the mean colour channel difference) times the projected length over
 * the viewport's diagonal, here weighted by the rays the ends' samples
 * traced, plus the face's own share of the primary samples (half a
 * sample), so that no face is free (docs/distributed.md). Runs the
 * pre-pass first unless kept, as rl_vt_refine_faces. cost[i] receives
 * faces[i]'s estimate; stats (may be NULL): its rays and samples. */
RL_API rl_status rl_vt_estimate_costs(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                      const uint32_t *faces, size_t count, double *cost, rl_render_stats *stats);
/* Draws cam's frame into image: the rasterized half and the faces of
 * parts[0..count) (sizes[i] bytes each), in that order; with dist_postpass,
 * the faces of one process' refinement replayed over the parts' samples
 * (see above). A part that fails
 * rl_vt_part_check, or names triangles the scene lacks, is RL_ERR_PARSE
 * and the image is not drawn. rl_vt_get_stats and rl_vt_get_mesh then
 * describe the drawn faces (no refinement counts). */
RL_API rl_status rl_vt_draw_parts(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                  const void *const *parts, const size_t *sizes, size_t count,
                                  rl_render_stats *stats);
/* The post-pass overlapped with the packages still out (option
 * dist_postpass; Ullmann 2003, Sec. 6.1.3; docs/distributed.md, "The
 * post-pass overlapped"): the master adds every part as it comes
 * (rl_vt_postpass_add: checked as rl_vt_part_check, its samples taken
 * into r's map; the part must stay valid until rl_vt_postpass_draw
 * returns) and may start rl_vt_postpass_draw before all are in. The
 * replay takes a vertex's sample from the parts added so far and traces
 * it when none has it, which gives the same sample, so the image is the
 * one-process image whichever parts came when. Between its refinement
 * stages it calls r's progress callback, from which the caller may add
 * the parts that came meanwhile. rl_vt_postpass_draw draws as
 * rl_vt_draw_parts does with dist_postpass and forgets the added parts;
 * rl_vt_postpass_clear forgets them without drawing (a frame that
 * failed). rl_vt_draw_parts with dist_postpass is clear, add every part,
 * draw. */
RL_API rl_status rl_vt_postpass_add(rl_renderer *r, const void *part, size_t size);
RL_API rl_status rl_vt_postpass_draw(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                     rl_render_stats *stats);
RL_API void rl_vt_postpass_clear(rl_renderer *r);
/* Checks a part without a scene (magic, version, counts against its size,
 * checksum, vertex indices): RL_OK with its vertex and face counts, or
 * RL_ERR_PARSE saying what is wrong. vertices and faces may be NULL. */
RL_API rl_status rl_vt_part_check(const void *part, size_t size, size_t *vertices, size_t *faces);

#ifdef __cplusplus
}
#endif
#endif
