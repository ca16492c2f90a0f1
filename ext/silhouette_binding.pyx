"""Thin binding over ext/silhouette.c, compiled as ``rigger._rigger_silhouette``.

Inputs arrive validated and C-contiguous from ``rigger.silhouette``; this layer only moves buffers across and turns
error codes into exceptions. Outputs are numpy arrays filled through typed memoryviews (no numpy C-API).
"""
from libc.stdint cimport int32_t, int64_t

import numpy as np


cdef extern from "silhouette.h":
    ctypedef struct SilTrace:
        pass
    int SIL_OK
    int SIL_ERR_NOMEM
    int SIL_ERR_EMPTY
    int SIL_ERR_INTERNAL
    int SIL_ERR_ZERO_AREA
    int SIL_MIN_RESOLUTION
    int SIL_MAX_RESOLUTION
    double SIL_SEAM_GAP
    const char *sil_error_message(int code)
    int sil_trace(const double *vertices, int64_t n_vertices, const int32_t *triangles, int64_t n_triangles,
                  const double *direction, int32_t resolution, double tolerance, SilTrace **out) nogil
    void sil_free(SilTrace *trace)
    void sil_frame(const SilTrace *trace, double *origin, double *u, double *v, double *direction)
    void sil_grid(const SilTrace *trace, double *corner, double *cell, int32_t *width, int32_t *height)
    int64_t sil_loop_count(const SilTrace *trace)
    const int64_t *sil_loop_offsets(const SilTrace *trace)
    const double *sil_loop_points(const SilTrace *trace)
    int sil_depth(SilTrace *trace, const double *points, int64_t n, double *front, double *back)
    int sil_layers(SilTrace *trace, const double *points, int64_t n, int64_t **offsets, double **intervals)
    void sil_release(void *memory)
    int sil_share_components(SilTrace *trace, SilTrace *source)
    int sil_seal(const double *vertices, int64_t n, const int32_t *triangles, int64_t m, double *out,
                 int64_t *moved) nogil


MIN_RESOLUTION = SIL_MIN_RESOLUTION
MAX_RESOLUTION = SIL_MAX_RESOLUTION
SEAM_GAP = SIL_SEAM_GAP


class NoSilhouette(ValueError):
    """Every triangle projects to zero area along the direction: the mesh shows nothing that way."""


cdef raise_for(int code):
    message = sil_error_message(code).decode()
    if code == SIL_ERR_ZERO_AREA:
        raise NoSilhouette(message)
    if code == SIL_ERR_NOMEM:
        raise MemoryError(message)
    if code == SIL_ERR_INTERNAL:
        raise RuntimeError(message)
    raise ValueError(message)


cdef class Trace:
    """Owns one traced silhouette (SilTrace) and answers ray queries against it."""
    cdef SilTrace *handle

    def __dealloc__(self):
        sil_free(self.handle)

    def frame(self):
        """(origin, u, v, direction) as float64 arrays of shape (3,)."""
        origin, u, v, direction = (np.empty(3) for _ in range(4))
        cdef double[::1] o = origin, uu = u, vv = v, d = direction
        sil_frame(self.handle, &o[0], &uu[0], &vv[0], &d[0])
        return origin, u, v, direction

    def grid(self):
        """(corner, cell, width, height): frame position of grid point (0, 0), cell size, cell counts."""
        corner = np.empty(2)
        cdef double[::1] c = corner
        cdef double cell
        cdef int32_t width, height
        sil_grid(self.handle, &c[0], &cell, &width, &height)
        return corner, cell, width, height

    def loops(self):
        """The outline as a list of (K, 2) float64 arrays."""
        cdef int64_t n = sil_loop_count(self.handle)
        cdef const int64_t *offsets = sil_loop_offsets(self.handle)
        return _rows(n, offsets, sil_loop_points(self.handle))

    def depth(self, const double[:, ::1] points):
        """Nearest and farthest hit depth per (P, 2) frame point; NaN where the ray misses."""
        cdef int64_t n = points.shape[0]
        front = np.empty(n)  # sil_depth writes every entry (NaN on a miss) or fails and they are dropped
        back = np.empty(n)
        if n == 0:
            return front, back
        cdef double[::1] f = front, b = back
        cdef int code = sil_depth(self.handle, &points[0, 0], n, &f[0], &b[0])
        if code != SIL_OK:
            raise_for(code)
        return front, back

    def share_components(self, Trace source not None):
        """Take the welded connected components ``source`` (a trace of the same mesh) has found, for ``layers``."""
        cdef int code = sil_share_components(self.handle, source.handle)
        if code != SIL_OK:
            raise_for(code)

    def layers(self, const double[:, ::1] points):
        """Per (P, 2) frame point, a (K, 2) array of (entry, exit) depths where the ray is inside the mesh."""
        cdef int64_t n = points.shape[0]
        if n == 0:
            return []
        cdef int64_t *offsets = NULL
        cdef double *intervals = NULL
        cdef int code = sil_layers(self.handle, &points[0, 0], n, &offsets, &intervals)
        if code != SIL_OK:
            raise_for(code)
        try:
            return _rows(n, offsets, intervals)
        finally:
            sil_release(offsets)
            sil_release(intervals)


def trace(const double[:, ::1] vertices, const int32_t[:, ::1] triangles, const double[::1] direction, int resolution,
          double tolerance):
    """Trace the silhouette; see ``rigger.silhouette.trace`` for the contract. Arrays must be non-empty."""
    if vertices.shape[0] == 0 or triangles.shape[0] == 0:
        raise_for(SIL_ERR_EMPTY)
    if vertices.shape[1] != 3 or triangles.shape[1] != 3 or direction.shape[0] != 3:
        raise ValueError("vertices and triangles need 3 columns and direction 3 components")
    cdef SilTrace *handle = NULL
    cdef int code
    with nogil:
        code = sil_trace(&vertices[0, 0], vertices.shape[0], &triangles[0, 0], triangles.shape[0], &direction[0],
                         resolution, tolerance, &handle)
    if code != SIL_OK:
        raise_for(code)
    result = Trace.__new__(Trace)
    (<Trace>result).handle = handle
    return result


def seal(const double[:, ::1] vertices, const int32_t[:, ::1] triangles):
    """(vertices with the seams between abutting parts closed, how many moved); see ``rigger.silhouette.sealed``."""
    out = np.empty((vertices.shape[0], 3), dtype=np.float64)
    cdef double[:, ::1] o = out
    cdef int64_t moved = 0
    cdef int code
    if vertices.shape[0] == 0 or triangles.shape[0] == 0:
        return out, 0
    with nogil:
        code = sil_seal(&vertices[0, 0], vertices.shape[0], &triangles[0, 0], triangles.shape[0], &o[0, 0], &moved)
    if code != SIL_OK:
        raise_for(code)
    return out, moved


cdef list _rows(int64_t n, const int64_t *offsets, const double *xy):
    """Group ``n`` runs of interleaved (x, y) pairs, run k from pair offsets[k] to offsets[k + 1], into a list of
    (K, 2) float64 arrays."""
    cdef int64_t k, i, first, count
    cdef double[:, ::1] view
    rows = []
    for k in range(n):
        first = offsets[k]
        count = offsets[k + 1] - first
        row = np.empty((count, 2))
        view = row
        for i in range(count):
            view[i, 0] = xy[2 * (first + i)]
            view[i, 1] = xy[2 * (first + i) + 1]
        rows.append(row)
    return rows
