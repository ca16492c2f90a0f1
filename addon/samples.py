"""The project's own sample characters as data: a known skeleton with a skin radius at every joint.

Rigger ships no third-party models; its tests and demo build these characters around their skeletons (the Blender layer
wraps them in a Skin modifier), so the true skeleton of every test mesh is known exactly. Conventions: Blender's Z up,
the character faces -Y, its left side is +X (``.L``), sizes in metres.

A character is a tree of joints. Each joint except the root names the bone that ends at it: the bone runs from the
parent joint (head) to this joint (tail). ``.L`` joints are written once and mirrored to ``.R`` across X = 0.
"""
import math
from typing import NamedTuple

import numpy as np

from .core.skeleton import Skeleton


class Joint(NamedTuple):
    """A skeleton node: the bone ending here (``name``), its parent joint, where it is and how thick the body is."""

    name: str
    parent: str | None
    position: tuple[float, float, float]
    radius: float


def _mirrored(joints):
    """The joints followed by a ``.R`` copy of every ``.L`` joint, reflected across X = 0."""
    def right(name):
        return name[:-2] + ".R" if name is not None and name.endswith(".L") else name

    copies = [Joint(right(joint.name), right(joint.parent), (-joint.position[0], *joint.position[1:]), joint.radius)
              for joint in joints if joint.name.endswith(".L")]
    return tuple(joints) + tuple(copies)


def _chain(prefix, parent, points, radii):
    """Joints ``prefix_01``, ``prefix_02``... along ``points``, each the child of the one before (a tail, a limb)."""
    suffix = ""
    if prefix.endswith((".L", ".R")):
        prefix, suffix = prefix[:-2], prefix[-2:]
    joints = []
    for index, (point, radius) in enumerate(zip(points, radii), start=1):
        name = f"{prefix}_{index:02d}{suffix}"
        joints.append(Joint(name, parent, tuple(float(c) for c in point), float(radius)))
        parent = name
    return joints


def _humanoid(wrist, hand_tip):
    """A 1.8 m human, upper arms raised halfway; ``wrist`` and ``hand_tip`` place the left forearm and hand."""
    return _mirrored([
        Joint("root", None, (0.0, 0.0, 1.00), 0.135),
        Joint("spine", "root", (0.0, 0.01, 1.20), 0.125),
        Joint("chest", "spine", (0.0, 0.0, 1.38), 0.145),
        Joint("neck", "chest", (0.0, 0.0, 1.55), 0.055),
        Joint("head", "neck", (0.0, -0.01, 1.66), 0.10),
        Joint("head_top", "head", (0.0, -0.01, 1.73), 0.075),
        Joint("shoulder.L", "chest", (0.17, 0.0, 1.44), 0.06),
        Joint("upper_arm.L", "shoulder.L", (0.42, 0.02, 1.28), 0.045),
        Joint("forearm.L", "upper_arm.L", wrist, 0.035),
        Joint("hand.L", "forearm.L", hand_tip, 0.04),
        Joint("pelvis.L", "root", (0.10, 0.0, 0.93), 0.09),
        Joint("thigh.L", "pelvis.L", (0.11, -0.01, 0.52), 0.06),
        Joint("shin.L", "thigh.L", (0.11, 0.02, 0.10), 0.045),
        Joint("foot.L", "shin.L", (0.11, -0.11, 0.045), 0.04),
    ])


def _quadruped():
    """A dog-sized animal: its legs pair up left/right, so they overlap exactly in a side view."""
    spine = _chain("spine", "root", [(0.0, 0.05, 0.62), (0.0, -0.25, 0.63)], [0.15, 0.16])
    neck = [
        Joint("neck", "spine_02", (0.0, -0.42, 0.80), 0.08),
        Joint("head", "neck", (0.0, -0.52, 0.86), 0.10),
        Joint("snout", "head", (0.0, -0.68, 0.80), 0.05),
    ]
    tail = _chain("tail", "root", [(0.0, 0.55, 0.66), (0.0, 0.72, 0.74), (0.0, 0.86, 0.78)], [0.05, 0.035, 0.025])
    front = [
        Joint("shoulder.L", "spine_02", (0.12, -0.26, 0.55), 0.07),
        Joint("upper_arm.L", "shoulder.L", (0.12, -0.24, 0.33), 0.05),
        Joint("forearm.L", "upper_arm.L", (0.12, -0.27, 0.10), 0.04),
        Joint("front_paw.L", "forearm.L", (0.12, -0.33, 0.04), 0.035),
    ]
    back = [
        Joint("hip.L", "root", (0.12, 0.36, 0.55), 0.08),
        Joint("thigh.L", "hip.L", (0.12, 0.28, 0.35), 0.055),
        Joint("shin.L", "thigh.L", (0.12, 0.38, 0.14), 0.04),
        Joint("back_paw.L", "shin.L", (0.12, 0.33, 0.04), 0.035),
    ]
    return _mirrored([Joint("root", None, (0.0, 0.35, 0.62), 0.14), *spine, *neck, *tail, *front, *back])


def _octopus():
    """A mantle over eight legs that reach out and down, then curl up and sideways at their tips."""
    joints = [
        Joint("root", None, (0.0, 0.0, 0.45), 0.22),
        Joint("mantle", "root", (0.0, 0.06, 0.72), 0.20),
        Joint("mantle_top", "mantle", (0.0, 0.10, 0.88), 0.12),
    ]
    curl = np.linspace(0.0, 1.0, 6)
    reach = 0.22 + 0.62 * np.sin(curl * 2.2) / math.sin(2.2)  # out to 0.84 m, then back in as the tip curls up
    height = 0.34 - 0.30 * np.sin(curl * math.pi * 0.9)  # down towards the ground, then up again
    sweep = 0.35 * curl ** 2  # radians turned sideways, growing towards the tip
    radii = 0.07 - 0.05 * curl
    for leg, angle in enumerate((math.radians(22.5), math.radians(67.5), math.radians(-22.5), math.radians(-67.5)), 1):
        points = [(r * math.cos(angle + s), r * math.sin(angle + s), z) for r, z, s in zip(reach, height, sweep)]
        joints += _chain(f"leg{leg}.L", "root", points, radii)
    return _mirrored(joints)


def _tree():
    """A trunk that forks into boughs, each carrying twigs: branching in all three dimensions, no symmetry."""
    joints = [Joint("root", None, (0.0, 0.0, 0.14), 0.13)]
    joints += _chain("trunk", "root", [(0.0, 0.0, 0.50), (0.02, 0.01, 0.90), (0.03, 0.03, 1.30), (0.02, 0.04, 1.70)],
                     [0.12, 0.10, 0.085, 0.075])
    joints += _chain("bough_a", "trunk_03", [(0.33, 0.12, 1.45), (0.62, 0.10, 1.75)], [0.055, 0.035])
    joints += _chain("twig_a", "bough_a_01", [(0.45, -0.20, 1.68)], [0.025])
    joints += _chain("bough_b", "trunk_02", [(-0.25, -0.22, 1.15), (-0.50, -0.45, 1.40)], [0.055, 0.035])
    joints += _chain("bough_c", "trunk_04", [(-0.15, 0.22, 2.05), (-0.25, 0.40, 2.35)], [0.05, 0.03])
    joints += _chain("bough_d", "trunk_04", [(0.20, 0.08, 2.05), (0.35, 0.02, 2.40)], [0.05, 0.03])
    joints += _chain("twig_d", "bough_d_01", [(0.48, 0.28, 2.18)], [0.022])
    return tuple(joints)


def _snake():
    """A snake about 3.5 m long in an S-curve on the ground, its head raised at the -Y end; the root behind the head."""
    t = np.linspace(0.0, 1.0, 15)
    body = np.column_stack([0.30 * np.sin(t * 3.0 * math.pi), -0.9 + 2.4 * t, 0.055 - 0.04 * t])
    radii = 0.055 - 0.04 * t
    return tuple([
        Joint("root", None, (-0.05, -1.05, 0.10), 0.055),
        Joint("head", "root", (-0.10, -1.18, 0.22), 0.05),
        Joint("head_tip", "head", (-0.12, -1.30, 0.22), 0.035),
        *_chain("spine", "root", body, radii),
    ])


CHARACTERS = {
    "humanoid": _humanoid(wrist=(0.66, -0.02, 1.13), hand_tip=(0.78, -0.03, 1.06)),  # arms held out from the body
    "humanoid_hips": _humanoid(wrist=(0.23, 0.0, 1.02), hand_tip=(0.16, -0.04, 0.96)),  # hands on hips
    "quadruped": _quadruped(),
    "octopus": _octopus(),
    "tree": _tree(),
    "snake": _snake(),
}


def character_joints(name):
    """The joints of sample character ``name``, parents before their children."""
    if name not in CHARACTERS:
        raise ValueError(f"unknown sample character {name!r}; choose one of {', '.join(CHARACTERS)}")
    return CHARACTERS[name]


def ground_truth_bones(name):
    """The true skeleton of sample character ``name``: a ``Skeleton`` with one bone per non-root joint.

    Each bone runs from its joint's parent to the joint. Bones leaving the root joint are roots (parent -1): the
    humanoid's spine and both pelvis bones, for example.
    """
    joints = character_joints(name)
    bones = [joint for joint in joints if joint.parent is not None]
    bone_index = {joint.name: index for index, joint in enumerate(bones)}
    position = {joint.name: joint.position for joint in joints}
    return Skeleton(
        names=[joint.name for joint in bones],
        heads=[position[joint.parent] for joint in bones],
        tails=[joint.position for joint in bones],
        parents=np.array([bone_index.get(joint.parent, -1) for joint in bones], dtype=np.int32),
    )
