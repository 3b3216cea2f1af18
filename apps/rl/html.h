/* html.h: a small writer of self-contained HTML reports (rl eval, rl
 * compare, bench reports): inline CSS, no scripts, no external resources.
 * Plots come as SVG text from rl_plot_* (which already makes their ids
 * unique per plot, see rl_plot.h) and are inlined. Errors are sticky:
 * check html_end(). */
#ifndef RL_APP_HTML_H
#define RL_APP_HTML_H

#include <stdbool.h>
#include <stdio.h>

typedef struct html_doc html_doc;

/* Opens path and writes the head; prints the error and returns NULL on
 * failure. */
html_doc *html_begin(const char *path, const char *title);
/* Headings h1..h3, escaped. */
void html_heading(html_doc *h, int level, const char *text);
/* A paragraph of escaped, printf-formatted text. */
void html_para(html_doc *h, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Markup written as is (the caller escapes). */
void html_raw(html_doc *h, const char *markup);
void html_escaped(html_doc *h, const char *text);
/* A figure: the SVG inlined, with an escaped caption (may be NULL). */
void html_svg(html_doc *h, const char *svg, const char *caption);
/* Figures side by side until html_row_end. */
void html_row_begin(html_doc *h);
void html_row_end(html_doc *h);
/* A table: header cells, then rows of cells (escaped text). */
void html_table_begin(html_doc *h, const char *const *headers, int n);
void html_table_row(html_doc *h, const char *const *cells, int n);
void html_table_end(html_doc *h);
/* Closes the document and the file; false (error printed) when anything
 * failed to write. Frees h. */
bool html_end(html_doc *h, const char *path);

/* HTML-escapes text into f (shared with the demo page). */
void html_put_escaped(FILE *f, const char *text);

#endif
