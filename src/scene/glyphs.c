/* glyphs.c: the 5x7 dial font (see glyphs.h). Shapes in the style of the
 * classic 5x7 dot-matrix character generators, drawn here from scratch;
 * every row is five bits, leftmost column in bit 4. */
#include "scene/glyphs.h"

#include <math.h>
#include <string.h>

typedef struct glyph { char c; unsigned char rows[RL_GLYPH_ROWS]; } glyph;

static const glyph font[] = {
    { '0', { 0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E } },
    { '1', { 0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E } },
    { '2', { 0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F } },
    { '3', { 0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E } },
    { '4', { 0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02 } },
    { '5', { 0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E } },
    { '6', { 0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E } },
    { '7', { 0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08 } },
    { '8', { 0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E } },
    { '9', { 0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C } },
    { ' ', { 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00 } },
    { '/', { 0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10 } },
    { '.', { 0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C } },
    { 'k', { 0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12 } },
    { 'm', { 0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11 } },
    { 'h', { 0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11 } },
    { 'x', { 0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11 } },
    { 'r', { 0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10 } },
    { 'p', { 0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10 } },
    { 'i', { 0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E } },
    { 'n', { 0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11 } },
};

const unsigned char *rl_glyph_5x7(char c)
{
    for (size_t i = 0; i < sizeof font / sizeof font[0]; ++i)
        if (font[i].c == c)
            return font[i].rows;
    return NULL;
}

float rl_glyphs_width(const char *text, float char_h)
{
    size_t n = strlen(text);
    float dot = char_h / (float)RL_GLYPH_ROWS;
    return n ? dot * (float)((RL_GLYPH_COLS + 1) * n - 1) : 0.0f;
}

/* Whether the dot at glyph-grid position (gx, gy) of the text is set. */
static bool dot_set(const char *text, size_t len, float gx, float gy)
{
    if (gx < 0.0f || gy < 0.0f || gy >= (float)RL_GLYPH_ROWS)
        return false;
    size_t cell = (size_t)(gx / (float)(RL_GLYPH_COLS + 1));
    int col = (int)gx - (int)cell * (RL_GLYPH_COLS + 1);
    if (cell >= len || col >= RL_GLYPH_COLS)
        return false;
    const unsigned char *rows = rl_glyph_5x7(text[cell]);
    return rows && (rows[(int)gy] >> (RL_GLYPH_COLS - 1 - col)) & 1;
}

void rl_glyphs_draw(rl_vec4 *texels, int width, int height, const char *text, float cx,
                    float cy, float char_h, rl_vec4 colour)
{
    size_t len = strlen(text);
    if (!len || !(char_h > 0.0f))
        return;
    float dot = char_h / (float)RL_GLYPH_ROWS;
    float w = rl_glyphs_width(text, char_h);
    float x0 = cx - 0.5f * w, y0 = cy - 0.5f * char_h;
    int px0 = (int)floorf(x0), px1 = (int)ceilf(x0 + w);
    int py0 = (int)floorf(y0), py1 = (int)ceilf(y0 + char_h);
    for (int py = py0 < 0 ? 0 : py0; py < py1 && py < height; ++py)
        for (int px = px0 < 0 ? 0 : px0; px < px1 && px < width; ++px) {
            int hits = 0;
            for (int sy = 0; sy < 4; ++sy)
                for (int sx = 0; sx < 4; ++sx) {
                    float gx = ((float)px + ((float)sx + 0.5f) / 4.0f - x0) / dot;
                    float gy = ((float)py + ((float)sy + 0.5f) / 4.0f - y0) / dot;
                    hits += dot_set(text, len, gx, gy);
                }
            if (!hits)
                continue;
            float a = (float)hits / 16.0f;
            rl_vec4 *t = &texels[(size_t)py * (size_t)width + (size_t)px];
            *t = rl_v4(rl_lerpf(t->x, colour.x, a), rl_lerpf(t->y, colour.y, a),
                       rl_lerpf(t->z, colour.z, a), 1.0f);
        }
}
