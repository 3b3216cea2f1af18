/* gl_fixtures.h: what the GL tests share: whether this machine can make a
 * GL 4.5 context (found once per test program by find_gl, the group
 * setup) and NEED_GL(), which skips a case where it cannot; the per-channel
 * comparison of a GPU image with a CPU reference (gl-pt's tests) and the
 * query quad the drawer tests hold before the camera. The helpers are
 * static inline so that each test uses any subset without unused-function
 * warnings. Include after <cmocka.h>. */
#ifndef RL_TESTS_GL_FIXTURES_H
#define RL_TESTS_GL_FIXTURES_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "rl/rl_camera.h"
#include "rl/rl_gl.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"

static bool have_gl;

static int find_gl(void **state)
{
    (void)state;
    char why[256];
    have_gl = rl_gl_available(NULL, why, sizeof why);
    if (!have_gl)
        print_message("no OpenGL 4.5 context (%s): the GL cases skip\n", why);
    return 0;
}

#define NEED_GL()                                                                                              \
    do {                                                                                                       \
        if (!have_gl)                                                                                          \
            skip();                                                                                            \
    } while (0)

/* Per channel: the RMSE of a - b and the difference of the image means. */
static inline void fx_difference(const rl_image *a, const rl_image *b, double rmse[3], double mean_diff[3])
{
    const size_t n = (size_t)a->width * (size_t)a->height;
    for (int c = 0; c < 3; ++c) {
        double sq = 0.0, sum = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const float *pa = &a->color[i].x, *pb = &b->color[i].x;
            double d = (double)pa[c] - pb[c];
            sq += d * d;
            sum += d;
        }
        rmse[c] = sqrt(sq / (double)n);
        mean_diff[c] = sum / (double)n;
    }
}

/* The RMSE over the three channels of fx_difference's per-channel RMSEs. */
static inline double fx_rmse_all(const double rmse[3])
{
    return sqrt((rmse[0] * rmse[0] + rmse[1] * rmse[1] + rmse[2] * rmse[2]) / 3.0);
}

/* The means agree within 3 sigma of the mean of n independent pixel
 * differences, sigma^2 = their variance / n, estimated by RMSE^2 (pixels
 * have independent generator states or scrambles in both tracers). */
static inline void fx_assert_means_agree(const char *what, const rl_image *img, const rl_image *ref)
{
    double rmse[3], md[3];
    fx_difference(img, ref, rmse, md);
    const double n = (double)img->width * img->height;
    for (int c = 0; c < 3; ++c) {
        double sigma = rmse[c] / sqrt(n);
        print_message("%s: channel %d mean difference %+.5f, sigma %.5f (%.2f sigma)\n", what, c, md[c], sigma,
                      sigma > 0.0 ? fabs(md[c]) / sigma : 0.0);
        assert_true(fabs(md[c]) <= 3.0 * sigma + 1e-6);
    }
}

/* A quad facing the camera at distance dist along its view, half side
 * half, as the two triangles of a query batch. */
static inline void fx_view_quad(const rl_camera *cam, float dist, float half, rl_vec3 pos[4])
{
    rl_vec3 fwd = rl_normalize(rl_sub(cam->target, cam->eye));
    rl_vec3 right = rl_normalize(rl_cross(fwd, cam->up));
    rl_vec3 up = rl_cross(right, fwd);
    rl_vec3 c = rl_add(cam->eye, rl_scale(fwd, dist));
    for (int k = 0; k < 4; ++k)
        pos[k] = rl_add(c, rl_add(rl_scale(right, k == 1 || k == 2 ? half : -half),
                                  rl_scale(up, k >= 2 ? half : -half)));
}

#endif
