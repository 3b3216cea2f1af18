/* path.c: joining and splitting file paths for scene assets and outputs
 * (POSIX '/' separators; a Windows drive prefix "C:" also counts as absolute). */
#include "rl/rl_path.h"

#include <stdio.h>
#include <string.h>

static bool is_absolute(const char *path)
{
    if (path[0] == '/' || path[0] == '\\')
        return true;
    /* "C:/..." so that scenes written on Windows still resolve. */
    return path[0] != '\0' && path[1] == ':';
}

void rl_path_join(const char *base_dir, const char *path, char *out, size_t out_size)
{
    if (!out || out_size == 0)
        return;
    if (!path)
        path = "";
    if (!base_dir || base_dir[0] == '\0' || is_absolute(path)) {
        snprintf(out, out_size, "%s", path);
        return;
    }
    size_t n = strlen(base_dir);
    bool has_sep = base_dir[n - 1] == '/' || base_dir[n - 1] == '\\';
    snprintf(out, out_size, "%s%s%s", base_dir, has_sep ? "" : "/", path);
}

void rl_path_dirname(const char *path, char *out, size_t out_size)
{
    if (!out || out_size == 0)
        return;
    out[0] = '\0';
    if (!path)
        return;
    const char *slash = strrchr(path, '/');
    const char *bslash = strrchr(path, '\\');
    if (bslash && (!slash || bslash > slash))
        slash = bslash;
    if (!slash)
        return;
    /* Keep the root of "/file" so that the result is still absolute. */
    size_t len = slash == path ? 1 : (size_t)(slash - path);
    if (len >= out_size)
        len = out_size - 1;
    memcpy(out, path, len);
    out[len] = '\0';
}

bool rl_path_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    if (n < e)
        return false;
    for (size_t i = 0; i < e; ++i) {
        char c = path[n - e + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != ext[i])
            return false;
    }
    return true;
}
