/* test_raster_renderer.c: renderer "raster" against oracles: a brute-force
 * ray caster for visibility (IDs, depth), the analytic Phong value for a
 * lit quad, and itself (determinism, thread count, requested layers). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

#define ALL_LAYERS FX_ALL_LAYERS

/* Möller & Trumbore 1997: distance along r to triangle (a,b,c), or INFINITY. */
static float intersect_triangle(const rl_ray *r, rl_vec3 a, rl_vec3 b, rl_vec3 c)
{
    rl_vec3 e1 = rl_sub(b, a), e2 = rl_sub(c, a);
    rl_vec3 p = rl_cross(r->d, e2);
    float det = rl_dot(e1, p);
    if (fabsf(det) < 1e-12f)
        return INFINITY;
    float inv = 1.0f / det;
    rl_vec3 s = rl_sub(r->o, a);
    float u = rl_dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f)
        return INFINITY;
    rl_vec3 q = rl_cross(s, e1);
    float v = rl_dot(r->d, q) * inv;
    if (v < 0.0f || u + v > 1.0f)
        return INFINITY;
    float t = rl_dot(e2, q) * inv;
    return t > r->t_min && t < r->t_max ? t : INFINITY;
}

/* Closest triangle along r by testing all of them; RL_ID_NONE on a miss. */
static uint32_t brute_force_hit(const rl_scene_data *d, const rl_ray *r, float *t_hit)
{
    uint32_t best = RL_ID_NONE;
    *t_hit = INFINITY;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        const uint32_t *i = &d->indices[3 * t];
        float dist = intersect_triangle(r, d->positions[i[0]], d->positions[i[1]], d->positions[i[2]]);
        if (dist < *t_hit) {
            *t_hit = dist;
            best = t;
        }
    }
    return best;
}

static void test_cornell_ids_and_depth_agree_with_brute_force_ray_casting(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_image *img = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    rl_camera resolved = rl_camera_resolve(&cam);
    rl_camera_frame f = rl_camera_frame_make(&resolved);

    int object_mismatches = 0, triangle_mismatches = 0, hits = 0;
    for (int y = 0; y < img->height; ++y) {
        for (int x = 0; x < img->width; ++x) {
            size_t p = (size_t)y * img->width + x;
            rl_ray ray = rl_camera_frame_ray(&f, x + 0.5f, y + 0.5f);
            float t;
            uint32_t tri = brute_force_hit(d, &ray, &t);
            uint32_t object = tri == RL_ID_NONE ? RL_ID_NONE : d->triangle_object[tri];
            if (img->object_id[p] != object) {
                ++object_mismatches;
                continue;
            }
            triangle_mismatches += img->triangle_id[p] != tri;
            if (object == RL_ID_NONE) {
                assert_true(isinf(img->depth[p]));
                continue;
            }
            ++hits;
            /* Depth is the distance along the view axis, -w. */
            float depth = t * rl_dot(ray.d, rl_neg(f.w));
            assert_float_equal(img->depth[p], depth, 1e-3 * depth);
        }
    }
    int pixels = img->width * img->height;
    assert_true(hits > pixels / 2);                  /* the box fills most of the view */
    assert_true(object_mismatches * 100 < pixels);   /* only silhouette pixels may differ */
    assert_true(triangle_mismatches * 100 < pixels);
    rl_image_release(img);
    rl_scene_release(s);
}

/* An n x n grid over [-1,1]^2 at y = 0, facing +y, uv = (x, z) mapped to [0,1]. */
typedef struct grid {
    uint32_t nv, nt;
    rl_vec3 *pos, *nrm;
    rl_vec2 *uv;
    uint32_t *idx;
} grid;

static grid make_grid(int n)
{
    grid g = { (uint32_t)((n + 1) * (n + 1)), (uint32_t)(2 * n * n), NULL, NULL, NULL, NULL };
    g.pos = calloc(g.nv, sizeof *g.pos);
    g.nrm = calloc(g.nv, sizeof *g.nrm);
    g.uv = calloc(g.nv, sizeof *g.uv);
    g.idx = calloc((size_t)g.nt * 3, sizeof *g.idx);
    assert_true(g.pos && g.nrm && g.uv && g.idx);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            g.pos[j * (n + 1) + i] = rl_v3(-1.0f + 2.0f * i / n, 0.0f, -1.0f + 2.0f * j / n);
            g.nrm[j * (n + 1) + i] = rl_v3(0, 1, 0);
            g.uv[j * (n + 1) + i] = rl_v2((float)i / n, (float)j / n);
        }
    uint32_t *t = g.idx;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, dd = a + n + 1;
            /* Counter-clockwise seen from +y. */
            *t++ = a; *t++ = c; *t++ = b;
            *t++ = a; *t++ = dd; *t++ = c;
        }
    return g;
}

static void free_grid(grid *g)
{
    free(g->pos);
    free(g->nrm);
    free(g->uv);
    free(g->idx);
}

/* Adds nt triangles of g (indices idx) as one mesh on its own node. */
static void add_grid_part(rl_scene *s, const grid *g, const uint32_t *idx, uint32_t nt,
                          const uint32_t *triangle_materials, uint32_t material)
{
    rl_mesh_desc md = { .name = "grid", .num_vertices = g->nv, .positions = g->pos,
                        .normals = g->nrm, .uvs = g->uv, .num_triangles = nt, .indices = idx,
                        .triangle_materials = triangle_materials, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "grid", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static void add_grid(rl_scene *s, int n, uint32_t material)
{
    grid g = make_grid(n);
    add_grid_part(s, &g, g.idx, g.nt, NULL, material);
    free_grid(&g);
}

static const rl_vec3 quad_kd = { 0.5f, 0.5f, 0.5f }, quad_ks = { 0.5f, 0.5f, 0.5f };
static const float light_height = 2.0f, light_intensity = 2.0f;

/* The grid lit by one light. */
static rl_scene *quad_with_light(const rl_light *l)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = quad_kd;
    m.specular = quad_ks;
    m.shininess = 10.0f;
    uint32_t mat;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    add_grid(s, 8, mat);
    assert_int_equal(rl_scene_add_light(s, l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* The grid with a point light straight above its centre. */
static rl_scene *lit_quad(void)
{
    rl_light l = { .type = RL_LIGHT_POINT, .color = { 1, 1, 1 }, .intensity = light_intensity,
                   .position = { 0, light_height, 0 } };
    return quad_with_light(&l);
}

/* Looking straight down at the quad; odd size so that the centre pixel's
 * centre is exactly the centre vertex. */
static rl_camera top_camera(float height)
{
    return (rl_camera){ .eye = { 0, height, 0 }, .target = { 0, 0, 0 }, .up = { 0, 0, -1 },
                        .fov_deg = 45.0f, .width = 65, .height = 65 };
}

static void test_quad_under_point_light_matches_analytic_phong_at_centre_vertex(void **state)
{
    (void)state;
    rl_scene *s = lit_quad();
    rl_camera cam = top_camera(3.0f);
    rl_image *img = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);

    /* At the centre n = l = v = r = +y: E = I / h^2, n.l = r.v = 1. */
    float E = light_intensity / (light_height * light_height);
    float expected = quad_kd.x * E + quad_ks.x * E + 0.05f * quad_kd.x;
    rl_vec4 centre = *rl_image_pixel(img, 32, 32);
    assert_int_equal(img->object_id[32 * 65 + 32], 0);
    assert_float_equal(centre.x, expected, 0.02f * expected);
    assert_float_equal(centre.y, expected, 0.02f * expected);
    assert_float_equal(centre.z, expected, 0.02f * expected);
    assert_float_equal(img->depth[32 * 65 + 32], 3.0f, 3e-3f);

    const int corners[4][2] = { { 8, 8 }, { 56, 8 }, { 8, 56 }, { 56, 56 } };
    for (int i = 0; i < 4; ++i) {
        int x = corners[i][0], y = corners[i][1];
        assert_int_equal(img->object_id[y * 65 + x], 0);
        assert_true(rl_image_pixel(img, x, y)->x < 0.5f * centre.x);
    }
    /* Outside the quad: the default black background. */
    assert_int_equal(img->object_id[0], RL_ID_NONE);
    assert_float_equal(img->color[0].x, 0.0f, 0.0f);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_directional_and_spot_lights_match_analytic_values(void **state)
{
    (void)state;
    rl_camera cam = top_camera(3.0f);
    const float ambient = 0.05f * quad_kd.x;

    /* Directional straight down: E = I everywhere, n.l = 1; at the centre r.v = 1 too. */
    rl_light sun = { .type = RL_LIGHT_DIRECTIONAL, .color = { 1, 1, 1 }, .intensity = 0.5f,
                     .direction = { 0, -1, 0 } };
    rl_scene *s = quad_with_light(&sun);
    rl_image *img = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    float expected = (quad_kd.x + quad_ks.x) * 0.5f + ambient;
    assert_float_equal(rl_image_pixel(img, 32, 32)->x, expected, 0.02f * expected);
    /* Away from the centre the specular lobe fades but the diffuse part stays. */
    float corner = rl_image_pixel(img, 8, 8)->x;
    assert_true(corner < expected && corner > quad_kd.x * 0.5f);
    rl_image_release(img);
    rl_scene_release(s);

    /* Spot from above with a 20 degree cone: the centre sees it like a point
     * light, the corners (35 degrees off the axis) get only ambient. */
    rl_light spot = { .type = RL_LIGHT_SPOT, .color = { 1, 1, 1 }, .intensity = light_intensity,
                      .position = { 0, light_height, 0 }, .direction = { 0, -1, 0 },
                      .spot_inner_deg = 10.0f, .spot_outer_deg = 20.0f };
    s = quad_with_light(&spot);
    img = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    float E = light_intensity / (light_height * light_height);
    expected = (quad_kd.x + quad_ks.x) * E + ambient;
    assert_float_equal(rl_image_pixel(img, 32, 32)->x, expected, 0.02f * expected);
    assert_float_equal(rl_image_pixel(img, 8, 8)->x, ambient, 1e-4f);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_back_face_culling_hides_the_quad_from_below(void **state)
{
    (void)state;
    rl_scene *s = lit_quad();
    rl_camera below = top_camera(-3.0f);
    rl_render_stats culled, kept;
    const char *const cull[] = { "cull", "true", NULL };
    rl_image *a = fx_render("raster", s, &below, ALL_LAYERS, cull, &culled);
    rl_image *b = fx_render("raster", s, &below, ALL_LAYERS, NULL, &kept);
    assert_int_equal(culled.pixels_written, 0);
    assert_true(kept.pixels_written > 0);
    /* Two-sided lighting: from below the quad is lit as if its normal faced us,
     * but the light is behind it, so only ambient remains. */
    assert_float_equal(rl_image_pixel(b, 32, 32)->x, 0.05f * quad_kd.x, 1e-4f);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

/* A UV sphere of radius 1 at the origin with smooth normals. */
static rl_scene *sphere_scene(void)
{
    enum { STACKS = 8, SLICES = 12 };
    rl_vec3 pos[(STACKS + 1) * (SLICES + 1)], nrm[(STACKS + 1) * (SLICES + 1)];
    uint32_t idx[STACKS * SLICES * 6], nt = 0;
    for (int i = 0; i <= STACKS; ++i)
        for (int j = 0; j <= SLICES; ++j) {
            float theta = RL_PI * i / STACKS, phi = 2.0f * RL_PI * j / SLICES;
            rl_vec3 p = rl_v3(sinf(theta) * cosf(phi), cosf(theta), -sinf(theta) * sinf(phi));
            pos[i * (SLICES + 1) + j] = p;
            nrm[i * (SLICES + 1) + j] = p;
        }
    for (int i = 0; i < STACKS; ++i)
        for (int j = 0; j < SLICES; ++j) {
            uint32_t a = i * (SLICES + 1) + j, b = a + SLICES + 1;
            if (i > 0) {               /* skip the zero-area triangles at the poles */
                idx[3 * nt] = a; idx[3 * nt + 1] = b; idx[3 * nt + 2] = a + 1; ++nt;
            }
            if (i < STACKS - 1) {
                idx[3 * nt] = a + 1; idx[3 * nt + 1] = b; idx[3 * nt + 2] = b + 1; ++nt;
            }
        }
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    rl_mesh_desc md = { .name = "sphere", .num_vertices = (STACKS + 1) * (SLICES + 1),
                        .positions = pos, .normals = nrm, .num_triangles = nt, .indices = idx,
                        .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "sphere", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    rl_light l = { .type = RL_LIGHT_POINT, .color = { 1, 1, 1 }, .intensity = 20.0f,
                   .position = { 2, 3, 4 } };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void test_flat_and_gouraud_differ_on_a_sphere_but_cover_the_same_pixels(void **state)
{
    (void)state;
    rl_scene *s = sphere_scene();
    rl_camera cam = { .eye = { 0, 0, 4 }, .target = { 0, 0, 0 }, .width = 48, .height = 48 };
    const char *const flat[] = { "shading", "flat", NULL };
    const char *const gouraud[] = { "shading", "gouraud", NULL };
    rl_image *a = fx_render("raster", s, &cam, ALL_LAYERS, flat, NULL);
    rl_image *b = fx_render("raster", s, &cam, ALL_LAYERS, gouraud, NULL);
    size_t n = 48 * 48, covered = 0, differing = 0;
    assert_memory_equal(a->object_id, b->object_id, n * sizeof *a->object_id);
    for (size_t p = 0; p < n; ++p) {
        if (a->object_id[p] == RL_ID_NONE)
            continue;
        ++covered;
        differing += fabsf(a->color[p].x - b->color[p].x) > 1e-3f;
    }
    assert_true(covered > n / 4);
    assert_true(differing > covered / 4);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

static const rl_vec4 texel = { 0.5f, 1.0f, 0.25f, 1.0f };

/* Red (textured with a uniform texel) on the left half of the grid, green on
 * the right; as one object mixing materials, or split into one object each. */
static rl_scene *two_material_grid(bool split)
{
    enum { N = 8 };
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_vec4 texels[4] = { texel, texel, texel, texel };
    rl_texture *tex = NULL;
    uint32_t tex_id, red, green;
    assert_int_equal(rl_texture_create(2, 2, texels, &tex), RL_OK);
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = rl_v3(0.8f, 0.1f, 0.1f);
    m.diffuse_texture = tex_id;
    assert_int_equal(rl_scene_add_material(s, &m, &red), RL_OK);
    m = rl_material_default();
    m.diffuse = rl_v3(0.1f, 0.8f, 0.1f);
    m.specular = rl_v3s(0.3f);
    assert_int_equal(rl_scene_add_material(s, &m, &green), RL_OK);

    grid g = make_grid(N);
    uint32_t materials[2 * N * N], left[6 * N * N], right[6 * N * N], nl = 0, nr = 0;
    for (uint32_t t = 0; t < g.nt; ++t) {
        bool is_left = (t / 2) % N < N / 2;      /* cell column i < N/2: x < 0 */
        materials[t] = is_left ? red : green;
        uint32_t *dst = is_left ? &left[3 * nl++] : &right[3 * nr++];
        memcpy(dst, &g.idx[3 * t], 3 * sizeof *dst);
    }
    if (split) {
        add_grid_part(s, &g, left, nl, NULL, red);
        add_grid_part(s, &g, right, nr, NULL, green);
    } else {
        add_grid_part(s, &g, g.idx, g.nt, materials, red);
    }
    free_grid(&g);
    rl_light l = { .type = RL_LIGHT_POINT, .color = { 1, 1, 1 }, .intensity = light_intensity,
                   .position = { 0.3f, light_height, 0.2f } };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void test_an_object_mixing_materials_renders_like_its_parts_split_by_material(void **state)
{
    (void)state;
    rl_scene *mixed = two_material_grid(false), *split = two_material_grid(true);
    assert_int_equal(rl_scene_get_data(mixed)->num_objects, 1);
    assert_int_equal(rl_scene_get_data(split)->num_objects, 2);
    rl_camera cam = top_camera(3.0f);
    const char *const modes[] = { "flat", "gouraud", "textured" };
    for (int i = 0; i < 3; ++i) {
        const char *const opts[] = { "shading", modes[i], NULL };
        rl_image *a = fx_render("raster", mixed, &cam, ALL_LAYERS, opts, NULL);
        rl_image *b = fx_render("raster", split, &cam, ALL_LAYERS, opts, NULL);
        assert_memory_equal(a->color, b->color, 65 * 65 * sizeof *a->color);
        assert_memory_equal(a->depth, b->depth, 65 * 65 * sizeof *a->depth);
        /* Left half red, right half green. */
        rl_vec4 l = *rl_image_pixel(a, 16, 32), r = *rl_image_pixel(a, 48, 32);
        assert_true(l.x > 2.0f * l.y);
        assert_true(r.y > 2.0f * r.x);
        rl_image_release(a);
        rl_image_release(b);
    }
    rl_scene_release(mixed);
    rl_scene_release(split);
}

static void test_textured_shading_multiplies_gouraud_by_the_texel(void **state)
{
    (void)state;
    const bool splits[] = { true, false };      /* single-material objects, then mixed */
    for (int k = 0; k < 2; ++k) {
        rl_scene *s = two_material_grid(splits[k]);
        rl_camera cam = top_camera(3.0f);
        const char *const gouraud[] = { "shading", "gouraud", NULL };
        rl_image *a = fx_render("raster", s, &cam, ALL_LAYERS, gouraud, NULL);
        rl_image *b = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);      /* default: textured */
        int checked = 0;
        for (int y = 0; y < 65; ++y)
            for (int x = 0; x < 65; ++x) {
                size_t p = (size_t)y * 65 + x;
                if (a->object_id[p] == RL_ID_NONE)
                    continue;
                bool left = x < 30, right = x > 34;  /* away from the material seam */
                if (!left && !right)
                    continue;
                rl_vec4 want = left ? rl_v4(a->color[p].x * texel.x, a->color[p].y * texel.y,
                                            a->color[p].z * texel.z, a->color[p].w)
                                    : a->color[p];
                assert_float_equal(b->color[p].x, want.x, 1e-5f + 1e-4f * want.x);
                assert_float_equal(b->color[p].y, want.y, 1e-5f + 1e-4f * want.y);
                assert_float_equal(b->color[p].z, want.z, 1e-5f + 1e-4f * want.z);
                ++checked;
            }
        assert_true(checked > 1000);
        rl_image_release(a);
        rl_image_release(b);
        rl_scene_release(s);
    }
}

static void test_stats_count_triangles_pixels_and_samples(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    rl_render_stats st;
    memset(&st, 0xff, sizeof st);
    rl_image *img = fx_render("raster", s, &cam, ALL_LAYERS, NULL, &st);
    assert_true(st.triangles_rasterized > 0);
    assert_true(st.pixels_written >= 64 * 64 / 2);
    assert_int_equal(st.samples, 64 * 64);
    assert_true(st.time_ms >= 0.0);
    for (int t = 0; t < RL_RAY_TYPE_COUNT; ++t)
        assert_int_equal(st.rays[t], 0);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_renders_are_deterministic_and_independent_of_thread_count(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    const char *const one[] = { "threads", "1", NULL };
    const char *const two[] = { "threads", "2", NULL };
    rl_image *a = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    rl_image *b = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    rl_image *c = fx_render("raster", s, &cam, ALL_LAYERS, one, NULL);
    rl_image *d = fx_render("raster", s, &cam, ALL_LAYERS, two, NULL);
    fx_assert_images_identical(a, b);
    fx_assert_images_identical(c, d);
    fx_assert_images_identical(a, c);
    rl_image_release(a);
    rl_image_release(b);
    rl_image_release(c);
    rl_image_release(d);
    rl_scene_release(s);
}

static void test_colour_does_not_depend_on_the_layers_asked_for(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    const char *const bg[] = { "background", "0.25,0.5,0.75", NULL };
    rl_image *full = fx_render("raster", s, &cam, ALL_LAYERS, bg, NULL);
    rl_image *color = fx_render("raster", s, &cam, RL_LAYER_COLOR, bg, NULL);
    assert_memory_equal(full->color, color->color, 64 * 64 * sizeof *full->color);
    for (size_t p = 0; p < 64 * 64; ++p)
        if (full->object_id[p] == RL_ID_NONE)
            assert_float_equal(full->color[p].z, 0.75f, 0.0f);
    rl_image_release(full);
    rl_image_release(color);
    rl_scene_release(s);
}

/* The renderer keeps its rasterizer and drawer between frames
 * (rl_drawer_keep): every frame must equal a fresh renderer's across view,
 * shading, layer, thread and scene changes. A drawer kept across a
 * shading change keeps the wrong buffers (flat colours are per face); one
 * kept across scenes lights the other scene's vertices. */
static void test_a_kept_renderer_follows_view_shading_layers_threads_and_scene(void **state)
{
    (void)state;
    rl_camera a, b;
    rl_scene *s = fx_cornell(&a, 48), *mixed = two_material_grid(false);
    b = a;
    b.eye = rl_add(a.eye, rl_v3(0.3f, 0.2f, -0.4f));
    rl_camera top = top_camera(3.0f);
    top.width = top.height = 48;
    rl_renderer *r = fx_make("raster", NULL);
    rl_image *first = fx_render_with(r, s, &a, ALL_LAYERS, NULL);
    rl_image_release(first);
    struct {
        const rl_scene *scene;
        const rl_camera *cam;
        const char *shading, *threads;
        unsigned layers;
    } steps[] = { { s, &b, "textured", "0", ALL_LAYERS },   { s, &a, "flat", "0", ALL_LAYERS },
                  { s, &b, "gouraud", "0", RL_LAYER_COLOR }, { s, &a, "gouraud", "1", ALL_LAYERS },
                  { mixed, &top, "textured", "1", ALL_LAYERS }, { mixed, &top, "flat", "2", ALL_LAYERS },
                  { s, &a, "textured", "2", ALL_LAYERS } };
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; ++i) {
        assert_int_equal(rl_renderer_set(r, "shading", steps[i].shading), RL_OK);
        assert_int_equal(rl_renderer_set(r, "threads", steps[i].threads), RL_OK);
        rl_image *kept = fx_render_with(r, steps[i].scene, steps[i].cam, steps[i].layers, NULL);
        const char *const opts[] = { "shading", steps[i].shading, "threads", steps[i].threads, NULL };
        rl_image *fresh = fx_render("raster", steps[i].scene, steps[i].cam, steps[i].layers, opts, NULL);
        fx_assert_images_identical(kept, fresh);
        rl_image_release(kept);
        rl_image_release(fresh);
    }
    rl_renderer_release(r);
    rl_scene_release(mixed);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_ids_and_depth_agree_with_brute_force_ray_casting),
        cmocka_unit_test(test_a_kept_renderer_follows_view_shading_layers_threads_and_scene),
        cmocka_unit_test(test_quad_under_point_light_matches_analytic_phong_at_centre_vertex),
        cmocka_unit_test(test_directional_and_spot_lights_match_analytic_values),
        cmocka_unit_test(test_back_face_culling_hides_the_quad_from_below),
        cmocka_unit_test(test_flat_and_gouraud_differ_on_a_sphere_but_cover_the_same_pixels),
        cmocka_unit_test(test_an_object_mixing_materials_renders_like_its_parts_split_by_material),
        cmocka_unit_test(test_textured_shading_multiplies_gouraud_by_the_texel),
        cmocka_unit_test(test_stats_count_triangles_pixels_and_samples),
        cmocka_unit_test(test_renders_are_deterministic_and_independent_of_thread_count),
        cmocka_unit_test(test_colour_does_not_depend_on_the_layers_asked_for),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
