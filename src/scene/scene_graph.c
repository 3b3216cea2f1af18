/* scene_graph.c: nodes (transform, mesh instance, material override, free
 * attributes) linked as first-child / next-sibling lists so that commit can
 * walk children in insertion order. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rl_status check_node(const rl_scene *scene, uint32_t node, const char *what)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "%s: NULL scene", what);
    if (node >= scene->num_nodes)
        return rl_error(RL_ERR_INVALID_ARG, "%s: node %u does not exist (%u nodes)", what, node,
                        scene->num_nodes);
    return RL_OK;
}

/* Singular transforms would collapse geometry to zero area and make the
 * normal matrix undefined; reject them where the caller can still see why. */
rl_status rl_node_check_transform(const rl_mat4 *t, const char *name)
{
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            if (!isfinite(t->m[r][c]))
                return rl_error(RL_ERR_INVALID_ARG, "node \"%s\": transform is not finite", name);
    double a = t->m[0][0], b = t->m[0][1], c = t->m[0][2];
    double d = t->m[1][0], e = t->m[1][1], f = t->m[1][2];
    double g = t->m[2][0], h = t->m[2][1], i = t->m[2][2];
    double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    double scale = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k)
            scale = fmax(scale, fabs((double)t->m[r][k]));
    rl_mat4 inv;
    if (fabs(det) <= 1e-12 * scale * scale * scale || !rl_mat4_invert(t, &inv))
        return rl_error(RL_ERR_INVALID_ARG, "node \"%s\": transform is singular", name);
    return RL_OK;
}

rl_status rl_scene_add_node(rl_scene *scene, uint32_t parent, const char *name,
                            const rl_mat4 *transform, uint32_t *node_id)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_node: NULL scene");
    rl_status st = rl_scene_check_mutable(scene, "add a node");
    if (st != RL_OK)
        return st;
    /* Only the root (created by rl_scene_create) has no parent. */
    if (scene->num_nodes > 0 && (st = check_node(scene, parent, "rl_scene_add_node")) != RL_OK)
        return st;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "node%u", scene->num_nodes);
    if (!name)
        name = fallback;
    if (transform && (st = rl_node_check_transform(transform, name)) != RL_OK)
        return st;
    if ((st = rl_scene_reserve((void **)&scene->nodes, &scene->cap_nodes, scene->num_nodes + 1,
                               sizeof *scene->nodes)) != RL_OK)
        return st;
    char *copy = rl_strdup(name);
    if (!copy)
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t id = scene->num_nodes;
    rl_node *n = &scene->nodes[id];
    memset(n, 0, sizeof *n);
    n->name = copy;
    n->parent = id == 0 ? RL_NONE : parent;
    n->local = transform ? *transform : rl_mat4_identity();
    n->mesh = RL_NONE;
    n->material = RL_NONE;
    n->first_child = n->next_sibling = n->last_child = RL_NONE;
    if (id > 0) {
        rl_node *p = &scene->nodes[parent];
        if (p->last_child == RL_NONE)
            p->first_child = id;
        else
            scene->nodes[p->last_child].next_sibling = id;
        p->last_child = id;
    }
    scene->num_nodes++;
    if (node_id)
        *node_id = id;
    return RL_OK;
}

rl_status rl_scene_node_set_mesh(rl_scene *scene, uint32_t node, uint32_t mesh)
{
    rl_status st = check_node(scene, node, "rl_scene_node_set_mesh");
    if (st != RL_OK || (st = rl_scene_check_mutable(scene, "set a node mesh")) != RL_OK)
        return st;
    if (mesh != RL_NONE && mesh >= scene->num_meshes)
        return rl_error(RL_ERR_INVALID_ARG, "node \"%s\": mesh %u does not exist (%u meshes)",
                        scene->nodes[node].name, mesh, scene->num_meshes);
    scene->nodes[node].mesh = mesh;
    return RL_OK;
}

rl_status rl_scene_node_set_material(rl_scene *scene, uint32_t node, uint32_t material)
{
    rl_status st = check_node(scene, node, "rl_scene_node_set_material");
    if (st != RL_OK || (st = rl_scene_check_mutable(scene, "set a node material")) != RL_OK)
        return st;
    if (material != RL_NONE && material >= scene->num_materials)
        return rl_error(RL_ERR_INVALID_ARG, "node \"%s\": material %u does not exist (%u materials)",
                        scene->nodes[node].name, material, scene->num_materials);
    scene->nodes[node].material = material;
    return RL_OK;
}

rl_status rl_scene_node_set_attr(rl_scene *scene, uint32_t node, const char *key, const char *value)
{
    rl_status st = check_node(scene, node, "rl_scene_node_set_attr");
    if (st != RL_OK || (st = rl_scene_check_mutable(scene, "set a node attribute")) != RL_OK)
        return st;
    if (!key || !key[0])
        return rl_error(RL_ERR_INVALID_ARG, "node \"%s\": empty attribute key",
                        scene->nodes[node].name);
    rl_node *n = &scene->nodes[node];
    uint32_t at = 0;
    while (at < n->num_attrs && strcmp(n->attrs[at].key, key) != 0)
        ++at;
    if (!value) {
        if (at < n->num_attrs) {
            free(n->attrs[at].key);
            free(n->attrs[at].value);
            /* Keep the remaining attributes in insertion order. */
            memmove(&n->attrs[at], &n->attrs[at + 1], (n->num_attrs - at - 1) * sizeof *n->attrs);
            n->num_attrs--;
        }
        return RL_OK;
    }
    char *v = rl_strdup(value);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    if (at < n->num_attrs) {
        free(n->attrs[at].value);
        n->attrs[at].value = v;
        return RL_OK;
    }
    /* Nodes carry a handful of attributes: grow by one, no capacity field. */
    char *k = rl_strdup(key);
    rl_attr *grown = k ? rl_realloc_array(n->attrs, (size_t)n->num_attrs + 1, sizeof *n->attrs) : NULL;
    if (!grown) {
        free(k);
        free(v);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "node \"%s\": out of memory", n->name);
    }
    n->attrs = grown;
    n->attrs[n->num_attrs].key = k;
    n->attrs[n->num_attrs].value = v;
    n->num_attrs++;
    return RL_OK;
}

const char *rl_scene_node_attr(const rl_scene *scene, uint32_t node, const char *key)
{
    if (!scene || node >= scene->num_nodes || !key)
        return NULL;
    const rl_node *n = &scene->nodes[node];
    for (uint32_t i = 0; i < n->num_attrs; ++i)
        if (strcmp(n->attrs[i].key, key) == 0)
            return n->attrs[i].value;
    return NULL;
}

uint32_t rl_scene_node_count(const rl_scene *scene) { return scene ? scene->num_nodes : 0; }

const char *rl_scene_node_name(const rl_scene *scene, uint32_t node)
{
    return scene && node < scene->num_nodes ? scene->nodes[node].name : NULL;
}

uint32_t rl_scene_node_parent(const rl_scene *scene, uint32_t node)
{
    return scene && node < scene->num_nodes ? scene->nodes[node].parent : RL_NONE;
}

uint32_t rl_scene_find_node(const rl_scene *scene, const char *name)
{
    if (!scene || !name)
        return RL_NONE;
    for (uint32_t i = 0; i < scene->num_nodes; ++i)
        if (strcmp(scene->nodes[i].name, name) == 0)
            return i;
    return RL_NONE;
}
