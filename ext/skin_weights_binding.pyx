"""Thin binding over ext/skin_weights.c, compiled as ``rigger._rigger_weights``.

Inputs arrive validated and C-contiguous from ``rigger.weights``; this layer moves buffers across, checks the
shapes and the bone count that C's int32 indices need, and turns error codes into exceptions.
"""
from libc.stdint cimport int32_t, int64_t

import numpy as np


cdef extern from "skin_weights.h":
    int SW_OK
    int SW_ERR_NOMEM
    int SW_MAX_BONES
    const char *sw_error_message(int code)
    int sw_bone_weights(const double *points, int64_t n_points, const double *normals, const double *heads,
                        const double *tails, int32_t n_bones, int32_t per_point, double power, double facing_penalty,
                        int32_t *bones_out, double *weights_out) nogil

MAX_BONES = SW_MAX_BONES  # the most bones one call takes


def bone_weights(const double[:, ::1] points, const double[:, ::1] normals, const double[:, ::1] heads,
                 const double[:, ::1] tails, int per_point, double power, double facing_penalty):
    """(bones (N, per_point) int32, weights (N, per_point) float64); ``normals`` may be None. See sw_bone_weights."""
    cdef int64_t n = points.shape[0]
    # sw_bone_weights writes every entry (-1 and 0 past the weighted bones), or fails and they are dropped
    bones = np.empty((n, per_point), dtype=np.int32)
    weights = np.empty((n, per_point), dtype=np.float64)
    if n == 0:
        return bones, weights
    if heads.shape[0] == 0 or tails.shape[0] != heads.shape[0] or points.shape[1] != 3 or heads.shape[1] != 3 \
            or tails.shape[1] != 3 or (normals is not None and (normals.shape[0] != n or normals.shape[1] != 3)):
        raise ValueError("points (N, 3), normals (N, 3) or None, heads and tails (B, 3) with B >= 1 expected")
    if heads.shape[0] > SW_MAX_BONES:  # checked before narrowing to int32, where a larger count would wrap
        raise ValueError(f"at most {SW_MAX_BONES} bones are supported, got {heads.shape[0]}")
    cdef int32_t[:, ::1] bones_view = bones
    cdef double[:, ::1] weights_view = weights
    cdef const double *normals_data = NULL if normals is None else &normals[0, 0]
    cdef int32_t n_bones = heads.shape[0]
    cdef int code
    with nogil:
        code = sw_bone_weights(&points[0, 0], n, normals_data, &heads[0, 0], &tails[0, 0], n_bones, per_point,
                               power, facing_penalty, &bones_view[0, 0], &weights_view[0, 0])
    if code == SW_ERR_NOMEM:
        raise MemoryError(sw_error_message(code).decode())
    if code != SW_OK:
        raise ValueError(sw_error_message(code).decode())
    return bones, weights
