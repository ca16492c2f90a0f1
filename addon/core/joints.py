"""Where joints go along a chain (a 3D polyline through a part), and mirror twins given mirror-image joints."""
from dataclasses import dataclass, replace

import numpy as np

from .mirror import mirror_chain_pairs, mirrored
from .polyline import arc_lengths, arc_nearest, length, point_at, resampled
from .tuning import TuningTable, tuned


@dataclass(frozen=True)
class JointTuning(TuningTable):
    """The tuned numbers of cutting chains into bones (in bone lengths unless said otherwise)."""

    longest_bone: float = tuned(3.0, "no bone is longer, whatever max_bones says: a straight leg still gets a knee")
    longest_share: float = tuned(0.5, "nor, beyond its base's disc, longer than this share of its chain unless that "
                                      "asks for one bone: the joints a leg needs at hip and ankle leave thigh and "
                                      "shin no single bone")
    joint_spacing: float = tuned(0.35, "joint candidates closer than this to a joint already placed are dropped")
    leaf_two_bones: float = tuned(0.5, "a leaf chain this long gets two bones, as the artists' leaf chains have")
    trunk_bones: int = tuned(4, "a body's trunk gets this many bones at least (max_bones allowing), as a torso bends "
                                "at hips, waist and chest: Rigify's spine to spine.003, Mixamo's Hips to Spine2")
    disc_exit: float = tuned(0.3, "the joint where a chain leaves its branch point's disc is this far along at least")
    disc_exit_rest: float = tuned(0.5, "... and this much of the chain lies beyond it")
    corner_tolerance: float = tuned(0.25, "corners are measured on the chain simplified within this: no jitter stubs")
    narrowing: float = tuned(0.9, "spare bones go first to where a part narrows to this share of its width on both "
                                  "sides within a bone length (a knee, an elbow, a wrist)")
    spare_bend: float = tuned(0.5, "spare bones go to bends a straight bone would leave the part's middle at, this "
                                   "share of the half-width off")


@dataclass(frozen=True)
class Cutting:
    """How chains are cut into bones: ``bone_angle`` (radians) a chain turns by for a corner joint, the
    ``bone_length`` (mesh units), ``max_bones`` per chain (0: no limit) and the ``tuning``."""

    bone_angle: float
    bone_length: float
    max_bones: int
    tuning: JointTuning


def chain_joints(line, cutting, widths=None, leaf=False, min_bones=0):
    """Joint positions along a polyline.

    ``widths`` are the half-widths of the part along the line. A chain leaving a branch point first gets a joint
    where it leaves that point's disc (``widths[0]``): a hip, a shoulder. Every corner where the line turns by more
    than the bone angle gets a joint (an elbow, a knee), and so does every bend that would take a straight bone out
    of the part, the sharpest first where two are close. The chain has one bone per bone length begun (the artist
    rigs give a chain about one bone more than length / bone length: a hand, a foot), at most ``max_bones`` unless
    those joints need more, leave a piece between them whose bones would be longer than ``longest_share`` of the
    chain, a bone would exceed ``longest_bone``, or ``min_bones`` (its twin's count) asks for more.
    Spare bones go to the gentler bends, from the start: they place joints but add none (every wiggle of a feathered
    wing would be a bone), and take none a long piece needs. The pieces between joints are cut evenly. A ``leaf``
    chain (a finger, a toe) long enough gets at least two bones.
    """
    tuning, bone_length = cutting.tuning, cutting.bone_length
    widths = np.zeros(len(line)) if widths is None else widths
    arc = arc_lengths(line)
    wanted = max(1, int(np.ceil(arc[-1] / bone_length - 1e-9)))  # one bone per bone length begun
    if leaf and arc[-1] >= tuning.leaf_two_bones * bone_length:
        wanted = max(wanted, 2)
    if cutting.max_bones > 0:
        wanted = min(wanted, cutting.max_bones)
    wanted = max(wanted, min_bones)
    stops, places = [0.0, arc[-1]], [line[0], line[-1]]
    candidates, needed, inside = _candidate_stops(line, arc, widths, cutting)
    points = point_at(line, arc, np.array(candidates, dtype=float))
    spacing = tuning.joint_spacing * bone_length
    _place(stops, places, candidates[:needed], points[:needed], spacing)
    uneven = (wanted, max(tuning.longest_share, 1.0 / wanted) * arc[-1], inside)
    extra = _uneven(stops, *uneven)  # a leg's thigh and shin, left one piece
    _place(stops, places, candidates[needed:], points[needed:], spacing, spare=uneven)
    stops.sort()
    lengths = np.diff(stops)
    counts = _share(lengths, wanted + extra)
    counts = np.maximum(counts, np.ceil(lengths / (tuning.longest_bone * bone_length)).astype(int))
    at = [0.0]
    for start, piece, count in zip(stops[:-1], lengths, counts):
        at.extend(start + piece * np.arange(1, count + 1) / count)
    return point_at(line, arc, np.array(at))


def _candidate_stops(line, arc, widths, cutting):
    """Arc lengths where a joint belongs, most important first, how many of them are needed, and where the chain
    leaves its branch point's disc (0 when it gets no joint there). Needed: leaving that disc, corners by how
    sharply they turn and the bends a straight bone would leave the part at (its axis farther than a half-width
    away); then, for the bones to spare, the bends it would leave the part's middle at."""
    tuning, bone_length = cutting.tuning, cutting.bone_length
    found = []
    reach = np.linalg.norm(line - line[0], axis=1)
    outside = np.flatnonzero(reach > widths[0]) if widths[0] > 0 else []
    if len(outside) and arc[outside[0]] >= tuning.disc_exit * bone_length and (
            arc[-1] - arc[outside[0]] >= tuning.disc_exit_rest * bone_length):
        found.append(arc[outside[0]])
    inside = found[0] if found else 0.0
    turns = _turns(line, np.full(len(line), tuning.corner_tolerance * bone_length))
    found += [arc[i] for i, angle in sorted(turns, key=lambda item: -item[1]) if angle > cutting.bone_angle]
    if not widths.any():
        return found, len(found), inside
    found += [arc[i] for i in _simplified(line, np.maximum(widths, 1e-12 * bone_length))[1:-1]]
    needed = len(found)
    found += [arc[i] for i in _narrowings(arc, widths, tuning.narrowing, bone_length)]
    found += [arc[i] for i in _simplified(line, np.maximum(tuning.spare_bend * widths, 1e-12 * bone_length))[1:-1]]
    return found, needed, inside


def _narrowings(arc, widths, ratio, reach):
    """Nodes where the part narrows, narrowest first: the least half-width within ``reach`` (arc length) either
    side, and at most ``ratio`` times the widest on each side within that reach (a knee between thigh and calf, an
    elbow, a wrist); not within ``reach`` of the chain's end, where a part tapers to its tip."""
    arc, widths = arc.tolist(), widths.tolist()  # plain floats: a loop over the nodes, each with a short window
    first, last, found = 0, 0, []
    for i in range(1, len(arc) - 1):
        here = arc[i]
        while arc[first] < here - reach:
            first += 1
        while last + 1 < len(arc) and arc[last + 1] <= here + reach:
            last += 1
        if here > arc[-1] - reach or widths[i] > min(widths[first:last + 1]):
            continue
        before = [w for a, w in zip(arc[first:i], widths[first:i]) if a < here]
        after = [w for a, w in zip(arc[i + 1:last + 1], widths[i + 1:last + 1]) if a > here]
        if before and after and widths[i] <= ratio * min(max(before), max(after)):
            found.append((widths[i] / min(max(before), max(after)), i))
    return [i for _, i in sorted(found)]


def _place(stops, places, candidates, points, spacing, spare=None):
    """Add the ``candidates`` (arc lengths, at ``points``) in order to ``stops`` and ``places``, each not within
    ``spacing`` of a joint placed. With ``spare`` (:func:`_uneven`'s bones, longest and inside), until the stops cut
    the chain into that many pieces, and none that leaves a piece those bones would cut into bones too long."""
    for at, place in zip(candidates, points):
        if spare is not None and len(stops) > spare[0]:
            return  # no bone to spare for this bend (nor for the gentler ones after it)
        if min(np.linalg.norm(place - other) for other in places) < spacing or (
                spare is not None and _uneven(stops + [at], *spare)):
            continue
        stops.append(at)
        places.append(place)


def _uneven(stops, wanted, longest, inside):
    """Bones to add to ``wanted`` so that no piece between these ``stops`` (arc lengths) is cut into bones longer
    than ``longest`` when the bones are shared over the pieces; the piece inside the branch point's disc (up to
    ``inside``) does not count: a hip's connector in the pelvis needs no joint of its own."""
    stops = np.sort(stops)
    lengths = np.diff(stops)
    over = np.ceil(lengths / longest - 1e-9) - _share(lengths, wanted)
    return int(np.maximum(over[stops[:-1] >= inside], 0).sum())


def _share(lengths, total):
    """Split ``total`` bones over pieces of the given lengths, at least one each, the rest by largest remainder."""
    counts = np.ones(len(lengths), dtype=int)
    spare = total - len(lengths)
    if spare > 0 and lengths.sum() > 0:
        ideal = lengths / lengths.sum() * total - 1
        extra = np.floor(np.clip(ideal, 0, None)).astype(int)
        while extra.sum() > spare:
            extra[np.argmax(extra)] -= 1
        left = spare - extra.sum()
        order = np.argsort(-(ideal - extra))
        extra[order[:left]] += 1
        counts += extra
    return counts


def _simplified(line, tolerance):
    """Indices kept by Douglas-Peucker simplification (iterative) with a per-point tolerance."""
    n = len(line)
    if n <= 2:
        return [0, n - 1]
    keep = np.zeros(n, bool)
    keep[[0, n - 1]] = True
    stack = [(0, n - 1)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        seg = line[b] - line[a]
        rel = line[a + 1:b] - line[a]
        length = np.linalg.norm(seg)
        if length > 0:
            dist = np.linalg.norm(rel - np.outer(rel @ seg / length ** 2, seg), axis=1)
        else:
            dist = np.linalg.norm(rel, axis=1)
        excess = dist - tolerance[a + 1:b]
        far = int(np.argmax(excess))
        if excess[far] > 0:
            keep[a + 1 + far] = True
            stack += [(a, a + 1 + far), (a + 1 + far, b)]
    return list(np.flatnonzero(keep))


def _turns(line, tolerance):
    """(index, turning angle) at each inner vertex of the simplified ``line``."""
    idx = _simplified(line, tolerance)
    turns = []
    for prev, here, nxt in zip(idx[:-2], idx[1:-1], idx[2:]):
        u, w = line[here] - line[prev], line[nxt] - line[here]
        cos = float(u @ w) / max(np.linalg.norm(u) * np.linalg.norm(w), 1e-300)
        turns.append((here, float(np.arccos(np.clip(cos, -1.0, 1.0)))))
    return turns


def symmetric_joints(chains, cutting, symmetry):
    """Joints along each of the (polyline, half-widths or None, is a leaf) ``chains`` (``chain_joints``), each pair
    of mirror twins (``mirror_chain_pairs``) given mirror-image joints where the mesh allows, so every bone has a
    twin in the mirrored place (``.L`` and ``.R``, X-mirror posing).

    Twins whose lines agree (``Symmetry.agree``) are one limb traced twice: both get the average of their own joints,
    mirrored, when the lines have one shape, else the joints of their mean line (each placed its knee otherwise).
    Where one runs on along the other's image past its tip (pruning kept a hand's branch on one side only), both get
    the joints of one of them: the shorter's when the longer is a leaf (both arms end at the wrist), else the
    longer's when the shorter is a leaf. Twins whose lines differ (a leg stepping forward) keep their own joints but
    get one bone count: the smaller, unless the other's corners or the longest bone need more, then the larger.
    Each chain keeps its first joint, where it attaches to its parent.

    Across a plane the body only roughly mirrors about (``symmetry`` not exact: a posed or hand-made figure, whose
    twins are no images of each other) twins get one bone count and their joints meet halfway (``_met_halfway``);
    those that then nearly mirror each other (``_nearly_mirrored``) move to their mean, mirror images across the
    body's ``middle``.
    """
    chains = [(line, np.zeros(len(line)) if widths is None else widths, leaf) for line, widths, leaf in chains]
    joints = [chain_joints(line, cutting, widths, leaf) for line, widths, leaf in chains]
    lines = [line for line, _, _ in chains]
    close = []  # (i, j, which of their joints nearly mirror) across a rough plane
    for i, j in mirror_chain_pairs(lines, symmetry):
        shared = (_shared_joints(chains[i], chains[j], joints[i], joints[j], cutting, symmetry) if symmetry.exact
                  else None)
        if shared is not None:
            joints[i] = np.vstack([joints[i][:1], shared[0][1:]])
            joints[j] = np.vstack([joints[j][:1], shared[1][1:]])
            continue
        if len(joints[i]) != len(joints[j]):
            joints[i], joints[j] = _one_count(chains[i], chains[j], joints[i], joints[j], cutting)
        if not symmetry.exact:
            joints[i], joints[j] = _met_halfway(lines[i], lines[j], joints[i], joints[j], symmetry)
            close.append((i, j, _nearly_mirrored(chains[i], chains[j], joints[i], joints[j], symmetry)))
    for i, j, near in close:
        joints[i][near] = (joints[i][near] + mirrored(joints[j][near], symmetry.twin_plane)) / 2
        joints[j][near] = mirrored(joints[i][near], symmetry.twin_plane)
    return joints


def _shared_joints(chain, twin, joints, twin_joints, cutting, symmetry):
    """The joints of ``chain`` and of its mirror ``twin`` made mirror images where their lines agree, or None when
    their lines differ. Twins whose tips match share the average of their own ``joints`` and the image of
    ``twin_joints``, recounted to one count, when their lines have one shape (``Symmetry.same_shape``), else the
    joints of their mean line; a twin running on past the other's tip shares the joints of the one whose joints both
    can take. A leaf running on past a twin that goes on in the chains hanging from it (a wing traced from the body
    on one side, from a shoulder junction on the other) takes the twin's image as far as it goes and its own joints
    beyond."""
    (line, widths, leaf), (other, other_widths, other_leaf) = chain, twin
    image = symmetry.reflect(other)
    if not symmetry.agree(line, image):
        return None
    longer_is_chain = length(line) >= length(image)
    longer, shorter = (line, image) if longer_is_chain else (image, line)
    if np.linalg.norm(longer[-1] - shorter[-1]) <= symmetry.tolerance:
        if len(joints) != len(twin_joints):
            joints, twin_joints = _one_count(chain, twin, joints, twin_joints, cutting)
        if symmetry.same_shape(line, image):
            shared = (joints + symmetry.reflect(twin_joints)) / 2
        else:
            count = max(len(line), len(other))
            mean = (resampled(line, count) + resampled(image, count)) / 2
            fractions = np.linspace(0.0, 1.0, count)
            mean_widths = (_at_fractions(line, widths, fractions) + _at_fractions(other, other_widths, fractions)) / 2
            shared = chain_joints(mean, cutting, mean_widths, leaf and other_leaf)
        return shared, symmetry.reflect(shared)
    shorter_leaf, longer_leaf = (other_leaf, leaf) if longer_is_chain else (leaf, other_leaf)
    if longer_leaf and not shorter_leaf:
        if longer_is_chain:
            return _run_on(chain, symmetry.reflect(twin_joints), cutting), twin_joints
        return joints, _run_on(twin, symmetry.reflect(joints), cutting)
    if shorter_leaf or longer_leaf:
        lead_is_chain = longer_is_chain != longer_leaf  # the shorter leads when the longer can be cut back
        shared = joints if lead_is_chain else symmetry.reflect(twin_joints)
        return shared, symmetry.reflect(shared)
    return None


def _run_on(chain, image_joints, cutting):
    """The joints of the leaf ``chain`` ((polyline, half-widths, is a leaf)) that runs on past its shorter twin:
    ``image_joints`` (the twin's, mirrored) up to where the twin ends, then the chain's own joints on the rest."""
    line, widths, _ = chain
    arc = arc_lengths(line)
    start = arc_nearest(line, arc, image_joints[-1])
    beyond = arc > start
    rest = np.vstack([point_at(line, arc, np.array([start])), line[beyond]])
    rest_widths = np.concatenate([np.interp([start], arc, widths), widths[beyond]])
    if len(rest) < 2:
        return image_joints
    return np.vstack([image_joints, chain_joints(rest, cutting, rest_widths, leaf=True)[1:]])


def _met_halfway(line, other, joints, other_joints, symmetry):
    """The joints of twins whose lines are no mirror images of each other (one count each), each moved along its
    own line halfway to where its twin's image falls on that line, first joints kept: the k-th joints of both
    then lie as nearly mirrored as the two lines allow, so posing one side and mirroring it bends both alike."""
    arcs = arc_lengths(line), arc_lengths(other)
    if not (arcs[0][-1] > 0 and arcs[1][-1] > 0):
        return joints, other_joints
    moved = []
    for points, arc, own, twin in ((line, arcs[0], joints, other_joints), (other, arcs[1], other_joints, joints)):
        along = [(arc_nearest(points, arc, joint) + arc_nearest(points, arc, image)) / 2
                 for joint, image in zip(own[1:], symmetry.reflect(twin[1:]))]
        moved.append(np.vstack([own[:1], point_at(points, arc, np.array(along))]))
    return moved[0], moved[1]


def _nearly_mirrored(chain, twin, joints, twin_joints, symmetry):
    """Which k-th joints of twins across a plane the body only roughly mirrors about (one count each, met halfway)
    nearly mirror each other: within the twin tolerance, and within both limbs' half-widths, so their mean lies in
    both limbs (a shoulder; not the elbow of an arm raised while its twin hangs). First joints are attached."""
    gaps = np.linalg.norm(joints - symmetry.reflect(twin_joints), axis=1)
    reach = np.minimum(_widths_at(chain, joints), _widths_at(twin, twin_joints))
    close = (gaps <= symmetry.tolerance) & (gaps <= 2 * reach)
    close[0] = False
    return close


def _widths_at(chain, joints):
    """The half-width of the (polyline, half-widths, is a leaf) ``chain``'s part where each of ``joints`` lies."""
    line, widths, _ = chain
    arc = arc_lengths(line)
    return np.interp([arc_nearest(line, arc, joint) for joint in joints], arc, widths)


def _at_fractions(line, values, fractions):
    """``values`` given at the points of ``line``, at the fractions of its arc length."""
    arc = arc_lengths(line)
    return np.interp(fractions * arc[-1], arc, values)


def _one_count(chain, twin, joints, twin_joints, cutting):
    """Both chains' own joints, recounted to one bone count: the smaller, rising while the one recounted needs more
    (its corners, or no bone longer than ``longest_bone``) until both agree."""
    pair = [chain, twin]
    counts = [joints, twin_joints]

    def recount(k, max_bones, min_bones):
        line, widths, leaf = pair[k]
        return chain_joints(line, replace(cutting, max_bones=max_bones), widths, leaf, min_bones)

    more, fewer = (0, 1) if len(joints) > len(twin_joints) else (1, 0)
    counts[more] = recount(more, len(counts[fewer]) - 1, 0)
    while len(counts[more]) != len(counts[fewer]):  # the count only grows, up to what both need
        more, fewer = (more, fewer) if len(counts[more]) > len(counts[fewer]) else (fewer, more)
        counts[fewer] = recount(fewer, len(counts[more]) - 1, len(counts[more]) - 1)
    return counts
