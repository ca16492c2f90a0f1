"""View choice: which axis the method looks along, the frame a view direction defines, each view's silhouette with
its triangulation and chordal axis, and how a mirror plane looks in a view."""
from typing import NamedTuple

import numpy as np

from ... import cdt, silhouette
from ...core.mirror import mirrored
from .chordal import chordal_axis, triangle_classes
from .outline import outline_segments, without_small_holes

AXES = np.eye(3)
AXIS_NAMES = ("X", "Y", "Z")


class View(NamedTuple):
    """A view of the mesh: its ``Silhouette``, the outline's ``rigger.cdt`` triangulation with the class of each
    triangle, and its ``ChordalAxis``."""

    sil: object
    triangulation: object
    classes: np.ndarray
    axis_graph: object


def view_frame(direction, tuning):
    """(frame, axis) to rig along ``direction``: ``frame`` rows are orthonormal axes in world coordinates, number
    ``axis`` being the direction (signed to point along that world axis, the nearest one to it) and the others as
    near their world axes as that allows; None for the world frame when the direction is a world axis."""
    vector = np.asarray(direction, dtype=np.float64)
    axis = int(np.argmax(np.abs(vector)))
    if vector[axis] == 0:
        raise ValueError("view_direction must not be zero when the view is DIRECTION")
    vector = vector / vector[axis]  # along the nearest axis's positive end, its largest component 1 (no overflow)
    vector[np.abs(vector) < tuning.axis_snap] = 0.0  # single-precision noise (a 3D view's front): the axis itself
    frame = np.eye(3)
    frame[axis] = vector / np.linalg.norm(vector)
    for other in (a for a in range(3) if a != axis):  # Gram-Schmidt from the view direction on: right-handed
        row = np.eye(3)[other]
        for done in [axis] + [a for a in range(other) if a != axis]:
            row = row - (row @ frame[done]) * frame[done]
        frame[other] = row / np.linalg.norm(row)
    return (None if np.array_equal(frame, np.eye(3)) else frame), axis


def primary_view(mesh, view, params, tuning):
    """(axis, ``View``) of the primary view: along the chosen axis, or for AUTO along the first of the
    ``axes_by_spread`` that shows the mesh at all (triangles all standing edge-on to one axis show nothing along
    it); a flat mesh tilted off the axis planes is seen straight on, not edge-on."""
    if view != "AUTO":
        axis = AXIS_NAMES.index(view)
        candidates = [(axis, AXES[axis])]  # (axis, view direction), the first that shows the mesh wins
    else:
        order = axes_by_spread(mesh.vertices, mesh.triangles, tuning.spread_samples)
        flat = mesh.flat_normal
        if flat is not None:
            candidates = [(order[0], flat if abs(flat @ AXES[order[0]]) < 1 - 1e-9 else AXES[order[0]])]
        else:
            candidates = [(axis, AXES[axis]) for axis in order]
    first_error = None
    for axis, direction in candidates:
        try:
            return axis, planar_view(mesh.vertices, mesh.triangles, direction, params.resolution, params)
        except silhouette.PartsTooSmall:
            raise  # along every axis alike
        except silhouette.NoSilhouette as error:
            first_error = first_error or error
    raise first_error


def perpendicular_views(mesh, axis, params, tuning):
    """The ``View``s across the primary one along ``axis``: the side view (the other axis of smaller spread) and the
    end-on view (along the longest extent when the view is AUTO) at ``end_resolution`` of the resolution, as it only
    looks for limbs; None for one that shows nothing (an open tube seen end-on)."""
    side_axis, end_axis = sorted((a for a in range(3) if a != axis), key=lambda a: mesh.spread[a])
    end_resolution = max(tuning.min_view_resolution, round(tuning.end_resolution * params.resolution))
    return [_other_view(mesh, other, resolution, params) for other, resolution in
            ((side_axis, params.resolution), (end_axis, end_resolution))]


def _other_view(mesh, axis, resolution, params):
    try:
        return planar_view(mesh.vertices, mesh.triangles, AXES[axis], resolution, params)
    except silhouette.NoSilhouette:
        return None


def axes_by_spread(vertices, triangles, samples):
    """The axes by how wide their projection spreads the surface, widest first: the sum of the variances of the
    other two coordinates, over (a regular sample of ``samples``) triangle centroids weighted by area (so dense
    regions do not dominate)."""
    variances = _variances(vertices, triangles, samples)
    return [int(a) for a in np.argsort([-(variances.sum() - variances[a]) for a in range(3)], kind="stable")]


def _variances(vertices, triangles, samples):
    """Per-axis variance of the surface (area-weighted triangle centroids)."""
    triangles = triangles[::max(1, len(triangles) // samples)]
    a, b, c = (np.take(vertices, triangles[:, k], axis=0) for k in range(3))  # take: far faster than indexing
    points = (a + b + c) / 3
    u, w = b - a, c - a
    weights = np.sqrt((u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1]) ** 2 + (u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2]) ** 2
                      + (u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) ** 2)
    if not weights.sum() > 0:
        return points.var(axis=0)
    mean = weights @ points / weights.sum()
    return weights @ (points - mean) ** 2 / weights.sum()


def planar_view(vertices, triangles, direction, resolution, params):
    """The ``View`` along ``direction``: the silhouette, its outline (holes under ``min_hole`` filled, edges
    subdivided to ``outline_spacing``) triangulated, and the chordal axis."""
    sil = silhouette.trace(vertices, triangles, direction, resolution=resolution)
    points, segments = outline_segments(without_small_holes(sil.loops, params.min_hole), params.outline_spacing)
    tri = cdt.triangulate(points, segments, mode="inside")
    classes = triangle_classes(tri)
    return View(sil, tri, classes, chordal_axis(tri, classes))


def reflection_in_view(sil, plane, tuning):
    """The reflection across ``plane`` = (axis, offset) of points (P, 2) in the plane of view ``sil``, or None when
    there is no plane or the view does not look along it (``along_plane``): seen from the side, a plane's two
    halves hide each other."""
    if plane is None or abs(sil.direction[plane[0]]) > tuning.along_plane:
        return None
    return lambda points: sil.project(mirrored(sil.lift(points, 0.0), plane))[0]


def mirror_in_depth(sil, plane, tolerance, tuning):
    """(depth, ``tolerance``) of ``plane`` = (axis, offset) along view ``sil`` when the view looks straight across
    it (along its axis, within ``along_plane``), else None: ``depth.place_chains``' ``mirror``."""
    if plane is None or abs(abs(sil.direction[plane[0]]) - 1) > tuning.along_plane:
        return None
    axis, offset = plane
    return float((offset - sil.origin[axis]) * sil.direction[axis]), tolerance
