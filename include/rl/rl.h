/* rl.h: everything public in renderlab. */
#ifndef RL_H
#define RL_H
#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_rng.h"
#include "rl/rl_image.h"
#include "rl/rl_timer.h"
#include "rl/rl_camera.h"
#include "rl/rl_scene.h"
#include "rl/rl_raster.h"
#include "rl/rl_render.h"
#include "rl/rl_accel.h"
#include "rl/rl_linespace.h"
#include "rl/rl_trace.h"
#include "rl/rl_metrics.h"
#include "rl/rl_filter.h"
#include "rl/rl_shadowmap.h"
#include "rl/rl_property.h"
#include "rl/rl_sampling.h"
#include "rl/rl_stats.h"
#include "rl/rl_plot.h"
#include "rl/rl_surfels.h"
#endif
