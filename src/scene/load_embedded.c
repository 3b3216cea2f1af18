/* load_embedded.c: textures stored inside model files (glTF data URIs and
 * GLB buffers, FBX, ...). Assimp hands them over either still compressed
 * (mHeight == 0: mWidth bytes of PNG/JPEG/...), which stb_image decodes, or
 * as raw texels (aiTexel is BGRA, 8 bits each). Colour is sRGB-encoded in
 * both cases, as glTF specifies for base colour textures, and converted to
 * linear like rl_texture_load does; alpha stays linear. */
#include <assimp/texture.h>
#include <stdlib.h>

#include <stb/stb_image.h>

#include "core/error.h"
#include "core/image_internal.h"
#include "scene/load_internal.h"

static rl_vec4 texel(unsigned r, unsigned g, unsigned b, unsigned a)
{
    const float s = 1.0f / 255.0f;
    return rl_v4(rl_srgb_to_linear((float)r * s), rl_srgb_to_linear((float)g * s),
                 rl_srgb_to_linear((float)b * s), (float)a * s);
}

rl_status rl_embedded_texture_decode(const struct aiTexture *tex, const char *what,
                                     rl_texture **out)
{
    if (!tex->pcData)
        return rl_error(RL_ERR_PARSE, "%s: embedded texture without data", what);
    int w, h;
    rl_vec4 *texels = NULL;
    rl_status st;
    if (tex->mHeight == 0) {
        /* stb_image takes an int length. */
        if (tex->mWidth > (unsigned)INT32_MAX)
            return rl_error(RL_ERR_LIMIT, "%s: embedded texture too large", what);
        const unsigned char *bytes = (const unsigned char *)tex->pcData;
        int len = (int)tex->mWidth, comp;
        /* Refuse absurd sizes from the header before decoding. */
        if (!stbi_info_from_memory(bytes, len, &w, &h, &comp))
            return rl_error(RL_ERR_PARSE, "%s: cannot decode embedded texture: %s", what,
                            stbi_failure_reason());
        if ((st = rl_texture_check_size(what, w, h)) != RL_OK ||
            (st = rl_texture_check_png_memory(bytes, (size_t)len, what)) != RL_OK)
            return st;
        unsigned char *rgba = stbi_load_from_memory(bytes, len, &w, &h, &comp, 4);
        if (!rgba)
            return rl_error(RL_ERR_PARSE, "%s: cannot decode embedded texture: %s", what,
                            stbi_failure_reason());
        texels = rl_calloc((size_t)w * (size_t)h, sizeof *texels);
        for (size_t i = 0; texels && i < (size_t)w * (size_t)h; ++i)
            texels[i] = texel(rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], rgba[4 * i + 3]);
        stbi_image_free(rgba);
    } else {
        if ((st = rl_texture_check_size(what, tex->mWidth, tex->mHeight)) != RL_OK)
            return st;
        w = (int)tex->mWidth;
        h = (int)tex->mHeight;
        texels = rl_calloc((size_t)w * (size_t)h, sizeof *texels);
        for (size_t i = 0; texels && i < (size_t)w * (size_t)h; ++i) {
            const struct aiTexel *t = &tex->pcData[i];
            texels[i] = texel(t->r, t->g, t->b, t->a);
        }
    }
    if (!texels)
        return RL_ERR_OUT_OF_MEMORY;
    st = rl_texture_create(w, h, texels, out);
    free(texels);
    return st;
}
