/* view.h: what the files of `rl view` share (cmd_view.c and its view_*.c).
 * The parts without a window (the font, the script, the viewer's keys) are
 * built with or without SDL2, so that a script is checked the same way
 * everywhere. */
#ifndef RL_APP_VIEW_H
#define RL_APP_VIEW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cli.h"

/* view_font.c: a 5x7 bitmap font; a cell is 6 x 9 pixels at scale 1. */
enum { VIEW_FONT_W = 5, VIEW_FONT_H = 7, VIEW_FONT_ADVANCE = 6, VIEW_FONT_LINE = 9 };
bool view_font_has(char c);
int view_text_width(const char *line, int scale);
/* Draws text ('\n' starts a new line) at (x, y) in px (ARGB8888, width x
 * height), over a darkened box; cells outside are clipped. */
void view_draw_text(uint32_t *px, int width, int height, int x, int y, int scale, const char *text,
                    uint32_t color);

/* The viewer's keys, the same for the keyboard and a script. */
typedef enum view_key {
    VIEW_KEY_NONE = 0,
    VIEW_KEY_FORWARD, VIEW_KEY_BACK, VIEW_KEY_LEFT, VIEW_KEY_RIGHT, VIEW_KEY_DOWN, VIEW_KEY_UP,
    VIEW_KEY_FAST,                       /* held: moves 4x faster */
    VIEW_KEY_NEXT_ALGO, VIEW_KEY_PREV_ALGO,
    VIEW_KEY_HELP, VIEW_KEY_STATS,
    VIEW_KEY_CAMERA_1,                   /* .. VIEW_KEY_CAMERA_1 + 8: the scene's cameras 1..9 */
    VIEW_KEY_CAMERA_RESET = VIEW_KEY_CAMERA_1 + 9,
    VIEW_KEY_PLAY, VIEW_KEY_SCRUB_BACK, VIEW_KEY_SCRUB_FORWARD,
    VIEW_KEY_RECORD,
    VIEW_KEY_OPTION_UP, VIEW_KEY_OPTION_DOWN,
    /* Which of the renderer's live options + and - change. */
    VIEW_KEY_OPTION_NEXT, VIEW_KEY_OPTION_PREV,
    /* Cycle an enum option of the current renderer through its choices:
     * overlay, shadow / diffuse backend, filter, VT criteria. */
    VIEW_KEY_CYCLE_OVERLAY, VIEW_KEY_CYCLE_SHADOW, VIEW_KEY_CYCLE_DIFFUSE, VIEW_KEY_CYCLE_FILTER,
    VIEW_KEY_CYCLE_CRITERIA,
    VIEW_KEY_LAYER,                      /* show colour, depth or object IDs */
    VIEW_KEY_MENU,                       /* the renderers and the current one's options */
    VIEW_KEY_REFERENCE,                  /* SSIM / hSSIM against an exact reference */
    VIEW_KEY_SCREENSHOT,
    VIEW_KEY_QUIT,
    VIEW_KEY_COUNT
} view_key;
/* The key a script names ("Tab", "w", "F12"; case-insensitive), or
 * VIEW_KEY_NONE. */
view_key view_key_from_name(const char *name);
/* Whether the key acts while it is held (motion) rather than once. */
bool view_key_is_held(view_key k);
/* The key list of rl view --help and the on-screen help. */
extern const char view_keys_help[];

/* view_script.c: --script FILE, one timed event a line (docs/viewer.md). */
typedef enum view_event_kind {
    VIEW_EV_KEY,          /* press and release */
    VIEW_EV_KEYDOWN,
    VIEW_EV_KEYUP,
    VIEW_EV_DRAG,         /* button 0 left (orbit), 1 right (look); dx, dy pixels */
    VIEW_EV_WHEEL,        /* steps in dx, positive towards the target */
    VIEW_EV_MOVE,         /* eye, target */
    VIEW_EV_CAMERA,       /* text: a camera name of the scene */
    VIEW_EV_ALGO,         /* text */
    VIEW_EV_SET,          /* text: KEY=VALUE */
    VIEW_EV_SCREENSHOT,   /* text: FILE.png */
    VIEW_EV_CAPTURE,      /* text: FILE.png, the window's pixels with the overlay */
    VIEW_EV_RESIZE,       /* dx x dy: window size */
    VIEW_EV_CLICK,        /* button 0 left, 1 right at dx, dy: image pixels (the menu's entries) */
    VIEW_EV_RECORD,       /* text: FILE.json starts, NULL stops and saves */
    VIEW_EV_QUIT
} view_event_kind;

typedef struct view_event {
    double time_s;
    view_event_kind kind;
    int line;
    view_key key;
    int button;
    double dx, dy;
    rl_vec3 eye, target;
    char *text;
} view_event;

typedef struct view_script {
    char *path;
    view_event *events;
    size_t count;
} view_script;

/* Reads and checks the whole script before the window opens: RL_CLI_OK, or
 * the exit code after one "rl: error: FILE:LINE: ..." line (2 for a
 * malformed or unknown event or key, 1 when the file cannot be read). */
int view_script_load(const char *path, view_script *out);
void view_script_free(view_script *s);

/* view_gl.c: the window's EGL context shared with the GL backend, with
 * SDL2 and the GL backend (stubs that fail otherwise). open takes the
 * SDL_Window (made with SDL_WINDOW_OPENGL under
 * SDL_HINT_VIDEO_X11_FORCE_EGL) and hands its context to rl_gl_share_with;
 * NULL with the reason. The rest runs on the thread that opened it. */
typedef struct view_gl view_gl;
view_gl *view_gl_open(void *window, char *why, size_t n);
void view_gl_close(view_gl *g);
/* The image's (and the overlay's) size. */
bool view_gl_resize(view_gl *g, int w, int h);
/* A frame texture of the library, now shown (its fence waited on by the
 * GPU, the last one deleted), or deleted unseen. */
void view_gl_adopt(view_gl *g, const rl_gl_frame *f);
void view_gl_delete(view_gl *g, const rl_gl_frame *f);
/* The shown frame is no longer the image (a CPU frame replaced it). */
void view_gl_drop_frame(view_gl *g);
/* The shown frame's linear colour into dst (width x height); false when
 * there is none. */
bool view_gl_read(view_gl *g, rl_vec4 *dst);
/* Draws the frame (use_frame) under the overlay (ARGB8888 as draw() makes
 * it: alpha 255 text, else transparent or shaded, view_gl.c), uploading
 * its first rows rows, and swaps. */
void view_gl_present(view_gl *g, const uint32_t *overlay, int rows, bool use_frame);
/* The same picture at the image's size into out (ARGB8888, top row
 * first), for a script's capture: what the shader draws, not a CPU copy. */
bool view_gl_capture(view_gl *g, const uint32_t *overlay, int rows, bool use_frame, uint32_t *out);
/* Where the image lies in the drawable, and the drawable's size. */
void view_gl_viewport(const view_gl *g, int *x, int *y, int *w, int *h);
void view_gl_drawable_size(const view_gl *g, int *w, int *h);

/* cmd_view.c with SDL2, or the message that it is missing. */
int view_run(int argc, char **argv);

#endif
