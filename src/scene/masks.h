/* masks.h: what the drawers and queries ask of an object's materials.
 * Which materials have alpha masks (rl_material.alpha_cutoff, glTF
 * alphaMode MASK), for every query and pass that honours them: rl_accel and
 * the Line Space skip the holes' hits (rl_alpha_masked), the rasterizer
 * drops their fragments (rl_raster_batch.mask_texture). And whether an
 * object has one material, which both drawers (software and GL) light per
 * vertex, or mixes them, which they draw by triangle corners. */
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

/* The material all of object o's triangles share, or RL_NONE when they mix
 * materials (or o has none). */
static inline uint32_t rl_object_material(const rl_scene_data *d, uint32_t o)
{
    const rl_object *obj = &d->objects[o];
    uint32_t m = obj->num_triangles ? d->triangle_material[obj->first_triangle] : RL_NONE;
    for (uint32_t t = 1; t < obj->num_triangles && m != RL_NONE; ++t)
        if (d->triangle_material[obj->first_triangle + t] != m)
            m = RL_NONE;
    return m;
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
