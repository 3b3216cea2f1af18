/* generators.c: procedural meshes for JSON and built-in scenes
 * (rl_scene_add_generated). Each generator adds one mesh named after it.
 *
 * Parameters ("key=value", separated by commas or spaces; unknown keys are
 * RL_ERR_INVALID_ARG, values outside the range likewise):
 *
 * | generator | key      | default | range         | meaning                                   |
 * |-----------|----------|---------|---------------|-------------------------------------------|
 * | box       | size     | 1       | (0, 1e6]      | edge lengths: one number (cube) or three   |
 * |           |          |         |               | joined by 'x' or ':' ("2x1x0.5")           |
 * |           | sx,sy,sz | size    | (0, 1e6]      | edge length along one axis (overrides size)|
 * |           |          |         |               | 12 triangles, centred on the origin, flat  |
 * |           |          |         |               | normals, uv 0..1 per face                  |
 * | quad      | sx, sz   | 1       | (0, 1e6]      | extent along x and z; the plane y = 0,     |
 * |           |          |         |               | centred, facing +y, 2 triangles            |
 * |           | repeat   | 1       | [1e-3, 1e4]   | uv runs 0..repeat (texture tiling)         |
 * | sphere    | radius   | 1       | (0, 1e6]      | UV sphere centred on the origin            |
 * |           | segments | 32      | [3, 4096]     | divisions around y (longitude)             |
 * |           | rings    | 16      | [2, 4096]     | divisions pole to pole (latitude);         |
 * |           |          |         |               | 2*segments*(rings-1) triangles, smooth     |
 * |           |          |         |               | normals, u = longitude, v = latitude       |
 * | cylinder  | radius   | 1       | (0, 1e6]      | circular cylinder around y, centred        |
 * |           | height   | 2       | (0, 1e6]      | y from -height/2 to +height/2              |
 * |           | segments | 32      | [3, 65536]    | divisions around y; smooth side normals    |
 * |           | caps     | true    | bool          | close top and bottom with flat discs       |
 * | teapot    | triangles| 15704   | [1, 4000000]  | target count; the per-patch grid closest   |
 * |           |          |         |               | to it is used (minimum 56). 15704 is       |
 * |           |          |         |               | Schröder 2017's teapot (13 x 19 per patch) |
 * |           | size     | 1       | (0, 1e6]      | height; stands on y = 0 around the y axis, |
 * |           |          |         |               | spout towards +x, width about 2.04 * size  |
 * | blob      | triangles| 20000   | even, [4, 16e6]| exactly this many triangles; closed,      |
 * |           |          |         |               | genus 0, outward (blob.c); odd is an error |
 * |           | seed     | 1       | [0, 2^53]     | lump placement                             |
 * |           | scale    | 1       | (0, 1e6]      | radius of the sphere before the lumps      |
 * |           | lumps    | 6       | [0, 64]       | smooth bumps and dents                     |
 *
 * The teapot is Newell's 32-patch Utah teapot (teapot.c). The blob
 * (blob.c) stands in for the bunny and dragon of Schröder 2017, Sec. 9.3. */
#include "scene/generators.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"
#include "core/params.h"
#include "scene/blob.h"

#define GEN_MAX_SIZE 1e6

void rl_gen_box(rl_meshbuf *b, rl_vec3 size)
{
    rl_vec3 h = rl_scale(size, 0.5f);
    rl_meshbuf_box(b, rl_neg(h), h);
}

void rl_gen_quad(rl_meshbuf *b, float sx, float sz, float repeat)
{
    float x = 0.5f * sx, z = 0.5f * sz;
    /* Counter-clockwise seen from +y so the normal is +y; uv u along +x,
     * v along -z (towards the back, as a texture lies on the floor). */
    rl_meshbuf_quad(b, rl_v3(-x, 0.0f, z), rl_v3(x, 0.0f, z), rl_v3(x, 0.0f, -z),
                    rl_v3(-x, 0.0f, -z), rl_v2(repeat, repeat));
}

void rl_gen_sphere(rl_meshbuf *b, float radius, uint32_t segments, uint32_t rings)
{
    /* (segments+1) x (rings+1) vertices: the seam column is duplicated for
     * continuous u, and each pole gets one vertex per segment so that the
     * pole triangles have their own u; those rings emit one triangle per
     * segment instead of a degenerate quad. */
    if (!rl_meshbuf_reserve(b, (uint64_t)(segments + 1) * (rings + 1),
                            2ull * segments * (rings - 1)))
        return;
    uint32_t base = b->num_vertices;
    for (uint32_t r = 0; r <= rings; ++r) {
        float v = (float)r / (float)rings;
        float theta = v * RL_PI;                   /* from +y down */
        float st = sinf(theta), ct = cosf(theta);
        if (r == 0 || r == rings)
            st = 0.0f;                             /* exact poles */
        for (uint32_t s = 0; s <= segments; ++s) {
            float u = (float)s / (float)segments;
            float phi = u * 2.0f * RL_PI;
            rl_vec3 n = rl_v3(st * cosf(phi), ct, -st * sinf(phi));
            rl_meshbuf_vertex(b, rl_scale(n, radius), n, rl_v2(u, 1.0f - v));
        }
    }
    uint32_t row = segments + 1;
    for (uint32_t r = 0; r < rings; ++r) {
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t a = base + r * row + s, c = a + 1;      /* upper ring */
            uint32_t d = a + row, e = d + 1;                 /* lower ring */
            /* phi grows towards -z, i.e. counter-clockwise seen from +y. */
            if (r != 0)
                rl_meshbuf_triangle(b, a, d, c);
            if (r != rings - 1)
                rl_meshbuf_triangle(b, c, d, e);
        }
    }
}

void rl_gen_cylinder(rl_meshbuf *b, float radius, float height, uint32_t segments, bool caps)
{
    float h = 0.5f * height;
    uint64_t nv = 2ull * (segments + 1) + (caps ? 2ull * (segments + 1) : 0);
    uint64_t nt = 2ull * segments + (caps ? 2ull * segments : 0);
    if (!rl_meshbuf_reserve(b, nv, nt))
        return;
    uint32_t side = b->num_vertices;
    for (uint32_t s = 0; s <= segments; ++s) {
        float u = (float)s / (float)segments;
        float phi = u * 2.0f * RL_PI;
        rl_vec3 n = rl_v3(cosf(phi), 0.0f, -sinf(phi));
        rl_vec3 p = rl_scale(n, radius);
        rl_meshbuf_vertex(b, rl_v3(p.x, -h, p.z), n, rl_v2(u, 0.0f));
        rl_meshbuf_vertex(b, rl_v3(p.x, h, p.z), n, rl_v2(u, 1.0f));
    }
    for (uint32_t s = 0; s < segments; ++s) {
        uint32_t a = side + 2 * s;     /* bottom, top at a+1; next column a+2 */
        rl_meshbuf_triangle(b, a, a + 2, a + 3);
        rl_meshbuf_triangle(b, a, a + 3, a + 1);
    }
    if (!caps)
        return;
    for (int top = 0; top < 2; ++top) {
        float y = top ? h : -h;
        rl_vec3 n = rl_v3(0.0f, top ? 1.0f : -1.0f, 0.0f);
        uint32_t centre = rl_meshbuf_vertex(b, rl_v3(0.0f, y, 0.0f), n, rl_v2(0.5f, 0.5f));
        uint32_t rim = b->num_vertices;
        for (uint32_t s = 0; s < segments; ++s) {
            float phi = (float)s / (float)segments * 2.0f * RL_PI;
            float c = cosf(phi), sn = sinf(phi);
            rl_meshbuf_vertex(b, rl_v3(radius * c, y, -radius * sn), n,
                              rl_v2(0.5f + 0.5f * c, 0.5f + 0.5f * sn));
        }
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t p = rim + s, q = rim + (s + 1) % segments;
            /* The rim runs counter-clockwise seen from +y. */
            if (top)
                rl_meshbuf_triangle(b, centre, p, q);
            else
                rl_meshbuf_triangle(b, centre, q, p);
        }
    }
}

/* "2", "2x1x3" or "2:1:3" -> edge lengths. */
static rl_status parse_size(const char *text, rl_vec3 *out)
{
    char buf[128];
    size_t len = strlen(text);
    if (len >= sizeof buf)
        return rl_error(RL_ERR_INVALID_ARG, "box: size \"%.32s...\" is too long", text);
    memcpy(buf, text, len + 1);
    double v[3];
    int n = 0;
    char *start = buf;
    for (char *c = buf;; ++c) {
        bool end = *c == '\0';
        if (end || *c == 'x' || *c == 'X' || *c == ':') {
            *c = '\0';
            if (n == 3 || !rl_parse_float(start, &v[n]) || !(v[n] > 0.0) || v[n] > GEN_MAX_SIZE)
                return rl_error(RL_ERR_INVALID_ARG,
                                "box: size \"%s\": expected one or three numbers in (0, 1e6] "
                                "joined by 'x' or ':'", text);
            ++n;
            start = c + 1;
            if (end)
                break;
        }
    }
    if (n == 2)
        return rl_error(RL_ERR_INVALID_ARG, "box: size \"%s\": expected one or three numbers",
                        text);
    *out = n == 1 ? rl_v3s((float)v[0]) : rl_v3((float)v[0], (float)v[1], (float)v[2]);
    return RL_OK;
}

/* Each generator's parameters, one table row per key (the option store of
 * src/core/options.h; docs/scene-format.md lists them). Sizes lie in
 * (0, 1e6]: the tables say [1e-30, 1e6]. */
#define GEN_SIZE(key, def, help) { key, RL_OPT_FLOAT, def, help, 1e-30, GEN_MAX_SIZE, NULL }

static const rl_option_info box_options[] = {
    { "size", RL_OPT_STRING, "1", "edge length, or three joined by x (\"2x1x0.5\"); centred", 0, 0, NULL },
    GEN_SIZE("sx", "1", "edge length along x; not given: from size"),
    GEN_SIZE("sy", "1", "edge length along y; not given: from size"),
    GEN_SIZE("sz", "1", "edge length along z; not given: from size"),
};

static rl_status build_box(rl_meshbuf *b, const rl_option_store *p)
{
    rl_vec3 size = rl_v3s(1.0f);
    rl_status s = rl_option_store_given(p, "size") ? parse_size(rl_option_store_string(p, "size"), &size) : RL_OK;
    /* An edge given on its own wins over size. */
    double e[3] = { size.x, size.y, size.z };
    const char *keys[3] = { "sx", "sy", "sz" };
    for (int k = 0; k < 3; ++k)
        if (rl_option_store_given(p, keys[k]))
            e[k] = rl_option_store_float(p, keys[k]);
    if (!s)
        rl_gen_box(b, rl_v3((float)e[0], (float)e[1], (float)e[2]));
    return s;
}

static const rl_option_info quad_options[] = {
    GEN_SIZE("sx", "1", "extent along x in the plane y = 0, centred, facing +y"),
    GEN_SIZE("sz", "1", "extent along z"),
    { "repeat", RL_OPT_FLOAT, "1", "uv runs 0..repeat", 1e-3, 1e4, NULL },
};

static rl_status build_quad(rl_meshbuf *b, const rl_option_store *p)
{
    rl_gen_quad(b, (float)rl_option_store_float(p, "sx"), (float)rl_option_store_float(p, "sz"),
                (float)rl_option_store_float(p, "repeat"));
    return RL_OK;
}

static const rl_option_info sphere_options[] = {
    GEN_SIZE("radius", "1", "UV sphere centred on the origin"),
    { "segments", RL_OPT_INT, "32", "divisions around y", 3, 4096, NULL },
    { "rings", RL_OPT_INT, "16", "divisions pole to pole", 2, 4096, NULL },
};

static rl_status build_sphere(rl_meshbuf *b, const rl_option_store *p)
{
    rl_gen_sphere(b, (float)rl_option_store_float(p, "radius"), (uint32_t)rl_option_store_int(p, "segments"),
                  (uint32_t)rl_option_store_int(p, "rings"));
    return RL_OK;
}

static const rl_option_info cylinder_options[] = {
    GEN_SIZE("radius", "1", "around y, centred"),
    GEN_SIZE("height", "2", "along y"),
    { "segments", RL_OPT_INT, "32", "divisions around y", 3, 65536, NULL },
    { "caps", RL_OPT_BOOL, "true", "close top and bottom", 0, 0, NULL },
};

static rl_status build_cylinder(rl_meshbuf *b, const rl_option_store *p)
{
    rl_gen_cylinder(b, (float)rl_option_store_float(p, "radius"), (float)rl_option_store_float(p, "height"),
                    (uint32_t)rl_option_store_int(p, "segments"), rl_option_store_bool(p, "caps"));
    return RL_OK;
}

_Static_assert(RL_TEAPOT_DEFAULT_TRIANGLES == 15704, "the table's default is the teapot's");
static const rl_option_info teapot_options[] = {
    { "triangles", RL_OPT_INT, "15704", "target count (Utah teapot from its Bezier patches)", 1,
      RL_TEAPOT_MAX_TRIANGLES, NULL },
    GEN_SIZE("size", "1", "height; stands on y = 0"),
};

static rl_status build_teapot(rl_meshbuf *b, const rl_option_store *p)
{
    rl_gen_teapot(b, (uint32_t)rl_option_store_int(p, "triangles"), (float)rl_option_store_float(p, "size"));
    return RL_OK;
}

_Static_assert(RL_BLOB_DEFAULT_TRIANGLES == 20000, "the table's default is the blob's");
static const rl_option_info blob_options[] = {
    { "triangles", RL_OPT_INT, "20000", "exactly this many (even): a closed, genus-0, outward-oriented mesh",
      RL_BLOB_MIN_TRIANGLES, RL_BLOB_MAX_TRIANGLES, NULL },
    { "seed", RL_OPT_INT, "1", "lump placement", 0, 9007199254740992.0, NULL },
    GEN_SIZE("scale", "1", "radius of the sphere before the lumps"),
    { "lumps", RL_OPT_INT, "6", "smooth bumps and dents", 0, RL_BLOB_MAX_LUMPS, NULL },
};

static rl_status build_blob(rl_meshbuf *b, const rl_option_store *p)
{
    return rl_gen_blob(b, &(rl_blob_desc){ .triangles = (uint32_t)rl_option_store_int(p, "triangles"),
                                           .seed = (uint64_t)rl_option_store_int(p, "seed"),
                                           .scale = (float)rl_option_store_float(p, "scale"),
                                           .lumps = (int)rl_option_store_int(p, "lumps") });
}

typedef struct generator {
    const char *name;
    const rl_option_info *options;
    size_t num_options;
    rl_status (*build)(rl_meshbuf *b, const rl_option_store *p);
} generator;

#define GEN(name, table, build) { name, table, sizeof table / sizeof table[0], build }
static const generator generators[] = {
    GEN("box", box_options, build_box),
    GEN("quad", quad_options, build_quad),
    GEN("sphere", sphere_options, build_sphere),
    GEN("cylinder", cylinder_options, build_cylinder),
    GEN("teapot", teapot_options, build_teapot),
    GEN("blob", blob_options, build_blob),
};
#define NUM_GENERATORS (sizeof generators / sizeof generators[0])

static const char *const generator_names[NUM_GENERATORS + 1] = {
    "box", "quad", "sphere", "cylinder", "teapot", "blob", NULL
};

const char *const *rl_generator_names(size_t *count)
{
    if (count)
        *count = NUM_GENERATORS;
    return generator_names;
}

rl_status rl_scene_add_generated(rl_scene *scene, const char *generator_name,
                                 const char *params, uint32_t material, uint32_t *mesh_id)
{
    if (!scene || !generator_name)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_generated: scene and generator "
                                            "must not be NULL");
    const generator *g = NULL;
    for (size_t i = 0; i < NUM_GENERATORS; ++i)
        if (strcmp(generators[i].name, generator_name) == 0)
            g = &generators[i];
    if (!g)
        return rl_error(RL_ERR_NOT_FOUND, "unknown generator \"%s\" (known: box, quad, "
                                          "sphere, cylinder, teapot, blob)", generator_name);
    /* Every key=value checked against the table first; a repeated key
     * keeps the last value. */
    rl_params list;
    rl_status s = rl_params_parse(params, &list);
    if (s)
        return s;
    rl_option_store p;
    s = rl_option_store_init(&p, g->options, g->num_options, NULL);
    for (uint32_t i = 0; s == RL_OK && i < list.count; ++i)
        s = rl_option_store_set(&p, list.items[i].key, list.items[i].value, g->name, NULL);
    rl_params_free(&list);
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = material;
    if (!s)
        s = g->build(&b, &p);
    if (!s)
        s = rl_meshbuf_add_to_scene(scene, &b, g->name, mesh_id);
    rl_meshbuf_free(&b);
    rl_option_store_free(&p);
    return s;
}
