/* load_json_transform.c: the "transform" object of JSON scene objects:
 * translate, Euler rotate_deg (X, then Y, then Z), axis-angle rotate, scale,
 * or a whole row-major matrix; composed as M = T * R * S. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/load_json_internal.h"

rl_status rl_jscene_transform(const rl_jscene_ctx *c, const cJSON *obj, rl_mat4 *out)
{
    static const char *const keys[] = { "translate", "rotate_deg", "rotate", "scale", "matrix",
                                        NULL };
    rl_status st = rl_jscene_check_object(c, obj, "transform", keys);
    if (st != RL_OK)
        return st;
    const cJSON *matrix = rl_jscene_member(obj, "matrix");
    if (matrix) {
        if (obj->child->next)
            return rl_json_error(c->doc, matrix, "\"matrix\" cannot be combined with "
                                                 "translate, rotate or scale");
        if (!cJSON_IsArray(matrix) || cJSON_GetArraySize(matrix) != 16)
            return rl_json_error(c->doc, matrix, "expected an array of 16 numbers (row-major)");
        rl_mat4 m;
        int i = 0;
        for (const cJSON *e = matrix->child; e; e = e->next, ++i) {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
                return rl_json_error(c->doc, e, "expected a finite number");
            m.m[i / 4][i % 4] = (float)e->valuedouble;
        }
        if (m.m[3][0] != 0.0f || m.m[3][1] != 0.0f || m.m[3][2] != 0.0f || m.m[3][3] != 1.0f)
            return rl_json_error(c->doc, matrix, "the last row of \"matrix\" must be 0 0 0 1");
        rl_mat4 inv;
        if (!rl_mat4_invert(&m, &inv))
            return rl_json_error(c->doc, matrix, "\"matrix\" is singular");
        *out = m;
        return RL_OK;
    }
    if (rl_jscene_member(obj, "rotate") && rl_jscene_member(obj, "rotate_deg"))
        return rl_json_error(c->doc, rl_jscene_member(obj, "rotate"),
                             "use either \"rotate\" or \"rotate_deg\", not both");

    rl_vec3 t = rl_v3s(0.0f), s = rl_v3s(1.0f), euler = rl_v3s(0.0f);
    if ((st = rl_jscene_vec3(c, obj, "translate", false, &t)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "rotate_deg", false, &euler)) != RL_OK)
        return st;
    rl_mat4 r = rl_mat4_identity();
    if (rl_jscene_member(obj, "rotate_deg")) {
        /* X first, then Y, then Z: R = Rz * Ry * Rx for column vectors. */
        rl_mat4 rx = rl_mat4_rotate(rl_v3(1, 0, 0), rl_radians(euler.x));
        rl_mat4 ry = rl_mat4_rotate(rl_v3(0, 1, 0), rl_radians(euler.y));
        rl_mat4 rz = rl_mat4_rotate(rl_v3(0, 0, 1), rl_radians(euler.z));
        rl_mat4 yx = rl_mat4_mul(&ry, &rx);
        r = rl_mat4_mul(&rz, &yx);
    }
    const cJSON *rot = rl_jscene_member(obj, "rotate");
    if (rot) {
        static const char *const rot_keys[] = { "axis", "deg", NULL };
        const cJSON *unused;
        rl_vec3 axis = rl_v3s(0.0f);
        double deg = 0.0;
        if ((st = rl_jscene_check_object(c, rot, "rotate", rot_keys)) != RL_OK ||
            (st = rl_jscene_require(c, rot, "axis", "rotate", &unused)) != RL_OK ||
            (st = rl_jscene_require(c, rot, "deg", "rotate", &unused)) != RL_OK ||
            (st = rl_jscene_vec3(c, rot, "axis", true, &axis)) != RL_OK ||
            (st = rl_jscene_number(c, rot, "deg", -INFINITY, INFINITY, &deg)) != RL_OK)
            return st;
        r = rl_mat4_rotate(rl_normalize(axis), rl_radians((float)deg));
    }
    const cJSON *scale = rl_jscene_member(obj, "scale");
    if (scale) {
        if (cJSON_IsNumber(scale))
            s = rl_v3s((float)scale->valuedouble);
        else if ((st = rl_jscene_read_vec3(c, scale, &s)) != RL_OK)
            return rl_json_error(c->doc, scale, "\"scale\" must be a number or [x, y, z]");
        if (!rl_vfinite(s) || s.x == 0.0f || s.y == 0.0f || s.z == 0.0f)
            return rl_json_error(c->doc, scale, "\"scale\" must be finite and non-zero");
    }
    /* Scale, then rotate, then translate: M = T * R * S. */
    rl_mat4 tm = rl_mat4_translate(t), sm = rl_mat4_scale(s);
    rl_mat4 rs = rl_mat4_mul(&r, &sm);
    *out = rl_mat4_mul(&tm, &rs);
    return RL_OK;
}
