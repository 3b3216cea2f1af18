/* pathtrace_env.c: importance sampling of the scene's environment for
 * "pt" (issue 37; the skybox item of Schröder 2017, Sec. 13.4).
 *
 * The lat-long map (rl_environment, environment.c) is a piecewise-constant
 * function of (u, v) in [0,1)^2. Directions are drawn from a 2-D
 * piecewise-constant distribution over its texels, built as a marginal
 * cumulative distribution over the rows and one conditional distribution
 * per row (pbrt's Distribution2D, Pharr et al. 2016, Sec. 13.6.7). The
 * weight of a texel is the mean of its channels times sin(theta) at the
 * row's centre: the solid angle a texel covers shrinks towards the poles,
 * and a texel that is bright in one channel only must stay reachable. The
 * density in solid angle of a direction in texel (i, j) is
 *     p(w) = p(u, v) / (2 pi^2 sin(theta)),
 * p(u, v) = weight(i, j) W H / sum of weights, with theta the direction's
 * own polar angle. A constant environment (no map) uses ENV_CONST_ROWS
 * rows of one texel, nearly uniform in solid angle; env_sampling=uniform
 * keeps the map's grid but weighs by sin(theta) alone, for comparison. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/pathtrace_internal.h"

#define ENV_CONST_ROWS 64

void rl_pt_env_release(pt_env *e)
{
    free(e->marginal);
    free(e->conditional);
    free(e->weight);
    memset(e, 0, sizeof *e);
}

static float texel_weight(const rl_environment *env, bool uniform, int x, int y, int h)
{
    float sin_t = sinf(RL_PI * ((float)y + 0.5f) / (float)h);
    if (!env->map || uniform)
        return sin_t;
    const rl_texture *m = env->map;
    rl_vec4 t = m->texels[(size_t)y * (size_t)m->width + (size_t)x];
    rl_vec3 c = rl_mul(env->radiance, rl_v3(t.x, t.y, t.z));
    return (c.x + c.y + c.z) * (1.0f / 3.0f) * sin_t;
}

rl_status rl_pt_env_build(pt_env *e, const rl_environment *env, bool uniform)
{
    rl_pt_env_release(e);
    if (!env)
        return RL_OK;
    e->env = env;
    e->uniform = uniform;
    int w = env->map ? env->map->width : 1, h = env->map ? env->map->height : ENV_CONST_ROWS;
    e->width = w;
    e->height = h;
    e->weight = rl_calloc((size_t)w * (size_t)h, sizeof *e->weight);
    e->conditional = rl_calloc((size_t)(w + 1) * (size_t)h, sizeof *e->conditional);
    e->marginal = rl_calloc((size_t)h + 1, sizeof *e->marginal);
    if (!e->weight || !e->conditional || !e->marginal) {
        rl_pt_env_release(e);
        return RL_ERR_OUT_OF_MEMORY;
    }
    /* Running sums in double: a 8192-wide row of tiny weights would lose
     * its tail in float. */
    double total = 0.0;
    double *row_sum = rl_calloc((size_t)h, sizeof *row_sum);
    if (!row_sum) {
        rl_pt_env_release(e);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (int y = 0; y < h; ++y) {
        float *cdf = &e->conditional[(size_t)y * (size_t)(w + 1)];
        double run = 0.0;
        for (int x = 0; x < w; ++x) {
            float f = texel_weight(env, uniform, x, y, h);
            e->weight[(size_t)y * (size_t)w + (size_t)x] = f;
            run += f;
        }
        double acc = 0.0;
        for (int x = 0; x < w; ++x) {
            cdf[x] = run > 0.0 ? (float)(acc / run) : (float)x / (float)w;
            acc += e->weight[(size_t)y * (size_t)w + (size_t)x];
        }
        cdf[w] = 1.0f;
        row_sum[y] = run;
        total += run;
    }
    double acc = 0.0;
    for (int y = 0; y < h; ++y) {
        e->marginal[y] = total > 0.0 ? (float)(acc / total) : (float)y / (float)h;
        acc += row_sum[y];
    }
    e->marginal[h] = 1.0f;
    free(row_sum);
    /* A black map gives no light samples; the BSDF rays that escape see
     * it (black) with the full weight. */
    e->sum = total;
    e->sampled = total > 0.0 && isfinite(total);
    return RL_OK;
}

/* The cell of cdf (n + 1 entries) holding u, and u's position in it. */
static int pick(const float *cdf, int n, float u, float *frac)
{
    int lo = 0, hi = n;
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    float width = cdf[lo + 1] - cdf[lo];
    *frac = width > 0.0f ? rl_clampf((u - cdf[lo]) / width, 0.0f, 0.99999994f) : 0.5f;
    return lo;
}

float rl_pt_env_pdf(const pt_env *e, rl_vec3 dir)
{
    if (!e->sampled)
        return 0.0f;
    rl_vec2 uv = rl_environment_uv(e->env, dir);
    float sin_t = sqrtf(rl_maxf(0.0f, 1.0f - dir.y * dir.y));
    if (!(sin_t > 0.0f))
        return 0.0f;
    int x = (int)(uv.x * (float)e->width), y = (int)(uv.y * (float)e->height);
    x = x < 0 ? 0 : (x >= e->width ? e->width - 1 : x);
    y = y < 0 ? 0 : (y >= e->height ? e->height - 1 : y);
    double p_uv = (double)e->weight[(size_t)y * (size_t)e->width + (size_t)x] * e->width * e->height / e->sum;
    return (float)(p_uv / (2.0 * RL_PI * RL_PI * sin_t));
}

bool rl_pt_env_sample(const pt_env *e, float u1, float u2, rl_vec3 *dir, float *pdf)
{
    if (!e->sampled)
        return false;
    float fy, fx;
    int y = pick(e->marginal, e->height, u1, &fy);
    int x = pick(&e->conditional[(size_t)y * (size_t)(e->width + 1)], e->width, u2, &fx);
    float u = ((float)x + fx) / (float)e->width, v = ((float)y + fy) / (float)e->height;
    rl_vec3 d = rl_environment_direction(e->env, u, v);
    /* The density of the texel the direction looks up, so that radiance
     * and pdf always come from one texel even where rounding moves a
     * direction across a texel edge. */
    float p = rl_pt_env_pdf(e, d);
    if (!(p > 0.0f) || !isfinite(p))
        return false;
    *dir = d;
    *pdf = p;
    return true;
}
