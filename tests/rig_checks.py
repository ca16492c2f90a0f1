"""Checks of a rig against a known skeleton, for tests on the generated characters (bpy-free).

The skeletons are ``rigger.Skeleton``s: the rig under test and the true one (``rigger.samples.ground_truth_bones``).
Distances are fractions of ``size``, the mesh's largest bounding-box extent, as in the posing benchmark, whose
measures these reuse (``bench/posing_math.py``). A *chain* of a skeleton is a run of bones from a root bone or a
branch (a bone whose parent has more children than it) down to a leaf or to the last bone before the next branch.
"""
import os
import sys
from typing import NamedTuple

import numpy as np

from rigger.core.polyline import segment_distances

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "bench"))
import posing_math  # noqa: E402  (bench/ is no package)

FOLLOWS = posing_math.FOLLOWS  # a true limb is followed when its points lie this close on average (fraction of size)
CHAIN_STEP = posing_math.CHAIN_STEP  # spacing of the points along a true limb (fraction of size)
OFF_PLANE = posing_math.OFF_PLANE  # a bone farther off the mirror plane than this (midpoint) has a side
X_MIRROR = (0, 0.0)  # the generated characters' mirror plane: (axis, offset), X = 0


def mesh_size(vertices):
    """The largest extent of the bounding box of ``vertices`` (N, 3): the unit of every distance here."""
    return float(np.ptp(np.asarray(vertices, dtype=np.float64), axis=0).max())


def side_of(name):
    """``"L"`` or ``"R"`` for a name with Blender's side suffix (``limb02.01.L``), else None."""
    match = posing_math.SIDE.match(name)
    return match.group(2) if match else None


def side_counts(skeleton):
    """(bones named ``.L``, bones named ``.R``)."""
    sides = [side_of(name) for name in skeleton.names]
    return sides.count("L"), sides.count("R")


def unsided_off_plane(skeleton, size, plane=X_MIRROR, tolerance=OFF_PLANE):
    """Names of the bones without a side suffix whose midpoint lies more than ``tolerance`` * ``size`` off ``plane``
    ((axis, offset)): bones that should say which side they are on."""
    return posing_math.unsided_off_plane(skeleton.names, skeleton.heads, skeleton.tails, _plane(plane), size,
                                         tolerance)


def twin_mismatches(skeleton, size, plane=X_MIRROR):
    """{name without its side: the larger of the head-to-head and tail-to-tail distances between the ``.L`` bone and
    the mirror image of its ``.R`` twin, a fraction of ``size``} for every named pair."""
    return posing_math.twin_mismatches(skeleton.names, skeleton.heads, skeleton.tails, _plane(plane), size)


def _plane(plane):
    axis, offset = plane
    return posing_math.MirrorPlane(axis, offset, 0.0)


def chains(skeleton):
    """The skeleton's chains (see the module's docstring) as lists of bone indices from the top down, in the order of
    their first bones."""
    parents = np.asarray(skeleton.parents)
    children = np.bincount(parents[parents >= 0], minlength=len(parents))
    starts = [bone for bone in range(len(parents)) if parents[bone] < 0 or children[parents[bone]] > 1]
    result = []
    for start in starts:
        chain = [start]
        while children[chain[-1]] == 1:
            chain.append(int(np.flatnonzero(parents == chain[-1])[0]))
        result.append(chain)
    return result


def chain_parent(skeleton, chain):
    """The bone ``chain`` (a list of bone indices from :func:`chains`) hangs from, or -1 for a root chain."""
    return int(skeleton.parents[chain[0]])


def chains_in_ball(skeleton, centre, radius, min_inside=0.5, step=0.005):
    """The chains of which at least ``min_inside`` * ``radius`` of bone length lies inside the ball (``centre``,
    ``radius``): how many chains run through a part, such as a head (a trunk ending at the neck grazes it)."""
    centre = np.asarray(centre, dtype=np.float64)
    found = []
    for chain in chains(skeleton):
        inside = 0.0
        for bone in chain:
            head, tail = skeleton.heads[bone], skeleton.tails[bone]
            length = float(np.linalg.norm(tail - head))
            count = max(int(np.ceil(length / (step * radius))), 1)
            points = head + (np.arange(count) + 0.5)[:, None] / count * (tail - head)
            inside += length * float((np.linalg.norm(points - centre, axis=1) <= radius).mean())
        if inside >= min_inside * radius:
            found.append(chain)
    return found


def nearest_joint(skeleton, point):
    """(distance, position) of the skeleton's joint (``Skeleton.joints``) nearest ``point``."""
    joints = skeleton.joints()
    gaps = np.linalg.norm(joints - np.asarray(point, dtype=np.float64), axis=1)
    return float(gaps.min()), joints[int(gaps.argmin())]


def stray_joints(skeleton, truth, size, tolerance=FOLLOWS):
    """The joints of ``skeleton`` (``Skeleton.joints``) farther than ``tolerance`` * ``size`` from every joint of the
    true skeleton ``truth``: bends where the body has none (mid-shin, mid-forearm)."""
    joints, true_joints = skeleton.joints(), truth.joints()
    gaps = np.linalg.norm(joints[:, None] - true_joints[None], axis=2).min(axis=1)
    return joints[gaps > tolerance * size]


def nearest_bone(skeleton, point):
    """(index, distance) of the skeleton's bone (as a segment) nearest ``point``."""
    gaps = segment_distances(np.asarray(point, dtype=np.float64).reshape(1, 3), skeleton.heads, skeleton.tails)[0]
    return int(gaps.argmin()), float(gaps.min())


class Limb(NamedTuple):
    """A true limb (from a branch joint or the root to a leaf) and the path of the rig's bones nearest it.

    ``bones``: the true bones' names, from the top down; ``distance``: how far its points lie from the path on
    average (fraction of size); ``path``: the rig's bones from the leaf bone up to the root; ``carrying``: the bones
    of that path nearest to some point of the limb (a tie to the one nearer the leaf), from the top down (the bones
    that move it)."""

    bones: tuple
    distance: float
    path: tuple
    carrying: tuple

    def followed(self, tolerance=FOLLOWS):
        return self.distance <= tolerance


def limbs(truth, skeleton, size, step=CHAIN_STEP):
    """{name of the leaf bone: ``Limb``} for every limb of the true skeleton ``truth``: its chains from a branch
    joint, or the root, to a leaf joint (the bones leaving one root joint branch there)."""
    positions, parents, bone_of_joint = _joint_tree(truth)
    result = {}
    for chain in posing_math.leaf_chains(parents):
        if len(chain) < 2:
            continue
        points = posing_math.chain_points(positions, chain, step * size)
        distance, path = posing_math.closest_path(points, skeleton.heads, skeleton.tails, skeleton.parents)
        nearest = segment_distances(points, skeleton.heads[path], skeleton.tails[path]).argmin(axis=1)
        carrying = tuple(path[k] for k in sorted(set(nearest.tolist()), reverse=True))
        names = tuple(truth.names[bone_of_joint[joint]] for joint in chain[1:])
        result[names[-1]] = Limb(names, distance / size, tuple(path), carrying)
    return result


def limb_recall(truth, skeleton, size, tolerance=FOLLOWS):
    """The share of the true limbs (:func:`limbs`) a path of the rig's bones follows within ``tolerance``."""
    found = limbs(truth, skeleton, size)
    return float(np.mean([limb.followed(tolerance) for limb in found.values()]))


def _joint_tree(skeleton):
    """The skeleton as a tree of joints: (positions (J, 3), parents (J,), bone ending at each joint (-1 for a root
    joint)). Root bones that start at one point share its joint."""
    positions, parents, bone_of_joint = [], [], []
    tail_joint, root_joint = {}, {}
    for bone in posing_math.topological_order(skeleton.parents):
        parent = int(skeleton.parents[bone])
        if parent >= 0:
            head = tail_joint[parent]
        else:
            key = tuple(skeleton.heads[bone])
            if key not in root_joint:
                root_joint[key] = len(positions)
                positions.append(skeleton.heads[bone])
                parents.append(-1)
                bone_of_joint.append(-1)
            head = root_joint[key]
        tail_joint[bone] = len(positions)
        positions.append(skeleton.tails[bone])
        parents.append(head)
        bone_of_joint.append(int(bone))
    return np.array(positions), np.array(parents), bone_of_joint
