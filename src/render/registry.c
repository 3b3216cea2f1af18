/* registry.c: the one list of renderer classes (pbrt-style create-by-name).
 *
 * A new algorithm adds its class here and nowhere else; rl_renderer_list()
 * and rl_renderer_create() read this table in order. */
#include "render/renderer.h"

/* Each class is defined in the file named after its algorithm. */
extern const rl_renderer_class rl_raster_renderer_class;     /* raster.c */
extern const rl_renderer_class rl_whitted_renderer_class;    /* whitted.c */
extern const rl_renderer_class rl_vt_renderer_class;         /* vt.c */
extern const rl_renderer_class rl_pt_renderer_class;         /* pathtrace.c */
extern const rl_renderer_class rl_chcpp_renderer_class;      /* chcpp.c */
extern const rl_renderer_class rl_svs_renderer_class;        /* svs.c */
extern const rl_renderer_class rl_visset_renderer_class;     /* visset.c */
extern const rl_renderer_class rl_surfels_renderer_class;    /* surfels.c */
extern const rl_renderer_class rl_select_renderer_class;     /* select.c */

const rl_renderer_class *const rl_renderer_classes[] = {
    &rl_raster_renderer_class,
    &rl_whitted_renderer_class,
    &rl_vt_renderer_class,
    &rl_pt_renderer_class,
    &rl_chcpp_renderer_class,
    &rl_svs_renderer_class,
    &rl_visset_renderer_class,
    &rl_surfels_renderer_class,
    &rl_select_renderer_class,
};
const size_t rl_renderer_class_count = sizeof rl_renderer_classes / sizeof rl_renderer_classes[0];
