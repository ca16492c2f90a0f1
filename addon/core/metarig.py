"""Fitting a Rigify metarig to a rigged skeleton, bpy-free: which of Rigify's metarigs a body plan gets
(:func:`choose_metarig`) and where every bone of it goes (:func:`fit_metarig`), from the skeleton's bone roles and the
mesh. The Blender layer (``rigger.blender.rigify``) adds the real metarig, reads its bones as :class:`MetaBone` data,
moves them where the fit says and lets Rigify generate the control rig.

The metarigs (:data:`METARIGS`): a humanoid whose hands show named fingers gets Rigify's ``human`` (palms and three
bones a finger), other humanoids ``basic_human``; a quadruped ``basic_quadruped``, the generic one (paws, whose every
bone the skeleton can place: Rigify's wolf, cat and horse add faces, manes and hooves no skeleton shows), with ears and
a jaw added as Rigify's horse has them (two-bone simple tentacles on the head) when the skeleton shows them; a bird
``bird`` (a bird with legs: Rigify's bird stands on them, and a bird in flight shows none to place). Fish and
serpents get none (Rigify's shark fits a shark, and a body plan cannot tell it from a snake).

How the bones are placed, in order:

- The character's frame (``core.facing``): up is the body plan's, the front and left as that module finds them from
  the roles. Rigify expects Z up and the front at -Y in the armature's own space, so the metarig gets this frame as
  its rotation and its bones are placed in it. A skeleton whose ``.L`` limbs lie on the character's right has its
  sides swapped: Rigify's ``.L`` bones go on the character's left.
- Chains: each :class:`Chain` of a metarig is a run of its bones with the roles each takes. The skeleton's bones of
  those roles (of that side; fingers of that digit) form a path, ordered from the body outwards; where the path has
  branches or pieces, the longest piece (on the chain's side, the one farthest out on it) is taken. The torso's path
  begins at the hips' named joint when that lies lower (``core.roles.hips_below``).
- On that path, a metarig joint between bones of two roles sits where the skeleton's next role begins (a knee where
  the shin begins), or where the one before ends when the next is missing; where the role has a named joint
  (``core.roles.named_joints``) the joint sits at the path's point nearest it, and on it when that is within reach
  (``core.roles.within_reach``: a hip joint beside the path, up the bone the leg hangs from or down its own); the
  other joints divide the stretch between such joints in the metarig's own proportions and move onto a skeleton
  joint near them (the skeleton's joints sit where the mesh bends): a skeleton without a toe gets its foot split at
  the metarig's ball. A chain whose last roles the skeleton lacks goes on to where the mesh ends ahead of it, when
  the mesh goes on there (an arm ending at the wrist gets its hand; a skeleton whose spine ends at the chest gets a
  neck and a head; a leg ending at the ankle gets its foot forward along the ground, ``core.facing.foot_ahead``),
  else they share the stretch of the last role (a leg whose shin reaches the ground gets its foot and toe from the
  shin's lower part); either way the fit says so.
- Limbs that Rigify bends with IK (legs, arms, paws): the joint between their first two bones is moved, when it does
  not already bend that way by ``bend`` of the limb's reach, so that knees bend forward and elbows backward (Rigify
  takes the bend direction from the chain); a limb bent sideways leans at most ``tilt`` from that. An animal's hind
  leg whose first joint bends backward is read one joint down: that joint is its hock, and its knee (hidden in the
  body) goes where the metarig has it relative to the hip and the hock; one whose shin bends back well above the paw
  (its roles begin the foot near the ground: a leg with too few joints to cut at its hock) has its hock, where
  Rigify's foot begins, at that bend; a hind knee bending forward less than the metarig's (the skeleton runs down the
  middle of a flank that hides it: every animal's in ``../shared``) goes where the metarig has it too: Rigify's
  three-bone paw bends the way its chain bends at rest, and a nearly straight knee above a sharp hock folded back. A
  joint the skeleton bends the wrong way by more than ``bend_move`` stays (the fit says so).
- Twins that mirror within ``mirror_tolerance`` of the size are made exact mirror images across the midline.
- The heel (Rigify's ``heel.02``, the foot's rocking edge) runs across the back of the foot on the ground, from the
  mesh: the foot's vertices below the ankle, their rearmost and their width.
- Palms run from inside the hand (where the metarig's do, as a share of the way from the wrist) to their finger.
- Chains start exactly where the metarig starts them on another chain (the neck at the torso's end, the tail at its
  start): Rigify connects such chains only when their ends coincide.
- Derived bones (pelvis, breast: Rigify's deforming helpers) keep their place among the torso's joints: each
  nearest placed joint carries the metarig's point at its own offset, scaled by how much the fit spread those
  joints, weighted by inverse square distance (a leg's joints, placed by legs longer or shorter than the metarig's,
  would spread them out of the body); their ends stay within ``helper_depth`` of the body's half-thickness from
  the torso bone they hang from.
- Bones whose part the skeleton lacks are removed (what hangs from them hangs from the nearest kept bone above): a
  tail, an arm, ears, the fingers of a hand that shows none, and the face of Rigify's human (a face rig needs eyes,
  lids and lips that no skeleton shows).
"""
from dataclasses import dataclass, field

import numpy as np

from .facing import TORSO, bones_middle, facing, foot_ahead, role_bones
from .polyline import arc_lengths, arc_nearest, point_at
from .roles import CHAINS, LIMB_STARTS, BoneRole, RoleTuning, hips_below, mesh_reach, named_joints, within_reach
from .rotations import about, between
from .tuning import TuningTable, tuned

FORWARD, BACKWARD = 1, -1  # the way a limb's first joint bends (a knee, an elbow)
HELPERS = (("pelvis.{s}", "hips"), ("breast.{s}", "chest"))  # Rigify's deforming helpers and their roles
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
    tilt: float = tuned(30.0, "degrees: a limb's bend leans at most this far sideways from the way it should bend "
                              "(further, IK bends it more sideways than forward)")
    bend_move: float = tuned(0.2, "a limb's middle joint moves at most this share of its reach to bend the right "
                                  "way; a skeleton bending it further the wrong way keeps its joint (its roles are "
                                  "likely wrong there; the ../shared models need up to 0.18, then 0.3 and more)")
    extend: float = tuned(0.4, "a chain whose last roles the skeleton lacks (an arm ending at the wrist) goes on "
                                "to the end of the mesh when the mesh goes on for at least this share of what the "
                                "metarig's proportions give them; else they share the last role's stretch (a leg "
                                "reaching the ground)")
    extend_most: float = tuned(2.5, "... and no further than this many times what the proportions give them (a "
                                    "cartoon's head is two to three times a man's; a sword in the hand is no hand)")
    snap: float = tuned(0.3, "a joint placed by the metarig's proportions moves onto a skeleton joint within this "
                             "share of the shorter of its two bones")
    mirror_tolerance: float = tuned(0.03, "twin chains whose joints mirror within this are made exact mirror images "
                                          "(a posed figure's differ more and keep their pose)")
    merge: float = tuned(1e-6, "bone ends closer than this are one joint")
    shortest: float = tuned(0.002, "no placed bone is shorter than this")
    anchors: int = tuned(8, "a derived bone moves with this many placed torso joints nearest it in the metarig")
    helper_depth: float = tuned(0.8, "... and its ends lie at most this share of the mesh's half-thickness from the "
                                     "bone it hangs from (inside the body it deforms)")
    heel_reach: float = tuned(0.6, "the heel is looked for among the vertices within this many foot lengths of the "
                                   "ankle, across the ground")
    hock_bend: float = tuned(0.15, "a hind leg's shin with a joint this share of its length behind it bends there: "
                                   "that joint is the hock, where Rigify's foot begins (a fox's shin 0.33)")
    side_piece: float = tuned(0.5, "of a side's pieces of a limb's roles, those at least this share of the longest's "
                                   "length compete, the farthest out winning (a stub off a leg is no leg)")


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
    role is ``palm`` starts at the wrist. ``bend``: ``FORWARD`` or ``BACKWARD`` for a limb Rigify bends with IK;
    ``hock``: the roles its bones take instead when its first joint bends the other way (an animal's hind leg whose
    first bend is the hock, its knee hidden in the body above)."""

    bones: tuple
    roles: tuple
    sided: bool = False
    bend: int = 0
    digit: str = None
    hock: tuple = None

    def names(self, side):
        return tuple(bone.replace("{s}", side or "") for bone in self.bones)


@dataclass(frozen=True)
class MetarigSpec:
    """How a metarig's bones are placed: its ``chains``, the ``derived`` bones that keep their place among the
    placed joints ((name, role) pairs), and the ``heels`` placed from the mesh (``{s}``: the side); ``added``:
    (``MetaBone``, Rigify rig type or "") of bones Rigger adds to Rigify's metarig first."""

    chains: tuple
    derived: tuple = ()
    heels: tuple = ()
    added: tuple = ()


def _tentacle(name, points, parent, z_axis):
    """``MetaBone`` data of a chain of bones ``name.01``, ``name.02``... along ``points`` hanging from ``parent``
    (``{s}`` in ``name``: ``.L`` and ``.R`` twins, mirrored across X), the first with Rigify's simple tentacle."""
    base, suffixes = (name[:-4], (".L", ".R")) if name.endswith(".{s}") else (name, ("",))
    added = []
    for suffix in suffixes:
        flip = np.array([-1.0 if suffix == ".R" else 1.0, 1.0, 1.0])
        for k, (head, tail) in enumerate(zip(points, points[1:]), start=1):
            bone = MetaBone(f"{base}.{k:02d}{suffix}", tuple(np.multiply(head, flip)), tuple(np.multiply(tail, flip)),
                            parent if k == 1 else f"{base}.{k - 1:02d}{suffix}", z_axis, k > 1)
            added.append((bone, "limbs.simple_tentacle" if k == 1 else ""))
    return tuple(added)


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
    "human": MetarigSpec(_human_chains(True), HELPERS, ("heel.02.{s}",)),
    "basic_human": MetarigSpec(_human_chains(False), HELPERS, ("heel.02.{s}",)),
    "basic_quadruped": MetarigSpec((
        Chain(("spine.004", "spine.005", "spine.006", "spine.007", "spine.008"), (TORSO,) * 5),
        Chain(("spine.009", "spine.010", "spine.011"), ("neck", "neck", "head")),
        Chain(("spine.003", "spine.002", "spine.001", "spine"), ("tail",) * 4),
        Chain(("shoulder.{s}",), ("shoulder",), sided=True),
        Chain(("front_thigh.{s}", "front_shin.{s}", "front_foot.{s}", "front_toe.{s}"),
              ("upper_arm", "forearm", "hand", "hand"), True, BACKWARD),
        Chain(("thigh.{s}", "shin.{s}", "foot.{s}", "toe.{s}"), ("thigh", "shin", "foot", "toe"), True, FORWARD,
              hock=("thigh", "thigh", "shin", ("foot", "toe"))),
        Chain(("ear.01.{s}", "ear.02.{s}"), ("ear", "ear"), sided=True),
        Chain(("jaw.01", "jaw.02"), ("jaw", "jaw")),
    ), HELPERS, added=(  # ears and a jaw as Rigify's horse metarig has them
        *_tentacle("ear.{s}", ((0.05, -0.5, 0.93), (0.07, -0.51, 0.99), (0.09, -0.52, 1.05)), "spine.011",
                   (0.0, -1.0, 0.0)),
        *_tentacle("jaw", ((0.0, -0.5, 0.85), (0.0, -0.58, 0.82), (0.0, -0.66, 0.81)), "spine.011",
                   (0.0, 0.0, 1.0)))),
    "bird": MetarigSpec((
        Chain(("spine.003", "spine.004", "spine.005", "spine.006"), (TORSO,) * 4),
        Chain(("neck.001", "neck.002", "head"), ("neck", "neck", "head")),
        Chain(("spine.002", "spine.001", "spine"), ("tail",) * 3),
        Chain(("shoulder.{s}",), ("shoulder",), sided=True),
        Chain(("Wing.{s}", "Wing.001.{s}", "Wing.002.{s}"), ("wing",) * 3, sided=True),
        Chain(("thigh.{s}", "shin.{s}", "foot.{s}", "toe.{s}"), ("thigh", "shin", "foot", "toe"), True, BACKWARD),
    ), HELPERS[:1]),
}
PLAN_METARIGS = {"humanoid": "basic_human", "quadruped": "basic_quadruped", "bird": "bird"}  # "human": fingers


def choose_metarig(skeleton):
    """The name of the Rigify metarig for ``skeleton`` (its body plan and roles): see the module docstring.
    ValueError for a plan that no metarig fits."""
    plan = skeleton.body_plan
    kind = "unknown" if plan is None else plan.kind
    if kind not in PLAN_METARIGS:
        raise ValueError(f"no Rigify metarig fits a {kind} body plan (metarigs for: {', '.join(PLAN_METARIGS)})")
    if kind == "humanoid" and any(role.role == "finger" and role.digit == "index" for role in skeleton.roles or ()):
        return "human"
    return PLAN_METARIGS[kind]


@dataclass
class Fit:
    """Where a metarig's bones go: the ``metarig``'s name, the ``frame`` (3x3: the columns are the metarig's X, Y, Z
    axes in the world: the character's left, back and up), and in that frame each kept bone's ``heads``, ``tails``
    and ``z_axes`` (the roll reference) by name; the metarig bones ``removed``; ``notes``: the parts of the metarig
    the skeleton lacks and what the fit could not do, in words (the face of ``human`` goes unsaid); ``roles``: the
    ``core.roles.BoneRole`` of each kept bone that deforms (sides the metarig's: ``L`` is the character's left)."""

    metarig: str
    frame: np.ndarray
    heads: dict = field(default_factory=dict)
    tails: dict = field(default_factory=dict)
    z_axes: dict = field(default_factory=dict)
    removed: tuple = ()
    notes: list = field(default_factory=list)
    roles: dict = field(default_factory=dict)


def fit_metarig(skeleton, mesh, metarig, bones, tuning=MetarigTuning()):
    """A :class:`Fit` of metarig ``metarig`` (a name in :data:`METARIGS`, whose bones are ``bones``, a sequence of
    :class:`MetaBone`) to ``skeleton`` (with its body plan and roles) rigging ``mesh`` ((vertices, triangles) or a
    ``core.mesh.Mesh``, in the skeleton's frame). ValueError when the skeleton has no roles, or ``bones`` lack a bone
    the fit places."""
    if metarig not in METARIGS:
        raise ValueError(f"unknown metarig {metarig!r}; known: {', '.join(METARIGS)}")
    if skeleton.roles is None or skeleton.body_plan is None:
        raise ValueError("fitting a metarig needs the skeleton's body plan and roles (rigger.rig_mesh gives them)")
    vertices = np.asarray(mesh.vertices if hasattr(mesh, "vertices") else mesh[0], dtype=np.float64)
    spec = METARIGS[metarig]
    meta = {bone.name: bone for bone in bones}
    wanted = {name for chain in spec.chains for side in _sides(chain) for name in chain.names(side)}
    missing = sorted(wanted - set(meta))
    if missing:
        raise ValueError(f"the {metarig} metarig has no bones {', '.join(missing)}: not the metarig Rigger knows")
    body = _Body(skeleton, vertices, tuning)
    fit = Fit(metarig, body.frame)
    chains = _continued(spec.chains, meta, body)
    for chain in chains:
        for side in _sides(chain):
            names = chain.names(side)
            points = _fit_chain(body, chain, side, names, meta, tuning)
            for k, name in enumerate(names if points is not None else ()):
                fit.heads[name], fit.tails[name] = points[k], points[k + 1]
            if points is not None:
                fit.roles.update(_chain_roles(chain, side, names))
    units = [chain.names("L") for chain in spec.chains if chain.sided]
    midline = [chain.names(None) for chain in spec.chains if not chain.sided]
    middle = _mirror_twins(fit, units, midline, tuning.mirror_tolerance * body.size)
    _join_chains(fit, spec, meta)
    torso = {name for chain in spec.chains if TORSO in chain.roles for name in chain.names(None)}
    placed = [name for name in fit.heads if name in torso]  # the helpers' anchors: the legs' would spread them
    meta_points = np.array([meta[name].head for name in placed] + [meta[name].tail for name in placed], float)
    fitted_points = np.array([fit.heads[name] for name in placed] + [fit.tails[name] for name in placed])
    for template in spec.heels:
        for side in "LR":
            name = template.replace("{s}", side)
            if f"foot.{side}" in fit.heads and name in meta:
                fit.heads[name], fit.tails[name] = _heel(body, fit, side, tuning)
    for template, role in spec.derived:
        for side in "LR":
            name = template.replace("{s}", side)
            bone = meta.get(name)
            if bone is not None and (bone.parent is None or bone.parent in fit.heads):
                fit.heads[name], fit.tails[name] = (_derived(np.asarray(point, float), meta_points, fitted_points,
                                                             tuning) for point in (bone.head, bone.tail))
                if bone.parent in fit.heads:
                    _within_body(fit, name, bone.parent, body, tuning)
                fit.roles[name] = BoneRole(role, side)
    extra = [[template.replace("{s}", "L")] for template in (*spec.heels, *(name for name, _ in spec.derived))]
    _mirror_twins(fit, extra, (), tuning.mirror_tolerance * body.size, middle)
    for name in fit.heads:
        fit.z_axes[name] = np.asarray(meta[name].z_axis, dtype=np.float64)
        if name not in wanted:
            _keep_length(fit, name, body.size * tuning.shortest)
    _roll_on(fit, meta)
    fit.removed = _removed(meta, fit.heads)
    fit.notes = _notes(spec, fit, body)
    return fit


def _continued(chains, meta, body):
    """``chains``, each midline chain that goes on from another one's end in the metarig (the neck from the torso)
    and whose roles the skeleton lacks made part of that one: it goes on from it in the metarig's proportions (a
    skeleton whose chest runs up through the head still gets a neck and a head)."""
    ends = {chain.bones[-1]: k for k, chain in enumerate(chains) if not chain.sided}
    tolerance = 1e-6 * float(np.ptp([end for bone in meta.values() for end in (bone.head, bone.tail)], axis=0).max())
    merged, absorbed = list(chains), set()
    for k, chain in enumerate(chains):
        roles = {role for group in _groups(chain.roles) for role in group}
        if chain.sided or body.bones_of(roles, None):
            continue
        before = next((ends[bone] for bone in ends if ends[bone] != k and
                       np.linalg.norm(np.subtract(meta[bone].tail, meta[chain.bones[0]].head)) <= tolerance), None)
        if before is None:
            continue
        first = merged[before]
        merged[before] = Chain(first.bones + chain.bones, first.roles + chain.roles)
        absorbed.add(k)
        body.notes.append(f"no {'/'.join(dict.fromkeys(chain.roles))} found on the model: the metarig's "
                          f"{', '.join(chain.bones)} go on from {first.bones[-1]} in its proportions")
    return [chain for k, chain in enumerate(merged) if k not in absorbed]


def _chain_roles(chain, side, names):
    """{bone name: BoneRole} of a placed chain: each bone its role (a torso's first bone the hips, its last the
    chest, those between the spine; a palm the hand), counted along the chain."""
    roles, counts = {}, {}
    for k, (name, role) in enumerate(zip(names, chain.roles)):
        if isinstance(role, tuple):  # the torso
            run = [j for j, other in enumerate(chain.roles) if other == role]
            role = role[0] if k == run[0] else role[-1] if k == run[-1] else role[len(role) // 2]
        role = "hand" if role == "palm" else role
        digit = chain.digit if role == "finger" else None
        index = counts.get(role, 0)
        counts[role] = index + 1
        roles[name] = BoneRole(role, side, index, digit)
    return roles


def _sides(chain):
    return ("L", "R") if chain.sided else (None,)


class _Body:
    """The skeleton read for fitting: its bones as segments joined at shared ends, its roles, size, frame and the
    mapping of the metarig's sides onto the skeleton's."""

    def __init__(self, skeleton, vertices, tuning):
        self.skeleton, self.roles, self.vertices, self.tuning = skeleton, skeleton.roles, vertices, tuning
        ends = np.concatenate([skeleton.heads, skeleton.tails])
        self.size = float(np.ptp(np.concatenate([ends, vertices]), axis=0).max())
        self.notes = []  # what the fit could not do as it should, in words
        self.joints = named_joints(skeleton)
        self.node = _merged_ends(ends, tuning.merge * self.size)
        count = len(skeleton)
        self.head_node, self.tail_node = self.node[:count], self.node[count:]
        self.points = np.zeros((self.node.max() + 1, 3))
        self.points[self.node] = ends
        self.faced = faced = facing(skeleton, self.points, self.head_node, self.tail_node)
        self.up, self.centre = faced.up, faced.centre
        self.frame = np.column_stack([faced.left, -faced.front, faced.up])
        self.side_map = {"L": faced.side("L"), "R": faced.side("R"), None: None}

    def meeting(self, point):
        """The far ends of the skeleton's bones with an end at ``point`` (none when no joint lies there)."""
        at = np.linalg.norm(self.points[self.node] - point, axis=1) <= self.tuning.merge * self.size
        count = len(self.skeleton)
        return self.points[self.node[np.r_[np.flatnonzero(at[count:]), count + np.flatnonzero(at[:count])]]]

    def local(self, points):
        """World points in the metarig's frame."""
        return np.asarray(points) @ self.frame

    def middle(self, bones):
        return bones_middle(self.skeleton, bones)

    def bones_of(self, roles, side, digit=None):
        return role_bones(self.roles, roles, side, digit)

    def path(self, bones, order, side):
        """Points (K, 3) of the longest path through ``bones`` and the bone of each step, from the body outwards:
        ``order(bone)`` ranks a bone's role along the chain (the path runs from low to high rank; when all ranks
        tie, from the end where the piece hangs from the rest of the skeleton, else from the end nearer the torso's
        middle). Of several pieces, the longest (on side ``side``, the one farthest out on it of those at least
        ``side_piece`` of the longest's length)."""
        pieces = _pieces(bones, self.head_node, self.tail_node)
        if side is not None:
            sign = 1 if side == self.side_map["L"] else -1
            left = self.frame[:, 0]
            longest = max(self._length(piece) for piece in pieces)
            pieces = [piece for piece in pieces if self._length(piece) >= self.tuning.side_piece * longest]
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
            attached = self._attached(piece)
            first, last = (np.linalg.norm(self.points[node] - self.centre) for node in (nodes[0], nodes[-1]))
            flip = nodes[-1] in attached if (nodes[0] in attached) != (nodes[-1] in attached) else last < first
        if flip:
            nodes, steps = nodes[::-1], steps[::-1]
        return self.points[nodes], steps

    def _attached(self, piece):
        """The joints where bones outside ``piece`` hang from it or it hangs from them (by parent links)."""
        inside = set(piece)
        parents = self.skeleton.parents
        nodes = {int(self.head_node[bone]) for bone in piece if parents[bone] >= 0 and parents[bone] not in inside}
        nodes |= {int(self.tail_node[parents[bone]]) for bone in range(len(parents))
                  if bone not in inside and parents[bone] in inside}
        return nodes

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
    groups = _groups(chain.roles)
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
    heights = points @ body.up
    hips = hips_below(body.joints, points[np.argmin(heights)], body.up, tuning.merge * body.size) \
        if groups[0][0] == "hips" and side is None else None
    if hips is not None:
        if heights[-1] < heights[0]:  # a torso of one bone may read either way: up from the hips
            points, step_roles = points[::-1], step_roles[::-1]
        points, step_roles = np.vstack([hips, points]), ["hips"] + step_roles
    if groups[0] == ("palm",):
        wrist = _wrist(body, skeleton_side, points[0])
        if wrist is None:
            return None
        points = np.vstack([wrist, points])
        step_roles = ["palm"] + step_roles
    arc = arc_lengths(points)
    if arc[-1] <= 0:
        return None
    lengths = np.array([np.linalg.norm(np.subtract(meta[name].tail, meta[name].head)) for name in names])
    noted = len(body.notes)
    own = set(body.bones_of(set(wanted) | {"finger", "toe"}, skeleton_side))  # the limb's, its digits' too
    others = [bone for bone in range(len(body.roles)) if bone not in own]
    joints = _joints(body, groups, points, arc, step_roles, lengths, tuning, (skeleton_side, chain.digit), side,
                     others)
    if chain.hock:
        meta_joints = np.array([meta[name].head for name in names[:3]], dtype=np.float64)
        if _bent(joints, chain.bend)[0] < 0:  # the first joint bends backward: it is the hock
            del body.notes[noted:]  # read again from the hock, which notes what it lacks itself
            joints = _joints(body, _groups(chain.hock), points, arc, step_roles, lengths, tuning, side=side,
                             others=others)
            joints[1] = _as_in_metarig(joints, meta_joints, chain.bend)
        else:
            _hock(joints, body.local(points), tuning)
            if _forward_share(joints, chain.bend) < _forward_share(meta_joints, chain.bend):  # a knee in the flank
                joints[1] = _as_in_metarig(joints, meta_joints, chain.bend)
    if groups[0] == ("palm",):
        joints[0] = _palm_head(joints, meta, names, side)
    if chain.bend and not _bend(joints, chain.bend, tuning):
        body.notes.append(f"the skeleton's {names[0]} bends too far the wrong way to move its joint: its IK bends "
                          f"that way (move the metarig's {names[1]} head and regenerate)")
    return joints


def _hock(joints, path, tuning):
    """Move a hind leg's hock (``joints[2]``, where Rigify's foot begins) to the joint of the skeleton's ``path``
    between the knee and it that lies farthest behind the line between them, when that is ``hock_bend`` of their
    distance or more: the skeleton bends there, where its roles (a foot near the ground) ran the shin on down to the
    paw. The paw, from the old hock on, becomes the toe."""
    knee, low = joints[1], joints[2]
    reach = float(np.linalg.norm(low - knee))
    arc = arc_lengths(path)
    after, before = arc_nearest(path, arc, knee), arc_nearest(path, arc, low)
    inside = [point for point, at in zip(path, arc) if after < at < before]
    if not inside or not reach > 0:
        return
    behind = [_bent(np.array([knee, point, low]), BACKWARD)[0] for point in inside]
    k = int(np.argmax(behind))
    if behind[k] >= tuning.hock_bend * reach:
        joints[3], joints[2] = joints[2], inside[k]


def _groups(roles):
    return [role if isinstance(role, tuple) else (role,) for role in roles]


def _joints(body, groups, points, arc, step_roles, lengths, tuning, named=None, side=None, others=()):
    """A chain's joints in the metarig's frame, its bones taking the role ``groups`` on the path ``points`` (arc
    lengths ``arc``) whose steps have the roles ``step_roles``; with ``named`` (the skeleton's side and digit), a
    joint where a role begins moves to that role's named joint when it is within reach, and the path ends where the
    role after the chain's begins (the torso at the neck's named joint). Roles the skeleton lacks are noted, on the
    metarig's ``side``; the mesh they go on into is not that nearer the skeleton's ``others`` bones (another part's:
    a hip a hand rests on)."""
    after = body.joints.get((_next_role(groups[-1][-1]), *named)) if named is not None else None
    if after is not None and 0 < (end := arc_nearest(points, arc, after)) < arc[-1]:
        kept = int(np.searchsorted(arc, end, side="left"))
        points, step_roles = np.vstack([points[:kept], point_at(points, arc, end)]), step_roles[:kept]
        arc = np.r_[arc[:kept], end]
    spans = []
    for group in groups:
        at = [k for k, role in enumerate(step_roles) if role in group]
        spans.append((arc[min(at)], arc[max(at) + 1]) if at else None)
    starts = {} if named is None else {k: body.joints.get((group[0], *named)) for k, group in enumerate(groups)
                                       if spans[k] is not None and (k == 0 or group != groups[k - 1])}
    starts = {k: joint for k, joint in starts.items() if joint is not None}  # of roles the skeleton has
    pins = {}  # where a role begins, moved to its named joint when within reach of the roles around it
    for k, joint in starts.items():
        before = next((span for span in reversed(spans[:k]) if span is not None), None)
        if k and before is not None and within_reach(point_at(points, arc, spans[k][0]), joint,
                                                     point_at(points, arc, np.array([before[0], spans[k][1]]))):
            pins[k] = arc_nearest(points, arc, joint)
    missing = next((k for k in range(len(groups)) if all(span is None for span in spans[k:])), len(groups))
    if 0 < missing < len(groups):  # the chain's last roles are missing: the mesh may go on where they belong
        present = [k for k in range(missing) if spans[k] is not None]
        scale = (arc[-1] - spans[present[0]][0]) / lengths[present[0]:missing].sum()
        wanted = scale * lengths[missing:].sum()
        direction = points[-1] - points[-2]
        direction = direction / max(np.linalg.norm(direction), 1e-300)
        foot = foot_ahead(body.vertices, points[-1], body.faced, wanted) if groups[missing][0] == "foot" else None
        if foot is not None:  # a leg ending at the ankle: its foot runs forward on the ground, not on down the shin
            extended = True
            points = np.vstack([points, foot])
            arc = arc_lengths(points)
            spans[missing] = (arc[-3], arc[-1])
        else:
            bones = (body.skeleton.heads[others], body.skeleton.tails[others]) if len(others) else None
            reach = mesh_reach(body.vertices, points[-1], direction, tuning.extend_most * wanted, body.size, bones,
                               RoleTuning().other_part * body.size)
            extended = reach >= tuning.extend * wanted
            if extended:
                points = np.vstack([points, points[-1] + reach * direction])
                arc = np.r_[arc, arc[-1] + reach]
                spans[missing] = (arc[-2], arc[-1])
        lacking = "/".join(dict.fromkeys(role for group in groups[missing:] for role in group))
        body.notes.append(f"the skeleton has no {lacking}{f' ({side})' if side else ''}: placed " + (
            "where the mesh goes on past its last bone" if extended else "over its last bones"))
    cuts = _cuts(groups, spans, arc, lengths, tuning.shortest * body.size, tuning, pins)
    placed = point_at(points, arc, cuts)
    ends = {0: starts.get(0), len(groups): after}  # the chain's ends exactly there (a hip joint beside the path)
    for k, joint in ends.items():
        beside = placed[[i for i in (k - 1, k + 1) if 0 <= i < len(placed)]]
        limb_start = k == 0 and groups[0][0] in LIMB_STARTS
        if limb_start:  # the skeleton's bones meeting there count (a leg's hips bone above its thigh), not the limb's
            meeting = body.meeting(placed[k])
            own = np.linalg.norm(meeting[:, None] - points[None], axis=2).min(axis=1) <= tuning.merge * body.size
            beside = np.vstack([beside, meeting[~own]])
        if joint is not None and within_reach(placed[k], joint, beside, limb_start=limb_start):
            placed[k] = joint
    return body.local(placed)


def _next_role(role):
    """The role that follows ``role`` along a chain (``core.roles.CHAINS``: the neck after the chest), or None."""
    return next((chain[k + 1] for chain in CHAINS for k, name in enumerate(chain[:-1]) if name == role), None)


def _cuts(groups, spans, arc, lengths, shortest, tuning, named=None):
    """Arc positions of a chain's n + 1 joints along a path with joints at ``arc``: pinned where roles change
    (see the module docstring; at ``named[k]`` for the joints whose named joint lies there), the rest in the
    metarig's proportions ``lengths``, snapped to nearby joints; no two closer than ``shortest``."""
    count = len(groups)
    pins = [0.0] + [None] * (count - 1) + [arc[-1]]
    for k in range(1, count):
        if groups[k] == groups[k - 1]:
            continue
        pins[k] = spans[k][0] if spans[k] is not None else spans[k - 1][1] if spans[k - 1] is not None else None
        if named and k in named:
            pins[k] = named[k]
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
    gap = min(shortest, arc[-1] / count)  # no bone shorter than ``shortest`` (a chain too short: all alike)
    for k in range(1, count + 1):
        cuts[k] = max(cuts[k], cuts[k - 1] + gap)
    cuts[count] = arc[-1]
    for k in range(count - 1, 0, -1):
        cuts[k] = min(cuts[k], cuts[k + 1] - gap)
    return cuts


def _wrist(body, side, base):
    """Where the hand of skeleton side ``side`` begins, for a palm reaching ``base``: the hand's end farther from
    it, else (no hand bone) the forearm's end nearer it."""
    for roles, pick in ((("hand",), max), (("forearm",), min)):
        bones = body.bones_of(roles, side)
        if bones:
            points, _ = body.path(bones, lambda bone: 0, side)
            return pick((points[0], points[-1]), key=lambda end: np.linalg.norm(end - base))
    return None


def _palm_head(joints, meta, names, side):
    """A palm's head: as far from the wrist towards its finger as the metarig's is."""
    hand = meta[f"hand.{side}"]
    wrist, base = np.asarray(hand.head, float), np.asarray(meta[names[1]].head, float)
    share = float(np.clip((np.asarray(meta[names[0]].head) - wrist) @ (base - wrist) / max((base - wrist) @
                                                                                         (base - wrist), 1e-300),
                          0.0, 0.9))
    return joints[0] + share * (joints[1] - joints[0])


def _bent(joints, way):
    """How a limb's first joint lies off the line from its root to the end of its second bone: (the offset the way
    it should bend, the offset sideways, the reach, the unit vectors of both ways); the front is -Y."""
    root, middle, end = joints[0], joints[1], joints[2]
    length = float(np.linalg.norm(end - root))
    along = (end - root) / max(length, 1e-300)
    front = np.array([0.0, -1.0, 0.0]) * way
    front = front - (front @ along) * along
    front /= max(np.linalg.norm(front), 1e-300)
    sideways = np.cross(along, front)
    return float((middle - root) @ front), float((middle - root) @ sideways), length, front, sideways


def _forward_share(joints, way):
    """How far a limb's first joint lies off the line from its root to the end of its second bone, the way it should
    bend, as a share of that reach."""
    forward, _, reach, _, _ = _bent(joints, way)
    return forward / max(reach, 1e-300)


def _as_in_metarig(joints, meta_joints, way):
    """Where the metarig has a limb's first joint relative to its root and the end of its second bone, in units of
    that reach, placed on ``joints`` (a hidden knee above a hock)."""
    forward, _, length, _, _ = _bent(np.array(meta_joints), way)
    _, _, reach, front, _ = _bent(joints, way)
    along = (meta_joints[1] - meta_joints[0]) @ (meta_joints[2] - meta_joints[0]) / max(length, 1e-300) ** 2
    return joints[0] + along * (joints[2] - joints[0]) + forward / max(length, 1e-300) * reach * front


def _bend(joints, way, tuning):
    """Move the joint between a limb's first two bones so that it bends ``way``: at least ``bend`` of the limb's
    reach that way, at most ``tilt`` degrees sideways from it (none when it lies less than ``straight`` sideways);
    Rigify's IK bends the limb in the plane its chain bends in. A move longer than ``bend_move`` of the reach is not
    made (the skeleton bends that limb another way: its IK will too). Returns whether the limb now bends ``way``."""
    forward, aside, length, front, sideways = _bent(joints, way)
    if not length > 0 or not np.linalg.norm(front) > 0:
        return False
    wanted = max(forward, tuning.bend * length)
    limit = 0.0 if abs(aside) < tuning.straight * length else wanted * np.tan(np.radians(tuning.tilt))
    move = (wanted - forward) * front + (np.clip(aside, -limit, limit) - aside) * sideways
    if np.linalg.norm(move) > tuning.bend_move * length:
        return forward > 0 and abs(aside) <= forward * np.tan(np.radians(tuning.tilt))
    joints[1] = joints[1] + move
    return True


def _mirror_twins(fit, units, midline, tolerance, middle=None):
    """Make each unit of twin bones (``.L`` names; their ``.R`` twins) exact mirror images across the midline (the
    metarig's X = ``middle``, by default the median X of the bones of the ``midline`` chains) when all of them
    mirror within ``tolerance`` already; a midline chain all within it of the midline goes onto it. Returns
    ``middle``."""
    if middle is None:
        xs = [point[0] for chain in midline for name in chain if name in fit.heads
              for point in (fit.heads[name], fit.tails[name])]
        middle = float(np.median(xs)) if xs else 0.0
    for chain in midline:
        names = [name for name in chain if name in fit.heads]
        if names and max(abs(end[name][0] - middle) for name in names for end in (fit.heads, fit.tails)) <= tolerance:
            for name in names:
                for end in (fit.heads, fit.tails):
                    end[name] = np.r_[middle, end[name][1:]]

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


def _join_chains(fit, spec, meta):
    """Start each chain exactly where the metarig starts it on another chain's bone (the neck at the torso's end, a
    tail at the hips' start): Rigify connects such chains only when their ends coincide."""
    ends = np.array([end for bone in meta.values() for end in (bone.head, bone.tail)], dtype=np.float64)
    tolerance = 1e-4 * float(np.ptp(ends, axis=0).max())
    done = []
    for chain in spec.chains:
        for side in _sides(chain):
            names = chain.names(side)
            if names[0] in fit.heads:
                start = np.asarray(meta[names[0]].head, dtype=np.float64)
                for other in done:
                    for end, fitted in (("tail", fit.tails), ("head", fit.heads)):
                        if np.linalg.norm(np.asarray(getattr(meta[other], end)) - start) <= tolerance:
                            fit.heads[names[0]] = fitted[other].copy()
                            break
                    else:
                        continue
                    break
            done += [name for name in names if name in fit.heads]


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


def _roll_on(fit, meta):
    """Roll each placed bone connected to a placed parent as the metarig rolls it relative to that parent, where
    the metarig's own Z axis (``fit.z_axes``) would roll it more than a quarter turn from there. A bone pointing past
    that axis (a tail curling up over the back, where the metarig's runs back) turns it half a turn, and Rigify's
    bendy tail crumples at rest; a chain bent like the metarig's keeps the metarig's rolls."""
    def depth(name):
        parent = meta[name].parent
        return 0 if parent not in fit.heads else 1 + depth(parent)

    for name in sorted(fit.heads, key=depth):
        parent = meta[name].parent
        if parent not in fit.heads or not meta[name].connected:
            continue
        ways = [_unit(np.subtract(tail, head)) for head, tail in (
            (meta[parent].head, meta[parent].tail), (meta[name].head, meta[name].tail),
            (fit.heads[parent], fit.tails[parent]), (fit.heads[name], fit.tails[name]))]
        if any(way is None for way in ways) or ways[0] @ ways[1] <= 0 or ways[2] @ ways[3] <= 0:
            continue  # a turn this sharp carries no roll across
        meta_parent, meta_bone, parent_way, way = ways
        z_axes = [_across(meta[parent].z_axis, meta_parent), _across(meta[name].z_axis, meta_bone),
                  _across(fit.z_axes[parent], parent_way), _across(fit.z_axes[name], way)]
        if any(z is None for z in z_axes):
            continue
        meta_parent_z, meta_z, parent_z, own = z_axes
        carried = _across(between(meta_parent, meta_bone) @ meta_parent_z, meta_bone)  # the metarig's twist ...
        twist = np.arctan2(np.cross(carried, meta_z) @ meta_bone, carried @ meta_z)
        wanted = about(way, twist) @ _across(between(parent_way, way) @ parent_z, way)  # ... on the fitted chain
        if own @ wanted < 0:
            fit.z_axes[name] = wanted


def _unit(vector):
    norm = float(np.linalg.norm(vector))
    return np.asarray(vector, dtype=np.float64) / norm if norm > 1e-12 else None


def _across(vector, axis):
    """The unit part of ``vector`` across unit ``axis`` (None when it runs along it)."""
    vector = np.asarray(vector, dtype=np.float64)
    return _unit(vector - (vector @ axis) * axis)


def _within_body(fit, name, parent, body, tuning):
    """Pull the ends of derived bone ``name`` towards its ``parent`` bone to at most ``helper_depth`` of the mesh's
    half-thickness there (the distance from the parent's nearest point to the nearest mesh vertex): a thin body's
    pelvis and breast would stand out of it in the metarig's proportions."""
    start, span = fit.heads[parent], fit.tails[parent] - fit.heads[parent]
    for ends in (fit.heads, fit.tails):
        point = ends[name]
        share = np.clip((point - start) @ span / max(float(span @ span), 1e-300), 0.0, 1.0)
        anchor = start + share * span
        depth = float(np.linalg.norm(body.vertices - anchor @ body.frame.T, axis=1).min())  # in the mesh's frame
        off = point - anchor
        reach = float(np.linalg.norm(off))
        if reach > tuning.helper_depth * depth and depth >= tuning.shortest * body.size:  # none: on the surface
            ends[name] = anchor + off * (tuning.helper_depth * depth / reach)


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


def _notes(spec, fit, body):
    """What the fit left out and could not do, in words: one note per part the skeleton lacks."""
    removed, missing = set(fit.removed), {}
    for chain in spec.chains:
        for side in _sides(chain):
            names = chain.names(side)
            if all(name in removed for name in names):
                part = f"{chain.digit} finger" if chain.digit else "/".join(
                    role if isinstance(role, str) else "+".join(role) for role in dict.fromkeys(chain.roles))
                sides, bones = missing.setdefault(part, ([], []))
                sides.append(side)
                bones.extend(names)
    notes = [f"no {part}{' (' + ' and '.join(sides) + ')' if sides != [None] else ''} found on the model: "
             f"removed the metarig's {', '.join(bones)}" for part, (sides, bones) in missing.items()]
    notes += body.notes
    if body.side_map["L"] == "R":
        notes.append("the skeleton's .L limbs are on the character's right: Rigify's .L bones went to its left")
    return notes
