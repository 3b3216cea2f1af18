/* glyphs.h: a tiny 5x7 bitmap font for the printed scales of the cluster
 * scene's dials (builtin_cluster.c), drawn anti-aliased into texels.
 *
 * Covers the digits, space, '/', '.', and the letters of "km/h", "x1000",
 * "rpm" and "min"; any other character is drawn as a blank cell. */
#ifndef RL_SCENE_GLYPHS_H
#define RL_SCENE_GLYPHS_H

#include "rl/rl_math.h"

#define RL_GLYPH_COLS 5
#define RL_GLYPH_ROWS 7

/* Seven rows, top first, of five bits each (bit 4 = leftmost column), or
 * NULL for a character the font lacks. */
const unsigned char *rl_glyph_5x7(char c);

/* Width in pixels of text drawn with glyphs char_h pixels tall (one blank
 * column between characters). */
float rl_glyphs_width(const char *text, float char_h);

/* Blends text, centred on pixel position (cx, cy) (x right, y down, row 0 at
 * the top), char_h pixels tall, into a width x height texel array with the
 * given colour; 4x4 samples per pixel give smooth edges. Clipped to the
 * array. */
void rl_glyphs_draw(rl_vec4 *texels, int width, int height, const char *text, float cx,
                    float cy, float char_h, rl_vec4 colour);

#endif
