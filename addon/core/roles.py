"""Bone roles: what each bone of a skeleton is in its body plan (a thigh, the second spine bone, the left index finger's
first bone), given the plan's layout of the body (``core.bodyplan``). Bones keep their names; roles sit beside them.

Along the spine, from the tail end to the head end: tail (or root, a bone rising from the ground to the hips), hips,
spine, chest up to where the arms, wings or front legs hang (a humanoid's arms hanging where its legs do: one bone),
then neck up to the spine's thinnest joint above them (a quadruped's: or a sharp turn past it, ``head_bend``) and head
beyond, its last bone at least (one bone there is the neck: it pivots where a neck does; a fish: head, spine and tail by
length). A leg: hips (its bones from the mirror plane until it leaves it and turns down; shoulder for a front leg),
thigh, shin from the joint nearest the knee's named place (below), foot from the joint nearest an ankle's height (but
never the leg's tip while its last bone runs along the ground: that is a paw), and toe (the last bone when the foot has
two or more; a quadruped's hind leg stands on its toes: its foot from the joint nearest its hock's named place, its toe
from the ankle's height); a front leg: shoulder, upper_arm, forearm, hand. An arm: shoulder up to where it leaves the
torso, then upper_arm, forearm and hand by shares of the rest of its reach where the artists' humanoids have an elbow
and a wrist (a bend near the elbow's share wins); each branch beyond the hand is a finger, the one that leaves earliest
and points most away the thumb, the others index, middle, ring and pinky in order across the hand. Twins are cut at the
same joints (on their mirror-averaged points). A wing: shoulder up to where it leaves the body, as an arm's, then wing.
Fins, ears, tails and jaws take their part's role for every bone. A body plan that is ``other`` gives every bone the
role ``other``. Sides: ``.L`` / ``.R`` bone names when a limb's bones have them, else the side of the mirror plane, left
being the character's left when its front is known (Blender's +X for a character facing -Y).

Roles are whole bones; named joints are points (:func:`named_joints`: where each role begins, ``{(role, side,
digit): point}``), placed along the chains where the artists' rigs have them rather than at the nearest bone end
(:func:`joint_places`, at recognition, stored in ``BodyPlan.joints``): on a leg the ankle where it comes down to
``ankle_height``, the hip joint at ``hip_rise`` of the height from there to where the leg hangs (on the thigh's line
when the thigh stands upright; a front leg's shoulder joint no higher than where its upper arm's bones begin; a
humanoid's no higher above its crotch than the leg lies off the mirror plane there), the knee ``knee_at`` of the way
between (a bend there, below where the thigh's bones begin, winning) and the ball of the foot ``toe_at`` of the way
to the toes' tip (a quadruped's hind leg, on its toes: the ankle is its hock, at ``hock_at`` of that hip joint's
height, a bend there winning; the knee ``knee_at`` of the way down to it; the ball where it comes down to
``ankle_height``; then the hip joint where the thigh's bones begin, atop the rump); on an arm the shoulder joint
where the arm leaves the torso, the elbow and wrist at ``elbow_at`` and ``wrist_at`` of the way from there to the end
of the hand (the mesh beyond the last joint included; a bend winning for the elbow), the collarbone's start
``clavicle_at`` of the way in; on an upright humanoid's spine the hips, spine, chest and neck at ``hips_at`` ...
``neck_at`` of the height from the hip joints to the shoulder joints. :func:`landmarks` gives the ends no role
begins at, placed the same way: head top, hand and toe tips, finger tips, heels. A place is a weighted sum of points
on bones, so named joints and landmarks follow the skeleton when it is moved (``Skeleton.transformed``).
"""
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from .polyline import arc_lengths, segment_distances
from .stages import Labels, Stage
from .tuning import TuningTable, tuned

ROLES = ("root", "hips", "spine", "chest", "neck", "head", "jaw", "shoulder", "upper_arm", "forearm", "hand", "finger",
         "thigh", "shin", "foot", "toe", "tail", "ear", "wing", "fin", "other")
DIGITS = ("thumb", "index", "middle", "ring", "pinky")
LANDMARKS = ("head_top", "hand_tip", "finger_tip", "toe_tip", "heel")
SIDES = ("L", "R", None)


@dataclass(frozen=True)
class BoneRole:
    """A bone's ``role`` (one of ``ROLES``), ``side`` ("L", "R" or None), ``index`` (its place among the bones of
    that role and side along its chain, from the body outwards: spine 0, 1, 2; a finger's segments) and, for a
    finger, its ``digit`` (one of ``DIGITS``, or None when the hand shows no clear thumb)."""

    role: str
    side: str = None
    index: int = 0
    digit: str = None

    def __post_init__(self):
        if self.role not in ROLES:
            raise ValueError(f"unknown bone role {self.role!r}; roles are {', '.join(ROLES)}")
        if self.side not in SIDES:
            raise ValueError(f"a bone's side is 'L', 'R' or None, got {self.side!r}")
        if not isinstance(self.index, int) or isinstance(self.index, bool) or self.index < 0:
            raise ValueError(f"a bone role's index is a whole number >= 0, got {self.index!r}")
        if self.digit is not None and (self.role != "finger" or self.digit not in DIGITS):
            raise ValueError(f"only fingers have a digit ({', '.join(DIGITS)}), got {self.digit!r} on a "
                             f"{self.role}")

    @property
    def label(self):
        """Short text: ``thigh.L``, ``spine.2``, ``finger.index.1.R``."""
        words = [self.role] + ([self.digit] if self.digit else []) + ([str(self.index)] if self.index else [])
        return ".".join(words) + (f".{self.side}" if self.side else "")

    def to_dict(self):
        return {"role": self.role, "side": self.side, "index": self.index, "digit": self.digit}


@dataclass(frozen=True)
class RoleTuning(TuningTable):
    """The tuned numbers of giving bones their roles."""

    thigh_drop: float = tuned(0.8, "a leg's thigh starts at its first joint off the mirror plane from which it runs "
                                   "this steeply down (cosine of the angle from down); the bones before run out from "
                                   "the body: hips")
    plane_exit: float = tuned(0.01, "a leg leaves the mirror plane at its first joint this far off it (legs close "
                                    "together stand 0.035 off it)")
    ankle_height: float = tuned(0.065, "a leg's ankle is its joint nearest this height (a share of the mesh's; the "
                                       "artists' humanoids: 0.036 to 0.08, median 0.064)")
    foot_height: float = tuned(0.15, "... among its joints this low or lower")
    bend: float = tuned(25.0, "degrees: a limb joint turning this much near where an elbow or a knee belongs is one")
    bend_window: float = tuned(0.2, "a bend counts within this share of the limb's length of where the joint belongs")
    knee_at: float = tuned(0.47, "a knee's share of the way from the hip to the ankle (the artists' humanoids: 0.38 "
                                 "to 0.49, median 0.47; their animals' from the hip to the hock: 0.41 to 0.56)")
    hock_at: float = tuned(0.42, "a quadruped's hind leg stands on its toes: its ankle, the hock, at this share of the "
                               "height ``hip_rise`` gives a leg's hip joint (the artists' animals and Rigify's: 0.34 "
                               "to 0.53 of their own hip joints')")
    shoulder_thickness: float = tuned(1.3, "an arm's shoulder joint is its first joint where the mesh is at most this "
                                           "many times as thick as along the arm (the torso is thicker) ...")
    arm_from: float = tuned(0.3, "... the arm's thickness being the median at its joints from this share of its "
                                 "reach ...")
    arm_to: float = tuned(0.8, "... to this share (the upper arm and forearm, not the torso or the hand)")
    shoulder_at: float = tuned(0.22, "else the shoulder joint's share of the way from where the arm hangs to the "
                                     "end of its hand (the artists' humanoids: 0.18 to 0.31, median 0.23)")
    elbow_at: float = tuned(0.39, "an elbow's share of the way from the shoulder joint to the end of the hand (the "
                                  "artists' humanoids: 0.37 to 0.42)")
    wrist_at: float = tuned(0.73, "a wrist's share of that way (0.65 to 0.79, median 0.74)")
    head_share: float = tuned(0.25, "a fish's head: this share of its spine's length from the head end")
    tail_share: float = tuned(0.35, "a fish's tail: this share from the tail end")
    tail_length: float = tuned(0.08, "spine behind the hips this long (a share of the size) is a tail, not hips")
    hip_rise: float = tuned(0.89, "a leg's hip joint lies this share of the height from its ankle up to where the "
                                  "leg hangs from the spine")
    heel_width: float = tuned(0.03, "the heel is the hindmost point of the mesh this close to the foot's line "
                                    "(half a foot's width)")
    thigh_lean: float = tuned(30.0, "degrees: a thigh leaning at most this far from up carries the hip joint on its "
                                    "line (a standing biped's)")
    toe_at: float = tuned(0.65, "the ball of the foot: this share of the way from the ankle to the tip of the toes "
                                "(the mesh's; a human foot's ball two thirds of the way)")
    clavicle_at: float = tuned(0.25, "an arm's collarbone starts this share of the way from where the arm hangs to "
                                     "its shoulder joint (Rigify's and Mixamo's near the body's middle)")
    hips_at: float = tuned(0.25, "a humanoid's hips joint: this share of the height from its hip joints to its "
                                 "shoulder joints")
    spine_at: float = tuned(0.45, "its spine joint: this share of that height")
    chest_at: float = tuned(0.65, "its chest joint: this share")
    neck_at: float = tuned(0.85, "its neck joint: this share")
    head_below: float = tuned(0.6, "a humanoid's head begins no farther than this share of the way from the neck's "
                                   "base to the head's top (the artists' 0.24 to 0.46): above, the mesh is thin for "
                                   "the crown, not for a neck")
    head_bend: float = tuned(60.0, "degrees: a quadruped's spine turning this much at or past its neck's narrowest "
                                   "joint turns into the head there (a deer's 90, where a dog's neck runs on into "
                                   "its head)")
    spine_fall: float = tuned(0.02, "... on its spine up to where it falls this share of the height (a hunched "
                                    "figure's head hanging forward)")
    other_part: float = tuned(0.01, "a share of the size: the mesh beyond a limb's end lying more than this nearer "
                                    "another part's bone than that end is the other part's (a hip the hand rests on)")
    named_reach: float = tuned(0.75, "a target's joint moves to its named joint only within this share of its "
                                     "shortest bone (none shrinks below a quarter); farther off is another chain's")


def assign_roles(skeleton, body, layout, paths, tuning=RoleTuning()):
    """One :class:`BoneRole` per bone of ``skeleton`` (see the module docstring), from its ``body``
    (``core.body.Body``), ``layout`` (``core.bodyplan.Layout``) and its limbs' ``paths`` (:func:`twin_paths`)."""
    graph = body.graph
    segment_bone = {}
    for a, links in enumerate(graph.neighbours):
        for b, bone in links:
            if bone >= 0:
                segment_bone[(a, b)] = bone
    roles = [None] * len(skeleton)

    def put(nodes, names, side=None):
        counts = {}
        for (a, b), name in zip(zip(nodes, nodes[1:]), names):
            bone = segment_bone.get((a, b))
            if bone is None or roles[bone] is not None or name is None:
                continue
            role, digit = name if isinstance(name, tuple) else (name, None)
            key = (role, digit)
            roles[bone] = BoneRole(role, side, counts.get(key, 0), digit)
            counts[key] = counts.get(key, 0) + 1

    kind = layout.plan.kind
    left = _left_sign(body, layout)
    spine_names = _spine_roles(body, layout, tuning)
    below = [index for index, name in enumerate(spine_names) if name in ("tail", "root")]
    spine = list(layout.spine)
    if below:  # tail and root bones count from the body outwards
        cut = below[-1] + 1
        put(spine[:cut + 1][::-1], spine_names[:cut][::-1])
    put(spine, spine_names)
    for node, base in body.connectors.items():
        for other, bone in graph.neighbours[node]:
            if bone >= 0 and roles[bone] is None:
                roles[bone] = BoneRole(_connector_role(spine, spine_names, base) if kind != "other" else "other")
    for k, limb in enumerate(body.limbs):
        side = _limb_side(skeleton, graph, limb, left)
        part = layout.parts[k]
        path = paths[k]
        if part == "leg":
            _leg(body, limb, path, layout.front[k], kind, tuning, lambda nodes, names: put(nodes, names, side))
        elif part == "arm":
            _arm(body, limb, path, tuning, lambda nodes, names: put(nodes, names, side))
        elif part == "wing":  # its bones in the body are a shoulder, as an arm's: the wing turns where it leaves
            shoulder = _shoulder(path, arc_lengths(path.points), tuning)
            put(list(limb.main)[:shoulder + 1], ["shoulder"] * shoulder, side)
        for nodes in _paths(limb):
            put(nodes, [part] * (len(nodes) - 1), side)
    _mirror_twin_roles(roles, body, segment_bone)
    return _named_sides(_filled(roles, skeleton, kind), skeleton.names)


def _named_sides(roles, names):
    """``roles`` with a side wherever the bone's name has one and its role none: a chain named ``.R`` that the
    body's path runs through (one ear of a figure without a mirror plane) is on the right like its ``.L`` twin. The
    spine and chest stay the body's middle, whatever chain the spine runs along (a broken mesh's)."""
    return tuple(replace(role, side=name[-1]) if role.side is None and name[-2:] in (".L", ".R")
                 and role.role not in ("spine", "chest") else role for role, name in zip(roles, names))


def _mirror_twin_roles(roles, body, segment_bone):
    """Give each twin limb (the later of a pair) its twin's roles, bone for bone, keeping its side: measures of the
    mesh (thickness, reach, a hand's fingers) differ a little from side to side, and twins must get twin roles. Only
    where every bone of the limb lies on a bone of its twin's mirror image, both ends within a tenth of its shortest
    bone."""
    if body.plane is None:
        return
    points = body.graph.points
    for k, limb in enumerate(body.limbs):
        if not 0 <= limb.twin < k:
            continue
        twin = body.limbs[limb.twin]
        mine = [(before, node) for node, before in limb.before.items() if (before, node) in segment_bone]
        theirs = [(before, node) for node, before in twin.before.items() if (before, node) in segment_bone]
        if not mine or len(mine) != len(theirs):
            continue
        ends = points[np.array(mine)]  # (S, 2, 3)
        images = body.plane.reflect(points[np.array(theirs)])
        gaps = np.linalg.norm(ends[:, None] - images[None], axis=3).max(axis=2)  # (S, S): the farther end apart
        match = np.argmin(gaps, axis=1)
        shortest = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).min()
        if len(set(match)) != len(mine) or gaps[np.arange(len(mine)), match].max() > 0.1 * shortest:
            continue
        for segment, m in zip(mine, match):
            bone, source = segment_bone[segment], segment_bone[theirs[m]]
            if roles[source] is not None and roles[bone] is not None:
                roles[bone] = BoneRole(roles[source].role, roles[bone].side, roles[source].index, roles[source].digit)


def _filled(roles, skeleton, kind):
    """``roles`` with the bones the body left out (a bone shorter than a joint, a link closing a loop) given the
    role of the first child bone that has one (a collapsed bone sits at its start), else their parent's, else
    ``other``."""
    parents = skeleton.parents.tolist()
    children = {}
    for bone, parent in enumerate(parents):
        children.setdefault(parent, []).append(bone)
    roles = list(roles)
    for _ in range(len(roles)):
        missing = [bone for bone, role in enumerate(roles) if role is None]
        if not missing:
            break
        for bone in missing:
            given = [roles[child] for child in children.get(bone, ()) if roles[child] is not None]
            if given:
                roles[bone] = given[0]
    for bone, role in enumerate(roles):
        if role is None:
            parent = parents[bone]
            roles[bone] = roles[parent] if kind != "other" and parent >= 0 and roles[parent] is not None \
                else BoneRole("other")
    return tuple(roles)


def twin_paths(body, tuning=RoleTuning()):
    """A :class:`TwinPath` per limb of ``body``: read once for its roles and its joints (the mesh's reach beyond an
    arm is a search of the whole mesh)."""
    return [TwinPath(body, limb, tuning) for limb in body.limbs]


class TwinPath:
    """A limb's main path read for its roles and joints: the joints' ``points``, the mesh's ``radius`` at them and its
    ``reach`` beyond the last (:func:`_reach`), averaged with its twin's mirror image when both have as many joints:
    twins get their roles cut, and their joints placed, alike though the mesh mirrors only nearly."""

    def __init__(self, body, limb, tuning):
        nodes = list(limb.main)
        self.body, self.limb, self.points, self.radius = body, limb, body.graph.points[nodes], body.radius[nodes]
        self.margin = tuning.other_part * body.size
        self.twin = twin = body.limbs[limb.twin] if limb.twin >= 0 else None
        self.mirrored = twin is not None and len(twin.main) == len(nodes) and body.plane is not None
        if self.mirrored:
            self.points = 0.5 * (self.points + body.plane.reflect(body.graph.points[list(twin.main)]))
            self.radius = 0.5 * (self.radius + body.radius[list(twin.main)])
        self._leg_joints = {}

    @cached_property
    def reach(self):
        reach = _reach(self.body, self.points, self.limb, self.margin)
        if not self.mirrored:
            return reach
        return 0.5 * (reach + _reach(self.body, self.body.plane.reflect(self.points), self.twin, self.margin))

    def leg_joints(self, front, kind, tuning):
        """:func:`_leg_joints` along this path, found once for the roles and the named joints."""
        key = (front, kind, tuning)
        if key not in self._leg_joints:
            self._leg_joints[key] = _leg_joints(self.body, self, arc_lengths(self.points), front, tuning, kind)
        return self._leg_joints[key]


def _paths(limb):
    """Every path of ``limb`` from where it hangs to one of its leaves, the main one first."""
    children = {}
    for node, before in limb.before.items():
        children.setdefault(before, []).append(node)
    leaves = [node for node in limb.before if node not in children]
    paths = [list(limb.main)]
    for leaf in leaves:
        if leaf == limb.main[-1]:
            continue
        path = [leaf]
        while path[-1] != limb.attach:
            path.append(limb.before[path[-1]])
        paths.append(path[::-1])
    return paths


# The spine.

def _spine_roles(body, layout, tuning):
    """Roles of the spine's bones, from its tail end to its head end."""
    spine = list(layout.spine)
    count = len(spine) - 1
    if count <= 0:
        return []
    kind = layout.plan.kind
    if kind == "other":
        return ["other"] * count
    points = body.graph.points[spine]
    arc = arc_lengths(points)
    middle = 0.5 * (arc[1:] + arc[:-1]) / max(arc[-1], 1e-300)
    if kind == "fish":
        return ["tail" if at < tuning.tail_share else "head" if at > 1 - tuning.head_share else "spine"
                for at in middle]
    hips = max(layout.hips, 0)
    if layout.chest > hips:
        chest = layout.chest
    elif kind == "humanoid":  # arms hanging where the legs do (a gingerbread man): the head sits on that joint
        chest = min(count, hips + 1)
    else:
        chest = min(count, hips + max(1, round(0.65 * (count - hips))))
    names = []
    behind = arc[hips]
    if hips > 0:
        lowest = spine[0]
        grounded = body.touches(lowest, 0.05) and body.height(points[0]) < body.height(points[hips])
        name = "root" if grounded else "tail" if behind >= tuning.tail_length * body.size else "hips"
        names += [name] * hips
    torso = chest - hips
    names += (["hips"] + ["spine"] * (torso - 2) + ["chest"]) if torso >= 3 else ["hips", "spine"][:torso]
    above = count - chest
    if above >= 3:
        low = count  # the candidates: chest + 1 .. low - 1
        if kind == "humanoid":
            top = arc[-1] + _reach(body, points)
            low = chest + 2 + int(np.count_nonzero(arc[chest + 2:count] - arc[chest] <= tuning.head_below
                                                   * (top - arc[chest])))
        thinnest = chest + 1 + int(np.argmin(body.radius[spine[chest + 1:low]]))
        if kind == "quadruped":  # a head carried at an angle to the neck (a deer's) begins at the bend: the skull
            thinnest = _skull_bend(points, thinnest, low, tuning.head_bend)
        # the ears are on the skull: a bone they hang from (all but the first above the chest) is the head's
        ears = [spine.index(body.bases[k]) for k, part in enumerate(layout.parts) if part == "ear"
                and body.bases[k] in spine]
        start = min([thinnest] + [at - 1 for at in ears if chest + 1 < at <= count])
        # the head has a bone: a last piece of the spine may be none (a link where the ears join it)
        start = min(start, max(i for i in range(count) if _is_bone(body.graph, spine[i], spine[i + 1])))
        names += ["neck"] * (start - chest) + ["head"] * (count - start)
    else:
        names += ["neck", "head"][:above]  # one bone into the head pivots at the neck
    return names


def _is_bone(graph, a, b):
    """Whether the graph's piece from node ``a`` to node ``b`` is one of the skeleton's bones."""
    return any(other == b and bone >= 0 for other, bone in graph.neighbours[a])


def _skull_bend(points, start, stop, least):
    """The joint among ``start`` .. ``stop`` - 1 of a spine (``points``) where it turns most (:func:`_bend`), when by
    at least ``least`` degrees, else ``start``."""
    turns = [_bend(points[i], points[i - 1], points[i + 1]) for i in range(start, stop)]
    sharpest = int(np.argmax(turns)) if turns else 0
    return start + sharpest if turns and turns[sharpest] >= least else start


def _connector_role(spine, names, base):
    """The role of a midline bone off the spine hanging from spine joint ``base``: that of the spine bone leaving
    it towards the head (or arriving, at the head end)."""
    if not names:
        return "other"
    at = spine.index(base) if base in spine else 0
    return names[min(at, len(names) - 1)]


# Limbs.

def _leg(body, limb, path, front, kind, tuning, put):
    """Roles along a leg's main ``path``: hips (or shoulder), thigh, shin, foot, toe (front legs: shoulder,
    upper_arm, forearm, hand); the shin from the joint nearest the knee's named place and, on a leg on its toes, the
    foot from the joint nearest its hock's and the toe from the ground's (:func:`_leg_joints`)."""
    nodes, points = list(limb.main), path.points
    last = len(nodes) - 1
    thigh = _thigh_start(body, points, tuning)
    heights = body.height(points)
    low = [i for i in range(thigh + 2, last + 1) if heights[i] <= tuning.foot_height]
    ankle = min(low, key=lambda i: abs(heights[i] - tuning.ankle_height)) if low else last
    if ankle == last and last - 1 >= thigh + 2 and _along_ground(body, points[-2], points[-1]):
        ankle = last - 1  # the paw: a last bone running more along the ground than down is the foot
    toe = last - 1 if last - ankle >= 2 else last
    knee = ankle
    if ankle - thigh >= 2:
        arc = arc_lengths(points)
        _, _, knee_arc, ankle_arc, ball_arc = path.leg_joints(front, kind, tuning)
        if ankle_arc < ball_arc:  # on its toes: the foot from the hock, the toes from the ground
            hock = min(range(thigh + 2, ankle + 1), key=lambda i: abs(arc[i] - ankle_arc))
            toe = ankle if ankle > hock else toe
            ankle = hock
        knee = min(range(thigh + 1, ankle), key=lambda i: abs(arc[i] - knee_arc))
    names = (["shoulder", "upper_arm", "forearm", "hand", "hand"] if front else
             ["hips", "thigh", "shin", "foot", "toe"])
    roles = _segments(names, [thigh, knee, ankle, toe, last])
    put(nodes, roles)
    for path in _paths(limb)[1:]:  # toes and spurs: a branch past the ankle is a toe
        split = _fork(path, nodes)
        put(path[split:], ["toe" if split >= ankle else roles[min(split, len(roles) - 1)] if roles else "other"]
            * (len(path) - 1 - split))


def _along_ground(body, head, tail):
    """Whether a bone from ``head`` to ``tail`` runs more along the ground than down."""
    step = np.asarray(tail) - np.asarray(head)
    drop = -float(step @ body.up)
    return float(np.linalg.norm(step + drop * body.up)) > drop


def _on_toes(front, kind, arc, thigh, ground):
    """Whether a leg stands on its toes, its ankle (the hock) high above the ground: a quadruped's hind leg with
    room for a knee and a hock, two joints or more between where its thigh begins and the ground (arc positions
    ``thigh`` and ``ground`` along a path whose joints lie at ``arc``)."""
    return kind == "quadruped" and not front and np.count_nonzero((arc > thigh) & (arc < ground)) >= 2


def _thigh_start(body, points, tuning):
    """Index of the joint a leg's thigh (a front leg's upper arm) starts at along its path ``points``: the first
    off the mirror plane from which the path runs down (``thigh_drop``); before it, it runs in the body."""
    steps = np.diff(points, axis=0)
    down = -(steps @ body.up) / np.maximum(np.linalg.norm(steps, axis=1), 1e-300)
    last = len(points) - 1
    off = 0 if body.plane is None else next(
        (i for i in range(last + 1) if abs(body.plane.distance(points[i])) > tuning.plane_exit * body.size), last)
    return next((i for i in range(off, last) if down[i] >= tuning.thigh_drop), off if off < last else 0)


def _segments(names, cuts):
    """Role per bone: ``names[k]`` for the bones before joint ``cuts[k]`` (and after the cut before it)."""
    roles, start = [], 0
    for name, end in zip(names, cuts):
        roles += [name] * (end - start)
        start = max(start, end)
    return roles


def _arm(body, limb, path, tuning, put):
    """Roles along an arm: shoulder up to the shoulder joint (where the arm leaves the torso, :func:`_shoulder`),
    then upper_arm, forearm and hand by where each bone's middle lies, at ``elbow_at`` and ``wrist_at`` of the way
    from that joint to the end of the arm's reach (the mesh beyond its last joint included: an artist's arm may end
    at the wrist), the elbow at a bend near its share; the fingers beyond the hand."""
    nodes, points = list(limb.main), path.points
    last = len(nodes) - 1
    arc = arc_lengths(points)
    total = arc[-1] + path.reach
    middle = 0.5 * (arc[1:] + arc[:-1])
    shoulder = _shoulder(path, arc, tuning)
    rest = total - arc[shoulder]  # from the shoulder joint on
    elbow, wrist = (int(np.searchsorted(middle, arc[shoulder] + share * rest))
                    for share in (tuning.elbow_at, tuning.wrist_at))
    bent = _pick(points, shoulder + 1, wrist - 1, tuning.elbow_at, tuning, shoulder, last, rest, bends_only=True)
    elbow = elbow if bent is None else bent
    branches = _paths(limb)[1:]
    forks = sorted({_fork(branch, nodes) for branch in branches})
    fingers_from = forks[0] if forks else last
    wrist = min(wrist, fingers_from) if fingers_from > elbow else wrist
    fingers_from = max(fingers_from, wrist)
    roles = _segments(["shoulder", "upper_arm", "forearm", "hand"], [shoulder, elbow, wrist, fingers_from])
    put(nodes[:fingers_from + 1], roles)
    if fingers_from >= last and not branches:
        return
    fingers = [nodes[fingers_from:]] if fingers_from < last else []
    fingers += [path[_fork(path, nodes):] for path in branches]
    raw = body.graph.points[nodes]
    for finger, digit in zip(fingers, _digits(body, fingers, raw[wrist], raw[min(fingers_from, last)], raw[elbow])):
        put(finger, [("finger", digit)] * (len(finger) - 1))


def _shoulder(path, arc, tuning):
    """Index of an arm's (a wing's) shoulder joint along its ``path`` (:func:`twin_paths`; its joints at arc lengths
    ``arc``, the mesh's half-thickness ``radius`` there, its ``reach`` beyond the last): its first joint where the
    mesh is about as thin as along the arm (``shoulder_thickness`` times the median half-thickness of its joints
    between ``arm_from`` and ``arm_to`` of its reach): the arm has left the torso there. Else the joint where the
    bones pass ``shoulder_at`` of the reach. Never past the last joint."""
    radius, total = path.radius, arc[-1] + path.reach
    middle = 0.5 * (arc[1:] + arc[:-1])
    share = arc / max(total, 1e-300)
    along = radius[(share >= tuning.arm_from) & (share <= tuning.arm_to)]
    if len(along):
        thin = np.flatnonzero(radius[1:] <= tuning.shoulder_thickness * np.median(along)) + 1
        if len(thin) and share[thin[0]] < tuning.elbow_at:
            return int(thin[0])
    return int(np.searchsorted(middle, tuning.shoulder_at * total))


def _reach(body, points, limb=None, margin=0.0):
    """How far the mesh goes on beyond the last of ``points``, along the last bone's direction (``mesh_reach``, up to
    a quarter of the size); with the ``limb`` they run along, not the mesh nearer a bone off that limb by ``margin``
    than to their end."""
    direction = points[-1] - points[-2]
    norm = np.linalg.norm(direction)
    if not norm > 0:
        return 0.0
    others = None
    if limb is not None:
        graph, own = body.graph, {limb.attach, *limb.before}
        off = [bone for bone, (head, tail) in enumerate(zip(graph.head_node, graph.tail_node))
               if not (head in own and tail in own)]
        others = (graph.points[graph.head_node[off]], graph.points[graph.tail_node[off]]) if off else None
    return mesh_reach(body.vertices, points[-1], direction / norm, 0.25 * body.size, body.size, others, margin)


def mesh_reach(vertices, point, direction, limit, size, bones=None, margin=0.0):
    """How far the mesh (its ``vertices``) goes on beyond ``point`` along ``direction`` (unit), up to ``limit``: its
    vertices within a tube as thick as the mesh is at ``point`` (at least 0.02 of the ``size``). With ``bones``
    ((B, 3) heads and tails), not those nearer one of them than ``point`` by ``margin``: that mesh is another
    part's, which the limb's end touches (a hand resting on the hip)."""
    offsets = vertices - point
    along = offsets @ direction
    across = np.linalg.norm(offsets - np.outer(along, direction), axis=1)
    tube = max(2 * float(np.linalg.norm(offsets, axis=1).min()), 0.02 * size)
    inside = (along > 0) & (across <= tube) & (along <= limit)
    if bones is not None and inside.any():
        nearest = segment_distances(vertices[inside], *bones).min(axis=1)
        inside[inside] = np.linalg.norm(offsets[inside], axis=1) <= nearest + margin
    beyond = along[inside]
    return float(beyond.max()) if len(beyond) else 0.0


def _fork(path, nodes):
    """Where ``path`` leaves the main path ``nodes`` (its index in both)."""
    return next(i for i, node in enumerate(path) if i + 1 >= len(path) or path[i + 1] not in nodes)


def _digits(body, fingers, wrist, palm, elbow):
    """Digit names for the finger paths: with three or more, the one leaving the hand earliest and pointing most
    away from it (the forearm's way when the fingers leave from the wrist) is the thumb, the others index, middle,
    ring, pinky by their tips' distance from the thumb's; otherwise none."""
    if len(fingers) < 3:
        return [None] * len(fingers)
    points = body.graph.points
    span = float(np.linalg.norm(palm - wrist))
    hand = palm - wrist if span > 0 else wrist - elbow
    hand = hand / max(np.linalg.norm(hand), 1e-300)

    def away(finger):
        direction = points[finger[-1]] - points[finger[0]]
        norm = np.linalg.norm(direction)
        later = np.linalg.norm(points[finger[0]] - wrist) / span if span > 0 else 0.0
        return (1 - (direction @ hand) / norm if norm > 0 else 0) - later

    thumb = max(range(len(fingers)), key=lambda k: away(fingers[k]))
    order = sorted((k for k in range(len(fingers)) if k != thumb),
                   key=lambda k: np.linalg.norm(points[fingers[k][-1]] - points[fingers[thumb][-1]]))
    names = [None] * len(fingers)
    names[thumb] = "thumb"
    for name, k in zip(DIGITS[1:], order):
        names[k] = name
    return names


def _pick(points, low, high, share, tuning, start=0, end=None, total=None, bends_only=False):
    """The joint in [low, high] for a joint at ``share`` of the way (by length) from joint ``start`` to joint ``end``
    (or to ``total`` past ``start``): of the joints within ``bend_window`` of it where the limb turns by ``bend``
    or more (:func:`_bend`, seen from ``start`` and ``end``), the one :func:`_bend_weight` weighs most; else the
    nearest (None with ``bends_only``)."""
    end = len(points) - 1 if end is None else end
    arc = arc_lengths(points)
    span = (arc[end] - arc[start]) if total is None else total
    at = (arc - arc[start]) / max(span, 1e-300)
    candidates = np.arange(int(low), int(max(low, high)) + 1)
    candidates = candidates[(candidates > 0) & (candidates < len(points))]
    if not len(candidates):
        return None if bends_only else int(low)
    turns = np.array([_bend(points[i], points[start], points[end]) for i in candidates])
    off = np.abs(at[candidates] - share)
    bent = (off <= tuning.bend_window) & (turns >= tuning.bend)
    if bent.any():
        return int(candidates[bent][np.argmax(_bend_weight(turns[bent], off[bent], tuning))])
    return None if bends_only else int(candidates[np.argmin(np.abs(at[candidates] - share))])


def _bend(point, first, last):
    """Degrees a limb turns at ``point`` seen from its ends ``first`` and ``last`` (short bones zigzagging along a
    straight limb make no bend; 0 where it cannot be told)."""
    a, b = point - first, last - point
    norms = np.linalg.norm(a) * np.linalg.norm(b)
    return float(np.degrees(np.arccos(np.clip(a @ b / norms, -1, 1)))) if norms > 0 else 0.0


# Sides.

def _left_sign(body, layout):
    """+1 when the mirror plane's positive side is the character's left, -1 when it is its right: up x forward
    (the character's left) when its front is known, else +1 (Blender's +X left for a character facing -Y)."""
    if body.plane is None or layout.forward is None or layout.plan.kind not in ("quadruped", "bird", "fish"):
        return 1
    return 1 if np.cross(body.up, layout.forward) @ body.plane.normal >= 0 else -1


def _limb_side(skeleton, graph, limb, left):
    """"L", "R" or None: from the limb's bone names when they all end in one of .L / .R, else its side of the plane."""
    suffixes = {skeleton.names[bone][-2:] for node, before in limb.before.items()
                for bone in [graph.bone_between(node, before)] if bone >= 0}
    if suffixes in ({".L"}, {".R"}):
        return suffixes.pop()[1]
    if limb.side == 0:
        return None
    return "L" if limb.side * left > 0 else "R"


LIMB_STARTS = ("thigh", "upper_arm")  # roles that begin where a limb leaves the body
CHAINS = (("hips", "spine", "chest", "neck", "head"), ("shoulder", "upper_arm", "forearm", "hand"),
          ("hips", "thigh", "shin", "foot", "toe"))  # roles that follow each other along a chain


def within_reach(joint, named, ends, tuning=RoleTuning(), limb_start=False):
    """Whether a target's joint at ``joint`` may move to its role's named joint ``named``, the bones meeting there
    running to ``ends``: only within ``named_reach`` of the shortest of them (of the longest at a ``limb_start``, a
    hip or shoulder joint, which the roles place where the limb leaves the body: up the bone the skeleton's leg
    hangs from when a skirt hid its top), no bone shrinking below 1 - ``named_reach`` of its length. A named joint
    farther off is another chain's (a second pair of arms) or a guess. A stub the move lengthens, shorter than
    1 - ``named_reach`` of the longest bone it shortens, does not count (a cow's shin between a knee joint just above
    its hock and the hock: the knee moves up its thigh)."""
    lengths = [float(np.linalg.norm(np.subtract(end, joint))) for end in ends]
    shortened = [float(np.linalg.norm(np.subtract(named, end))) < length for end, length in zip(ends, lengths)]
    stub = (1.0 - tuning.named_reach) * max((length for length, short in zip(lengths, shortened) if short),
                                            default=0.0)
    counted = [length for length, short in zip(lengths, shortened) if short or length >= stub]
    reach = (max if limb_start else min)(counted or lengths, default=0.0)
    if float(np.linalg.norm(np.subtract(named, joint))) > tuning.named_reach * reach:
        return False
    return all(np.linalg.norm(np.subtract(named, end)) >= (1.0 - tuning.named_reach) * length
               for end, length in zip(ends, lengths))


def hips_below(joints, start, up, tolerance):
    """The hips' named joint in ``joints`` when it lies lower along ``up`` than a target's trunk ``start`` (by more
    than ``tolerance``), else None: a short torso whose legs and arms all leave one joint high in it (a gingerbread
    man) has its hips below that joint, and the target's trunk begins there."""
    hips = joints.get(("hips", None, None))
    return hips if hips is not None and (np.asarray(start) - hips) @ up > tolerance else None


def named_joints(skeleton, roles=None):
    """{(role, side, digit): point}: where each role begins on ``skeleton``. With its own roles (``roles`` None, or
    equal to them) the places its body plan found (``BodyPlan.joints``, see the module docstring); else, and for
    roles without a place, the role boundaries (a knee where the thigh's last bone ends). Roles ``other`` have none.
    ValueError without one role per bone."""
    own = roles is None
    roles = skeleton.roles if roles is None else roles
    if roles is None or len(roles) != len(skeleton):
        raise ValueError("named_joints needs one role per bone (recognise the body plan first)")
    places = _boundaries(skeleton, roles)
    if own or tuple(roles) == skeleton.roles:
        places.update((key, place) for key, place in _plan_places(skeleton).items() if key[0] in ROLES)
    return {key: _point_of(skeleton, place) for key, place in places.items()}


def landmarks(skeleton):
    """{(landmark, side, digit): point} of the body's ends that begin no role (``LANDMARKS``): the top of the head,
    the end of each hand's reach and each finger's tip (digit named), the tip of each foot's toes (the mesh beyond
    the last joints included) and each heel (on the ground under the back of the foot). Those the plan has; empty
    before the body plan is recognised."""
    if skeleton.roles is None:
        return {}
    found = {key: _point_of(skeleton, place) for key, place in _plan_places(skeleton).items() if key[0] in LANDMARKS}
    tips = {}
    for bone, role in enumerate(skeleton.roles):
        if role.role == "finger" and role.digit and role.index >= tips.get((role.side, role.digit), (-1, 0))[0]:
            tips[(role.side, role.digit)] = (role.index, bone)
    found.update({("finger_tip", side, digit): skeleton.tails[bone] for (side, digit), (_, bone) in tips.items()})
    return found


def _plan_places(skeleton):
    """The places the skeleton's body plan found (``BodyPlan.joints``), when they are places on this skeleton."""
    plan = skeleton.body_plan
    joints = {} if plan is None else plan.joints
    if all(0 <= bone < len(skeleton) for place in joints.values() for bone, _, _ in place):
        return joints
    return {}


def _point_of(skeleton, place):
    """The point a place (:func:`joint_places`) stands for on ``skeleton``."""
    return sum(weight * (skeleton.heads[bone] + share * (skeleton.tails[bone] - skeleton.heads[bone]))
               for bone, share, weight in place)


def _boundaries(skeleton, roles):
    """{(role, side, digit): place} where each role begins at a bone boundary: the end of the bones of the role
    before it in its chain nearest its own bones (a knee where the thigh ends, a hip joint where a leg's hips bone
    ends; a leg's thigh follows its own side's hips, else the body's); for a chain's first role, the end of its bones
    farthest from the role after it (the back end of a quadruped's hips, whichever way its bones point); else the
    start of its first bone (a finger's base); and where a chain's role has no bone, after a last bone with nothing
    beyond it, that bone's end (the wrist of an arm whose forearm ends there)."""
    first, last, bones_of = {}, {}, {}  # (role, side, digit) -> bone, bone, bones
    for bone, role in enumerate(roles):
        if role.role == "other":
            continue
        key = (role.role, role.side, role.digit)
        bones_of.setdefault(key, []).append(bone)
        if key not in first or role.index < roles[first[key]].index:
            first[key] = bone
        if key not in last or role.index >= roles[last[key]].index:
            last[key] = bone
    is_leaf = np.ones(len(skeleton), dtype=bool)
    is_leaf[skeleton.parents[skeleton.parents >= 0]] = False
    joints = {key: ((bone, 0.0, 1.0),) for key, bone in first.items()}

    def end_of(bones, others, farthest=False):
        """The (bone, share) of the end of ``bones`` nearest (``farthest``: farthest from) the ends of ``others``."""
        ends = np.concatenate([skeleton.heads[others], skeleton.tails[others]])
        candidates = [(bone, share) for bone in bones for share in (0.0, 1.0)]
        gaps = [np.linalg.norm(ends - (skeleton.tails if share else skeleton.heads)[bone], axis=1).min()
                for bone, share in candidates]
        return candidates[int(np.argmax(gaps) if farthest else np.argmin(gaps))]

    started = set()  # the first roles of chains placed already (the body's hips: by the trunk, not a leg)
    for chain in CHAINS:
        for side in ("L", "R", None):
            start, after = (chain[0], side, None), (chain[1], side, None)
            if start in bones_of and after in bones_of and start not in started:
                joints[start] = (end_of(bones_of[start], bones_of[after], farthest=True) + (1.0,),)
                started.add(start)
            for before, role in zip(chain, chain[1:]):
                previous = next((key for key in ((before, side, None), (before, None, None)) if key in last), None)
                if previous is None:
                    continue
                if (role, side, None) in first:
                    joints[(role, side, None)] = (end_of(bones_of[previous], bones_of[(role, side, None)]) + (1.0,),)
                elif is_leaf[last[previous]]:
                    joints[(role, side, None)] = ((last[previous], 1.0, 1.0),)
    return joints


# Places of named joints along the bones.

def joint_places(skeleton, body, layout, paths, tuning=RoleTuning()):
    """{(name, side, digit): place} of the named joints (a role's name) and landmarks (``LANDMARKS``) the body's
    geometry places between bone ends (see the module docstring): on legs and arms (their ``paths``,
    :func:`twin_paths`), on an upright humanoid's spine, and the head's top. ``skeleton`` is the one ``body`` was read
    from. A place is ``((bone, share, weight), ...)``: the weighted sum (weights summing to 1) of the points ``share``
    of the way along those bones."""
    if layout.plan.kind == "other":
        return {}
    graph = body.graph
    ends = {}
    for bone in range(len(skeleton)):
        ends.setdefault(int(graph.head_node[bone]), (bone, 0.0))
        ends[int(graph.tail_node[bone])] = (bone, 1.0)
    left = _left_sign(body, layout)
    places = {}
    for k, limb in enumerate(body.limbs):
        part = layout.parts[k]
        if part not in ("leg", "arm") or len(limb.main) < 2:
            continue
        side = _limb_side(skeleton, graph, limb, left)
        path = paths[k]
        arc = arc_lengths(path.points)
        found = _leg_places(body, path, arc, layout.front[k], tuning, layout.plan.kind) if part == "leg" \
            else _arm_places(body, limb, path, arc, tuning)
        for role, spots in found.items():
            places[(role, side, None)] = _on_bones(graph, ends, list(limb.main), arc, spots)
    spine = list(layout.spine)
    if layout.plan.kind == "humanoid" and len(spine) >= 2:
        places.update(_spine_places(skeleton, body, layout, places, ends, tuning))
    if layout.plan.kind != "fish" and len(spine) >= 2:
        points = graph.points[spine]
        arc = arc_lengths(points)
        places[("head_top", None, None)] = _on_bones(graph, ends, spine, arc, ((arc[-1] + _reach(body, points), 1.0),))
    return places


def _spine_places(skeleton, body, layout, places, ends, tuning):
    """{role: place} of a humanoid's hips, spine, chest and neck: on its spine where it reaches ``hips_at``,
    ``spine_at``, ``chest_at`` and ``neck_at`` of the height from its hip joints (else where the spine leaves the
    legs) to its shoulder joints (else where the arms hang); below the spine's start, on the way from there to the
    hip joints."""
    graph = body.graph
    spine = list(layout.spine)[max(layout.hips, 0):]
    points = graph.points[spine]
    heights = body.height(points)
    hip_joints = [places[key] for key in places if key[0] == "thigh"]
    shoulders = [places[key] for key in places if key[0] == "upper_arm"]
    low = float(np.mean([body.height(_point_of(skeleton, place)) for place in hip_joints])) if hip_joints \
        else heights[0]
    chest = spine.index(layout.spine[layout.chest]) if 0 <= layout.chest and layout.spine[layout.chest] in spine \
        else len(spine) - 1
    high = float(np.mean([body.height(_point_of(skeleton, place)) for place in shoulders])) if shoulders \
        else heights[chest]
    falls = np.flatnonzero(heights[1:] < np.maximum.accumulate(heights)[:-1] - tuning.spine_fall)
    if len(falls):  # a head hanging forward: the spine falls from there on
        spine, points, heights = spine[:falls[0] + 1], points[:falls[0] + 1], heights[:falls[0] + 1]
    if len(spine) < 2 or not high > low:
        return {}
    arc = arc_lengths(points)
    result = {}
    for role, share in (("hips", tuning.hips_at), ("spine", tuning.spine_at), ("chest", tuning.chest_at),
                        ("neck", tuning.neck_at)):
        level = low + share * (high - low)
        if level >= heights[0] or not hip_joints:
            result[(role, None, None)] = _on_bones(graph, ends, spine, arc, ((_up_to(heights, arc, level), 1.0),))
        else:  # between the spine's start and the middle of the hip joints
            weight = (heights[0] - level) / max(heights[0] - low, 1e-300)
            start = _on_bones(graph, ends, spine, arc, ((0.0, 1.0 - weight),))
            share = weight / len(hip_joints)
            result[(role, None, None)] = start + tuple((bone, at, part * share) for place in hip_joints
                                                       for bone, at, part in place)
    return result


def _up_to(heights, arc, level):
    """Arc position where a path with these ``heights`` first rises to ``level`` (its end when it never does)."""
    return _down_to(-heights, arc, -level)


def _on_bones(graph, ends, nodes, arc, spots):
    """The place of ``spots`` (``((arc position, weight), ...)`` along the path through ``nodes``, measured on
    points whose arc lengths are ``arc``: a twin's mirror-averaged ones): the same shares of the path's own links (or
    on past its end, along its last link), each a share of the way along a bone, or between two bones' ends where a
    link has no bone."""
    place = []
    last = len(nodes) - 2
    for at, weight in spots:
        k = min(max(int(np.searchsorted(arc, at, side="right")) - 1, 0), last)
        share = max((at - arc[k]) / max(arc[k + 1] - arc[k], 1e-300), 0.0)
        share = float(share if k == last else min(share, 1.0))  # on past the last joint: a tip
        a, b = nodes[k], nodes[k + 1]
        bone = graph.bone_between(a, b)
        if bone >= 0:
            place.append((bone, share if graph.head_node[bone] == a else 1.0 - share, weight))
        else:
            place += [(*ends[a], weight * (1.0 - share)), (*ends[b], weight * share)]
    return tuple(place)


def _down_to(heights, arc, level):
    """Arc position where a path with these ``heights`` first comes down to ``level`` (its end when it never
    does; its start when it starts below)."""
    below = np.flatnonzero(heights <= level)
    if not len(below):
        return float(arc[-1])
    i = int(below[0])
    if i == 0:
        return 0.0
    drop = heights[i - 1] - heights[i]
    return float(arc[i - 1] + (arc[i] - arc[i - 1]) * (heights[i - 1] - level) / max(drop, 1e-300))


def _leg_places(body, path, arc, front, tuning, kind):
    """{role: spots} along a leg's path: the hip joint, knee and ankle as :func:`_leg_joints` finds them, the hip
    joint on the line of the thigh when that stands within ``thigh_lean`` of up (the path from the knee halfway up
    to the hip, carried on up: the path may reach the hip slanting in from the body's middle; a bent hind leg's thigh
    line leads elsewhere), the toe at ``toe_at`` of the way from the ankle to the tip (a leg on its toes: where it
    comes down to ``ankle_height``), and the heel."""
    points = path.points
    heights = body.height(points)
    hip, hip_height, knee, ankle, ball = path.leg_joints(front, kind, tuning)
    tip = arc[-1] + path.reach
    toes = ankle < ball
    toe = ball if toes else ankle + tuning.toe_at * (tip - ankle)
    thigh = 0.5 * (hip + knee)
    line = _along(points, arc, thigh) - _along(points, arc, knee)
    rise = float(line @ body.up)
    carry = (hip_height - float(np.interp(thigh, arc, heights))) / rise * (body.high - body.low) if rise > 0 else 0
    upright = rise >= np.cos(np.radians(tuning.thigh_lean)) * np.linalg.norm(line)
    hip_spots = ((thigh, 1.0 + carry), (knee, -carry)) if upright and 0 < carry <= 2 else ((hip, 1.0),)
    names = ("upper_arm", "forearm", "hand", None, "hand_tip") if front else \
        ("thigh", "shin", "foot", "toe", "toe_tip")
    places = {name: spots for name, spots in zip(names, (hip_spots, ((knee, 1.0),), ((ankle, 1.0),), ((toe, 1.0),),
                                                         ((tip, 1.0),))) if name}
    heel = None if front else _heel(body, points, arc, ankle, ball, tip, tuning) if toes \
        else _heel(body, points, arc, knee, ankle, tip, tuning)
    if heel is not None:
        places["heel"] = heel
    return places


def _leg_joints(body, path, arc, front, tuning, kind):
    """(hip, its height, knee, ankle, ball) along a leg's path (arc positions; the height a share of the mesh's) of a
    body plan of ``kind``: the ball where it comes down to ``ankle_height``, the ankle there too (a leg on its toes,
    :func:`_on_toes`: its hock at ``hock_at`` of the hip joint's height, above the ball, a bend near there seen from
    mid-leg winning), the hip joint at ``hip_rise`` of the height from the ball to where the leg hangs (a humanoid's
    no higher above its crotch, :func:`_crotch`, than the leg lies off the mirror plane where it comes down to it: a
    gingerbread man's legs hang from the middle of his chest, a heavy golem's stubby legs stand wide apart under a
    belly that hides his thighs; a front leg's shoulder joint no higher than where its path turns down,
    :func:`_thigh_start`: a bear's runs along its shoulder blade first), the knee at ``knee_at`` of the way between
    (a bend near there, below where the thigh's bones begin, winning). A leg on its toes then has its hip joint where
    its thigh's bones begin, atop the rump (the artists' animals' within 0.03 of the height)."""
    points = path.points
    heights = body.height(points)
    ball = _down_to(heights, arc, tuning.ankle_height)
    ball_height = float(np.interp(ball, arc, heights))
    hip_height = ball_height + tuning.hip_rise * (heights[0] - ball_height)
    crotch = _crotch(body, path, ball_height) if kind == "humanoid" else None
    if crotch is not None:  # no higher above the crotch than the leg, where it leaves the body, lies off the plane
        beside = abs(float(body.plane.distance(_along(points, arc, _down_to(heights, arc, crotch)))))
        hip_height = min(hip_height, crotch + beside / (body.high - body.low))
    hip = _down_to(heights, arc, hip_height)
    thigh_from = float(arc[_thigh_start(body, points, tuning)])  # above, the path runs in the body
    if front and thigh_from < ball:  # no higher than where the upper arm's bones begin (a bear's blade)
        hip = max(hip, thigh_from)
        hip_height = float(np.interp(hip, arc, heights))
    ankle = ball
    toes = _on_toes(front, kind, arc, thigh_from, ball)
    if toes:  # the hock, its bend seen from mid-leg (the knee lies above it)
        ankle = _bent(points, arc, hip + tuning.knee_at * (ball - hip),
                      min(_down_to(heights, arc, tuning.hock_at * hip_height), ball), ball, ball - hip, tuning)
        toes = ankle < ball
    knee = _bent(points, arc, max(hip, thigh_from), hip + tuning.knee_at * (ankle - hip), ankle, ankle - hip, tuning)
    if toes and thigh_from < knee:  # the hip joint atop the rump, where the thigh's bones begin
        hip, hip_height = thigh_from, float(np.interp(thigh_from, arc, heights))
    return hip, hip_height, knee, ankle, ball


def _crotch(body, path, ankle):
    """The height (a share of the mesh's) of the crotch beside a leg: the lowest point, above its ``ankle`` (a height:
    feet meeting under a big-headed figure are no crotch) and below where the leg hangs, where the mesh's cut by the
    mirror plane (``Body.midsection``) comes within the leg's half-width of the upright line on the plane level with
    the leg; None when it comes nowhere near (a dress open below, a body without a plane)."""
    section = body.midsection
    forward = np.cross(body.plane.normal, body.up) if len(section) else np.zeros(3)
    if not np.linalg.norm(forward) > 1e-9:  # no cut, or a plane across up: no line on it to look along
        return None
    forward /= np.linalg.norm(forward)
    along = section @ forward - float(np.mean(path.points @ forward))  # (S, 2): off the line, along the body
    heights = body.height(section)
    reach = float(np.median(path.radius))
    step = along[:, 1] - along[:, 0]
    flat = np.abs(step) < 1e-12
    edges = (np.array([[-reach], [reach]]) - along[:, 0]) / np.where(flat, 1.0, step)  # where it meets |off| = reach
    low = np.clip(np.where(flat, 0.0, edges.min(axis=0)), 0.0, 1.0)
    high = np.clip(np.where(flat, 1.0, edges.max(axis=0)), 0.0, 1.0)
    near = (~flat | (np.abs(along[:, 0]) <= reach)) & (low < high)
    rise = heights[:, 1] - heights[:, 0]
    lowest = heights[:, 0] + rise * np.where(rise > 0, low, high)  # the clipped piece's lowest end
    leg = body.height(path.points)
    candidates = lowest[near & (lowest > ankle) & (lowest < leg[0])]
    return float(candidates.min()) if len(candidates) else None


def _heel(body, points, arc, knee, ankle, tip, tuning):
    """Spots of the heel: on the ground under the back of the foot (the mesh's hindmost vertex there, along the
    foot's way from the ankle to the toe's tip, within ``heel_width`` of its line), as weights of the knee, the ankle
    and the toe's tip (the leg's own plane); None when they are in line or the foot points nowhere."""
    corners = np.array([_along(points, arc, at) for at in (knee, ankle, tip)])
    ankle_point, up = corners[1], body.up
    forward = corners[2] - ankle_point
    forward -= (forward @ up) * up
    if not np.linalg.norm(forward) > 0:
        return None
    forward /= np.linalg.norm(forward)
    across = np.cross(up, forward)
    offsets = body.vertices - ankle_point
    near = (np.abs(offsets @ across) <= tuning.heel_width * body.size) & (offsets @ up <= 0) \
        & (np.abs(offsets @ forward) <= np.linalg.norm(corners[2] - ankle_point))
    if not near.any():
        return None
    heel = ankle_point + float((offsets[near] @ forward).min()) * forward + (body.low - ankle_point @ up) * up
    sides = np.stack([corners[0] - corners[2], corners[1] - corners[2]], axis=1)
    weights, _, rank, _ = np.linalg.lstsq(sides, heel - corners[2], rcond=None)
    if rank < 2:
        return None
    return ((knee, float(weights[0])), (ankle, float(weights[1])), (tip, float(1.0 - weights.sum())))


def _arm_places(body, limb, path, arc, tuning):
    """{role: spots} along an arm's path: the collarbone's start ``clavicle_at`` of the way to the shoulder joint,
    the shoulder joint as :func:`_shoulder` finds it, the elbow and the wrist
    at ``elbow_at`` and ``wrist_at`` of the way from there to the end of the reach (a bend near the elbow winning;
    the wrist no farther than where the fingers fork)."""
    nodes, points = list(limb.main), path.points
    total = arc[-1] + path.reach
    shoulder = float(arc[_shoulder(path, arc, tuning)])
    rest = total - shoulder
    elbow, wrist = (shoulder + share * rest for share in (tuning.elbow_at, tuning.wrist_at))
    elbow = _bent(points, arc, shoulder, elbow, wrist, rest, tuning)
    forks = [arc[_fork(branch, nodes)] for branch in _paths(limb)[1:]]
    if forks and min(forks) > elbow:
        wrist = min(wrist, min(forks))
    return {"shoulder": ((tuning.clavicle_at * shoulder, 1.0),), "upper_arm": ((shoulder, 1.0),),
            "forearm": ((elbow, 1.0),), "hand": ((min(wrist, arc[-1]), 1.0),), "hand_tip": ((total, 1.0),)}


def _bent(points, arc, start, middle, end, length, tuning):
    """Arc position of a limb's middle joint (an elbow, a knee) between ``start`` and ``end``: of the joints within
    ``bend_window`` of the limb's ``length`` from ``middle`` where it turns by ``bend`` or more (:func:`_bend`, seen
    from ``start`` and ``end``), the one :func:`_bend_weight` weighs most; else ``middle``."""
    first, last = _along(points, arc, start), _along(points, arc, end)
    best, weight = middle, 0.0
    for i in range(1, len(points) - 1):
        off = abs(arc[i] - middle) / max(length, 1e-300)
        if start < arc[i] < end and off <= tuning.bend_window:
            angle = _bend(points[i], first, last)
            counts = _bend_weight(angle, off, tuning)
            if angle >= tuning.bend and counts > weight:
                best, weight = float(arc[i]), counts
    return best


def _bend_weight(turn, off, tuning):
    """How much a bend turning by ``turn`` degrees ``off`` (a share of the limb's length) from where an elbow or a
    knee belongs counts as that joint: its turn, halved at ``bend_window``'s edge (an ogre's arm turns as much
    under its deltoid as at its elbow, which lies nearer the elbow's share)."""
    return turn / (1.0 + off / tuning.bend_window)


def _along(points, arc, at):
    """The point at arc length ``at`` along ``points`` (whose arc lengths are ``arc``), on past the last point
    along the last link as :func:`_on_bones` places it."""
    k = min(max(int(np.searchsorted(arc, at, side="right")) - 1, 0), len(points) - 2)
    share = max((at - arc[k]) / max(arc[k + 1] - arc[k], 1e-300), 0.0)
    return points[k] + (share if k == len(points) - 2 else min(share, 1.0)) * (points[k + 1] - points[k])


@dataclass(frozen=True, eq=False)
class Roles(Stage):
    """Each bone's role as a label at its middle: ``points`` (B, 3) and ``texts`` (B,)."""

    points: np.ndarray
    texts: tuple

    label = "Bone Roles"
    colour = (1.0, 0.55, 0.1)

    def __post_init__(self):
        self.drawing()  # Labels checks the arrays

    @classmethod
    def of(cls, skeleton, roles):
        """The stage labelling ``skeleton``'s bones with ``roles``."""
        return cls(0.5 * (skeleton.heads + skeleton.tails), tuple(role.label for role in roles))

    def drawing(self):
        return Labels(np.asarray(self.points, dtype=np.float64), tuple(self.texts)) if len(self.texts) else None
