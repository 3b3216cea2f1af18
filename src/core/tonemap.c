/* tonemap.c: exposure and tone mapping of linear colour for 8-bit output
 * (rl_image.h). Operators: clamp; Reinhard et al. 2002, eq. 3 on the
 * luminance; the ACES filmic curve as fitted by Narkowicz 2015. In contrast
 * to Reinhard's paper there is no key scaling by the log-average luminance
 * (eq. 1-2): an image's mapping would then depend on its content, and a
 * progressive render's previews would brighten and darken as it converges.
 * The exposure (2^EV) is the fixed scale instead. */
#include "rl/rl_image.h"

#include <math.h>
#include <string.h>

#include "core/error.h"

/* Order = rl_tonemap_op. */
static const char *const op_names[RL_TONEMAP_COUNT] = { "none", "reinhard", "aces" };

/* Narkowicz 2015's fit, f(x) = x (a x + b) / (x (c x + d) + e). It rises
 * monotonically on x >= 0 (its derivative's numerator (ad - bc) x^2 +
 * 2ae x + be has only positive coefficients) and reaches 1 near x = 7.24;
 * from ACES_ONE on the answer is 1, which also keeps inf/inf out. */
#define ACES_A 2.51
#define ACES_B 0.03
#define ACES_C 2.43
#define ACES_D 0.59
#define ACES_E 0.14
#define ACES_ONE 8.0

/* Clamp to [0, 1] that lets NaN through (the PNG writer shows it black). */
static double clamp01(double v)
{
    return v > 1.0 ? 1.0 : (v < 0.0 ? 0.0 : v);
}

static double aces(double x)
{
    if (x >= ACES_ONE)
        return 1.0;
    if (x < 0.0)
        return 0.0;
    return clamp01(x * (ACES_A * x + ACES_B) / (x * (ACES_C * x + ACES_D) + ACES_E));
}

const char *rl_tonemap_name(rl_tonemap_op op)
{
    return (int)op >= 0 && (int)op < RL_TONEMAP_COUNT ? op_names[op] : NULL;
}

rl_status rl_tonemap_parse(const char *name, rl_tonemap_op *out)
{
    for (int k = 0; name && k < RL_TONEMAP_COUNT; ++k)
        if (strcmp(name, op_names[k]) == 0) {
            if (out)
                *out = (rl_tonemap_op)k;
            return RL_OK;
        }
    return rl_error(RL_ERR_INVALID_ARG, "unknown tone mapping '%s' (none, reinhard, aces)", name ? name : "(null)");
}

rl_vec3 rl_tonemap_rgb(rl_vec3 c, const rl_tonemap_desc *desc)
{
    rl_tonemap_desc d = desc ? *desc : (rl_tonemap_desc){ 0 };
    double scale = exp2(d.exposure_ev);
    double v[3] = { c.x * scale, c.y * scale, c.z * scale };
    switch (d.op) {
    case RL_TONEMAP_REINHARD: {
        /* Reinhard 2002, eq. 3: L_d = L / (1 + L); scaling the colour by
         * L_d / L = 1 / (1 + L) keeps its chromaticity. */
        double lum = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        if (isinf(lum)) {
            /* The limit L_d = 1, carried by the infinite channels. */
            for (int k = 0; k < 3; ++k)
                v[k] = isinf(v[k]) && v[k] > 0.0 ? 1.0 : 0.0;
        } else if (lum > 0.0) {
            for (int k = 0; k < 3; ++k)
                v[k] = v[k] / (1.0 + lum);
        }
        break;
    }
    case RL_TONEMAP_ACES:
        for (int k = 0; k < 3; ++k)
            v[k] = isnan(v[k]) ? v[k] : aces(v[k]);
        break;
    default:
        break;
    }
    return (rl_vec3){ (float)clamp01(v[0]), (float)clamp01(v[1]), (float)clamp01(v[2]) };
}

rl_status rl_image_tonemap(rl_image *img, const rl_tonemap_desc *desc)
{
    rl_tonemap_desc d = desc ? *desc : (rl_tonemap_desc){ 0 };
    if (!img || !img->color)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_tonemap: needs an image with a colour layer");
    if (!rl_tonemap_name(d.op))
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_tonemap: unknown operator %d", (int)d.op);
    if (!isfinite(d.exposure_ev))
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_tonemap: exposure must be finite");
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; ++i) {
        rl_vec4 *p = &img->color[i];
        rl_vec3 m = rl_tonemap_rgb((rl_vec3){ p->x, p->y, p->z }, &d);
        p->x = m.x;
        p->y = m.y;
        p->z = m.z;
    }
    return RL_OK;
}
