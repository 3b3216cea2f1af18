/* builtin_table.c: the "table" scene, a built-in analogue of the table scene
 * of Ullmann 2003, Sec. 5.1 (Fig. 5.1-5.8): a table with reflective and
 * refractive objects. The thesis' scene has 18 objects and about 20,000
 * polygons; three are VT objects (the two cups and the table top), and one
 * point light sits inside the shade of a table lamp.
 *
 * Here (metres, y up, table top surface at y = 0.75): floor, back wall,
 * table (top + 4 legs), a blue reflective cup with handle (k_r 0.6), a red
 * transparent glass (k_t 0.7, k_r 0.1, ior 1.5), a fork resting on a plate, a table
 * lamp (base, stem, socket, opaque frustum shade open at the bottom), a Utah teapot,
 * a plate and two books: 18 objects, about 20,000 triangles at detail=1. The
 * table top carries a procedural checkerboard tablecloth (checks cells
 * across its width) and reflects slightly (k_r 0.2), so the cups mirror the
 * pattern as in Fig. 5.2e/f and 5.8.
 *
 * VT objects: the nodes "table_top", "cup_blue" and "glass_red" carry the
 * attribute "vt" = "true"; no other node does. Cups are lathed solids with
 * real wall thickness (outer wall, rounded rim, inner wall, inner bottom),
 * closed and wound outward, so refraction through the glass enters and
 * leaves; the cup's handle is a capped torus arc in the same mesh.
 *
 * Lights: as in the thesis, one point light inside the lamp shade, which
 * casts the sharp shadows of cups, fork and teapot onto the table. Deviation:
 * the opaque shade leaves the wall and the far room in the ambient term
 * only, so a dim fill light from behind the camera (param fill, 0 turns it
 * off for the thesis' single-light setup) keeps the overview readable; its
 * shadows are faint.
 *
 * Cameras: "default" looks down at the cups from the front (Fig. 5.1b),
 * "overview" shows the whole table (Fig. 5.1a).
 *
 * Variants (param variant, issue 36): "mirror" is the scene above, the
 * default. "thesis" is the set-up of Sec. 5.1 as its text gives it: one
 * light (fill 0) and a table top that mirrors nothing (cloth_kr 0), still
 * three VT objects. "cup" is "thesis" with the blue cup as the only VT
 * object: Sec. 5.1.1 judges the criteria "anhand der Darstellungsqualitaet
 * der blauen Tasse" and Figs. 5.5/5.6 show that cup; counting its vertices
 * alone is what reproduces the figures' counts (docs/vertex-tracing.md,
 * "Issue 36: the thesis' vertex counts"). fill and cloth_kr, when given,
 * override a variant's values. */
#include "scene/builtin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/generators.h"
#include "scene/lathe.h"

#define TABLE_Y 0.75f            /* table top surface */
#define TABLE_W 1.4f             /* along x */
#define TABLE_D 0.9f             /* along z */
#define TABLE_T 0.04f            /* top thickness */
#define LEG 0.05f                /* leg cross-section */
#define CHECK_TEXELS 64          /* texels per checker cell: crisp edges up close */
#define MAX_PROFILE 64
#define PLATE_X (-0.26f)         /* plate centre, left in front of the cup */
#define PLATE_Z 0.27f

typedef struct table_materials {
    uint32_t cloth, wood, floor, wall, cup, glass, metal, teapot, lamp, shade, shade_inner,
        plate, book, pages;
} table_materials;

enum { VARIANT_MIRROR, VARIANT_THESIS, VARIANT_CUP };

typedef struct table {
    rl_scene *scene;
    float detail;                /* tessellation multiplier */
    long long checks;
    int variant;                 /* VARIANT_* */
    table_materials m;
} table;

/* Tessellation scaled by detail, never below the given minimum. */
static uint32_t tess(const table *t, float base, uint32_t min)
{
    float n = roundf(base * t->detail);
    return n < (float)min ? min : (uint32_t)n;
}

/* Hands the buffer to the scene as a mesh on a new node; frees it. */
static rl_status add_part(table *t, rl_meshbuf *b, const char *name, const char *kind,
                          const rl_mat4 *transform, uint32_t *node)
{
    uint32_t mesh;
    rl_status s = rl_meshbuf_add_to_scene(t->scene, b, name, &mesh);
    rl_meshbuf_free(b);
    if (!s)
        s = rl_builtin_instance(t->scene, RL_NODE_ROOT, name, mesh, kind, transform, node);
    return s;
}

/* A VT object in every variant but "cup", where only the blue cup is one:
 * the others are then rasterized like the rest of the scene (Sec. 3.5). */
static rl_status add_vt_part(table *t, rl_meshbuf *b, const char *name, const char *kind,
                             const rl_mat4 *transform)
{
    uint32_t node;
    rl_status s = add_part(t, b, name, kind, transform, &node);
    bool vt = t->variant != VARIANT_CUP || strcmp(name, "cup_blue") == 0;
    if (!s && vt)
        s = rl_scene_node_set_attr(t->scene, node, "vt", "true");
    return s;
}

/* Red and white tablecloth, 2 x 2 cells per repeat. */
static rl_status add_cloth_texture(rl_scene *scene, uint32_t *id)
{
    return rl_builtin_checker(scene, CHECK_TEXELS, rl_v4(0.85f, 0.84f, 0.80f, 1.0f),
                              rl_v4(0.60f, 0.06f, 0.05f, 1.0f), id);
}


static rl_status add_materials(table *t, float cloth_kr)
{
    uint32_t cloth_tex;
    rl_status s = add_cloth_texture(t->scene, &cloth_tex);
    if (s)
        return s;
    rl_material cloth = rl_builtin_phong("tablecloth", rl_v3s(1.0f), 0.2f, 40.0f);
    cloth.diffuse_texture = cloth_tex;     /* k_d modulated by the checkers */
    cloth.reflectivity = cloth_kr;
    rl_material cup = rl_builtin_phong("cup_blue", rl_v3(0.04f, 0.10f, 0.42f), 0.8f, 120.0f);
    cup.reflectivity = 0.6f;
    /* The tracer does not tint transmitted light, so the red comes from a
     * strong diffuse term next to k_t. */
    rl_material glass = rl_builtin_phong("glass_red", rl_v3(0.30f, 0.02f, 0.02f), 0.9f, 200.0f);
    glass.reflectivity = 0.1f;
    glass.transmissivity = 0.7f;
    glass.ior = 1.5f;
    rl_material metal = rl_builtin_phong("metal", rl_v3s(0.25f), 0.7f, 80.0f);
    metal.reflectivity = 0.3f;
    const struct { rl_material m; uint32_t *id; } list[] = {
        { cloth, &t->m.cloth },
        { rl_builtin_phong("wood", rl_v3(0.42f, 0.26f, 0.14f), 0.1f, 20.0f), &t->m.wood },
        { rl_builtin_phong("floor", rl_v3(0.45f, 0.40f, 0.34f), 0.0f, 1.0f), &t->m.floor },
        { rl_builtin_phong("wall", rl_v3(0.70f, 0.70f, 0.64f), 0.0f, 1.0f), &t->m.wall },
        { cup, &t->m.cup },
        { glass, &t->m.glass },
        { metal, &t->m.metal },
        { rl_builtin_phong("teapot", rl_v3(0.72f, 0.70f, 0.62f), 0.0f, 1.0f), &t->m.teapot },
        { rl_builtin_phong("lamp", rl_v3s(0.12f), 0.6f, 60.0f), &t->m.lamp },
        { rl_builtin_phong("shade", rl_v3(0.85f, 0.78f, 0.55f), 0.0f, 1.0f), &t->m.shade },
        /* A few centimetres from the bulb the inside gets ~30x the table's
         * irradiance; a dark lining keeps its mirror image in the table and
         * the cup a highlight rather than a white blot. */
        { rl_builtin_phong("shade_inner", rl_v3(0.06f, 0.055f, 0.04f), 0.0f, 1.0f), &t->m.shade_inner },
        { rl_builtin_phong("plate", rl_v3s(0.7f), 0.3f, 90.0f), &t->m.plate },
        { rl_builtin_phong("book", rl_v3(0.15f, 0.35f, 0.18f), 0.1f, 20.0f), &t->m.book },
        { rl_builtin_phong("pages", rl_v3(0.86f, 0.84f, 0.76f), 0.0f, 1.0f), &t->m.pages },
    };
    for (size_t i = 0; i < sizeof list / sizeof list[0] && !s; ++i)
        s = rl_scene_add_material(t->scene, &list[i].m, list[i].id);
    return s;
}

/* The top surface as an nx x nz grid: Vertex Tracing samples a surface at
 * its vertices first (Ullmann 2003, Sec. 3.2), so a table top made of two
 * triangles would start from four samples and miss every shadow lying
 * inside them (Sec. 3.3.2). Counter-clockwise seen from +y; uv 0..rx, 0..rz
 * along +x and -z like rl_meshbuf_quad. */
static void top_grid(rl_meshbuf *b, float x, float z, float y, float rx, float rz, int nx, int nz)
{
    uint32_t first = 0;
    for (int j = 0; j <= nz; ++j)
        for (int i = 0; i <= nx; ++i) {
            float u = (float)i / (float)nx, v = (float)j / (float)nz;
            uint32_t id = rl_meshbuf_vertex(b, rl_v3(-x + 2.0f * x * u, y, z - 2.0f * z * v), rl_v3(0.0f, 1.0f, 0.0f),
                                            rl_v2(rx * u, rz * v));
            if (i == 0 && j == 0)
                first = id;
        }
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            uint32_t a = first + (uint32_t)(j * (nx + 1) + i), c = a + 1, d = a + (uint32_t)(nx + 1), e = d + 1;
            rl_meshbuf_triangle(b, a, c, e);
            rl_meshbuf_triangle(b, a, e, d);
        }
}

/* Room and table: floor, back wall, checkered top (VT object), legs. */
static rl_status add_furniture(table *t)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = t->m.floor;
    rl_gen_quad(&b, 8.0f, 8.0f, 4.0f);
    rl_status s = add_part(t, &b, "floor", "floor", NULL, NULL);

    rl_meshbuf_init(&b);
    b.material = t->m.wall;
    rl_meshbuf_quad(&b, rl_v3(-4.0f, 0.0f, -1.2f), rl_v3(4.0f, 0.0f, -1.2f),
                    rl_v3(4.0f, 3.0f, -1.2f), rl_v3(-4.0f, 3.0f, -1.2f), rl_v2(1.0f, 1.0f));
    if (!s) s = add_part(t, &b, "back_wall", "wall", NULL, NULL);

    /* Top: a box whose faces carry the checkers at their true size (one
     * texture repeat = 2 x 2 cells, `checks` cells across the width). */
    float cell = TABLE_W / (float)t->checks;
    float x = 0.5f * TABLE_W, z = 0.5f * TABLE_D, y0 = TABLE_Y - TABLE_T, y1 = TABLE_Y;
    float rx = TABLE_W / (2.0f * cell), rz = TABLE_D / (2.0f * cell), ry = TABLE_T / (2.0f * cell);
    rl_meshbuf_init(&b);
    b.material = t->m.cloth;
    int grid = (int)(48.0f * t->detail + 0.5f);
    grid = grid < 4 ? 4 : grid;
    top_grid(&b, x, z, y1, rx, rz, grid, (int)((float)grid * TABLE_D / TABLE_W + 0.5f));
    rl_meshbuf_quad(&b, rl_v3(-x, y0, -z), rl_v3(x, y0, -z), rl_v3(x, y0, z), rl_v3(-x, y0, z), rl_v2(rx, rz));
    rl_meshbuf_quad(&b, rl_v3(-x, y0, z), rl_v3(x, y0, z), rl_v3(x, y1, z), rl_v3(-x, y1, z), rl_v2(rx, ry));
    rl_meshbuf_quad(&b, rl_v3(x, y0, -z), rl_v3(-x, y0, -z), rl_v3(-x, y1, -z), rl_v3(x, y1, -z), rl_v2(rx, ry));
    rl_meshbuf_quad(&b, rl_v3(x, y0, z), rl_v3(x, y0, -z), rl_v3(x, y1, -z), rl_v3(x, y1, z), rl_v2(rz, ry));
    rl_meshbuf_quad(&b, rl_v3(-x, y0, -z), rl_v3(-x, y0, z), rl_v3(-x, y1, z), rl_v3(-x, y1, -z), rl_v2(rz, ry));
    if (!s) s = add_vt_part(t, &b, "table_top", "table", NULL);

    for (int i = 0; i < 4 && !s; ++i) {
        float lx = (i & 1 ? 1.0f : -1.0f) * (x - 0.06f), lz = (i & 2 ? 1.0f : -1.0f) * (z - 0.06f);
        rl_meshbuf_init(&b);
        b.material = t->m.wood;
        rl_meshbuf_box(&b, rl_v3(lx - 0.5f * LEG, 0.0f, lz - 0.5f * LEG),
                       rl_v3(lx + 0.5f * LEG, y0, lz + 0.5f * LEG));
        char name[24]; /* room for any int: GCC -O1 cannot see i < 4 */
        snprintf(name, sizeof name, "table_leg_%d", i);
        s = add_part(t, &b, name, "table", NULL, NULL);
    }
    return s;
}

/* Profile of a thick-walled vessel standing on y = 0, for rl_lathe: inner
 * bottom centre, inner wall up, rounded rim, outer wall down, bottom. The
 * material stays on the right of the walk, so the lathe winds outward. */
static uint32_t vessel_profile(rl_vec2 *p, float r_bottom, float r_top, float height,
                               float wall, float base, uint32_t rim_steps)
{
    uint32_t n = 0;
    float half = 0.5f * wall;
    p[n++] = rl_v2(0.0f, base);
    p[n++] = rl_v2(r_bottom - wall, base);
    /* Rim: half circle over the wall, from the inner to the outer side. */
    rl_lathe_arc(p, &n, rl_v2(r_top - half, height - half), half, RL_PI, 0.0f, rim_steps);
    p[n++] = rl_v2(r_bottom, 0.0f);
    p[n++] = rl_v2(0.0f, 0.0f);
    return n;
}

static rl_status add_cups(table *t)
{
    rl_vec2 profile[MAX_PROFILE];
    uint32_t segments = tess(t, 96.0f, 8), rim = tess(t, 6.0f, 2);

    /* Blue cup: 8 cm wide, 9 cm tall, 4 mm wall; the handle's capped ends
     * sit inside the wall, its arc bulges out along +x. */
    const float cup_r = 0.04f, cup_h = 0.09f, cup_wall = 0.004f;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = t->m.cup;
    uint32_t n = vessel_profile(profile, cup_r, cup_r, cup_h, cup_wall, 0.007f, rim);
    rl_lathe(&b, profile, n, segments);
    uint32_t first = b.num_vertices;
    rl_torus_arc(&b, 0.022f, 0.0045f, -0.5f * RL_PI, 0.5f * RL_PI, tess(t, 16.0f, 4),
                 tess(t, 12.0f, 4), true);
    for (uint32_t i = first; i < b.num_vertices; ++i)
        b.positions[i] = rl_add(b.positions[i], rl_v3(cup_r - 0.5f * cup_wall, 0.047f, 0.0f));
    rl_mat4 at = rl_mat4_translate(rl_v3(-0.10f, TABLE_Y, 0.05f));
    rl_mat4 turn = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians(-150.0f));
    rl_mat4 world = rl_mat4_mul(&at, &turn);
    rl_status s = add_vt_part(t, &b, "cup_blue", "cup", &world);

    /* Red glass: slightly flared, thick base, closed so rays enter and leave. */
    rl_meshbuf_init(&b);
    b.material = t->m.glass;
    n = vessel_profile(profile, 0.030f, 0.036f, 0.11f, 0.0035f, 0.010f, rim);
    rl_lathe(&b, profile, n, segments);
    at = rl_mat4_translate(rl_v3(0.10f, TABLE_Y, 0.10f));
    if (!s) s = add_vt_part(t, &b, "glass_red", "cup", &at);
    return s;
}

/* Fork: handle, neck, head and four prongs as thin prisms, its handle end
 * on the table and its prongs resting on the plate's rim, so it casts a
 * shadow (Fig. 5.3 shows the fork's shadow). */
static rl_status add_fork(table *t)
{
    const float y0 = 0.0005f, y1 = y0 + 0.003f;
    const rl_vec2 handle[] = { { 0.0f, -0.007f }, { 0.11f, -0.004f }, { 0.11f, 0.004f }, { 0.0f, 0.007f } };
    const rl_vec2 neck[] = { { 0.109f, -0.004f }, { 0.13f, -0.011f }, { 0.13f, 0.011f }, { 0.109f, 0.004f } };
    const rl_vec2 head[] = { { 0.129f, -0.011f }, { 0.146f, -0.011f }, { 0.146f, 0.011f }, { 0.129f, 0.011f } };
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = t->m.metal;
    rl_extrude_convex(&b, handle, 4, y0, y1);
    rl_extrude_convex(&b, neck, 4, y0, y1);
    rl_extrude_convex(&b, head, 4, y0, y1);
    for (int i = 0; i < 4; ++i) {
        float zc = (-0.00825f + 0.0055f * (float)i), w = 0.00175f;
        const rl_vec2 prong[] = { { 0.145f, zc - w }, { 0.19f, zc - 0.6f * w },
                                  { 0.19f, zc + 0.6f * w }, { 0.145f, zc + w } };
        rl_extrude_convex(&b, prong, 4, y0, y1);
    }
    /* Lift the prong end by the rim height 1.6 cm over 15 cm (6.1 degrees),
     * then point it at the plate's centre. */
    rl_mat4 lift = rl_mat4_rotate(rl_v3(0.0f, 0.0f, 1.0f), rl_radians(6.1f));
    rl_mat4 turn = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians(166.0f));
    rl_mat4 at = rl_mat4_translate(rl_v3(PLATE_X + 0.25f, TABLE_Y, PLATE_Z + 0.06f));
    rl_mat4 world = rl_mat4_mul(&turn, &lift);
    world = rl_mat4_mul(&at, &world);
    return add_part(t, &b, "fork", "cutlery", &world, NULL);
}

#define LAMP_X (-0.42f)
#define LAMP_Z (-0.22f)
#define SHADE_Y0 0.30f           /* shade bottom above the table */
#define SHADE_Y1 0.46f
#define BULB_Y 0.37f             /* the point light, inside the shade */

static rl_status add_lamp(table *t)
{
    rl_vec2 p[MAX_PROFILE];
    uint32_t segments = tess(t, 48.0f, 8), n = 0;
    rl_mat4 at = rl_mat4_translate(rl_v3(LAMP_X, TABLE_Y, LAMP_Z));

    /* Base: a low disc with a rounded edge. */
    p[n++] = rl_v2(0.0f, 0.02f);
    rl_lathe_arc(p, &n, rl_v2(0.07f, 0.01f), 0.01f, 0.5f * RL_PI, -0.5f * RL_PI, tess(t, 6.0f, 2));
    p[n++] = rl_v2(0.0f, 0.0f);
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = t->m.lamp;
    rl_lathe(&b, p, n, segments);
    rl_status s = add_part(t, &b, "lamp_base", "lamp", &at, NULL);

    /* Stem up to just below the light. */
    n = 0;
    p[n++] = rl_v2(0.0f, BULB_Y - 0.03f);
    p[n++] = rl_v2(0.008f, BULB_Y - 0.03f);
    p[n++] = rl_v2(0.008f, 0.019f);
    p[n++] = rl_v2(0.0f, 0.019f);
    rl_meshbuf_init(&b);
    b.material = t->m.lamp;
    rl_lathe(&b, p, n, tess(t, 16.0f, 6));
    if (!s) s = add_part(t, &b, "lamp_stem", "lamp", &at, NULL);

    /* Socket below the bulb: shades the lamp's own base. */
    n = 0;
    p[n++] = rl_v2(0.0f, BULB_Y - 0.015f);
    p[n++] = rl_v2(0.015f, BULB_Y - 0.015f);
    p[n++] = rl_v2(0.015f, BULB_Y - 0.045f);
    p[n++] = rl_v2(0.0f, BULB_Y - 0.045f);
    rl_meshbuf_init(&b);
    b.material = t->m.lamp;
    rl_lathe(&b, p, n, tess(t, 24.0f, 6));
    if (!s) s = add_part(t, &b, "lamp_socket", "lamp", &at, NULL);

    /* Shade: opaque frustum, closed on top and open at the bottom, 4 mm
     * thick: top, outer wall down, rim, inner wall up, inner top. */
    const float r0 = 0.14f, r1 = 0.07f, th = 0.004f;
    n = 0;
    p[n++] = rl_v2(0.0f, SHADE_Y1);
    p[n++] = rl_v2(r1, SHADE_Y1);
    p[n++] = rl_v2(r0, SHADE_Y0);
    p[n++] = rl_v2(r0 - th, SHADE_Y0);
    p[n++] = rl_v2(r1 - th, SHADE_Y1 - th);
    p[n++] = rl_v2(0.0f, SHADE_Y1 - th);
    rl_meshbuf_init(&b);
    b.material = t->m.shade;
    rl_lathe(&b, p, 4, segments);            /* top, outer wall, rim */
    b.material = t->m.shade_inner;
    rl_lathe(&b, p + 3, n - 3, segments);    /* lining: inner wall, inner top */
    if (!s) s = add_part(t, &b, "lamp_shade", "lamp", &at, NULL);
    return s;
}

#define BOOK_H 0.035f

/* Book: cover boxes around a block of pages, lying on y = 0. */
static void book(const table *t, rl_meshbuf *b)
{
    b->material = t->m.book;
    rl_meshbuf_box(b, rl_v3(-0.085f, 0.0f, -0.12f), rl_v3(0.085f, 0.004f, 0.12f));
    rl_meshbuf_box(b, rl_v3(-0.085f, BOOK_H - 0.004f, -0.12f), rl_v3(0.085f, BOOK_H, 0.12f));
    rl_meshbuf_box(b, rl_v3(-0.085f, 0.004f, -0.12f), rl_v3(-0.080f, BOOK_H - 0.004f, 0.12f));
    b->material = t->m.pages;
    rl_meshbuf_box(b, rl_v3(-0.080f, 0.004f, -0.115f), rl_v3(0.082f, BOOK_H - 0.004f, 0.115f));
}

static rl_status add_props(table *t)
{
    /* Utah teapot, plain diffuse, spout towards the cups. */
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = t->m.teapot;
    rl_gen_teapot(&b, tess(t, 14000.0f, 56), 0.13f);
    rl_mat4 at = rl_mat4_translate(rl_v3(0.34f, TABLE_Y, -0.14f));
    rl_mat4 turn = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians(200.0f));
    rl_mat4 world = rl_mat4_mul(&at, &turn);
    rl_status s = add_part(t, &b, "teapot", "teapot", &world, NULL);

    /* Plate: a shallow lathed dish. */
    rl_vec2 p[MAX_PROFILE];
    uint32_t n = 0;
    p[n++] = rl_v2(0.0f, 0.006f);
    p[n++] = rl_v2(0.075f, 0.006f);
    p[n++] = rl_v2(0.105f, 0.016f);
    p[n++] = rl_v2(0.11f, 0.016f);
    p[n++] = rl_v2(0.08f, 0.002f);
    p[n++] = rl_v2(0.06f, 0.0f);
    p[n++] = rl_v2(0.0f, 0.0f);
    rl_meshbuf_init(&b);
    b.material = t->m.plate;
    rl_lathe(&b, p, n, tess(t, 48.0f, 8));
    at = rl_mat4_translate(rl_v3(PLATE_X, TABLE_Y + 0.0005f, PLATE_Z));
    if (!s) s = add_part(t, &b, "plate", "plate", &at, NULL);

    /* Two books, the second stacked askew on the first. */
    const float book_pose[2][3] = { { -0.50f, 0.17f, 20.0f }, { -0.50f, 0.18f, -5.0f } };
    for (int i = 0; i < 2 && !s; ++i) {
        rl_meshbuf_init(&b);
        book(t, &b);
        at = rl_mat4_translate(rl_v3(book_pose[i][0], TABLE_Y + 0.0005f + BOOK_H * (float)i,
                                     book_pose[i][1]));
        turn = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians(book_pose[i][2]));
        world = rl_mat4_mul(&at, &turn);
        s = add_part(t, &b, i ? "book_2" : "book", "book", &world, NULL);
    }
    return s;
}

static rl_status add_lights_and_cameras(table *t, double fill)
{
    rl_light bulb = {
        .type = RL_LIGHT_POINT,
        .color = rl_v3(1.0f, 0.92f, 0.78f),
        .intensity = 0.35f,
        .position = rl_v3(LAMP_X, TABLE_Y + BULB_Y, LAMP_Z),
    };
    rl_status s = rl_scene_add_light(t->scene, &bulb);
    if (!s && fill > 0.0) {
        rl_light fill_light = {
            .type = RL_LIGHT_POINT,
            .color = rl_v3(0.85f, 0.9f, 1.0f),
            .intensity = (float)fill * 10.0f,
            .position = rl_v3(1.2f, 2.4f, 3.0f),
        };
        s = rl_scene_add_light(t->scene, &fill_light);
    }
    rl_camera cups = {
        .eye = rl_v3(0.06f, 1.12f, 0.66f),
        .target = rl_v3(-0.01f, 0.78f, 0.08f),
        .up = rl_v3(0.0f, 1.0f, 0.0f),
        .fov_deg = 40.0f,
        .width = 640,
        .height = 480,
    };
    rl_camera overview = {
        .eye = rl_v3(0.9f, 1.55f, 2.0f),
        .target = rl_v3(-0.05f, 0.8f, 0.0f),
        .up = rl_v3(0.0f, 1.0f, 0.0f),
        .fov_deg = 40.0f,
        .width = 640,
        .height = 480,
    };
    if (!s) s = rl_scene_add_camera(t->scene, "default", &cups);
    if (!s) s = rl_scene_add_camera(t->scene, "overview", &overview);
    return s;
}

static rl_status build_table(rl_scene *scene, const rl_option_store *params)
{
    double detail = rl_option_store_float(params, "detail"), fill = rl_option_store_float(params, "fill");
    double cloth_kr = rl_option_store_float(params, "cloth_kr");
    long long checks = rl_option_store_int(params, "checks");
    int variant = rl_option_store_enum(params, "variant");
    /* The thesis' single light and non-mirroring table top (Sec. 5.1),
     * unless fill or cloth_kr was given explicitly. */
    if (variant != VARIANT_MIRROR && !rl_option_store_given(params, "fill"))
        fill = 0.0;
    if (variant != VARIANT_MIRROR && !rl_option_store_given(params, "cloth_kr"))
        cloth_kr = 0.0;
    table t = { .scene = scene, .detail = (float)detail, .checks = checks, .variant = variant };
    rl_status s = add_materials(&t, (float)cloth_kr);
    if (!s) s = add_furniture(&t);
    if (!s) s = add_cups(&t);
    if (!s) s = add_fork(&t);
    if (!s) s = add_lamp(&t);
    if (!s) s = add_props(&t);
    if (!s) s = add_lights_and_cameras(&t, fill);
    return s;
}

static const char *const variant_names[] = { "mirror", "thesis", "cup", NULL };
static const rl_option_info table_options[] = {
    { "variant", RL_OPT_ENUM, "mirror",
      "mirror (fill light, mirroring tablecloth: the hard case), thesis (Ullmann 2003, Sec. 5.1: one light, "
      "fill 0 and cloth_kr 0 unless given) or cup (thesis with the blue cup as the only VT object, the set-up "
      "that reproduces the vertex counts of Figs. 5.5/5.6)", 0, 0, variant_names },
    { "detail", RL_OPT_FLOAT, "1", "tessellation multiplier (about 20000 triangles at 1)", 0.25, 8, NULL },
    { "checks", RL_OPT_INT, "8", "tablecloth checkers across the table", 1, 256, NULL },
    { "fill", RL_OPT_FLOAT, "0.15", "dim fill light from behind the camera (0: the thesis' single lamp light)", 0,
      1, NULL },
    { "cloth_kr", RL_OPT_FLOAT, "0.2", "reflectivity k_r of the tablecloth (the thesis' table top shows no mirror image: 0)",
      0, 1, NULL },
};

const rl_builtin_class rl_builtin_table_class = {
    { "table",
      "the table scene of Ullmann 2003, Sec. 5.1: checkered table top, blue mirroring cup and red glass (the VT "
      "objects, node attribute vt=true), fork, teapot, plate, book, table lamp with a point light in its shade; "
      "cameras default and overview",
      RL_BUILTIN_OPTIONS(table_options) },
    build_table,
};
