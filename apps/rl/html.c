/* html.c: see html.h. */
#include "html.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

struct html_doc {
    rl_output *out;
    FILE *f;                    /* out's stream */
};

void html_put_escaped(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

html_doc *html_begin(const char *path, const char *title)
{
    html_doc *h = calloc(1, sizeof *h);
    if (!h) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return NULL;
    }
    rl_clear_error();
    rl_status st = rl_output_open(path, &h->out);
    if (st != RL_OK) {
        free(h);
        cli_fail_status(RL_CLI_FAIL, st, path);
        return NULL;
    }
    h->f = rl_output_file(h->out);
    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>", h->f);
    html_put_escaped(h->f, title);
    fputs("</title>\n<style>\n"
          "body{font-family:sans-serif;margin:2em;color:#222;max-width:1400px}\n"
          "h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ddd}\n"
          "h3{font-size:1em}\n"
          "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
          "padding:.3em .6em;font-size:.85em;text-align:right}th{background:#f4f4f4}\n"
          "td:first-child,th:first-child{text-align:left}\n"
          ".row{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}\n"
          "figure{margin:0 0 1em 0}figcaption{font-size:.8em;color:#555;max-width:640px}\n"
          "svg{max-width:100%;height:auto}\n.s{color:#666;font-size:.9em}\n"
          "</style></head><body>\n<h1>", h->f);
    html_put_escaped(h->f, title);
    fputs("</h1>\n", h->f);
    return h;
}

void html_heading(html_doc *h, int level, const char *text)
{
    if (level < 1 || level > 3)
        level = 2;
    fprintf(h->f, "<h%d>", level);
    html_put_escaped(h->f, text);
    fprintf(h->f, "</h%d>\n", level);
}

void html_para(html_doc *h, const char *fmt, ...)
{
    char text[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    fputs("<p>", h->f);
    html_put_escaped(h->f, text);
    fputs("</p>\n", h->f);
}

void html_raw(html_doc *h, const char *markup) { fputs(markup, h->f); }

void html_escaped(html_doc *h, const char *text) { html_put_escaped(h->f, text); }

void html_svg(html_doc *h, const char *svg, const char *caption)
{
    fputs("<figure>", h->f);
    if (svg)
        fputs(svg, h->f);
    if (caption && *caption) {
        fputs("<figcaption>", h->f);
        html_put_escaped(h->f, caption);
        fputs("</figcaption>", h->f);
    }
    fputs("</figure>\n", h->f);
}

void html_row_begin(html_doc *h) { fputs("<div class=\"row\">\n", h->f); }
void html_row_end(html_doc *h) { fputs("</div>\n", h->f); }

static void put_cells(html_doc *h, const char *tag, const char *const *cells, int n)
{
    fputs("<tr>", h->f);
    for (int i = 0; i < n; i++) {
        fprintf(h->f, "<%s>", tag);
        html_put_escaped(h->f, cells[i]);
        fprintf(h->f, "</%s>", tag);
    }
    fputs("</tr>\n", h->f);
}

void html_table_begin(html_doc *h, const char *const *headers, int n)
{
    fputs("<table>\n", h->f);
    put_cells(h, "th", headers, n);
}

void html_table_row(html_doc *h, const char *const *cells, int n) { put_cells(h, "td", cells, n); }
void html_table_end(html_doc *h) { fputs("</table>\n", h->f); }

bool html_end(html_doc *h, const char *path)
{
    fputs("</body></html>\n", h->f);
    rl_clear_error();
    rl_status st = rl_output_commit(h->out);
    free(h);
    if (st != RL_OK)
        cli_fail_status(RL_CLI_FAIL, st, path);
    return st == RL_OK;
}
