/* image_internal.h: helpers shared by image.c and the per-format files. */
#ifndef RL_CORE_IMAGE_INTERNAL_H
#define RL_CORE_IMAGE_INTERNAL_H

#include "rl/rl_image.h"

/* RL_ERR_LIMIT "what: size WxH outside 1..16384 per side" unless in range. */
rl_status rl_image_check_size(const char *what, long long width, long long height);
/* Before a reader allocates the picture its header declares: RL_ERR_PARSE
 * when the file is too short to hold width x height pixels of at least
 * min_bytes_per_pixel under the strongest compression (deflate, 1032:1),
 * so that a few hundred bytes cannot claim gigabytes (issue 34). */
rl_status rl_image_check_file_size(const char *path, long long width, long long height, double min_bytes_per_pixel);
/* Argument checks common to every writer, before the file is touched. */
rl_status rl_image_check_writable(const rl_image *img, const char *who, const char *path);
rl_status rl_image_read_png(const char *path, rl_image **out);
/* Before stb_image decodes len bytes in memory (an embedded texture): when
 * they are a PNG, RL_ERR_PARSE naming `what` if a chunk is longer than the
 * bytes after it (stb would allocate its declared length). */
rl_status rl_texture_check_png_memory(const unsigned char *data, size_t len, const char *what);
rl_status rl_image_read_exr(const char *path, rl_image **out);
/* The data window's size from an EXR's header, nothing decoded. */
rl_status rl_image_exr_size(const char *path, long long *width, long long *height);

#endif
