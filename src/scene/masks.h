/* masks.h: which materials have alpha masks (rl_material.alpha_cutoff, glTF
 * alphaMode MASK), for every query and pass that honours them: rl_accel and
 * the Line Space skip the holes' hits (rl_alpha_masked), the rasterizer
 * drops their fragments (rl_raster_batch.mask_texture). */
#ifndef RL_SCENE_MASKS_H
#define RL_SCENE_MASKS_H

#include "rl/rl_scene.h"

/* Material m's mask texture (the diffuse texture, whose alpha is tested), or
 * RL_NONE when m has no mask. */
static inline uint32_t rl_material_mask(const rl_scene_data *d, uint32_t m)
{
    const rl_material *mat = &d->materials[m];
    return mat->alpha_cutoff > 0.0f && mat->diffuse_texture < d->num_textures && d->textures[mat->diffuse_texture]
               ? mat->diffuse_texture
               : RL_NONE;
}

/* Whether some material has a mask: only then do queries pay for the test. */
static inline bool rl_data_has_masks(const rl_scene_data *d)
{
    for (uint32_t m = 0; m < d->num_materials; ++m)
        if (rl_material_mask(d, m) != RL_NONE)
            return true;
    return false;
}

#endif
