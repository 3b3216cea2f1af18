/* builtin_city.c: the "city" scene, a procedural, parameterised city for
 * visibility and level-of-detail work (occlusion culling, LOD, out-of-core
 * style experiments need many objects, many triangles and strong occlusion).
 *
 * Layout (metres, y up, centred on the origin): blocks x blocks city blocks
 * of block_size metres separated by streets of street_width metres. Each
 * block is a raised sidewalk slab whose inner area is cut into a grid of lots
 * of 3..6 bays (a bay is 4 m); a lot holds one building (1 m gap to its
 * neighbours) or, rarely, a small plaza with a tree. Buildings are stacks of
 * storeys, 3.5 m each, of random height in floors_min..floors_max (taller
 * towards the centre). A storey is a closed shell: floor slab, thick outer
 * walls with window openings (reveals and a glass pane per bay; shop windows
 * and a door on the ground floor) and, at detail 2, interior walls with
 * doors: a corridor wall along x and room walls every two bays. A roof slab
 * with a parapet closes the top. So walls and slabs occlude each other from
 * inside and out.
 *
 * Instancing: storeys, roofs, sidewalks, lamps and trees are shared meshes
 * placed by node transforms; a storey mesh is built once per (footprint in
 * bays, ground/upper/roof, facade colour). Every storey and roof is its own
 * object (node with a mesh) under a "building" node, so the default city has
 * thousands of objects and well over a million flattened triangles while
 * building only a few dozen meshes; cost is linear in the number of nodes.
 * Randomness: one rl_rng stream per block (seeded with `seed`, stream =
 * block index), so the same parameters always give the same city and blocks
 * do not depend on each other's draws.
 *
 * Attributes: "kind" = block, sidewalk, building, storey, roof, lamp, tree,
 * ground; buildings also carry "floors". Cameras: "overview" (first) and
 * "street" (eye height 1.7 m in the central street). */
#include "scene/builtin.h"

#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "rl/rl_rng.h"
#include "scene/generators.h"

#define BAY 4.0f               /* lot grid unit, m */
#define LOT_GAP 1.0f           /* gap from lot edge to facade, m */
#define SIDEWALK 2.0f          /* sidewalk ring inside a block, m */
#define CURB 0.15f             /* sidewalk height, m */
#define STOREY 3.5f            /* floor-to-floor height, m */
#define SLAB 0.3f              /* floor slab thickness, m */
#define WALL 0.3f              /* outer wall thickness, m */
#define INNER_WALL 0.15f       /* interior wall thickness, m */
#define MAX_UNITS 6            /* largest lot side in bays */
#define FACADES 3              /* facade colour variants */
#define CITY_MAX_TRIANGLES (16u << 20)  /* flattened; keeps commit's arrays ~1 GB */

enum { KIND_GROUND, KIND_UPPER, KIND_ROOF, NUM_KINDS };

typedef struct city_params {
    long long blocks, seed, floors_min, floors_max, detail;
    double block_size, street_width;
    bool furniture;
} city_params;

typedef struct city_materials {
    uint32_t asphalt, sidewalk, slab, roof, interior, glass, lamp, bark, leaves;
    uint32_t facade[FACADES];
} city_materials;

typedef struct city {
    rl_scene *scene;
    city_params p;
    city_materials m;
    /* Shared meshes: storeys by [facade][ux][uz][kind], RL_NONE until built. */
    uint32_t storey_mesh[FACADES][MAX_UNITS + 1][MAX_UNITS + 1][NUM_KINDS];
    uint32_t storey_tris[FACADES][MAX_UNITS + 1][MAX_UNITS + 1][NUM_KINDS];
    uint32_t sidewalk_mesh, lamp_mesh, tree_mesh;
    uint32_t sidewalk_tris, lamp_tris, tree_tris;
    uint64_t triangles;        /* flattened so far, checked against the cap */
    uint32_t buildings;
} city;

/* ---- geometry helpers ------------------------------------------------- */

/* Rectangle origin + s*e1 + t*e2 (s, t in [0,1]) facing `want`. */
static void rect(rl_meshbuf *b, rl_vec3 o, rl_vec3 e1, rl_vec3 e2, rl_vec3 want)
{
    if (rl_dot(rl_cross(e1, e2), want) < 0.0f) {
        rl_vec3 t = e1;
        e1 = e2;
        e2 = t;
    }
    /* uv in units of 4 m so facade textures (if any) tile per bay. */
    rl_vec2 uv = rl_v2(rl_length(e1) / BAY, rl_length(e2) / BAY);
    rl_meshbuf_quad(b, o, rl_add(o, e1), rl_add(rl_add(o, e1), e2), rl_add(o, e2), uv);
}

/* A wall runs along axis a (x or z) with its faces at c = c_out and c_in on
 * the other horizontal axis; wall coordinates (a, y, c) map to the world. */
typedef struct wall_frame { bool along_z; } wall_frame;

static rl_vec3 wmap(wall_frame f, float a, float y, float c)
{
    return f.along_z ? rl_v3(c, y, a) : rl_v3(a, y, c);
}

typedef struct opening { float a0, a1, y0, y1; bool glass; } opening;

/* Thick wall between y0 and y1 with openings (sorted by a, inside a0..a1):
 * both faces are split into columns between openings and strips below and
 * above them; reveals line each opening; windows get a pane in the middle.
 * Top and bottom are left open: slabs cover them. caps closes the ends. */
static void wall(rl_meshbuf *b, const city_materials *m, uint32_t material, wall_frame f,
                 float a0, float a1, float c_out, float c_in, float y0, float y1,
                 const opening *o, int n, bool caps)
{
    rl_vec3 ea = wmap(f, 1.0f, 0.0f, 0.0f), ey = rl_v3(0.0f, 1.0f, 0.0f);
    rl_vec3 out = rl_scale(wmap(f, 0.0f, 0.0f, 1.0f), c_out > c_in ? 1.0f : -1.0f);
    b->material = material;
    for (int face = 0; face < 2; ++face) {
        float c = face ? c_in : c_out;
        rl_vec3 want = face ? rl_neg(out) : out;
        float cursor = a0;
        for (int i = 0; i < n; ++i) {
            if (o[i].a0 > cursor)
                rect(b, wmap(f, cursor, y0, c), rl_scale(ea, o[i].a0 - cursor),
                     rl_scale(ey, y1 - y0), want);
            float w = o[i].a1 - o[i].a0;
            if (o[i].y0 > y0)
                rect(b, wmap(f, o[i].a0, y0, c), rl_scale(ea, w), rl_scale(ey, o[i].y0 - y0), want);
            if (o[i].y1 < y1)
                rect(b, wmap(f, o[i].a0, o[i].y1, c), rl_scale(ea, w), rl_scale(ey, y1 - o[i].y1),
                     want);
            cursor = o[i].a1;
        }
        if (a1 > cursor)
            rect(b, wmap(f, cursor, y0, c), rl_scale(ea, a1 - cursor), rl_scale(ey, y1 - y0), want);
    }
    rl_vec3 depth = rl_scale(wmap(f, 0.0f, 0.0f, 1.0f), c_out - c_in);
    for (int i = 0; i < n; ++i) {
        float w = o[i].a1 - o[i].a0, h = o[i].y1 - o[i].y0;
        /* Reveals face into the opening. */
        if (o[i].y0 > y0)
            rect(b, wmap(f, o[i].a0, o[i].y0, c_in), rl_scale(ea, w), depth, ey);
        rect(b, wmap(f, o[i].a0, o[i].y1, c_in), rl_scale(ea, w), depth, rl_neg(ey));
        rect(b, wmap(f, o[i].a0, o[i].y0, c_in), rl_scale(ey, h), depth, ea);
        rect(b, wmap(f, o[i].a1, o[i].y0, c_in), rl_scale(ey, h), depth, rl_neg(ea));
        if (o[i].glass) {
            b->material = m->glass;
            rect(b, wmap(f, o[i].a0, o[i].y0, 0.5f * (c_in + c_out)), rl_scale(ea, w),
                 rl_scale(ey, h), out);
            b->material = material;
        }
    }
    if (caps) {
        rect(b, wmap(f, a0, y0, c_in), rl_scale(ey, y1 - y0), depth, rl_neg(ea));
        rect(b, wmap(f, a1, y0, c_in), rl_scale(ey, y1 - y0), depth, ea);
    }
}

/* Openings centred in n bays of width bay starting at `start`. */
static int bay_openings(opening *o, int n, float start, float bay, float half_width, float y0,
                        float y1)
{
    if (n > MAX_UNITS) /* lots never exceed MAX_UNITS bays (see lots()); keeps o[] in bounds */
        n = MAX_UNITS;
    for (int i = 0; i < n; ++i) {
        float c = start + ((float)i + 0.5f) * bay;
        o[i] = (opening){ c - half_width, c + half_width, y0, y1, true };
    }
    return n;
}

/* Interior wall between the slabs with doors (no glass) centred at `doors`. */
static void inner_wall(rl_meshbuf *b, const city_materials *m, wall_frame f, float a0, float a1,
                       float c, const float *doors, int n)
{
    opening o[MAX_UNITS];
    int k = 0;
    for (int i = 0; i < n && k < MAX_UNITS; ++i)
        if (doors[i] - 0.5f > a0 + 0.2f && doors[i] + 0.5f < a1 - 0.2f)
            o[k++] = (opening){ doors[i] - 0.45f, doors[i] + 0.45f, SLAB, SLAB + 2.1f, false };
    wall(b, m, m->interior, f, a0, a1, c + 0.5f * INNER_WALL, c - 0.5f * INNER_WALL, SLAB,
         STOREY, o, k, false);
}

/* One storey of a ux x uz bay footprint, origin at the footprint centre on
 * the slab bottom. */
static void storey(rl_meshbuf *b, const city *cy, int ux, int uz, int kind, uint32_t facade)
{
    const city_materials *m = &cy->m;
    float w = (float)ux * BAY - 2.0f * LOT_GAP, d = (float)uz * BAY - 2.0f * LOT_GAP;
    float hw = 0.5f * w, hd = 0.5f * d, bx = w / (float)ux, bz = d / (float)uz;
    b->material = m->slab;
    rl_meshbuf_box(b, rl_v3(-hw, 0.0f, -hd), rl_v3(hw, SLAB, hd));

    bool ground = kind == KIND_GROUND;
    bool windows = cy->p.detail >= 1;
    float sill = ground ? SLAB + 0.5f : SLAB + 0.9f, lintel = ground ? STOREY - 0.4f : SLAB + 2.4f;
    float half_x = (ground ? 0.36f : 0.28f) * bx, half_z = (ground ? 0.36f : 0.28f) * bz;
    opening o[MAX_UNITS];
    wall_frame along_x = { false }, along_z = { true };
    for (int side = 0; side < 2; ++side) {
        float s = side ? -1.0f : 1.0f;
        int n = windows ? bay_openings(o, ux, -hw, bx, half_x, sill, lintel) : 0;
        /* The entrance: a door in the middle bay of the front (+z) facade. */
        if (ground && side == 0 && n > 0) {
            float c = -hw + ((float)(ux / 2) + 0.5f) * bx;
            o[ux / 2] = (opening){ c - 0.8f, c + 0.8f, SLAB, SLAB + 2.4f, false };
        }
        wall(b, m, facade, along_x, -hw, hw, s * hd, s * (hd - WALL), SLAB, STOREY, o, n, true);
        n = windows ? bay_openings(o, uz, -hd, bz, half_z, sill, lintel) : 0;
        wall(b, m, facade, along_z, -hd + WALL, hd - WALL, s * hw, s * (hw - WALL), SLAB, STOREY,
             o, n, false);
    }
    if (cy->p.detail < 2)
        return;
    /* Interior: a corridor wall along x (deep footprints) and room walls on
     * every second bay line, each with a door. */
    bool corridor = uz >= 3;
    float room_doors[MAX_UNITS];
    int rooms = 0;
    for (int k = 0; k < ux; k += 2)   /* rooms are two bays wide (the last may be one) */
        room_doors[rooms++] = -hw + (float)k * bx + 0.5f * rl_minf(2.0f, (float)(ux - k)) * bx;
    if (corridor)
        inner_wall(b, m, along_x, -hw + WALL, hw - WALL, 0.0f, room_doors, rooms);
    for (int k = 2; k < ux; k += 2) {
        float x = -hw + (float)k * bx;
        if (corridor) {
            float lo = -hd + WALL, hi = -0.5f * INNER_WALL;
            float door = 0.5f * (lo + hi);
            inner_wall(b, m, along_z, lo, hi, x, &door, 1);
            door = -door;
            inner_wall(b, m, along_z, -hi, -lo, x, &door, 1);
        } else {
            float door = 0.0f;
            inner_wall(b, m, along_z, -hd + WALL, hd - WALL, x, &door, 1);
        }
    }
}

/* Roof slab with a 1 m parapet and, with detail, a stair house. */
static void roof(rl_meshbuf *b, const city *cy, int ux, int uz)
{
    float hw = 0.5f * ((float)ux * BAY - 2.0f * LOT_GAP), hd = 0.5f * ((float)uz * BAY - 2.0f * LOT_GAP);
    const float t = 0.25f, top = SLAB + 1.0f;
    b->material = cy->m.roof;
    rl_meshbuf_box(b, rl_v3(-hw, 0.0f, -hd), rl_v3(hw, SLAB, hd));
    rl_meshbuf_box(b, rl_v3(-hw, SLAB, hd - t), rl_v3(hw, top, hd));
    rl_meshbuf_box(b, rl_v3(-hw, SLAB, -hd), rl_v3(hw, top, -hd + t));
    rl_meshbuf_box(b, rl_v3(-hw, SLAB, -hd + t), rl_v3(-hw + t, top, hd - t));
    rl_meshbuf_box(b, rl_v3(hw - t, SLAB, -hd + t), rl_v3(hw, top, hd - t));
    if (cy->p.detail >= 1)
        rl_meshbuf_box(b, rl_v3(-1.5f, SLAB, -1.5f), rl_v3(1.5f, SLAB + 3.0f, 1.5f));
}

static void translate_vertices(rl_meshbuf *b, uint32_t first, rl_vec3 offset)
{
    if (b->status != RL_OK)
        return;
    for (uint32_t v = first; v < b->num_vertices; ++v)
        b->positions[v] = rl_add(b->positions[v], offset);
}

/* ---- shared meshes ---------------------------------------------------- */

static rl_status finish_mesh(city *cy, rl_meshbuf *b, const char *name, uint32_t *mesh,
                             uint32_t *tris)
{
    *tris = b->num_triangles;
    rl_status s = rl_meshbuf_add_to_scene(cy->scene, b, name, mesh);
    rl_meshbuf_free(b);
    return s;
}

static rl_status storey_mesh(city *cy, int facade, int ux, int uz, int kind, uint32_t *mesh,
                             uint32_t *tris)
{
    uint32_t *slot = &cy->storey_mesh[facade][ux][uz][kind];
    if (*slot == RL_NONE) {
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        if (kind == KIND_ROOF)
            roof(&b, cy, ux, uz);
        else
            storey(&b, cy, ux, uz, kind, cy->m.facade[facade]);
        char name[64];
        static const char *const kinds[NUM_KINDS] = { "ground", "storey", "roof" };
        snprintf(name, sizeof name, "%s_%dx%d_f%d", kinds[kind], ux, uz, facade);
        rl_status s = finish_mesh(cy, &b, name, slot, &cy->storey_tris[facade][ux][uz][kind]);
        if (s) {
            *slot = RL_NONE;
            return s;
        }
    }
    *mesh = *slot;
    *tris = cy->storey_tris[facade][ux][uz][kind];
    return RL_OK;
}

static rl_status furniture_meshes(city *cy)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    float size = (float)cy->p.block_size;
    b.material = cy->m.sidewalk;
    rl_meshbuf_box(&b, rl_v3(0.0f, 0.0f, 0.0f), rl_v3(size, CURB, size));
    rl_status s = finish_mesh(cy, &b, "sidewalk", &cy->sidewalk_mesh, &cy->sidewalk_tris);
    if (s)
        return s;

    /* Street lamp: 6 m pole, arm and lamp head; base at the origin. */
    rl_meshbuf_init(&b);
    b.material = cy->m.lamp;
    rl_gen_cylinder(&b, 0.08f, 6.0f, 8, true);
    translate_vertices(&b, 0, rl_v3(0.0f, 3.0f, 0.0f));
    rl_meshbuf_box(&b, rl_v3(-0.05f, 5.8f, -0.05f), rl_v3(1.2f, 5.9f, 0.05f));
    rl_meshbuf_box(&b, rl_v3(0.9f, 5.6f, -0.2f), rl_v3(1.4f, 5.8f, 0.2f));
    if ((s = finish_mesh(cy, &b, "lamp", &cy->lamp_mesh, &cy->lamp_tris)))
        return s;

    /* Tree: trunk and a low-poly crown. */
    rl_meshbuf_init(&b);
    b.material = cy->m.bark;
    rl_gen_cylinder(&b, 0.2f, 3.0f, 8, false);
    translate_vertices(&b, 0, rl_v3(0.0f, 1.5f, 0.0f));
    uint32_t first = b.num_vertices;
    b.material = cy->m.leaves;
    rl_gen_sphere(&b, 2.0f, 12, 8);
    translate_vertices(&b, first, rl_v3(0.0f, 4.5f, 0.0f));
    return finish_mesh(cy, &b, "tree", &cy->tree_mesh, &cy->tree_tris);
}

/* ---- placement -------------------------------------------------------- */

static rl_status place(city *cy, uint32_t parent, const char *name, uint32_t mesh, uint32_t tris,
                       const char *kind, rl_vec3 at, uint32_t *node)
{
    cy->triangles += tris;
    if (cy->triangles > CITY_MAX_TRIANGLES)
        return rl_error(RL_ERR_LIMIT,
                        "city: more than %u triangles; lower blocks, floors_max or detail",
                        CITY_MAX_TRIANGLES);
    rl_mat4 t = rl_mat4_translate(at);
    return rl_builtin_instance(cy->scene, parent, name, mesh, kind, &t, node);
}

/* Splits `units` bays into lots of 3..6 bays (units >= 3). */
static int split_lots(rl_rng *rng, int units, int *parts)
{
    int n = 0;
    while (units > 0) {
        int part = units;
        if (units > MAX_UNITS) {
            part = 3 + (int)rl_rng_bounded(rng, MAX_UNITS - 2);
            if (units - part < 3)
                part = units - 3;
        }
        parts[n++] = part;
        units -= part;
    }
    return n;
}

static rl_status building(city *cy, rl_rng *rng, uint32_t block, rl_vec3 centre, int ux, int uz,
                          double centrality)
{
    /* Taller towards the centre: the random fraction is scaled by 0.4..1. */
    double f = rl_rng_double(rng) * (0.4 + 0.6 * centrality);
    long long range = cy->p.floors_max - cy->p.floors_min;
    int floors = (int)(cy->p.floors_min + (long long)(f * (double)(range + 1)));
    if (floors > cy->p.floors_max)
        floors = (int)cy->p.floors_max;
    int facade = (int)rl_rng_bounded(rng, FACADES);

    char name[64], value[16];
    snprintf(name, sizeof name, "building_%u", cy->buildings++);
    uint32_t node, mesh, tris;
    rl_status s = place(cy, block, name, RL_NONE, 0, "building", centre, &node);
    snprintf(value, sizeof value, "%d", floors);
    if (!s) s = rl_scene_node_set_attr(cy->scene, node, "floors", value);
    for (int k = 0; k < floors && !s; ++k) {
        int kind = k == 0 ? KIND_GROUND : KIND_UPPER;
        s = storey_mesh(cy, facade, ux, uz, kind, &mesh, &tris);
        snprintf(name, sizeof name, "storey_%d", k);
        if (!s) s = place(cy, node, name, mesh, tris, "storey", rl_v3(0.0f, (float)k * STOREY, 0.0f), NULL);
    }
    if (!s) s = storey_mesh(cy, facade, ux, uz, KIND_ROOF, &mesh, &tris);
    if (!s) s = place(cy, node, "roof", mesh, tris, "roof", rl_v3(0.0f, (float)floors * STOREY, 0.0f), NULL);
    return s;
}

static rl_status city_block(city *cy, int bx, int bz)
{
    const city_params *p = &cy->p;
    float pitch = (float)(p->block_size + p->street_width);
    float half = 0.5f * pitch * (float)p->blocks;
    float x0 = -half + 0.5f * (float)p->street_width + (float)bx * pitch;
    float z0 = -half + 0.5f * (float)p->street_width + (float)bz * pitch;
    float size = (float)p->block_size;
    /* Independent stream per block: the same seed gives the same block. */
    rl_rng rng;
    rl_rng_seed(&rng, (uint64_t)p->seed, (uint64_t)(bz * p->blocks + bx) + 1);

    char name[48];
    snprintf(name, sizeof name, "block_%d_%d", bx, bz);
    uint32_t block;
    rl_status s = place(cy, RL_NODE_ROOT, name, RL_NONE, 0, "block", rl_v3(x0, 0.0f, z0), &block);
    if (!s) s = place(cy, block, "sidewalk", cy->sidewalk_mesh, cy->sidewalk_tris, "sidewalk",
                      rl_v3(0.0f, 0.0f, 0.0f), NULL);

    /* Lots inside the sidewalk ring; leftover metres become extra margin. */
    float inner = size - 2.0f * SIDEWALK;
    int units = (int)(inner / BAY);
    float margin = SIDEWALK + 0.5f * (inner - (float)units * BAY);
    int lx[64], lz[64];  /* units <= 127, parts >= 3 */
    int nx = split_lots(&rng, units, lx), nz = split_lots(&rng, units, lz);
    double dx = ((double)bx + 0.5) / (double)p->blocks - 0.5, dz = ((double)bz + 0.5) / (double)p->blocks - 0.5;
    double centrality = 1.0 - sqrt(2.0 * (dx * dx + dz * dz));
    float cz = margin;
    for (int j = 0; j < nz && !s; ++j) {
        float cx = margin;
        for (int i = 0; i < nx && !s; ++i) {
            rl_vec3 centre = rl_v3(cx + 0.5f * BAY * (float)lx[i], CURB, cz + 0.5f * BAY * (float)lz[j]);
            /* One lot in twelve is a plaza with a tree. */
            if (rl_rng_bounded(&rng, 12) == 0) {
                if (p->furniture)
                    s = place(cy, block, "tree", cy->tree_mesh, cy->tree_tris, "tree", centre, NULL);
            } else {
                s = building(cy, &rng, block, centre, lx[i], lz[j], centrality);
            }
            cx += BAY * (float)lx[i];
        }
        cz += BAY * (float)lz[j];
    }
    if (!p->furniture)
        return s;
    /* Lamps every ~20 m along the curb, trees between some of them. */
    int per_side = (int)(size / 20.0f);
    if (per_side < 1)
        per_side = 1;
    for (int side = 0; side < 4 && !s; ++side)
        for (int k = 0; k < per_side && !s; ++k) {
            float t = ((float)k + 0.5f) / (float)per_side * size, e = 0.5f;
            rl_vec3 at = side == 0 ? rl_v3(t, CURB, e) : side == 1 ? rl_v3(size - e, CURB, t)
                       : side == 2 ? rl_v3(size - t, CURB, size - e) : rl_v3(e, CURB, size - t);
            s = place(cy, block, "lamp", cy->lamp_mesh, cy->lamp_tris, "lamp", at, NULL);
            if (!s && rl_rng_bounded(&rng, 3) == 0) {
                float tt = t + 0.5f * size / (float)per_side;
                if (tt < size - 2.0f) {
                    rl_vec3 tree = side == 0 ? rl_v3(tt, CURB, 1.0f) : side == 1 ? rl_v3(size - 1.0f, CURB, tt)
                                 : side == 2 ? rl_v3(size - tt, CURB, size - 1.0f) : rl_v3(1.0f, CURB, size - tt);
                    s = place(cy, block, "tree", cy->tree_mesh, cy->tree_tris, "tree", tree, NULL);
                }
            }
        }
    return s;
}

/* ---- scene ------------------------------------------------------------ */

static rl_status add_materials(city *cy)
{
    struct { const char *name; float r, g, b, spec, shin, kr, kt; uint32_t *id; } list[] = {
        { "asphalt", 0.12f, 0.12f, 0.13f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.asphalt },
        { "sidewalk", 0.55f, 0.54f, 0.52f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.sidewalk },
        { "slab", 0.60f, 0.60f, 0.58f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.slab },
        { "roof", 0.30f, 0.30f, 0.32f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.roof },
        { "interior", 0.82f, 0.80f, 0.76f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.interior },
        { "glass", 0.05f, 0.07f, 0.08f, 0.8f, 128.0f, 0.3f, 0.5f, &cy->m.glass },
        { "lamp", 0.25f, 0.25f, 0.27f, 0.5f, 64.0f, 0.0f, 0.0f, &cy->m.lamp },
        { "bark", 0.35f, 0.25f, 0.15f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.bark },
        { "leaves", 0.20f, 0.45f, 0.15f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.leaves },
        { "facade_sand", 0.76f, 0.68f, 0.52f, 0.1f, 16.0f, 0.0f, 0.0f, &cy->m.facade[0] },
        { "facade_grey", 0.55f, 0.56f, 0.58f, 0.1f, 16.0f, 0.0f, 0.0f, &cy->m.facade[1] },
        { "facade_brick", 0.55f, 0.25f, 0.18f, 0.0f, 8.0f, 0.0f, 0.0f, &cy->m.facade[2] },
    };
    rl_status s = RL_OK;
    for (size_t i = 0; i < sizeof list / sizeof list[0] && !s; ++i) {
        rl_material m = rl_material_default();
        snprintf(m.name, sizeof m.name, "%s", list[i].name);
        m.diffuse = rl_v3(list[i].r, list[i].g, list[i].b);
        m.specular = rl_v3s(list[i].spec);
        m.shininess = list[i].shin;
        m.reflectivity = list[i].kr;
        m.transmissivity = list[i].kt;
        s = rl_scene_add_material(cy->scene, &m, list[i].id);
    }
    return s;
}

static rl_status read_params(const rl_option_store *params, city_params *p)
{
    *p = (city_params){ .blocks = rl_option_store_int(params, "blocks"),
                        .seed = rl_option_store_int(params, "seed"),
                        .floors_min = rl_option_store_int(params, "floors_min"),
                        .floors_max = rl_option_store_int(params, "floors_max"),
                        .detail = rl_option_store_int(params, "detail"),
                        .block_size = rl_option_store_float(params, "block_size"),
                        .street_width = rl_option_store_float(params, "street_width"),
                        .furniture = rl_option_store_bool(params, "furniture") };
    if (p->floors_min > p->floors_max)
        return rl_error(RL_ERR_INVALID_ARG, "city: floors_min (%lld) exceeds floors_max (%lld)", p->floors_min,
                        p->floors_max);
    return RL_OK;
}

static rl_status build_city(rl_scene *scene, const rl_option_store *params)
{
    city *cy = rl_calloc(1, sizeof *cy);
    if (!cy)
        return RL_ERR_OUT_OF_MEMORY;
    cy->scene = scene;
    rl_status s = read_params(params, &cy->p);
    for (int f = 0; f < FACADES; ++f)
        for (int x = 0; x <= MAX_UNITS; ++x)
            for (int z = 0; z <= MAX_UNITS; ++z)
                for (int k = 0; k < NUM_KINDS; ++k)
                    cy->storey_mesh[f][x][z][k] = RL_NONE;
    if (!s) s = add_materials(cy);
    if (!s) s = furniture_meshes(cy);

    const city_params *p = &cy->p;
    float extent = (float)((p->block_size + p->street_width) * (double)p->blocks);
    if (!s) {
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        b.material = cy->m.asphalt;
        rl_gen_quad(&b, extent + 2.0f * (float)p->street_width, extent + 2.0f * (float)p->street_width,
                    extent / 8.0f);
        uint32_t mesh, tris;
        s = finish_mesh(cy, &b, "ground", &mesh, &tris);
        if (!s) s = place(cy, RL_NODE_ROOT, "ground", mesh, tris, "ground", rl_v3s(0.0f), NULL);
    }
    for (int bz = 0; bz < p->blocks && !s; ++bz)
        for (int bx = 0; bx < p->blocks && !s; ++bx)
            s = city_block(cy, bx, bz);

    if (!s) {
        rl_light sun = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1.0f, 0.96f, 0.88f),
                         .intensity = 3.0f, .direction = rl_v3(-0.35f, -0.8f, -0.45f) };
        rl_light sky = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(0.55f, 0.65f, 0.9f),
                         .intensity = 0.4f, .direction = rl_v3(0.3f, -1.0f, 0.5f) };
        s = rl_scene_add_light(scene, &sun);
        if (!s) s = rl_scene_add_light(scene, &sky);
    }
    if (!s) {
        rl_camera overview = { .eye = rl_v3(0.55f * extent, 0.45f * extent, 0.75f * extent),
                               .target = rl_v3s(0.0f), .up = rl_v3(0.0f, 1.0f, 0.0f),
                               .fov_deg = 45.0f, .width = 960, .height = 540 };
        /* The street nearest the centre line, looking along it. */
        float pitch = (float)(p->block_size + p->street_width);
        float x = -0.5f * extent + (float)(p->blocks / 2) * pitch;
        rl_camera street = { .eye = rl_v3(x, 1.7f, 0.5f * extent - 2.0f),
                             .target = rl_v3(x, 1.7f + 0.05f * extent, -0.5f * extent),
                             .up = rl_v3(0.0f, 1.0f, 0.0f), .fov_deg = 60.0f,
                             .width = 960, .height = 540 };
        s = rl_scene_add_camera(scene, "overview", &overview);
        if (!s) s = rl_scene_add_camera(scene, "street", &street);
    }
    free(cy);
    return s;
}

static const rl_option_info city_options[] = {
    { "blocks", RL_OPT_INT, "6", "blocks per side", 1, 64, NULL },
    { "seed", RL_OPT_INT, "1", "random seed of the buildings", 0, 9007199254740992.0, NULL },
    { "floors_min", RL_OPT_INT, "2", "lowest building, floors", 1, 200, NULL },
    { "floors_max", RL_OPT_INT, "16", "highest building, floors (>= floors_min)", 1, 200, NULL },
    { "detail", RL_OPT_INT, "2", "0: boxes with slabs, 1: + windows, 2: + interior walls", 0, 2, NULL },
    { "block_size", RL_OPT_FLOAT, "64", "block side, m", 24, 512, NULL },
    { "street_width", RL_OPT_FLOAT, "16", "street width, m", 4, 200, NULL },
    { "furniture", RL_OPT_BOOL, "true", "street lamps and trees", 0, 0, NULL },
};

const rl_builtin_class rl_builtin_city_class = {
    { "city",
      "procedural city: blocks of buildings with window openings, floor slabs and interior rooms, street lamps "
      "and trees; for visibility and LOD work",
      RL_BUILTIN_OPTIONS(city_options) },
    build_city,
};
