"""Body plans: what kind of body a skeleton rigs (humanoid, quadruped, bird, fish or serpent, other), how sure that is
and why, and which part each limb is; from geometry (``core.body``), whatever method made the skeleton.

The rules, in order (``Body`` gives the up axis, the mirror plane, the spine and the limbs):

- legs are limbs off the mirror plane that hang from at least ``leg_lift`` of the mesh's height and run down
  (``leg_drop``; toes along the ground aside) to near the ground (``leg_reach``);
- more than four legs, or legs standing in more than two rows along the body, make no known plan (``other``), nor
  do three or more pairs of long limbs (an octopus);
- legs in two rows, front and back (``front_back`` apart), make a quadruped;
- two legs in one row, hanging from ``biped_lift`` or higher, make a biped: a humanoid when its
  torso, from the hips to the spine's upper end, leans less than ``upright`` from up, or leans more but has round
  arms (a hunched monster); a bird when it leans forward with flat wings (``wing_flat``) or no arms; arms hang
  above the hips, else from the hips reaching out or up (``_chest``); none when the body hangs below its hips
  (``overturned``) or an upright torso runs on below them much farther than the legs reach (``tail_legs``: a head);
- without legs: one pair of long limbs on a small body is a bird in flight (wings); an upright body with long limbs
  high on it is a humanoid without legs; else a body with one pair of limbs at least ``wing_ratio`` times its
  length is a bird (a penguin); a long body lying down (the mesh lower than it is long) whose limbs are short
  beside it (fins, or none) and that tapers, curves or has fins is a fish or a serpent (not a plain log or
  column); anything else is ``other``.

Recognition also places the named joints along the chains (``core.roles``: a knee between bone ends where the
artists' rigs have it) and keeps them in ``BodyPlan.joints``.

The confidence multiplies how the up axis was found (legs on the ground, a flat bottom, or only the preferred up),
where the mirror plane came from and how clearly the deciding rule held.
"""
from dataclasses import dataclass, field, replace

import numpy as np

from .body import AXES, BodyTuning, read_body, spreads_across
from .facing import role_bones, toes_way
from .polyline import arc_lengths, length, nearest_on_segments
from .roles import RoleTuning, assign_roles, joint_places, twin_paths
from .stages import MirrorPlane
from .tuning import tuned

KINDS = ("humanoid", "quadruped", "bird", "fish", "other")
UNSURE = 0.5  # a plan recognised with less confidence than this comes with a warning
PARTS = ("leg", "arm", "wing", "fin", "ear", "tail", "jaw", "other")


@dataclass(frozen=True)
class BodyPlanTuning(BodyTuning, RoleTuning):
    """The tuned numbers of recognising a body plan and giving bones their roles (shares of the mesh size unless
    said otherwise)."""

    leg_lift: float = tuned(0.15, "a limb off the mirror plane is a leg when it hangs from this share of the mesh's "
                                  "height or higher (a cartoon cow's stubby legs from 0.2) ...")
    leg_drop: float = tuned(0.45, "... and its tip lies below where it hangs by this share of its length (a leg runs "
                                  "down; an arm reaching down and out, a blade in its hand, does not)")
    leg_reach: float = tuned(0.2, "... and reaches this low (a share of the height, the mesh around its tip "
                                  "included): the skeleton may stop short of the feet (a cartoon cow's at 0.17)")
    biped_lift: float = tuned(0.3, "legs in one row hang from this share of the height or higher (a bird's from "
                                   "0.42); lower ones are fins or stubs (a fish's fins hang from 0.2)")
    wing_flat: float = tuned(0.45, "a limb whose blade is this flat (thin across over wide across) or flatter is a "
                                   "wing or a fin (a bird's wings 0.2 to 0.35, arms 0.55 or rounder)")
    front_back: float = tuned(0.15, "feet this far apart along the body stand in two rows, front and back")
    ground_slack: float = tuned(0.02, "a leg runs down to where it comes this near (a share of the size) to its "
                                      "tip's height for good; toes along the ground beyond do not count")
    upright: float = tuned(45.0, "degrees: a biped whose torso leans less than this from up is a humanoid")
    overturned: float = tuned(100.0, "degrees: a biped whose body leans more than this from up hangs below its hips: "
                                     "no plan (a bird's body leans about 90)")
    tail_legs: float = tuned(1.3, "an upright biped whose spine runs on below its hips farther than this many times "
                                  "its legs is no plan (Suzanne's chin read as a tail 1.6; tailed bipeds up to 1.1)")
    long_limb: float = tuned(0.2, "limbs at least this long are arms, wings or legs; shorter ones ears, fins or stubs")
    small_body: float = tuned(0.25, "a spine shorter than this is a small body (a bat's, between its wings)")
    wing_ratio: float = tuned(1.3, "a legless body's one pair of long limbs this many times its spine's length are "
                                   "wings, unless high on an upright body (a penguin's flippers)")
    many_limbs: int = tuned(6, "this many long limbs off the plane besides the legs are no known plan (an "
                               "octopus; a humanoid has two arms and maybe two long ears)")
    fish_body: float = tuned(0.45, "a legless body with a spine at least this long may be a fish or a serpent")
    lying: float = tuned(55.0, "degrees: a fish's or serpent's spine, end to end, is at least this far from up")
    low_body: float = tuned(0.8, "... and the mesh is at most this many times as high as its spine is long (a fish "
                                 "with its fins 0.68, a snake 0.07; ears on a tall body are no fish)")
    fin_share: float = tuned(0.7, "a fish's limbs are shorter than this share of its spine (fins)")
    taper: float = tuned(1.3, "a body whose head end is this many times as thick as its tail end tapers")
    curve: float = tuned(1.15, "a spine this many times as long as its ends are apart curves")
    end_part: float = tuned(0.3, "the share of the spine's length at each end where head and tail are looked for")
    toes_reach: float = tuned(0.1, "a humanoid's feet point the way its mesh about its ankles lies: within this "
                                   "share of the size of each ankle across up, up to half that above it")


@dataclass(frozen=True)
class BodyPlan:
    """A recognised body plan: ``kind`` (one of ``KINDS``), ``confidence`` in [0, 1], a one-line ``reason``, counts
    of its ``parts`` ({"legs": 2, "arms": 2, ...}), the world ``up`` it stands along, where its named joints and
    landmarks lie on the skeleton it was recognised on (``joints``: ``core.roles.joint_places``; read them with
    ``core.roles.named_joints`` and ``landmarks``), and for a humanoid the way its mesh's feet point (``front``, a
    world direction: ``core.facing.toes_way``; None when they show none)."""

    kind: str
    confidence: float
    reason: str
    parts: dict = field(default_factory=dict)
    up: tuple = (0.0, 0.0, 1.0)
    joints: dict = field(default_factory=dict, repr=False)
    front: tuple = None

    def to_dict(self):
        """JSON-ready: kind, confidence, reason and parts (``up`` is in the world's frame, so left out)."""
        return {"kind": self.kind, "confidence": round(float(self.confidence), 3), "reason": self.reason,
                "parts": dict(self.parts)}

    @property
    def recognised(self):
        """Whether the plan is one Rigger knows (not ``other``)."""
        return self.kind != "other"

    @property
    def warning(self):
        """Why the plan was not recognised, or that it was only with a confidence under ``UNSURE``, for reports
        (None when it was surely)."""
        if not self.recognised:
            return f"body plan not recognised ({self.reason}); the rig stays plain, every bone's role 'other'"
        if self.confidence < UNSURE:
            return (f"body plan {self.kind} recognised with a low confidence, {self.confidence:.2f} ({self.reason}): "
                    f"check the bone roles (the game and rigify targets name and place bones by them)")
        return None

    def summary(self):
        """One line: "humanoid (0.99): 2 legs under ..."."""
        return f"{self.kind} ({self.confidence:.2f}): {self.reason}"


@dataclass(frozen=True)
class Layout:
    """How a body plan lays out a :class:`~rigger.core.body.Body`: the ``plan``, each limb's ``part`` (one of
    ``PARTS``) and whether it is a ``front`` leg, the ``spine`` joints from the tail end to the head end, the places
    on it (indices) of the ``hips`` and the ``chest`` (-1 when none) and the ``forward`` direction (None when not
    known)."""

    plan: BodyPlan
    parts: tuple
    front: tuple
    spine: tuple
    hips: int
    chest: int
    forward: np.ndarray


def recognise(skeleton, mesh, *, plane=None, prefer_up=AXES[2], tuning=BodyPlanTuning()):
    """(:class:`BodyPlan`, roles) of ``skeleton`` on ``mesh``: roles is one ``core.roles.BoneRole`` per bone.

    ``mesh`` is a ``core.mesh.Mesh`` or a (vertices, triangles) pair; ``plane`` a mirror plane the caller knows (a
    method's ``MirrorPlane`` stage); ``prefer_up`` the up the mesh's source assumes, which breaks ties (+Z in
    Blender, +Y for an OBJ file read as it is). ValueError for a mesh or skeleton that is not one.
    """
    from .mesh import Mesh
    from .skeleton import Skeleton

    if not isinstance(skeleton, Skeleton):
        raise ValueError(f"recognise needs a rigger Skeleton, got {type(skeleton).__name__}")
    if not isinstance(mesh, Mesh):
        try:
            vertices, triangles = mesh
        except (TypeError, ValueError):
            raise ValueError("mesh must be a rigger.core.mesh.Mesh or a (vertices, triangles) pair") from None
        mesh = Mesh(vertices, triangles)
    prefer_up = np.asarray(prefer_up, dtype=np.float64)
    if prefer_up.shape != (3,) or not np.isfinite(prefer_up).all() or not np.linalg.norm(prefer_up) > 0:
        raise ValueError(f"prefer_up must be a non-zero 3D vector, got {prefer_up.tolist()}")
    factor = mesh.unit_factor  # read at unit size (a power of two: exact), as the methods rig
    at_unit_size = Skeleton(skeleton.names, skeleton.heads * factor, skeleton.tails * factor, skeleton.parents)
    if plane is not None:
        plane = MirrorPlane(plane.axis, plane.offset * factor, plane.normal, plane.exact)
    body = read_body(at_unit_size, mesh.at_unit_size(), tuning, plane, prefer_up / np.linalg.norm(prefer_up))
    layout = lay_out(body, tuning)
    paths = twin_paths(body, tuning)
    roles = assign_roles(skeleton, body, layout, paths, tuning)
    plan = replace(layout.plan, joints=joint_places(at_unit_size, body, layout, paths, tuning))
    if plan.kind == "humanoid":
        toes = toes_way(body.vertices, _ankles(at_unit_size, roles, body.up), body.up,
                        tuning.toes_reach * body.size)
        if toes is not None and body.plane is not None:  # a front lies along the mirror plane: the rest is noise
            toes = toes - (toes @ body.plane.normal) * body.plane.normal
        clear = toes is not None and np.linalg.norm(toes) > 1e-9 * body.size  # a flat cut-out's feet point nowhere
        plan = replace(plan, front=tuple(float(v) for v in toes / np.linalg.norm(toes)) if clear else None)
    return plan, roles


def _ankles(skeleton, roles, up):
    """Per side, where the leg's foot begins, else its leg's lowest bone end."""
    ankles = []
    for side in ("L", "R"):
        feet, legs = role_bones(roles, ("foot",), side), role_bones(roles, ("thigh", "shin"), side)
        if feet:
            ankles.append(skeleton.heads[feet[0]])
        elif legs:
            ends = np.concatenate([skeleton.heads[legs], skeleton.tails[legs]])
            ankles.append(ends[np.argmin(ends @ up)])
    return ankles


def lay_out(body, tuning=BodyPlanTuning()):
    """The :class:`Layout` of ``body`` by the rules in this module's docstring."""
    limbs, size = body.limbs, body.size
    lengths = [body.limb_length(limb) for limb in limbs]
    legs = _legs(body, lengths, tuning)
    forward = _forward_axis(body, legs)
    rows = _rows(body, legs, forward, tuning)
    if len(rows) == 1 and (len(legs) < 2 or _low_slung(body, legs, tuning)):
        legs, rows = [], []  # fins, stubs or a lone leg: not legs a biped stands on
    long_pairs = _long_pairs(body, lengths, legs, tuning)
    spine_points = body.graph.points[list(body.spine)]
    spine_length = length(spine_points)
    confidence = _frame_confidence(body)
    parts = ["other"] * len(limbs)
    front = [False] * len(limbs)
    for k in legs:
        parts[k] = "leg"
    if len(legs) > 4 or len(rows) > 2:
        return _other(body, parts, f"{len(legs)} legs on the ground in {len(rows)} rows: not a body plan Rigger knows",
                      confidence)
    long_limbs = sum(len(pair) for pair in long_pairs)
    if long_limbs >= tuning.many_limbs:
        return _other(body, parts, f"{long_limbs} long limbs besides the legs: not a body plan Rigger knows",
                      confidence)
    if len(rows) == 2:
        spine, hips, chest = _quadruped_spine(body, rows, legs, lengths, tuning)
        forward = _headward(body, spine, forward)
        for k in max(rows, key=lambda row: np.mean([_tip(body, k) @ forward for k in row])):
            front[k] = True
        paired = all(limbs[k].twin in legs for k in legs)
        kind_confidence = confidence * (1.0 if len(legs) == 4 and paired else 0.8)
        _name_parts(body, parts, lengths, spine, hips, chest, "quadruped", tuning)
        reason = f"{len(legs)} legs standing front and back under a body" + ("" if len(legs) == 4 else
                                                                            " (the others hidden or missing)")
        return _layout(body, "quadruped", kind_confidence, reason, parts, front, spine, hips, chest, forward)
    if len(rows) == 1:
        spine, hips = _biped_spine(body, legs)
        lean = _lean(body, spine, hips)
        if lean > tuning.overturned:
            return _other(body, parts, f"{len(legs)} legs under a body leaning {lean:.0f} degrees, below its hips: "
                                       f"not a body plan Rigger knows", confidence)
        below = length(body.graph.points[list(spine[:hips + 1])])
        if lean < tuning.upright and below > tuning.tail_legs * max(lengths[k] for k in legs):
            return _other(body, parts, f"{len(legs)} legs under an upright torso that runs on below its hips farther "
                                       f"than they reach: not a body plan Rigger knows", confidence)
        paired = all(limbs[k].twin in legs for k in legs)
        margin = min(1.0, abs(lean - tuning.upright) / tuning.upright)
        chest = _chest(body, spine, hips, legs, lengths, tuning)
        arms = [k for k in range(len(limbs)) if k not in legs and limbs[k].side != 0 and lengths[k] >=
                tuning.long_limb * size and _spine_index(spine, body, k) == chest]
        winged = bool(arms) and max(body.flatness[k] for k in arms) <= tuning.wing_flat
        kind = "bird" if lean >= tuning.upright and (winged or not arms) else "humanoid"
        agrees = (kind == "humanoid") == (lean < tuning.upright)
        kind_confidence = confidence * (0.6 + 0.4 * margin if agrees else 0.6) \
            * (1.0 if paired and len(legs) == 2 else 0.85)
        _name_parts(body, parts, lengths, spine, hips, chest, kind, tuning)
        reason = (f"{len(legs)} legs under a torso leaning {lean:.0f} degrees, with " +
                  ("round arms" if arms else "no arms") if kind == "humanoid" else
                  f"{len(legs)} legs under a body leaning {lean:.0f} degrees, with " +
                  ("flat wings" if winged else "no wings"))
        return _layout(body, kind, kind_confidence, reason, parts, front, spine, hips, chest, forward)
    return _legless(body, parts, front, lengths, long_pairs, spine_length, forward, confidence, tuning)


def _legless(body, parts, front, lengths, long_pairs, spine_length, forward, confidence, tuning):
    """The layout of a body without legs (see the module docstring)."""
    size, graph = body.size, body.graph
    spine = list(body.spine)
    ends = graph.points[[spine[0], spine[-1]]]
    rise = _angle_from_up(body, ends[1] - ends[0]) if spine_length > 0 else 90.0
    longest_pair = max(long_pairs, key=lambda pair: max(lengths[k] for k in pair), default=())
    if long_pairs and spine_length < tuning.small_body * size:
        return _flying(body, parts, front, lengths, long_pairs, longest_pair, spine, forward, confidence, tuning,
                       "a pair of long limbs on a small body: wings, no legs")
    if long_pairs and min(rise, 180 - rise) < tuning.upright:
        upward = _upward(body, spine)
        heights = body.height(graph.points[upward])  # how high, not how far along: a head's wiggles add length
        low, high = float(heights.min()), float(heights.max())
        attach = [(heights[upward.index(body.bases[k])] - low) / max(high - low, 1e-300) for pair in long_pairs
                  for k in pair if body.bases[k] in upward]
        if attach and max(attach) >= 0.5:
            chest = _chest(body, upward, 0, [], lengths, tuning)
            _name_parts(body, parts, lengths, upward, 0, chest, "humanoid", tuning)
            return _layout(body, "humanoid", confidence * 0.7, "an upright body with arms high on it, no legs",
                           parts, front, upward, 0, chest, forward)
    if len(long_pairs) == 1 and len(longest_pair) == 2 and \
            spine_length * tuning.wing_ratio <= min(lengths[k] for k in longest_pair):
        return _flying(body, parts, front, lengths, long_pairs, longest_pair, spine, forward, confidence, tuning,
                       f"a pair of limbs at least {tuning.wing_ratio:g} times the spine's length: wings, no legs")
    longest = max(lengths, default=0.0)
    if spine_length >= tuning.fish_body * size and rise >= tuning.lying and 180 - rise >= tuning.lying \
            and longest < tuning.fin_share * spine_length and body.high - body.low <= tuning.low_body * spine_length:
        thin, thick = sorted(_end_thickness(body, spine, tuning))
        tapers = thick >= tuning.taper * max(thin, 1e-300)
        spread = _end_spread(body, spine, tuning)
        spine = spine if spread[1] >= spread[0] else spine[::-1]
        curves = spine_length >= tuning.curve * float(np.linalg.norm(ends[1] - ends[0]))
        if len(body.limbs) or tapers or curves:
            for k in range(len(parts)):
                parts[k] = "fin"
            what = "fins" if body.limbs else "no fins"
            return _layout(body, "fish", confidence * 0.85, f"one long body lying down, with {what}", parts, front,
                           spine, -1, -1, forward)
        return _other(body, parts, "one long body without fins that neither tapers nor curves (a log or a column)",
                      confidence)
    return _other(body, parts, _legless_reason(long_pairs, spine_length, size), confidence)


def _flying(body, parts, front, lengths, long_pairs, wings, spine, forward, confidence, tuning, reason):
    """The layout of a bird in flight: the pair ``wings`` on the spine, named from its lower end."""
    for k in wings:
        parts[k] = "wing"
    spine = _upward(body, spine)
    _name_parts(body, parts, lengths, spine, -1, 0, "bird", tuning)
    return _layout(body, "bird", confidence * (0.8 if len(long_pairs) == 1 else 0.65), reason, parts, front, spine,
                   -1, 0, forward)


def _legless_reason(long_pairs, spine_length, size):
    if not long_pairs:
        return f"no legs, no long limbs and a body {spine_length / size:.2f} of the size long: no known plan"
    return (f"no legs, {len(long_pairs)} pair(s) of long limbs: not wings (on a small body, or one pair much longer "
            f"than it) nor arms high on an upright body")


# Legs and where they stand.

def _legs(body, lengths, tuning):
    """Indices of the limbs that are legs (see the module docstring)."""
    limbs, size = body.limbs, body.size
    legs = set()
    for k, limb in enumerate(limbs):
        if lengths[k] >= tuning.min_limb * size and body.touches(limb.main[-1], tuning.leg_reach) \
                and body.height(body.graph.points[limb.attach]) >= tuning.leg_lift \
                and (limb.side != 0 or body.plane is None):
            drop, run = _descent(body, limb, tuning)
            if drop >= tuning.leg_drop * run:
                legs.add(k)
    return sorted(legs)


def _descent(body, limb, tuning):
    """(how far down, how long) a limb's main path runs from where it hangs to where it comes within
    ``ground_slack`` of the height of its tip to stay there, when what follows is the shorter part: toes along the
    ground after the foot reaches it (a bird's, a bone turned in along it) make a leg no less a leg, while a limb
    lying along the ground (a wing spread flat) runs as long as it is."""
    points = body.graph.points[list(limb.main)]
    heights = points @ body.up
    above = np.flatnonzero(heights > heights[-1] + tuning.ground_slack * body.size)
    down = int(above[-1]) + 1 if len(above) else 0
    descent, along = length(points[:down + 1]), length(points[down:])
    return float(heights[0] - heights[-1]), max(descent if along <= descent else descent + along, 1e-300)


def _tip(body, k):
    return body.graph.points[body.limbs[k].main[-1]]


def _forward_axis(body, legs):
    """A horizontal direction along the body (sign not yet known): across the mirror plane's normal, else the widest
    horizontal spread of the spine and the feet."""
    up = body.up
    if body.plane is not None:
        forward = np.cross(body.plane.normal, up)
        return forward / np.linalg.norm(forward)
    points = np.concatenate([body.graph.points[list(body.spine)], [_tip(body, k) for k in legs]]) \
        if legs else body.graph.points
    flat = points - np.outer(points @ up, up)
    flat = flat - flat.mean(axis=0)
    axes = np.linalg.svd(flat, full_matrices=False)[2] if len(flat) > 1 else np.eye(3)
    forward = axes[0] - (axes[0] @ up) * up
    if not np.linalg.norm(forward) > 1e-9:
        forward = np.cross(up, AXES[int(np.argmin(np.abs(up)))])
    return forward / np.linalg.norm(forward)


def _rows(body, legs, forward, tuning):
    """The legs in rows across the body: sorted along ``forward``, a new row where feet lie ``front_back`` apart."""
    if not legs:
        return []
    order = sorted(legs, key=lambda k: _tip(body, k) @ forward)
    rows = [[order[0]]]
    for before, k in zip(order, order[1:]):
        if (_tip(body, k) - _tip(body, before)) @ forward > tuning.front_back * body.size:
            rows.append([])
        rows[-1].append(k)
    return rows


def _long_pairs(body, lengths, legs, tuning):
    """Twin pairs (and single limbs off the plane) of long limbs that are not legs."""
    seen, pairs = set(), []
    for k, limb in enumerate(body.limbs):
        if k in seen or k in legs or limb.side == 0 or lengths[k] < tuning.long_limb * body.size:
            continue
        pair = (k,) if limb.twin < 0 else (k, limb.twin)
        seen.update(pair)
        pairs.append(pair)
    return pairs


# The spine: which end is the head, where the hips and the chest are.

def _spine_index(spine, body, k):
    base = body.bases[k]
    return spine.index(base) if base in spine else 0


def _biped_spine(body, legs):
    """(spine joints from the bottom up, index of the hips: where the legs hang)."""
    spine = _upward(body, list(body.spine))
    hips = int(round(np.median([_spine_index(spine, body, k) for k in legs])))
    if hips >= len(spine) - 1 and len(spine) > 1:  # the spine runs down from the hips: turn it round
        spine = spine[::-1]
        hips = len(spine) - 1 - hips
    return spine, hips


def _low_slung(body, legs, tuning):
    """Whether a row of ``legs`` hangs below ``biped_lift`` from a body that does not stand upright over them: a
    lying fish's fins, where a big-headed figure's short legs under its upright torso are legs."""
    low = min(body.height(body.graph.points[body.limbs[k].attach]) for k in legs) < tuning.biped_lift
    return low and _lean(body, *_biped_spine(body, legs)) >= tuning.upright


def _upward(body, spine):
    """The spine from its lower end to its upper end."""
    points = body.graph.points
    return spine if body.height(points[spine[-1]]) >= body.height(points[spine[0]]) else spine[::-1]


def _lean(body, spine, hips):
    """Degrees the torso (hips to the spine's upper end) leans from up."""
    if hips >= len(spine) - 1:
        return 90.0
    points = body.graph.points
    return _angle_from_up(body, points[spine[-1]] - points[spine[hips]])


def _angle_from_up(body, vector):
    norm = np.linalg.norm(vector)
    return float(np.degrees(np.arccos(np.clip(vector @ body.up / norm, -1, 1)))) if norm > 0 else 90.0


def _chest(body, spine, hips, legs, lengths, tuning):
    """Index of the chest on the spine: where the longest limbs off the plane that are not legs hang above the hips
    (hands on the hips may join an arm to them); else the hips, when such limbs hang there and reach out or up
    without running down as legs do (a gingerbread figure's torso is one junction); else -1."""
    best = None
    for k, limb in enumerate(body.limbs):
        if k in legs or limb.side == 0 or lengths[k] < tuning.min_limb * body.size:
            continue
        at = _spine_index(spine, body, k)
        level = (_tip(body, k) - body.graph.points[body.bases[k]]) @ body.up > -tuning.leg_drop * lengths[k]
        rank = (at > hips or not legs, at == hips and level, at < len(spine) - 1, lengths[k])
        if (rank[0] or rank[1]) and (best is None or rank > best[0]):
            best = (rank, at)
    return -1 if best is None else best[1]


def _quadruped_spine(body, rows, legs, lengths, tuning):
    """(spine joints from the tail end to the head end, hips index, chest index): the head end has the ears, is the
    higher and the thicker (``_head_score``); the hind legs hang nearer the tail end."""
    spine = list(body.spine)
    spine = spine if _head_score(body, spine[::-1], legs, lengths, tuning) <= \
        _head_score(body, spine, legs, lengths, tuning) else spine[::-1]
    places = [np.median([_spine_index(spine, body, k) for k in row]) for row in rows]
    hips, chest = int(round(min(places))), int(round(max(places)))
    return spine, hips, chest


def _head_score(body, spine, legs, lengths, tuning):
    """How much the last end of ``spine`` looks like a head, compared in this order: limbs (not legs) hanging near
    it, higher, thicker. Thickness only decides between ends as high: the spine may end in a thin neck before a big
    head (a crocodile's) while the rump is wide."""
    points = body.graph.points
    arc = arc_lengths(points[spine])
    near = arc >= arc[-1] * (1 - tuning.end_part)
    limbs = sum(1 for k in range(len(body.limbs)) if k not in legs and lengths[k] >= tuning.min_limb * body.size
                and body.bases[k] in spine and near[spine.index(body.bases[k])])
    thickness = _end_thickness(body, spine, tuning)
    return limbs, body.height(points[spine[-1]]) > body.height(points[spine[0]]), thickness[1] > thickness[0]


def _end_thickness(body, spine, tuning):
    """Largest mesh radius over the first and the last ``end_part`` of the spine's length: how thick each end of the
    body is, whether or not the spine runs on into the rounded tip (where any body is thin)."""
    points = body.graph.points[spine]
    if len(spine) < 2:
        return (float(body.radius[spine[0]]),) * 2
    arc = arc_lengths(points)
    radius = body.radius[spine]
    first = radius[arc <= arc[-1] * tuning.end_part]
    last = radius[arc >= arc[-1] * (1 - tuning.end_part)]
    return float(first.max()), float(last.max())


def _end_spread(body, spine, tuning):
    """How wide the mesh is across the spine over its first and last ``end_part``: the spreads (standard deviations)
    across the spine's end-to-end direction of the sampled vertices nearest there, the two added. A fish's head is
    wider than its tail, fins and all, where the mesh radius at joints misleads: joints in an open mouth, or on a
    flat profile, lie near the surface."""
    points = body.graph.points[list(spine)]
    arc = arc_lengths(points)
    direction = points[-1] - points[0]
    if len(spine) < 2 or not np.linalg.norm(direction) > 0:
        return 0.0, 0.0
    direction /= np.linalg.norm(direction)
    starts, ends = points[:-1], points[1:]
    nearest = nearest_on_segments(body.vertices, starts, ends)
    link = np.argmin(np.linalg.norm(body.vertices[:, None] - nearest, axis=2), axis=1)
    at = arc[link] + np.linalg.norm(nearest[np.arange(len(link)), link] - starts[link], axis=1)
    spreads = []
    for part in (at <= arc[-1] * tuning.end_part, at >= arc[-1] * (1 - tuning.end_part)):
        spreads.append(float(spreads_across(body.vertices[part], direction).sum()) if part.sum() > 1 else 0.0)
    return tuple(spreads)


# Parts and the result.

def _name_parts(body, parts, lengths, spine, hips, chest, kind, tuning):
    """Name the limbs that are not legs in ``parts``: arms or wings at the chest (the longest pair), ears on the head
    part of the spine, a jaw on the plane there, tails on the plane behind the hips, others ``other``."""
    points = body.graph.points
    arc = arc_lengths(points[spine]) if len(spine) > 1 \
        else np.zeros(1)
    head_from = max(chest, hips, 0)
    for k, limb in enumerate(body.limbs):
        if parts[k] != "other":
            continue
        at = _spine_index(spine, body, k)
        near_head = arc[at] >= arc[-1] * (1 - tuning.end_part) and at > head_from
        if limb.side != 0 and at == chest and lengths[k] >= tuning.min_limb * body.size:
            parts[k] = "wing" if kind == "bird" else "arm"
        elif near_head and limb.side != 0:
            parts[k] = "ear"
        elif near_head:
            parts[k] = "jaw"
        elif limb.side == 0 and hips >= 0 and at <= hips:
            parts[k] = "tail"
    for k, limb in enumerate(body.limbs):  # twins are one part
        if limb.twin >= 0 and parts[k] == "other" and parts[limb.twin] != "other":
            parts[k] = parts[limb.twin]


def _headward(body, spine, forward):
    """``forward`` turned to point from the spine's first end towards its last (the head)."""
    points = body.graph.points
    return -forward if len(spine) > 1 and (points[spine[-1]] - points[spine[0]]) @ forward < 0 else forward


def _layout(body, kind, confidence, reason, parts, front, spine, hips, chest, forward):
    if kind in ("quadruped", "bird", "fish"):
        forward = _headward(body, spine, forward)
    counts = {}
    for part in parts:
        counts[part + "s"] = counts.get(part + "s", 0) + 1
    counts.pop("others", None)
    plan = BodyPlan(kind, float(np.clip(confidence, 0.0, 1.0)), reason, counts, tuple(float(v) for v in body.up))
    return Layout(plan, tuple(parts), tuple(front), tuple(spine), hips, chest, forward)


def _other(body, parts, reason, confidence):
    return _layout(body, "other", confidence * 0.8, reason, ["other"] * len(parts), [False] * len(parts),
                   list(body.spine), -1, -1, _forward_axis(body, []))


def _frame_confidence(body):
    """How sure the frame is: up from legs on the ground, a flat bottom or only the preferred up; the mirror plane
    from the method or the mesh, fitted to the skeleton, or none."""
    up = {"legs": 1.0, "flat": 0.85}.get(body.up_evidence, 0.65)
    plane = 0.8 if body.plane is None else 0.9 if body.plane.source == "fitted" else 1.0
    return up * plane
