/* interrupt.c: Ctrl-C during a render. The first SIGINT only raises a
 * flag (the render's progress callback turns it into a cancel, and the
 * command saves what it has); the handler is installed with SA_RESETHAND,
 * so a second Ctrl-C finds the default action and ends the process at once
 * for a user who does not want to wait. A SIGINT that the parent set to be
 * ignored (a background job of a script without job control) stays
 * ignored: that is the parent's request that Ctrl-C at the terminal should
 * not reach us. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <signal.h>
#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

/* Lock-free atomics are the C11 objects a signal handler may write. */
static atomic_int interrupted;
static const char *notice;
static size_t notice_len;
static struct sigaction previous;
static bool installed;

static void on_sigint(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
    /* write(2) is async-signal-safe, stdio is not; the user learns at once
     * that the key was seen, even while a frame still has to finish. */
    if (notice_len) {
        ssize_t n = write(STDERR_FILENO, notice, notice_len);
        (void)n;
    }
}

void cli_interrupt_begin(const char *message)
{
    atomic_store(&interrupted, 0);
    notice = message;
    notice_len = message ? strlen(message) : 0;
    if (installed || sigaction(SIGINT, NULL, &previous) != 0 || previous.sa_handler == SIG_IGN)
        return;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    installed = sigaction(SIGINT, &sa, NULL) == 0;
}

bool cli_interrupted(void)
{
    return atomic_load(&interrupted) != 0;
}

void cli_interrupt_end(void)
{
    if (installed)
        sigaction(SIGINT, &previous, NULL);
    installed = false;
    notice_len = 0;
}
