/* progress.c: the stock progress reporter for applications (rl_timer.h).
 *
 * On a terminal it redraws one line in place ("label [#####.....]  42%  ETA
 * 3s") at most 10 times a second; on a pipe or log file it writes at most one
 * plain line per 25% so logs stay short. Nothing appears for work that ends
 * within the delay (1 s by default). Updates arrive from many OpenMP threads:
 * a lock-free check of the next allowed draw time makes the common case (too
 * early to draw) cost one atomic load, and drawing itself takes a mutex. */
#define _POSIX_C_SOURCE 200809L
#include "rl/rl_timer.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/error.h"

#define BAR_WIDTH 30
#define REDRAW_INTERVAL_S 0.1

struct rl_progress {
    char *label;
    FILE *stream;
    bool tty;
    double start_s, delay_s;
    _Atomic double next_draw_s;   /* no drawing before this time */
    pthread_mutex_t lock;
    bool drawn;                   /* something was written */
    int last_quarter;             /* non-TTY: last 25% step printed */
    double last_done;
};

rl_status rl_progress_create(const char *label, FILE *stream, rl_progress **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_progress_create: out is NULL");
    rl_progress *p = rl_calloc(1, sizeof *p);
    if (!p)
        return RL_ERR_OUT_OF_MEMORY;
    p->label = rl_strdup(label ? label : "");
    if (!p->label) {
        free(p);
        return RL_ERR_OUT_OF_MEMORY;
    }
    p->stream = stream ? stream : stderr;
    p->tty = isatty(fileno(p->stream)) == 1;
    p->start_s = rl_time_s();
    p->delay_s = 1.0;
    atomic_init(&p->next_draw_s, p->start_s + p->delay_s);
    pthread_mutex_init(&p->lock, NULL);
    p->last_quarter = 0;
    *out = p;
    return RL_OK;
}

void rl_progress_set_delay(rl_progress *p, double seconds)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->delay_s = seconds > 0.0 ? seconds : 0.0;
    atomic_store(&p->next_draw_s, p->start_s + p->delay_s);
    pthread_mutex_unlock(&p->lock);
}

static void format_eta(char *buf, size_t n, double s)
{
    if (!isfinite(s) || s < 0.0)
        snprintf(buf, n, "?");
    else if (s < 60.0)
        snprintf(buf, n, "%.0fs", s);
    else if (s < 3600.0)
        snprintf(buf, n, "%dm%02ds", (int)(s / 60.0), (int)fmod(s, 60.0));
    else
        snprintf(buf, n, "%dh%02dm", (int)(s / 3600.0), (int)fmod(s / 60.0, 60.0));
}

static void draw_bar(rl_progress *p, double done, double now)
{
    int filled = (int)(done * BAR_WIDTH);
    char bar[BAR_WIDTH + 1];
    for (int i = 0; i < BAR_WIDTH; ++i)
        bar[i] = i < filled ? '#' : '.';
    bar[BAR_WIDTH] = '\0';
    /* Linear extrapolation of the elapsed time; unknown until some work is done. */
    double elapsed = now - p->start_s;
    char eta[32];
    format_eta(eta, sizeof eta, done > 0.0 ? elapsed * (1.0 - done) / done : NAN);
    fprintf(p->stream, "\r%s [%s] %3d%%  ETA %s  ", p->label, bar, (int)(done * 100.0), eta);
    fflush(p->stream);
}

bool rl_progress_update(void *progress, double done)
{
    rl_progress *p = progress;
    if (!p)
        return true;
    double now = rl_time_s();
    if (now < atomic_load_explicit(&p->next_draw_s, memory_order_relaxed))
        return true;
    done = isfinite(done) ? (done < 0.0 ? 0.0 : (done > 1.0 ? 1.0 : done)) : 0.0;
    pthread_mutex_lock(&p->lock);
    if (now >= atomic_load(&p->next_draw_s)) {
        if (p->tty) {
            draw_bar(p, done, now);
            p->drawn = true;
            atomic_store(&p->next_draw_s, now + REDRAW_INTERVAL_S);
        } else {
            int quarter = (int)(done * 4.0);
            if (quarter > p->last_quarter || !p->drawn) {
                fprintf(p->stream, "%s: %d%%\n", p->label, quarter * 25);
                fflush(p->stream);
                p->last_quarter = quarter;
                p->drawn = true;
            }
        }
        p->last_done = done;
    }
    pthread_mutex_unlock(&p->lock);
    return true;
}

void rl_progress_finish(rl_progress *p)
{
    if (!p)
        return;
    if (p->drawn && p->tty) {
        draw_bar(p, 1.0, rl_time_s());
        fputc('\n', p->stream);
        fflush(p->stream);
    }
    pthread_mutex_destroy(&p->lock);
    free(p->label);
    free(p);
}
