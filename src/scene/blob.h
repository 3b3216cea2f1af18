/* blob.h: the "blob" generator (blob.c), a closed organic-looking triangle
 * mesh with an exact triangle count. It stands in for the Stanford bunny
 * and dragon of Schröder 2017, Sec. 9.3, whose triangle counts matter for
 * the Line Space measurements but whose data renderlab does not ship. */
#ifndef RL_SCENE_BLOB_H
#define RL_SCENE_BLOB_H

#include "scene/generators.h"

#define RL_BLOB_MIN_TRIANGLES 4u
#define RL_BLOB_MAX_TRIANGLES 16000000u
#define RL_BLOB_DEFAULT_TRIANGLES 20000u
#define RL_BLOB_MAX_LUMPS 64

typedef struct rl_blob_desc {
    uint32_t triangles;       /* even, RL_BLOB_MIN..MAX_TRIANGLES */
    uint64_t seed;            /* lump placement */
    float scale;              /* radius of the undisplaced sphere, > 0 */
    int lumps;                /* smooth bumps and dents, 0..RL_BLOB_MAX_LUMPS */
} rl_blob_desc;

/* Appends the blob, centred on the origin (the origin is inside it and
 * sees every triangle from the front), to b. RL_ERR_INVALID_ARG for an odd
 * or out-of-range count or bad parameters (the message says why);
 * RL_ERR_OUT_OF_MEMORY. On failure b is unchanged except for its sticky
 * status on allocation failure. */
rl_status rl_gen_blob(rl_meshbuf *b, const rl_blob_desc *desc);

#endif
