/* rl_shadowmap.h: shadow maps (Williams 1978) as the path tracer's
 * alternative shadow test (Schröder 2017, Sec. 8.6, Diagram 3).
 *
 * Each light gets a cube of six square depth maps rendered with renderlab's
 * rasterizer from the light's position (a quad light: its centre, so its
 * shadows are those of a point light, as in the thesis' Fig. 20). A lookup
 * transforms the point into the light's face, jitters the texel (the
 * thesis' percentage-closer offset) and compares depths with a slope-scaled
 * bias. Directional lights are not supported (RL_ERR_UNSUPPORTED at create
 * for a scene that has one; lights of other types are all mapped). */
#ifndef RL_SHADOWMAP_H
#define RL_SHADOWMAP_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_shadowmap rl_shadowmap;

typedef struct rl_shadowmap_desc {        /* zero = default */
    int size;                 /* texels per face side; 0 -> 1024 (the thesis) */
    float bias;               /* constant depth bias, relative to the distance; 0 -> 1e-3 */
    float slope_bias;         /* slope-scaled bias factor; 0 -> 2 texels */
    float pcf_radius;         /* jitter radius in texels; 0 -> 1 */
} rl_shadowmap_desc;

RL_API rl_status rl_shadowmap_create(const rl_scene *scene, const rl_shadowmap_desc *desc,
                                     rl_shadowmap **out);
RL_API void rl_shadowmap_release(rl_shadowmap *sm);      /* NULL is a no-op */
/* Whether point p (geometric normal n) sees light `light`'s sample point;
 * (ju, jv) in [0,1)^2 jitter the lookup by up to pcf_radius texels. False
 * when n faces away from the light and for a light index out of range.
 * Thread-safe. */
RL_API bool rl_shadowmap_visible(const rl_shadowmap *sm, uint32_t light, rl_vec3 p, rl_vec3 n,
                                 float ju, float jv);
RL_API double rl_shadowmap_build_ms(const rl_shadowmap *sm);
RL_API size_t rl_shadowmap_memory(const rl_shadowmap *sm);

#ifdef __cplusplus
}
#endif
#endif
