"""The project's own sample characters as data: a known skeleton with a skin radius at every joint.

Rigger ships no third-party models; its tests and demo build these characters around their skeletons (the Blender layer
wraps them in a Skin modifier), so the true skeleton of every test mesh is known exactly. Conventions: Blender's Z up,
the character faces -Y, its left side is +X (``.L``), sizes in metres.

A character is a tree of joints. Each joint except the root names the bone that ends at it: the bone runs from the
parent joint (head) to this joint (tail). ``.L`` joints are written once and mirrored to ``.R`` across X = 0, except
on the characters of ``NEAR_SYMMETRIC``, whose right side differs on purpose. A ``skin_only`` point shapes the body
between joints (a calf's bulge, a knee's narrowing) and is no joint: the bone runs through it.
"""
import math
from typing import NamedTuple

import numpy as np

from .core.skeleton import Skeleton


class Joint(NamedTuple):
    """A skeleton node: the bone ending here (``name``), its parent joint, where it is and how thick the body is.
    A ``skin_only`` point is a node of the skin, not of the skeleton: the bone of its first descendant joint runs
    from its nearest joint ancestor, through (or past) it."""

    name: str
    parent: str | None
    position: tuple[float, float, float]
    radius: float
    skin_only: bool = False


def _right(name):
    return name[:-2] + ".R" if name is not None and name.endswith(".L") else name


def _mirrored(joints):
    """The joints followed by a ``.R`` copy of every ``.L`` joint, reflected across X = 0."""
    copies = [joint._replace(name=_right(joint.name), parent=_right(joint.parent),
                             position=(-joint.position[0], *joint.position[1:]))
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


def _along(start, end, share, offset=(0.0, 0.0, 0.0)):
    """The point ``share`` of the way from ``start`` to ``end``, moved by ``offset``."""
    return tuple(float(a + share * (b - a) + o) for a, b, o in zip(start, end, offset))


def _rotation(axis, degrees):
    """The 3x3 matrix turning by ``degrees`` about ``axis`` (right-handed)."""
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    angle = math.radians(degrees)
    return np.eye(3) + math.sin(angle) * cross + (1.0 - math.cos(angle)) * cross @ cross


def _turned(joints, about, axis, degrees, scale=1.0, thicker=1.0):
    """``joints`` with every descendant of joint ``about`` turned by ``degrees`` about ``axis`` through it, its
    distance from it times ``scale`` and its radius times ``thicker``: a limb posed, grown or thickened."""
    below, moved = {about}, []
    centre = np.array(next(joint.position for joint in joints if joint.name == about))
    turn = _rotation(axis, degrees)
    for joint in joints:  # parents come before their children
        if joint.parent in below:
            below.add(joint.name)
            place = centre + scale * turn @ (np.array(joint.position) - centre)
            joint = joint._replace(position=tuple(float(c) for c in place), radius=joint.radius * thicker)
        moved.append(joint)
    return tuple(moved)


def _moved(joints, offsets):
    """``joints`` with those named in ``offsets`` moved by their offset (metres)."""
    return tuple(joint._replace(position=tuple(float(p + o) for p, o in zip(joint.position, offsets[joint.name])))
                 if joint.name in offsets else joint for joint in joints)


def _human_trunk(nose=False):
    """Hips, spine, neck and head of a 1.8 m human (the ``humanoid``'s); ``nose``: the face has one."""
    joints = [
        Joint("root", None, (0.0, 0.0, 1.00), 0.135),
        Joint("spine", "root", (0.0, 0.01, 1.20), 0.125),
        Joint("chest", "spine", (0.0, 0.0, 1.38), 0.145),
        Joint("neck", "chest", (0.0, 0.0, 1.55), 0.055),
        Joint("head", "neck", (0.0, -0.01, 1.66), 0.10),
        Joint("head_top", "head", (0.0, -0.01, 1.73), 0.075),
    ]
    if nose:  # a nose sticking 3 cm out of the face, below the eyes' height
        joints.append(Joint("nose", "head", (0.0, -0.122, 1.635), 0.02))
    return joints


def _a_pose_arm(shaped=False, fingers=False):
    """A left arm hanging 45 degrees out from the body, the wrist a little forward, with a mitten hand or, palm
    forward, three finger stubs spread and a thumb pointing out, all in the front view's plane.
    ``shaped``: biceps and forearm bulge, the elbow narrows between them."""
    shoulder, elbow, wrist = (0.20, 0.0, 1.40), (0.398, 0.0, 1.202), (0.582, -0.03, 1.018)
    radius = (0.06, 0.036, 0.03) if shaped else (0.06, 0.045, 0.035)
    joints = [Joint("shoulder.L", "chest", shoulder, radius[0])]
    if shaped:
        joints.append(Joint("biceps.L", "shoulder.L", _along(shoulder, elbow, 0.45, (0.0, 0.005, 0.0)), 0.05, True))
    joints.append(Joint("upper_arm.L", joints[-1].name, elbow, radius[1]))
    if shaped:
        joints.append(Joint("forearm_bulge.L", "upper_arm.L", _along(elbow, wrist, 0.3), 0.042, True))
    joints.append(Joint("forearm.L", joints[-1].name, wrist, radius[2]))
    along = np.subtract(wrist, elbow) / np.linalg.norm(np.subtract(wrist, elbow))
    across = np.cross(along, (0.0, 1.0, 0.0))  # up and out, square to the forearm in the front view
    knuckles = np.add(wrist, 0.085 * along)
    joints.append(Joint("hand.L", "forearm.L", tuple(float(c) for c in knuckles), 0.038))
    if fingers:  # (the Skin modifier's hull tears where more or closer fingers leave one point)
        for number, offset in enumerate((-0.045, 0.0, 0.045), start=1):
            tip = knuckles + 0.09 * along + offset * across
            joints.append(Joint(f"finger{number}.L", "hand.L", tuple(float(c) for c in tip), 0.011))
        thumb = np.add(wrist, 0.05 * along) + 0.055 * across
        joints.append(Joint("thumb.L", "forearm.L", tuple(float(c) for c in thumb), 0.013))
    return joints


def _human_leg(shaped=False, bend=0.0):
    """A left leg standing, its knee ``bend`` metres forward. ``shaped``: thigh and calf bulge, the knee narrows
    between them."""
    hip, knee, ankle = (0.10, 0.0, 0.93), (0.11, -0.01 - bend, 0.52), (0.11, 0.02, 0.10)
    radius = (0.045, 0.035) if shaped else (0.06, 0.045)
    joints = [Joint("pelvis.L", "root", hip, 0.09)]
    if shaped:
        joints.append(Joint("thigh_bulge.L", "pelvis.L", _along(hip, knee, 0.4, (0.0, -0.01, 0.0)), 0.085, True))
    joints.append(Joint("thigh.L", joints[-1].name, knee, radius[0]))
    if shaped:
        joints.append(Joint("calf.L", "thigh.L", _along(knee, ankle, 0.33, (0.0, 0.018, 0.0)), 0.062, True))
    joints.append(Joint("shin.L", joints[-1].name, ankle, radius[1]))
    joints.append(Joint("foot.L", "shin.L", (0.11, -0.11, 0.045), 0.04))
    return joints


def _humanoid(wrist, hand_tip):
    """A 1.8 m human, upper arms raised halfway; ``wrist`` and ``hand_tip`` place the left forearm and hand."""
    return _mirrored([
        *_human_trunk(),
        Joint("shoulder.L", "chest", (0.17, 0.0, 1.44), 0.06),
        Joint("upper_arm.L", "shoulder.L", (0.42, 0.02, 1.28), 0.045),
        Joint("forearm.L", "upper_arm.L", wrist, 0.035),
        Joint("hand.L", "forearm.L", hand_tip, 0.04),
        *_human_leg(),
    ])


def _handmade():
    """The arms-out ``humanoid`` as a hand-made model is: nearly, not exactly, mirror-symmetric. The right arm is 3%
    longer, 6% thicker and raised 7 degrees more, the right shoulder 1.5 cm lower; the left forearm bends 10 degrees
    forward; the right leg steps 5 degrees forward, the left one is 2% shorter; the head leans 1.2 cm to the left."""
    joints = _humanoid(wrist=(0.66, -0.02, 1.13), hand_tip=(0.78, -0.03, 1.06))
    joints = _moved(joints, {"shoulder.R": (0.0, 0.0, -0.015), "head": (0.012, 0.0, 0.0),
                             "head_top": (0.012, 0.0, 0.0)})
    joints = _turned(joints, "shoulder.R", (0.0, 1.0, 0.0), 7.0, scale=1.03, thicker=1.06)
    joints = _turned(joints, "upper_arm.L", (0.0, 0.0, 1.0), -10.0)
    joints = _turned(joints, "pelvis.R", (1.0, 0.0, 0.0), -5.0)
    return _turned(joints, "pelvis.L", (1.0, 0.0, 0.0), 0.0, scale=0.98)


def _four_arms():
    """A stocky 1.7 m four-armed creature with a bird's beak (like ``rignet_17364``): two arms a side held out, the
    upper pair higher and behind, the lower pair in front, touching along the upper arms seen from the front; a
    short neck between broad shoulders."""
    joints = [
        Joint("root", None, (0.0, 0.0, 0.95), 0.16),
        Joint("spine", "root", (0.0, 0.01, 1.12), 0.17),
        Joint("chest", "spine", (0.0, 0.0, 1.32), 0.18),
        Joint("neck", "chest", (0.0, 0.0, 1.52), 0.09),
        Joint("head", "neck", (0.0, -0.02, 1.61), 0.10),
        Joint("head_top", "head", (0.0, -0.02, 1.68), 0.07),
        Joint("beak", "head", (0.0, -0.235, 1.59), 0.025),
    ]
    for pair, (height, depth, radius) in enumerate(((1.40, 0.04, 0.05), (1.32, -0.04, 0.0475)), start=1):
        joints += [
            Joint(f"shoulder{pair}.L", "chest", (0.16, depth, height), 0.07),
            Joint(f"upper_arm{pair}.L", f"shoulder{pair}.L", (0.445, depth, height), radius),
            Joint(f"forearm{pair}.L", f"upper_arm{pair}.L", (0.70, depth, height), radius * 0.75),
            Joint(f"hand{pair}.L", f"forearm{pair}.L", (0.805, depth, height), radius * 0.8),
        ]
    joints += [
        Joint("pelvis.L", "root", (0.10, 0.0, 0.90), 0.10),
        Joint("thigh.L", "pelvis.L", (0.12, -0.01, 0.50), 0.075),
        Joint("shin.L", "thigh.L", (0.12, 0.02, 0.10), 0.055),
        Joint("foot.L", "shin.L", (0.12, -0.12, 0.05), 0.045),
    ]
    return _mirrored(joints)


def _bear():
    """A brown bear on all fours, 1.8 m long: a heavy body, short legs about as long as they are thick, a short
    tail, a head with round ears, a snout and its lower jaw a little open."""
    joints = [
        Joint("root", None, (0.0, 0.42, 0.64), 0.29),
        *_chain("spine", "root", [(0.0, 0.05, 0.68), (0.0, -0.28, 0.70)], [0.33, 0.31]),
        Joint("neck", "spine_02", (0.0, -0.52, 0.76), 0.19),
        Joint("head", "neck", (0.0, -0.68, 0.80), 0.16),
        Joint("snout", "head", (0.0, -0.90, 0.77), 0.075),
        Joint("jaw", "head", (0.0, -0.83, 0.62), 0.055),
        Joint("ear.L", "head", (0.13, -0.65, 1.01), 0.06),
        Joint("tail", "root", (0.0, 0.80, 0.70), 0.06),
    ]
    for name, parent, top, ankle, toe in (
            ("front", "spine_02", (0.19, -0.30, 0.50), (0.20, -0.34, 0.11), (0.20, -0.45, 0.07)),
            ("back", "root", (0.19, 0.46, 0.50), (0.20, 0.46, 0.11), (0.20, 0.35, 0.07))):
        joints += [
            Joint(f"{name}_top.L", parent, top, 0.14),  # the shoulder or hip joint, inside the body
            Joint(f"{name}_leg.L", f"{name}_top.L", ankle, 0.105),
            Joint(f"{name}_paw.L", f"{name}_leg.L", toe, 0.07),
        ]
    return _mirrored(joints)


CHARACTERS = {
    "humanoid": _humanoid(wrist=(0.66, -0.02, 1.13), hand_tip=(0.78, -0.03, 1.06)),  # arms held out from the body
    "humanoid_hips": _humanoid(wrist=(0.23, 0.0, 1.02), hand_tip=(0.16, -0.04, 0.96)),  # hands on hips
    "quadruped": _quadruped(),
    "octopus": _octopus(),
    "tree": _tree(),
    "snake": _snake(),
    # characters for issue 28's posing defects (tests/rig_checks.py measures rigs against them)
    "humanoid_a_pose": _mirrored([*_human_trunk(), *_a_pose_arm(fingers=True), *_human_leg()]),  # twins, wrists
    "humanoid_handmade": _handmade(),  # sides named without an exact mirror plane
    "head_with_nose": (*_humanoid(wrist=(0.66, -0.02, 1.13), hand_tip=(0.78, -0.03, 1.06)),  # one chain per head
                       *_human_trunk(nose=True)[-1:]),
    "bear": _bear(),  # stubby legs, ears and jaw that are limbs
    "humanoid_knees": _mirrored([*_human_trunk(), *_a_pose_arm(shaped=True),  # joints at the knee and elbow
                                 *_human_leg(shaped=True, bend=0.015)]),
    "four_arms": _four_arms(),  # parents: the head hangs from the trunk, each arm its own chain
}
NEAR_SYMMETRIC = frozenset({"humanoid_handmade"})  # .L and .R joints that differ on purpose: no exact mirror


def character_joints(name):
    """The joints of sample character ``name``, parents before their children."""
    if name not in CHARACTERS:
        raise ValueError(f"unknown sample character {name!r}; choose one of {', '.join(CHARACTERS)}")
    return CHARACTERS[name]


def ground_truth_bones(name):
    """The true skeleton of sample character ``name``: a ``Skeleton`` with one bone per non-root joint (``skin_only``
    points are no joints).

    Each bone runs from its joint's parent (its nearest ancestor that is a joint) to the joint. Bones leaving the root
    joint are roots (parent -1): the humanoid's spine and both pelvis bones, for example.
    """
    joints = character_joints(name)
    by_name = {joint.name: joint for joint in joints}

    def joint_parent(joint):
        parent = joint.parent
        while parent is not None and by_name[parent].skin_only:
            parent = by_name[parent].parent
        return parent

    bones = [(joint, joint_parent(joint)) for joint in joints if joint.parent is not None and not joint.skin_only]
    bone_index = {joint.name: index for index, (joint, _) in enumerate(bones)}
    return Skeleton(
        names=[joint.name for joint, _ in bones],
        heads=[by_name[parent].position for _, parent in bones],
        tails=[joint.position for joint, _ in bones],
        parents=np.array([bone_index.get(parent, -1) for _, parent in bones], dtype=np.int32),
    )
