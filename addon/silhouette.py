"""The 3D silhouette: the outline of a mesh seen along a direction, and the mesh's depth behind every outline point.

A small documented API over the bundled compiled module ``rigger._rigger_silhouette`` (``ext/silhouette.c``).

Example::

    from rigger import silhouette
    sil = silhouette.trace(vertices, triangles, "Y")      # look along +Y: u = +X (right), v = +Z (up)
    sil.loops                     # [(K, 2) float64, ...]: outer boundaries counter-clockwise, holes clockwise
    front, back = sil.depth(sil.loops[0])                # nearest / farthest mesh depth along each ray
    sil.layers([(0.0, 1.2)])      # [(L, 2) array of (entry, exit) depths where the ray is inside the mesh]
    sil.lift(points, front)       # back to 3D: origin + x*u + y*v + depth*direction
    sil.project(points3d)         # (points, depths) in the view's frame: the inverse of lift
    sil.encloses(points3d)        # the ray hits the mesh and the depth lies between its nearest and farthest hit
    closed = silhouette.sealed(vertices, triangles)      # pieces that abut without shared vertices welded, to trace

How it works, and why tracing cannot fail: the projected triangles are snapped to an integer lattice (65536 steps per
grid cell) and every inside/outside decision is exact integer arithmetic under a symbolic perturbation, so no grid
point ever sits on an edge and shared edges leave no cracks. Along each horizontal and vertical grid line the union
of the triangles' cross-sections is computed exactly; the outline passes through those exact crossing points and is
closed inside each cell by straight chords. A cell with more than two crossings (two features meeting, a thin strip
passing a corner) is split into quarters along exact midlines until each part is clear, down to 1/256 of a cell.
Loops are therefore closed, simple and consistently oriented by construction; where parts of the shape touch at a
single point the loops are pulled a hair (1e-6 cell) apart so they stay strictly simple. Nothing recurses, buffers
grow on the heap, and the cost is linear in the triangles plus the grid lines they cross.

Accuracy versus resolution: ``resolution`` is the number of grid cells along the longest side of the projected
bounding box (cell size = longest side / resolution). Because crossings are exact, a straight silhouette edge is
reproduced exactly wherever it crosses a grid line; the outline departs from the exact union only

- at corners, which a chord cuts off: at most about half a cell's area each, far less for the blunt corners of a
  smooth mesh;
- for specks: islands or holes that cross no grid line (smaller than a cell both ways) or enclose less than 1e-4
  square cells are dropped. A thin part that crosses grid lines keeps its exact width there, so fingers, tails and
  antennae stay separate lobes even where the gap between them is narrower than a cell. When nothing but specks
  is left, ``trace`` raises ``PartsTooSmall``.

How close the outline comes to the exact union at each resolution, and what it costs, is measured in
``bench/results/silhouette.md``. Lower resolutions are cheaper mainly for meshes of large triangles, whose
cross-sections are computed on every line they cross.

``tolerance`` then removes outline points while a bound on the distance between the traced and the simplified
outline stays within that fraction of a cell, never removing a point whose removal could make two loop segments
cross; the default 0.05 keeps the outline's area essentially unchanged while dropping the collinear runs that straight
mesh edges produce.
"""
from dataclasses import dataclass, field

import numpy as np

from . import _rigger_silhouette
from .core.arrays import index_array, numeric_array, point_array

NoSilhouette = _rigger_silhouette.NoSilhouette  # a ValueError: the mesh shows no area along the direction


class PartsTooSmall(NoSilhouette):
    """The mesh shows area along the direction, but no part of it covers a grid cell: its parts are tiny for the
    space between them (another direction would not help)."""


DEFAULT_RESOLUTION = 1024
DEFAULT_TOLERANCE = 0.05
INT32_MAX = 2**31 - 1  # the tracer indexes vertices with int32
AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True, eq=False)
class Silhouette:
    """The result of :func:`trace`.

    Attributes:
        loops: list of (K, 2) float64 arrays in the (u, v) frame, closing point not repeated. Outer boundaries run
            counter-clockwise, holes clockwise, every loop is simple and no two loops touch, so they can be passed
            directly to ``rigger.cdt.triangulate(points, segments, mode="inside")``. Never empty: ``trace`` raises
            ``PartsTooSmall`` when every part of the projection is a speck (see the module docstring).
        origin, u, v, direction: (3,) float64. A frame point (x, y) at depth d is the 3D point
            ``origin + x*u + y*v + d*direction``; ``direction`` is the unit view direction, depth grows away from
            the viewer, and (u, v) is what the viewer sees as (right, up).
        cell: the grid cell size in mesh units (the outline's resolution).
    """

    loops: list
    origin: np.ndarray
    u: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    cell: float
    _trace: object = field(repr=False)

    def depth(self, points):
        """Nearest (``front``) and farthest (``back``) mesh depth along the view ray through each (P, 2) point.

        Rays are cast exactly against the projected triangles (shared edges are hit exactly once). Both arrays are
        NaN where the ray misses the mesh, i.e. outside the silhouette.
        """
        return self._trace.depth(_as_points(points))

    def layers(self, points):
        """Every depth interval where the view ray through each (P, 2) point is inside the mesh.

        Returns a list with one (L, 2) float64 array of (entry, exit) depths per point, sorted front to back (empty
        on a miss). Hits pair up by crossing parity within each connected part of the mesh (vertices at identical
        positions are welded first, as glTF seams split them; pieces that only abut are joined by tracing
        :func:`sealed` vertices), and overlapping intervals of different parts are merged: two legs one behind the
        other give two intervals, an eye inside a head gives one. Where an open part
        is hit an odd number of times, the hit whose removal leaves the thinnest pairing becomes a zero-thickness
        interval. Within a part whose hits along a ray nest by winding (each entry faces the way the nearest hit
        does, each exit the other way, as on closed, consistently wound surfaces) the stretches of positive winding
        are inside, so shells of one part that overlap stay solid where they overlap.
        """
        return self._trace.layers(_as_points(points))

    def share_parts(self, other):
        """Take for ``layers`` the welded connected parts that ``other``, a silhouette of the same mesh seen along
        another direction, has found (finding them now if it has not): the parts belong to the mesh, not the view
        (welded where ``other`` sees vertices at exactly one place), so the views of one mesh weld and join it
        once. ValueError if ``other`` traced other triangles or another number of vertices."""
        if not isinstance(other, Silhouette):
            raise TypeError(f"share_parts needs another Silhouette of the same mesh, got {type(other).__name__}")
        self._trace.share_components(other._trace)

    def lift(self, points, depth):
        """3D positions of (P, 2) frame points at the given depths (scalar or (P,))."""
        pts = _as_points(points)
        d = np.broadcast_to(np.asarray(depth, dtype=np.float64), (len(pts),))
        return self.origin + pts[:, :1] * self.u + pts[:, 1:] * self.v + d[:, None] * self.direction

    def project(self, points):
        """The frame points (P, 2) and depths (P,) of (P, 3) points: the inverse of ``lift``."""
        offset = point_array(points, 3, "points") - self.origin
        return np.stack([offset @ self.u, offset @ self.v], axis=1), offset @ self.direction

    def encloses(self, points, slack=0.0):
        """Which (P, 3) points lie within the mesh's depth span as this view sees it (its visual hull): their ray
        hits the mesh and, give or take ``slack`` (a depth, in mesh units), they lie between the nearest and
        farthest hit. Unlike ``layers`` this needs no closed surface, so it holds on open and self-intersecting
        meshes; it cannot see gaps along the ray (another view can)."""
        frame, depth = self.project(points)
        front, back = self._trace.depth(frame)  # frame points are valid already: skip depth()'s checks
        return (depth >= front - slack) & (depth <= back + slack)  # NaN (a miss) compares False


def trace(vertices, triangles, direction, *, resolution=None, tolerance=None):
    """Trace the silhouette of a triangle soup seen along ``direction``.

    Args:
        vertices: (N, 3) finite coordinates.
        triangles: (M, 3) vertex indices. Any soup works: open, non-manifold, several parts, degenerate or
            duplicate faces, inconsistent winding, inner shells.
        direction: the view direction: ``"X"``, ``"Y"``, ``"Z"`` (optionally ``"-X"`` …, looking along the axis
            towards its positive or negative end) or any non-zero 3D vector.
        resolution: grid cells along the longest side of the projected bounding box (default
            ``DEFAULT_RESOLUTION``); see the module docstring for the accuracy it buys.
        tolerance: how far simplification may move the outline, as a fraction of a cell in [0, 1] (default
            ``DEFAULT_TOLERANCE``; 0 keeps every traced point).

    Returns:
        A :class:`Silhouette`.

    Raises:
        ValueError: wrong shapes, NaN or infinite coordinates, out-of-range indices, an empty mesh, a bad
            direction or resolution or tolerance; :class:`NoSilhouette` (a ValueError) for a mesh whose
            projection has zero area, or :class:`PartsTooSmall` (one too) for one that covers no grid cell (tiny
            parts far apart).
    """
    verts, tris = _mesh_arrays(vertices, triangles)
    if len(verts) == 0 or len(tris) == 0:
        raise ValueError(f"the mesh is empty ({len(verts)} vertices, {len(tris)} triangles)")
    view = _as_direction(direction)
    res = DEFAULT_RESOLUTION if resolution is None else resolution
    lo, hi = _rigger_silhouette.MIN_RESOLUTION, _rigger_silhouette.MAX_RESOLUTION
    if isinstance(res, bool) or not isinstance(res, (int, np.integer)) or not lo <= res <= hi:
        raise ValueError(f"resolution must be an integer in [{lo}, {hi}], got {res!r}")
    tol = DEFAULT_TOLERANCE if tolerance is None else tolerance
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) or not 0 <= tol <= 1:
        raise ValueError(f"tolerance must be a number in [0, 1] (a fraction of a grid cell), got {tol!r}")
    handle = _rigger_silhouette.trace(verts, tris, view, int(res), float(tol))
    loops = handle.loops()
    if not loops:
        raise PartsTooSmall(f"no part of the mesh covers a grid cell seen along {tuple(float(c) for c in view)} "
                           f"({res} cells along the projection's longest side): its parts are too small for "
                           f"the space between them; rig them separately or raise the resolution")
    origin, u, v, unit = handle.frame()
    _, cell, _, _ = handle.grid()
    return Silhouette(loops, origin, u, v, unit, cell, handle)


SEAM_GAP = _rigger_silhouette.SEAM_GAP


def sealed(vertices, triangles):
    """The ``vertices`` of a mesh built of pieces that abut without sharing vertices, with those seams closed.

    Game exports often are such pieces (a body shell, and its legs' inner shell, open where they meet): each piece
    alone bounds nothing, so ``layers`` cannot pair its hits. Every vertex on an open boundary that lies within
    ``SEAM_GAP`` of the mesh's largest extent from a boundary vertex of another part moves, with the vertices at its
    position, onto one shared position, so the pieces weld into the solid they bound; parts farther apart stay
    apart. Returns (N, 3) float64 vertices: a new array when any moved, else ``vertices`` as given (as float64).
    """
    verts, tris = _mesh_arrays(vertices, triangles)
    out, moved = _rigger_silhouette.seal(verts, tris)
    return out if moved else verts


def _mesh_arrays(vertices, triangles):
    """``vertices`` as finite (N, 3) float64 and ``triangles`` as in-range (M, 3) int32, as the compiled tracer takes
    them; ValueError saying what is wrong."""
    verts = point_array(vertices, 3, "vertices")
    if len(verts) > INT32_MAX:
        raise ValueError(f"the mesh has {len(verts)} vertices; the tracer indexes at most {INT32_MAX}")
    tris = index_array(triangles, 3, len(verts), name="triangles", item="triangle", target=("vertex", "vertices"),
                       dtype=np.int32)
    return verts, tris


def _as_direction(direction):
    if isinstance(direction, str):
        name = direction.strip().upper()
        sign = -1.0 if name.startswith("-") else 1.0
        axis = AXES.get(name.lstrip("+-"))
        if axis is None or name.count("-") + name.count("+") > 1:
            raise ValueError(f"direction must be 'X', 'Y', 'Z' (optionally with a sign) or a 3D vector, "
                             f"got {direction!r}")
        return np.array(axis) * sign
    vec = numeric_array(direction, "direction")
    if vec.shape != (3,):
        raise ValueError(f"direction must be 'X', 'Y', 'Z' or a 3D vector, got shape {vec.shape}")
    if not np.isfinite(vec).all() or not np.any(vec):
        raise ValueError(f"direction must be finite and non-zero, got {vec.tolist()}")
    return np.ascontiguousarray(vec)


def _as_points(values):
    """(P, 2) finite points; a single (2,) point is one row."""
    pts = numeric_array(values, "points")
    return point_array(pts[None] if pts.shape == (2,) else pts, 2, "points")
