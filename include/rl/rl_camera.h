/* rl_camera.h: perspective pinhole camera and keyframed camera paths.
 *
 * A camera is a look-at frame (eye, target, up), a vertical field of view and
 * a resolution. Zero fields mean defaults (see rl_camera_resolve). Pixel
 * (0,0) is the top-left pixel; its centre is at (0.5, 0.5). The camera looks
 * down its -w axis; depth everywhere in renderlab is the eye-space distance
 * along the view axis. */
#ifndef RL_CAMERA_H
#define RL_CAMERA_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_CAMERA_DEFAULT_FOV_DEG 45.0f
#define RL_CAMERA_DEFAULT_WIDTH 640
#define RL_CAMERA_DEFAULT_HEIGHT 480

typedef struct rl_camera {
    rl_vec3 eye, target;
    rl_vec3 up;           /* zero -> +y */
    float fov_deg;        /* vertical, 0 -> 45 */
    int width, height;    /* 0 -> 640 x 480 */
    float z_near, z_far;  /* 0 -> chosen by the renderer from the scene bounds */
} rl_camera;

/* Returns a copy with defaults filled in. */
RL_API rl_camera rl_camera_resolve(const rl_camera *cam);
/* RL_ERR_INVALID_ARG for eye == target, up parallel to the view direction,
 * fov outside (0,180), non-finite values; RL_ERR_LIMIT for a resolution
 * outside 1..RL_IMAGE_MAX_SIZE. Checks the resolved camera. */
RL_API rl_status rl_camera_validate(const rl_camera *cam);
/* Whether a and b are the same camera, field by field as given (not
 * resolved: a zero field and its default differ). The vectors compare bit
 * for bit, the scalars by value. Progressive renderers restart their
 * accumulation when this is false. */
RL_API bool rl_camera_equal(const rl_camera *a, const rl_camera *b);

/* Precomputed frame for generating rays quickly. */
typedef struct rl_camera_frame {
    rl_vec3 eye;
    rl_vec3 u, v, w;          /* right, up, backwards (orthonormal) */
    float tan_half_fov_y, aspect;
    int width, height;
} rl_camera_frame;
RL_API rl_camera_frame rl_camera_frame_make(const rl_camera *cam);
/* Primary ray through image position (px, py) in pixels, with a unit
 * direction, t_min = 0 and t_max = INFINITY. */
RL_API rl_ray rl_camera_frame_ray(const rl_camera_frame *f, float px, float py);

/* Matrices for rasterization (OpenGL conventions, see rl_math.h). */
RL_API rl_mat4 rl_camera_view(const rl_camera *cam);
RL_API rl_mat4 rl_camera_projection(const rl_camera *cam, float z_near, float z_far);
/* Near/far planes that enclose bounds as seen from the camera, for cameras
 * with z_near = 0: near is clamped to at least far * 1e-5. */
RL_API void rl_camera_clip_range(const rl_camera *cam, rl_aabb bounds, float *z_near, float *z_far);
/* A camera looking at bounds from the front-ish diagonal so that the whole
 * box (its bounding sphere) is in view. */
RL_API rl_camera rl_camera_frame_bounds(rl_aabb bounds, int width, int height);
/* The default orbit of rl_camera_fit_points: a three-quarter view from the
 * front (+z), to the right (+x) and above (+y). */
#define RL_CAMERA_FIT_AZIMUTH_DEG 25.0f
#define RL_CAMERA_FIT_ELEVATION_DEG 20.0f
/* A camera that looks at the points from an orbit direction (azimuth about
 * +y from +z, elevation above the xz plane, in degrees; elevation clamped to
 * +-89) and is as close as the default field of view allows while every
 * finite point stays inside the width x height frame, with a 4 % margin.
 * The tightest framing of a model: the points touch the frame on one axis
 * and are centred on the other. Non-finite angles take the defaults; no
 * finite point gives a camera at +z looking at the origin. */
RL_API rl_camera rl_camera_fit_points(const rl_vec3 *points, size_t count, float azimuth_deg,
                                      float elevation_deg, int width, int height);

/* Camera paths: keyframes at increasing times, interpolated with centripetal
 * Catmull-Rom on eye and target, linearly on up and fov. Resolution is taken
 * from the first key. */
typedef struct rl_camera_key {
    double time_s;
    rl_camera camera;
} rl_camera_key;

typedef struct rl_camera_path rl_camera_path;
/* RL_ERR_INVALID_ARG for no keys, decreasing times or invalid cameras. */
RL_API rl_status rl_camera_path_create(const rl_camera_key *keys, uint32_t count, rl_camera_path **out);
RL_API void rl_camera_path_release(rl_camera_path *path);
RL_API uint32_t rl_camera_path_key_count(const rl_camera_path *path);
RL_API const rl_camera_key *rl_camera_path_key(const rl_camera_path *path, uint32_t i);
RL_API double rl_camera_path_duration(const rl_camera_path *path);
/* Camera at time t (clamped to the path's time range). */
RL_API rl_camera rl_camera_path_eval(const rl_camera_path *path, double time_s);
/* Camera for frame i of n frames spread evenly over the path (n >= 1). */
RL_API rl_camera rl_camera_path_frame(const rl_camera_path *path, uint32_t i, uint32_t n);

#ifdef __cplusplus
}
#endif
#endif
