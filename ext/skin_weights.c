/* Skin weights by distance to bone segments over a bounding-volume hierarchy; see skin_weights.h. */
#include "skin_weights.h"

#include <math.h>
#include <stdlib.h>

#define LEAF_BONES 4 /* a tree node holding at most this many bones is a leaf */

typedef struct {
    double lo[3], hi[3]; /* bounding box of the node's bone segments */
    int32_t first;       /* leaf: first slot in Tree.order; inner node: index of its left child (right = left + 1) */
    int32_t count;       /* leaf: number of bones; inner node: 0 */
} Node;

typedef struct {
    Node *nodes;
    int32_t n_nodes;
    int32_t *order; /* bone indices, each leaf's bones contiguous */
} Tree;

/* A tree node waiting to be visited, with its box's squared distance from the point (computed once, when pushed). */
typedef struct {
    int32_t node;
    double box_squared;
} Pending;

/* A bone with a sort key; ordered by key, then by bone index, so ties never depend on visiting order. */
typedef struct {
    double key;
    int32_t bone;
} Keyed;

const char *sw_error_message(int code)
{
    switch (code) {
    case SW_OK: return "ok";
    case SW_ERR_NOMEM: return "out of memory computing skin weights";
    case SW_ERR_ARGUMENT: return "skin weights need 1 to INT32_MAX / 2 (1073741823) bones, per_point >= 1, "
                                 "power > 0 and a finite facing_penalty >= 0";
    default: return "unknown skin weights error";
    }
}

static int keyed_compare(const void *a, const void *b)
{
    const Keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->bone > y->bone) - (x->bone < y->bone);
}

static void tree_free(Tree *tree)
{
    free(tree->nodes);
    free(tree->order);
}

static void node_bound(Node *node, const int32_t *order, const double *heads, const double *tails)
{
    for (int k = 0; k < 3; k++) {
        node->lo[k] = INFINITY;
        node->hi[k] = -INFINITY;
    }
    for (int32_t i = node->first; i < node->first + node->count; i++) {
        const double *ends[2] = {heads + 3 * (int64_t)order[i], tails + 3 * (int64_t)order[i]};
        for (int e = 0; e < 2; e++)
            for (int k = 0; k < 3; k++) {
                node->lo[k] = fmin(node->lo[k], ends[e][k]);
                node->hi[k] = fmax(node->hi[k], ends[e][k]);
            }
    }
}

/* Split nodes at the median bone centre along their widest axis until every leaf holds at most LEAF_BONES bones.
 * A binary tree whose leaves are non-empty has at most 2 * n_bones - 1 nodes. */
static int tree_build(Tree *tree, const double *heads, const double *tails, int32_t n_bones)
{
    int32_t capacity = 2 * n_bones;
    tree->nodes = malloc((size_t)capacity * sizeof(Node));
    tree->order = malloc((size_t)n_bones * sizeof(int32_t));
    Keyed *keys = malloc((size_t)n_bones * sizeof(Keyed));
    int32_t *pending = malloc((size_t)capacity * sizeof(int32_t));
    if (!tree->nodes || !tree->order || !keys || !pending) {
        tree_free(tree);
        free(keys);
        free(pending);
        return SW_ERR_NOMEM;
    }
    for (int32_t i = 0; i < n_bones; i++)
        tree->order[i] = i;
    tree->nodes[0].first = 0;
    tree->nodes[0].count = n_bones;
    tree->n_nodes = 1;
    int32_t top = 0;
    pending[top++] = 0;
    while (top) {
        Node *node = &tree->nodes[pending[--top]];
        node_bound(node, tree->order, heads, tails);
        if (node->count <= LEAF_BONES)
            continue;
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (node->hi[k] - node->lo[k] > node->hi[axis] - node->lo[axis])
                axis = k;
        int32_t first = node->first, count = node->count;
        for (int32_t i = 0; i < count; i++) {
            int32_t bone = tree->order[first + i];
            keys[i].key = heads[3 * (int64_t)bone + axis] + tails[3 * (int64_t)bone + axis];
            keys[i].bone = bone;
        }
        qsort(keys, (size_t)count, sizeof(Keyed), keyed_compare);
        for (int32_t i = 0; i < count; i++)
            tree->order[first + i] = keys[i].bone;
        int32_t left = tree->n_nodes, half = count / 2;
        tree->nodes[left].first = first;
        tree->nodes[left].count = half;
        tree->nodes[left + 1].first = first + half;
        tree->nodes[left + 1].count = count - half;
        tree->n_nodes += 2;
        node->first = left;
        node->count = 0;
        pending[top++] = left;
        pending[top++] = left + 1;
    }
    free(keys);
    free(pending);
    return SW_OK;
}

static double box_distance_squared(const Node *node, const double point[3])
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double gap = fmax(fmax(node->lo[k] - point[k], point[k] - node->hi[k]), 0.0);
        sum += gap * gap;
    }
    return sum;
}

/* The point's reach key for one bone: the distance to the segment plus facing_penalty times how far the segment's
 * nearest point lies in front of the surface (along the unit normal; NULL when there is no penalty). Never less than
 * the plain distance. */
static double bone_key(const double point[3], const double *unit_normal, const double *head, const double *tail,
                       double facing_penalty)
{
    double axis[3], along = 0.0, length_squared = 0.0;
    for (int k = 0; k < 3; k++) {
        axis[k] = tail[k] - head[k];
        along += (point[k] - head[k]) * axis[k];
        length_squared += axis[k] * axis[k];
    }
    double t = length_squared > 0.0 ? fmin(fmax(along / length_squared, 0.0), 1.0) : 0.0;
    double toward[3], distance_squared = 0.0;
    for (int k = 0; k < 3; k++) {
        toward[k] = head[k] + t * axis[k] - point[k];
        distance_squared += toward[k] * toward[k];
    }
    double distance = sqrt(distance_squared);
    if (!unit_normal)
        return distance;
    double facing = 0.0;
    for (int k = 0; k < 3; k++)
        facing += unit_normal[k] * toward[k];
    return facing > 0.0 ? distance + facing_penalty * facing : distance;
}

/* `normal` scaled to unit length into `unit`; NULL (no facing penalty) for a missing or zero normal. */
static const double *unit_or_null(const double *normal, double unit[3])
{
    if (!normal)
        return NULL;
    double length = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (!(length > 0.0))
        return NULL;
    for (int k = 0; k < 3; k++)
        unit[k] = normal[k] / length;
    return unit;
}

/* Keep `best` sorted with at most `capacity` entries. */
static void offer(Keyed *best, int32_t *count, int32_t capacity, double key, int32_t bone)
{
    Keyed item = {key, bone};
    if (*count == capacity && keyed_compare(&item, &best[capacity - 1]) >= 0)
        return;
    int32_t slot = *count < capacity ? (*count)++ : capacity - 1;
    while (slot > 0 && keyed_compare(&item, &best[slot - 1]) < 0) {
        best[slot] = best[slot - 1];
        slot--;
    }
    best[slot] = item;
}

/* The `capacity` bones (at most all of them) with the smallest keys into `best`, depth first with the nearer child
 * first; a node is skipped when its box is farther than the worst key kept (the key is never below the distance, so
 * nothing better is lost). */
static void nearest_bones(const Tree *tree, const double *heads, const double *tails, const double point[3],
                          const double *unit_normal, double facing_penalty, Keyed *best, int32_t capacity,
                          Pending *stack)
{
    int32_t count = 0, top = 0;
    stack[top++] = (Pending){0, 0.0}; /* the root's distance is never read: nothing is kept yet when it is visited */
    while (top) {
        Pending visit = stack[--top];
        const Node *node = &tree->nodes[visit.node];
        if (count == capacity) {
            double worst = best[capacity - 1].key;
            if (visit.box_squared > worst * worst)
                continue;
        }
        if (node->count) {
            for (int32_t i = node->first; i < node->first + node->count; i++) {
                int32_t bone = tree->order[i];
                double key = bone_key(point, unit_normal, heads + 3 * (int64_t)bone, tails + 3 * (int64_t)bone,
                                      facing_penalty);
                offer(best, &count, capacity, key, bone);
            }
            continue;
        }
        const Node *left = &tree->nodes[node->first];
        Pending near = {node->first, box_distance_squared(left, point)};
        Pending far = {node->first + 1, box_distance_squared(left + 1, point)};
        if (far.box_squared < near.box_squared) {
            Pending swap = near;
            near = far;
            far = swap;
        }
        stack[top++] = far;
        stack[top++] = near;
    }
}

static double relative_weight(double key, double nearest, double power)
{
    return key == nearest ? 1.0 : pow(nearest / key, power);
}

/* One point's row: the first `used` of the `kept` nearest bones weighted, the bone after them (if kept) setting the
 * zero. */
static void point_weights(const Keyed *best, int32_t kept, int32_t used, int32_t per_point, double power,
                          int32_t *bones, double *weights)
{
    double nearest = best[0].key;
    double floor = kept > used ? relative_weight(best[used].key, nearest, power) : 0.0;
    double total = 0.0;
    for (int32_t i = 0; i < used; i++) {
        weights[i] = relative_weight(best[i].key, nearest, power) - floor;
        total += weights[i];
    }
    if (!(total > 0.0)) { /* every kept bone ties with the next one: share equally among the nearest */
        total = 0.0;
        for (int32_t i = 0; i < used; i++) {
            weights[i] = best[i].key == nearest ? 1.0 : 0.0;
            total += weights[i];
        }
    }
    for (int32_t i = 0; i < per_point; i++) {
        if (i < used && weights[i] > 0.0) {
            bones[i] = best[i].bone;
            weights[i] /= total;
        } else {
            bones[i] = -1;
            weights[i] = 0.0;
        }
    }
}

int sw_bone_weights(const double *points, int64_t n_points, const double *normals, const double *heads,
                    const double *tails, int32_t n_bones, int32_t per_point, double power, double facing_penalty,
                    int32_t *bones_out, double *weights_out)
{
    if (n_points < 0 || n_bones < 1 || n_bones > SW_MAX_BONES || per_point < 1 || !(power > 0.0) || !isfinite(power) ||
        !(facing_penalty >= 0.0) || !isfinite(facing_penalty))
        return SW_ERR_ARGUMENT;
    Tree tree;
    int code = tree_build(&tree, heads, tails, n_bones);
    if (code != SW_OK)
        return code;
    int32_t used = per_point < n_bones ? per_point : n_bones;
    int32_t capacity = used < n_bones ? used + 1 : used;
    Keyed *best = malloc((size_t)capacity * sizeof(Keyed));
    Pending *stack = malloc((size_t)tree.n_nodes * sizeof(Pending));
    if (!best || !stack) {
        free(best);
        free(stack);
        tree_free(&tree);
        return SW_ERR_NOMEM;
    }
    if (!(facing_penalty > 0.0)) normals = NULL; /* no penalty: no normal to read */
    for (int64_t p = 0; p < n_points; p++) {
        double unit[3];
        const double *unit_normal = unit_or_null(normals ? normals + 3 * p : NULL, unit);
        nearest_bones(&tree, heads, tails, points + 3 * p, unit_normal, facing_penalty, best, capacity, stack);
        point_weights(best, capacity, used, per_point, power, bones_out + p * per_point, weights_out + p * per_point);
    }
    free(best);
    free(stack);
    tree_free(&tree);
    return SW_OK;
}
