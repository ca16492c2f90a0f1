/* Skin weights that always exist: each point weighted over its nearest few bones by distance to the bone segments.
 *
 * A bounding-volume hierarchy over the bone segments finds, for every point, the k + 1 bones with the smallest
 * "reach" key: the distance to the segment, lengthened by up to (1 + facing_penalty) when the segment lies in front
 * of the point's surface normal (a bone of another body part seen through the outside of this one). The nearest k
 * bones get weights (s1 / s)^power minus the same term of the (k + 1)-th bone, so a bone's weight falls to zero
 * exactly as it leaves the nearest k: weights are continuous in the point's position. Ties are broken by bone index,
 * so the result does not depend on the tree's layout. Nothing recurses; every error path frees what it allocated.
 */
#ifndef RIGGER_SKIN_WEIGHTS_H
#define RIGGER_SKIN_WEIGHTS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    SW_OK = 0,
    SW_ERR_NOMEM,
    SW_ERR_ARGUMENT
};

/* The most bones sw_bone_weights takes: the bone tree holds up to 2 * n_bones nodes, counted in int32. */
#define SW_MAX_BONES (INT32_MAX / 2)

/* A human-readable message for an error code. */
const char *sw_error_message(int code);

/* Weights of `n_points` xyz points over `n_bones` bone segments heads[i] -> tails[i] (interleaved xyz).
 * `normals` (n_points xyz, may be NULL, need not be unit length) enables the facing penalty. 1 <= n_bones <=
 * SW_MAX_BONES; `per_point` >= 1 bones per point (at most n_bones are used), `power` > 0, `facing_penalty` >= 0.
 * Outputs are n_points x per_point, row-major: bone indices by decreasing weight, -1 with weight 0 past the bones
 * that carry weight; each row's weights sum to 1. */
int sw_bone_weights(const double *points, int64_t n_points, const double *normals, const double *heads,
                    const double *tails, int32_t n_bones, int32_t per_point, double power, double facing_penalty,
                    int32_t *bones_out, double *weights_out);

#ifdef __cplusplus
}
#endif

#endif
