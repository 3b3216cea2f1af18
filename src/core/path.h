/* path.h: file path helpers shared by loaders, image I/O and the CLI. */
#ifndef RL_CORE_PATH_H
#define RL_CORE_PATH_H

#include <stdbool.h>
#include <stddef.h>

/* Joins base_dir and a relative path into out (absolute paths are kept). */
void rl_path_join(const char *base_dir, const char *path, char *out, size_t out_size);
/* Directory part of path ("" if none) into out. */
void rl_path_dirname(const char *path, char *out, size_t out_size);
/* True when path ends in ext (given in lower case, with its dot), ignoring
 * the case of path: rl_path_has_ext("A.PNG", ".png"). */
bool rl_path_has_ext(const char *path, const char *ext);

#endif
