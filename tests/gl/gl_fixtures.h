/* gl_fixtures.h: what the GL tests share: whether this machine can make a
 * GL 4.5 context (found once per test program by find_gl, the group
 * setup) and NEED_GL(), which skips a case where it cannot. Include after
 * <cmocka.h>. */
#ifndef RL_TESTS_GL_FIXTURES_H
#define RL_TESTS_GL_FIXTURES_H

#include <stdbool.h>

#include "rl/rl_gl.h"

static bool have_gl;

static int find_gl(void **state)
{
    (void)state;
    char why[256];
    have_gl = rl_gl_available(NULL, why, sizeof why);
    if (!have_gl)
        print_message("no OpenGL 4.5 context (%s): the GL cases skip\n", why);
    return 0;
}

#define NEED_GL()                                                                                              \
    do {                                                                                                       \
        if (!have_gl)                                                                                          \
            skip();                                                                                            \
    } while (0)

#endif
