/* demo_html.c: the demo's index.html, written from the same cJSON object as
 * report.json so that the page and the data cannot disagree. One section
 * per scene, a grid of cards in it, one per renderer: the image scaled to
 * its card (linked to the full size), marked exact or approximate with its
 * error against the reference, and its numbers. Self-contained: inline
 * CSS, no scripts, no external resources; the images are the PNGs next to
 * the page. */
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

/* Renderer names in first-seen order: every scene's cards come in this
 * order, so a renderer keeps its place from scene to scene. */
static int collect_names(const cJSON *items, const char *key, const char **names, int max)
{
    int n = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, items) {
        const char *a = str(e, key);
        int k = 0;
        while (k < n && strcmp(names[k], a) != 0)
            k++;
        if (k == n && n < max)
            names[n++] = a;
    }
    return n;
}

static const cJSON *find_image(const cJSON *images, const char *scene, const char *algo)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, images)
        if (strcmp(str(e, "scene"), scene) == 0 && strcmp(str(e, "algorithm"), algo) == 0)
            return e;
    return NULL;
}

/* One image as a card: the thumbnail links to the full image; its mark,
 * its error against the reference, why it differs, and its numbers. */
static void put_card(FILE *f, const cJSON *e)
{
    const cJSON *rs = cJSON_GetObjectItemCaseSensitive(e, "render_stats");
    const cJSON *err = cJSON_GetObjectItemCaseSensitive(e, "error");
    const char *mark = str(e, "accuracy");
    fputs("<figure><a href=\"", f);
    html_put_escaped(f, str(e, "file"));
    fputs("\"><img src=\"", f);
    html_put_escaped(f, str(e, "file"));
    fputs("\" alt=\"", f);
    html_put_escaped(f, str(e, "file"));
    fputs("\"></a><figcaption><b>", f);
    html_put_escaped(f, str(e, "algorithm"));
    fputs("</b> <span class=\"mark ", f);
    html_put_escaped(f, mark);
    fputs("\">", f);
    html_put_escaped(f, *mark ? mark : "unmarked");
    fputs("</span> ", f);
    if (cJSON_GetObjectItemCaseSensitive(err, "rmse"))
        fprintf(f, "RMSE %.4f &middot; SSIM %.4f", num(err, "rmse"), num(err, "ssim"));
    else
        fputs("error: no reference image", f);
    fputs("<br><span class=\"s\">", f);
    html_put_escaped(f, str(e, "note"));
    /* Preparation apart from the frame: one-time work is not a frame's cost. */
    fprintf(f, "</span><br>prep %.1f ms &middot; frame %.1f ms", num(rs, "prep_ms"), num(rs, "frame_ms"));
    if (num(rs, "triangles_rasterized") > 0)
        fprintf(f, " &middot; %.0f triangles rasterized", num(rs, "triangles_rasterized"));
    fprintf(f, " &middot; %.0f pixels written", num(rs, "pixels_written"));
    if (num(rs, "rays_total") > 0)
        fprintf(f, " &middot; %.0f rays", num(rs, "rays_total"));
    fputs("</figcaption></figure>\n", f);
}

/* A scene: heading, what it is, then a grid of cards that wraps to the
 * screen's width (the one-row-per-scene table was about 4,600 px wide). */
static void put_scene(FILE *f, const cJSON *report, const char *scene, const char *const *algos, int num_algos)
{
    const cJSON *images = cJSON_GetObjectItemCaseSensitive(report, "images");
    const cJSON *first = NULL, *e;
    cJSON_ArrayForEach(e, images)
        if (!first && strcmp(str(e, "scene"), scene) == 0)
            first = e;
    fputs("<h2>", f);
    html_put_escaped(f, scene);
    fputs("</h2>\n<p class=\"s\">", f);
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(report, "scenes"))
        if (strcmp(str(e, "name"), scene) == 0 && !cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(e, "builtin"))) {
            fputs("file: <code>", f);
            html_put_escaped(f, str(e, "source"));
            fputs("</code> &middot; ", f);
        }
    const cJSON *ss = cJSON_GetObjectItemCaseSensitive(first, "scene_stats");
    double lights = num(ss, "lights");
    fprintf(f, "%.0f triangles, %.0f objects, %.0f light%s</p>\n<div class=\"grid\">\n", num(ss, "triangles"),
            num(ss, "objects"), lights, lights == 1.0 ? "" : "s");
    for (int k = 0; k < num_algos; k++) {
        const cJSON *img = find_image(images, scene, algos[k]);
        if (img)
            put_card(f, img);
        else {
            fputs("<figure class=\"failed\"><figcaption><b>", f);
            html_put_escaped(f, algos[k]);
            fputs("</b> failed (see failures)</figcaption></figure>\n", f);
        }
    }
    fputs("</div>\n", f);
}

bool cli_write_demo_html(const cJSON *report, const char *path)
{
    rl_output *o = NULL;
    rl_clear_error();
    rl_status st = rl_output_open(path, &o);
    if (st != RL_OK) {
        cli_fail_status(RL_CLI_FAIL, st, path);
        return false;
    }
    FILE *f = rl_output_file(o);
    const cJSON *images = cJSON_GetObjectItemCaseSensitive(report, "images");
    const cJSON *failures = cJSON_GetObjectItemCaseSensitive(report, "failures");
    const cJSON *machine = cJSON_GetObjectItemCaseSensitive(report, "machine");
    const char *algos[64], *scenes[256];
    int num_algos = collect_names(images, "algorithm", algos, 64);
    int num_scenes = collect_names(images, "scene", scenes, 256);

    /* No fixed width: images shrink to their card, cards wrap, the
     * comparison table shares the page's width. */
    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
          "<meta name=\"viewport\" content=\"width=device-width\">\n"
          "<title>renderlab demo</title>\n<style>\n"
          "body{font-family:sans-serif;margin:2em;color:#222}\n"
          ".grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:1em}\n"
          "figure{margin:0;border:1px solid #ccc;padding:.5em;font-size:.85em}\n"
          "figcaption{margin-top:.4em}\n"
          "img{max-width:100%;height:auto;display:block}\n"
          ".mark{padding:0 .4em;border-radius:.3em;font-weight:bold}\n"
          ".exact{background:#cfeccf}.approximate{background:#f7e2b5}\n"
          "table{border-collapse:collapse;width:100%;table-layout:fixed}td,th{border:1px solid #ccc;"
          "padding:.5em;vertical-align:top;font-size:.85em}\n"
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
          "rest of the first frame.<br>Marks: <span class=\"mark exact\">exact</span> is the scene's "
          "reference, ", f);
    html_put_escaped(f, str(report, "reference"));
    fputs(" at its defaults, or an image equal to it; <span class=\"mark approximate\">approximate</span> "
          "any other. The error of each image is against the reference: RMSE of the sRGB values in [0, 1] "
          "and SSIM on luma (Wang et al. 2004). Click an image for its full size.</p>\n", f);

    for (int i = 0; i < num_scenes; i++)
        put_scene(f, report, scenes[i], algos, num_algos);
    const cJSON *e;
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
    /* pt and bdpt at equal time: one row per Cornell box, pt left. */
    const cJSON *eq = cJSON_GetObjectItemCaseSensitive(report, "equal_time");
    if (cJSON_GetArraySize(eq) > 0) {
        fprintf(f, "<h2>pt and bdpt at equal time</h2>\n<p>The Cornell box lit directly (variant=bitterli) "
                   "and lit only by light bounced off the plate under the lamp (variant=shade). Each renderer "
                   "accumulated samples until its CPU time per thread reached %.2f s, after an uncounted first "
                   "frame (its BVH and light tables). Where light arrives by bounces, bdpt's connections find "
                   "it; where it arrives directly, pt's cheaper samples win. The samples reached, and so these "
                   "images, depend on the machine. <code>rl bench pt --only bdpt</code> measures the error "
                   "against a reference.</p>\n<table>\n<tr><th>scene</th><th>pt</th><th>bdpt</th></tr>\n",
                num(report, "equal_time_s"));
        const char *variants[8];
        int nv = collect_names(eq, "variant", variants, 8);
        for (int v = 0; v < nv; v++) {
            fputs("<tr><th>cornell:variant=", f);
            html_put_escaped(f, variants[v]);
            fputs("</th>", f);
            static const char *const algos_eq[2] = { "pt", "bdpt" };
            for (int k = 0; k < 2; k++) {
                const cJSON *hit = NULL;
                cJSON_ArrayForEach(e, eq) {
                    if (strcmp(str(e, "variant"), variants[v]) == 0 && strcmp(str(e, "algorithm"), algos_eq[k]) == 0)
                        hit = e;
                }
                fputs("<td>", f);
                if (hit) {
                    fputs("<a href=\"", f);
                    html_put_escaped(f, str(hit, "file"));
                    fputs("\"><img src=\"", f);
                    html_put_escaped(f, str(hit, "file"));
                    fprintf(f, "\" alt=\"%s\"></a>%.0f spp in %.2f s CPU per thread (%.2f s wall, %.0f threads)",
                            algos_eq[k], num(hit, "spp"), num(hit, "cpu_s_per_thread"), num(hit, "wall_ms") / 1e3,
                            num(hit, "threads"));
                } else {
                    fputs("failed", f);
                }
                fputs("</td>", f);
            }
            fputs("</tr>\n", f);
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
    rl_clear_error();
    st = rl_output_commit(o);
    if (st != RL_OK)
        cli_fail_status(RL_CLI_FAIL, st, path);
    return st == RL_OK;
}
