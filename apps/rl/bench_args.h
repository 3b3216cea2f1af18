/* bench_args.h: the option parser every `rl bench` subcommand shares.
 *
 * A subcommand describes its options as a table of rows (name, kind, where
 * the value goes, an optional "was given" flag) and calls bench_parse_args
 * once. The parser walks argv from index 2 (argv[0] "bench", argv[1] the
 * benchmark), matches "--name VALUE" and "--name=VALUE" with
 * cli_take_value, and checks each value as it comes, so the first bad
 * argument is the one reported. Defaults, including those that depend on
 * --quick, stay with the caller: the parser only writes what was given. */
#ifndef RL_APP_BENCH_ARGS_H
#define RL_APP_BENCH_ARGS_H

#include <stdbool.h>

typedef enum bench_opt_kind {
    RL_BENCH_OPT_FLAG,      /* no value: *flag = true */
    RL_BENCH_OPT_COUNT,     /* whole number in 1..max (bench_parse_count) */
    RL_BENCH_OPT_REAL,      /* finite number in lo..hi */
    RL_BENCH_OPT_STRING,    /* *string points into argv */
    RL_BENCH_OPT_OUT,       /* like STRING; must end in .json (checked after all options) */
    RL_BENCH_OPT_SIZE,      /* "WxH" (cli_parse_size) into *width, *height */
    RL_BENCH_OPT_SECTIONS,  /* --only: names[0..count-1] as bits (bench_parse_sections) */
    RL_BENCH_OPT_CUSTOM,    /* parse(ctx, value); false when it printed the error */
} bench_opt_kind;

typedef struct bench_opt {
    const char *name;               /* "--threads" */
    bench_opt_kind kind;
    bool *set;                      /* optional: true once the option was given */
    /* The destination of the row's kind (one of these). */
    bool *flag;
    long long *count;
    double *real;
    const char **string;
    int *width, *height;
    unsigned *sections;
    /* COUNT: the largest value. */
    long long max;
    /* REAL: the range; lo_open excludes lo itself. The error reads
     * "NAME: expected EXPECT, got 'VALUE'", EXPECT defaulting to
     * "a number in [lo, hi]". */
    double lo, hi;
    bool lo_open;
    const char *expect;
    /* SECTIONS: the section names. */
    const char *const *names;
    int num_names;
    /* CUSTOM */
    bool (*parse)(void *ctx, const char *value);
    void *ctx;
} bench_opt;

/* Rows for the common kinds; anything else is written out with designated
 * initializers. */
#define RL_BENCH_FLAG(name_, dest) { .name = (name_), .kind = RL_BENCH_OPT_FLAG, .flag = (dest) }
#define RL_BENCH_COUNT(name_, max_, dest, set_)                                                   \
    { .name = (name_), .kind = RL_BENCH_OPT_COUNT, .count = (dest), .max = (max_), .set = (set_) }
#define RL_BENCH_REAL(name_, lo_, hi_, dest, set_)                                                \
    { .name = (name_), .kind = RL_BENCH_OPT_REAL, .real = (dest), .lo = (lo_), .hi = (hi_),     \
      .set = (set_) }
#define RL_BENCH_STRING(name_, dest) { .name = (name_), .kind = RL_BENCH_OPT_STRING, .string = (dest) }
#define RL_BENCH_OUT(dest) { .name = "--out", .kind = RL_BENCH_OPT_OUT, .string = (dest) }
#define RL_BENCH_SIZE(name_, w, h, set_)                                                          \
    { .name = (name_), .kind = RL_BENCH_OPT_SIZE, .width = (w), .height = (h), .set = (set_) }
#define RL_BENCH_SECTIONS(names_, count_, dest)                                                   \
    { .name = "--only", .kind = RL_BENCH_OPT_SECTIONS, .sections = (dest), .names = (names_),   \
      .num_names = (count_) }
#define RL_BENCH_CUSTOM(name_, fn, ctx_, set_)                                                    \
    { .name = (name_), .kind = RL_BENCH_OPT_CUSTOM, .parse = (fn), .ctx = (ctx_), .set = (set_) }

/* Returned after -h/--help printed help; the subcommand then exits 0. */
#define RL_BENCH_HELP_SHOWN (-1)

/* Parses argv[2..argc-1] against rows[0..count-1]. -h/--help prints help to
 * stdout and returns RL_BENCH_HELP_SHOWN; an unknown argument is reported by
 * cli_unknown_arg(command, ...), a missing or bad value with one error
 * line; both return RL_CLI_USAGE. Returns RL_CLI_OK otherwise. */
int bench_parse_args(int argc, char **argv, const char *command, const char *help,
                        const bench_opt *rows, int count);

#endif
