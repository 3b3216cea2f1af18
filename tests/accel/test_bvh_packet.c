/* test_bvh_packet.c: the BVH's packet traversal (bvh_packet.c) and the
 * batch queries that use it (rl_accel_intersect_n / rl_accel_occluded_n).
 *
 * Oracle: the single-ray traversal. Every lane must get bit for bit the
 * single ray's hit (triangle, t, u, v, shortened t_max) and occlusion, on
 * coherent packets (camera rays of 4x2 pixel tiles, shadow rays to one
 * point) and on random ones (mixed octants, through the kernel directly),
 * with per-lane t_min and t_max, inactive and invalid lanes, ties (rays
 * through the shared edges and vertices of a mesh and its coplanar copy:
 * the lowest ID must win) and alpha-masked triangles (the batch query must
 * skip the holes as rl_accel_intersect does). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/bvh.h"
#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create_builtin(name, params, &s);
    if (st != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    return s;
}

static rl_accel *make_bvh(const rl_scene *s)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_OK);
    return a;
}

static bool same_float(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Batch results against single queries on copies of the same rays. */
static void assert_batch_equals_single(const rl_accel *a, const rl_ray *rays, size_t n, int *hits_out,
                                       int *occluded_out)
{
    rl_ray *batch = malloc(n * sizeof *batch), *single = malloc(n * sizeof *single);
    rl_hit *bh = malloc(n * sizeof *bh);
    bool *bo = malloc(n * sizeof *bo);
    assert_true(batch && single && bh && bo);
    memcpy(batch, rays, n * sizeof *batch);
    memcpy(single, rays, n * sizeof *single);
    for (size_t i = 0; i < n; ++i)
        bh[i] = (rl_hit){ .t = -7.0f, .u = -7.0f, .v = -7.0f };   /* a miss leaves t, u, v */
    rl_accel_intersect_n(a, batch, bh, n);
    rl_accel_occluded_n(a, rays, bo, n);
    int hits = 0, occluded = 0;
    for (size_t i = 0; i < n; ++i) {
        rl_hit h = { .t = -7.0f, .u = -7.0f, .v = -7.0f };
        bool got = rl_accel_intersect(a, &single[i], &h);
        if (bh[i].triangle != h.triangle || !same_float(bh[i].t, h.t) || !same_float(bh[i].u, h.u) ||
            !same_float(bh[i].v, h.v) || bh[i].object != h.object || !same_float(batch[i].t_max, single[i].t_max))
            fail_msg("ray %zu: batch triangle %u t %.9g u %.9g, single triangle %u t %.9g u %.9g", i,
                     bh[i].triangle, (double)bh[i].t, (double)bh[i].u, h.triangle, (double)h.t, (double)h.u);
        hits += got;
        bool occ = rl_accel_occluded(a, &rays[i]);
        if (bo[i] != occ)
            fail_msg("ray %zu: batch occluded %d, single %d", i, bo[i], occ);
        occluded += occ;
    }
    free(batch);
    free(single);
    free(bh);
    free(bo);
    *hits_out = hits;
    *occluded_out = occluded;
}

/* Camera rays in 4x2 pixel tiles (a packet per tile); every third lane
 * gets a shorter t_max and every fifth a t_min > 0, one ray is invalid. */
static rl_ray *tile_rays(const rl_scene *s, int w, int h, rl_rng *rng, size_t *n)
{
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = w;
    cam.height = h;
    rl_camera_frame f = rl_camera_frame_make(&cam);
    rl_ray *rays = malloc((size_t)w * (size_t)h * sizeof *rays);
    assert_non_null(rays);
    size_t k = 0;
    float scale = rl_vmax_comp(rl_aabb_extent(rl_scene_get_data(s)->bounds));
    for (int ty = 0; ty < h; ty += 2)
        for (int tx = 0; tx < w; tx += 4)
            for (int y = ty; y < ty + 2; ++y)
                for (int x = tx; x < tx + 4; ++x) {
                    rl_ray r = rl_camera_frame_ray(&f, (float)x + rl_rng_float(rng), (float)y + rl_rng_float(rng));
                    if (k % 3 == 1)
                        r.t_max = scale * 2.0f * rl_rng_float(rng);
                    if (k % 5 == 2)
                        r.t_min = scale * 0.5f * rl_rng_float(rng);
                    if (r.t_min > r.t_max)
                        r.t_min = 0.0f;
                    if (k == 13)
                        r.d = rl_v3(0.0f, 0.0f, 0.0f);   /* invalid: turned away */
                    rays[k++] = r;
                }
    *n = k;
    return rays;
}

/* Shadow rays from the hits of rays to one point (a light). */
static rl_ray *shadow_rays(const rl_accel *a, const rl_ray *primary, size_t n, rl_vec3 light, size_t *out)
{
    rl_ray *rays = malloc(n * sizeof *rays);
    assert_non_null(rays);
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        rl_ray r = primary[i];
        rl_hit h;
        if (!rl_accel_intersect(a, &r, &h))
            continue;
        rl_vec3 p = rl_ray_at(&r, h.t * 0.9999f);
        rl_vec3 to = rl_sub(light, p);
        float d = rl_length(to);
        rays[k++] = (rl_ray){ .o = p, .t_min = 0.0f, .d = rl_scale(to, 1.0f / d), .t_max = d * 0.9999f };
    }
    *out = k;
    return rays;
}

static void assert_coherent_batches_equal_single_rays(const char *scene, const char *params)
{
    rl_scene *s = builtin(scene, params);
    rl_accel *a = make_bvh(s);
    rl_rng rng;
    rl_rng_seed(&rng, 5, 1);
    size_t n, ns;
    rl_ray *rays = tile_rays(s, 96, 64, &rng, &n);
    int hits, occluded;
    assert_batch_equals_single(a, rays, n, &hits, &occluded);
    assert_true(hits > (int)n / 10 && hits < (int)n);
    rl_aabb b = rl_scene_get_data(s)->bounds;
    rl_vec3 light = rl_add(rl_aabb_center(b), rl_v3(0.0f, 0.45f * rl_aabb_extent(b).y, 0.0f));
    rl_ray *shadow = shadow_rays(a, rays, n, light, &ns);
    assert_batch_equals_single(a, shadow, ns, &hits, &occluded);
    print_message("%s: %zu primary rays, %zu shadow rays, %d occluded\n", scene, n, ns, occluded);
    assert_true(occluded > 0 && occluded < (int)ns);
    free(shadow);
    free(rays);
    rl_accel_release(a);
    rl_scene_release(s);
}

static void test_coherent_batches_equal_single_rays_cornell(void **state)
{
    (void)state;
    assert_coherent_batches_equal_single_rays("cornell", NULL);
}

static void test_coherent_batches_equal_single_rays_teapot(void **state)
{
    (void)state;
    assert_coherent_batches_equal_single_rays("cornell-teapot", "triangles=2000");
}

static void test_coherent_batches_equal_single_rays_city(void **state)
{
    (void)state;
    assert_coherent_batches_equal_single_rays("city", "blocks=1,detail=0");
}

/* One packet's results (found, occluded) against the single-ray traversal
 * of each active lane, bit for bit: hit or not, triangle, t, u, v and the
 * lane's t_max (a miss leaves it alone); counts lanes, hits and blocked
 * lanes for the callers' plausibility bounds. */
static void check_packet_lanes(const rl_bvh *bvh, const char *what, int packet, rl_ray *rays,
                               const rl_ray *single, rl_hit *hit, unsigned active, int *lanes, int *hits,
                               int *blocked)
{
    unsigned found = rl_bvh_packet_intersect(bvh, rays, hit, active);
    unsigned occ = rl_bvh_packet_occluded(bvh, single, active);
    assert_int_equal(found & ~active, 0);
    assert_int_equal(occ & ~active, 0);
    for (int l = 0; l < RL_BVH_PACKET; ++l) {
        if (!(active & (1u << l)))
            continue;
        ++*lanes;
        rl_ray q = single[l];
        rl_hit h = { .object = RL_ID_NONE };
        bool got = rl_bvh_wide_intersect(bvh, &q, &h);
        if (got != (bool)((found >> l) & 1u) || !same_float(rays[l].t_max, q.t_max) ||
            (got && (hit[l].triangle != h.triangle || !same_float(hit[l].t, h.t) || !same_float(hit[l].u, h.u) ||
                     !same_float(hit[l].v, h.v))))
            fail_msg("%s packet %d lane %d: packet %d triangle %u t %.9g, single %d triangle %u t %.9g", what, packet,
                     l, (int)((found >> l) & 1u), hit[l].triangle, (double)hit[l].t, got, h.triangle, (double)h.t);
        *hits += got;
        bool o = rl_bvh_wide_occluded(bvh, &single[l]);
        if (o != (bool)((occ >> l) & 1u))
            fail_msg("%s packet %d lane %d: packet occluded %d, single %d", what, packet, l, (int)((occ >> l) & 1u), o);
        *blocked += o;
    }
}

/* The kernel itself on packets of random rays of mixed octants (accel.c
 * would not send these, the traversal must still be exact), random active
 * masks and per-lane t_min, t_max. */
static void test_packet_kernel_equals_single_rays_on_random_packets(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_bvh bvh = { 0 };
    rl_accel_stats st = { 0 };
    assert_int_equal(rl_bvh_build(d, &(rl_accel_desc){ .threads = 1 }, &bvh, &st), RL_OK);
    assert_int_equal(rl_bvh_widen(&bvh), RL_OK);
    rl_rng rng;
    rl_rng_seed(&rng, 9, 3);
    rl_aabb b = d->bounds;
    rl_vec3 ext = rl_aabb_extent(b);
    int hits = 0, blocked = 0, lanes = 0;
    for (int packet = 0; packet < 4000; ++packet) {
        rl_ray rays[RL_BVH_PACKET], single[RL_BVH_PACKET];
        rl_hit hit[RL_BVH_PACKET];
        unsigned active = 0;
        /* Half the packets share an origin (a point light's shadow rays
         * outwards, a camera's rays), half are scattered. */
        rl_vec3 shared = rl_v3(b.min.x + ext.x * rl_rng_float(&rng), b.min.y + ext.y * rl_rng_float(&rng),
                               b.min.z + ext.z * rl_rng_float(&rng));
        for (int l = 0; l < RL_BVH_PACKET; ++l) {
            rl_vec3 o = packet % 2 ? shared
                                   : rl_v3(b.min.x + ext.x * rl_rng_float(&rng), b.min.y + ext.y * rl_rng_float(&rng),
                                           b.min.z + ext.z * rl_rng_float(&rng));
            float z = 2.0f * rl_rng_float(&rng) - 1.0f, phi = 2.0f * RL_PI * rl_rng_float(&rng);
            float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            rays[l] = (rl_ray){ .o = o, .t_min = 0.0f, .d = rl_v3(r * cosf(phi), r * sinf(phi), z),
                                .t_max = INFINITY };
            if (rl_rng_float(&rng) < 0.3f)
                rays[l].t_max = rl_vmax_comp(ext) * rl_rng_float(&rng);
            if (rl_rng_float(&rng) < 0.2f)
                rays[l].t_min = rays[l].t_max * 0.5f * rl_rng_float(&rng);
            if (rl_rng_float(&rng) < 0.85f)
                active |= 1u << l;
            single[l] = rays[l];
            hit[l] = (rl_hit){ .object = RL_ID_NONE };
        }
        check_packet_lanes(&bvh, "random", packet, rays, single, hit, active, &lanes, &hits, &blocked);
    }
    assert_true(hits > lanes / 10 && hits < lanes);
    assert_true(blocked > lanes / 10 && blocked < lanes);
    rl_bvh_free(&bvh);
    rl_scene_release(s);
}

/* Narrow packets, the frustum's domain (frustum_children: its reject and
 * its shortcut for the children that every lane surely hits decide most
 * nodes): one shared origin or origins within a small box, directions in
 * a cone of random width (1e-6 to 0.1 rad) around a triangle's vertex or
 * centroid (so lanes run along edges and graze the boxes' faces, the flat
 * boxes of walls included), random active masks, per-lane t_min and
 * t_max; each lane against the single-ray traversal, bit for bit. */
static void assert_narrow_packets_equal_single_rays(const char *scene, const char *params, uint64_t seed)
{
    rl_scene *s = builtin(scene, params);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_bvh bvh = { 0 };
    rl_accel_stats st = { 0 };
    assert_int_equal(rl_bvh_build(d, &(rl_accel_desc){ .threads = 1 }, &bvh, &st), RL_OK);
    assert_int_equal(rl_bvh_widen(&bvh), RL_OK);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 7);
    float extent = rl_vmax_comp(rl_aabb_extent(d->bounds));
    int hits = 0, blocked = 0, lanes = 0;
    for (int packet = 0; packet < 3000; ++packet) {
        uint32_t tri = (uint32_t)(rl_rng_float(&rng) * (float)d->num_triangles) % d->num_triangles;
        rl_vec3 v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = d->positions[d->indices[3 * (size_t)tri + (size_t)k]];
        int corner = (int)(rl_rng_float(&rng) * 4.0f);
        rl_vec3 target = corner < 3 ? v[corner] : rl_scale(rl_add(rl_add(v[0], v[1]), v[2]), 1.0f / 3.0f);
        float z = 2.0f * rl_rng_float(&rng) - 1.0f, phi = 2.0f * RL_PI * rl_rng_float(&rng);
        float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        float dist = extent * (0.02f + 1.5f * rl_rng_float(&rng));
        rl_vec3 eye = rl_add(target, rl_scale(rl_v3(r * cosf(phi), r * sinf(phi), z), dist));
        float cone = powf(10.0f, -1.0f - 5.0f * rl_rng_float(&rng)) * dist;
        float spread = packet % 3 == 0 ? 0.0f : cone * rl_rng_float(&rng);
        rl_ray rays[RL_BVH_PACKET], single[RL_BVH_PACKET];
        rl_hit hit[RL_BVH_PACKET];
        unsigned active = 0;
        for (int l = 0; l < RL_BVH_PACKET; ++l) {
            rl_vec3 o = rl_add(eye, rl_v3(spread * (rl_rng_float(&rng) - 0.5f), spread * (rl_rng_float(&rng) - 0.5f),
                                          spread * (rl_rng_float(&rng) - 0.5f)));
            rl_vec3 at = l == 0 ? target
                                : rl_add(target, rl_v3(cone * (rl_rng_float(&rng) - 0.5f), cone * (rl_rng_float(&rng) - 0.5f),
                                                       cone * (rl_rng_float(&rng) - 0.5f)));
            rl_vec3 dir = rl_sub(at, o);
            rays[l] = (rl_ray){ .o = o, .t_min = 0.0f, .d = rl_scale(dir, 1.0f / rl_length(dir)), .t_max = INFINITY };
            if (rl_rng_float(&rng) < 0.3f)
                rays[l].t_max = dist * 2.0f * rl_rng_float(&rng);
            if (rl_rng_float(&rng) < 0.2f)
                rays[l].t_min = rays[l].t_max * 0.5f * rl_rng_float(&rng);
            if (rl_rng_float(&rng) < 0.9f)
                active |= 1u << l;
            single[l] = rays[l];
            hit[l] = (rl_hit){ .object = RL_ID_NONE };
        }
        check_packet_lanes(&bvh, scene, packet, rays, single, hit, active, &lanes, &hits, &blocked);
    }
    print_message("%s: %d narrow-packet lanes, %d hits, %d blocked\n", scene, lanes, hits, blocked);
    assert_true(hits > lanes / 4 && hits < lanes);
    assert_true(blocked > lanes / 4 && blocked < lanes);
    rl_bvh_free(&bvh);
    rl_scene_release(s);
}

static void test_narrow_packets_equal_single_rays_cornell(void **state)
{
    (void)state;
    assert_narrow_packets_equal_single_rays("cornell", NULL, 21);
}

static void test_narrow_packets_equal_single_rays_teapot(void **state)
{
    (void)state;
    assert_narrow_packets_equal_single_rays("cornell-teapot", "triangles=2000", 22);
}

/* A 16x16 quad grid at z = 0 and its exact copy (coplanar: every hit is a
 * tie at equal t), rays aimed at its vertices and edge midpoints from
 * above: the lowest triangle ID must win in both paths. */
static void test_ties_on_shared_edges_go_to_the_lowest_id(void **state)
{
    (void)state;
    enum { G = 16 };
    rl_vec3 pos[(G + 1) * (G + 1)];
    uint32_t idx[2][G * G * 6];
    for (int y = 0; y <= G; ++y)
        for (int x = 0; x <= G; ++x)
            pos[y * (G + 1) + x] = rl_v3((float)x / G * 2.0f - 1.0f, (float)y / G * 2.0f - 1.0f, 0.0f);
    for (int y = 0, k = 0; y < G; ++y)
        for (int x = 0; x < G; ++x, k += 6) {
            uint32_t v = (uint32_t)(y * (G + 1) + x);
            const uint32_t q[6] = { v, v + 1, v + G + 2, v, v + G + 2, v + G + 1 };
            memcpy(&idx[0][k], q, sizeof q);
            /* The copy winds the other way round and in another order. */
            const uint32_t c[6] = { v + G + 2, v + 1, v, v + G + 1, v + G + 2, v };
            memcpy(&idx[1][k], c, sizeof c);
        }
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    for (int copy = 0; copy < 2; ++copy) {
        rl_mesh_desc md = { .name = copy ? "copy" : "grid", .num_vertices = (G + 1) * (G + 1), .positions = pos,
                            .num_triangles = G * G * 2, .indices = idx[copy], .material = mat };
        assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, md.name, NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_accel *a = make_bvh(s);
    enum { N = (2 * G + 1) * (2 * G + 1) };
    rl_ray *rays = malloc(N * sizeof *rays);
    assert_non_null(rays);
    rl_vec3 eye = rl_v3(0.1f, -0.2f, 3.0f);
    for (int y = 0, k = 0; y <= 2 * G; ++y)
        for (int x = 0; x <= 2 * G; ++x, ++k) {
            rl_vec3 target = rl_v3((float)x / G - 1.0f, (float)y / G - 1.0f, 0.0f);
            rays[k] = (rl_ray){ .o = eye, .t_min = 0.0f, .d = rl_sub(target, eye), .t_max = INFINITY };
        }
    int hits, occluded;
    assert_batch_equals_single(a, rays, N, &hits, &occluded);
    assert_true(hits > N / 2 && occluded == hits);
    /* The winner is always from the first copy (lower IDs). */
    for (int k = 0; k < N; ++k) {
        rl_hit h;
        rl_ray r = rays[k];
        if (rl_accel_intersect(a, &r, &h))
            assert_true(h.triangle < G * G * 2);
    }
    free(rays);
    rl_accel_release(a);
    rl_scene_release(s);
}

/* Alpha masks: a quad (-1..1)^2 at z = 0 opaque only where u > 1/2, a
 * larger quad behind it. The batch query must skip the holes exactly as
 * rl_accel_intersect does (same hits, same occlusion). */
static void test_batches_skip_alpha_mask_holes_as_single_rays_do(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    const rl_vec4 texels[8] = { { 1, 1, 1, 0 }, { 1, 1, 1, 0 }, { 1, 1, 1, 0 }, { 1, 1, 1, 0 },
                                { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 } };
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(8, 1, texels, &tex), RL_OK);
    uint32_t tex_id, leaf, back;
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse_texture = tex_id;
    m.alpha_cutoff = 0.5f;
    assert_int_equal(rl_scene_add_material(s, &m, &leaf), RL_OK);
    m = rl_material_default();
    assert_int_equal(rl_scene_add_material(s, &m, &back), RL_OK);
    for (int q = 0; q < 2; ++q) {
        float half = q ? 2.5f : 1.0f, z = q ? -1.0f : 0.0f;
        const rl_vec3 pos[4] = { { -half, -half, z }, { half, -half, z }, { half, half, z }, { -half, half, z } };
        const rl_vec2 uv[4] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
        const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
        uint32_t mesh, node;
        rl_mesh_desc md = { .name = q ? "back" : "leaf", .num_vertices = 4, .positions = pos, .uvs = uv,
                            .num_triangles = 2, .indices = idx, .material = q ? back : leaf };
        assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, md.name, NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_accel *a = make_bvh(s);
    enum { W = 48, H = 48 };
    rl_ray rays[W * H];
    rl_vec3 eye = rl_v3(0.0f, 0.0f, 4.0f);
    size_t k = 0;
    for (int ty = 0; ty < H; ty += 2)
        for (int tx = 0; tx < W; tx += 4)
            for (int y = ty; y < ty + 2; ++y)
                for (int x = tx; x < tx + 4; ++x) {
                    rl_vec3 target = rl_v3(3.0f * ((float)x + 0.5f) / W - 1.5f, 3.0f * ((float)y + 0.5f) / H - 1.5f, 0.0f);
                    rays[k] = (rl_ray){ .o = eye, .d = rl_sub(target, eye), .t_max = k % 7 == 3 ? 1.1f : INFINITY };
                    ++k;
                }
    int hits, occluded;
    assert_batch_equals_single(a, rays, k, &hits, &occluded);
    /* Some rays pass through a hole to the back quad, and rays stopped
     * short of it there are not occluded. */
    int through = 0;
    for (size_t i = 0; i < k; ++i) {
        rl_ray r = rays[i];
        rl_hit h;
        if (rl_accel_intersect(a, &r, &h) && h.object == 1 && fabsf(rays[i].d.x) < 0.2f && fabsf(rays[i].d.y) < 0.2f)
            ++through;
    }
    assert_true(through > 4);
    /* Rays stopped at t = 1.1, between the quads (t = 1 and 1.25: d is
     * not normalised), miss behind a hole. */
    assert_true(hits < (int)k && occluded == hits);
    rl_accel_release(a);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coherent_batches_equal_single_rays_cornell),
        cmocka_unit_test(test_coherent_batches_equal_single_rays_teapot),
        cmocka_unit_test(test_coherent_batches_equal_single_rays_city),
        cmocka_unit_test(test_packet_kernel_equals_single_rays_on_random_packets),
        cmocka_unit_test(test_narrow_packets_equal_single_rays_cornell),
        cmocka_unit_test(test_narrow_packets_equal_single_rays_teapot),
        cmocka_unit_test(test_ties_on_shared_edges_go_to_the_lowest_id),
        cmocka_unit_test(test_batches_skip_alpha_mask_holes_as_single_rays_do),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
