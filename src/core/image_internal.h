/* image_internal.h: helpers shared by image.c and the per-format files. */
#ifndef RL_CORE_IMAGE_INTERNAL_H
#define RL_CORE_IMAGE_INTERNAL_H

#include "rl/rl_image.h"

/* RL_ERR_LIMIT "what: size WxH outside 1..16384 per side" unless in range. */
rl_status rl_image_check_size(const char *what, long long width, long long height);
/* Argument checks common to every writer, before the file is touched. */
rl_status rl_image_check_writable(const rl_image *img, const char *who, const char *path);
rl_status rl_image_read_png(const char *path, rl_image **out);
rl_status rl_image_read_exr(const char *path, rl_image **out);

#endif
