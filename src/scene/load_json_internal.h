/* load_json_internal.h: shared by the files of the JSON scene loader
 * (load_json.c: sections; load_json_read.c: typed reads with positions;
 * load_json_transform.c; load_json_base.c: starting from a built-in). */
#ifndef RL_SCENE_LOAD_JSON_INTERNAL_H
#define RL_SCENE_LOAD_JSON_INTERNAL_H

#include "core/json.h"
#include "scene/scene_internal.h"

typedef struct rl_jscene_ctx {
    const rl_json_doc *doc;
    const char *path;
    rl_scene *scene;
    uint32_t default_material;   /* RL_NONE until a generator needs it */
    bool had_error;              /* an error was pending before we started */
} rl_jscene_ctx;

/* Re-records the error a core call (validator, importer, generator) just
 * returned as st, prefixed with file:line:col of item; RL_ERR_INVALID_ARG
 * and RL_ERR_NOT_FOUND become RL_ERR_PARSE. Returns the status. */
rl_status rl_jscene_located(const rl_jscene_ctx *c, const cJSON *item, rl_status st);

/* All reads below fail with RL_ERR_PARSE "file:line:col: what was expected".
 * Optional keys leave *out (the default) alone when absent. */
rl_status rl_jscene_expect_object(const rl_jscene_ctx *c, const cJSON *item, const char *what);
rl_status rl_jscene_expect_array(const rl_jscene_ctx *c, const cJSON *item, const char *what);
/* Object with only the NULL-terminated allowed keys. */
rl_status rl_jscene_check_object(const rl_jscene_ctx *c, const cJSON *obj, const char *what,
                                 const char *const *allowed);
const cJSON *rl_jscene_member(const cJSON *obj, const char *key);   /* or NULL */
rl_status rl_jscene_require(const rl_jscene_ctx *c, const cJSON *obj, const char *key,
                            const char *what, const cJSON **out);
rl_status rl_jscene_number(const rl_jscene_ctx *c, const cJSON *obj, const char *key, double lo,
                           double hi, double *out);
rl_status rl_jscene_float(const rl_jscene_ctx *c, const cJSON *obj, const char *key, double lo,
                          double hi, float *out);
rl_status rl_jscene_read_vec3(const rl_jscene_ctx *c, const cJSON *item, rl_vec3 *out);
/* nonzero: the vector must have non-zero length. */
rl_status rl_jscene_vec3(const rl_jscene_ctx *c, const cJSON *obj, const char *key, bool nonzero,
                         rl_vec3 *out);
/* [r, g, b] or one number (grey), not negative. */
rl_status rl_jscene_color(const rl_jscene_ctx *c, const cJSON *obj, const char *key, rl_vec3 *out);
/* Non-empty string. */
rl_status rl_jscene_string(const rl_jscene_ctx *c, const cJSON *obj, const char *key,
                           const char **out);
/* A number, string or bool as text ("2", "0.5", "true"). */
rl_status rl_jscene_scalar_text(const rl_jscene_ctx *c, const cJSON *item, char *out,
                                size_t size);
/* {"k": 1, "b": true} or "k=1,b=true" -> "k=1,b=true" (core/params.h). */
rl_status rl_jscene_params_text(const rl_jscene_ctx *c, const cJSON *obj, char *out,
                                size_t size);

/* load_json_transform.c: a "transform" object -> matrix. */
rl_status rl_jscene_transform(const rl_jscene_ctx *c, const cJSON *obj, rl_mat4 *out);

/* load_json_base.c: copies everything of the (committed) built-in src into
 * the empty, uncommitted dst, keeping all ids. */
rl_status rl_jscene_copy_base(const rl_scene *src, rl_scene *dst);

#endif
