/* view_script.c: the viewer's keys by name and --script files.
 *
 * A script line is "TIME EVENT ARGS..." (docs/viewer.md); blank lines and
 * lines starting with '#' are skipped. Everything is checked when the file
 * is read, so that a typo on line 40 fails before a window opens, not
 * after a minute of rendering. */
#define _POSIX_C_SOURCE 200809L
#include "view.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rl/rl_options.h"

const char view_keys_help[] =
    "keys:\n"
    "  W A S D         fly forward, left, back, right (Q down, E up;\n"
    "                  Shift held: 4x faster); speed scales with the scene\n"
    "  left drag       orbit around the target\n"
    "  right drag      look around (mouse look)\n"
    "  wheel           dolly towards / away from the target\n"
    "  1..9            the scene's cameras; C the first one\n"
    "  P               play / pause the scene's camera_path; , and . scrub 1 s\n"
    "  R               record a camera path; R again saves it (--path-out)\n"
    "  Tab, Shift+Tab  next / previous renderer (every available one of rl algos)\n"
    "  + -             the renderer's live option up / down (vt min_edge, pt\n"
    "                  spp, surfels overdraw, chcpp assumed_visible, svs\n"
    "                  neighbours, visset budget, ...); [ ] choose which one\n"
    "  O B N F K       cycle the renderer's overlay (vt: wire, samples),\n"
    "                  shadow backend, diffuse backend, filter, vt criteria\n"
    "  L               show colour, depth or object IDs (false colours)\n"
    "  M               menu: the renderers and the current one's options; a\n"
    "                  click switches the renderer or changes the option\n"
    "                  (right click: the other way)\n"
    "  X               SSIM and hSSIM against an exact reference (whitted;\n"
    "                  pt at --ref-spp for the path tracers)\n"
    "  F12             screenshot: PNG + stats JSON (--shot-dir)\n"
    "  F1 or H         this help on screen; I the stats overlay\n"
    "  Esc             quit\n";

typedef struct key_name {
    const char *name;
    view_key key;
} key_name;

static const key_name key_names[] = {
    { "w", VIEW_KEY_FORWARD }, { "s", VIEW_KEY_BACK }, { "a", VIEW_KEY_LEFT }, { "d", VIEW_KEY_RIGHT },
    { "q", VIEW_KEY_DOWN }, { "e", VIEW_KEY_UP }, { "Shift", VIEW_KEY_FAST },
    { "Tab", VIEW_KEY_NEXT_ALGO }, { "Shift+Tab", VIEW_KEY_PREV_ALGO },
    { "F1", VIEW_KEY_HELP }, { "h", VIEW_KEY_HELP }, { "i", VIEW_KEY_STATS },
    { "1", VIEW_KEY_CAMERA_1 }, { "2", VIEW_KEY_CAMERA_1 + 1 }, { "3", VIEW_KEY_CAMERA_1 + 2 },
    { "4", VIEW_KEY_CAMERA_1 + 3 }, { "5", VIEW_KEY_CAMERA_1 + 4 }, { "6", VIEW_KEY_CAMERA_1 + 5 },
    { "7", VIEW_KEY_CAMERA_1 + 6 }, { "8", VIEW_KEY_CAMERA_1 + 7 }, { "9", VIEW_KEY_CAMERA_1 + 8 },
    { "c", VIEW_KEY_CAMERA_RESET }, { "p", VIEW_KEY_PLAY }, { ",", VIEW_KEY_SCRUB_BACK },
    { ".", VIEW_KEY_SCRUB_FORWARD }, { "r", VIEW_KEY_RECORD }, { "+", VIEW_KEY_OPTION_UP },
    { "-", VIEW_KEY_OPTION_DOWN }, { "]", VIEW_KEY_OPTION_NEXT }, { "[", VIEW_KEY_OPTION_PREV },
    { "o", VIEW_KEY_CYCLE_OVERLAY }, { "b", VIEW_KEY_CYCLE_SHADOW },
    { "n", VIEW_KEY_CYCLE_DIFFUSE }, { "f", VIEW_KEY_CYCLE_FILTER }, { "k", VIEW_KEY_CYCLE_CRITERIA },
    { "l", VIEW_KEY_LAYER }, { "m", VIEW_KEY_MENU }, { "x", VIEW_KEY_REFERENCE },
    { "F12", VIEW_KEY_SCREENSHOT }, { "Escape", VIEW_KEY_QUIT },
};

view_key view_key_from_name(const char *name)
{
    for (size_t i = 0; i < sizeof key_names / sizeof key_names[0]; i++)
        if (strcasecmp(name, key_names[i].name) == 0)
            return key_names[i].key;
    return VIEW_KEY_NONE;
}

bool view_key_is_held(view_key k)
{
    return k >= VIEW_KEY_FORWARD && k <= VIEW_KEY_FAST;
}

static const char *const event_names[] = {
    [VIEW_EV_KEY] = "key", [VIEW_EV_KEYDOWN] = "keydown", [VIEW_EV_KEYUP] = "keyup", [VIEW_EV_DRAG] = "drag",
    [VIEW_EV_WHEEL] = "wheel", [VIEW_EV_MOVE] = "move", [VIEW_EV_CAMERA] = "camera", [VIEW_EV_ALGO] = "algo",
    [VIEW_EV_SET] = "set", [VIEW_EV_SCREENSHOT] = "screenshot", [VIEW_EV_CAPTURE] = "capture",
    [VIEW_EV_RESIZE] = "resize", [VIEW_EV_CLICK] = "click",
    [VIEW_EV_RECORD] = "record", [VIEW_EV_QUIT] = "quit",
};
#define NUM_EVENTS (sizeof event_names / sizeof event_names[0])

/* The longest script: a typo in a generator loop should not fill memory. */
#define SCRIPT_MAX_EVENTS 100000
#define SCRIPT_MAX_LINE 4096

/* Splits line into at most max whitespace-separated words (in place). */
static int split_words(char *line, char **words, int max)
{
    int n = 0;
    char *save = NULL;
    for (char *w = strtok_r(line, " \t\r\n", &save); w; w = strtok_r(NULL, " \t\r\n", &save)) {
        if (n == max)
            return max + 1;
        words[n++] = w;
    }
    return n;
}

static bool parse_number(const char *text, double lo, double hi, double *out)
{
    return rl_parse_float(text, out) && *out >= lo && *out <= hi;
}

/* One event from its words (words[0] the time); 0, or the exit code after
 * the error was printed. */
static int parse_event(const char *path, int line, char **w, int n, view_event *e)
{
#define BAD(...) cli_fail(RL_CLI_USAGE, __VA_ARGS__)
    e->line = line;
    if (!parse_number(w[0], 0.0, 1e6, &e->time_s))
        return BAD("%s:%d: expected a time in seconds in [0, 1e6] first, got '%s'", path, line, w[0]);
    if (n < 2)
        return BAD("%s:%d: expected an event after the time", path, line);
    size_t k = 0;
    while (k < NUM_EVENTS && strcmp(w[1], event_names[k]) != 0)
        k++;
    if (k == NUM_EVENTS) {
        char hint[96];
        return BAD("%s:%d: unknown event '%s' (%sevents: key, keydown, keyup, drag, wheel, move, camera, algo, "
                   "set, screenshot, capture, resize, click, record, quit)", path, line, w[1],
                   cli_did_you_mean(w[1], event_names, NUM_EVENTS, hint, sizeof hint));
    }
    e->kind = (view_event_kind)k;
    int want = 0;
    switch (e->kind) {
    case VIEW_EV_KEY: case VIEW_EV_KEYDOWN: case VIEW_EV_KEYUP: case VIEW_EV_CAMERA: case VIEW_EV_ALGO:
    case VIEW_EV_SET: case VIEW_EV_SCREENSHOT: case VIEW_EV_CAPTURE: case VIEW_EV_RECORD: case VIEW_EV_WHEEL:
        want = 1;
        break;
    case VIEW_EV_DRAG: want = 3; break;
    case VIEW_EV_RESIZE: want = 2; break;
    case VIEW_EV_CLICK: want = n == 5 ? 3 : 2; break;     /* [left|right] X Y */
    case VIEW_EV_MOVE: want = 4; break;
    case VIEW_EV_QUIT: want = 0; break;
    }
    if (n - 2 != want)
        return BAD("%s:%d: '%s' takes %d argument%s, got %d", path, line, w[1], want, want == 1 ? "" : "s", n - 2);
    switch (e->kind) {
    case VIEW_EV_KEY: case VIEW_EV_KEYDOWN: case VIEW_EV_KEYUP:
        e->key = view_key_from_name(w[2]);
        if (e->key == VIEW_KEY_NONE)
            return BAD("%s:%d: unknown key '%s' (see rl view --help)", path, line, w[2]);
        if (e->kind != VIEW_EV_KEY && !view_key_is_held(e->key))
            return BAD("%s:%d: %s: '%s' is not held (keydown/keyup are for W A S D Q E Shift; use key)", path,
                       line, w[1], w[2]);
        break;
    case VIEW_EV_DRAG:
        if (strcmp(w[2], "left") != 0 && strcmp(w[2], "right") != 0)
            return BAD("%s:%d: drag: expected left or right, got '%s'", path, line, w[2]);
        e->button = strcmp(w[2], "right") == 0;
        if (!parse_number(w[3], -1e5, 1e5, &e->dx) || !parse_number(w[4], -1e5, 1e5, &e->dy))
            return BAD("%s:%d: drag: expected DX DY in pixels, got '%s %s'", path, line, w[3], w[4]);
        break;
    case VIEW_EV_WHEEL:
        if (!parse_number(w[2], -1000, 1000, &e->dx))
            return BAD("%s:%d: wheel: expected steps in [-1000, 1000], got '%s'", path, line, w[2]);
        break;
    case VIEW_EV_RESIZE:
        if (!parse_number(w[2], 16, 16384, &e->dx) || !parse_number(w[3], 16, 16384, &e->dy))
            return BAD("%s:%d: resize: expected WIDTH HEIGHT in [16, 16384], got '%s %s'", path, line, w[2], w[3]);
        break;
    case VIEW_EV_CLICK: {
        int at = n == 5 ? 3 : 2;
        if (n == 5 && strcmp(w[2], "left") != 0 && strcmp(w[2], "right") != 0)
            return BAD("%s:%d: click: expected left or right, got '%s'", path, line, w[2]);
        e->button = n == 5 && strcmp(w[2], "right") == 0;
        if (!parse_number(w[at], 0, 16383, &e->dx) || !parse_number(w[at + 1], 0, 16383, &e->dy))
            return BAD("%s:%d: click: expected X Y in image pixels, got '%s %s'", path, line, w[at], w[at + 1]);
        break;
    }
    case VIEW_EV_MOVE:
        if (strcmp(w[2], "eye") != 0 || strcmp(w[4], "target") != 0)
            return BAD("%s:%d: move: expected 'eye x,y,z target x,y,z'", path, line);
        if (!cli_parse_vec3("move eye", w[3], &e->eye) || !cli_parse_vec3("move target", w[5], &e->target))
            return RL_CLI_USAGE;
        break;
    case VIEW_EV_SET:
        if (!strchr(w[2], '=') || w[2][0] == '=')
            return BAD("%s:%d: set: expected KEY=VALUE, got '%s'", path, line, w[2]);
        break;
    case VIEW_EV_SCREENSHOT: case VIEW_EV_CAPTURE:
        if (!cli_has_extension(w[2], (const char *const[]){ ".png", NULL }))
            return BAD("%s:%d: %s: expected a .png file, got '%s'", path, line, w[1], w[2]);
        break;
    case VIEW_EV_RECORD:
        if (strcmp(w[2], "stop") != 0 && !cli_has_extension(w[2], (const char *const[]){ ".json", NULL }))
            return BAD("%s:%d: record: expected a .json file or stop, got '%s'", path, line, w[2]);
        break;
    default:
        break;
    }
    bool texted = e->kind == VIEW_EV_CAMERA || e->kind == VIEW_EV_ALGO || e->kind == VIEW_EV_SET ||
                  e->kind == VIEW_EV_SCREENSHOT || e->kind == VIEW_EV_CAPTURE || (e->kind == VIEW_EV_RECORD && strcmp(w[2], "stop") != 0);
    if (texted && !(e->text = strdup(w[2])))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    return RL_CLI_OK;
#undef BAD
}

int view_script_load(const char *path, view_script *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return cli_fail(RL_CLI_FAIL, "--script %s: %s", path, strerror(errno));
    out->path = strdup(path);
    int rc = out->path ? RL_CLI_OK : cli_fail(RL_CLI_FAIL, "out of memory");
    size_t cap = 0;
    char buf[SCRIPT_MAX_LINE];
    double last = 0.0;
    for (int line = 1; rc == RL_CLI_OK && fgets(buf, sizeof buf, f); line++) {
        if (!strchr(buf, '\n') && !feof(f)) {
            rc = cli_fail(RL_CLI_USAGE, "%s:%d: line longer than %d characters", path, line, SCRIPT_MAX_LINE - 2);
            break;
        }
        char *words[8];
        char *p = buf;
        while (isspace((unsigned char)*p))
            p++;
        if (*p == '#' || *p == '\0')
            continue;
        int n = split_words(p, words, 6);
        if (n > 6) {
            rc = cli_fail(RL_CLI_USAGE, "%s:%d: too many words for an event", path, line);
            break;
        }
        if (out->count == SCRIPT_MAX_EVENTS) {
            rc = cli_fail(RL_CLI_USAGE, "%s:%d: more than %d events", path, line, SCRIPT_MAX_EVENTS);
            break;
        }
        if (out->count == cap) {
            size_t ncap = cap ? 2 * cap : 64;
            view_event *ev = realloc(out->events, ncap * sizeof *ev);
            if (!ev) {
                rc = cli_fail(RL_CLI_FAIL, "out of memory");
                break;
            }
            out->events = ev;
            cap = ncap;
        }
        view_event *e = &out->events[out->count];
        memset(e, 0, sizeof *e);
        rc = parse_event(path, line, words, n, e);
        if (rc != RL_CLI_OK) {
            free(e->text);
            break;
        }
        out->count++;
        /* Events are applied in file order; a time running backwards would
         * silently mean "now", so it is refused. */
        if (e->time_s < last) {
            rc = cli_fail(RL_CLI_USAGE, "%s:%d: time %g s is before the previous event's %g s", path, line,
                          e->time_s, last);
            break;
        }
        last = e->time_s;
    }
    if (rc == RL_CLI_OK && ferror(f))
        rc = cli_fail(RL_CLI_FAIL, "--script %s: read error", path);
    fclose(f);
    if (rc != RL_CLI_OK)
        view_script_free(out);
    return rc;
}

void view_script_free(view_script *s)
{
    for (size_t i = 0; i < s->count; i++)
        free(s->events[i].text);
    free(s->events);
    free(s->path);
    memset(s, 0, sizeof *s);
}
