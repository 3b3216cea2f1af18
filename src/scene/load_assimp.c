/* load_assimp.c: imports mesh files (OBJ, PLY, STL, glTF, DAE, FBX, ...) with
 * the Assimp C API into a scene under a given parent node.
 *
 * Mapping: every aiNode becomes a scene node with its transform (aiMatrix4x4
 * is row-major a1..d4 with column vectors, like rl_mat4, so it is copied
 * element by element); a node carrying one mesh gets it directly, a node with
 * several gets one child node per mesh. Each aiMesh becomes one rl mesh that
 * all its instances share. Materials map onto the Phong model of
 * rl_material: diffuse (glTF base colour when there is no diffuse), specular,
 * shininess, reflectivity, k_t = 1 - opacity, ior = refracti, emissive,
 * diffuse texture (a file relative to the model file, or embedded in it:
 * load_embedded.c). Assimp cameras and point, spot and directional lights
 * are imported too.
 *
 * Assimp is lenient with broken input, so we add checks of our own
 * (load_validate.c) before and after it runs: control bytes in OBJ text,
 * PLY bodies shorter than their header, face indices out of range. Point and
 * line primitives are skipped with one warning. NaN positions pass through
 * to rl_scene_add_mesh(), which drops and counts those triangles.
 *
 * It runs where load_isolate.c puts it: by default in a child process.
 *
 * Failure: RL_ERR_IO for a missing file, RL_ERR_PARSE "path: <reason>" for
 * anything Assimp or our checks reject, including a file without triangles;
 * all of these are found before the scene is touched. Later failures (out of
 * memory, an undecodable texture) can leave nodes behind in the scene, which
 * the caller then releases. */
#define _POSIX_C_SOURCE 200809L   /* stat, opendir, strcasecmp */
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/options.h"
#include "scene/load_internal.h"
#include "scene/scene_internal.h"

#define PATH_MAX_LEN 4096

static rl_mat4 from_ai(const struct aiMatrix4x4 *a)
{
    rl_mat4 m = { { { a->a1, a->a2, a->a3, a->a4 },
                    { a->b1, a->b2, a->b3, a->b4 },
                    { a->c1, a->c2, a->c3, a->c4 },
                    { a->d1, a->d2, a->d3, a->d4 } } };
    return m;
}

/* Local-to-world transform of an existing scene node: parents always have
 * smaller ids than their children, but walking up is just as simple. */
static rl_mat4 scene_node_world(const rl_scene *scene, uint32_t node)
{
    rl_mat4 world = rl_mat4_identity();
    for (uint32_t n = node; n != RL_NONE && n < scene->num_nodes; n = scene->nodes[n].parent)
        world = rl_mat4_mul(&scene->nodes[n].local, &world);
    return world;
}

static bool is_triangle_face(const struct aiFace *f) { return f->mNumIndices == 3; }

/* Everything that can be wrong with the imported data is checked here, before
 * the scene is modified, so that a rejected file leaves the scene untouched. */
static rl_status check_scene(const char *path, const struct aiScene *ai)
{
    uint64_t triangles = 0, skipped = 0;
    for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
        const struct aiMesh *m = ai->mMeshes[i];
        if (!m->mVertices && m->mNumVertices > 0)
            return rl_error(RL_ERR_PARSE, "%s: mesh %u has no vertex positions", path, i);
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            const struct aiFace *face = &m->mFaces[f];
            for (unsigned k = 0; k < face->mNumIndices; ++k)
                if (face->mIndices[k] >= m->mNumVertices)
                    return rl_error(RL_ERR_PARSE,
                                    "%s: mesh \"%s\": face %u uses vertex %u of %u", path,
                                    m->mName.data, f, face->mIndices[k], m->mNumVertices);
            if (is_triangle_face(face))
                ++triangles;
            else
                ++skipped;
        }
        if (m->mMaterialIndex >= ai->mNumMaterials)
            return rl_error(RL_ERR_PARSE, "%s: mesh \"%s\" refers to material %u of %u", path,
                            m->mName.data, m->mMaterialIndex, ai->mNumMaterials);
    }
    if (triangles > RL_SCENE_MAX_TRIANGLES)
        return rl_error(RL_ERR_LIMIT, "%s: %llu triangles exceed the limit of %u", path,
                        (unsigned long long)triangles, RL_SCENE_MAX_TRIANGLES);
    if (triangles == 0)
        return rl_error(RL_ERR_PARSE, "%s: no triangles", path);
    if (skipped > 0)
        rl_warn("%s: ignoring %llu point and line primitives", path, (unsigned long long)skipped);
    return RL_OK;
}

static bool get_color(const struct aiMaterial *mat, const char *key, unsigned type,
                      unsigned idx, rl_vec3 *out)
{
    struct aiColor4D c;
    if (aiGetMaterialColor(mat, key, type, idx, &c) != aiReturn_SUCCESS)
        return false;
    rl_vec3 v = rl_v3(c.r, c.g, c.b);
    if (!rl_vfinite(v))
        return false;
    *out = rl_v3(rl_maxf(v.x, 0.0f), rl_maxf(v.y, 0.0f), rl_maxf(v.z, 0.0f));
    return true;
}

static bool get_float(const struct aiMaterial *mat, const char *key, unsigned type,
                      unsigned idx, float *out)
{
    ai_real f;
    unsigned one = 1;
    if (aiGetMaterialFloatArray(mat, key, type, idx, &f, &one) != aiReturn_SUCCESS ||
        !isfinite((float)f))
        return false;
    *out = (float)f;
    return true;
}

/* What an import could not map faithfully, counted over the whole file
 * and reported in one warning (import_notes), not one line per mesh. */
typedef struct import_notes {
    unsigned normal_maps, pbr_textures, alpha_modes, invisible;
    unsigned textures_missing, textures_case;
    char missing_names[512];    /* the first three missing textures */
} import_notes;

/* What materials need while they are converted. */
typedef struct material_ctx {
    rl_scene *scene;
    const char *path, *dir;     /* the model file and its folder */
    const struct aiScene *ai;
    uint32_t *embedded;         /* scene texture id per aiTexture, RL_NONE until used */
    import_notes notes;
    bool ggx;                   /* rl_scene_import_desc.ggx_materials */
} material_ctx;

static float luminance(rl_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/* glTF 2.0 metallic-roughness onto the Phong model of rl_material, as close
 * as one diffuse lobe, one Phong lobe and one mirror allow:
 * - diffuse: base colour x (1 - metallic) (glTF 2.0 spec, Appendix B: the
 *   metal has no diffuse lobe);
 * - specular: the Fresnel reflectance at normal incidence, 0.04 for
 *   dielectrics and the base colour for metals, blended by metallic;
 * - shininess: the Phong exponent whose lobe matches the microfacet lobe
 *   of alpha = roughness^2, n = 2 / alpha^2 - 2 (Walter et al. 2007,
 *   Sec. 3.3 gives the Beckmann/Phong correspondence), clamped to 1..10^4;
 * - reflectivity: a metal smoother than roughness 0.2 reflects as a
 *   mirror; its lobe would be narrower than a pixel at common sizes, which
 *   the Phong highlight cannot show. Our choice, since Phong has no
 *   microfacet lobe. */
static void map_metal_roughness(rl_material *m, rl_vec3 base, float metallic, float roughness)
{
    /* ... unless the loader asks for the microfacet BRDF, which takes the
     * glTF values as they are (materials=ggx; off by default so that
     * imported models render as before). */
    if (m->bsdf == RL_BSDF_GGX) {
        m->diffuse = base;
        m->metallic = metallic;
        m->roughness = roughness;
        return;
    }
    m->diffuse = rl_scale(base, 1.0f - metallic);
    m->specular = rl_add(rl_scale(rl_v3s(0.04f), 1.0f - metallic), rl_scale(base, metallic));
    float alpha = rl_maxf(roughness * roughness, 1e-3f);
    m->shininess = rl_clampf(2.0f / (alpha * alpha) - 2.0f, 1.0f, 1e4f);
    if (roughness < 0.2f) {
        float smooth = 1.0f - roughness / 0.2f;
        m->reflectivity = rl_clampf(metallic * smooth * luminance(m->specular), 0.0f, 1.0f);
    }
}

/* Assimp names embedded textures "*<index>"; some readers use the original
 * file name instead (what aiScene::GetEmbeddedTexture matches in C++). */
static int embedded_index(const struct aiScene *ai, const char *ref)
{
    if (ref[0] == '*') {
        char *end;
        unsigned long i = strtoul(ref + 1, &end, 10);
        return end != ref + 1 && *end == '\0' && i < ai->mNumTextures ? (int)i : -1;
    }
    const char *base = strrchr(ref, '/') ? strrchr(ref, '/') + 1 : ref;
    for (unsigned i = 0; i < ai->mNumTextures; ++i) {
        const char *name = ai->mTextures[i]->mFilename.data;
        const char *nb = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
        if (name[0] && strcmp(nb, base) == 0)
            return (int)i;
    }
    return -1;
}

static rl_status load_embedded(material_ctx *c, int index, uint32_t *id)
{
    if (c->embedded[index] == RL_NONE) {
        char what[PATH_MAX_LEN + 32];
        snprintf(what, sizeof what, "%s: texture *%d", c->path, index);
        rl_texture *tex = NULL;
        rl_status st = rl_embedded_texture_decode(c->ai->mTextures[index], what, &tex);
        if (st == RL_OK && (st = rl_scene_add_texture(c->scene, tex, &c->embedded[index])) != RL_OK)
            rl_texture_release(tex);
        if (st != RL_OK)
            return st;
    }
    *id = c->embedded[index];
    return RL_OK;
}

static bool is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* The name in dir that equals name ignoring ASCII case, into out. */
static bool match_nocase(const char *dir, const char *name, char *out, size_t size)
{
    DIR *d = opendir(dir[0] ? dir : ".");
    if (!d)
        return false;
    bool found = false;
    for (struct dirent *e; !found && (e = readdir(d)) != NULL;) {
        if (strcasecmp(e->d_name, name) != 0)
            continue;
        rl_path_join(dir, e->d_name, out, size);
        found = is_file(out);
    }
    closedir(d);
    return found;
}

/* Where a texture reference that does not resolve as written may be: the
 * same path with other letter case (files made on Windows or macOS ask for
 * TEST.PNG where test.png sits), or only its file name beside the model
 * (an absolute path from the author's machine, "D:/projects/.../wood.jpg").
 * Only the model's folder and the reference's own folder are searched, and
 * each find costs a warning, so that a wrong guess is visible. */
static bool find_texture_nearby(material_ctx *c, const char *rel, char *out, size_t size)
{
    const char *slash = strrchr(rel, '/');
    const char *name = slash ? slash + 1 : rel;
    char dir[PATH_MAX_LEN], joined[PATH_MAX_LEN];
    rl_path_join(c->dir, rel, joined, sizeof joined);
    rl_path_dirname(joined, dir, sizeof dir);
    bool found = name[0] && (match_nocase(dir, name, out, size) ||
                             (strcmp(dir, c->dir) != 0 && match_nocase(c->dir, name, out, size)));
    if (found) {
        rl_warn("%s: texture %s not found as written, using %s", c->path, rel, out);
        c->notes.textures_case++;
    }
    return found;
}

/* Resolves a texture reference of the model file: an embedded texture, or a
 * path against the model's folder, loaded through the scene (which shares
 * repeated paths). A texture file that is missing only costs a warning, as
 * in viewers; one that exists but cannot be decoded is an error. */
static rl_status load_material_texture(material_ctx *c, const char *tex_path, uint32_t *id)
{
    *id = RL_NONE;
    int index = embedded_index(c->ai, tex_path);
    if (index >= 0)
        return load_embedded(c, index, id);
    if (tex_path[0] == '*') {
        rl_warn("%s: embedded texture %s does not exist, material left untextured", c->path,
                tex_path);
        return RL_OK;
    }
    char rel[PATH_MAX_LEN], full[PATH_MAX_LEN];
    /* Files written on Windows often use backslashes. */
    snprintf(rel, sizeof rel, "%s", tex_path);
    for (char *ch = rel; *ch; ++ch)
        if (*ch == '\\')
            *ch = '/';
    if (rel[0] == '\0')
        return RL_OK;   /* an empty reference: no texture (MD5 writes them) */
    rl_path_join(c->dir, rel, full, sizeof full);
    if (!is_file(full) && !find_texture_nearby(c, rel, full, sizeof full)) {
        if (c->notes.textures_missing++ < 3)
            rl_option_append(c->notes.missing_names, sizeof c->notes.missing_names,
                             c->notes.textures_missing > 1 ? ", " : "");
        if (c->notes.textures_missing <= 3)
            rl_option_append(c->notes.missing_names, sizeof c->notes.missing_names, rel);
        return RL_OK;
    }
    /* rl_scene_load_texture resolves relative paths against the scene's base
     * dir; an absolute or cwd-relative path must reach it unchanged, so the
     * base dir is cleared for the call and restored afterwards. */
    rl_scene *scene = c->scene;
    char *saved = rl_strdup(rl_scene_base_dir(scene) ? rl_scene_base_dir(scene) : "");
    if (!saved)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = rl_scene_set_base_dir(scene, "");
    if (st == RL_OK) {
        st = rl_scene_load_texture(scene, full, id);
        rl_status st2 = rl_scene_set_base_dir(scene, saved);
        if (st == RL_OK)
            st = st2;
    }
    free(saved);
    return st;
}

/* A normal map holds vectors, not colours: the texture loaders decode sRGB,
 * so the map gets a copy of its own with the decoding undone (exact for
 * 8-bit texels, done before any filtering). The decoded texture stays
 * shared by path for any colour use. */
static rl_status load_normal_map(material_ctx *c, const char *tex_path, uint32_t *id)
{
    uint32_t colour = RL_NONE;
    rl_status st = load_material_texture(c, tex_path, &colour);
    *id = RL_NONE;
    if (st != RL_OK || colour == RL_NONE)
        return st;
    const rl_texture *src = c->scene->textures[colour];
    size_t n = (size_t)src->width * (size_t)src->height;
    rl_vec4 *raw = rl_calloc(n ? n : 1, sizeof *raw);
    if (!raw)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: normal map: out of memory", c->path);
    for (size_t i = 0; i < n; ++i) {
        rl_vec4 t = src->texels[i];
        raw[i] = rl_v4(rl_linear_to_srgb(t.x), rl_linear_to_srgb(t.y), rl_linear_to_srgb(t.z), t.w);
    }
    rl_texture *tex = NULL;
    st = rl_texture_create(src->width, src->height, raw, &tex);
    free(raw);
    if (st == RL_OK && (st = rl_scene_add_texture(c->scene, tex, id)) != RL_OK)
        rl_texture_release(tex);
    return st;
}

static rl_status add_material(material_ctx *c, const struct aiMaterial *mat, uint32_t *id)
{
    rl_material m = rl_material_default();
    struct aiString name;
    if (aiGetMaterialString(mat, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS)
        snprintf(m.name, sizeof m.name, "%.63s", name.data);

    rl_vec3 base;
    float metallic = 0.0f, roughness = 1.0f, f;
    /* Both factors are read (each keeps its default when absent); either
     * one makes the material metallic-roughness. */
    bool has_metallic = get_float(mat, AI_MATKEY_METALLIC_FACTOR, &metallic);
    bool has_roughness = get_float(mat, AI_MATKEY_ROUGHNESS_FACTOR, &roughness);
    bool pbr = get_color(mat, AI_MATKEY_BASE_COLOR, &base) && (has_metallic || has_roughness);
    if (pbr) {
        if (c->ggx)
            m.bsdf = RL_BSDF_GGX;
        map_metal_roughness(&m, base, rl_clampf(metallic, 0.0f, 1.0f),
                            rl_clampf(roughness, 0.0f, 1.0f));
    } else {
        if (!get_color(mat, AI_MATKEY_COLOR_DIFFUSE, &m.diffuse))
            get_color(mat, AI_MATKEY_BASE_COLOR, &m.diffuse);
        get_color(mat, AI_MATKEY_COLOR_SPECULAR, &m.specular);
        if (get_float(mat, AI_MATKEY_SHININESS, &f))
            m.shininess = rl_maxf(f, 0.0f);
        /* The mirror term is reflectivity x reflective colour (Collada's
         * <reflective> and <reflectivity>, COLLADA 1.4.1 spec, Ch. 8
         * "phong"); rl_material has one scalar k_r, so the colour
         * contributes its luminance. A file without a reflective colour
         * means a white one. */
        float reflectivity;
        if (get_float(mat, AI_MATKEY_REFLECTIVITY, &reflectivity)) {
            rl_vec3 reflective = rl_v3s(1.0f);
            get_color(mat, AI_MATKEY_COLOR_REFLECTIVE, &reflective);
            m.reflectivity = rl_clampf(reflectivity * luminance(reflective), 0.0f, 1.0f);
        }
    }
    get_color(mat, AI_MATKEY_COLOR_EMISSIVE, &m.emission);
    if (get_float(mat, AI_MATKEY_OPACITY, &f)) {
        /* Transmission is (1 - opacity) x the transparent colour where the
         * file gives one (Assimp folds Collada's <transparency> into the
         * opacity and keeps <transparent> as the colour). */
        rl_vec3 transparent = rl_v3s(1.0f);
        get_color(mat, AI_MATKEY_COLOR_TRANSPARENT, &transparent);
        float kt = rl_clampf((1.0f - f) * luminance(transparent), 0.0f, 1.0f);
        if (kt >= 1.0f) {
            /* A surface that lets everything through and reflects nothing
             * is invisible; in files it is an exporter's inverted
             * transparency far more often than a wish. */
            c->notes.invisible++;
            kt = 0.0f;
        }
        m.transmissivity = kt;
    }
    if (get_float(mat, AI_MATKEY_REFRACTI, &f))
        m.ior = rl_maxf(f, 1.0f);
    /* Ullmann 2003, eq. 3.1: the reflected and transmitted shares must not
     * create energy; files do not promise that, so scale them down. */
    float sum = m.reflectivity + m.transmissivity;
    if (sum > 1.0f) {
        m.reflectivity /= sum;
        m.transmissivity /= sum;
    }

    struct aiString tex;
    if (aiGetMaterialTexture(mat, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL, NULL,
                             NULL) == aiReturn_SUCCESS ||
        aiGetMaterialTexture(mat, aiTextureType_BASE_COLOR, 0, &tex, NULL, NULL, NULL, NULL,
                             NULL, NULL) == aiReturn_SUCCESS) {
        rl_status st = load_material_texture(c, tex.data, &m.diffuse_texture);
        if (st != RL_OK)
            return st;
    }
    if (aiGetMaterialTexture(mat, aiTextureType_NORMALS, 0, &tex, NULL, NULL, NULL, NULL, NULL,
                             NULL) == aiReturn_SUCCESS) {
        rl_status st = load_normal_map(c, tex.data, &m.normal_texture);
        if (st != RL_OK)
            return st;
        float scale;
        if (get_float(mat, "$tex.scale", aiTextureType_NORMALS, 0, &scale))
            m.normal_scale = scale;
    }
    /* What the material model cannot hold yet is counted, and reported once
     * per file (import_notes). A height (bump) map would need its
     * derivatives; OBJ's map_bump is one. */
    c->notes.normal_maps += aiGetMaterialTextureCount(mat, aiTextureType_HEIGHT) > 0;
    c->notes.pbr_textures += aiGetMaterialTextureCount(mat, aiTextureType_METALNESS) > 0 ||
                             aiGetMaterialTextureCount(mat, aiTextureType_DIFFUSE_ROUGHNESS) > 0 ||
                             aiGetMaterialTextureCount(mat, aiTextureType_UNKNOWN) > 0;
    /* glTF 2.0 alphaMode: MASK cuts holes where the base colour's alpha
     * is below alphaCutoff (default 0.5); BLEND would need transparency
     * sorted or stochastic, and is drawn opaque for now. */
    struct aiString mode;
    if (aiGetMaterialString(mat, "$mat.gltf.alphaMode", 0, 0, &mode) == aiReturn_SUCCESS) {
        if (strcmp(mode.data, "MASK") == 0 && m.diffuse_texture != RL_NONE) {
            float cutoff = 0.5f;
            get_float(mat, "$mat.gltf.alphaCutoff", 0, 0, &cutoff);
            m.alpha_cutoff = rl_clampf(cutoff, 0.0f, 1.0f);
        } else if (strcmp(mode.data, "BLEND") == 0) {
            c->notes.alpha_modes++;
        }
    }
    return rl_scene_add_material(c->scene, &m, id);
}

/* One rl mesh per aiMesh, keeping only its triangles. */
static rl_status add_mesh(rl_scene *scene, const struct aiMesh *am, uint32_t material,
                          uint32_t *mesh_id)
{
    *mesh_id = RL_NONE;
    uint32_t nt = 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f)
        nt += is_triangle_face(&am->mFaces[f]);
    if (nt == 0)
        return RL_OK;   /* points or lines only */

    uint32_t *indices = rl_calloc((size_t)nt * 3, sizeof *indices);
    rl_vec2 *uvs = am->mTextureCoords[0]
                       ? rl_calloc(am->mNumVertices, sizeof *uvs) : NULL;
    if (!indices || (am->mTextureCoords[0] && !uvs)) {
        free(indices);
        free(uvs);
        return RL_ERR_OUT_OF_MEMORY;
    }
    uint32_t t = 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const struct aiFace *face = &am->mFaces[f];
        if (!is_triangle_face(face))
            continue;
        for (int k = 0; k < 3; ++k)
            indices[3 * t + k] = face->mIndices[k];
        ++t;
    }
    if (uvs)
        for (unsigned v = 0; v < am->mNumVertices; ++v)
            uvs[v] = rl_v2(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y);

    /* aiVector3D is three floats (ai_real is float in our builds), the same
     * layout as rl_vec3. */
    _Static_assert(sizeof(struct aiVector3D) == sizeof(rl_vec3), "aiVector3D layout");
    rl_mesh_desc desc = {
        .name = am->mName.data,
        .num_vertices = am->mNumVertices,
        .positions = (const rl_vec3 *)am->mVertices,
        .normals = (const rl_vec3 *)am->mNormals,   /* NULL: the scene computes smooth ones */
        .uvs = uvs,
        .num_triangles = nt,
        .indices = indices,
        .material = material,
    };
    rl_status st = rl_scene_add_mesh(scene, &desc, mesh_id);
    free(indices);
    free(uvs);
    return st;
}

typedef struct import_ctx {
    rl_scene *scene;
    const char *path;
    const struct aiScene *ai;
    const uint32_t *mesh_ids;   /* per aiMesh, RL_NONE when it had no triangles */
    rl_vec3 centre;             /* of the imported geometry, in world space */
} import_ctx;

/* Centre of the world-space bounds of the nodes from first on (an import
 * appends its nodes, children after parents). */
static rl_vec3 imported_centre(const rl_scene *scene, uint32_t first)
{
    rl_aabb b = rl_aabb_empty();
    for (uint32_t n = first; n < scene->num_nodes; ++n) {
        const rl_node *node = &scene->nodes[n];
        if (node->mesh == RL_NONE || node->mesh >= scene->num_meshes)
            continue;
        rl_mat4 w = scene_node_world(scene, n);
        const rl_mesh *m = &scene->meshes[node->mesh];
        for (uint32_t v = 0; v < m->num_vertices; ++v) {
            rl_vec3 p = rl_mat4_mul_point(&w, m->positions[v]);
            if (rl_vfinite(p))
                b = rl_aabb_grow(b, p);
        }
    }
    return rl_aabb_is_empty(b) ? rl_v3s(0.0f) : rl_aabb_center(b);
}

static rl_status add_node(import_ctx *c, const struct aiNode *an, uint32_t parent,
                          const char *fallback_name, uint32_t *out)
{
    rl_mat4 local = from_ai(&an->mTransformation);
    const char *name = an->mName.length > 0 ? an->mName.data : fallback_name;
    uint32_t node;
    rl_status st = rl_scene_add_node(c->scene, parent, name, &local, &node);
    if (st != RL_OK)
        return st;
    if (out)
        *out = node;

    unsigned with_geometry = 0;
    for (unsigned i = 0; i < an->mNumMeshes; ++i)
        with_geometry += an->mMeshes[i] < c->ai->mNumMeshes &&
                         c->mesh_ids[an->mMeshes[i]] != RL_NONE;
    for (unsigned i = 0; i < an->mNumMeshes; ++i) {
        if (an->mMeshes[i] >= c->ai->mNumMeshes)
            continue;   /* ValidateDataStructure already refuses this */
        uint32_t mesh = c->mesh_ids[an->mMeshes[i]];
        if (mesh == RL_NONE)
            continue;
        uint32_t target = node;
        if (with_geometry > 1) {
            /* A node holds one mesh instance in our model. */
            const struct aiMesh *am = c->ai->mMeshes[an->mMeshes[i]];
            char child[256];
            snprintf(child, sizeof child, "%.120s/%.120s", name,
                     am->mName.length > 0 ? am->mName.data : "mesh");
            st = rl_scene_add_node(c->scene, node, child, NULL, &target);
            if (st != RL_OK)
                return st;
        }
        st = rl_scene_node_set_mesh(c->scene, target, mesh);
        if (st != RL_OK)
            return st;
    }
    for (unsigned i = 0; i < an->mNumChildren; ++i) {
        st = add_node(c, an->mChildren[i], node, "node", NULL);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

/* Finds the aiNode called name below an and its transform relative to the
 * import root (lights and cameras are placed by the node of the same name). */
static bool find_node(const struct aiNode *an, const char *name, rl_mat4 parent_to_root,
                      rl_mat4 *out)
{
    rl_mat4 local = from_ai(&an->mTransformation);
    rl_mat4 to_root = rl_mat4_mul(&parent_to_root, &local);
    if (strcmp(an->mName.data, name) == 0) {
        *out = to_root;
        return true;
    }
    for (unsigned i = 0; i < an->mNumChildren; ++i)
        if (find_node(an->mChildren[i], name, to_root, out))
            return true;
    return false;
}

static rl_mat4 placement(const import_ctx *c, const rl_mat4 *parent_world, const char *name)
{
    rl_mat4 rel = rl_mat4_identity();
    find_node(c->ai->mRootNode, name, rl_mat4_identity(), &rel);
    return rl_mat4_mul(parent_world, &rel);
}

static rl_vec3 v3(struct aiVector3D v) { return rl_v3(v.x, v.y, v.z); }

static bool is_gltf(const char *path)
{
    size_t n = strlen(path);
    return (n >= 5 && strcmp(path + n - 5, ".gltf") == 0) ||
           (n >= 4 && strcmp(path + n - 4, ".glb") == 0);
}

static bool camera_name_taken(const rl_scene *scene, const char *name)
{
    for (uint32_t i = 0; i < scene->num_cameras; ++i)
        if (strcmp(scene->camera_names[i], name) == 0)
            return true;
    return false;
}

static rl_status add_cameras(import_ctx *c, const rl_mat4 *parent_world)
{
    /* Assimp before 5.3 copies a glTF camera node's translation into
     * mPosition as well (assimp issue #5054), and stores yfov * aspect as
     * mHorizontalFOV instead of the documented half horizontal angle. */
    bool old_gltf = is_gltf(c->path) && (aiGetVersionMajor() < 5 ||
                                         (aiGetVersionMajor() == 5 && aiGetVersionMinor() < 3));
    for (unsigned i = 0; i < c->ai->mNumCameras; ++i) {
        const struct aiCamera *ac = c->ai->mCameras[i];
        rl_mat4 w = placement(c, parent_world, ac->mName.data);
        rl_camera cam = { 0 };
        rl_vec3 position = old_gltf ? rl_v3s(0.0f) : v3(ac->mPosition);
        cam.eye = rl_mat4_mul_point(&w, position);
        cam.target = rl_add(cam.eye, rl_normalize(rl_mat4_mul_dir(&w, v3(ac->mLookAt))));
        cam.up = rl_mat4_mul_dir(&w, v3(ac->mUp));
        /* We want the full vertical angle. aiCamera documents
         * mHorizontalFOV as the half horizontal angle, but Assimp 5.2's
         * importers store the full one: Collada's (the spec's xfov is the
         * full angle, and a yfov-only camera gets 2 atan(aspect tan(yfov/2))),
         * FBX's FieldOfView, Blender's, 3DS's, ASE's, LWS's and OpenGEX's.
         * Checked on the assimp test models: duck.dae's yfov 37.85 comes back
         * as 54.43 degrees at aspect 1.5, Blender's default camera as 49.13.
         * The file's aspect (if any) also sets the camera's resolution, so
         * that the default render shows what the file frames. */
        float aspect = ac->mAspect > 0.0f
                           ? ac->mAspect
                           : (float)RL_CAMERA_DEFAULT_WIDTH / RL_CAMERA_DEFAULT_HEIGHT;
        if (old_gltf)
            cam.fov_deg = rl_degrees(ac->mHorizontalFOV /
                                     (ac->mAspect > 0.0f ? ac->mAspect : 1.0f));
        else if (is_gltf(c->path))
            cam.fov_deg = rl_degrees(2.0f * atanf(tanf(ac->mHorizontalFOV) / aspect));
        else
            cam.fov_deg = rl_degrees(2.0f * atanf(tanf(0.5f * ac->mHorizontalFOV) / aspect));
        if (ac->mAspect > 0.0f && ac->mAspect < 16.0f && ac->mAspect > 1.0f / 16.0f) {
            cam.height = RL_CAMERA_DEFAULT_HEIGHT;
            cam.width = (int)lroundf(RL_CAMERA_DEFAULT_HEIGHT * ac->mAspect);
        }
        /* Vetted here: rl_camera_validate would record an error for a camera
         * we merely skip. */
        rl_vec3 view = rl_sub(cam.target, cam.eye);
        bool ok = rl_vfinite(cam.eye) && rl_vfinite(cam.target) && rl_vfinite(cam.up) &&
                  rl_length2(view) > 0.0f &&
                  rl_length2(rl_cross(view, cam.up)) > 1e-12f * rl_length2(cam.up) &&
                  cam.fov_deg > 0.0f && cam.fov_deg < 180.0f;
        if (!ok) {
            rl_warn("%s: camera \"%s\" with invalid parameters ignored", c->path,
                    ac->mName.data);
            continue;
        }
        /* Camera names must be unique in a scene; the same model imported
         * twice, or a JSON camera of the same name, would clash. */
        char name[160];
        snprintf(name, sizeof name, "%.120s", ac->mName.data);
        for (unsigned k = 2; name[0] && camera_name_taken(c->scene, name); ++k)
            snprintf(name, sizeof name, "%.120s#%u", ac->mName.data, k);
        rl_status st = rl_scene_add_camera(c->scene, name, &cam);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

/* Assimp's point and spot lights fall off as 1 / (c + l d + q d^2) with
 * the file's attenuation; ours fall off as intensity / d^2 (rl_light). The
 * two agree exactly for a quadratic-only law (intensity 1/q: FBX and Blender
 * lights with "decay" write q alone, spider.fbx q = 2.2e-7 at distances of
 * thousands of units, which made its lamp black at intensity 1) and are
 * matched at the distance d0 from the light to the model's centre
 * otherwise: intensity = d0^2 / (c + l d0 + q d0^2). No attenuation at all
 * (0, 0, 0; Blender's default lamp) means a constant law. */
static float falloff_scale(const struct aiLight *al, float d0)
{
    double c = al->mAttenuationConstant, l = al->mAttenuationLinear,
           q = al->mAttenuationQuadratic;
    if (!(c >= 0.0 && l >= 0.0 && q >= 0.0) || !isfinite(c + l + q))
        return 1.0f;
    if (c == 0.0 && l == 0.0 && q > 0.0)
        return (float)fmin(1.0 / q, 1e30);
    if (c == 0.0 && l == 0.0)
        c = 1.0;
    double d = d0 > 0.0f && isfinite(d0) ? d0 : 1.0;
    return (float)fmin(d * d / (c + l * d + q * d * d), 1e30);
}

static rl_status add_lights(import_ctx *c, const rl_mat4 *parent_world)
{
    for (unsigned i = 0; i < c->ai->mNumLights; ++i) {
        const struct aiLight *al = c->ai->mLights[i];
        rl_mat4 w = placement(c, parent_world, al->mName.data);
        rl_light l = { 0 };
        /* Assimp folds intensity into the colour. */
        l.color = rl_v3(al->mColorDiffuse.r, al->mColorDiffuse.g, al->mColorDiffuse.b);
        l.intensity = 1.0f;
        l.position = rl_mat4_mul_point(&w, v3(al->mPosition));
        if (al->mType == aiLightSource_POINT || al->mType == aiLightSource_SPOT)
            l.intensity = falloff_scale(al, rl_length(rl_sub(c->centre, l.position)));
        l.direction = rl_normalize(rl_mat4_mul_dir(&w, v3(al->mDirection)));
        switch (al->mType) {
        case aiLightSource_POINT: l.type = RL_LIGHT_POINT; break;
        case aiLightSource_DIRECTIONAL: l.type = RL_LIGHT_DIRECTIONAL; break;
        case aiLightSource_SPOT:
            /* Taken as half angles, as glTF (KHR_lights_punctual) defines them. */
            l.type = RL_LIGHT_SPOT;
            l.spot_inner_deg = rl_degrees(al->mAngleInnerCone);
            l.spot_outer_deg = rl_degrees(al->mAngleOuterCone);
            break;
        default:
            rl_warn("%s: light \"%s\" of unsupported type %d ignored", c->path,
                    al->mName.data, (int)al->mType);
            continue;
        }
        /* Vet the light ourselves: a failing validator would record an error. */
        bool ok = rl_vfinite(l.color) && l.color.x >= 0 && l.color.y >= 0 && l.color.z >= 0 &&
                  rl_vfinite(l.position) &&
                  (l.type == RL_LIGHT_POINT || rl_length2(l.direction) > 0.0f) &&
                  (l.type != RL_LIGHT_SPOT ||
                   (l.spot_inner_deg >= 0 && l.spot_inner_deg <= l.spot_outer_deg &&
                    l.spot_outer_deg <= 180.0f));
        if (!ok) {
            rl_warn("%s: light \"%s\" with invalid parameters ignored", c->path, al->mName.data);
            continue;
        }
        rl_status st = rl_scene_add_light(c->scene, &l);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

/* One warning per file for what was dropped or could not be mapped. */
static void report_notes(const char *path, const import_notes *n, uint64_t degenerate,
                         uint64_t nonfinite, unsigned meshes_dropping)
{
    char text[1024] = "";
    char part[600];
    if (degenerate || nonfinite) {
        snprintf(part, sizeof part, "; dropped %llu degenerate and %llu non-finite triangles in %u meshes",
                 (unsigned long long)degenerate, (unsigned long long)nonfinite, meshes_dropping);
        rl_option_append(text, sizeof text, part);
    }
    if (n->textures_missing) {
        snprintf(part, sizeof part, "; %u textures not found (%s%s)", n->textures_missing,
                 n->missing_names, n->textures_missing > 3 ? ", ..." : "");
        rl_option_append(text, sizeof text, part);
    }
    if (n->invisible) {
        snprintf(part, sizeof part, "; %u materials with opacity 0 taken as opaque", n->invisible);
        rl_option_append(text, sizeof text, part);
    }
    if (n->normal_maps) {
        snprintf(part, sizeof part, "; bump (height) maps ignored (%u materials)", n->normal_maps);
        rl_option_append(text, sizeof text, part);
    }
    if (n->pbr_textures) {
        snprintf(part, sizeof part, "; metal/roughness textures ignored, factors used (%u materials)",
                 n->pbr_textures);
        rl_option_append(text, sizeof text, part);
    }
    if (n->alpha_modes) {
        snprintf(part, sizeof part, "; alpha blending ignored, drawn opaque (%u materials)",
                 n->alpha_modes);
        rl_option_append(text, sizeof text, part);
    }
    if (text[0])
        rl_warn("%s: %s", path, text + 2);
}

static rl_status build(rl_scene *scene, const char *path, const struct aiScene *ai,
                       uint32_t parent, const rl_scene_import_desc *desc, uint32_t *root_node)
{
    char model_dir[PATH_MAX_LEN];
    rl_path_dirname(path, model_dir, sizeof model_dir);

    uint32_t *material_ids = rl_calloc(ai->mNumMaterials + 1u, sizeof *material_ids);
    uint32_t *mesh_ids = rl_calloc(ai->mNumMeshes + 1u, sizeof *mesh_ids);
    uint32_t *embedded = rl_calloc(ai->mNumTextures + 1u, sizeof *embedded);
    rl_status st = material_ids && mesh_ids && embedded ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (unsigned i = 0; st == RL_OK && i < ai->mNumTextures; ++i)
        embedded[i] = RL_NONE;
    material_ctx mc = { scene, path, model_dir, ai, embedded, { 0 }, desc->ggx_materials };
    for (unsigned i = 0; st == RL_OK && i < ai->mNumMaterials; ++i)
        st = add_material(&mc, ai->mMaterials[i], &material_ids[i]);
    /* The scene counts what add_mesh drops; the import reports it once. */
    uint64_t degenerate0 = scene->dropped_degenerate, nonfinite0 = scene->dropped_nonfinite;
    unsigned meshes_dropping = 0;
    scene->quiet_mesh_warnings = true;
    for (unsigned i = 0; st == RL_OK && i < ai->mNumMeshes; ++i) {
        uint64_t before = scene->dropped_degenerate + scene->dropped_nonfinite;
        st = add_mesh(scene, ai->mMeshes[i], material_ids[ai->mMeshes[i]->mMaterialIndex],
                      &mesh_ids[i]);
        meshes_dropping += scene->dropped_degenerate + scene->dropped_nonfinite > before;
    }
    scene->quiet_mesh_warnings = false;
    if (st == RL_OK)
        report_notes(path, &mc.notes, scene->dropped_degenerate - degenerate0,
                     scene->dropped_nonfinite - nonfinite0, meshes_dropping);

    if (st == RL_OK) {
        /* The file stem names the import root when the file leaves it unnamed. */
        const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
        import_ctx c = { scene, path, ai, mesh_ids, rl_v3s(0.0f) };
        uint32_t root = RL_NONE, first = scene->num_nodes;
        st = add_node(&c, ai->mRootNode, parent, base, &root);
        rl_mat4 parent_world = scene_node_world(scene, parent);
        c.centre = imported_centre(scene, first);
        if (st == RL_OK && !desc->no_cameras)
            st = add_cameras(&c, &parent_world);
        if (st == RL_OK && !desc->no_lights)
            st = add_lights(&c, &parent_world);
        if (st == RL_OK)
            *root_node = root;
    }
    free(material_ids);
    free(mesh_ids);
    free(embedded);
    return st;
}

/* The import proper; the caller checked its arguments and the file
 * (load_isolate.c), and chose the process it runs in. */
rl_status rl_assimp_import(rl_scene *scene, const char *path, uint32_t parent,
                           const rl_scene_import_desc *desc, uint32_t *root_node)
{
    /* No FindInvalidData: it deletes whole meshes over one NaN position,
     * which the scene core handles per triangle. No GenNormals either: the
     * scene computes area-weighted ones when a mesh has none. GenUVCoords
     * turns spherical, cylindrical and planar texture projections (LWO,
     * 3DS) into UVs, and TransformUVCoords applies a texture's UV
     * transform, since our textures take UVs only. */
    const struct aiScene *ai =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                               aiProcess_SortByPType | aiProcess_ValidateDataStructure |
                               aiProcess_GenUVCoords | aiProcess_TransformUVCoords);
    if (!ai) {
        /* Assimp catches the std::bad_alloc of a failed allocation and
         * reports it as its error text: that is running out of memory (the
         * isolated import's limit), not a malformed file. */
        const char *raw = aiGetErrorString();
        if (strstr(raw, "bad_alloc"))
            return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: out of memory in Assimp", path);
        char why[256];
        rl_load_safe_message(path, raw, why, sizeof why);
        return rl_error(RL_ERR_PARSE, "%s: %s", path, why);
    }
    if (!ai->mRootNode || (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        bool meshless = ai->mNumMeshes == 0;
        aiReleaseImport(ai);
        return rl_error(RL_ERR_PARSE, "%s: incomplete scene%s", path,
                        meshless ? " (no meshes: cameras, lights or animation only, or a reader that gave up)" : "");
    }
    rl_status st = check_scene(path, ai);
    if (st == RL_OK)
        st = build(scene, path, ai, parent, desc, root_node);
    aiReleaseImport(ai);
    return st;
}
