/* rl_path.h: file path helpers shared by the loaders, image I/O and
 * applications (which file type a name says, where a scene's relative
 * texture path points). Plain string work: nothing here touches the file
 * system. Outputs are always NUL-terminated and cut to out_size. */
#ifndef RL_PATH_H
#define RL_PATH_H

#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Joins base_dir and a relative path into out (absolute paths are kept). */
RL_API void rl_path_join(const char *base_dir, const char *path, char *out, size_t out_size);
/* Directory part of path ("" if none) into out. */
RL_API void rl_path_dirname(const char *path, char *out, size_t out_size);
/* True when path ends in ext (given in lower case, with its dot), ignoring
 * the case of path: rl_path_has_ext("A.PNG", ".png"). */
RL_API bool rl_path_has_ext(const char *path, const char *ext);

#ifdef __cplusplus
}
#endif
#endif
