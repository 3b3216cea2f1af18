/* rl_scene.h: the shared scene model.
 *
 * A scene is a graph of nodes (transform, optional mesh instance, optional
 * material override, free string attributes) over shared meshes, materials,
 * textures, lights and cameras. rl_scene_commit() flattens it into
 * world-space triangle arrays with stable IDs:
 *   - object ID   = index of a mesh-carrying node in depth-first order
 *                   (children in insertion order), one per instance;
 *   - triangle ID = index into the flattened triangle array; an object's
 *                   triangles are contiguous, in mesh order.
 * The same scene description therefore always yields the same IDs.
 * A committed scene is immutable; accelerators and renderers borrow it.
 *
 * Bad geometry: rl_scene_add_mesh() drops triangles that reference a NaN/Inf
 * vertex or have zero area, counts them in rl_scene_stats and logs one warning
 * per mesh. Indices out of range are an error. Committing a scene without
 * triangles fails with RL_ERR_EMPTY_SCENE. */
#ifndef RL_SCENE_H
#define RL_SCENE_H

#include "rl/rl_camera.h"
#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"
#include "rl/rl_options.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_NONE 0xFFFFFFFFu          /* "no index" for meshes, materials, textures */
#define RL_NODE_ROOT 0u              /* every scene has a root node */
#define RL_SCENE_MAX_TRIANGLES (1u << 30)

/* The BRDF of a material's non-specular event. */
typedef enum rl_material_bsdf {
    RL_BSDF_PHONG = 0,        /* modified Phong (Lafortune & Willems 1994) */
    RL_BSDF_GGX,              /* Cook-Torrance with the GGX distribution (Walter et al. 2007) */
    RL_BSDF_COUNT
} rl_material_bsdf;

/* How the specular events weigh reflection against refraction. */
typedef enum rl_fresnel_mode {
    RL_FRESNEL_NONE = 0,      /* fixed k_r and k_t (Ullmann 2003, eq. 3.1) */
    RL_FRESNEL_SCHLICK,       /* Schlick 1994's approximation */
    RL_FRESNEL_COUNT
} rl_fresnel_mode;

/* Schlick's Fresnel reflectance F = F0 + (1 - F0) (1 - cos)^5 for a
 * dielectric of relative index eta = n_t / n_i seen at cos_i from the
 * incident side (cos_i > 0): F0 = ((eta - 1) / (eta + 1))^2; from the
 * denser side the transmitted angle's cosine is used, and total internal
 * reflection gives 1. */
RL_API float rl_fresnel_schlick(float cos_i, float eta);

/* Phong material with the ray-tracing coefficients of Ullmann 2003, Sec. 3.1
 * (eq. 3.1-3.4): local Phong term + k_r * reflected + k_t * transmitted. */
typedef struct rl_material {
    char name[64];
    rl_vec3 diffuse;          /* k_d, linear RGB */
    rl_vec3 specular;         /* k_s */
    float shininess;          /* Phong exponent n */
    float reflectivity;       /* k_r in [0,1] */
    float transmissivity;     /* k_t in [0,1] */
    float ior;                /* index of refraction, >= 1 */
    rl_vec3 emission;         /* emitted radiance */
    uint32_t diffuse_texture; /* scene texture index or RL_NONE */
    /* Tangent-space normal map (RGB = (n + 1) / 2, raw values, not sRGB)
     * or RL_NONE; normal_scale scales its x and y (glTF's "scale"). Used by
     * the ray tracers (whitted, vt's samples, pt): rl_shading_normal. */
    uint32_t normal_texture;
    float normal_scale;
    /* Alpha mask (glTF alphaMode MASK): where the diffuse texture's alpha
     * is below this cutoff the surface is a hole that rays pass through
     * (rl_accel queries skip it). 0: opaque, no test. */
    float alpha_cutoff;
    /* Physically based extensions (issue 37; docs/scene-format.md). Their
     * zeros keep the Phong model above, so older materials render as
     * before. The path tracers honour them (pt fully, bdpt without the
     * environment); the other renderers approximate (docs/path-tracing.md). */
    rl_material_bsdf bsdf;    /* the non-specular event's BRDF */
    /* RL_BSDF_GGX: perceptual roughness r in [0,1], microfacet alpha = r^2;
     * metallic in [0,1] blends F0 from the ior's dielectric value towards
     * k_d and fades the diffuse lobe out. */
    float roughness;
    float metallic;
    /* RL_FRESNEL_SCHLICK: the k_t event splits into reflection and
     * refraction by Schlick's F(ior), and the k_r mirror reflects F with
     * F0 = k_s; RL_FRESNEL_NONE: the fixed coefficients above. */
    rl_fresnel_mode fresnel;
} rl_material;

/* Grey diffuse (0.8), no specular, shininess 32, ior 1.5, no textures,
 * normal scale 1, Phong BRDF, no Fresnel term. */
RL_API rl_material rl_material_default(void);
/* RL_ERR_INVALID_ARG for negative or non-finite coefficients, k_r + k_t > 1,
 * ior < 1, an unknown bsdf or fresnel, roughness or metallic outside [0,1]. */
RL_API rl_status rl_material_validate(const rl_material *m);

typedef enum rl_light_type {
    RL_LIGHT_POINT = 0,
    RL_LIGHT_SPOT,
    RL_LIGHT_DIRECTIONAL,
    RL_LIGHT_QUAD,
    RL_LIGHT_TYPE_COUNT
} rl_light_type;

/* Point and spot lights fall off with 1/d^2; intensity scales color.
 * Directional: irradiance color*intensity from direction -direction.
 * Quad: emitted radiance color*intensity from the parallelogram
 * position + s*edge_u + t*edge_v (s,t in [0,1]), on the side of
 * cross(edge_u, edge_v). */
typedef struct rl_light {
    rl_light_type type;
    rl_vec3 color;
    float intensity;
    rl_vec3 position;         /* point, spot; quad corner */
    rl_vec3 direction;        /* spot, directional: the direction light travels */
    float spot_inner_deg;     /* full intensity inside this half angle */
    float spot_outer_deg;     /* zero outside this half angle */
    rl_vec3 edge_u, edge_v;   /* quad */
} rl_light;

RL_API const char *rl_light_type_name(rl_light_type type);
RL_API rl_status rl_light_validate(const rl_light *l);

/* A scene's environment (issue 37): the radiance of directions that leave
 * the scene, for the path tracers (pt; docs/path-tracing.md). Lat-long
 * map: row 0 looks straight up (+y), the bottom row straight down, the
 * columns sweep the azimuth phi = 2 pi u from +x towards -z (u = 0 the
 * left edge), turned by rotation_deg about +y. Any aspect ratio is taken
 * (2:1 keeps texels square in angle). Texels are read without filtering,
 * as the piecewise-constant function the sampling uses. */
typedef struct rl_environment {
    rl_vec3 radiance;         /* colour * intensity: the constant, or the map's scale */
    const rl_texture *map;    /* lat-long, linear RGB; NULL: constant */
    float rotation_deg;
} rl_environment;

typedef struct rl_environment_desc {
    const char *path;         /* .exr, .hdr (linear) or PNG etc. (sRGB), relative to the
                               * base dir; NULL: a constant environment */
    rl_vec3 color;            /* scales the map, or the constant radiance */
    float intensity;          /* scales both; 0 -> 1 */
    float rotation_deg;       /* about +y */
} rl_environment_desc;

/* The environment's radiance towards unit direction dir. */
RL_API rl_vec3 rl_environment_radiance(const rl_environment *env, rl_vec3 dir);
/* Lat-long coordinates (u, v in [0,1), v = 0 up) of unit dir, and back. */
RL_API rl_vec2 rl_environment_uv(const rl_environment *env, rl_vec3 dir);
RL_API rl_vec3 rl_environment_direction(const rl_environment *env, float u, float v);

/* Mesh input. Data is copied. normals == NULL: area-weighted smooth normals
 * are computed; uvs == NULL: all (0,0). */
typedef struct rl_mesh_desc {
    const char *name;
    uint32_t num_vertices;
    const rl_vec3 *positions;
    const rl_vec3 *normals;
    const rl_vec2 *uvs;
    uint32_t num_triangles;
    const uint32_t *indices;           /* 3 per triangle */
    const uint32_t *triangle_materials;/* per triangle, or NULL: use material */
    uint32_t material;                 /* scene material index */
} rl_mesh_desc;

typedef struct rl_scene rl_scene;

RL_API rl_status rl_scene_create(rl_scene **out);
RL_API void rl_scene_release(rl_scene *scene);         /* NULL is a no-op */
/* A number unique to this scene within the process (never reused), so that
 * caches keyed on a scene survive a new scene at a recycled address. */
RL_API uint64_t rl_scene_uid(const rl_scene *scene);
RL_API rl_status rl_scene_set_name(rl_scene *scene, const char *name);
RL_API const char *rl_scene_name(const rl_scene *scene);
/* Folder that relative asset paths are resolved against ("" = cwd). */
RL_API rl_status rl_scene_set_base_dir(rl_scene *scene, const char *dir);
RL_API const char *rl_scene_base_dir(const rl_scene *scene);

/* Building (only before commit; afterwards RL_ERR_INVALID_ARG). */
RL_API rl_status rl_scene_add_material(rl_scene *scene, const rl_material *m, uint32_t *id);
/* Index of the material with this name, or RL_NONE. */
RL_API uint32_t rl_scene_find_material(const rl_scene *scene, const char *name);
/* Takes ownership of tex on success. */
RL_API rl_status rl_scene_add_texture(rl_scene *scene, rl_texture *tex, uint32_t *id);
/* Loads a texture file (relative to the base dir), sharing repeated paths. */
RL_API rl_status rl_scene_load_texture(rl_scene *scene, const char *path, uint32_t *id);
RL_API rl_status rl_scene_add_mesh(rl_scene *scene, const rl_mesh_desc *desc, uint32_t *mesh_id);
RL_API rl_status rl_scene_add_light(rl_scene *scene, const rl_light *light);
RL_API rl_status rl_scene_add_camera(rl_scene *scene, const char *name, const rl_camera *cam);
/* Takes ownership of path on success; replaces any previous path. */
RL_API rl_status rl_scene_set_camera_path(rl_scene *scene, rl_camera_path *path);
/* Sets the scene's environment (rl_environment above), replacing any
 * previous one. RL_ERR_IO / RL_ERR_PARSE for an unreadable file or texels
 * that are negative or not finite, RL_ERR_LIMIT past
 * rl_texture_max_pixels(), RL_ERR_INVALID_ARG for negative or non-finite
 * values; a map that is not 2:1 is taken with a warning. */
RL_API rl_status rl_scene_set_environment(rl_scene *scene, const rl_environment_desc *desc);

/* Scene graph. transform == NULL: identity. node ids are dense, root = 0. */
RL_API rl_status rl_scene_add_node(rl_scene *scene, uint32_t parent, const char *name,
                                   const rl_mat4 *transform, uint32_t *node_id);
RL_API rl_status rl_scene_node_set_mesh(rl_scene *scene, uint32_t node, uint32_t mesh);
/* Replaces the materials of this node's mesh and of its descendants' meshes,
 * unless a descendant sets its own override. */
RL_API rl_status rl_scene_node_set_material(rl_scene *scene, uint32_t node, uint32_t material);
/* Free per-node attributes (e.g. "vt" = "true"); value NULL removes. */
RL_API rl_status rl_scene_node_set_attr(rl_scene *scene, uint32_t node, const char *key,
                                        const char *value);
RL_API const char *rl_scene_node_attr(const rl_scene *scene, uint32_t node, const char *key);
RL_API uint32_t rl_scene_node_count(const rl_scene *scene);
RL_API const char *rl_scene_node_name(const rl_scene *scene, uint32_t node);
RL_API uint32_t rl_scene_node_parent(const rl_scene *scene, uint32_t node); /* RL_NONE for root */
/* First node with this name in id order, or RL_NONE. */
RL_API uint32_t rl_scene_find_node(const rl_scene *scene, const char *name);

/* Flattens and validates. RL_ERR_EMPTY_SCENE without triangles. */
RL_API rl_status rl_scene_commit(rl_scene *scene);
RL_API bool rl_scene_is_committed(const rl_scene *scene);

/* One flattened mesh instance. */
typedef struct rl_object {
    const char *name;          /* node name */
    uint32_t node, mesh;
    uint32_t first_triangle, num_triangles;
    uint32_t first_vertex, num_vertices;
    rl_aabb bounds;            /* world space */
    rl_mat4 world;             /* node's local-to-world transform */
} rl_object;

/* Read-only view of a committed scene; valid until the scene is released. */
typedef struct rl_scene_data {
    uint32_t num_vertices;
    const rl_vec3 *positions;           /* world space */
    const rl_vec3 *normals;             /* world space, unit */
    const rl_vec2 *uvs;                 /* never NULL */
    uint32_t num_triangles;
    const uint32_t *indices;            /* 3 per triangle, into the vertex arrays */
    const uint32_t *triangle_object;    /* object ID per triangle */
    const uint32_t *triangle_material;  /* material index per triangle */
    uint32_t num_objects;
    const rl_object *objects;
    uint32_t num_materials;
    const rl_material *materials;
    uint32_t num_textures;
    rl_texture *const *textures;
    uint32_t num_lights;
    const rl_light *lights;
    uint32_t num_cameras;
    const rl_camera *cameras;
    const char *const *camera_names;
    const rl_camera_path *camera_path;  /* or NULL */
    rl_aabb bounds;
    const rl_environment *environment;  /* or NULL: none (renderers' background) */
} rl_scene_data;

/* NULL (with RL_ERR_NOT_COMMITTED recorded) unless committed. */
RL_API const rl_scene_data *rl_scene_get_data(const rl_scene *scene);
/* The shading normal of triangle tri at texture coordinate uv, given the
 * interpolated vertex normal ns: ns itself, or ns bent by the material's
 * normal map in the triangle's tangent frame (dP/du, dP/dv from its
 * positions and uvs, Gram-Schmidt against ns), of unit length. Without a
 * map, ns is returned as it came; where the frame is degenerate, ns
 * normalised. */
RL_API rl_vec3 rl_shading_normal(const rl_scene_data *d, uint32_t tri, rl_vec3 ns, rl_vec2 uv);
/* Whether the hit at barycentrics (u, v) of triangle tri falls in a hole of
 * its material's alpha mask (rl_material.alpha_cutoff). */
RL_API bool rl_alpha_masked(const rl_scene_data *d, uint32_t tri, float u, float v);

/* The named camera, the first camera (name NULL), or, when the scene has
 * none, rl_scene_fit_camera at the default size. RL_ERR_NOT_FOUND for an
 * unknown name. */
RL_API rl_status rl_scene_get_camera(const rl_scene *scene, const char *name, rl_camera *out);
/* The orbit from which a scene without cameras is framed (degrees, see
 * rl_camera_fit_points; default RL_CAMERA_FIT_AZIMUTH_DEG/ELEVATION_DEG).
 * Before commit; RL_ERR_INVALID_ARG for a non-finite azimuth or an
 * elevation outside -89..89. */
RL_API rl_status rl_scene_set_default_view(rl_scene *scene, float azimuth_deg, float elevation_deg);
/* A camera that frames every vertex of the committed scene tightly for a
 * width x height image from the scene's default view
 * (rl_camera_fit_points). For a caller that picks the image size after
 * loading: the fit depends on the aspect ratio. */
RL_API rl_status rl_scene_fit_camera(const rl_scene *scene, int width, int height, rl_camera *out);

typedef struct rl_scene_stats {
    uint32_t nodes, meshes, objects, materials, textures, lights, cameras;
    uint64_t mesh_triangles;       /* unique triangles in meshes */
    uint64_t triangles, vertices;  /* after instancing (committed scenes) */
    uint64_t emissive_triangles;
    uint64_t dropped_degenerate;   /* zero-area triangles dropped */
    uint64_t dropped_nonfinite;    /* triangles with NaN/Inf vertices dropped */
    size_t memory_bytes;           /* flattened arrays + meshes */
    rl_aabb bounds;
} rl_scene_stats;
RL_API void rl_scene_get_stats(const rl_scene *scene, rl_scene_stats *out);

/* Procedural meshes ("generators"), shared by built-in and JSON scenes.
 * params: "key=value" pairs separated by commas or NULL; unknown keys are
 * RL_ERR_INVALID_ARG. Generators: box, quad, sphere, cylinder, teapot
 * (Utah teapot from its Bezier patches), blob (a closed, lumpy genus-0 mesh
 * with an exact even triangle count). See docs/scene-format.md. */
RL_API rl_status rl_scene_add_generated(rl_scene *scene, const char *generator,
                                        const char *params, uint32_t material,
                                        uint32_t *mesh_id);
RL_API const char *const *rl_generator_names(size_t *count);

/* Built-in scenes: cornell, cornell-teapot, spheres, city, table, cluster,
 * ls-open, ls-cornell (rl scenes lists them with their parameters). params as above
 * (e.g. "triangles=70000" for cornell-teapot, "blocks=8" for city). The
 * returned scene is committed. */
typedef struct rl_builtin_info {
    const char *name;
    const char *description;
    const rl_option_info *options;     /* the parameters: key, type, default, help, range */
    size_t num_options;
} rl_builtin_info;
RL_API const rl_builtin_info *rl_builtin_scenes(size_t *count);
RL_API rl_status rl_scene_create_builtin(const char *name, const char *params, rl_scene **out);

/* Loading. rl_scene_load() accepts a built-in name, a .json scene file or
 * any mesh file Assimp reads (OBJ, PLY, STL, glTF/GLB, DAE, 3DS, FBX, ...);
 * for a model file without lights it adds default ones, and one without
 * cameras is framed by rl_scene_fit_camera. params: a built-in's
 * parameters or a model file's (rl_model_options), "k=v,k=v" or NULL.
 * Returns a committed scene. Errors name the file, and for JSON the line
 * and column. */
RL_API rl_status rl_scene_load(const char *source, const char *params, rl_scene **out);
/* The parameters rl_scene_load takes for a model file (cameras=file|off,
 * lights=file|off|add, headlight, azimuth, elevation, materials=phong|ggx). */
RL_API const rl_option_info *rl_model_options(size_t *count);
RL_API rl_status rl_scene_load_json(const char *path, rl_scene **out);   /* committed */
/* Imports a mesh file with Assimp under parent: its node hierarchy,
 * meshes (triangulated; quads and n-gons split), materials and textures
 * (paths relative to the file). *root_node receives the imported root.
 * Assimp runs in a child process (rl_import_limits below). */
RL_API rl_status rl_scene_import(rl_scene *scene, const char *path, uint32_t parent,
                                 uint32_t *root_node);
/* Assimp can crash, hang or allocate without bound on malformed files, so
 * by default an import runs it in a child process (fork) under these
 * limits, and only our own plain data (meshes, materials, textures, nodes,
 * cameras, lights, warnings) comes back, checked completely before use. A
 * crash, a timeout or an exhausted limit in the child fails the import:
 * RL_ERR_CRASHED "FILE: the importer crashed (signal 11)", RL_ERR_LIMIT
 * "FILE: the importer ran out of time (120 s)" or "... exceeded its memory
 * limit (4096 MiB)", RL_ERR_CANCELLED when Ctrl-C ended it, RL_ERR_PARSE
 * when what came back is malformed. Our own pre-checks (PLY counts, GLB
 * lengths, node cycles and depth, ...) run before, in the calling
 * process. docs/scene-format.md, "Untrusted files". Zero fields mean the
 * process-wide value (rl_scene_set_import_limits), whose zeros mean the
 * defaults below. */
typedef struct rl_import_limits {
    /* Wall-clock seconds for the whole import; the child's CPU time is
     * capped at the same number (RLIMIT_CPU), so that a child whose parent
     * is gone still ends. 0 -> RL_IMPORT_DEFAULT_TIMEOUT_S. */
    uint32_t timeout_s;
    /* Address space the child may add to what it inherits (RLIMIT_AS), in
     * MiB; 0 -> RL_IMPORT_DEFAULT_MEMORY_MIB. Not applied in
     * AddressSanitizer builds, whose shadow memory needs terabytes of it. */
    uint32_t memory_mib;
    /* UNSAFE for untrusted files: runs Assimp in the calling process,
     * without limits, where a malformed file can crash it, hang it or
     * exhaust its memory. For trusted files where the fork costs too much,
     * and for fuzzing Assimp itself. */
    bool in_process;
} rl_import_limits;
/* 120 s: the models of the Assimp test corpus import in seconds,
 * a 10^6-triangle OBJ in about 3 s of CPU, so only a hang or a model of
 * tens of millions of triangles gets near it. 4096 MiB of address space:
 * that OBJ needs between 512 and 1024 MiB of it, so the default takes
 * models about four times larger; a file that asks for more is hostile or
 * needs an explicit raise. */
#define RL_IMPORT_DEFAULT_TIMEOUT_S 120u
#define RL_IMPORT_DEFAULT_MEMORY_MIB 4096u
/* The limits that rl_scene_load, JSON scenes' "file" objects and imports
 * with zero fields use (NULL: the defaults). Process-wide; set it before
 * loading, not while loads are in flight. */
RL_API void rl_scene_set_import_limits(const rl_import_limits *limits);
RL_API rl_import_limits rl_scene_import_limits(void);

/* What of a file to take besides its geometry and materials; zero = all. */
typedef struct rl_scene_import_desc {
    bool no_cameras;      /* skip the file's cameras */
    bool no_lights;       /* skip the file's lights */
    rl_import_limits limits;   /* zero fields: rl_scene_import_limits() */
    /* glTF metallic-roughness materials as RL_BSDF_GGX with the file's
     * base colour, metallic and roughness, instead of their Phong mapping
     * (the model option materials=ggx). */
    bool ggx_materials;
} rl_scene_import_desc;
/* rl_scene_import with a desc (NULL: defaults). */
RL_API rl_status rl_scene_import_with(rl_scene *scene, const char *path, uint32_t parent,
                                      const rl_scene_import_desc *desc, uint32_t *root_node);

#ifdef __cplusplus
}
#endif
#endif
