"""Which way a character faces, from its skeleton's roles: its front and its left across the body plan's up, and
whether the skeleton's ``.L`` bones lie on its left. Bone names follow Blender's convention, ``.L`` on +X (the left of a
character facing -Y); a character facing +Y has them on its right, and names that mean the character's own side
(Rigify's, Mixamo's) must swap them."""
from dataclasses import dataclass

import numpy as np

from .tuning import TuningTable, tuned

TORSO = ("hips", "spine", "chest")
CLEAR_FEET = 0.5  # feet within 60 degrees of the front line say which way it faces
LIMBS = ("upper_arm", "forearm", "hand", "thigh", "shin", "foot")


@dataclass(frozen=True)
class FootTuning(TuningTable):
    """The tuned numbers of finding a foot the skeleton lacks (``foot_ahead``), in the foot's expected lengths."""

    ahead: float = tuned(2.0, "the foot is looked for among the vertices below the ankle up to this far ahead ...")
    beside: float = tuned(0.5, "... and this far beside it; ...")
    least: float = tuned(0.25, "... none when they reach less than this far ahead (a leg ending on a stump)")
    gap: float = tuned(0.8, "the foot is one piece from the ankle on: it ends where the mesh's vertices ahead have "
                            "a gap this long (another leg's foot lies beyond; a box foot's are 0.7 apart) ...")
    instep: float = tuned(0.5, "... counting those up to this high above the ankle (a foot's top, before its toes "
                               "reach below the ankle)")
    ball_at: float = tuned(0.7, "the foot's ball lies this share of the way from the ankle to the tip")


@dataclass(frozen=True, eq=False)
class Facing:
    """Unit vectors ``up``, ``front`` and ``left`` (= up x front) of a character, the middle of its torso
    (``centre``), and ``swapped``: its skeleton's ``.L`` bones lie on its right."""

    up: np.ndarray
    front: np.ndarray
    left: np.ndarray
    centre: np.ndarray
    swapped: bool

    def side(self, side):
        """The character's own side ("L", "R" or None) of a skeleton side."""
        return {"L": "R", "R": "L"}.get(side) if self.swapped else side


def facing(skeleton, points=None, head_node=None, tail_node=None):
    """The :class:`Facing` of ``skeleton`` (with roles and a body plan). ``points`` and each bone's ``head_node`` and
    ``tail_node`` in them may give its joints with nearby bone ends merged (default: the bones' own ends).

    The front: for an animal, from the torso's middle to its head (else its neck, else from its tail to the torso's
    middle, else from its hips to its chest); for a humanoid, across the line from its ``.R`` limbs to its ``.L`` ones,
    the way its feet point (its foot bones', else its mesh's: ``BodyPlan.front``; else the front of a figure whose
    ``.L`` side is its left, Blender's convention), else where its feet point; else Blender's -Y."""
    count = len(skeleton)
    if points is None:
        points = np.concatenate([skeleton.heads, skeleton.tails])
        head_node, tail_node = np.arange(count), np.arange(count, 2 * count)
    reading = _Reading(skeleton, np.asarray(points, dtype=np.float64), np.asarray(head_node), np.asarray(tail_node))
    front = reading.front()
    left = np.cross(reading.up, front)
    left /= np.linalg.norm(left)
    front = np.cross(left, reading.up)
    named = [bone for bone, role in enumerate(skeleton.roles) if role.side == "L"]
    swapped = bool(named) and (reading.middle(named) - reading.centre) @ left < 0
    return Facing(reading.up, front, left, reading.centre, swapped)


class _Reading:
    """The skeleton's bones by role and side, its up and its torso's middle, for :func:`facing`."""

    def __init__(self, skeleton, points, head_node, tail_node):
        self.skeleton, self.roles = skeleton, skeleton.roles
        self.points, self.head_node, self.tail_node = points, head_node, tail_node
        self.up = np.asarray(skeleton.body_plan.up, dtype=np.float64)
        self.up /= np.linalg.norm(self.up)
        torso = self.bones_of(TORSO, None) or list(range(len(skeleton)))
        self.centre = points[np.concatenate([head_node[torso], tail_node[torso]])].mean(axis=0)

    def bones_of(self, roles, side):
        return role_bones(self.roles, roles, side)

    def middle(self, bones):
        return bones_middle(self.skeleton, bones)

    def front(self):
        """The character's front across up (the rules in :func:`facing`'s docstring)."""
        candidates = []
        if self.skeleton.body_plan.kind != "humanoid":
            for ahead, behind in ((("head",), None), (("neck",), None), (None, ("tail",)), (("chest",), ("hips",))):
                front_bones, back_bones = (self.bones_of(roles, None) if roles else None for roles in (ahead, behind))
                if front_bones != [] and back_bones != []:
                    candidates.append((self.middle(front_bones) if front_bones else self.centre) -
                                      (self.middle(back_bones) if back_bones else self.centre))
        front = self.skeleton.body_plan.front  # the way the mesh's feet point, when the skeleton's do not show it
        feet = self._feet() or ([np.asarray(front, dtype=np.float64)] if front is not None else [])
        lefts, rights = (self.bones_of(LIMBS, side) for side in ("L", "R"))
        if lefts and rights:
            across = self._across(np.cross(self.middle(lefts) - self.middle(rights), self.up))
            if across is not None:  # feet pointing nearly sideways say nothing (a boot round about its ankle)
                clear = feet and abs(feet[0] @ across) >= CLEAR_FEET * np.linalg.norm(feet[0])
                candidates.append(-across if clear and feet[0] @ across < 0 else across)
        for direction in candidates + feet + [np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])]:
            across = self._across(direction)
            if across is not None:
                return across
        raise ValueError("cannot tell the character's front")  # unreachable: -Y and +Z are never both along up

    def _across(self, direction):
        """``direction`` across up, as a unit vector (None when it runs along up)."""
        across = direction - (direction @ self.up) * self.up
        norm = np.linalg.norm(across)
        return across / norm if norm > 1e-6 * np.linalg.norm(direction) else None

    def _feet(self):
        """From each ankle to its toe tip, of the legs that have feet."""
        directions = []
        for side in ("L", "R"):
            feet, legs = self.bones_of(("foot", "toe"), side), self.bones_of(("shin", "thigh"), side)
            if feet and legs:
                ends = self.points[np.unique(np.concatenate([self.head_node[feet], self.tail_node[feet]]))]
                leg_ends = self.points[np.concatenate([self.head_node[legs], self.tail_node[legs]])]
                ankle = ends[np.argmin([np.linalg.norm(leg_ends - end, axis=1).min() for end in ends])]
                directions.append(ends[np.argmax(np.linalg.norm(ends - ankle, axis=1))] - ankle)
        return [np.sum(directions, axis=0)] if directions else []


def toes_way(vertices, ankles, up, reach):
    """The way a standing figure's feet point, from its mesh: over its ``ankles``, the mean offset across ``up`` of
    the ``vertices`` within ``reach`` of each across up and no higher than half that above it (a foot runs farther
    ahead of its ankle than its heel behind; the shin above stands over it), summed; None when no vertex lies
    there."""
    vertices, total = np.asarray(vertices, dtype=np.float64), np.zeros(3)
    for ankle in ankles:
        offsets = vertices - ankle
        height = offsets @ up
        across = offsets - height[:, None] * up
        near = (height < 0.5 * reach) & (np.linalg.norm(across, axis=1) <= reach)
        if near.any():
            total += across[near].mean(axis=0)
    return total if np.linalg.norm(total) > 0 else None


def role_bones(bone_roles, roles, side, digit=None):
    """The bones (of a skeleton whose bones have ``bone_roles``) whose role is in ``roles``, of skeleton side
    ``side`` (and finger ``digit``)."""
    return [bone for bone, role in enumerate(bone_roles) if role.role in roles and role.side == side
            and (digit is None or role.digit == digit)]


def bones_middle(skeleton, bones):
    """The mean of the midpoints of ``skeleton``'s ``bones``."""
    return 0.5 * (skeleton.heads[bones] + skeleton.tails[bones]).mean(axis=0)


def foot_ahead(vertices, ankle, faced, length, tuning=FootTuning()):
    """(ball, tip) of a foot the skeleton lacks, from the mesh's ``vertices`` below the ``ankle`` and ahead of it (the
    :class:`Facing` ``faced``; within ``ahead`` and ``beside`` of the foot's expected ``length``), from the ankle on
    up to the first ``gap`` between the vertices there (up to ``instep`` above it): the tip where they reach farthest
    ahead, on their lowest level, the ball ``ball_at`` of the way there; a leg ending at the ankle has its foot run
    forward along the ground, not on down the shin. None when they reach less than ``least`` ahead."""
    offsets = np.asarray(vertices, dtype=np.float64) - ankle
    across, ahead, height = offsets @ faced.left, offsets @ faced.front, offsets @ faced.up
    near = (ahead >= 0) & (ahead <= tuning.ahead * length) & (np.abs(across) <= tuning.beside * length)
    order = np.sort(ahead[near & (height < tuning.instep * length)])
    breaks = np.flatnonzero(np.diff(np.r_[0.0, order]) > tuning.gap * length)
    near &= (height < 0) & (ahead < (order[breaks[0]] if len(breaks) else np.inf))
    if not near.any() or ahead[near].max() < tuning.least * length:
        return None
    reach, ground = float(ahead[near].max()), float(height[near].min())
    return np.vstack([ankle + tuning.ball_at * reach * faced.front + ground * faced.up,
                      ankle + reach * faced.front + ground * faced.up])
