/* The surfel atlas on GL (issue 35, part 6; Jähn 2015, Table 6.1): the 8
 * views of rl_surfels_build drawn by a GL drawer give the candidates of the
 * software atlas, up to the pixels that GL's rasterization rules give to
 * another triangle or to the background (measured and bounded here); a
 * software drawer as the atlas drawer gives the software atlas' surfels
 * byte for byte (the drawer path itself changes nothing); a drawer made
 * with another desc is refused; the surfels renderer with atlas=gl draws
 * the image of atlas=software within SSIM 0.99 and says why where GL is
 * missing. Runs on llvmpipe; the GL cases skip without a GL 4.5 context. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/render_fixtures.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_metrics.h"
#include "rl/rl_surfels.h"

#include "gl_fixtures.h"

/* Every candidate as a surfel: a count above the candidates takes them
 * all, in random order (quick to draw). */
static rl_surfel_desc all_candidates(uint32_t res, rl_drawer *dr)
{
    return (rl_surfel_desc){ .resolution = res, .count = 1u << 24, .sampling = RL_SURFEL_RANDOM, .seed = 7,
                             .atlas_drawer = dr };
}

static int by_bytes(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(rl_surfel));
}

/* Sorted copies of the candidates without their sizes (those depend on
 * the neighbours, i.e. on every other candidate). */
static rl_surfel *sorted(const rl_surfel_set *set)
{
    rl_surfel *s = malloc(((size_t)set->count + 1) * sizeof *s);
    assert_non_null(s);
    memcpy(s, set->surfels, (size_t)set->count * sizeof *s);
    for (uint32_t i = 0; i < set->count; ++i)
        s[i].size = 0;
    qsort(s, set->count, sizeof *s, by_bytes);
    return s;
}

/* How many surfels of a have a byte-equal one in b (a multiset match). */
static uint32_t common(const rl_surfel_set *a, const rl_surfel_set *b)
{
    rl_surfel *x = sorted(a), *y = sorted(b);
    uint32_t i = 0, j = 0, n = 0;
    while (i < a->count && j < b->count) {
        int c = by_bytes(&x[i], &y[j]);
        n += c == 0;
        i += c <= 0;
        j += c >= 0;
    }
    free(x);
    free(y);
    return n;
}

/* Candidates at the same place: a pixel on the diagonal of a quad that
 * GL gives to the quad's other triangle makes the same point of the same
 * plane, up to the rounding of the other triangle's arithmetic, and the
 * colour of a texel looked up a rounding away. The same surfel here: the
 * positions within tol, normal and colour bytes within 1. */
typedef struct cell_entry {
    int64_t key[3];
    uint32_t index;
} cell_entry;

static int by_cell(const void *a, const void *b)
{
    const cell_entry *x = a, *y = b;
    for (int k = 0; k < 3; ++k)
        if (x->key[k] != y->key[k])
            return x->key[k] < y->key[k] ? -1 : 1;
    return 0;
}

static bool close_bytes(const int8_t *a, const int8_t *b, int n)
{
    for (int k = 0; k < n; ++k)
        if (abs((int)a[k] - (int)b[k]) > 1)
            return false;
    return true;
}

static bool same_surfel(const rl_surfel *a, const rl_surfel *b, float tol, bool place_only)
{
    for (int k = 0; k < 3; ++k) {
        if (fabsf(a->position[k] - b->position[k]) > tol)
            return false;
        if (!place_only && abs((int)a->color[k] - (int)b->color[k]) > 1)
            return false;
    }
    return place_only || close_bytes(a->normal, b->normal, 3);
}

/* How many surfels of a have one of b at the same place (each of b used
 * once): b hashed into cells of side tol, a looked up in the 27 around.
 * place_only: the position alone. */
static uint32_t common_within(const rl_surfel_set *a, const rl_surfel_set *b, float tol, bool place_only)
{
    cell_entry *cells = malloc(((size_t)b->count + 1) * sizeof *cells);
    uint8_t *used = calloc((size_t)b->count + 1, 1);
    assert_non_null(cells);
    assert_non_null(used);
    for (uint32_t i = 0; i < b->count; ++i) {
        for (int k = 0; k < 3; ++k)
            cells[i].key[k] = (int64_t)floorf(b->surfels[i].position[k] / tol);
        cells[i].index = i;
    }
    qsort(cells, b->count, sizeof *cells, by_cell);
    uint32_t n = 0;
    for (uint32_t i = 0; i < a->count; ++i) {
        const rl_surfel *x = &a->surfels[i];
        bool found = false;
        for (int d = 0; d < 27 && !found; ++d) {
            cell_entry probe = { .index = 0 };
            for (int k = 0; k < 3; ++k)
                probe.key[k] = (int64_t)floorf(x->position[k] / tol) + (d / (k == 0 ? 1 : k == 1 ? 3 : 9)) % 3 - 1;
            /* The first entry of the probe's cell. */
            size_t lo = 0, hi = b->count;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (by_cell(&cells[mid], &probe) < 0)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            for (size_t j = lo; j < b->count && by_cell(&cells[j], &probe) == 0 && !found; ++j)
                if (!used[cells[j].index] && same_surfel(x, &b->surfels[cells[j].index], tol, place_only))
                    found = (used[cells[j].index] = 1) != 0;
        }
        n += found;
    }
    free(cells);
    free(used);
    return n;
}

static void test_software_drawer_gives_the_software_atlas(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    const rl_drawer_desc dd = RL_SURFEL_ATLAS_DRAWER_DESC;
    rl_drawer *dr = NULL;
    assert_int_equal(rl_drawer_create(s, &dd, &dr), RL_OK);
    const uint32_t objects[] = { 0, 3, 5, 8 };
    for (int sel = 0; sel < 2; ++sel) {
        rl_surfel_desc sw = { .resolution = 64, .count = 800 }, via = sw;
        via.atlas_drawer = dr;
        rl_surfel_set a, b;
        assert_int_equal(rl_surfels_build(s, sel ? objects : NULL, sel ? 4 : 0, &sw, &a), RL_OK);
        assert_int_equal(rl_surfels_build(s, sel ? objects : NULL, sel ? 4 : 0, &via, &b), RL_OK);
        assert_true(a.count > 0);
        assert_int_equal(a.count, b.count);
        assert_int_equal(a.candidates, b.candidates);
        assert_memory_equal(a.surfels, b.surfels, (size_t)a.count * sizeof *a.surfels);
        rl_surfel_set_free(&a);
        rl_surfel_set_free(&b);
    }
    rl_drawer_release(dr);
    rl_scene_release(s);
}

static void test_atlas_drawer_of_another_desc_is_refused(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_drawer *dr = NULL;
    assert_int_equal(rl_drawer_create(s, NULL, &dr), RL_OK);   /* lit: not an atlas drawer */
    rl_surfel_desc d = { .resolution = 32, .count = 10, .atlas_drawer = dr };
    rl_surfel_set set;
    assert_int_equal(rl_surfels_build(s, NULL, 0, &d, &set), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "atlas drawer"));
    assert_null(set.surfels);
    rl_drawer_release(dr);
    rl_scene_release(s);
}

/* The bounds of the comparison: at least 99 % of the software candidates
 * have a GL one at the same place (10^-5 of the diagonal), and the counts
 * differ by at most 0.5 %; where no two objects share a plane, 99 % are
 * the same surfel (colour and normal within 1 of 255 / 127 too). Where
 * they do (coplanar: the box city's buildings stand on its ground, and
 * the views from the four lower corners see the ground's underside and
 * the buildings' bottoms in one plane), the depth ties go either way
 * (docs/gl.md): the same points, another object's colour. The byte-equal
 * share is printed beside. */
static void check_candidates(const rl_scene *s, rl_drawer *gl, uint32_t res, const char *name, bool coplanar)
{
    const float tol = 1e-5f * rl_length(rl_aabb_extent(rl_scene_get_data(s)->bounds));
    rl_surfel_desc sw = all_candidates(res, NULL), gd = all_candidates(res, gl);
    rl_surfel_set a, b;
    assert_int_equal(rl_surfels_build(s, NULL, 0, &sw, &a), RL_OK);
    assert_int_equal(rl_surfels_build(s, NULL, 0, &gd, &b), RL_OK);
    assert_int_equal(a.count, a.candidates);   /* every candidate taken */
    assert_int_equal(b.count, b.candidates);
    uint32_t equal = common(&a, &b), same = common_within(&a, &b, tol, false);
    uint32_t place = common_within(&a, &b, tol, true);
    double diff = fabs((double)b.count - a.count) / a.count;
    print_message("%s at %u^2: candidates software %u, GL %u; at the same place %.3f %%, the same %.3f %%, "
                  "byte-equal %.3f %%; coverage %.4f / %.4f\n", name, res, a.count, b.count,
                  100.0 * place / a.count, 100.0 * same / a.count, 100.0 * equal / a.count,
                  (double)a.coverage, (double)b.coverage);
    assert_true(a.count > 1000);
    assert_true((double)place / a.count >= 0.99);
    if (!coplanar)
        assert_true((double)same / a.count >= 0.99);
    assert_true(diff <= 0.005);
    rl_surfel_set_free(&a);
    rl_surfel_set_free(&b);
}

static void test_gl_atlas_gives_the_software_candidates(void **state)
{
    (void)state;
    NEED_GL();
    /* cornell (quads, shared edges), table (textured colours, many small
     * triangles), the box city (many objects). */
    static const char *const names[] = { "cornell", "table", "city" };
    for (int i = 0; i < 3; ++i) {
        rl_scene *s = NULL;
        assert_int_equal(rl_scene_create_builtin(names[i], i == 2 ? "blocks=2" : NULL, &s), RL_OK);
        const rl_drawer_desc dd = RL_SURFEL_ATLAS_DRAWER_DESC;
        rl_drawer *gl = NULL;
        assert_int_equal(rl_gl_drawer_create(s, &dd, NULL, &gl), RL_OK);
        check_candidates(s, gl, 96, names[i], i == 2);
        check_candidates(s, gl, 61, names[i], i == 2);   /* odd: pixel centres off the view's axes */
        rl_drawer_release(gl);
        rl_scene_release(s);
    }
}

/* The sequences themselves part after the first differing candidate; the
 * renderer's images do not: far away (points only) and in between. */
static void test_surfels_renderer_with_gl_atlas(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = fx_box_city();
    const float dists[] = { 260.0f, 150.0f };
    for (int i = 0; i < 2; ++i) {
        float dist = dists[i];
        rl_camera cam = { .eye = rl_v3(60.0f - dist, 0.8f * dist, 60.0f - dist), .target = rl_v3(60, 5, 60),
                          .fov_deg = 40.0f, .width = 160, .height = 120 };
        rl_render_stats a, b;
#define SMALL_SURFELS "count", "3000", "resolution", "128", "min_triangles", "2000", "min_size", "400", \
                      "max_size", "800"
        rl_image *sw = fx_render("surfels", s, &cam, RL_LAYER_COLOR,
                                 (const char *const[]){ SMALL_SURFELS, NULL }, &a);
        rl_image *gl = fx_render("surfels", s, &cam, RL_LAYER_COLOR,
                                 (const char *const[]){ SMALL_SURFELS, "atlas", "gl", NULL }, &b);
        rl_image_metrics m;
        assert_int_equal(rl_image_compare(gl, sw, NULL, &m), RL_OK);
        print_message("surfels, atlas gl against software at distance %.0f: SSIM %.5f, %llu and %llu points\n",
                      (double)dist, m.ssim, (unsigned long long)a.points_drawn,
                      (unsigned long long)b.points_drawn);
        assert_true(a.points_drawn > 0);
        assert_true(m.ssim >= 0.99);
        rl_image_release(sw);
        rl_image_release(gl);
    }
    rl_scene_release(s);
}

static void test_surfels_atlas_gl_unavailable_says_why(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("surfels", (const char *const[]){ "atlas", "gl", "device", "99", NULL });
    char why[512];
    assert_false(rl_renderer_available(r, why, sizeof why));
    print_message("atlas=gl on device 99: %s\n", why);
    assert_non_null(strstr(why, "atlas=gl"));
    rl_renderer_release(r);
    /* The default atlas needs no GL. */
    r = fx_make("surfels", (const char *const[]){ "device", "99", NULL });
    assert_true(rl_renderer_available(r, why, sizeof why));
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_software_drawer_gives_the_software_atlas),
        cmocka_unit_test(test_atlas_drawer_of_another_desc_is_refused),
        cmocka_unit_test(test_gl_atlas_gives_the_software_candidates),
        cmocka_unit_test(test_surfels_renderer_with_gl_atlas),
        cmocka_unit_test(test_surfels_atlas_gl_unavailable_says_why),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
