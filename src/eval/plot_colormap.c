/* plot_colormap.c: colour maps for heat maps and colour bars (rl_plot.h).
 *
 * Each map is a small table of published key colours, interpolated linearly
 * in display (sRGB-encoded) space, which is also how cairo interpolates the
 * colour bar's gradient, so bar and cells agree.
 *  - viridis, magma: van der Walt & Smith, matplotlib 1.5 / 2.0 default maps
 *    (2015); 11 samples at t = 0, 0.1, ..., 1 of the published 256-entry
 *    tables, endpoints at full precision.
 *  - coolwarm: Moreland 2009, "Diverging Color Maps for Scientific
 *    Visualization", ISVC, the 33-entry table CoolWarmFloat33; every other
 *    entry (17 stops, spacing 1/16). The map is nearly linear between them. */
#include "rl/rl_plot.h"

#include <math.h>
#include <string.h>

#include "eval/plot_internal.h"

#define HEX(c) { ((c) >> 16 & 0xff) / 255.0f, ((c) >> 8 & 0xff) / 255.0f, ((c) & 0xff) / 255.0f }

static const float viridis[][3] = {
    { 0.267004f, 0.004874f, 0.329415f },
    HEX(0x482475), HEX(0x414487), HEX(0x355f8d), HEX(0x2a788e), HEX(0x21918c),
    HEX(0x22a884), HEX(0x44bf70), HEX(0x7ad151), HEX(0xbddf26),
    { 0.993248f, 0.906157f, 0.143936f },
};

static const float magma[][3] = {
    { 0.001462f, 0.000466f, 0.013866f },
    HEX(0x140e36), HEX(0x3b0f70), HEX(0x641a80), HEX(0x8c2981), HEX(0xb73779),
    HEX(0xde4968), HEX(0xf7705c), HEX(0xfe9f6d), HEX(0xfecf92),
    { 0.987053f, 0.991438f, 0.749504f },
};

static const float coolwarm[][3] = {
    { 0.2298057f, 0.298717966f, 0.753683153f }, { 0.30386891f, 0.406535296f, 0.84495867f },
    { 0.38301334f, 0.50941904f, 0.917387822f }, { 0.46666708f, 0.604562568f, 0.968154911f },
    { 0.552953156f, 0.688929332f, 0.995375608f }, { 0.639176211f, 0.759599947f, 0.998151185f },
    { 0.722193294f, 0.813952739f, 0.976574709f }, { 0.798691636f, 0.849786142f, 0.931688648f },
    { 0.865395197f, 0.86541021f, 0.865395561f }, { 0.924127593f, 0.827384882f, 0.774508472f },
    { 0.958852946f, 0.769767752f, 0.678007945f }, { 0.969954137f, 0.694266682f, 0.579375448f },
    { 0.958003065f, 0.602842431f, 0.481775914f }, { 0.923944917f, 0.49730856f, 0.387970225f },
    { 0.869186849f, 0.378313092f, 0.300267182f }, { 0.795631745f, 0.24128379f, 0.220525627f },
    { 0.705673158f, 0.01555616f, 0.150232812f },
};

typedef struct cmap {
    const char *name;
    const float (*keys)[3];
    int count;
} cmap;

static const cmap maps[] = {
    { "viridis", viridis, (int)(sizeof viridis / sizeof viridis[0]) },
    { "magma", magma, (int)(sizeof magma / sizeof magma[0]) },
    { "coolwarm", coolwarm, (int)(sizeof coolwarm / sizeof coolwarm[0]) },
};

static const cmap *find(const char *name)
{
    if (!name)
        return NULL;
    for (size_t i = 0; i < sizeof maps / sizeof maps[0]; ++i)
        if (strcmp(maps[i].name, name) == 0)
            return &maps[i];
    return NULL;
}

bool rl_plot_colormap_valid(const char *name) { return find(name) != NULL; }

rl_vec3 rl_plot_colormap(const char *name, double t)
{
    const cmap *m = find(name);
    if (!m)
        m = &maps[0];
    if (!(t > 0.0)) /* also NaN: the map's low end rather than garbage */
        t = 0.0;
    if (t > 1.0)
        t = 1.0;
    double s = t * (m->count - 1);
    int i = (int)s;
    if (i >= m->count - 1)
        i = m->count - 2;
    float f = (float)(s - i);
    const float *a = m->keys[i], *b = m->keys[i + 1];
    return rl_v3(a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f);
}
