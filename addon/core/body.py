"""A skeleton read as a body, from geometry: its joint graph, the frame it stands in (mirror plane, up), its midline
and its limbs, and how thick and how flat the mesh is around them. Bone names matter only for ``.L`` / ``.R`` twins.

The pieces, in the order :func:`read_body` finds them:

- the joint graph: bone ends closer than ``joint_merge`` are one joint; a bone whose head is not its parent's tail
  hangs from it by a link without a bone (from the parent's head when it starts that near it), and parts of a
  forest hang from the nearest joint of the largest part;
- the mirror plane: the method's own (its ``mirror_plane`` stage), else the mesh's (``core.mirror.mirror_plane``),
  else the axis plane that pairs the most leaf tips of the skeleton with mirror images and runs along the body (a
  posed or hand-made figure, whose mesh is not symmetric within 1%);
- up: the world axis, perpendicular to the plane's normal, along which the most separate leaf tips touch the
  ground with the mesh's centre above them (legs), then the one standing on the broadest flat bottom (its flat area
  times how far it spreads across: soles, a belly; a small flat patch atop a floating figure's head is none), then
  +Z (Blender's up) and +Y (the OBJ convention);
- the midline and the limbs: leaf chains whose tips lie off the plane are stripped, round after round (fingers,
  then the arm they hang from), and grouped into limbs, each hanging from one joint of what stays, the midline.
  The spine is the midline's longest path; side branches of the midline are limbs on the plane (a jaw, a fin).
  Without a mirror plane the spine is the skeleton's longest path and every branch off it is a limb.
"""
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .polyline import arc_lengths, length, segment_distances
from .tuning import TuningTable, tuned

AXES = np.eye(3)


@dataclass(frozen=True)
class BodyTuning(TuningTable):
    """The tuned numbers of reading a body (shares of the mesh size unless said otherwise)."""

    joint_merge: float = tuned(0.01, "a bone shorter than this is one joint: exporters repeat joints a hair apart "
                                     "(RigNet's _dup joints up to 0.0099 off), real bones are longer (Mixamo's "
                                     "finger bones 0.013)")
    plane_fit: float = tuned(0.08, "when the plane is fitted to the skeleton, twin joints mirror within this (a "
                                   "posed or hand-made figure is not symmetric within 1%)")
    plane_pairs: int = tuned(4, "a plane fitted to the skeleton pairs at least this many joints (two twin limbs of "
                                "two joints each)")
    midline: float = tuned(0.03, "a leaf chain all of whose joints lie this close to the mirror plane, or that has no "
                                 "twin and lies this close on average, is on the midline (two legs close together "
                                 "are not; a head whose tip turns aside is)")
    contact_height: float = tuned(0.08, "a leaf tip whose mesh comes this share of the mesh's height near its lowest "
                                        "point touches the ground")
    contact_apart: float = tuned(0.25, "leaf tips this close along the skeleton touch the ground as one limb (a "
                                       "hand's fingers, a hoof's two toes; two feet are a whole leg length apart)")
    leg_weight: float = tuned(2.0, "the up score of two or more limbs touching the ground: more than the best flat "
                                   "bottom (a flat back or flat wings are no ground)")
    prefer_weight: float = tuned(0.05, "the up score of the preferred up (the convention of the mesh's source): it "
                                       "only breaks ties")
    flat_bottom: float = tuned(0.02, "the mesh's bottom slab, where flat faces facing down count as ground area")
    flat_area: float = tuned(0.004, "a bottom with this share of the mesh's area flat on the ground stands on it")
    flat_spread: float = tuned(0.2, "... when it spreads this share of the mesh's breadth across up (geometric mean of "
                                    "both ways; a cartoon's soles 0.4, a flat patch atop a floating ghost's head 0.16)")
    min_limb: float = tuned(0.05, "a side branch of the midline shorter than this is part of the spine there, no "
                                  "limb (an exporter's helper joint, a stub)")
    twin_tolerance: float = tuned(0.12, "limbs whose tips and starts mirror within this are twins (posed figures "
                                        "differ)")
    blade_from: float = tuned(0.25, "a limb's flatness is measured from this share of its length ...")
    blade_to: float = tuned(0.8, "... to this one: its blade (a wing's, a fin's) or its thigh and shin, not the body "
                                 "it leaves nor a flat foot")
    sample_vertices: int = tuned(2000, "mesh vertices sampled for thickness and flatness (at most): enough to find "
                                       "a limb's surface, few enough to stay a few milliseconds")
    sample_triangles: int = tuned(40000, "triangles sampled for the flat bottom (at most)")


@dataclass(frozen=True)
class JointGraph:
    """Joints (``points`` (K, 3)) joined into one tree: ``neighbours[k]`` lists (joint, bone) pairs, bone -1 for a
    link that is no bone; ``head_node`` and ``tail_node`` (B,) give each bone's joints."""

    points: np.ndarray
    neighbours: tuple
    head_node: np.ndarray
    tail_node: np.ndarray

    def degree(self, node):
        return len(self.neighbours[node])

    def leaves(self):
        return [k for k in range(len(self.points)) if len(self.neighbours[k]) == 1]

    def search(self, start, allowed=None):
        """Distances (along the bones) from ``start`` to every joint reached within ``allowed`` (all when None), and
        the joint each was reached from."""
        distance, before = {start: 0.0}, {start: -1}
        stack = [start]
        while stack:
            node = stack.pop()
            for other, _ in self.neighbours[node]:
                if other not in distance and (allowed is None or other in allowed):
                    distance[other] = distance[node] + float(np.linalg.norm(self.points[other] - self.points[node]))
                    before[other] = node
                    stack.append(other)
        return distance, before

    @cached_property
    def distances(self):
        """(K, K) distances along the bones between every two joints: each joint's row is its parent's (in a
        depth-first order from joint 0) plus the bone between them, less twice that bone within its own subtree."""
        count = len(self.points)
        order, parent, seen = [], np.full(count, -1), np.zeros(count, bool)
        for root in range(count):  # one tree, but stay total on a forest
            if seen[root]:
                continue
            seen[root] = True
            stack = [root]
            while stack:
                node = stack.pop()
                order.append(node)
                for other, _ in self.neighbours[node]:
                    if not seen[other]:
                        seen[other], parent[other] = True, node
                        stack.append(other)
        place = np.empty(count, int)
        place[order] = np.arange(count)
        ends = np.arange(count) + 1  # where each joint's subtree ends in ``order``
        for node in reversed(order):
            if parent[node] >= 0:
                ends[place[parent[node]]] = max(ends[place[parent[node]]], ends[place[node]])
        table = np.full((count, count), np.inf)
        for node in order:
            row = place[node]
            if parent[node] < 0:
                reached = self.search(node)[0]
                table[row] = [reached.get(other, np.inf) for other in order]
                continue
            step = float(np.linalg.norm(self.points[node] - self.points[parent[node]]))
            table[row] = table[place[parent[node]]] + step
            table[row, row:ends[row]] -= 2 * step
        return table[np.ix_(place, place)]

    def longest_path(self, allowed=None, start=None):
        """The longest path (by length) within ``allowed`` joints: from the joint farthest from ``start`` to the one
        farthest from it."""
        nodes = sorted(allowed) if allowed is not None else range(len(self.points))
        first = nodes[0] if start is None else start
        distance = self.search(first, allowed)[0]
        one_end = max(distance, key=distance.get)
        distance, before = self.search(one_end, allowed)
        other_end = max(distance, key=distance.get)
        path = [other_end]
        while path[-1] != one_end:
            path.append(before[path[-1]])
        return path[::-1]

    def bone_between(self, a, b):
        return next((bone for other, bone in self.neighbours[a] if other == b), -1)


def joint_graph(skeleton, tolerance):
    """The :class:`JointGraph` of ``skeleton``. A bone's head is its parent's tail (or head), and the head of a
    sibling (or of another root), when they lie within ``tolerance`` / 100 (exporters round); the two ends of a bone
    shorter than ``tolerance`` are one joint. A bone hung from its parent elsewhere is linked to the parent's tail,
    or to its head when it starts within ``tolerance`` of it and nearer it (ears hung just past the start of a head's
    bone)."""
    count = len(skeleton)
    heads, tails, parents = skeleton.heads, skeleton.tails, skeleton.parents
    same = tolerance / 100
    left, right = [], []
    for bone, parent in enumerate(parents.tolist()):
        if np.linalg.norm(tails[bone] - heads[bone]) < tolerance:
            left.append(bone), right.append(count + bone)
        if parent >= 0 and np.linalg.norm(heads[bone] - tails[parent]) <= same:
            left.append(bone), right.append(count + parent)
        elif parent >= 0 and np.linalg.norm(heads[bone] - heads[parent]) <= same:
            left.append(bone), right.append(parent)  # a branch from the parent's head
    for group in _sibling_groups(parents):
        for bone in group[1:]:
            if np.linalg.norm(heads[bone] - heads[group[0]]) <= same:
                left.append(bone), right.append(group[0])
    _, node_of = np.unique(_joined(np.arange(2 * count), np.array(left, dtype=np.int64),
                                   np.array(right, dtype=np.int64)), return_inverse=True)
    node_of = node_of.reshape(-1)
    points = np.zeros((node_of.max() + 1, 3))
    points[node_of] = np.concatenate([heads, tails])  # a collapsed bone's joint sits at one of its ends
    head_node, tail_node = node_of[:count], node_of[count:]
    links = [(int(head_node[b]), int(tail_node[b]), b) for b in range(count) if head_node[b] != tail_node[b]]
    for bone, parent in enumerate(parents.tolist()):
        if parent >= 0 and tail_node[parent] != head_node[bone] and head_node[parent] != head_node[bone]:
            from_head = np.linalg.norm(heads[bone] - heads[parent])
            near_head = from_head < tolerance and from_head < np.linalg.norm(heads[bone] - tails[parent])
            links.append((int((head_node if near_head else tail_node)[parent]), int(head_node[bone]), -1))
    neighbours = _spanning_tree(points, links)
    return JointGraph(points, neighbours, head_node, tail_node)


def _sibling_groups(parents):
    """Bones grouped by parent (roots together)."""
    groups = {}
    for bone, parent in enumerate(parents.tolist()):
        groups.setdefault(parent, []).append(bone)
    return list(groups.values())


def _joined(labels, left, right):
    """``labels`` with each pair ``left[k]``, ``right[k]`` made one (the smaller label), transitively."""
    parent = np.arange(labels.max() + 1)
    if not len(left):
        return labels

    def root(label):
        while parent[label] != label:
            label = parent[label]
        return label

    for a, b in zip(left.tolist(), right.tolist()):
        a, b = root(a), root(b)
        parent[max(a, b)] = min(a, b)
    return np.array([root(label) for label in labels.tolist()])


def _spanning_tree(points, links):
    """Neighbour lists of one tree over all ``points``: ``links`` (a, b, bone) breadth first from the largest part
    (links closing a loop are left out), then every other part hung from its joint nearest the tree by a link."""
    adjacency = [[] for _ in points]
    for a, b, bone in links:
        adjacency[a].append((b, bone))
        adjacency[b].append((a, bone))
    parts, label = [], np.full(len(points), -1)
    for start in range(len(points)):
        if label[start] < 0:
            label[start] = len(parts)
            part, queue = [start], [start]
            while queue:
                node = queue.pop()
                for other, _ in adjacency[node]:
                    if label[other] < 0:
                        label[other] = label[start]
                        part.append(other)
                        queue.append(other)
            parts.append(part)
    parts.sort(key=len, reverse=True)
    neighbours = [[] for _ in points]
    in_tree = np.zeros(len(points), bool)

    def grow(start):
        in_tree[start] = True
        queue = [start]
        while queue:
            node = queue.pop(0)
            for other, bone in adjacency[node]:
                if not in_tree[other]:
                    in_tree[other] = True
                    neighbours[node].append((other, bone))
                    neighbours[other].append((node, bone))
                    queue.append(other)

    grow(parts[0][0])
    for part in parts[1:]:
        tree = np.flatnonzero(in_tree)
        gaps = np.linalg.norm(points[part][:, None] - points[tree][None], axis=2)
        inner, outer = np.unravel_index(np.argmin(gaps), gaps.shape)
        a, b = part[inner], int(tree[outer])
        neighbours[a].append((b, -1))
        neighbours[b].append((a, -1))
        grow(a)
    return tuple(tuple(each) for each in neighbours)


@dataclass(frozen=True)
class Plane:
    """A mirror plane: unit ``normal`` and ``offset`` along it; ``source`` says where it came from: "method" (the
    method's own), "mesh" (the mesh is symmetric about it) or "fitted" (leaf tips of the skeleton pair across it)."""

    normal: np.ndarray
    offset: float
    source: str

    def distance(self, points):
        return np.asarray(points) @ self.normal - self.offset

    def reflect(self, points):
        points = np.asarray(points, dtype=np.float64)
        return points - 2 * self.distance(points)[..., None] * self.normal


@dataclass(frozen=True)
class Limb:
    """A limb: the joint it hangs from (``attach``), its joints with the joint each hangs from (``before``: joint →
    joint, the attachment's children first), its ``main`` path (attach to its farthest tip), its ``side`` (+1 on the
    plane's positive side, -1, or 0 on the plane: the side its main path reaches farthest into) and its ``twin``
    (index of the limb mirroring it, or -1)."""

    attach: int
    before: dict
    main: tuple
    side: int
    twin: int = -1


@dataclass(frozen=True)
class Body:
    """A skeleton read as a body: its ``graph``, the mesh ``size`` (largest extent) and the mesh's ``low`` and
    ``high`` extent along ``up``, the mirror ``plane`` (or None), a sample of the mesh's ``vertices``, the ``spine``
    (joints along the midline's longest path), the ``limbs`` with the spine joint each hangs from (``bases``; through
    ``connectors``, midline joints off the spine, each with the spine joint it leaves), the ``radius`` (local
    half-thickness of the mesh; a flat cut-out's half-width, to its outline) at each joint, each limb's ``flatness``
    (the mesh around it: thin across over wide across, 1 for a round limb, near 0 for a wing or a fin; 1 on a flat
    mesh), how up was found (``up_evidence``: "legs", "flat" or "preferred") and the ``midsection``: the mesh cut by
    the mirror plane, as (S, 2, 3) segments (none without a plane)."""

    graph: JointGraph
    size: float
    up: np.ndarray
    low: float
    high: float
    plane: Plane
    vertices: np.ndarray
    spine: tuple
    limbs: tuple
    bases: tuple
    connectors: dict
    radius: np.ndarray
    flatness: tuple
    up_evidence: str
    midsection: np.ndarray

    def height(self, points):
        """Height above the mesh's lowest point, as a share of the mesh's height."""
        return (np.asarray(points) @ self.up - self.low) / max(self.high - self.low, 1e-300)

    def touches(self, node, contact_height):
        """Whether the mesh around joint ``node`` (its ``radius``) comes within ``contact_height`` (a share of the
        mesh's height) of the ground."""
        return bool(self.height(self.graph.points[node]) - self.radius[node] / max(self.high - self.low, 1e-300)
                    <= contact_height)

    def limb_length(self, limb):
        return length(self.graph.points[list(limb.main)])


def read_body(skeleton, mesh, tuning=BodyTuning(), plane=None, prefer_up=AXES[2]):
    """The :class:`Body` of ``skeleton`` on ``mesh`` (a validated ``core.mesh.Mesh``); ``plane`` is a mirror plane
    the caller knows (a method's ``MirrorPlane`` stage), else it is looked for; ``prefer_up`` breaks ties between up
    axes (the convention of the mesh's source: +Z in Blender, +Y in an OBJ file)."""
    size = mesh.scale
    graph = joint_graph(skeleton, tuning.joint_merge * size)
    vertices = _sampled(mesh.used_vertices, tuning.sample_vertices)
    radius = _radii(graph.points, _outline(mesh) if mesh.flat_normal is not None else vertices)
    found = _mirror(skeleton, graph, mesh, size, tuning, plane)
    spine, limbs, bases, connectors = _midline_and_limbs(graph, found, size, tuning)
    limbs = _paired(limbs, graph, skeleton, found, size, tuning)
    tips = sorted({node for limb in limbs for node in limb.before if graph.degree(node) == 1})
    up, up_evidence = _up_axis(graph, tips, radius, mesh, vertices, found, size, tuning,
                               np.asarray(prefer_up, dtype=np.float64))
    heights = mesh.used_vertices @ up
    if mesh.flat_normal is not None:
        flatness = tuple(1.0 for _ in limbs)  # a cut-out's limbs are all flat: no telling wings by it
    else:
        segments, nearest = _nearest_links(graph, vertices)
        flatness = tuple(_flatness(limb, graph, vertices, segments, nearest, (tuning.blade_from, tuning.blade_to))
                         for limb in limbs)
    return Body(graph, size, up, float(heights.min()), float(heights.max()), found, vertices, tuple(spine),
                tuple(limbs), bases, connectors, radius, flatness, up_evidence, _section(mesh, found))


def _section(mesh, plane):
    """The (S, 2, 3) segments where ``mesh``'s triangles meet ``plane`` (none without one): each triangle with
    corners on both sides, or with an edge on it, gives the points where its edges cross it or lie on it."""
    if plane is None:
        return np.zeros((0, 2, 3))
    distances = plane.distance(mesh.vertices)
    sides = np.sign(distances).astype(np.int8)[mesh.triangles].sum(axis=1, dtype=np.int8)  # +-3: all on one side
    touching = mesh.triangles[np.abs(sides) < 3]
    corners, offsets = mesh.vertices[touching], distances[touching]  # (T, 3, 3), (T, 3)
    ends = np.full((len(corners), 3, 3), np.nan)
    for k in range(3):
        a, b = offsets[:, k], offsets[:, (k + 1) % 3]
        crossing = a * b < 0
        share = np.where(crossing, a / np.where(crossing, a - b, 1.0), 0.0)
        point = corners[:, k] + share[:, None] * (corners[:, (k + 1) % 3] - corners[:, k])
        ends[:, k] = np.where((crossing | (a == 0))[:, None], point, np.nan)
    found = ~np.isnan(ends[:, :, 0])
    meets = found.sum(axis=1) >= 2
    if not meets.any():
        return np.zeros((0, 2, 3))
    ends, found = ends[meets], found[meets]
    order = np.argsort(~found, axis=1, kind="stable")[:, :2]  # the first two points found on each
    return np.take_along_axis(ends, order[:, :, None], axis=1)


def _sampled(rows, count):
    """Every k-th row, k the smallest that leaves at most ``count``."""
    return rows[::max(1, -(-len(rows) // count))]


# The mirror plane.

def _mirror(skeleton, graph, mesh, size, tuning, given):
    """The mirror plane as :func:`read_body` says, or None."""
    from .mirror import MirrorTuning, mirror_plane

    if given is not None:
        return Plane(np.asarray(given.normal, dtype=np.float64), float(given.offset), "method")
    mirror_tuning = MirrorTuning()
    found = mirror_plane(mesh.used_vertices, mesh.bbox, mirror_tuning.plane_match * size, mirror_tuning)
    if found is not None:
        return Plane(AXES[found[0]].copy(), float(found[1]), "mesh")
    return _fitted_plane(graph, mesh, size, tuning)


def _fitted_plane(graph, mesh, size, tuning):
    """The axis plane across which the most joints off it have another joint near their mirror image (at least
    ``plane_pairs``) and whose joints on it span ``min_limb`` or more (a body runs along its mirror plane; a plane
    across a lying body's line of joints pairs them all), or None. The planes tried run midway between two leaf tips
    that could be twins; two joints of one limb (a hand's fingers) never pair: the skeleton joins twins through the
    body, more than ``contact_apart`` apart."""
    points = graph.points
    tips = points[graph.leaves()]
    distance = graph.distances
    apart = distance > tuning.contact_apart * size
    best, best_pairs = None, tuning.plane_pairs - 1
    low, high = mesh.bbox
    step = tuning.midline * size
    for axis in range(3):
        if high[axis] - low[axis] <= 2 * step:
            continue  # a flat mesh has no sides across its own plane
        others = [k for k in range(3) if k != axis]
        close = np.linalg.norm(tips[:, None, others] - tips[None, :, others], axis=2) <= tuning.plane_fit * size
        first, second = np.nonzero(np.triu(close, 1))
        for offset in np.unique(np.round(0.5 * (tips[first, axis] + tips[second, axis]) / step)) * step:
            plane = Plane(AXES[axis].copy(), float(offset), "fitted")
            off = np.abs(plane.distance(points)) > step
            gaps = np.linalg.norm(plane.reflect(points[off])[:, None] - points[None], axis=2)
            gaps[~apart[off]] = np.inf
            pairs = int((gaps.min(axis=1, initial=np.inf) <= tuning.plane_fit * size).sum())
            if pairs > best_pairs and _span(points[~off]) >= tuning.min_limb * size:
                best, best_pairs = plane, pairs
    return best


def _span(points):
    """The largest distance between two of ``points`` (0 for fewer than two)."""
    if len(points) < 2:
        return 0.0
    return float(np.linalg.norm(points[:, None] - points[None], axis=2).max())


# Up.

def _up_axis(graph, tips, radius, mesh, sample, plane, size, tuning, prefer_up):
    """(up, evidence) as :func:`read_body` says: each candidate axis scores ``leg_weight`` when separate limbs
    touch the ground at its bottom (their leaf ``tips``: the body's own ends are no feet), plus its flat bottom area
    as a share of the best candidate's (or of ``flat_area`` when none has that much), spread over the vertex
    ``sample``; ``prefer_up`` breaks ties. The evidence is "legs", "flat" or "preferred"."""
    low, high = mesh.bbox
    thick = [axis for axis in range(3) if high[axis] - low[axis] > 2 * tuning.midline * size]
    # a flat mesh stands in its own plane; a mesh flat but along the mirror plane's normal (two parts far apart
    # across it) stands any way
    candidates = _up_candidates(thick, plane) or _up_candidates(range(3), plane)
    corners = mesh.vertices[_sampled(mesh.triangles, tuning.sample_triangles)]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    areas = np.linalg.norm(normals, axis=1)
    total_area = max(float(areas.sum()), 1e-300)
    ups = np.array(candidates)
    heights = mesh.used_vertices @ ups.T  # (N, C)
    lows, highs = heights.min(axis=0), heights.max(axis=0)
    tops = np.maximum(np.maximum(corners[:, 0] @ ups.T, corners[:, 1] @ ups.T), corners[:, 2] @ ups.T)  # (T, C):
    # each triangle's highest corner along each candidate (three plain products: a stack of 3x3 ones is slow)
    facing = -(normals @ ups.T) >= 0.7 * areas[:, None]
    bottom = tops <= lows + tuning.flat_bottom * size
    flats = (areas[:, None] * (bottom & facing)).sum(axis=0) / total_area
    spreads = np.array([_spread(corners[bottom[:, k] & facing[:, k]].reshape(-1, 3), sample, up)
                        if flats[k] >= tuning.flat_area else 0.0 for k, up in enumerate(candidates)])
    flats[spreads < tuning.flat_spread] = 0.0  # a base spreads under the body: a patch atop a floating head is none
    bases = flats * spreads
    measures = [(_contacts(graph, radius, tips, up, low, high, size, tuning), float(flat), high - low)
                for up, low, high, flat in zip(candidates, lows, highs, flats)]
    best_base = max(float(bases.max()), tuning.flat_area * tuning.flat_spread)
    scores = [tuning.leg_weight * (contacts >= 2) + base / best_base + tuning.prefer_weight * float(up @ prefer_up)
              for up, (contacts, _, _), base in zip(candidates, measures, bases)]
    best = int(np.argmax(scores))
    up, (contacts, flat, _) = candidates[best], measures[best]
    if contacts >= 2:
        return up, "legs"
    if flat >= tuning.flat_area:
        return up, "flat"
    return up, "preferred"


def _up_candidates(axes, plane):
    """Both directions of each of ``axes`` (indices) as up candidates, none along the mirror ``plane``'s normal (a
    body's up lies in its mirror plane), each made to lie in the plane."""
    candidates = []
    for axis in axes:
        for sign in (1.0, -1.0):
            up = sign * AXES[axis]
            if plane is not None:
                if abs(up @ plane.normal) > 0.5:
                    continue
                up = up - (up @ plane.normal) * plane.normal
                up /= np.linalg.norm(up)
            candidates.append(up)
    return candidates


def _spread(base, vertices, up):
    """How far ``base`` points spread across ``up`` as a share of how far the ``vertices`` do: the geometric mean
    over the two directions across (0 without points)."""
    if not len(base):
        return 0.0
    across = np.linalg.svd(np.eye(3) - np.outer(up, up))[0][:, :2]
    shares = np.ptp(base @ across, axis=0) / np.maximum(np.ptp(vertices @ across, axis=0), 1e-300)
    return float(np.sqrt(shares.prod()))


def _contacts(graph, radius, tips, up, low, high, size, tuning):
    """How many separate limbs touch the ground: leaf tips whose mesh (``radius`` around them) comes within
    ``contact_height`` of the mesh's bottom, those less than ``contact_apart`` apart along the skeleton counted once
    (a hand's fingers, a hoof's two toes)."""
    touching = [leaf for leaf in tips
                if graph.points[leaf] @ up - radius[leaf] <= low + tuning.contact_height * (high - low)]  # touches()
    groups = []
    for leaf in touching:
        if not any(graph.distances[first, leaf] <= tuning.contact_apart * size for first in groups):
            groups.append(leaf)
    return len(groups)


# Midline and limbs.

def _midline_and_limbs(graph, plane, size, tuning):
    """(spine joints, limbs, the spine joint each limb hangs from, connectors) as :func:`read_body` says.
    Connectors are midline joints off the spine that limbs hang from through them (a pelvis joint below the spine)
    or on stubs shorter than ``min_limb``, each with the spine joint it hangs from."""
    count = len(graph.points)
    if plane is None:
        spine = graph.longest_path()
        return (spine, *_side_branches(graph, spine, set(range(count)), [], plane, size, tuning))
    distance = plane.distance(graph.points)
    off_plane = np.abs(distance) > tuning.midline * size

    def leaves(chain):  # its course leaves the plane, not only its tip (a head turned aside)
        return np.abs(distance[chain[1:]]).mean() > tuning.midline * size

    active = set(range(count))
    stripped = []  # chains (base first) stripped from the midline, in order
    while True:
        degree = {node: sum(other in active for other, _ in graph.neighbours[node]) for node in active}
        chains = [_leaf_chain(graph, leaf, active, degree) for leaf in active if degree[leaf] == 1]
        if not chains or all(len(chain) == len(active) for chain in chains):  # a path: split it on the plane
            if chains and len(active) > 1:
                path = chains[0][::-1]
                middle = path[int(np.argmin(np.abs(distance[path])))]
                for part in (path[:path.index(middle) + 1][::-1], path[path.index(middle):]):
                    if len(part) > 1 and off_plane[part[-1]] and leaves(part):
                        stripped.append(part)
                        active -= set(part[1:])
            break
        tips = np.array([graph.points[chain[-1]] for chain in chains])
        off = [chain for chain in chains if off_plane[chain[1:]].any() and (
            leaves(chain) or _mirrored_tip(plane, graph.points[chain[-1]], tips, tuning.midline * size))]
        if not off:
            break
        for chain in off:
            stripped.append(chain)
            active -= set(chain[1:])
    spine = graph.longest_path(active) if len(active) > 1 else sorted(active)
    limbs = _grouped(graph, stripped, active, plane, size, tuning)
    return (spine, *_side_branches(graph, spine, active, limbs, plane, size, tuning))


def _mirrored_tip(plane, tip, tips, tolerance):
    """Whether another of the leaf chains' ``tips`` lies within ``tolerance`` of ``tip``'s mirror image (not on it)."""
    gaps = np.linalg.norm(tips - plane.reflect(tip), axis=1)
    return bool(((gaps <= tolerance) & (np.linalg.norm(tips - tip, axis=1) > tolerance)).any())


def _side_branches(graph, spine, allowed, limbs, plane, size, tuning):
    """(limbs, each one's spine joint, connectors) given the ``limbs`` stripped from the midline: each branch of the
    ``allowed`` joints off the ``spine`` is a limb of its own, unless a stripped limb hangs from it or it is shorter
    than ``min_limb``: then its joints are connectors of the spine joint it leaves."""
    on_spine = set(spine)
    attach_of = {}
    for k, limb in enumerate(limbs):
        attach_of.setdefault(limb.attach, []).append(k)
    base = [limb.attach if limb.attach in on_spine else -1 for limb in limbs]
    connectors, own = {}, []
    for node in spine:
        for start, _ in graph.neighbours[node]:
            if start in on_spine or start not in allowed:
                continue
            before = {start: node}
            queue = [start]
            while queue:
                here = queue.pop()
                for other, _ in graph.neighbours[here]:
                    if other not in before and other != node and other in allowed and other not in on_spine:
                        before[other] = here
                        queue.append(other)
            carried = [k for joint in before for k in attach_of.get(joint, ())]
            branch = _limb(graph, node, before, plane, size, tuning)
            for k in carried:
                base[k] = node
            if carried or length(graph.points[list(branch.main)]) < tuning.min_limb * size:
                connectors.update({joint: node for joint in before})
            else:
                own.append(branch)
    return list(limbs) + own, tuple(base) + tuple(branch.attach for branch in own), connectors


def _leaf_chain(graph, leaf, active, degree):
    """Joints from the branch joint a leaf chain hangs from out to ``leaf`` (the whole path when there is none)."""
    chain, before, node = [leaf], -1, leaf
    while True:
        ahead = [other for other, _ in graph.neighbours[node] if other in active and other != before]
        if not ahead:
            return chain[::-1]
        before, node = node, ahead[0]
        chain.append(node)
        if degree[node] != 2:
            return chain[::-1]


def _grouped(graph, stripped, midline, plane, size, tuning):
    """Limbs from stripped chains: each chain based on the midline starts a limb, and chains based on a limb's
    joints join it (fingers on an arm)."""
    limbs = []
    owner = {}
    for chain in reversed(stripped):  # limbs' base chains were stripped last
        base = chain[0]
        if base in midline:
            limbs.append({"attach": base, "before": {}})
            target = limbs[-1]
        elif base in owner:
            target = owner[base]
        else:
            continue  # cannot happen in a tree; keep going rather than fail
        for node, previous in zip(chain[1:], chain[:-1]):
            target["before"][node] = previous
            owner[node] = target
    return [_limb(graph, each["attach"], each["before"], plane, size, tuning) for each in limbs]


def _limb(graph, attach, before, plane, size, tuning):
    distance = {attach: 0.0}
    for node in before:  # parents come before children
        distance[node] = distance[before[node]] + float(np.linalg.norm(graph.points[node] - graph.points[before[node]]))
    tip = max(before, key=distance.get)
    main = [tip]
    while main[-1] != attach:
        main.append(before[main[-1]])
    side = 0
    if plane is not None:  # a foot curling in to the middle leaves a leg on its side
        offsets = plane.distance(graph.points[main])
        offset = float(offsets[int(np.argmax(np.abs(offsets)))])
        side = 0 if abs(offset) <= tuning.midline * size else int(np.sign(offset))
    return Limb(attach, dict(before), tuple(main[::-1]), side)


def _paired(limbs, graph, skeleton, plane, size, tuning):
    """The limbs with their twins: by ``.L`` / ``.R`` bone names when their bones have them, else the best mirror
    fits (tip and start within ``twin_tolerance``), best first."""
    if plane is None:
        return limbs
    twin = [-1] * len(limbs)
    names = [_side_names(limb, graph, skeleton) for limb in limbs]
    costs = []
    for i, a in enumerate(limbs):
        for j in range(i + 1, len(limbs)):
            b = limbs[j]
            if a.side == 0 or a.side != -b.side:
                continue
            if names[i] and names[j] and names[i] == _swapped(names[j]):
                costs.append((-1.0, i, j))
                continue
            tips = graph.points[[a.main[-1], b.main[-1]]]
            starts = graph.points[[a.main[min(1, len(a.main) - 1)], b.main[min(1, len(b.main) - 1)]]]
            cost = max(float(np.linalg.norm(plane.reflect(tips[0]) - tips[1])),
                       float(np.linalg.norm(plane.reflect(starts[0]) - starts[1])))
            if cost <= tuning.twin_tolerance * size:
                costs.append((cost, i, j))
    for _, i, j in sorted(costs):
        if twin[i] < 0 and twin[j] < 0:
            twin[i], twin[j] = j, i
    return [Limb(limb.attach, limb.before, limb.main, limb.side, twin[k]) for k, limb in enumerate(limbs)]


def _side_names(limb, graph, skeleton):
    """The limb's bone names with their ``.L`` / ``.R`` suffix, when every bone has one (else None)."""
    bones = [graph.bone_between(node, limb.before[node]) for node in limb.before]
    names = sorted(skeleton.names[bone] for bone in bones if bone >= 0)
    if not names or not all(name[-2:] in (".L", ".R") for name in names):
        return None
    return tuple(names)


def _swapped(names):
    return tuple(sorted(name[:-2] + (".R" if name.endswith(".L") else ".L") for name in names))


# The mesh around the skeleton.

def _outline(mesh):
    """The vertices on a flat mesh's open edges (those of one triangle), its outline: a cut-out's half-width at a
    joint is the distance to it, while the nearest vertex may lie anywhere on the sheet; all its vertices when it
    has none (a closed sheet)."""
    triangles = mesh.triangles
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    ends = np.unique(unique[counts == 1])
    return mesh.vertices[ends] if len(ends) else mesh.used_vertices


def _radii(points, vertices):
    """Distance from each joint to the nearest mesh vertex: the local half-thickness of a joint inside the mesh."""
    result = np.empty(len(points))
    for start in range(0, len(points), 64):
        block = points[start:start + 64]
        result[start:start + 64] = np.sqrt(((block[:, None] - vertices[None]) ** 2).sum(axis=2).min(axis=1))
    return result


def _flatness(limb, graph, vertices, segments, nearest, middle):
    """How round the mesh is around the middle of ``limb``'s main path (the links between ``middle`` (low, high)
    shares of its length: a wing's or a fin's blade, a leg's thigh and shin, not the body it leaves or its foot):
    the spread of the vertices nearest those links, thinnest across over widest across (both perpendicular to the
    links' overall direction). ``segments`` are the graph's links (a, b) and ``nearest`` the link nearest each
    vertex."""
    main = graph.points[list(limb.main)]
    arc = arc_lengths(main)
    if len(main) < 2 or arc[-1] <= 0:
        return 1.0
    mid = 0.5 * (arc[1:] + arc[:-1]) / arc[-1]
    chosen = [(limb.main[k], limb.main[k + 1]) for k in np.flatnonzero((mid >= middle[0]) & (mid <= middle[1]))]
    if not chosen:
        chosen = [(limb.main[k], limb.main[k + 1]) for k in [int(np.argmin(np.abs(mid - 0.5)))]]
    direction = graph.points[chosen[-1][1]] - graph.points[chosen[0][0]]
    if not np.linalg.norm(direction) > 0:
        return 1.0
    direction /= np.linalg.norm(direction)
    wanted = {tuple(sorted(pair)) for pair in chosen}
    own = [k for k, pair in enumerate(segments) if pair in wanted]
    around = vertices[np.isin(nearest, own)]
    if len(around) < 4:
        return 1.0
    spreads = spreads_across(around, direction)  # ascending; the first ~ 0
    return float(spreads[1] / spreads[2]) if spreads[2] > 0 else 1.0


def spreads_across(points, direction):
    """The standard deviations of ``points`` (P, 3) across the unit ``direction``, ascending (the first ~ 0, along
    it): how thick and how wide they spread around that axis."""
    across = points - points.mean(axis=0)
    across -= np.outer(across @ direction, direction)
    return np.sqrt(np.maximum(np.linalg.eigvalsh(across.T @ across / len(points)), 0.0))


def _nearest_links(graph, vertices):
    """The graph's links (a, b) with a < b, and the link nearest each vertex."""
    segments = [(a, b) for a, each in enumerate(graph.neighbours) for b, _ in each if a < b]
    pairs = np.array(segments, dtype=np.int64).reshape(-1, 2)
    nearest = np.zeros(len(vertices), dtype=np.int64)
    if len(pairs):
        starts, ends = graph.points[pairs[:, 0]], graph.points[pairs[:, 1]]
        for start in range(0, len(vertices), 1024):  # blocks whose (1024, links, 3) arrays stay in cache
            nearest[start:start + 1024] = np.argmin(segment_distances(vertices[start:start + 1024], starts, ends),
                                                    axis=1)
    return segments, nearest
