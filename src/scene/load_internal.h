/* load_internal.h: helpers shared by the mesh-file loader's files. */
#ifndef RL_SCENE_LOAD_INTERNAL_H
#define RL_SCENE_LOAD_INTERNAL_H

#include <stddef.h>

#include "rl/rl_image.h"
#include "rl/rl_scene.h"

struct aiTexture;

/* load_validate.c: checks for files Assimp accepts too leniently.
 * ".obj" files must be text (no control bytes); ".ply" files, and any file
 * starting with the PLY magic, must hold as many elements as the header
 * announces, with valid faces. Other files pass. RL_ERR_PARSE
 * "path: what is wrong", RL_ERR_IO if the file cannot be read. */
rl_status rl_check_mesh_file(const char *path);

/* load_validate_graph.c: node hierarchies Assimp would recurse through
 * without bound. glTF JSON text: child indices in range, one parent per
 * node, no cycle; Collada XML: no <node> that instances itself or an
 * ancestor. Both: at most RL_IMPORT_MAX_NODE_DEPTH levels (Assimp's
 * recursion uses a few hundred bytes of stack per level, so 1024 levels
 * stay far inside a 1 MiB thread stack; real files have tens), and for
 * Collada at most RL_IMPORT_MAX_NODE_COPIES nodes once <instance_node> is
 * expanded. RL_ERR_PARSE (cycles, bad indices) or RL_ERR_LIMIT,
 * "path: what". */
#define RL_IMPORT_MAX_NODE_DEPTH 1024
#define RL_IMPORT_MAX_NODE_COPIES 10000000ull
rl_status rl_check_gltf_nodes(const char *path, const char *json, size_t size);
rl_status rl_check_dae_nodes(const char *path, const char *data, size_t size);

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

/* load_assimp.c: the Assimp import into scene, in the calling process. The
 * caller has checked the arguments and the file (rl_check_mesh_file). */
rl_status rl_assimp_import(rl_scene *scene, const char *path, uint32_t parent,
                           const rl_scene_import_desc *desc, uint32_t *root_node);

/* import_stream.c: the result of an import in a child process, as bytes
 * (format in import_stream.c). The writer goes to fd, or to memory (buf,
 * len) when fd < 0; failed is set once a write or allocation fails. */
typedef struct rl_import_counts {
    uint32_t nodes, meshes, materials, textures, cameras, lights;
} rl_import_counts;
typedef struct rl_import_writer {
    int fd;
    uint8_t *buf;
    size_t len, cap;
    bool failed;
    uint32_t records;
    rl_import_counts base;              /* the scene before the import */
    uint64_t degenerate0, nonfinite0;
} rl_import_writer;
/* Starts the stream with the scene as it is before the import. */
void rl_import_writer_init(rl_import_writer *w, int fd, const rl_scene *scene);
/* A log line of the import, re-logged by the parent. */
void rl_import_writer_warning(rl_import_writer *w, rl_log_level level, const char *text);
/* Ends the stream: the error (status != RL_OK, with its message) or what
 * the import added to scene, under root. Flushes. */
void rl_import_writer_finish(rl_import_writer *w, const struct rl_scene *scene, rl_status status,
                             const char *message, uint32_t root);
bool rl_import_writer_flush(rl_import_writer *w);
void rl_import_writer_free(rl_import_writer *w);
/* Checks the whole stream against scene (which must be in the state the
 * child started from), then appends its items and re-logs its warnings.
 * RL_ERR_PARSE "path: the importer's result is malformed (...)" leaves the
 * scene untouched; a child's error comes back as the child recorded it,
 * except that running out of memory becomes RL_ERR_LIMIT "path: the
 * importer exceeded its memory limit (N MiB)" when memory_mib > 0. */
rl_status rl_import_stream_apply(rl_scene *scene, const uint8_t *bytes, size_t size,
                                 const char *path, uint32_t parent, uint32_t memory_mib,
                                 uint32_t *root_node);

#endif
