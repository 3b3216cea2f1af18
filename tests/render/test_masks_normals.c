/* Alpha masks and normal maps in the rasterizing renderers: every
 * renderer must see the holes of a masked leaf where the ray tracers do
 * (whitted is the reference: rl_accel skips masked hits), and raster must
 * shade a normal-mapped surface with the bent normal as whitted does. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl_accel.h"
#include "rl/rl_gl.h"
#include "rl/rl_linespace.h"
#include "rl/rl_raster.h"
#include "rl/rl_shadowmap.h"
#include "rl/rl_render.h"

#define SIZE 48

static void add_quad(rl_scene *s, const char *name, float half, float z, uint32_t mat)
{
    const rl_vec3 pos[4] = { { -half, -half, z }, { half, -half, z }, { half, half, z }, { -half, half, z } };
    const rl_vec2 uv[4] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    uint32_t mesh, node;
    rl_mesh_desc md = { .name = name, .num_vertices = 4, .positions = pos, .uvs = uv,
                        .num_triangles = 2, .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, name, NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

/* Object 0: a quad (-1..1)^2 at z = 0 whose texture is opaque only where
 * u > 1/2 (alpha_cutoff 0.5, or none when cutoff is 0); object 1: a
 * larger quad behind it at z = -1. Seen head-on from z = 4. */
static rl_scene *leaf_scene(float cutoff, rl_camera *cam)
{
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
    m.alpha_cutoff = cutoff;
    assert_int_equal(rl_scene_add_material(s, &m, &leaf), RL_OK);
    m = rl_material_default();
    m.diffuse = rl_v3(0.8f, 0.2f, 0.2f);
    assert_int_equal(rl_scene_add_material(s, &m, &back), RL_OK);
    add_quad(s, "leaf", 1.0f, 0.0f, leaf);
    add_quad(s, "back", 2.5f, -1.0f, back);
    rl_light L = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = 20.0f,
                   .position = rl_v3(0.5f, 0.5f, 4.0f) };
    assert_int_equal(rl_scene_add_light(s, &L), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = rl_v3(0, 0, 4), .target = rl_v3(0, 0, 0), .fov_deg = 45.0f,
                        .width = SIZE, .height = SIZE };
    return s;
}

/* Pixels whose object IDs differ. */
static int id_mismatches(const rl_image *a, const rl_image *b)
{
    int n = 0;
    for (int i = 0; i < SIZE * SIZE; ++i)
        n += a->object_id[i] != b->object_id[i];
    return n;
}

static int count_object(const rl_image *img, uint32_t object)
{
    int n = 0;
    for (int i = 0; i < SIZE * SIZE; ++i)
        n += img->object_id[i] == object;
    return n;
}

static void test_rasterizers_see_the_holes_the_ray_tracer_sees(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = leaf_scene(0.5f, &cam);
    rl_image *ref = fx_render("whitted", s, &cam, FX_ALL_LAYERS, NULL, NULL);
    /* The leaf covers about (2 / 3.3)^2 of the image, half of it a hole. */
    int leaf = count_object(ref, 0);
    assert_true(leaf > SIZE * SIZE / 8 && leaf < SIZE * SIZE / 4);

    static const char *const raster_flat[] = { "shading", "flat", NULL };
    static const char *const raster_gouraud[] = { "shading", "gouraud", NULL };
    static const char *const pt_raster[] = { "primary", "raster", "spp", "1", NULL };
    static const char *const pt_trace[] = { "spp", "1", NULL };
    const struct { const char *name; const char *const *opts; } cases[] = {
        { "raster", NULL }, { "raster", raster_flat }, { "raster", raster_gouraud },
        { "pt", pt_raster }, { "pt", pt_trace }, { "vt", NULL }, { "chcpp", NULL }, { "svs", NULL },
    };
    /* The GL drawer drops the same fragments, where a GL context exists. */
    const bool gl = rl_gl_available(NULL, NULL, 0);
    const char *const *gl_opts[] = { NULL, raster_flat, raster_gouraud };
    const size_t n = sizeof cases / sizeof cases[0];
    for (size_t i = 0; i < n + (gl ? 3 : 0); ++i) {
        const char *name = i < n ? cases[i].name : "gl-raster";
        const char *const *opts = i < n ? cases[i].opts : gl_opts[i - n];
        rl_image *img = fx_render(name, s, &cam, FX_ALL_LAYERS, opts, NULL);
        int diff = id_mismatches(img, ref);
        if (diff > SIZE)   /* the mask's edge: one column at most */
            print_error("%s (case %zu): %d pixels differ from whitted\n", name, i, diff);
        assert_true(diff <= SIZE);
        rl_image_release(img);
    }
    rl_image_release(ref);
    rl_scene_release(s);

    /* Without the cutoff the same texture hides the whole back quad's
     * middle: the comparison above can fail. */
    s = leaf_scene(0.0f, &cam);
    rl_image *whole = fx_render("raster", s, &cam, FX_ALL_LAYERS, NULL, NULL);
    assert_true(count_object(whole, 0) > leaf + leaf / 2);
    rl_image_release(whole);
    rl_scene_release(s);
}

/* The rasterizer alone: a masked batch without uvs is refused, and an
 * ID-only pass (no colour) drops the masked fragments too. */
static void test_raster_masks_in_id_passes(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = leaf_scene(0.5f, &cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_raster *ras = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
    assert_int_equal(rl_image_create(SIZE, SIZE, FX_ALL_LAYERS, &img), RL_OK);
    rl_image_clear(img);
    assert_int_equal(rl_raster_set_camera(ras, img, &cam, d->bounds), RL_OK);
    const uint32_t mask_texture[2] = { 0, 0 };
    const float cutoff[2] = { 0.5f, 0.5f };
    rl_raster_batch b = { .num_vertices = 4, .positions = d->positions, .num_triangles = 2,
                          .indices = d->indices, .flags = RL_RASTER_NO_COLOR,
                          .mask_texture = mask_texture, .mask_cutoff = cutoff,
                          .textures = d->textures };
    assert_int_equal(rl_raster_draw(ras, &b, NULL), RL_ERR_INVALID_ARG);
    b.uvs = d->uvs;
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw(ras, &b, &c), RL_OK);
    /* Only the right half of the leaf (x > 0) was written. */
    int left = 0, right = 0;
    for (int y = 0; y < SIZE; ++y)
        for (int x = 0; x < SIZE; ++x)
            if (img->object_id[y * SIZE + x] == 0)
                *(x < SIZE / 2 ? &left : &right) += 1;
    assert_int_equal(left, 0);
    assert_true(right > SIZE * SIZE / 16);
    assert_int_equal(c.pixels_written, (uint64_t)right);
    rl_image_release(img);
    rl_raster_release(ras);
    rl_scene_release(s);
}

static rl_vec3 grey(void *user, const rl_ls_surface *s, rl_vec3 dir)
{
    (void)user, (void)s, (void)dir;
    return rl_v3s(0.5f);
}

/* The Line Space's queries: candidates exactly as rl_accel, PNMT and
 * pre-illuminated records with the shafts whose midpoint rays meet only
 * holes recorded as empty. Vertical rays through the middle of the hole
 * (x = -0.5) and of the opaque half (x = 0.5), ending before the back quad. */
static void test_line_space_skips_holes(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = leaf_scene(0.5f, &cam);
    rl_accel *grid = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_GRID }, &grid), RL_OK);
    assert_int_equal(rl_accel_commit(grid), RL_OK);
    rl_linespace *ls = NULL;
    rl_linespace_desc desc = { .n = 4, .dynamic = true,
                               .payloads = RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM };
    assert_int_equal(rl_linespace_create(grid, &desc, &ls), RL_OK);
    assert_int_equal(rl_linespace_set_shader(ls, grey, NULL), RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_OK);
    for (int side = 0; side < 2; ++side) {
        const bool opaque = side == 1;
        rl_ray r = { rl_v3(opaque ? 0.5f : -0.5f, 0.1f, 5.0f), 0.0f, rl_v3(0, 0, -1), 5.5f };
        rl_ray q = r;
        rl_hit h;
        assert_int_equal(rl_linespace_intersect(ls, &q, &h), opaque);
        assert_int_equal(rl_linespace_occluded(ls, &r), opaque);
        assert_int_equal(rl_linespace_pnmt_occluded(ls, &r), opaque);
        assert_int_equal(rl_linespace_preillum_occluded(ls, &r), opaque);
        rl_ls_surface surf;
        assert_int_equal(rl_linespace_pnmt_intersect(ls, &r, &surf), opaque);
    }
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* pt's shadow maps: the light passes the leaf's hole and not its opaque
 * half, seen from two points on the back quad. */
static void test_shadow_maps_pass_holes(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = leaf_scene(0.5f, &cam);
    rl_shadowmap *sm = NULL;
    assert_int_equal(rl_shadowmap_create(s, &(rl_shadowmap_desc){ .size = 256 }, &sm), RL_OK);
    const rl_vec3 n = rl_v3(0, 0, 1);
    /* Light (0.5, 0.5, 4): these meet the leaf at x = -0.7 and x = 0.9. */
    assert_true(rl_shadowmap_visible(sm, 0, rl_v3(-1.0f, 0.5f, -1.0f), n, 0.5f, 0.5f));
    assert_false(rl_shadowmap_visible(sm, 0, rl_v3(1.0f, 0.5f, -1.0f), n, 0.5f, 0.5f));
    rl_shadowmap_release(sm);
    rl_scene_release(s);
}

/* A quad facing +z, optionally with a normal map that tilts every normal
 * by 45 degrees towards its tangent +x (+u), lit by a point light far off
 * to +x: the map makes it several times brighter. */
static rl_scene *bent_scene(bool mapped, rl_camera *cam)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    const float c = 0.5f + 0.5f * sqrtf(0.5f);
    const rl_vec4 raw = { c, 0.5f, c, 1.0f };   /* (1, 0, 1) / sqrt 2 in the tangent frame */
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(1, 1, &raw, &tex), RL_OK);
    uint32_t tex_id, mat;
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    m.normal_texture = mapped ? tex_id : RL_NONE;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    add_quad(s, "quad", 1.0f, 0.0f, mat);
    rl_light L = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = 30.0f,
                   .position = rl_v3(5.0f, 0.0f, 1.0f) };
    assert_int_equal(rl_scene_add_light(s, &L), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = rl_v3(0, 0, 4), .target = rl_v3(0, 0, 0), .fov_deg = 30.0f,
                        .width = SIZE, .height = SIZE };
    return s;
}

/* Mean red of the pixels that show object 0. */
static double mean_red(const rl_image *img)
{
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < SIZE * SIZE; ++i)
        if (img->object_id[i] == 0) {
            sum += img->color[i].x;
            ++n;
        }
    assert_true(n > SIZE * SIZE / 4);
    return sum / n;
}

/* raster shades normal-mapped pixels per pixel with the bent normal, as
 * whitted does (both Phong with the same lights; whitted's shadows do not
 * fall here). Without the map the quad is several times darker, so the
 * comparison fails if the map is ignored; Gouraud's interpolation over two
 * triangles is what keeps the plain quads apart by a few percent. */
static void test_raster_shades_normal_maps_per_pixel(void **state)
{
    (void)state;
    static const char *const gouraud[] = { "shading", "gouraud", NULL };
    const char *const *raster_opts[] = { NULL, gouraud };
    /* gl-raster bends the normals in its fragment stage: the same test,
     * where a GL context exists. */
    const int backends = rl_gl_available(NULL, NULL, 0) ? 2 : 1;
    const char *const names[] = { "raster", "gl-raster" };
    double ref[2], ras[2][2][2];
    for (int mapped = 0; mapped < 2; ++mapped) {
        rl_camera cam;
        rl_scene *s = bent_scene(mapped, &cam);
        rl_image *img = fx_render("whitted", s, &cam, FX_ALL_LAYERS, NULL, NULL);
        ref[mapped] = mean_red(img);
        rl_image_release(img);
        for (int b = 0; b < backends; ++b)
            for (int k = 0; k < 2; ++k) {
                img = fx_render(names[b], s, &cam, FX_ALL_LAYERS, raster_opts[k], NULL);
                ras[b][k][mapped] = mean_red(img);
                rl_image_release(img);
            }
        rl_scene_release(s);
    }
    assert_true(ref[1] > 2.0 * ref[0]);
    for (int b = 0; b < backends; ++b) {
        print_message("mean red, plain and mapped: whitted %.4f %.4f, %s %.4f %.4f, gouraud %.4f %.4f\n", ref[0],
                      ref[1], names[b], ras[b][0][0], ras[b][0][1], ras[b][1][0], ras[b][1][1]);
        for (int k = 0; k < 2; ++k) {
            assert_true(fabs(ras[b][k][1] / ref[1] - 1.0) < 0.02);
            assert_true(fabs(ras[b][k][0] / ref[0] - 1.0) < 0.15);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rasterizers_see_the_holes_the_ray_tracer_sees),
        cmocka_unit_test(test_raster_masks_in_id_passes),
        cmocka_unit_test(test_line_space_skips_holes),
        cmocka_unit_test(test_shadow_maps_pass_holes),
        cmocka_unit_test(test_raster_shades_normal_maps_per_pixel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
