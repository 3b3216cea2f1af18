/* load_internal.h: helpers shared by the mesh-file loader's files. */
#ifndef RL_SCENE_LOAD_INTERNAL_H
#define RL_SCENE_LOAD_INTERNAL_H

#include <stddef.h>

#include "rl/rl_image.h"

struct aiTexture;

/* load_validate.c: checks for files Assimp accepts too leniently.
 * ".obj" files must be text (no control bytes); ".ply" files, and any file
 * starting with the PLY magic, must hold as many elements as the header
 * announces, with valid faces. Other files pass. RL_ERR_PARSE
 * "path: what is wrong", RL_ERR_IO if the file cannot be read. */
rl_status rl_check_mesh_file(const char *path);

/* load_message.c: an importer's message msg about path as one safe line
 * into out: text it quotes is kept only where path itself holds it, cut
 * to 40 characters; non-printable bytes are escaped as \xNN. */
void rl_load_safe_message(const char *path, const char *msg, char *out, size_t size);

/* load_embedded.c: decodes a texture embedded in a model file (compressed
 * PNG/JPEG/... bytes, or raw BGRA texels) into linear RGBA. what names the
 * texture in messages. RL_ERR_PARSE if it cannot be decoded, RL_ERR_LIMIT
 * for sizes outside 1..RL_IMAGE_MAX_SIZE. */
rl_status rl_embedded_texture_decode(const struct aiTexture *tex, const char *what,
                                     rl_texture **out);

#endif
