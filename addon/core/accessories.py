"""Accessories: the loose parts of a mesh that no bone runs through (an eye, a tooth, a nail, a button, a plate).

Such a part has no bone of its own, so any bone's weight on it is a guess: bone heat on an ogre's tongue, which
sees the throat, gave it the neck, and turning the head pushed the tongue out through the cheek. An accessory
instead moves as one piece with the surface nearest to it, on the parts bones do run through
(``rigger.blender.skinning``): every vertex of it takes the mean, over the part, of the weights at each vertex's
nearest point of that surface, the points where it touches counting most (:func:`part_means`). It cannot poke
through what it sits on or in, and a rigid piece (a plate, a claw, an eye) stays rigid: over the development set
this posed closer to the artists' rigs than each vertex taking its own nearest point's weights, or an even mean.
"""
import numpy as np

from .arrays import concatenated_ranges

CONTACT = 0.05  # a point this share of its part's extent from the surface counts half as much as one touching it


def boneless_parts(part_of, positions, heads, tails):
    """(P,) bool: which loose parts of a mesh (its seams welded; ``part_of`` the part of each of its ``positions``,
    ``core.graphs.loose_parts``) are accessories, the parts whose bounding box no bone segment (``heads`` to
    ``tails``, (B, 3)) crosses. The largest part is never one: it is the body the others sit on."""
    part_of = np.asarray(part_of)
    count = int(part_of.max()) + 1 if len(part_of) else 0
    low, high = _bounds(part_of, np.asarray(positions, dtype=np.float64), count)
    crossed = np.zeros(count, dtype=bool)
    for head, tail in zip(np.asarray(heads, dtype=np.float64), np.asarray(tails, dtype=np.float64)):
        crossed |= _segment_crosses(head, tail, low, high)
    boneless = ~crossed
    if count:
        boneless[np.argmax(np.bincount(part_of, minlength=count))] = False
    return boneless


def _bounds(part_of, points, count):
    """(low, high) (count, 3): the corners of each part's bounding box, given the part of each of ``points``."""
    low, high = np.full((count, 3), np.inf), np.full((count, 3), -np.inf)
    np.minimum.at(low, part_of, points)
    np.maximum.at(high, part_of, points)
    return low, high


def _segment_crosses(head, tail, low, high):
    """(P,) bool: the segment from ``head`` to ``tail`` meets the boxes ``low``..``high`` ((P, 3) corners); the slab
    test, clipping the segment's parameter range to each axis's slab in turn."""
    enter = np.zeros(len(low))
    leave = np.ones(len(low))
    for axis in range(3):
        start, step = head[axis], tail[axis] - head[axis]
        if step == 0:
            outside = (start < low[:, axis]) | (start > high[:, axis])
            leave = np.where(outside, -1.0, leave)
            continue
        first, second = (low[:, axis] - start) / step, (high[:, axis] - start) / step
        enter = np.maximum(enter, np.minimum(first, second))
        leave = np.minimum(leave, np.maximum(first, second))
    return enter <= leave


def surface_entries(corners, barycentric, donor_entries):
    """The weights at points on a weighted surface: (point, bone, weight) arrays, each point's weights summing to
    those of its triangle's corners blended by ``barycentric``. ``corners`` (A, 3) are the vertices of the triangle
    each point lies on, ``barycentric`` (A, 3) its coordinates there, ``donor_entries`` the surface's (vertex, bone,
    weight) arrays."""
    vertices, bones, weights = (np.asarray(array) for array in donor_entries)
    order = np.argsort(vertices, kind="stable")
    vertices, bones, weights = vertices[order], bones[order], weights[order]
    flat = np.asarray(corners, dtype=np.int64).ravel()
    starts = np.searchsorted(vertices, flat, side="left")
    counts = np.searchsorted(vertices, flat, side="right") - starts
    picked = concatenated_ranges(starts, counts)
    points = np.repeat(np.arange(len(flat)) // 3, counts)
    share = np.repeat(np.asarray(barycentric, dtype=np.float64).ravel(), counts) * weights[picked]
    points, bones, totals = _summed(points, bones[picked], share)
    kept = totals > 0
    return points[kept], bones[kept], totals[kept]


def part_means(part_of, points, distances, entries):
    """(part, bone, weight) arrays: each part's weighted mean of its points' weights. ``part_of`` (A,) is the part of
    each point (0 .. P - 1), ``points`` (A, 3) where they are, ``distances`` (A,) how far each lies from the surface
    its weights come from, ``entries`` the points' (point, bone, weight) arrays. A point counts by how close it lies,
    1 / (distance + ``CONTACT`` x its part's extent): where a part touches the surface (a claw's root, a tooth's)
    outweighs its far side, which may lie nearer another limb."""
    part_of = np.asarray(part_of)
    count = int(part_of.max()) + 1 if len(part_of) else 0
    low, high = _bounds(part_of, points, count)
    extent = (high - low).max(axis=1)
    closeness = 1.0 / (np.asarray(distances, dtype=np.float64) + CONTACT * extent[part_of] + 1e-300)
    share = closeness / np.bincount(part_of, closeness, minlength=count)[part_of]
    point, bones, weights = (np.asarray(array) for array in entries)
    return _summed(part_of[point], bones, weights * share[point])


def _summed(rows, bones, weights):
    """(row, bone, weight) arrays, the weights of each (row, bone) pair summed, in order of row, then bone."""
    bone_count = int(bones.max()) + 1 if len(bones) else 1
    keys, pair = np.unique(rows * bone_count + bones, return_inverse=True)
    return keys // bone_count, keys % bone_count, np.bincount(pair.ravel(), weights, minlength=len(keys))


def barycentric(points, a, b, c):
    """(A, 3) barycentric coordinates of ``points`` (A, 3) in triangles ``a``, ``b``, ``c`` (A, 3 each), the points
    lying on them; a degenerate triangle gives its first corner everything."""
    ab, ac, ap = b - a, c - a, points - a
    d00, d01, d11 = (ab * ab).sum(1), (ab * ac).sum(1), (ac * ac).sum(1)
    d20, d21 = (ap * ab).sum(1), (ap * ac).sum(1)
    area = d00 * d11 - d01 * d01
    safe = np.where(area > 0, area, 1.0)
    v = np.where(area > 0, (d11 * d20 - d01 * d21) / safe, 0.0)
    w = np.where(area > 0, (d00 * d21 - d01 * d20) / safe, 0.0)
    result = np.clip(np.stack([1.0 - v - w, v, w], axis=1), 0.0, None)  # rounding may put a point just outside
    return result / result.sum(1, keepdims=True)
