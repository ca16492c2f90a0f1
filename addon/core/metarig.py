"""Fitting a Rigify metarig to a rigged skeleton, bpy-free: which of Rigify's metarigs a body plan gets
(:func:`choose_metarig`) and where every bone of it goes (:func:`fit_metarig`), from the skeleton's bone roles and the
mesh. The Blender layer (``rigger.blender.rigify``) adds the real metarig, reads its bones as :class:`MetaBone` data,
moves them where the fit says and lets Rigify generate the control rig.

The metarigs (:data:`METARIGS`): a humanoid whose hands show named fingers gets Rigify's ``human`` (palms and three
bones a finger), other humanoids ``basic_human``; a quadruped ``basic_quadruped`` (the metarig whose every bone the
skeleton can place: Rigify's wolf, cat and horse add faces, manes and hooves no skeleton shows); a bird ``bird``.
Fish and serpents get none (Rigify's shark fits a shark, and a body plan cannot tell it from a snake).

How the bones are placed, in order:

- The character's frame: up is the body plan's; the front is where the feet point (from the ankle to the toe tip),
  else, for an animal, from the tail end of the spine to the head end, else the front of a figure whose left is its
  ``.L`` side (Blender's convention); left = up x front. Rigify expects Z up and the front at -Y in the armature's own
  space, so the metarig gets this frame as its rotation and its bones are placed in it. A skeleton whose ``.L`` limbs
  lie on the character's right has its sides swapped: Rigify's ``.L`` bones go on the character's left.
- Chains: each :class:`Chain` of a metarig is a run of its bones with the roles each takes. The skeleton's bones of
  those roles (of that side; fingers of that digit) form a path, ordered from the body outwards; where the path has
  branches or pieces, the longest piece (on the chain's side, the one farthest out on it) is taken.
- On that path, a metarig joint between bones of two roles sits where the skeleton's next role begins (a knee where
  the shin begins), or where the one before ends when the next is missing; the other joints divide the stretch
  between such joints in the metarig's own proportions and move onto a skeleton joint near them (the skeleton's
  joints sit where the mesh bends): a skeleton without a toe gets its foot split at the metarig's ball.
- Limbs that Rigify bends with IK (legs, arms, paws): the joint between their first two bones is moved, when it does
  not already bend that way by ``bend`` of the limb's reach, so that knees bend forward and elbows backward (Rigify
  takes the bend direction from the chain).
- Twins that mirror within ``mirror_tolerance`` of the size are made exact mirror images across the midline.
- The heel (Rigify's ``heel.02``, the foot's rocking edge) runs across the back of the foot on the ground, from the
  mesh: the foot's vertices below the ankle, their rearmost and their width.
- Palms run from inside the hand (where the metarig's do, as a share of the way from the wrist) to their finger.
- Derived bones (pelvis, breast: Rigify's deforming helpers) keep their place relative to the joints around them:
  the metarig's position scaled per axis by how the nearest placed joints moved.
- Bones whose part the skeleton lacks are removed with everything hanging from them: a tail, an arm, the fingers of a
  hand that shows none, and the face of Rigify's human (a face rig needs eyes, lids and lips that no skeleton shows).
"""
from dataclasses import dataclass, field

import numpy as np

from .tuning import TuningTable, tuned

FORWARD, BACKWARD = 1, -1  # the way a limb's first joint bends (a knee, an elbow)
TORSO = ("hips", "spine", "chest")
DIGIT_BONES = {"thumb": "thumb", "index": "f_index", "middle": "f_middle", "ring": "f_ring", "pinky": "f_pinky"}


@dataclass(frozen=True)
class MetarigTuning(TuningTable):
    """The tuned numbers of fitting a metarig (shares of the mesh size unless said otherwise)."""

    bend: float = tuned(0.03, "a limb's middle joint lies at least this share of the limb's reach off the line "
                              "from its root to its end, the way it bends (Rigify's human metarig: knees 0.044, "
                              "elbows 0.09): Rigify's IK bends the way the chain does")
    straight: float = tuned(0.05, "a limb whose middle joint lies less than this share of its reach sideways off the "
                                  "plane of its bend is straight there: Rigify's IK then bends it exactly the way it "
                                  "bends (a limb bent more keeps its pose)")
    snap: float = tuned(0.3, "a joint placed by the metarig's proportions moves onto a skeleton joint within this "
                             "share of the shorter of its two bones")
    mirror_tolerance: float = tuned(0.03, "twin chains whose joints mirror within this are made exact mirror images "
                                          "(a posed figure's differ more and keep their pose)")
    merge: float = tuned(1e-6, "bone ends closer than this are one joint")
    shortest: float = tuned(0.002, "no placed bone is shorter than this")
    anchors: int = tuned(8, "a derived bone moves with this many placed joints nearest it in the metarig")
    heel_reach: float = tuned(0.6, "the heel is looked for among the vertices within this many foot lengths of the "
                                   "ankle, across the ground")


@dataclass(frozen=True)
class MetaBone:
    """A metarig bone as data: ``name``, ``head`` and ``tail`` (3,) in the metarig's frame (Z up, the front at -Y,
    the left at +X), its ``parent``'s name (None for a root), its ``z_axis`` (the roll, as the bone's Z axis) and
    whether it is ``connected`` to its parent."""

    name: str
    head: tuple
    tail: tuple
    parent: str = None
    z_axis: tuple = (0.0, 0.0, 1.0)
    connected: bool = False


@dataclass(frozen=True)
class Chain:
    """A run of metarig ``bones`` (``{s}`` stands for the side, ``L`` or ``R``, of a ``sided`` chain) and the roles
    each takes: a role name, or a tuple of role names the bone spans with its neighbours of the same tuple (the
    torso's hips, spine and chest). ``digit``: the finger whose bones the ``finger`` roles are; a chain whose first
    role is ``palm`` starts at the wrist. ``bend``: ``FORWARD`` or ``BACKWARD`` for a limb Rigify bends with IK."""

    bones: tuple
    roles: tuple
    sided: bool = False
    bend: int = 0
    digit: str = None

    def names(self, side):
        return tuple(bone.replace("{s}", side or "") for bone in self.bones)


@dataclass(frozen=True)
class MetarigSpec:
    """How a metarig's bones are placed: its ``chains``, the ``derived`` bones that keep their place among the
    placed joints, and the ``heels`` placed from the mesh (``{s}``: the side)."""

    chains: tuple
    derived: tuple = ()
    heels: tuple = ()


def _human_chains(fingers):
    chains = [
        Chain(("spine", "spine.001", "spine.002", "spine.003"), (TORSO,) * 4),
        Chain(("spine.004", "spine.005", "spine.006"), ("neck", "neck", "head")),
        Chain(("shoulder.{s}",), ("shoulder",), sided=True),
        Chain(("upper_arm.{s}", "forearm.{s}", "hand.{s}"), ("upper_arm", "forearm", "hand"), True, BACKWARD),
        Chain(("thigh.{s}", "shin.{s}", "foot.{s}", "toe.{s}"), ("thigh", "shin", "foot", "toe"), True, FORWARD),
    ]
    if fingers:
        chains.append(Chain(("thumb.01.{s}", "thumb.02.{s}", "thumb.03.{s}"), ("finger",) * 3, True, digit="thumb"))
        for number, digit in enumerate(("index", "middle", "ring", "pinky"), start=1):
            prefix = DIGIT_BONES[digit]
            chains.append(Chain((f"palm.0{number}.{{s}}", f"{prefix}.01.{{s}}", f"{prefix}.02.{{s}}",
                                 f"{prefix}.03.{{s}}"), ("palm",) + ("finger",) * 3, True, digit=digit))
    return tuple(chains)


METARIGS = {
    "human": MetarigSpec(_human_chains(True), ("pelvis.{s}", "breast.{s}"), ("heel.02.{s}",)),
    "basic_human": MetarigSpec(_human_chains(False), ("pelvis.{s}", "breast.{s}"), ("heel.02.{s}",)),
    "basic_quadruped": MetarigSpec((
        Chain(("spine.004", "spine.005", "spine.006", "spine.007", "spine.008"), (TORSO,) * 5),
        Chain(("spine.009", "spine.010", "spine.011"), ("neck", "neck", "head")),
        Chain(("spine.003", "spine.002", "spine.001", "spine"), ("tail",) * 4),
        Chain(("shoulder.{s}",), ("shoulder",), sided=True),
        Chain(("front_thigh.{s}", "front_shin.{s}", "front_foot.{s}", "front_toe.{s}"),
              ("upper_arm", "forearm", "hand", "hand"), True, BACKWARD),
        Chain(("thigh.{s}", "shin.{s}", "foot.{s}", "toe.{s}"), ("thigh", "shin", "foot", "toe"), True, FORWARD),
    ), ("pelvis.{s}", "breast.{s}")),
}
PLAN_METARIGS = {"humanoid": ("human", "basic_human"), "quadruped": ("basic_quadruped",)}


def choose_metarig(skeleton):
    """The name of the Rigify metarig for ``skeleton`` (its body plan and roles): see the module docstring.
    ValueError for a plan that no metarig fits."""
    plan = skeleton.body_plan
    kind = "unknown" if plan is None else plan.kind
    if kind not in PLAN_METARIGS:
        raise ValueError(f"no Rigify metarig fits a {kind} body plan (metarigs for: {', '.join(PLAN_METARIGS)})")
    if kind == "humanoid":
        fingers = any(role.role == "finger" and role.digit == "index" for role in skeleton.roles or ())
        return "human" if fingers else "basic_human"
    return PLAN_METARIGS[kind][0]


@dataclass
class Fit:
    """Where a metarig's bones go: the ``metarig``'s name, the ``frame`` (3x3: the columns are the metarig's X, Y, Z
    axes in the world: the character's left, back and up), and in that frame each kept bone's ``heads``, ``tails``
    and ``z_axes`` (the roll reference) by name; the metarig bones ``removed`` and ``notes`` saying why."""

    metarig: str
    frame: np.ndarray
    heads: dict = field(default_factory=dict)
    tails: dict = field(default_factory=dict)
    z_axes: dict = field(default_factory=dict)
    removed: tuple = ()
    notes: list = field(default_factory=list)

    def world(self, name):
        """(head, tail) of bone ``name`` in the world."""
        return self.frame @ self.heads[name], self.frame @ self.tails[name]


def fit_metarig(skeleton, mesh, metarig, bones, tuning=MetarigTuning()):
    """A :class:`Fit` of metarig ``metarig`` (a name in :data:`METARIGS`, whose bones are ``bones``, a sequence of
    :class:`MetaBone`) to ``skeleton`` (with its body plan and roles) rigging ``mesh`` ((vertices, triangles) or a
    ``core.mesh.Mesh``, in the skeleton's frame). ValueError when the skeleton has no roles or no torso."""
    if metarig not in METARIGS:
        raise ValueError(f"unknown metarig {metarig!r}; known: {', '.join(METARIGS)}")
    if skeleton.roles is None or skeleton.body_plan is None:
        raise ValueError("fitting a metarig needs the skeleton's body plan and roles (rigger.rig_mesh gives them)")
    vertices = np.asarray(mesh.vertices if hasattr(mesh, "vertices") else mesh[0], dtype=np.float64)
    spec = METARIGS[metarig]
    meta = {bone.name: bone for bone in bones}
    missing = sorted({name for chain in spec.chains for side in _sides(chain) for name in chain.names(side)} - set(meta))
    if missing:
        raise ValueError(f"the {metarig} metarig has no bones {', '.join(missing)}: not the metarig Rigger knows")
    body = _Body(skeleton, vertices, tuning)
    fit = Fit(metarig, body.frame)
    anchors = []  # (metarig point, fitted point) of every placed joint
    for chain in spec.chains:
        for side in _sides(chain):
            names = chain.names(side)
            points = _fit_chain(body, chain, side, names, meta, tuning)
            if points is None:
                continue
            for k, name in enumerate(names):
                fit.heads[name], fit.tails[name] = points[k], points[k + 1]
            anchors += [(np.asarray(meta[name].head, float), points[k]) for k, name in enumerate(names)]
            anchors.append((np.asarray(meta[names[-1]].tail, float), points[-1]))
    units = [chain.names("L") for chain in spec.chains if chain.sided]
    midline = [name for chain in spec.chains if not chain.sided for name in chain.names(None)]
    middle = _mirror_twins(fit, units, midline, tuning.mirror_tolerance * body.size)
    for template in spec.heels:
        for side in "LR":
            name = template.replace("{s}", side)
            if f"foot.{side}" in fit.heads and name in meta:
                fit.heads[name], fit.tails[name] = _heel(body, fit, side, tuning)
    meta_points = np.array([point for point, _ in anchors])
    fitted_points = np.array([point for _, point in anchors])
    for template in spec.derived:
        for side in "LR":
            name = template.replace("{s}", side)
            bone = meta.get(name)
            if bone is not None and (bone.parent is None or bone.parent in fit.heads):
                fit.heads[name], fit.tails[name] = (_derived(np.asarray(point, float), meta_points, fitted_points,
                                                             tuning) for point in (bone.head, bone.tail))
    extra = [[template.replace("{s}", "L")] for template in spec.heels + spec.derived]
    _mirror_twins(fit, extra, (), tuning.mirror_tolerance * body.size, middle)
    for name in fit.heads:
        fit.z_axes[name] = np.asarray(meta[name].z_axis, dtype=np.float64)
        _keep_length(fit, name, body.size * tuning.shortest)
    fit.removed = _removed(meta, fit.heads)
    fit.notes = _notes(spec, meta, fit, body)
    return fit


def _sides(chain):
    return ("L", "R") if chain.sided else (None,)


class _Body:
    """The skeleton read for fitting: its bones as segments joined at shared ends, its roles, size, frame and the
    mapping of the metarig's sides onto the skeleton's."""

    def __init__(self, skeleton, vertices, tuning):
        self.skeleton, self.roles, self.vertices = skeleton, skeleton.roles, vertices
        ends = np.concatenate([skeleton.heads, skeleton.tails])
        self.size = float(np.ptp(np.concatenate([ends, vertices]), axis=0).max())
        self.tuning = tuning
        self.node = _merged_ends(ends, tuning.merge * self.size)
        count = len(skeleton)
        self.head_node, self.tail_node = self.node[:count], self.node[count:]
        self.points = np.zeros((self.node.max() + 1, 3))
        self.points[self.node] = ends
        self.up = np.asarray(skeleton.body_plan.up, dtype=np.float64)
        self.up /= np.linalg.norm(self.up)
        torso = self.bones_of(TORSO, None) or list(range(count))
        self.centre = self.points[np.concatenate([self.head_node[torso], self.tail_node[torso]])].mean(axis=0)
        front = self._front()
        left = np.cross(self.up, front)
        left /= np.linalg.norm(left)
        front = np.cross(left, self.up)
        self.frame = np.column_stack([left, -front, self.up])
        self.side_map = {"L": "L", "R": "R", None: None}
        named = [bone for bone, role in enumerate(self.roles) if role.side == "L"]
        if named and (self.middle(named) - self.centre) @ left < 0:
            self.side_map = {"L": "R", "R": "L", None: None}

    def local(self, points):
        """World points in the metarig's frame."""
        return np.asarray(points) @ self.frame

    def middle(self, bones):
        return 0.5 * (self.skeleton.heads[bones] + self.skeleton.tails[bones]).mean(axis=0)

    def bones_of(self, roles, side, digit=None):
        """The bones whose role is in ``roles``, of skeleton side ``side`` (and finger ``digit``)."""
        return [bone for bone, role in enumerate(self.roles) if role.role in roles and role.side == side
                and (digit is None or role.digit == digit)]

    def _front(self):
        """The character's front, across up: for an animal from the tail end of its spine to the head end, else
        where its feet point, else (a humanoid without feet) the front of a figure whose ``.L`` side is its left,
        else Blender's -Y."""
        animal = self.skeleton.body_plan.kind != "humanoid"
        head, tail = self.bones_of(("head", "neck"), None), self.bones_of(("tail", "hips"), None)
        spine = [self.middle(head) - self.middle(tail)] if animal and head and tail else []
        lefts, rights = (self.bones_of(("upper_arm", "forearm", "thigh", "shin"), side) for side in ("L", "R"))
        sides = [np.cross(self.middle(lefts) - self.middle(rights), self.up)] if lefts and rights else []
        for direction in spine + self._feet() + sides + [np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])]:
            across = direction - (direction @ self.up) * self.up
            if np.linalg.norm(across) > 1e-6 * np.linalg.norm(direction):
                return across / np.linalg.norm(across)
        raise ValueError("cannot tell the character's front")  # unreachable: -Y and +Z are never both along up

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

    def path(self, bones, order, side):
        """Points (K, 3) of the longest path through ``bones`` and the bone of each step, from the body outwards:
        ``order(bone)`` ranks a bone's role along the chain (the path runs from low to high rank; the end nearer
        the torso's middle first when all ranks tie). Of several pieces, the longest (on side ``side``, the one
        farthest out on it)."""
        pieces = _pieces(bones, self.head_node, self.tail_node)
        if side is not None:
            sign = 1 if side == self.side_map["L"] else -1
            left = self.frame[:, 0]
            piece = max(pieces, key=lambda piece: sign * (self.middle(piece) - self.centre) @ left)
        else:
            piece = max(pieces, key=lambda piece: self._length(piece))
        nodes, steps = self._longest(piece)
        ranks = np.array([order(bone) for bone in steps], dtype=float)
        along = np.arange(len(steps))
        flip = False
        if np.ptp(ranks) > 0:
            flip = np.corrcoef(along, ranks)[0, 1] < 0 if len(steps) > 1 else False
        else:
            first, last = (np.linalg.norm(self.points[node] - self.centre) for node in (nodes[0], nodes[-1]))
            flip = last < first
        if flip:
            nodes, steps = nodes[::-1], steps[::-1]
        return self.points[nodes], steps

    def _length(self, bones):
        return float(np.linalg.norm(self.skeleton.tails[bones] - self.skeleton.heads[bones], axis=1).sum())

    def _longest(self, bones):
        """(nodes, bone of each step) of the longest path through ``bones`` (joined at shared ends)."""
        adjacency = {}
        for bone in bones:
            a, b = int(self.head_node[bone]), int(self.tail_node[bone])
            adjacency.setdefault(a, []).append((b, bone))
            adjacency.setdefault(b, []).append((a, bone))

        def farthest(start):
            distance, before = {start: 0.0}, {start: (None, None)}
            stack = [start]
            while stack:
                node = stack.pop()
                for other, bone in adjacency[node]:
                    if other not in distance:
                        distance[other] = distance[node] + np.linalg.norm(self.points[other] - self.points[node])
                        before[other] = (node, bone)
                        stack.append(other)
            end = max(distance, key=distance.get)
            return end, before

        one, _ = farthest(next(iter(adjacency)))
        other, before = farthest(one)
        nodes, steps = [other], []
        while before[nodes[-1]][0] is not None:
            node, bone = before[nodes[-1]]
            nodes.append(node)
            steps.append(bone)
        return nodes[::-1], steps[::-1]


def _merged_ends(points, tolerance):
    """A node per point, points within ``tolerance`` of each other one node (the first of them)."""
    node = np.arange(len(points))
    for i in range(len(points)):
        if node[i] != i:
            continue
        close = np.flatnonzero(np.linalg.norm(points[i + 1:] - points[i], axis=1) <= tolerance) + i + 1
        node[close[node[close] == close]] = i
    return np.unique(node, return_inverse=True)[1].reshape(-1)


def _pieces(bones, head_node, tail_node):
    """``bones`` split into the pieces they form, joined at shared ends."""
    label = {bone: bone for bone in bones}

    def root(bone):
        while label[bone] != bone:
            bone = label[bone]
        return bone

    at = {}
    for bone in bones:
        for node in (head_node[bone], tail_node[bone]):
            if node in at:
                a, b = root(bone), root(at[node])
                label[max(a, b)] = min(a, b)
            else:
                at[node] = bone
    groups = {}
    for bone in bones:
        groups.setdefault(root(bone), []).append(bone)
    return list(groups.values())


def _fit_chain(body, chain, side, names, meta, tuning):
    """The joints (n + 1, 3) in the metarig's frame of chain ``chain`` on side ``side`` (named ``names``), or None
    when the skeleton has none of its roles."""
    skeleton_side = body.side_map[side]
    groups = [role if isinstance(role, tuple) else (role,) for role in chain.roles]
    wanted = sorted({role for group in groups for role in group} - {"palm"})
    bones = body.bones_of(wanted, skeleton_side, chain.digit)
    if not bones:
        return None
    rank = {}
    for index, group in enumerate(groups):
        for offset, role in enumerate(group):
            rank.setdefault(role, index + offset / len(group))
    points, steps = body.path(bones, lambda bone: rank[body.roles[bone].role], skeleton_side)
    step_roles = [body.roles[bone].role for bone in steps]
    if groups[0] == ("palm",):
        wrist = _wrist(body, skeleton_side, points[0])
        if wrist is None:
            return None
        points = np.vstack([wrist, points])
        step_roles = ["palm"] + step_roles
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    if arc[-1] <= 0:
        return None
    spans = []
    for group in groups:
        at = [k for k, role in enumerate(step_roles) if role in group]
        spans.append((arc[min(at)], arc[max(at) + 1]) if at else None)
    lengths = np.array([np.linalg.norm(np.subtract(meta[name].tail, meta[name].head)) for name in names])
    cuts = _cuts(groups, spans, arc, lengths, tuning)
    joints = body.local(np.array([_at(points, arc, cut) for cut in cuts]))
    if groups[0] == ("palm",):
        joints[0] = _palm_head(joints, meta, names, side)
    if chain.bend:
        _bend(joints, chain.bend, tuning)
    return joints


def _cuts(groups, spans, arc, lengths, tuning):
    """Arc positions of a chain's n + 1 joints along a path with joints at ``arc``: pinned where roles change
    (see the module docstring), the rest in the metarig's proportions ``lengths``, snapped to nearby joints."""
    count = len(groups)
    pins = [0.0] + [None] * (count - 1) + [arc[-1]]
    for k in range(1, count):
        if groups[k] == groups[k - 1]:
            continue
        pins[k] = spans[k][0] if spans[k] is not None else spans[k - 1][1] if spans[k - 1] is not None else None
    changed = True
    while changed:  # pins that leave the bones between them no room give way
        changed = False
        pinned = [k for k, pin in enumerate(pins) if pin is not None]
        for i, j in zip(pinned, pinned[1:]):
            if pins[j] <= pins[i] + 1e-9 * arc[-1]:
                pins[j if j < count else i] = None
                changed = True
                break
        if pins[0] is None or pins[count] is None:
            pins[0], pins[count] = 0.0, arc[-1]
    cuts = np.array([0.0 if pin is None else pin for pin in pins])
    pinned = [k for k, pin in enumerate(pins) if pin is not None]
    for i, j in zip(pinned, pinned[1:]):
        shares = np.cumsum(lengths[i:j]) / lengths[i:j].sum()
        cuts[i + 1:j] = pins[i] + shares[:-1] * (pins[j] - pins[i])
        for k in range(i + 1, j):  # onto a skeleton joint near it, keeping the order
            room = tuning.snap * min(cuts[k] - cuts[k - 1], cuts[k + 1] - cuts[k])
            inner = arc[(arc > cuts[k - 1]) & (arc < cuts[k + 1])]
            if len(inner):
                nearest = inner[np.argmin(np.abs(inner - cuts[k]))]
                if abs(nearest - cuts[k]) <= room:
                    cuts[k] = nearest
    return cuts


def _at(points, arc, position):
    """The point ``position`` along the polyline ``points`` with cumulative lengths ``arc``."""
    k = int(np.clip(np.searchsorted(arc, position, side="right") - 1, 0, len(points) - 2))
    share = (position - arc[k]) / max(arc[k + 1] - arc[k], 1e-300)
    return points[k] + np.clip(share, 0.0, 1.0) * (points[k + 1] - points[k])


def _wrist(body, side, base):
    """Where the hand of skeleton side ``side`` begins (its end nearer the forearm), for a palm reaching ``base``."""
    hand = body.bones_of(("hand",), side)
    if not hand:
        return None
    points, _ = body.path(hand, lambda bone: 0, side)
    ends = (points[0], points[-1])
    return max(ends, key=lambda end: np.linalg.norm(end - base))


def _palm_head(joints, meta, names, side):
    """A palm's head: as far from the wrist towards its finger as the metarig's is."""
    hand = meta[f"hand.{side}"]
    wrist, base = np.asarray(hand.head, float), np.asarray(meta[names[1]].head, float)
    share = float(np.clip((np.asarray(meta[names[0]].head) - wrist) @ (base - wrist) / max((base - wrist) @
                                                                                         (base - wrist), 1e-300),
                          0.0, 0.9))
    return joints[0] + share * (joints[1] - joints[0])


def _bend(joints, way, tuning):
    """Move the joint between a limb's first two bones so that it bends ``way`` (the front is -Y) by at least
    ``tuning.bend`` of the limb's reach; a limb bent sideways by less than ``tuning.straight`` of its reach loses
    that sideways bend (Rigify's IK bends in the chain's plane)."""
    root, middle, end = joints[0], joints[1], joints[2]
    reach = end - root
    length = np.linalg.norm(reach)
    if not length > 0:
        return
    along = reach / length
    front = np.array([0.0, -1.0, 0.0]) * way
    front = front - (front @ along) * along
    if not np.linalg.norm(front) > 0:
        return
    front /= np.linalg.norm(front)
    sideways = np.cross(along, front)
    offset = middle - root
    forward, aside = offset @ front, offset @ sideways
    if abs(aside) < tuning.straight * length:
        middle = middle - aside * sideways
    joints[1] = middle + max(tuning.bend * length - forward, 0.0) * front


def _mirror_twins(fit, units, midline, tolerance, middle=None):
    """Make each unit of twin bones (``.L`` names; their ``.R`` twins) exact mirror images across the midline (the
    metarig's X = ``middle``, by default the median X of the ``midline`` bones) when all of them mirror within
    ``tolerance`` already; ``midline`` bones within it of the midline go onto it. Returns ``middle``."""
    if middle is None:
        xs = [point[0] for name in midline if name in fit.heads for point in (fit.heads[name], fit.tails[name])]
        middle = float(np.median(xs)) if xs else 0.0
    for name in midline:
        if name in fit.heads and max(abs(fit.heads[name][0] - middle), abs(fit.tails[name][0] - middle)) <= tolerance:
            fit.heads[name], fit.tails[name] = (np.r_[middle, point[1:]] for point in (fit.heads[name],
                                                                                        fit.tails[name]))

    def mirrored(point):
        return np.r_[2 * middle - point[0], point[1:]]

    for lefts in units:
        rights = [name[:-2] + ".R" for name in lefts]
        if not all(name in fit.heads for name in [*lefts, *rights]):
            continue
        gaps = [np.linalg.norm(end[a] - mirrored(end[b])) for a, b in zip(lefts, rights)
                for end in (fit.heads, fit.tails)]
        if max(gaps) > tolerance:
            continue
        for a, b in zip(lefts, rights):
            for end in (fit.heads, fit.tails):
                end[a] = 0.5 * (end[a] + mirrored(end[b]))
                end[b] = mirrored(end[a])
    return middle


def _heel(body, fit, side, tuning):
    """(head, tail) of a foot's heel bone: across the back of the foot, on the ground, inside to outside."""
    ankle, ball = fit.heads[f"foot.{side}"], fit.tails[f"foot.{side}"]
    tip = fit.tails.get(f"toe.{side}", ball)
    vertices = body.local(body.vertices)
    forward = np.array([tip[0] - ankle[0], tip[1] - ankle[1], 0.0])
    length = np.linalg.norm(forward)
    forward = forward / length if length > 0 else np.array([0.0, -1.0, 0.0])
    across = np.array([-forward[1], forward[0], 0.0])
    reach = tuning.heel_reach * max(length, 1e-9)
    offsets = vertices - ankle
    near = (np.abs(offsets @ across) <= reach) & (np.abs(offsets @ forward) <= 2 * reach) & \
        (vertices[:, 2] <= ankle[2])
    if not near.any():
        ground, back, width = min(ankle[2], tip[2]), -0.25 * length, 0.4 * length
    else:
        foot = vertices[near]
        ground = float(foot[:, 2].min())
        behind = foot @ forward - ankle @ forward
        back = float(min(behind.min(), 0.0))
        rear = foot[behind <= back + 0.3 * (0.0 - back) + 1e-9] if back < 0 else foot
        sideways = rear @ across - ankle @ across
        width = float(max(np.ptp(sideways), 0.2 * length))
    centre = ankle + back * forward
    centre[2] = ground
    outward = across if across[0] * (1 if side == "L" else -1) >= 0 else -across  # the metarig's left is +X
    return centre - 0.5 * width * outward, centre + 0.5 * width * outward


def _derived(point, meta_points, fitted_points, tuning):
    """``point`` of the metarig moved with its nearest placed joints: each carries it at its own offset from it,
    scaled by how much the fit spread those joints, weighted by inverse square distance (a point on a joint stays
    on it)."""
    distances = np.linalg.norm(meta_points - point, axis=1)
    nearest = np.argsort(distances)[:tuning.anchors]
    source, target, distances = meta_points[nearest], fitted_points[nearest], distances[nearest]
    spread = np.sqrt(((source - source.mean(axis=0)) ** 2).sum(axis=1).mean())
    scale = np.sqrt(((target - target.mean(axis=0)) ** 2).sum(axis=1).mean()) / spread if spread > 0 else 1.0
    if distances[0] <= 1e-9 * max(spread, 1e-300):
        return target[0].copy()
    weights = 1.0 / distances ** 2
    return (weights[:, None] * (target + scale * (point - source))).sum(axis=0) / weights.sum()


def _keep_length(fit, name, shortest):
    """Stretch bone ``name`` along its own direction (else up) to at least ``shortest``."""
    head, tail = fit.heads[name], fit.tails[name]
    length = np.linalg.norm(tail - head)
    if length >= shortest:
        return
    direction = (tail - head) / length if length > 0 else np.array([0.0, 0.0, 1.0])
    fit.tails[name] = head + shortest * direction


def _removed(meta, kept):
    """The metarig bones not kept (in the metarig's order); the Blender layer hangs their children from the nearest
    kept bone above."""
    return tuple(name for name in meta if name not in kept)


def _notes(spec, meta, fit, body):
    """What the fit left out, in words."""
    notes = []
    removed = set(fit.removed)
    for chain in spec.chains:
        for side in _sides(chain):
            names = chain.names(side)
            if all(name in removed for name in names):
                part = f"{chain.digit} finger" if chain.digit else "/".join(
                    role if isinstance(role, str) else "+".join(role) for role in dict.fromkeys(chain.roles))
                notes.append(f"the model shows no {part}{f' on the {side} side' if side else ''}: removed the "
                             f"metarig's {', '.join(names)}")
    covered = {name for chain in spec.chains for side in _sides(chain) for name in chain.names(side)}
    covered |= {template.replace("{s}", side) for template in spec.derived + spec.heels for side in "LR"}
    others = sorted(name for name in removed if name not in covered)
    if others:
        notes.append(f"removed {len(others)} metarig bones that no skeleton places ({', '.join(others[:4])}"
                     f"{', ...' if len(others) > 4 else ''})")
    if body.side_map["L"] == "R":
        notes.append("the skeleton's .L limbs are on the character's right: Rigify's .L bones went to its left")
    return notes
