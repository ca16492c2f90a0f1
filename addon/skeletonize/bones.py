"""Bones from 3D chains: where joints go along a chain, the mesh's mirror plane (and its reflection in a view), mirror
pairs of chains with mirror-image joints, and names with mirror suffixes."""
import numpy as np

from .polyline import arc_lengths, length, point_at, resampled, segment_distances

LONGEST = 3.0  # no bone longer than this many bone lengths, whatever max_bones says (a straight leg gets a knee)
SAME_SHAPE = 0.6  # mirror-pair chains get mirror-image joints when their shapes agree this closely (in tolerances)
SHAPE_SAMPLES = 9  # points along each chain compared for that
ALONG_PLANE = 1e-6  # a view whose direction has no larger component along a mirror plane's axis looks along it


def chain_joints(line, bone_angle, bone_length, max_bones=0, widths=None, leaf=False, min_bones=0):
    """Joint positions along a polyline.

    ``widths`` are the half-widths of the part along the line. A chain leaving a branch point first gets a joint
    where it leaves that point's disc (``widths[0]``): where a limb meets the body, like a hip or a shoulder. Every
    corner where the simplified line turns by more than ``bone_angle`` radians gets a joint (an elbow, a knee), and
    so does every bend that would take a straight bone out of the part (a snake's curves), the sharpest first where
    two lie closer than a third of a bone (measured straight: a line that jitters in depth makes no stub bones).
    The chain has one bone per bone length begun (``ceil(length / bone_length)``: the artist rigs of the quality
    benchmark give a chain about one more bone than ``length / bone_length``, a hand or a foot), at most
    ``max_bones`` when positive unless those joints need more or a bone would be longer than ``LONGEST`` bone
    lengths. Bones to spare go to the gentler bends that would take a straight bone out of the part's middle, from
    the chain's start: these place joints but add none (every wiggle of a feathered wing's outline would otherwise
    be a bone). The pieces between joints are cut evenly. A ``leaf`` chain (ending in a tip: a finger, a toe) at
    least half a bone long gets at least two bones, as the artists' leaf chains that long have (1.9 on average). A
    chain gets at least ``min_bones`` (its mirror twin's count), whatever ``max_bones`` says.
    """
    widths = np.zeros(len(line)) if widths is None else widths
    arc = arc_lengths(line)
    wanted = max(1, int(np.ceil(arc[-1] / bone_length - 1e-9)))  # one bone per bone length begun
    if leaf and arc[-1] >= 0.5 * bone_length:
        wanted = max(wanted, 2)
    if max_bones > 0:
        wanted = min(wanted, max_bones)
    wanted = max(wanted, min_bones)
    stops, places = [0.0, arc[-1]], [line[0], line[-1]]
    candidates, needed = _candidate_stops(line, arc, widths, bone_angle, bone_length)
    for k, (at, place) in enumerate(zip(candidates, point_at(line, arc, np.array(candidates, dtype=float)))):
        if k >= needed and len(stops) > wanted:
            break  # no bone to spare for this bend (nor for the gentler ones after it)
        if min(np.linalg.norm(place - other) for other in places) >= 0.35 * bone_length:
            stops.append(at)
            places.append(place)
    stops.sort()
    lengths = np.diff(stops)
    counts = _share(lengths, wanted)
    counts = np.maximum(counts, np.ceil(lengths / (LONGEST * bone_length)).astype(int))
    at = [0.0]
    for start, length, count in zip(stops[:-1], lengths, counts):
        at.extend(start + length * np.arange(1, count + 1) / count)
    return point_at(line, arc, np.array(at))


def mirrored(points, plane):
    """A copy of ``points`` (..., 3) reflected across ``plane`` = (axis, offset)."""
    axis, offset = plane
    image = np.array(points, dtype=float)
    image[..., axis] = 2 * offset - image[..., axis]
    return image


def reflection_in_view(sil, plane):
    """The reflection across ``plane`` = (axis, offset) of points (P, 2) in the plane of view ``sil`` (a
    ``Silhouette``), or None when there is no plane or the view does not look along it (``ALONG_PLANE``): seen
    from the side, a plane's two halves hide each other."""
    if plane is None or abs(sil.direction[plane[0]]) > ALONG_PLANE:
        return None
    return lambda points: sil.project(mirrored(sil.lift(points, 0.0), plane))[0]


def mirror_in_depth(sil, plane, tolerance):
    """(depth, ``tolerance``) of ``plane`` = (axis, offset) along view ``sil`` when the view looks straight across
    it (along its axis, as ``ALONG_PLANE`` allows), else None: ``depth.place_chains``' ``mirror``."""
    if plane is None or abs(abs(sil.direction[plane[0]]) - 1) > ALONG_PLANE:
        return None
    axis, offset = plane
    return float((offset - sil.origin[axis]) * sil.direction[axis]), tolerance


def _candidate_stops(line, arc, widths, bone_angle, bone_length):
    """Arc lengths where a joint belongs, most important first, and how many of them are needed: leaving the branch
    point's disc, corners by how sharply they turn and the bends a straight bone would leave the part at (its axis
    farther than a half-width away); then, for the bones to spare, the bends it would leave the part's middle at
    (half a half-width)."""
    found = []
    reach = np.linalg.norm(line - line[0], axis=1)
    outside = np.flatnonzero(reach > widths[0]) if widths[0] > 0 else []
    if len(outside) and arc[outside[0]] >= 0.3 * bone_length and arc[-1] - arc[outside[0]] >= 0.5 * bone_length:
        found.append(arc[outside[0]])
    turns = _turns(line, np.full(len(line), 0.25 * bone_length))
    found += [arc[i] for i, angle in sorted(turns, key=lambda item: -item[1]) if angle > bone_angle]
    if not widths.any():
        return found, len(found)
    found += [arc[i] for i in _simplified(line, np.maximum(widths, 1e-12 * bone_length))[1:-1]]
    needed = len(found)
    found += [arc[i] for i in _simplified(line, np.maximum(0.5 * widths, 1e-12 * bone_length))[1:-1]]
    return found, needed


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


def mirror_plane(vertices, bounds, tolerance, samples=600):
    """The axis (0, 1, 2) and offset of a plane the ``vertices`` are mirror-symmetric about, or None.

    Tries the planes through the centre of ``bounds`` (their (2, 3) bounding box) perpendicular to X, Y and Z where the
    box is more than two ``tolerance`` deep; a plane fits when at least 95% of (up to ``samples``) vertices have a
    mirror image among the vertices within ``tolerance``: vertices are hashed to a grid of that size and the mirrored
    ones looked up in the sorted hashes, with their 26 neighbour cells.
    """
    low, high = bounds
    origin = low - 2 * tolerance
    span = np.floor((high - low) / tolerance).astype(np.int64) + 5
    table = np.unique(_cell_keys(np.floor((vertices - origin) / tolerance).astype(np.int64), span))
    step = max(1, len(vertices) // samples)
    probe = vertices[::step]
    offsets = np.array([(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)])
    best = None
    for axis in np.flatnonzero(high - low > 2 * tolerance):  # across a flat mesh's own plane nothing has a side
        centre = 0.5 * (low[axis] + high[axis])
        cells = np.floor((mirrored(probe, (axis, centre)) - origin) / tolerance).astype(np.int64)
        around = np.clip(cells[:, None, :] + offsets[None], 0, span - 1).reshape(-1, 3)
        keys = _cell_keys(around, span)
        at = np.minimum(np.searchsorted(table, keys), len(table) - 1)
        score = (table[at] == keys).reshape(len(probe), -1).any(axis=1).mean()
        if score >= 0.95 and (best is None or score > best[2]):
            best = (int(axis), centre, score)
    return None if best is None else best[:2]


def _cell_keys(cells, span):
    return (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]


def mirror_chain_pairs(lines, plane, tolerance):
    """Pairs (i, j) of chains (3D polylines) that are mirror images of each other across ``plane`` = (axis, offset):
    their ends match the mirrored ends within ``tolerance``; then, among the chains left, those whose starts match
    within two tolerances and where one's tip lies within one tolerance of the other's image (a hand whose finger's
    branch was pruned on one side only: one arm runs on into the hand). Chains on the plane are never paired; one
    that lies on it on average but whose tip is off it (legs from the middle of the hips, antennae from the middle
    of the head) is on its tip's side."""
    ends = np.array([[line[0], line[-1]] for line in lines])  # (C, 2, 3)
    images = mirrored(ends, plane)
    side = np.array([_side(line, plane, tolerance, by_tip=True) for line in lines])
    pairs, taken = [], np.zeros(len(lines), bool)
    for partial in (False, True):
        for i in range(len(lines)):
            if taken[i] or side[i] == 0:
                continue
            candidates = (side == -side[i]) & ~taken
            if partial:
                j = _partial_twin(lines, mirrored(lines[i], plane), candidates, tolerance)
            else:
                cost = np.where(candidates, np.linalg.norm(ends - images[i], axis=2).sum(axis=1), np.inf)
                j = int(np.argmin(cost)) if cost.min() <= 2 * tolerance else None
            if j is not None:
                pairs.append((i, j))
                taken[[i, j]] = True
    return pairs


def _partial_twin(lines, image, candidates, tolerance):
    """The chain among ``candidates`` (a mask over ``lines``) that fits a chain's mirror ``image`` best, either one
    running on past the other's tip (``_fit``), if the longer one covers the shorter; else None."""
    fits = [(sum(gaps), gaps, int(k)) for k in np.flatnonzero(candidates)
            for gaps in (_fit(image, lines[k]), _fit(lines[k], image))]
    if not fits:
        return None
    _, gaps, best = min(fits, key=lambda fit: fit[0])
    return best if _covers(gaps, tolerance) else None


def _fit(long, short):
    """(start gap, tip gap) of polyline ``short`` against ``long``: how far apart their starts lie and how far the
    tip of ``short`` lies off ``long`` (``_covers``)."""
    return (float(np.linalg.norm(short[0] - long[0])),
            float(segment_distances(short[-1:], long[:-1], long[1:]).min()))


def _covers(gaps, tolerance):
    """Whether a polyline covers another whose ``_fit`` against it is ``gaps``: their starts lie within two
    ``tolerance``s, the other's tip within one of the polyline."""
    start_gap, tip_gap = gaps
    return start_gap <= 2 * tolerance and tip_gap <= tolerance


def mirror_completed(limbs, plane, tolerance):
    """The (polyline, half-widths) ``limbs`` with each one that a longer mirror twin covers replaced by the twin's
    mirror image: a limb on one side of ``plane`` whose start lies within two ``tolerance``s of the image of the
    twin's start, and whose tip lies within one ``tolerance`` of that image (anywhere along it): a view's
    triangulation is not symmetric, and may prune one ear's tip but not the other's, or bend one ear's branch more.
    A limb's twin is the one whose image fits it best (start and tip nearest), so a short limb beside a long one
    (a leg below an antenna) keeps its own; each twin replaces one limb, the one it fits best."""
    lines = [line for line, _ in limbs]
    side = [_side(line, plane, tolerance, by_tip=True) for line in lines]
    images = [mirrored(line, plane) for line in lines]
    fits = {}  # twin -> (misfit, limb it replaces)
    for j, line in enumerate(lines):
        twins = [i for i in range(len(lines)) if side[i] != 0 and side[i] == -side[j]]
        if not twins:
            continue
        gaps = np.array([_fit(images[i], line) for i in twins])  # (start gap, tip gap) per twin
        misfits = gaps.sum(axis=1)
        best = int(np.argmin(misfits))
        i = twins[best]
        covered = _covers(gaps[best], tolerance) and length(line) < length(lines[i])
        if covered and misfits[best] < fits.get(i, (np.inf,))[0]:
            fits[i] = (misfits[best], j)
    result = list(limbs)
    for i, (_, j) in fits.items():
        result[j] = (images[i], limbs[i][1])
    return result


def symmetric_joints(joints, lines, plane, tolerance, recount, *, leaves):
    """``joints`` per chain (3D polylines ``lines``, ``leaves`` telling which end in a tip), each mirror pair of
    chains (``mirror_chain_pairs``) made to match, so that every bone has a twin (``.L`` and ``.R`` names, X-mirror
    posing). Where one twin is a leaf that runs on along the other's image past its tip (``_runs_on``: pruning kept
    a hand's branch on one side only, or the triangulation ended one leg a little lower), it takes the other's
    mirror image, its bone count too, so both arms end at the wrist. Otherwise the pair gets one bone count: the
    one with more bones is recounted with at most as many as the other, and while their counts differ (its corners
    need more bones, or a bone would be too long), the one with fewer gets as many as the other (``recount(chain,
    max_bones, min_bones)`` gives a chain's joints anew). Pairs whose shapes agree then get the average of one's
    joints and the other's mirror image; pairs whose shapes do not (a leg stepping forward) keep their own joints.
    Each chain keeps its own first joint, where it attaches to its parent."""
    joints = list(joints)
    for i, j in mirror_chain_pairs(lines, plane, tolerance):
        runs_on = _runs_on(lines, i, j, plane, tolerance, leaves)
        if runs_on is not None:
            longer, shorter = runs_on
            joints[longer] = np.vstack([joints[longer][:1], mirrored(joints[shorter], plane)[1:]])
            continue
        if len(joints[i]) != len(joints[j]):
            more, fewer = (i, j) if len(joints[i]) > len(joints[j]) else (j, i)
            joints[more] = recount(more, len(joints[fewer]) - 1, 0)
            while len(joints[more]) != len(joints[fewer]):  # the count only grows, up to what both need
                more, fewer = (more, fewer) if len(joints[more]) > len(joints[fewer]) else (fewer, more)
                joints[fewer] = recount(fewer, len(joints[more]) - 1, len(joints[more]) - 1)
        image_of_j = mirrored(resampled(lines[j], SHAPE_SAMPLES), plane)
        same_shape = np.linalg.norm(resampled(lines[i], SHAPE_SAMPLES) - image_of_j, axis=1).max() <= (
            SAME_SHAPE * tolerance)
        if same_shape:
            a, b = joints[i], joints[j]
            mean = (a + mirrored(b, plane)) / 2
            joints[i] = np.vstack([a[:1], mean[1:]])
            joints[j] = np.vstack([b[:1], mirrored(mean, plane)[1:]])
    return joints


def _runs_on(lines, i, j, plane, tolerance, leaves):
    """(longer, shorter) of mirror twins ``i`` and ``j`` when the longer is a leaf (``leaves``) that covers the
    shorter's mirror image (``_covers``) and whose tip lies more than a ``tolerance`` from the image's tip; else
    None. A leg stepping forward does not cover its twin's image."""
    for longer, shorter in ((i, j), (j, i)):
        image = mirrored(lines[shorter], plane)
        if leaves[longer] and _covers(_fit(lines[longer], image), tolerance) and (
                np.linalg.norm(lines[longer][-1] - image[-1]) > tolerance):
            return longer, shorter
    return None


def _side(line, plane, tolerance, by_tip=False):
    """+1 on the plane's positive side, -1 on its negative side, 0 for a chain on the plane (on average), or with
    ``by_tip`` for one whose tip is on it too."""
    axis, offset = plane
    distance = float(np.mean(line[:, axis])) - offset
    if by_tip and abs(distance) <= tolerance:
        distance = float(line[-1, axis]) - offset
    return 0 if abs(distance) <= tolerance else int(np.sign(distance))


def bone_names(chain_of_bone, index_in_chain, lines, plane, tolerance):
    """Names by chain and place in it: ``trunk.00``, ``limb03.01`` …, chains numbered in order from 1.

    With a mirror ``plane``, every bone of a chain off the plane (on average; for a chain with a mirror twin, at its
    tip) gets ``.L`` on the side of the plane's positive axis (Blender's convention for a character's left) or
    ``.R``, and mirror-image chains share their number, so ``limb02.01.L`` and ``limb02.01.R`` are a left and a
    right bone in the same place.
    """
    label = list(range(len(lines)))
    suffix = [""] * len(lines)
    if plane is not None:
        paired = set()
        for i, j in mirror_chain_pairs(lines, plane, tolerance):
            label[j] = label[i] = min(i, j)
            paired |= {i, j}
        for c, line in enumerate(lines):
            suffix[c] = {1: ".L", -1: ".R", 0: ""}[_side(line, plane, tolerance, by_tip=c in paired)]
    number = {value: k for k, value in enumerate(sorted(set(label)))}  # the trunk (chain 0) keeps 0
    base = ["trunk" if number[label[c]] == 0 else f"limb{number[label[c]]:02d}" for c in range(len(lines))]
    names = [f"{base[c]}.{k:02d}{suffix[c]}" for c, k in zip(chain_of_bone, index_in_chain)]
    seen = {}
    for i, name in enumerate(names):  # two unpaired chains on one side can share a label only by mistake; be safe
        if name in seen:
            names[i] = f"{name}.{i:03d}"
        seen[name] = i
    return names
