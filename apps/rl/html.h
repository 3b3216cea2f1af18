/* html.h: a small writer of self-contained HTML reports (rl eval, rl
 * compare, bench reports): inline CSS, no scripts, no external resources.
 * Plots come as SVG text from rl_plot_* (which already makes their ids
 * unique per plot, see rl_plot.h) and are inlined. Errors are sticky:
 * check rl_html_end(). */
#ifndef RL_APP_HTML_H
#define RL_APP_HTML_H

#include <stdbool.h>
#include <stdio.h>

typedef struct rl_html rl_html;

/* Opens path and writes the head; prints the error and returns NULL on
 * failure. */
rl_html *rl_html_begin(const char *path, const char *title);
/* Headings h1..h3, escaped. */
void rl_html_heading(rl_html *h, int level, const char *text);
/* A paragraph of escaped, printf-formatted text. */
void rl_html_para(rl_html *h, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Markup written as is (the caller escapes). */
void rl_html_raw(rl_html *h, const char *markup);
void rl_html_escaped(rl_html *h, const char *text);
/* A figure: the SVG inlined, with an escaped caption (may be NULL). */
void rl_html_svg(rl_html *h, const char *svg, const char *caption);
/* Figures side by side until rl_html_row_end. */
void rl_html_row_begin(rl_html *h);
void rl_html_row_end(rl_html *h);
/* A table: header cells, then rows of cells (escaped text). */
void rl_html_table_begin(rl_html *h, const char *const *headers, int n);
void rl_html_table_row(rl_html *h, const char *const *cells, int n);
void rl_html_table_end(rl_html *h);
/* Closes the document and the file; false (error printed) when anything
 * failed to write. Frees h. */
bool rl_html_end(rl_html *h, const char *path);

/* HTML-escapes text into f (shared with the demo page). */
void rl_html_put_escaped(FILE *f, const char *text);

#endif
