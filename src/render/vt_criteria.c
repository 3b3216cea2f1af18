/* vt_criteria.c: the subdivision criteria of Vertex Tracing (Ullmann 2003,
 * Sec. 3.3.1): an edge is split when the samples at its ends differ by more
 * than a threshold in RGB (L1 norm, eq. 3.11), in HSV (three independent
 * thresholds), or in their ray trees (RT_i != RT_j).
 *
 * In contrast to the thesis, colours are compared as displayed (sRGB-encoded
 * and clamped to [0, 1]) rather than as linear radiance: the thresholds then
 * mean the same visible step in dark and bright regions, and overexposed
 * highlights, which clamp to white anyway, stop forcing refinement. The ray
 * tree is compared through its hash (rl_ray_tree_hash), which equals the
 * recursive comparison up to hash collisions. */
#include <math.h>
#include <string.h>

#include "render/vt_internal.h"

/* Below this saturation the hue of a colour is noise (undefined for greys). */
#define VT_HUE_MIN_SATURATION 1e-3f

bool vt_criteria_parse(const char *text, unsigned *bits)
{
    static const struct { const char *name; unsigned bits; } names[] = {
        { "rgb", VT_CRIT_RGB },
        { "hsv", VT_CRIT_HSV },
        { "tree", VT_CRIT_TREE },
        { "tree+rgb", VT_CRIT_TREE | VT_CRIT_RGB },
        { "rgb+tree", VT_CRIT_TREE | VT_CRIT_RGB },
        { "tree+hsv", VT_CRIT_TREE | VT_CRIT_HSV },
        { "hsv+tree", VT_CRIT_TREE | VT_CRIT_HSV },
        { "rgb+hsv", VT_CRIT_RGB | VT_CRIT_HSV },
    };
    if (!text || !bits)
        return false;
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        if (strcmp(text, names[i].name) == 0) {
            *bits = names[i].bits;
            return true;
        }
    }
    return false;
}

float vt_display(float linear)
{
    /* IEC 61966-2-1 sRGB transfer function; NaN counts as black. */
    if (!(linear > 0.0f))
        return 0.0f;
    if (linear >= 1.0f)
        return 1.0f;
    if (linear <= 0.0031308f)
        return 12.92f * linear;
    return 1.055f * powf(linear, 1.0f / 2.4f) - 0.055f;
}

void vt_rgb_to_hsv(rl_vec3 rgb, float *h, float *s, float *v)
{
    float max = rl_maxf(rgb.x, rl_maxf(rgb.y, rgb.z));
    float min = rl_minf(rgb.x, rl_minf(rgb.y, rgb.z));
    float delta = max - min;
    *v = max;
    *s = max > 0.0f ? delta / max : 0.0f;
    if (!(delta > 0.0f)) {
        *h = 0.0f;
        return;
    }
    /* Hexcone sector (Smith 1978), as a fraction of the full circle. */
    float hue;
    if (max == rgb.x)
        hue = (rgb.y - rgb.z) / delta;            /* between yellow and magenta */
    else if (max == rgb.y)
        hue = 2.0f + (rgb.z - rgb.x) / delta;     /* between cyan and yellow */
    else
        hue = 4.0f + (rgb.x - rgb.y) / delta;     /* between magenta and cyan */
    hue /= 6.0f;
    if (hue < 0.0f)
        hue += 1.0f;
    *h = hue >= 1.0f ? 0.0f : hue;
}

static rl_vec3 display_of(rl_vec3 c)
{
    return rl_v3(vt_display(c.x), vt_display(c.y), vt_display(c.z));
}

rl_vec3 vt_sample_display(const vt_vertex_sample *sample)
{
    /* Sec. 3.5.3: deferred textures are applied by the rasterizer, so only
     * the untextured ("flat") radiance decides where to sample. */
    return display_of(sample->flat);
}

uint64_t vt_tree_hash(const rl_ray_tree *tree, int shadow, int depth)
{
    if (!tree)
        return 0;
    bool keep_shadows = shadow == VT_TREE_SHADOW_BLOCKED || shadow == VT_TREE_SHADOW_OCCLUDER;
    if (keep_shadows && depth <= 0)
        return rl_ray_tree_hash(tree);
    rl_ray_tree kept;
    kept.count = 0;
    kept.truncated = tree->truncated;
    for (uint32_t i = 0; i < tree->count && i < RL_RAY_TREE_MAX; ++i) {
        const rl_ray_tree_node *n = &tree->nodes[i];
        bool feeler = n->type == RL_RAY_SHADOW;
        /* A feeler is one level below the ray whose hit it lights. */
        int ray_depth = feeler ? (int)n->depth - 1 : (int)n->depth;
        if (depth > 0 && ray_depth > depth)
            continue;
        if (feeler && shadow == VT_TREE_SHADOW_NONE)
            continue;
        if (feeler && shadow == VT_TREE_SHADOW_VISIBLE && n->object != RL_ID_NONE)
            continue;
        kept.nodes[kept.count++] = *n;
    }
    return rl_ray_tree_hash(&kept);
}

unsigned vt_criteria_test(const vt_criteria *c, const vt_vertex_sample *a, const vt_vertex_sample *b)
{
    unsigned fired = 0;
    /* Display values per test, not stored (vt_vertex_sample), and only
     * for the colour criteria: the tree criterion alone needs none. */
    rl_vec3 da = rl_v3s(0.0f), db = rl_v3s(0.0f);
    if (c->bits & (VT_CRIT_RGB | VT_CRIT_HSV)) {
        da = vt_sample_display(a);
        db = vt_sample_display(b);
    }
    if (c->bits & VT_CRIT_RGB) {
        /* eq. 3.11: L1 norm of the difference */
        float l1 = fabsf(da.x - db.x) + fabsf(da.y - db.y) + fabsf(da.z - db.z);
        if (l1 > c->eps_rgb)
            fired |= VT_CRIT_RGB;
    }
    if (c->bits & VT_CRIT_HSV) {
        float ha, sa, va, hb, sb, vb;
        vt_rgb_to_hsv(da, &ha, &sa, &va);
        vt_rgb_to_hsv(db, &hb, &sb, &vb);
        bool hue_fires = false;
        if (sa >= VT_HUE_MIN_SATURATION && sb >= VT_HUE_MIN_SATURATION) {
            /* Hue lives on a circle: 0.95 and 0.05 are 0.1 apart. */
            float dh = fabsf(ha - hb);
            if (dh > 0.5f)
                dh = 1.0f - dh;
            hue_fires = dh > c->eps_h;
        }
        if (hue_fires || fabsf(sa - sb) > c->eps_s || fabsf(va - vb) > c->eps_v)
            fired |= VT_CRIT_HSV;
    }
    if ((c->bits & VT_CRIT_TREE) && vt_sample_tree(a) != vt_sample_tree(b))
        fired |= VT_CRIT_TREE;
    return fired;
}
