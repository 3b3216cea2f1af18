/* light_eval.c: emission of the delta lights towards a point (see
 * light_eval.h). */
#include <math.h>

#include "scene/light_eval.h"

static float smoothstep(float e0, float e1, float x)
{
    float t = rl_clampf((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

bool rl_light_eval_delta(const rl_light *L, rl_vec3 p, rl_vec3 *E, rl_vec3 *l, float *dist)
{
    rl_vec3 power = rl_scale(L->color, L->intensity);
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        *l = rl_normalize(rl_neg(L->direction));
        *E = power;
        *dist = INFINITY;
        return rl_length2(*l) > 0.0f;
    }
    rl_vec3 to_light = rl_sub(L->position, p);
    float d2 = rl_length2(to_light);
    if (!(d2 > 0.0f))
        return false;
    *dist = sqrtf(d2);
    *l = rl_scale(to_light, 1.0f / *dist);
    float falloff = 1.0f / d2;
    if (L->type == RL_LIGHT_SPOT) {
        float cos_axis = rl_dot(rl_neg(*l), rl_normalize(L->direction));
        float cos_outer = cosf(rl_radians(L->spot_outer_deg));
        float cos_inner = cosf(rl_radians(L->spot_inner_deg));
        /* A hard cone when inner >= outer: smoothstep would divide by <= 0. */
        falloff *= cos_inner > cos_outer ? smoothstep(cos_outer, cos_inner, cos_axis)
                                         : (cos_axis >= cos_outer ? 1.0f : 0.0f);
    }
    *E = rl_scale(power, falloff);
    return falloff > 0.0f;
}
