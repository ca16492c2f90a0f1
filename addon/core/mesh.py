"""A triangle mesh validated once at the door, so every method can trust its arrays.

Bad input (empty, NaN, wrong shapes or dtypes, out-of-range indices, all on one line, a size beyond float64's normal
range) raises ``ValueError`` with a message that says what is wrong; faces that repeat a vertex index are dropped
and counted, since exporters routinely emit them.
"""
import itertools
from functools import cached_property

import numpy as np

from .arrays import column_bounds, concatenated_ranges, nonfinite_rows

# A principal variance this small relative to the largest is none: two such make a line, one a flat mesh.
LINE_VARIANCE_RATIO = 1e-12


class Mesh:
    """Vertices and triangles of one (possibly multi-part, possibly open) mesh.

    Attributes:
        vertices: (N, 3) float64, read-only copy of the input.
        triangles: (M, 3) int32, read-only, indexing ``vertices``; faces that repeat a vertex index are removed.
        degenerate_count: how many such faces were removed.

    ``bbox``, ``scale``, ``unit_factor``, ``centroid``, ``spread`` and ``flat_normal`` describe the ``used_vertices``,
    so a stray loose vertex cannot distort them.
    """

    def __init__(self, vertices, triangles):
        self.vertices = validated_vertices(vertices)
        self.triangles, self.degenerate_count = _validated_triangles(triangles, len(self.vertices))
        self._reject_line()

    def at_unit_size(self, rotation=None):
        """This mesh scaled by ``unit_factor`` (a power of two: exact) and turned by the orthonormal ``rotation`` (rows:
        the new axes), sharing its triangles. A similarity keeps a valid mesh valid, so only a vertex that would
        overflow (one far from the others, or a tiny mesh far from the origin) is checked for; which vertices are
        used carries over, and unturned, the measures already taken do too, scaled exactly. A mesh already at unit
        size and not turned is itself (its arrays are read-only, so sharing it is safe)."""
        factor = self.unit_factor
        if factor == 1 and rotation is None:
            return self
        with np.errstate(over="ignore"):
            vertices = self.vertices if factor == 1 else self.vertices * factor  # turning alone copies once
        far = nonfinite_rows(vertices) if factor > 1 else ()  # scaling down cannot overflow
        if len(far):
            raise ValueError(f"vertex {far[0]} at {self.vertices[far[0]]} lies too far from a mesh {self.scale:.3g} "
                             f"big to rig it at unit size; move the mesh nearer the origin, or remove that vertex if "
                             f"it is loose")
        moved = self._moved(vertices if rotation is None else vertices @ np.asarray(rotation).T)
        if rotation is None:
            moved.__dict__.update(bbox=_read_only(self.bbox * factor), centroid=_read_only(self.centroid * factor),
                                  _scatter=self._scatter)  # taken at unit size already
        return moved

    def with_vertices(self, vertices):
        """This mesh with its vertices replaced by ``vertices`` of the same count (moved a hair, as
        ``rigger.silhouette.sealed`` moves them), sharing its triangles; the measures are taken again when asked for.
        Itself when ``vertices`` is its own array."""
        if vertices is self.vertices:
            return self
        if np.shape(vertices) != self.vertices.shape:
            raise ValueError(f"with_vertices needs {self.vertices.shape} vertices, got {np.shape(vertices)}")
        return self._moved(np.array(vertices, dtype=np.float64))

    def _moved(self, vertices):
        """This mesh at other ``vertices`` (a valid (N, 3) float64 array it may keep), sharing its triangles and
        which vertices they use; the other measures are taken again when asked for."""
        moved = object.__new__(Mesh)
        moved.vertices = _read_only(vertices)
        moved.triangles, moved.degenerate_count = self.triangles, self.degenerate_count
        moved.__dict__["_used"] = self._used  # cached_property values live in the instance dict
        return moved

    @cached_property
    def _used(self):
        """Which vertices triangles use, or None when all are."""
        used = np.zeros(len(self.vertices), dtype=bool)
        used[self.triangles.ravel()] = True
        return None if used.all() else used

    @cached_property
    def used_vertices(self):
        """The vertices that triangles use (all of them, unless some are loose)."""
        return self.vertices if self._used is None else self.vertices[self._used]

    @cached_property
    def bbox(self):
        """(2, 3) float64: the minimum and maximum corner."""
        return _read_only(column_bounds(self.used_vertices))

    @cached_property
    def scale(self):
        """The largest extent of the bounding box: the length that makes tolerances scale-free. ValueError when
        it is not 0 (a point, which the constructor refuses) or a normal float64 number at least 2**-1022 and below
        2**1023 (so that ``unit_factor`` is a normal power of two)."""
        with np.errstate(over="ignore"):
            extent = float((self.bbox[1] - self.bbox[0]).max())
        if not extent < 2.0 ** 1023:
            raise ValueError(f"mesh is too large: its extent from {self.bbox[0]} to {self.bbox[1]} reaches float64's "
                             f"limit (2**1023); scale it down")
        if 0 < extent < np.finfo(np.float64).tiny:
            raise ValueError(f"mesh is too small: its size {extent:.3g} is below float64's normal numbers; scale it up")
        return extent

    @cached_property
    def unit_factor(self):
        """The power of two that scales the mesh to a size between 0.5 and 1 (1 for a point): exact in floating
        point, so a method may work at that size, far from overflow and underflow, and scale back without error."""
        return float(np.ldexp(1.0, -np.frexp(self.scale)[1]))  # frexp(0) has exponent 0: a point keeps its size

    @cached_property
    def centroid(self):
        """(3,) float64: the mean position of the used vertices."""
        points, factor = self.used_vertices, self.unit_factor
        # summed at unit size (no overflow, the same bits at any scale), the factor in the weights: no scaled copy
        return _read_only(np.full(len(points), factor) @ points / len(points) / factor)  # BLAS: faster than mean

    @cached_property
    def _scatter(self):
        """The (3, 3) scatter matrix of the used vertices about their centroid, at ``unit_factor`` size."""
        centred = self.used_vertices - self.centroid
        centred *= self.unit_factor
        return centred.T @ centred

    @cached_property
    def spread(self):
        """(3,) float64: how far the used vertices spread along each axis (their summed squared offsets from the
        centroid, at ``unit_factor`` size): proportional to the per-axis variances."""
        return _read_only(np.diag(self._scatter).copy())

    @cached_property
    def _principal(self):
        """Principal variances (ascending) and axes (columns) of the used vertices, at ``unit_factor`` size."""
        return np.linalg.eigh(self._scatter)

    @property
    def principal_axes(self):
        """(3, 3) float64: the used vertices' principal axes as unit columns, their spread ascending."""
        return self._principal[1]

    @cached_property
    def flat_normal(self):
        """(3,) unit normal of the plane a flat mesh (a 2D cut-out) lies in, its largest component positive; None
        for a mesh with thickness."""
        variances, axes = self._principal
        if variances[0] > LINE_VARIANCE_RATIO * variances[2]:
            return None
        normal = axes[:, 0]
        return _read_only(normal * np.sign(normal[np.argmax(np.abs(normal))]))

    def __repr__(self):
        return f"Mesh({len(self.vertices)} vertices, {len(self.triangles)} triangles)"

    def _reject_line(self):
        """A flat mesh is fine (a 2D cut-out character rigs in its plane); one with no extent in two directions
        has no outline to rig."""
        variances = self._principal[0]
        if variances[2] <= 0:
            raise ValueError("mesh has zero size: every vertex of its triangles is at the same point")
        if variances[1] <= LINE_VARIANCE_RATIO * variances[2]:
            raise ValueError("mesh is a line: its vertices lie on one line; rigging needs a surface")


def triangulate_polygons(faces):
    """Fan-triangulate polygon faces, each a sequence of vertex indices, as OBJ files and Blender polygons hold them.

    A face (a, b, c, d, ...) becomes (a, b, c), (a, c, d), ...: exact for convex faces, which is what modelling tools
    emit almost always. Returns (sum(len(face) - 2), 3) int32 in face order. Index range is checked by :class:`Mesh`.
    """
    counts = np.array([len(face) for face in faces], dtype=np.int64)
    if len(counts) == 0:
        return np.empty((0, 3), dtype=np.int32)
    short = np.flatnonzero(counts < 3)
    if short.size:
        raise ValueError(f"face {short[0]} has {counts[short[0]]} vertices; a polygon needs at least 3")
    flat = _as_array(list(itertools.chain.from_iterable(faces)), "face indices")
    if flat.dtype.kind not in "iu":
        raise ValueError(f"face indices must be integers, got dtype {flat.dtype}")
    int32 = np.iinfo(np.int32)
    if flat.min() < int32.min or flat.max() > int32.max:
        raise ValueError("face indices do not fit in 32 bits")
    return fan_triangles(flat, counts).astype(np.int32)


def fan_triangles(corners, counts):
    """Triangles (sum(counts - 2), 3) fanning each polygon from its first corner: ``corners`` holds every face's
    vertex indices one after the other, ``counts`` (F,) how many each has (at least 3)."""
    triangle_counts = counts - 2
    face_starts = np.cumsum(counts) - counts
    base = np.repeat(face_starts, triangle_counts)
    corner = concatenated_ranges(face_starts, triangle_counts)
    return np.stack([corners[base], corners[corner + 1], corners[corner + 2]], axis=1)


def _read_only(array):
    array.setflags(write=False)
    return array


def _as_array(values, what):
    try:
        return np.asarray(values)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} must be a rectangular array of numbers ({error})") from None


def _rows_of_three(values, what, kinds, kind_text, count_letter):
    """``values`` as a non-empty (count, 3) array whose dtype kind is one of ``kinds``, or a ValueError naming
    ``what`` is wrong."""
    array = _as_array(values, what)
    if array.size == 0:
        raise ValueError(f"mesh has no {what}")
    if array.dtype.kind not in kinds:
        raise ValueError(f"{what} must be {kind_text}, got dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{what} must have shape ({count_letter}, 3), got {array.shape}")
    return array


def validated_vertices(values):
    """``values`` as a read-only (N, 3) float64 array; ValueError unless they are N >= 1 rows of three finite real
    numbers."""
    array = np.array(_rows_of_three(values, "vertices", "iuf", "real numbers", "N"), dtype=np.float64)
    bad = nonfinite_rows(array)
    if bad.size:
        raise ValueError(f"{bad.size} vertices have NaN or infinite coordinates (the first is vertex {bad[0]})")
    return _read_only(array)


def _validated_triangles(values, vertex_count):
    array = _rows_of_three(values, "triangles", "iu", "integer vertex indices", "M")
    lowest, highest = array.min(), array.max()
    if lowest < 0:
        raise ValueError(f"triangles contain the negative vertex index {lowest}")
    if highest >= vertex_count:
        raise ValueError(f"triangles reference vertex {highest} but the mesh has only {vertex_count} vertices")
    array = array.astype(np.int32)
    degenerate = (array[:, 0] == array[:, 1]) | (array[:, 1] == array[:, 2]) | (array[:, 2] == array[:, 0])
    degenerate_count = int(degenerate.sum())
    if degenerate_count == len(array):
        raise ValueError(f"all {degenerate_count} triangles are degenerate (each repeats a vertex index)")
    if degenerate_count:
        array = array[~degenerate]
    return _read_only(array), degenerate_count
