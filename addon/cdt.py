"""Constrained Delaunay triangulation (CDT) of points and segments in the plane.

A small documented API over the bundled compiled module ``rigger._rigger_cdt`` (``ext/cdt.pyx``). Everything is
float64 and decided by exact adaptive orientation and in-circle predicates, so near-degenerate input (duplicate
points, collinear runs, cocircular grids, points on segments, crossing or overlapping segments) cannot corrupt the
triangulation.

The predicates are exact while no product of coordinate differences overflows or underflows: the input is scaled
by a power of two so its largest coordinate is about 1, which leaves differences down to about 1e-150 of that size.

Example::

    from rigger import cdt
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    tri = cdt.triangulate(square, [(0, 1), (1, 2), (2, 3), (3, 0)])
    tri.triangles        # (2, 3) int32, counter-clockwise
    cdt.orient2d((0, 0), (1, 0), (0, 1))   # 1: the exact predicates it decides with
"""
from dataclasses import dataclass

import numpy as np

from . import _rigger_cdt
from .core.arrays import index_array, point_array

MODES = ("inside", "all")


@dataclass(frozen=True)
class Triangulation:
    """The result of :func:`triangulate`.

    Attributes:
        vertices: (K, 2) float64. Rows 0..N-1 are the input points as given (exact duplicates stay in place but
            are not used by any triangle); rows N.. are Steiner points created where segments cross.
        triangles: (T, 3) int32, counter-clockwise, indexing ``vertices``.
        neighbors: (T, 3) int32. ``neighbors[t, k]`` is the triangle across the edge opposite vertex ``k``
            (the edge ``triangles[t, (k+1)%3] -> triangles[t, (k+2)%3]``), or -1 on the boundary of the result.
        constrained: (T, 3) bool. ``constrained[t, k]`` is True when the edge opposite vertex ``k`` is a
            constraint edge (a piece of an input segment).
        vertex_map: (N,) int32. The vertex each input point became: itself, or the lowest-index point it
            exactly duplicates.
        segments: (S, 2) int32. Every constraint edge of the result once, as (low, high) vertex indices, sorted:
            the input segments split at the vertices lying on them and at their crossings.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    neighbors: np.ndarray
    constrained: np.ndarray
    vertex_map: np.ndarray
    segments: np.ndarray

    @property
    def steiner_count(self):
        """How many vertices were created at segment crossings."""
        return len(self.vertices) - len(self.vertex_map)


def triangulate(points, segments=None, *, mode="inside", holes=None):
    """Triangulate ``points`` so that every segment is a union of triangle edges, Delaunay wherever it can be.

    Args:
        points: (N, 2) array-like of finite coordinates.
        segments: optional (M, 2) array-like of point-index pairs, the constraint edges. Segments may cross
            (they are split at a new Steiner vertex), overlap, pass through points, or have zero length (ignored).
            A Steiner vertex is the crossing rounded to doubles, so the pieces through it are off the input
            segments by a rounding error; to keep such pieces from crossing again and again, a vertex (or a
            crossing) closer than 2**-40 of the bounding box's size to a segment counts as lying on it.
        mode: ``"inside"`` keeps only the triangles inside the constraint boundaries, by the even-odd rule:
            nested boundaries make holes, disjoint boundaries make separate pieces. A segment given twice
            cancels out. ``"all"`` keeps the whole convex hull.
        holes: optional (H, 2) seed points, as in Triangle: every triangle reachable from a seed without crossing
            a constraint edge is removed. Seeds outside the triangulation are ignored.

    Returns:
        A :class:`Triangulation`. All-collinear (or fewer than three distinct) points give zero triangles.

    Raises:
        ValueError: wrong shapes or dtypes, NaN or infinite coordinates, out-of-range or negative indices, an
            unknown mode, or ``mode="inside"`` without segments.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, not {mode!r}")
    pts = point_array(points, 2, "points")
    segs = _as_segments(segments, len(pts))
    seeds = np.zeros((0, 2)) if holes is None else point_array(holes, 2, "holes")
    if mode == "inside" and len(segs) == 0:
        raise ValueError("mode='inside' needs constraint segments that enclose a region; use mode='all' for the "
                         "convex hull of the points")
    raw = _rigger_cdt.triangulate(pts, segs, mode == "inside", seeds)
    return Triangulation(**raw)


def orient2d(a, b, c):
    """Exact sign of the orientation of points ``a``, ``b``, ``c`` (pairs of floats): +1 counter-clockwise, -1
    clockwise, 0 collinear; the predicate the triangulation decides with."""
    return _rigger_cdt.orient2d(*map(float, a), *map(float, b), *map(float, c))


def incircle(a, b, c, d):
    """Exact sign of point ``d`` against the circle through counter-clockwise ``a``, ``b``, ``c``: +1 inside, -1
    outside, 0 on it; the predicate the triangulation decides with."""
    return _rigger_cdt.incircle(*map(float, a), *map(float, b), *map(float, c), *map(float, d))


def _as_segments(values, n_points):
    if values is None:
        return np.zeros((0, 2), np.int32)
    return index_array(values, 2, n_points, name="segments", item="segment", target=("point", "points"), dtype=np.int32)
