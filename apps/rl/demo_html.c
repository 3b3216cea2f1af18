/* demo_html.c: the demo's index.html, written from the same cJSON object as
 * report.json so that the page and the data cannot disagree. One table row
 * per scene, one column per renderer; each cell shows the image and its
 * numbers. Self-contained: inline CSS, no scripts, no external resources;
 * the images are the PNGs next to the page. */
#include "cli.h"
#include "html.h"

#include <cjson/cJSON.h>
#include <string.h>

static const char *str(const cJSON *obj, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    return cJSON_IsString(item) ? item->valuestring : "";
}

static double num(const cJSON *obj, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    return cJSON_IsNumber(item) ? item->valuedouble : 0.0;
}

/* Column headers: renderer names in first-seen order. */
static int collect_algos(const cJSON *images, const char **algos, int max)
{
    int n = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, images) {
        const char *a = str(e, "algorithm");
        int k = 0;
        while (k < n && strcmp(algos[k], a) != 0)
            k++;
        if (k == n && n < max)
            algos[n++] = a;
    }
    return n;
}

static void put_cell(FILE *f, const cJSON *e)
{
    const cJSON *rs = cJSON_GetObjectItemCaseSensitive(e, "render_stats");
    const cJSON *ss = cJSON_GetObjectItemCaseSensitive(e, "scene_stats");
    fputs("<td><a href=\"", f);
    html_put_escaped(f, str(e, "file"));
    fputs("\"><img src=\"", f);
    html_put_escaped(f, str(e, "file"));
    fputs("\" alt=\"", f);
    html_put_escaped(f, str(e, "file"));
    /* Preparation apart from the frame: one-time work is not a frame's cost. */
    fprintf(f, "\"></a><br>prep %.1f ms &middot; frame %.1f ms", num(rs, "prep_ms"), num(rs, "frame_ms"));
    if (num(rs, "triangles_rasterized") > 0)
        fprintf(f, " &middot; %.0f triangles rasterized", num(rs, "triangles_rasterized"));
    fprintf(f, " &middot; %.0f pixels written", num(rs, "pixels_written"));
    if (num(rs, "rays_total") > 0)
        fprintf(f, " &middot; %.0f rays", num(rs, "rays_total"));
    double lights = num(ss, "lights");
    fprintf(f, "<br><span class=\"s\">scene: %.0f triangles, %.0f objects, %.0f light%s</span>",
            num(ss, "triangles"), num(ss, "objects"), lights, lights == 1.0 ? "" : "s");
    fputs("</td>", f);
}

bool cli_write_demo_html(const cJSON *report, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        cli_fail(RL_CLI_FAIL, "%s: cannot write", path);
        return false;
    }
    const cJSON *images = cJSON_GetObjectItemCaseSensitive(report, "images");
    const cJSON *failures = cJSON_GetObjectItemCaseSensitive(report, "failures");
    const cJSON *machine = cJSON_GetObjectItemCaseSensitive(report, "machine");
    const char *algos[64];
    int num_algos = collect_algos(images, algos, 64);

    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
          "<title>renderlab demo</title>\n<style>\n"
          "body{font-family:sans-serif;margin:2em;color:#222}\n"
          "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.5em;"
          "vertical-align:top;font-size:.85em}\n"
          "img{max-width:480px;display:block;image-rendering:pixelated}\n"
          ".s{color:#666}\n</style></head><body>\n<h1>renderlab demo</h1>\n<p>",
          f);
    fputs("renderlab ", f);
    html_put_escaped(f, str(report, "renderlab"));
    fputs(" &middot; ", f);
    html_put_escaped(f, str(report, "date"));
    fprintf(f, " &middot; %.0fx%.0f<br>machine: ", num(report, "width"), num(report, "height"));
    html_put_escaped(f, str(machine, "uname"));
    fputs(" &middot; ", f);
    html_put_escaped(f, str(machine, "cpu"));
    fprintf(f, " &middot; %.0f processors<br>build: ", num(machine, "nproc"));
    html_put_escaped(f, str(report, "build"));
    fputs("<br>command: <code>", f);
    html_put_escaped(f, str(report, "command"));
    fputs("</code><br>Times: <em>prep</em> is the one-time preparation of a renderer for the scene "
          "(sampled inputs, acceleration structures, octrees, surfels, visible sets), <em>frame</em> the "
          "rest of the first frame.</p>\n", f);

    fputs("<table>\n<tr><th>scene</th>", f);
    for (int k = 0; k < num_algos; k++) {
        fputs("<th>", f);
        html_put_escaped(f, algos[k]);
        fputs("</th>", f);
    }
    fputs("</tr>\n", f);
    /* Images come scene by scene; a new scene starts a new row and every
     * renderer keeps its column even when one of them failed. */
    const char *row = NULL;
    int col = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, images) {
        const char *scene = str(e, "scene");
        if (!row || strcmp(row, scene) != 0) {
            if (row)
                fputs("</tr>\n", f);
            fputs("<tr><th>", f);
            html_put_escaped(f, scene);
            fputs("</th>", f);
            row = scene;
            col = 0;
        }
        while (col < num_algos && strcmp(algos[col], str(e, "algorithm")) != 0) {
            fputs("<td></td>", f);
            col++;
        }
        put_cell(f, e);
        col++;
    }
    if (row)
        fputs("</tr>\n", f);
    fputs("</table>\n", f);
    if (cJSON_GetArraySize(failures) > 0) {
        fputs("<h2>failures</h2>\n<ul>\n", f);
        cJSON_ArrayForEach(e, failures) {
            fputs("<li>", f);
            html_put_escaped(f, str(e, "scene"));
            fputs(" ", f);
            html_put_escaped(f, str(e, "algorithm"));
            fputs(": ", f);
            html_put_escaped(f, str(e, "error"));
            fputs("</li>\n", f);
        }
        fputs("</ul>\n", f);
    }
    const cJSON *changes = cJSON_GetObjectItemCaseSensitive(report, "changes");
    if (cJSON_GetArraySize(changes) > 0) {
        fputs("<h2>Changed on purpose</h2>\n<p>Defaults that changed, drawn again with the old value "
              "where that changes the image: now on the left, before on the right.</p>\n<table>\n"
              "<tr><th>scene, renderer</th><th>now</th><th>before</th><th>difference</th></tr>\n", f);
        cJSON_ArrayForEach(e, changes) {
            fputs("<tr><th>", f);
            html_put_escaped(f, str(e, "scene"));
            fputs(", ", f);
            html_put_escaped(f, str(e, "algorithm"));
            fputs("</th><td><img src=\"", f);
            html_put_escaped(f, str(e, "file_now"));
            fputs("\" alt=\"now\"></td><td><img src=\"", f);
            html_put_escaped(f, str(e, "file_before"));
            fputs("\" alt=\"before\"></td><td>", f);
            html_put_escaped(f, str(e, "option"));
            fputs(" = ", f);
            html_put_escaped(f, str(e, "before"));
            fprintf(f, " before<br>RMSE %.4f, SSIM %.4f<br><span class=\"s\">", num(e, "rmse"), num(e, "ssim"));
            html_put_escaped(f, str(e, "what"));
            fputs("</span></td></tr>\n", f);
        }
        fputs("</table>\n", f);
    }
    if (*str(report, "compare")) {
        fputs("<p>The renderers compared over a sampled region of the scene (time, rays, "
              "triangles, image quality; Jähn 2015): <a href=\"", f);
        html_put_escaped(f, str(report, "compare"));
        fputs("\">comparison report</a>.</p>\n", f);
    }
    fputs("<p class=\"s\">Data: <a href=\"report.json\">report.json</a></p>\n"
          "</body></html>\n", f);
    bool ok = !ferror(f);
    if (fclose(f) != 0)
        ok = false;
    if (!ok)
        cli_fail(RL_CLI_FAIL, "%s: cannot write", path);
    return ok;
}
