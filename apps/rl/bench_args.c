/* bench_args.c: see bench_args.h. */
#include "bench_args.h"

#include "bench_util.h"
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool parse_real(const bench_opt *o, const char *text)
{
    char *end = NULL;
    double x = strtod(text, &end);
    if (!*text || *end || !isfinite(x) || x < o->lo || (o->lo_open && x <= o->lo) || x > o->hi) {
        if (o->expect)
            cli_fail(RL_CLI_USAGE, "%s: expected %s, got '%s'", o->name, o->expect, text);
        else
            cli_fail(RL_CLI_USAGE, "%s: expected a number in [%g, %g], got '%s'", o->name,
                        o->lo, o->hi, text);
        return false;
    }
    *o->real = x;
    return true;
}

/* Stores text per the row's kind; false when the error is printed. */
static bool take(const bench_opt *o, const char *text)
{
    switch (o->kind) {
    case RL_BENCH_OPT_COUNT:
        return bench_parse_count(o->name, text, o->max, o->count);
    case RL_BENCH_OPT_REAL:
        return parse_real(o, text);
    case RL_BENCH_OPT_STRING:
    case RL_BENCH_OPT_OUT:
        *o->string = text;
        return true;
    case RL_BENCH_OPT_SIZE:
        return cli_parse_size(text, o->width, o->height);
    case RL_BENCH_OPT_SECTIONS:
        return bench_parse_sections(text, o->names, o->num_names, o->sections);
    case RL_BENCH_OPT_CUSTOM:
        return o->parse(o->ctx, text);
    case RL_BENCH_OPT_FLAG:
        break;
    }
    return false;
}

/* The row argv[*i] names: 1 when taken (*i past its value), 0 when no row
 * matches, -1 on a usage error (printed). */
static int match(int argc, char **argv, int *i, const bench_opt *rows, int count)
{
    for (int r = 0; r < count; r++) {
        const bench_opt *o = &rows[r];
        if (o->kind == RL_BENCH_OPT_FLAG) {
            if (strcmp(argv[*i], o->name) != 0)
                continue;
            *o->flag = true;
        } else {
            const char *v = NULL;
            int m = cli_take_value(argc, argv, i, o->name, &v);
            if (m == 0)
                continue;
            if (m < 0 || !take(o, v))
                return -1;
        }
        if (o->set)
            *o->set = true;
        return 1;
    }
    return 0;
}

int bench_parse_args(int argc, char **argv, const char *command, const char *help,
                        const bench_opt *rows, int count)
{
    for (int i = 2; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            fputs(help, stdout);
            return RL_BENCH_HELP_SHOWN;
        }
        int m = match(argc, argv, &i, rows, count);
        if (m < 0)
            return RL_CLI_USAGE;
        if (m == 0)
            return cli_unknown_arg(command, argv[i]);
    }
    for (int r = 0; r < count; r++) {
        const char *out = rows[r].kind == RL_BENCH_OPT_OUT ? *rows[r].string : NULL;
        if (out && !cli_has_extension(out, (const char *const[]){ ".json", NULL }))
            return cli_fail(RL_CLI_USAGE, "%s: '%s' should end in .json", rows[r].name, out);
    }
    return RL_CLI_OK;
}
