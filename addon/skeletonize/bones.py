"""Bones from 3D chains: where joints go along a chain, the bone hierarchy, and names with mirror suffixes."""
import numpy as np

MIN_BONE = 0.35  # shortest bone made at a corner, as a fraction of the longest bone


def chain_joints(line, bone_angle, bone_length):
    """Joint positions along a polyline: its ends, the corners where the simplified line turns by more than
    ``bone_angle`` radians, and evenly spaced points so that no bone is longer than ``bone_length``."""
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))]
    keep = [0]
    for corner in _corners(line, bone_angle, tolerance=0.25 * bone_length)[1:-1]:
        # a corner too close to the previous joint or to the end would make a stub bone
        if arc[corner] - arc[keep[-1]] >= MIN_BONE * bone_length and arc[-1] - arc[corner] >= MIN_BONE * bone_length:
            keep.append(corner)
    keep.append(len(line) - 1)
    joints = [line[0]]
    for a, b in zip(keep[:-1], keep[1:]):
        piece = line[a:b + 1]
        steps = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))]
        count = max(1, int(np.ceil(steps[-1] / bone_length - 1e-9))) if steps[-1] > 0 else 1
        for k in range(1, count + 1):
            at = steps[-1] * k / count
            joints.append(np.array([np.interp(at, steps, piece[:, d]) for d in range(3)]))
    return np.array(joints)


def _corners(line, angle, tolerance):
    """Indices of the ends and the sharp corners of ``line`` after Douglas-Peucker simplification (iterative)."""
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
        far = int(np.argmax(dist))
        if dist[far] > tolerance:
            keep[a + 1 + far] = True
            stack += [(a, a + 1 + far), (a + 1 + far, b)]
    idx = np.flatnonzero(keep)
    corners = [idx[0]]
    for prev, here, nxt in zip(idx[:-2], idx[1:-1], idx[2:]):
        u, w = line[here] - line[prev], line[nxt] - line[here]
        cos = float(u @ w) / max(np.linalg.norm(u) * np.linalg.norm(w), 1e-300)
        if np.arccos(np.clip(cos, -1.0, 1.0)) > angle:
            corners.append(here)
    corners.append(idx[-1])
    return corners


def mirror_plane(vertices, tolerance):
    """The axis (0, 1, 2) and offset of a plane the mesh is mirror-symmetric about, or None.

    Tries the planes through the bounding-box centre perpendicular to X, Y and Z; a plane fits when at least 95% of
    the vertices have a mirror image among the vertices within ``tolerance`` (grid hashing, no KD-tree needed)."""
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    cells = np.floor(vertices / tolerance).astype(np.int64)
    table = set(map(tuple, cells.tolist()))
    offsets = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)]
    best = None
    for axis in range(3):
        centre = 0.5 * (low[axis] + high[axis])
        mirrored = vertices.copy()
        mirrored[:, axis] = 2 * centre - mirrored[:, axis]
        mcells = np.floor(mirrored / tolerance).astype(np.int64).tolist()
        hits = sum(any((c[0] + dx, c[1] + dy, c[2] + dz) in table for dx, dy, dz in offsets) for c in mcells)
        score = hits / len(vertices)
        if score >= 0.95 and (best is None or score > best[2]):
            best = (axis, centre, score)
    return None if best is None else best[:2]


def mirror_pairs(heads, tails, plane, tolerance):
    """Pairs (i, j) of bones that are mirror images of each other across ``plane`` = (axis, offset)."""
    axis, offset = plane
    mh, mt = heads.copy(), tails.copy()
    mh[:, axis] = 2 * offset - mh[:, axis]
    mt[:, axis] = 2 * offset - mt[:, axis]
    pairs = []
    taken = set()
    for i in range(len(heads)):
        if i in taken:
            continue
        cost = np.linalg.norm(heads - mh[i], axis=1) + np.linalg.norm(tails - mt[i], axis=1)
        cost[i] = np.inf
        j = int(np.argmin(cost))
        if cost[j] <= tolerance and j not in taken:
            # a bone lying on the plane mirrors onto itself (or a twin on the plane): not a pair
            if abs(heads[i, axis] + tails[i, axis] - 2 * offset) > tolerance:
                pairs.append((i, j))
                taken.update((i, j))
    return pairs


def bone_names(chain_of_bone, index_in_chain, heads, tails, plane, tolerance):
    """Names by position in the hierarchy (``trunk.00``, ``limb03.01`` …) with ``.L``/``.R`` for mirror pairs:
    ``.L`` on the side of the plane's positive axis, Blender's convention for a character's left."""
    names = [("trunk" if c == 0 else f"limb{c:02d}") + f".{k:02d}" for c, k in zip(chain_of_bone, index_in_chain)]
    if plane is None:
        return names
    axis, offset = plane
    for i, j in mirror_pairs(heads, tails, plane, tolerance):
        base = names[min(i, j)]
        left = i if heads[i, axis] + tails[i, axis] > 2 * offset else j
        names[left], names[i + j - left] = base + ".L", base + ".R"
    seen = {}
    for i, name in enumerate(names):  # partial pairings can collide: keep every name unique
        if name in seen:
            names[i] = f"{name}.{i:03d}"
        seen[name] = i
    return names
