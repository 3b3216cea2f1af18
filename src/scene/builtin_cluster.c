/* builtin_cluster.c: the "cluster" scene, a vehicle instrument cluster behind
 * a curved cover glass: the application of Ullmann 2003, Sec. 5.4
 * (Fig. 5.16-5.21), where the readability of a car's instrument cluster is
 * judged in VR and only the cover glass ("Abdeckscheibe") is vertex traced.
 *
 * Layout (metres, y up, the driver looks along -z): a dark dashboard with a
 * recess holding the cluster, tilted 15 degrees back. In the cluster: a
 * housing with hood and lower lip, a speedometer (0-240 km/h) and a
 * tachometer (0-8 x1000/min, red zone from 6.5) as flat discs whose printed
 * scales are procedural textures (ticks, 5x7 digits from glyphs.c), red
 * needles at the angles of params speed and rpm, hubs, chrome bezels and four
 * warning lights; in front a cylindrically curved cover glass bulging
 * towards the driver, 3 mm thick and closed (outer, inner and rim faces),
 * k_r 0.09, k_t 0.85, ior 1.5: the only node with "vt" = "true". The upper
 * rim of the steering wheel shows at the bottom of the driver's view.
 *
 * Lights: an emissive "sky" quad (plus an RL_LIGHT_QUAD at the same place)
 * above and behind the driver, placed where the mirror direction of the
 * driver's view off the glass points, so the glass shows its reflection as a
 * band. The dials are lit from inside the housing, by four small point lights
 * under the hood and behind the lower lip (two per dial). Deviation from the
 * brief of one interior light: the tracer's shadow feelers are blocked by the
 * transmissive cover glass (hard shadows as in the thesis' tracer), so the
 * instrument lighting has to sit inside the glass, and a single light there,
 * a few centimetres from the dials, lights them too unevenly.
 *
 * Cameras: "driver" (Fig. 5.16), "lateral" (Fig. 5.18), "zoom" (Fig. 5.21);
 * the camera path moves the driver's head sideways and slightly up and down
 * over 4 s, so the reflections move over the dials. */
#include "scene/builtin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "scene/generators.h"
#include "scene/glyphs.h"
#include "scene/lathe.h"

#define TILT_DEG 15.0f          /* cluster leans back by this much */
#define DIAL_R 0.075f           /* dial radius */
#define DIAL_X 0.095f           /* dial centres at x = -/+ DIAL_X */
#define SWEEP_START_DEG 225.0f  /* scale zero, counter-clockwise from +x */
#define SWEEP_DEG 270.0f        /* full scale runs clockwise over this */
#define GLASS_HALF_W 0.205f     /* cover glass, half width */
#define GLASS_HALF_H 0.106f     /* half height */
#define GLASS_APEX_Z 0.10f      /* outer surface at x = 0 */
#define GLASS_SAG 0.03f         /* apex minus edge depth: the bulge */
#define GLASS_THICK 0.003f
#define SKY_RADIANCE 2.0f       /* emitted by the sky quad (blue channel) */
#define PATH_SECONDS 4.0
#define PATH_KEYS 17

typedef struct cluster_params {
    double speed, rpm, detail;
    long long tex, glass_segments;
} cluster_params;

typedef struct cluster_materials {
    uint32_t plastic, dash, dial_speed, dial_rpm, needle, chrome, hub, glass, wheel, sky;
    uint32_t warn[4];
} cluster_materials;

typedef struct cluster {
    rl_scene *scene;
    cluster_params p;
    cluster_materials m;
    uint32_t group;             /* the tilted cluster node */
    rl_mat4 frame;              /* its transform */
} cluster;

/* A scale printed on a dial: values 0..max, ticks every minor, labels every
 * major (value / divisor), a red zone from red_from (>= max: none). */
typedef struct dial_scale {
    double max, major, minor, divisor, red_from;
    float label_h;              /* digit height, dial radii */
    const char *unit;
} dial_scale;

static const dial_scale speed_scale = { 240.0, 20.0, 10.0, 1.0, 1e9, 0.085f, "km/h" };
static const dial_scale rpm_scale = { 8.0, 1.0, 0.25, 1.0, 6.5, 0.14f, "x1000/min" };

static uint32_t tess(const cluster *c, float base, uint32_t min)
{
    float n = roundf(base * (float)c->p.detail);
    return n < (float)min ? min : (uint32_t)n;
}

/* Needle angle (degrees, counter-clockwise from +x) for a value. */
static float scale_angle(const dial_scale *sc, double value)
{
    return SWEEP_START_DEG - SWEEP_DEG * (float)(value / sc->max);
}

/* Coverage of [lo, hi] at x for a pixel of size px: a box filter. */
static float cover(float x, float lo, float hi, float px)
{
    float a = rl_clampf((x - lo) / px + 0.5f, 0.0f, 1.0f);
    float b = rl_clampf((hi - x) / px + 0.5f, 0.0f, 1.0f);
    return a * b;
}

static void blend(rl_vec4 *t, rl_vec3 c, float a)
{
    *t = rl_v4(rl_lerpf(t->x, c.x, a), rl_lerpf(t->y, c.y, a), rl_lerpf(t->z, c.z, a), 1.0f);
}

/* Paints one dial face into n x n texels: uv (0,0)..(1,1) maps to the
 * square around the disc, dial radius 1. Ticks and zone are evaluated per
 * texel from the nearest tick (ticks are uniform in angle), labels are
 * splatted with the 5x7 font. */
static void paint_dial(rl_vec4 *texels, int n, const dial_scale *sc)
{
    const float px = 2.0f / (float)n;                   /* texel size, dial radii */
    const float step_deg = SWEEP_DEG * (float)(sc->minor / sc->max);
    const int ticks = (int)lround(sc->max / sc->minor);
    const int per_major = (int)lround(sc->major / sc->minor);
    const rl_vec3 white = rl_v3(0.92f, 0.92f, 0.90f), red = rl_v3(0.85f, 0.06f, 0.04f);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            float X = ((float)x + 0.5f) * px - 1.0f, Y = 1.0f - ((float)y + 0.5f) * px;
            float r = sqrtf(X * X + Y * Y);
            rl_vec4 *t = &texels[(size_t)y * (size_t)n + (size_t)x];
            *t = rl_v4(0.015f, 0.015f, 0.02f, 1.0f);
            blend(t, rl_v3s(0.35f), cover(r, 0.975f, 0.995f, px));   /* rim ring */
            /* phi: degrees along the scale from zero, the gap mapped negative. */
            float phi = fmodf(SWEEP_START_DEG - rl_degrees(atan2f(Y, X)) + 720.0f, 360.0f);
            if (phi > 0.5f * (360.0f + SWEEP_DEG))
                phi -= 360.0f;
            float value_phi = phi;
            int k = (int)lroundf(phi / step_deg);
            k = k < 0 ? 0 : (k > ticks ? ticks : k);
            bool major = k % per_major == 0;
            bool in_red = (double)k * sc->minor >= sc->red_from;
            float dphi = rl_radians(phi - (float)k * step_deg);
            float across = r * fabsf(sinf(dphi));
            float half_w = major ? 0.014f : 0.007f, r_in = major ? 0.78f : 0.86f;
            float a = cover(across, -half_w, half_w, px) * cover(r, r_in, 0.95f, px);
            if (cosf(dphi) > 0.0f)
                blend(t, in_red ? red : white, a);
            /* Red zone: a band outside the ticks. */
            float red_phi = SWEEP_DEG * (float)(sc->red_from / sc->max);
            if (sc->red_from < sc->max)
                blend(t, red, cover(r, 0.955f, 0.985f, px) *
                                  cover(value_phi, red_phi, SWEEP_DEG, rl_degrees(px / rl_maxf(r, px))));
        }
    const float to_px = 0.5f * (float)n;
    for (int k = 0; (double)k * sc->major <= sc->max + 1e-9; ++k) {
        char label[16];
        snprintf(label, sizeof label, "%d", (int)lround((double)k * sc->major / sc->divisor));
        float ang = rl_radians(scale_angle(sc, (double)k * sc->major));
        float lx = 0.60f * cosf(ang), ly = 0.60f * sinf(ang);
        rl_glyphs_draw(texels, n, n, label, (lx + 1.0f) * to_px, (1.0f - ly) * to_px,
                       sc->label_h * to_px, rl_v4(0.92f, 0.92f, 0.90f, 1.0f));
    }
    rl_glyphs_draw(texels, n, n, sc->unit, to_px, 1.38f * to_px, 0.07f * to_px,
                   rl_v4(0.7f, 0.7f, 0.7f, 1.0f));
}

static rl_status add_dial_texture(rl_scene *scene, int n, const dial_scale *sc, uint32_t *id)
{
    rl_vec4 *texels = rl_alloc((size_t)n * (size_t)n * sizeof *texels);
    if (!texels)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "cluster: no memory for a %d x %d dial texture", n, n);
    paint_dial(texels, n, sc);
    rl_status s = rl_builtin_texture(scene, n, n, texels, id);
    free(texels);
    return s;
}


static rl_material emitter(const char *name, rl_vec3 radiance)
{
    rl_material m = rl_builtin_phong(name, rl_v3s(0.0f), 0.0f, 1.0f);
    m.emission = radiance;
    return m;
}

static rl_status add_materials(cluster *c)
{
    uint32_t speed_tex, rpm_tex;
    int n = (int)c->p.tex;
    rl_status s = add_dial_texture(c->scene, n, &speed_scale, &speed_tex);
    if (!s) s = add_dial_texture(c->scene, n, &rpm_scale, &rpm_tex);
    if (s)
        return s;
    rl_material dial_speed = rl_builtin_phong("dial_speed", rl_v3s(1.0f), 0.05f, 10.0f);
    dial_speed.diffuse_texture = speed_tex;
    rl_material dial_rpm = dial_speed;
    snprintf(dial_rpm.name, sizeof dial_rpm.name, "dial_rpm");
    dial_rpm.diffuse_texture = rpm_tex;
    /* Needles glow faintly, as lit needles do. */
    rl_material needle = rl_builtin_phong("needle", rl_v3(0.80f, 0.05f, 0.02f), 0.4f, 40.0f);
    needle.emission = rl_v3(0.25f, 0.02f, 0.0f);
    rl_material chrome = rl_builtin_phong("chrome", rl_v3s(0.15f), 0.8f, 150.0f);
    chrome.reflectivity = 0.5f;
    rl_material glass = rl_builtin_phong("cover_glass", rl_v3s(0.01f), 0.25f, 400.0f);
    glass.reflectivity = 0.09f;
    glass.transmissivity = 0.85f;
    glass.ior = 1.5f;
    const struct { rl_material m; uint32_t *id; } list[] = {
        { rl_builtin_phong("plastic", rl_v3(0.05f, 0.05f, 0.055f), 0.15f, 20.0f), &c->m.plastic },
        { rl_builtin_phong("dashboard", rl_v3(0.09f, 0.09f, 0.10f), 0.1f, 15.0f), &c->m.dash },
        { dial_speed, &c->m.dial_speed },
        { dial_rpm, &c->m.dial_rpm },
        { needle, &c->m.needle },
        { chrome, &c->m.chrome },
        { rl_builtin_phong("hub", rl_v3s(0.06f), 0.5f, 60.0f), &c->m.hub },
        { glass, &c->m.glass },
        { rl_builtin_phong("wheel", rl_v3(0.05f, 0.045f, 0.04f), 0.25f, 15.0f), &c->m.wheel },
        { emitter("sky", rl_v3(0.8f * SKY_RADIANCE, 0.875f * SKY_RADIANCE, SKY_RADIANCE)), &c->m.sky },
        { emitter("warn_green", rl_v3(0.1f, 1.6f, 0.2f)), &c->m.warn[0] },
        { emitter("warn_amber", rl_v3(1.8f, 0.9f, 0.05f)), &c->m.warn[1] },
        { emitter("warn_red", rl_v3(1.8f, 0.1f, 0.05f)), &c->m.warn[2] },
        { emitter("warn_blue", rl_v3(0.15f, 0.35f, 1.8f)), &c->m.warn[3] },
    };
    for (size_t i = 0; i < sizeof list / sizeof list[0] && !s; ++i)
        s = rl_scene_add_material(c->scene, &list[i].m, list[i].id);
    return s;
}

/* Hands the buffer to the scene as a mesh on a new node; frees it. */
static rl_status add_part(cluster *c, uint32_t parent, rl_meshbuf *b, const char *name,
                          const char *kind, const rl_mat4 *transform, uint32_t *node)
{
    uint32_t mesh;
    rl_status s = rl_meshbuf_add_to_scene(c->scene, b, name, &mesh);
    rl_meshbuf_free(b);
    if (!s)
        s = rl_builtin_instance(c->scene, parent, name, mesh, kind, transform, node);
    return s;
}

/* Dashboard around the cluster recess, in world space. */
static rl_status add_dashboard(cluster *c)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.dash;
    rl_meshbuf_box(&b, rl_v3(-0.9f, -0.5f, -0.4f), rl_v3(0.9f, -0.135f, 0.24f));   /* below */
    rl_meshbuf_box(&b, rl_v3(-0.9f, 0.115f, -0.6f), rl_v3(0.9f, 0.15f, -0.03f));  /* top */
    rl_meshbuf_box(&b, rl_v3(-0.9f, -0.135f, -0.4f), rl_v3(-0.24f, 0.115f, 0.12f)); /* sides */
    rl_meshbuf_box(&b, rl_v3(0.24f, -0.135f, -0.4f), rl_v3(0.9f, 0.115f, 0.12f));
    return add_part(c, RL_NODE_ROOT, &b, "dashboard", "dashboard", NULL, NULL);
}

/* Housing in the cluster frame: back panel, hood, lower lip, side walls. */
static rl_status add_housing(cluster *c)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.plastic;
    rl_meshbuf_box(&b, rl_v3(-0.215f, -0.112f, -0.03f), rl_v3(0.215f, 0.112f, 0.0f));
    rl_meshbuf_box(&b, rl_v3(-0.23f, 0.112f, -0.03f), rl_v3(0.23f, 0.126f, 0.15f));
    rl_meshbuf_box(&b, rl_v3(-0.23f, -0.126f, -0.03f), rl_v3(0.23f, -0.112f, 0.11f));
    rl_meshbuf_box(&b, rl_v3(-0.23f, -0.112f, -0.03f), rl_v3(-0.215f, 0.112f, 0.11f));
    rl_meshbuf_box(&b, rl_v3(0.215f, -0.112f, -0.03f), rl_v3(0.23f, 0.112f, 0.11f));
    return add_part(c, c->group, &b, "cluster_housing", "housing", NULL, NULL);
}

/* Flat disc of radius DIAL_R facing +z, uv planar over its bounding square. */
static void dial_disc(rl_meshbuf *b, uint32_t segments)
{
    rl_vec3 n = rl_v3(0.0f, 0.0f, 1.0f);
    uint32_t centre = rl_meshbuf_vertex(b, rl_v3s(0.0f), n, rl_v2(0.5f, 0.5f));
    uint32_t rim = b->num_vertices;
    for (uint32_t i = 0; i < segments; ++i) {
        float a = 2.0f * RL_PI * (float)i / (float)segments;
        float ca = cosf(a), sa = sinf(a);
        rl_meshbuf_vertex(b, rl_v3(DIAL_R * ca, DIAL_R * sa, 0.0f), n,
                          rl_v2(0.5f + 0.5f * ca, 0.5f + 0.5f * sa));
    }
    for (uint32_t i = 0; i < segments; ++i)
        rl_meshbuf_triangle(b, centre, rim + i, rim + (i + 1) % segments);
}

static rl_status add_dials(cluster *c)
{
    static const char *const names[2] = { "dial_speed", "dial_rpm" };
    static const char *const needles[2] = { "needle_speed", "needle_rpm" };
    const uint32_t materials[2] = { c->m.dial_speed, c->m.dial_rpm };
    const float angles[2] = { scale_angle(&speed_scale, c->p.speed), scale_angle(&rpm_scale, c->p.rpm) };
    rl_status s = RL_OK;
    rl_mat4 up_to_z = rl_mat4_rotate(rl_v3(1.0f, 0.0f, 0.0f), 0.5f * RL_PI);  /* +y -> +z */
    for (int i = 0; i < 2 && !s; ++i) {
        float x = i ? DIAL_X : -DIAL_X;
        rl_mat4 at = rl_mat4_translate(rl_v3(x, 0.0f, 0.0005f));
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        b.material = materials[i];
        dial_disc(&b, tess(c, 96.0f, 16));
        s = add_part(c, c->group, &b, names[i], "dial", &at, NULL);

        /* Needle: a tapered 2 mm prism along +x, turned to its value,
         * 6 mm above the face. */
        const rl_vec2 outline[] = { { -0.014f, -0.0035f }, { 0.066f, -0.0009f },
                                    { 0.066f, 0.0009f }, { -0.014f, 0.0035f } };
        rl_meshbuf_init(&b);
        b.material = c->m.needle;
        rl_extrude_convex(&b, outline, 4, -0.001f, 0.001f);
        rl_mat4 lift = rl_mat4_translate(rl_v3(x, 0.0f, 0.006f));
        rl_mat4 turn = rl_mat4_rotate(rl_v3(0.0f, 0.0f, 1.0f), rl_radians(angles[i]));
        rl_mat4 m = rl_mat4_mul(&turn, &up_to_z);
        m = rl_mat4_mul(&lift, &m);
        if (!s) s = add_part(c, c->group, &b, needles[i], "needle", &m, NULL);
    }

    /* Hubs (domes over the needle axes) and chrome bezels round the dials. */
    rl_vec2 dome[16];
    uint32_t n = 0, steps = tess(c, 6.0f, 2);
    rl_lathe_arc(dome, &n, rl_v2(0.0f, 0.0f), 0.009f, 0.5f * RL_PI, 0.0f, steps);
    dome[n++] = rl_v2(0.0f, 0.0f);
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.hub;
    for (int i = 0; i < 2; ++i) {
        uint32_t first = b.num_vertices;
        rl_lathe(&b, dome, n, tess(c, 24.0f, 6));
        rl_mat4 m = rl_mat4_translate(rl_v3(i ? DIAL_X : -DIAL_X, 0.0f, 0.0065f));
        m = rl_mat4_mul(&m, &up_to_z);
        for (uint32_t v = first; v < b.num_vertices; ++v) {
            b.positions[v] = rl_mat4_mul_point(&m, b.positions[v]);
            b.normals[v] = rl_mat4_mul_dir(&m, b.normals[v]);
        }
    }
    if (!s) s = add_part(c, c->group, &b, "hubs", "hub", NULL, NULL);
    rl_meshbuf_init(&b);
    b.material = c->m.chrome;
    for (int i = 0; i < 2; ++i) {
        uint32_t first = b.num_vertices;
        rl_torus_arc(&b, DIAL_R + 0.003f, 0.003f, 0.0f, 2.0f * RL_PI, tess(c, 96.0f, 16),
                     tess(c, 12.0f, 4), false);
        for (uint32_t v = first; v < b.num_vertices; ++v)
            b.positions[v] = rl_add(b.positions[v], rl_v3(i ? DIAL_X : -DIAL_X, 0.0f, 0.0f));
    }
    if (!s) s = add_part(c, c->group, &b, "bezels", "bezel", NULL, NULL);

    /* Warning lights: small glowing squares between the dials. */
    rl_meshbuf_init(&b);
    for (int i = 0; i < 4; ++i) {
        float y = 0.045f - 0.03f * (float)i, h = 0.006f;
        b.material = c->m.warn[i];
        rl_meshbuf_quad(&b, rl_v3(-h, y - h, 0.0005f), rl_v3(h, y - h, 0.0005f),
                        rl_v3(h, y + h, 0.0005f), rl_v3(-h, y + h, 0.0005f), rl_v2(1.0f, 1.0f));
    }
    if (!s) s = add_part(c, c->group, &b, "warning_lights", "warning", NULL, NULL);
    return s;
}

/* Point on the glass: radius rad on the cylinder around the vertical axis
 * through (0, *, apex - R), column i of cols, row j of rows. */
static rl_vec3 glass_point(float rad, float big_r, float half_angle, uint32_t i, uint32_t cols,
                           uint32_t j, uint32_t rows, rl_vec3 *normal)
{
    float phi = -half_angle + 2.0f * half_angle * (float)i / (float)cols;
    float y = -GLASS_HALF_H + 2.0f * GLASS_HALF_H * (float)j / (float)rows;
    *normal = rl_v3(sinf(phi), 0.0f, cosf(phi));
    return rl_v3(rad * normal->x, y, GLASS_APEX_Z - big_r + rad * normal->z);
}

/* The cover glass: a closed shell cut from a vertical cylinder; outer and
 * inner surfaces with smooth normals, flat rim faces; outward winding. */
static rl_status add_glass(cluster *c)
{
    /* Circle through the apex and the edges at depth GLASS_SAG behind it. */
    const float big_r = (GLASS_HALF_W * GLASS_HALF_W + GLASS_SAG * GLASS_SAG) / (2.0f * GLASS_SAG);
    const float half_angle = asinf(GLASS_HALF_W / big_r);
    const float radii[2] = { big_r, big_r - GLASS_THICK };     /* outer, inner */
    uint32_t cols = (uint32_t)c->p.glass_segments;
    uint32_t rows = cols / 4 < 2 ? 2 : cols / 4;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.glass;
    for (int side = 0; side < 2; ++side) {
        uint32_t base = b.num_vertices;
        for (uint32_t j = 0; j <= rows; ++j)
            for (uint32_t i = 0; i <= cols; ++i) {
                rl_vec3 n;
                rl_vec3 p = glass_point(radii[side], big_r, half_angle, i, cols, j, rows, &n);
                rl_meshbuf_vertex(&b, p, side ? rl_neg(n) : n,
                                  rl_v2((float)i / (float)cols, (float)j / (float)rows));
            }
        for (uint32_t j = 0; j < rows; ++j)
            for (uint32_t i = 0; i < cols; ++i) {
                uint32_t a = base + j * (cols + 1) + i, d = a + cols + 1;
                /* Along phi then up is counter-clockwise seen from outside;
                 * the inner surface faces the dials, so it turns the other way. */
                if (side == 0) {
                    rl_meshbuf_triangle(&b, a, a + 1, d + 1);
                    rl_meshbuf_triangle(&b, a, d + 1, d);
                } else {
                    rl_meshbuf_triangle(&b, a, d + 1, a + 1);
                    rl_meshbuf_triangle(&b, a, d, d + 1);
                }
            }
    }
    /* Rims: top and bottom strips, left and right edges. */
    rl_vec3 n;
    rl_vec2 one = rl_v2(1.0f, 1.0f);
    for (uint32_t i = 0; i < cols; ++i) {
        rl_vec3 o0 = glass_point(radii[0], big_r, half_angle, i, cols, rows, rows, &n);
        rl_vec3 o1 = glass_point(radii[0], big_r, half_angle, i + 1, cols, rows, rows, &n);
        rl_vec3 i0 = glass_point(radii[1], big_r, half_angle, i, cols, rows, rows, &n);
        rl_vec3 i1 = glass_point(radii[1], big_r, half_angle, i + 1, cols, rows, rows, &n);
        rl_meshbuf_quad(&b, o0, o1, i1, i0, one);                  /* top, +y */
        o0 = glass_point(radii[0], big_r, half_angle, i, cols, 0, rows, &n);
        o1 = glass_point(radii[0], big_r, half_angle, i + 1, cols, 0, rows, &n);
        i0 = glass_point(radii[1], big_r, half_angle, i, cols, 0, rows, &n);
        i1 = glass_point(radii[1], big_r, half_angle, i + 1, cols, 0, rows, &n);
        rl_meshbuf_quad(&b, o0, i0, i1, o1, one);                  /* bottom, -y */
    }
    for (uint32_t j = 0; j < rows; ++j) {
        rl_vec3 o0 = glass_point(radii[0], big_r, half_angle, cols, cols, j, rows, &n);
        rl_vec3 o1 = glass_point(radii[0], big_r, half_angle, cols, cols, j + 1, rows, &n);
        rl_vec3 i0 = glass_point(radii[1], big_r, half_angle, cols, cols, j, rows, &n);
        rl_vec3 i1 = glass_point(radii[1], big_r, half_angle, cols, cols, j + 1, rows, &n);
        rl_meshbuf_quad(&b, o0, i0, i1, o1, one);                  /* right, +x */
        o0 = glass_point(radii[0], big_r, half_angle, 0, cols, j, rows, &n);
        o1 = glass_point(radii[0], big_r, half_angle, 0, cols, j + 1, rows, &n);
        i0 = glass_point(radii[1], big_r, half_angle, 0, cols, j, rows, &n);
        i1 = glass_point(radii[1], big_r, half_angle, 0, cols, j + 1, rows, &n);
        rl_meshbuf_quad(&b, o0, o1, i1, i0, one);                  /* left, -x */
    }
    uint32_t node;
    rl_status s = add_part(c, c->group, &b, "cover_glass", "glass", NULL, &node);
    if (!s)
        s = rl_scene_node_set_attr(c->scene, node, "vt", "true");
    return s;
}

static rl_status add_wheel(cluster *c)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.wheel;
    rl_torus_arc(&b, 0.185f, 0.016f, 0.0f, 2.0f * RL_PI, tess(c, 128.0f, 16), tess(c, 24.0f, 6),
                 false);
    /* Top leaning towards the dashboard, as a steering wheel does. */
    rl_mat4 at = rl_mat4_translate(rl_v3(0.0f, -0.21f, 0.40f));
    rl_mat4 lean = rl_mat4_rotate(rl_v3(1.0f, 0.0f, 0.0f), rl_radians(-25.0f));
    rl_mat4 m = rl_mat4_mul(&at, &lean);
    return add_part(c, RL_NODE_ROOT, &b, "steering_wheel", "wheel", &m, NULL);
}

static const rl_vec3 driver_eye = { 0.0f, 0.12f, 0.72f };

/* Sky quad where the driver's view mirrored off the glass centre points,
 * 1.6 m away, facing back at the glass; mesh and quad light coincide. */
static rl_status add_lights(cluster *c)
{
    rl_vec3 g = rl_mat4_mul_point(&c->frame, rl_v3(0.0f, 0.0f, GLASS_APEX_Z));
    rl_vec3 n = rl_normalize(rl_mat4_mul_dir(&c->frame, rl_v3(0.0f, 0.0f, 1.0f)));
    rl_vec3 r = rl_reflect(rl_normalize(rl_sub(g, driver_eye)), n);
    rl_vec3 across = rl_v3(1.0f, 0.0f, 0.0f);
    rl_vec3 up = rl_normalize(rl_cross(r, across));   /* in the quad's plane */
    /* A wide, low band a little above the mirror direction: it reflects in
     * the upper part of the glass and leaves most of the dials clear. */
    rl_vec3 centre = rl_madd(rl_madd(g, r, 1.6f), up, 0.12f);
    rl_vec3 edge_u = rl_scale(up, 0.25f), edge_v = rl_scale(across, 2.4f);
    rl_vec3 corner = rl_sub(centre, rl_add(rl_scale(edge_u, 0.5f), rl_scale(edge_v, 0.5f)));
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = c->m.sky;
    /* cross(edge_u, edge_v) points back at the glass. */
    rl_meshbuf_quad(&b, corner, rl_add(corner, edge_u), rl_add(corner, rl_add(edge_u, edge_v)),
                    rl_add(corner, edge_v), rl_v2(1.0f, 1.0f));
    rl_status s = add_part(c, RL_NODE_ROOT, &b, "sky", "light", NULL, NULL);
    rl_light quad = {
        .type = RL_LIGHT_QUAD,
        .color = rl_v3(0.8f, 0.875f, 1.0f),
        .intensity = SKY_RADIANCE,
        .position = corner,
        .edge_u = edge_u,
        .edge_v = edge_v,
    };
    if (!s) s = rl_scene_add_light(c->scene, &quad);
    /* Instrument lighting inside the glass: above and below each dial. */
    for (int i = 0; i < 4 && !s; ++i) {
        float x = i & 1 ? DIAL_X : -DIAL_X, y = i & 2 ? -0.084f : 0.084f;
        rl_light lamp = {
            .type = RL_LIGHT_POINT,
            .color = rl_v3(1.0f, 0.96f, 0.9f),
            .intensity = 0.012f,
            .position = rl_mat4_mul_point(&c->frame, rl_v3(x, y, 0.075f)),
        };
        s = rl_scene_add_light(c->scene, &lamp);
    }
    return s;
}

static rl_camera look(rl_vec3 eye, rl_vec3 target, float fov_deg)
{
    return (rl_camera){ .eye = eye, .target = target, .up = rl_v3(0.0f, 1.0f, 0.0f),
                        .fov_deg = fov_deg, .width = 640, .height = 480 };
}

static rl_status add_cameras(cluster *c)
{
    rl_vec3 centre = rl_mat4_mul_point(&c->frame, rl_v3(0.0f, 0.0f, 0.02f));
    rl_camera driver = look(driver_eye, centre, 30.0f);
    rl_camera lateral = look(rl_v3(0.36f, 0.16f, 0.60f), centre, 32.0f);
    rl_camera zoom = look(rl_v3(0.03f, 0.10f, 0.40f),
                          rl_mat4_mul_point(&c->frame, rl_v3(-DIAL_X, 0.0f, 0.0f)), 26.0f);
    rl_status s = rl_scene_add_camera(c->scene, "driver", &driver);
    if (!s) s = rl_scene_add_camera(c->scene, "lateral", &lateral);
    if (!s) s = rl_scene_add_camera(c->scene, "zoom", &zoom);
    if (s)
        return s;
    /* Head movement: one sideways sweep and two small nods over the path;
     * dense keys keep Catmull-Rom close to the sine. */
    rl_camera_key keys[PATH_KEYS];
    for (int k = 0; k < PATH_KEYS; ++k) {
        double t = PATH_SECONDS * (double)k / (double)(PATH_KEYS - 1);
        double w = 2.0 * (double)RL_PI * t / PATH_SECONDS;
        keys[k].time_s = t;
        keys[k].camera = driver;
        keys[k].camera.eye = rl_add(driver_eye, rl_v3((float)(0.12 * sin(w)),
                                                      (float)(0.025 * sin(2.0 * w)), 0.0f));
    }
    rl_camera_path *path = NULL;
    s = rl_camera_path_create(keys, PATH_KEYS, &path);
    if (!s && (s = rl_scene_set_camera_path(c->scene, path)))
        rl_camera_path_release(path);
    return s;
}

static rl_status build_cluster(rl_scene *scene, const rl_option_store *params)
{
    cluster c = { .scene = scene,
                  .p = { .speed = rl_option_store_float(params, "speed"),
                         .rpm = rl_option_store_float(params, "rpm"),
                         .detail = rl_option_store_float(params, "detail"),
                         .tex = rl_option_store_int(params, "tex"),
                         .glass_segments = rl_option_store_int(params, "glass_segments") } };
    rl_status s = add_materials(&c);
    if (s)
        return s;
    c.frame = rl_mat4_rotate(rl_v3(1.0f, 0.0f, 0.0f), rl_radians(-TILT_DEG));
    s = rl_scene_add_node(scene, RL_NODE_ROOT, "cluster", &c.frame, &c.group);
    if (!s) s = rl_scene_node_set_attr(scene, c.group, "kind", "cluster");
    if (!s) s = add_dashboard(&c);
    if (!s) s = add_housing(&c);
    if (!s) s = add_dials(&c);
    if (!s) s = add_glass(&c);
    if (!s) s = add_wheel(&c);
    if (!s) s = add_lights(&c);
    if (!s) s = add_cameras(&c);
    return s;
}

static const rl_option_info cluster_options[] = {
    { "speed", RL_OPT_FLOAT, "80", "speedometer needle, km/h", 0, 240, NULL },
    { "rpm", RL_OPT_FLOAT, "3", "tachometer needle, x1000/min", 0, 8, NULL },
    { "tex", RL_OPT_INT, "1024", "dial texture size, texels", 64, 4096, NULL },
    { "glass_segments", RL_OPT_INT, "48", "cover glass columns", 4, 1024, NULL },
    { "detail", RL_OPT_FLOAT, "1", "tessellation multiplier", 0.25, 8, NULL },
};

const rl_builtin_class rl_builtin_cluster_class = {
    { "cluster",
      "vehicle instrument cluster of Ullmann 2003, Sec. 5.4: speedometer and tachometer dials with printed "
      "textures, needles, warning lights behind a curved reflecting and refracting cover glass (the only VT "
      "object), steering wheel; cameras driver, lateral, zoom and a 4 s head-movement camera path",
      RL_BUILTIN_OPTIONS(cluster_options) },
    build_cluster,
};
