"""Skin weights that always exist: every point weighted over its nearest few bones, by distance to the bone segments.

The last step of Rigger's skinning (``rigger.blender.skinning``): Blender's bone heat can fail outright or leave
vertices unweighted, and this weighting is what every vertex still without a weight gets. A small documented API over
the bundled compiled module ``rigger._rigger_weights`` (``ext/skin_weights.c``); no bpy.

Example::

    from rigger import weights
    normals = weights.vertex_normals(points, triangles)           # of a mesh with its seams welded
    result = weights.bone_weights(points, heads, tails, normals)   # (N, 3), (B, 3), (B, 3), (N, 3) or None
    result.bones[:, 0]            # each point's dominant bone
    result.dense(len(heads))      # (N, B) weights, rows summing to 1

How a point is weighted: each bone gets a reach key ``s``, the distance from the point to the bone's segment plus
``facing_penalty`` times how far the segment's nearest point lies in front of the point's surface (along its unit
normal). A vertex's own bones lie behind its surface, inside the body; a bone in front of it belongs to another part
seen through the air (the other leg, from an inner thigh), and the penalty lets the own part's bones win at equal
distance. The ``bones_per_point`` bones with the smallest keys, s1 <= s2 <= ..., get weights
``(s1 / s)**power - (s1 / s_next)**power``, where ``s_next`` is the key of the next bone, then the row is normalised:
a bone's weight falls to zero exactly when another bone overtakes it, so weights vary continuously over the mesh. A
point on a bone gets that bone alone (shared equally where bones meet); a point where every kept bone ties with the
next one shares equally among the nearest. Ties are broken by bone index and the search is exact, so the result
depends only on the input. A bounding-volume hierarchy over the bones makes each point cost about log(B) + k bone
tests (timings: ``bench/results/skinning.md``).
"""
from dataclasses import dataclass

import numpy as np

from . import _rigger_weights
from .core.arrays import index_array, point_array

DEFAULT_BONES_PER_POINT = 4
DEFAULT_POWER = 4.0
DEFAULT_FACING_PENALTY = 1.0
MAX_BONES = _rigger_weights.MAX_BONES  # bone indices and the bone tree's nodes are int32


@dataclass(frozen=True, eq=False)
class BoneWeights:
    """The result of :func:`bone_weights`.

    Attributes:
        bones: (N, K) int32 bone indices per point, by decreasing weight; -1 past the bones that carry weight.
            ``bones[:, 0]`` is every point's dominant bone.
        weights: (N, K) float64, matching ``bones``: positive, non-increasing along each row, 0 where the bone is
            -1, each row summing to 1 (up to rounding).
    """

    bones: np.ndarray
    weights: np.ndarray

    def dense(self, bone_count):
        """(N, bone_count) float64 weights: row i holds point i's weight for every bone."""
        if isinstance(bone_count, bool) or not isinstance(bone_count, (int, np.integer)) or bone_count < 1:
            raise ValueError(f"bone_count must be a positive integer, got {bone_count!r}")
        if self.bones.size and self.bones.max() >= bone_count:
            raise ValueError(f"bone_count {bone_count} is too small for bone index {int(self.bones.max())}")
        table = np.zeros((len(self.bones), bone_count))
        rows, slots = np.nonzero(self.bones >= 0)
        table[rows, self.bones[rows, slots]] = self.weights[rows, slots]
        return table


def bone_weights(points, heads, tails, normals=None, *, bones_per_point=DEFAULT_BONES_PER_POINT,
                 power=DEFAULT_POWER, facing_penalty=DEFAULT_FACING_PENALTY):
    """Weights of every point over its nearest bones; see the module docstring for the rule.

    Args:
        points: (N, 3) finite coordinates (N may be 0).
        heads, tails: (B, 3) finite coordinates of the bone segments, B >= 1, in the same frame as ``points``.
            A bone whose head equals its tail acts as a point.
        normals: None, or (N, 3) finite outward surface normals at the points (any length; a zero normal switches
            the facing penalty off for that point).
        bones_per_point: how many bones may weigh on a point (K >= 1; at most B carry weight).
        power: how fast a bone's share falls with its key relative to the nearest (> 0; higher is sharper).
        facing_penalty: how much a bone in front of the surface is pushed away (>= 0; 0 ignores normals).

    Returns:
        A :class:`BoneWeights` with K columns.

    Raises:
        ValueError: wrong shapes, NaN or infinite coordinates, no bones, or a parameter out of range.
    """
    point_rows = point_array(points, 3, "points")
    head_array = point_array(heads, 3, "heads")
    tail_array = point_array(tails, 3, "tails")
    if len(head_array) == 0:
        raise ValueError("bone weights need at least one bone (heads and tails are empty)")
    if len(head_array) > MAX_BONES:
        raise ValueError(f"at most {MAX_BONES} bones are supported, got {len(head_array)}")
    if tail_array.shape != head_array.shape:
        raise ValueError(f"heads and tails must have the same shape, got {head_array.shape} and {tail_array.shape}")
    normal_array = None
    if normals is not None:
        normal_array = point_array(normals, 3, "normals")
        if normal_array.shape != point_rows.shape:
            raise ValueError(f"normals must match points' shape {point_rows.shape}, got {normal_array.shape}")
    if isinstance(bones_per_point, bool) or not isinstance(bones_per_point, (int, np.integer)) \
            or not 1 <= bones_per_point <= 1024:
        raise ValueError(f"bones_per_point must be an integer from 1 to 1024, got {bones_per_point!r}")
    power_value = _number(power, "power")
    if not power_value > 0:
        raise ValueError(f"power must be a finite number > 0, got {power!r}")
    penalty_value = _number(facing_penalty, "facing_penalty")
    if not penalty_value >= 0:
        raise ValueError(f"facing_penalty must be a finite number >= 0, got {facing_penalty!r}")
    bones, weights = _rigger_weights.bone_weights(point_rows, normal_array, head_array, tail_array,
                                                  int(bones_per_point), power_value, penalty_value)
    return BoneWeights(bones, weights)


def vertex_normals(vertices, triangles):
    """Area-weighted vertex normals (N, 3) of a triangle mesh, not normalised (``bone_weights`` takes any length):
    each vertex sums the cross products of its triangles' edges. A vertex without triangles, or whose triangles
    cancel out, gets a zero normal, which switches the facing penalty off for it.

    Weld a mesh's seams before: a vertex split along a seam would otherwise get the normal of its own side's
    triangles only, and its copies could take different bones.
    """
    vertex_rows = point_array(vertices, 3, "vertices")
    triangle_rows = index_array(triangles, 3, len(vertex_rows), name="triangles", item="triangle",
                                target=("vertex", "vertices"), dtype=np.int64)
    corners = vertex_rows[triangle_rows]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals = np.zeros_like(vertex_rows)
    for corner in range(3):
        np.add.at(normals, triangle_rows[:, corner], face_normals)
    return normals


def _number(value, name):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not np.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)
