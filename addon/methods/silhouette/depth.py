"""Depth: put every planar skeleton chain inside the mesh, in 3D.

Each axis node is a ray along the view direction; ``Silhouette.layers`` gives the depth intervals where that ray is
inside the mesh. A node is centred in one of them, chosen for continuity along its chain. Where a chain's rays cross
the mesh in k > 1 separate parts over much of its length (a quadruped's left and right legs seen from the side),
the chain is split into k chains, one per part, from where the parts come apart (a hand's fingers seen edge-on fork
off the one arm); copies that mirror each other across the plane each hang from one bone across the depth, from
their parent's end or the root (a leg's hips bone). Where the chosen interval is much thicker than the part is wide
(an arm in front of the body merges with it along the ray), the perpendicular silhouette decides, as in Pan et al.:
its own chordal axis, seen from the side, says at which depth a part of that width and height lies. The thresholds
are the tuning's depth section (``tuning.py``).
"""
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ...core.graphs import chains_of
from .tree import islands, rooted_chains


class Blob(NamedTuple):
    """An island whose pruned axis is a single node (a round speck): that node's point (2D) and disc radius."""

    point: np.ndarray
    radius: float


class PlacedIsland(NamedTuple):
    """An island's chains placed in 3D (``place_chains``): the root's point and (polyline, parent, widths)s."""

    root_point: np.ndarray
    chains: list


@dataclass(frozen=True)
class Placing:
    """How one view's chains are put in depth.

    Attributes:
        tuning: the method's ``Tuning``.
        speck: islands other than the largest whose axis is shorter than this (mesh units) get no bones.
        side_axis: the perpendicular view's ``SideAxis``, for depth where this view is occluded; None: none.
        split: split chains that run through several separate parts along the view (else follow one).
        mirror: (depth, tolerance) of a mirror plane the view looks across, or None: with ``split``, a chain on
            the plane stays on it where its rays pass only beside it, through parts mirroring each other (the gap
            between a head's ears seen from the side), and a leaf chain ends before a tip that does, rather than
            follow one ear off the plane; the perpendicular views find the ears (``_plane_course``).
    """

    tuning: object
    speck: float = 0.0
    side_axis: object = None
    split: bool = True
    mirror: tuple = None


def placed_islands(sil, graph, alive, kept, placing):
    """Per island of the pruned axis (``graph``'s nodes ``alive`` joined by the links ``kept``), largest first: a
    ``PlacedIsland`` (its chains in 3D), or a ``Blob`` for an island that is a single node; specks (``Placing``)
    are skipped: skinning gives them to the nearest bone."""
    for number, (nodes, links, size) in enumerate(islands(graph, alive, kept)):
        if number and size < placing.speck:
            continue
        keys, island_chains = chains_of(nodes, links)
        if not island_chains:
            widest = nodes[int(np.argmax(graph.radius[nodes]))]
            yield Blob(graph.points[widest], graph.radius[widest])
            continue
        root, rooted = rooted_chains(graph.points, keys, island_chains, graph.radius, placing.tuning)
        yield PlacedIsland(*place_chains(sil, graph.points, graph.radius, root, rooted, placing))


def place_chains(sil, points, radius, root, chains, placing):
    """3D polylines for the rooted ``chains`` (see ``tree.rooted_chains``).

    Args:
        sil: the view's ``Silhouette``.
        points, radius: the axis nodes (n, 2) in ``sil``'s frame and their half-widths.
        root: the root node; chains: ``tree.Chain`` list, parents first.
        placing: how (``Placing``).

    Returns (root_point, placed) with ``placed`` a list of (polyline (k, 3), parent_index, half-widths (k,)) —
    parents first; a split chain yields several entries with the same parent, or, split into twin parts, each its
    bone across (``_across``) and itself hanging from it.
    """
    tuning, mirror = placing.tuning, placing.mirror
    used = sorted({root} | {n for c in chains for n in c.nodes})
    slot = {n: i for i, n in enumerate(used)}
    layers = [solid_layers(layer, radius[n], tuning) for layer, n in zip(sil.layers(points[used]), used)]
    root_layers = layers[slot[root]]
    root_depth = _middle(root_layers[np.argmax(root_layers[:, 1] - root_layers[:, 0])]) if len(root_layers) else 0.0
    root_point = sil.lift(points[[root]], [root_depth])[0]
    end_depth = {-1: root_depth}
    ends_of = {-1: []}  # chain -> the placed entries its child chains hang from (its outer copies)
    root_is_end = sum(chain.parent < 0 for chain in chains) == 1
    has_children = {chain.parent for chain in chains}
    placed = []
    for ci, chain in enumerate(chains):
        nodes = np.asarray(chain.nodes)
        node_layers = [layers[slot[n]] for n in chain.nodes]
        copies, parts, plane = 1, node_layers, None  # plane: the mirror this chain keeps to, if any
        if placing.split:
            parts = [separate_parts(layer, r, tuning) for layer, r in zip(node_layers, radius[nodes])]
            copies = layer_count(parts, tuning)
            if copies > 1 and _merged_again(parts):
                copies = 1
            if copies == 1 and mirror is not None:
                end, stays = _plane_course(node_layers, *mirror, leaf=ci not in has_children)
                nodes, node_layers, parts = nodes[:end], node_layers[:end], parts[:end]
                plane = mirror if stays else None
        chain_points, chain_radius = points[nodes], radius[nodes]
        widths = chain_radius
        if chain.parent < 0 and root_is_end:
            widths = np.r_[0.0, widths[1:]]  # no branch point here: no disc for the chain to leave (chain_joints)
        fork = fork_point(parts, chain_radius, copies, tuning) if copies > 1 else 0
        pieces = [(slice(0, fork + 1), 1), (slice(fork, None), copies)] if fork else [(slice(None), copies)]
        parents = ends_of[chain.parent]
        copies_placed = []  # this chain's entries, without the bones across (``_across``)
        for part, count in pieces:
            first = len(copies_placed)
            followed = _follow((parts if count > 1 else node_layers)[part], count, end_depth[chain.parent], plane)
            twins = count == 2 and mirror is not None and _twin_parts(parts[part], *mirror)
            if twins:
                followed = _twin_copies(followed, mirror[0])
                if len(parents) == 1:
                    _end_on_plane(placed[parents[0]][0], sil, mirror[0])
            for copy in range(count):
                depths = resolve_occlusion(sil, chain_points[part], chain_radius[part], node_layers[part],
                                           followed[copy], placing, followed[:copy] + followed[copy + 1:])
                line = sil.lift(chain_points[part], depths)
                parent, start = -1, root_point if chain.parent < 0 else None
                if parents:
                    # a copy hangs from the copy of its parent chain that ends nearest to it
                    probe = line[min(1, len(line) - 1)]
                    parent = min(parents, key=lambda p: np.linalg.norm(placed[p][0][-1] - probe))
                    start = placed[parent][0][-1]
                if twins and start is not None and np.linalg.norm(line[0] - start) > sil.cell:
                    placed.append(_across(start, line[0], parent))
                    parent = len(placed) - 1
                elif parents:
                    line[0] = start
                placed.append((line, parent, widths[part]))
                copies_placed.append(len(placed) - 1)
            parents = copies_placed[first:]
        ends_of[ci] = parents
        end_depth[ci] = depths[-1]
    return root_point, placed


def _end_on_plane(line, sil, depth):
    """Move the end of a placed ``line`` that twin copies hang from onto the mirror plane at ``depth`` when it lies
    more than a grid cell off it: a stretch before the twins (a fork's piece, a head below its ears) may have
    followed one of them, and the other twin's bone across the depth would start in its twin (one hip's bone to the
    other hip)."""
    off = depth - sil.project(line[-1:])[1][0]
    if abs(off) > sil.cell:
        line[-1] += off * sil.direction


def _across(start, end, parent):
    """The placed entry of a bone across the depth, from its parent's end (or the root) ``start`` to where a copy of
    a chain split into twin parts begins at its own depth, ``end``: a leg seen from the side hangs straight down from
    its hip beside the body's middle, not slanting from the middle to its first node below, and this is its hips
    bone, one bone on top of the leg's own (:func:`is_across`)."""
    return np.vstack([start, end]), parent, np.zeros(2)


def is_across(line, widths):
    """Whether a placed chain (its ``line`` and ``widths``) is a bone across the depth (:func:`_across`): two points
    with no part around them (zero widths)."""
    return len(line) == 2 and not widths.any()


def _middle(interval):
    return 0.5 * (interval[0] + interval[1])


def solid_layers(layer, radius, tuning):
    """One node's depth intervals without those thinner than ``sheet_thickness`` times its half-width when a thicker one
    exists: the zero-thickness intervals of open sheets (a cloak's hem) are not parts a chain should split into."""
    if len(layer) < 2:
        return layer  # the common case, kept free of numpy calls: nodes are many
    thick = layer[:, 1] - layer[:, 0] >= tuning.sheet_thickness * radius
    return layer[thick] if thick.any() else layer


def separate_parts(layer, radius, tuning):
    """The intervals of one node that count as separate parts for splitting: those at least ``part_thickness`` times its
    half-width thick, a limb's round cross-section, not the plates and shells of one limb (a robot's forearm, a
    sheet), and ``part_alike`` as thick as the thickest (legs and fingers side by side are alike; a nose or a hat's brim
    beside a head is not a second head); a single part spanning all the intervals when none is that thick."""
    if len(layer) < 2:
        return layer  # the common case, kept free of numpy calls: nodes are many
    size = layer[:, 1] - layer[:, 0]
    thick = size >= max(tuning.part_thickness * radius, tuning.part_alike * size.max())
    if thick.any():
        return layer[thick]
    return np.array([[layer[0, 0], layer[-1, 1]]])


def fork_point(parts, radius, copies, tuning):
    """Where a chain that runs through ``copies`` parts forks into them: the last node before the outer stretch over
    which (for ``fork_share`` of its nodes) the parts are apart, when the chain runs through one round part of its own
    width before it (a hand's fingers off an arm: one arm, then a chain per finger); else 0, the parts apart from
    the start (a leg pair seen from the side merges with the body and each other towards its parent)."""
    apart = np.array([len(layer) >= 2 for layer in parts], dtype=float)
    share = np.cumsum(apart[::-1])[::-1] / np.arange(len(apart), 0, -1)
    if not (share >= tuning.fork_share).any():
        return 0
    start = int(np.argmax(share >= tuning.fork_share))
    start += int(np.argmax(apart[start:]))  # the stretch begins where the parts are first apart
    if start < 2 or not any(len(layer) == copies for layer in parts[start:]):
        return 0
    thickness = [layer[:, 1].max() - layer[:, 0].min() if len(layer) else 0.0 for layer in parts[:start]]
    own = np.median(np.array(thickness) / (2 * np.maximum(radius[:start], 1e-300))) <= tuning.round_part
    return start - 1 if own else 0


def _plane_course(node_layers, depth, tolerance, leaf):
    """(how many nodes to keep, whether to keep to the plane) for a single chain seen across a mirror plane at
    ``depth``: where no tip stretch of its nodes passes only beside the plane (``_beside``), all of them, keeping
    to the plane across gaps; for a ``leaf`` whose tip stretch does, after a node whose rays cross the plane inside
    the mesh, the nodes before that stretch, keeping to the plane; else all of them, following one part as without
    a plane (a chain wholly beside the plane, or one that others hang from, would otherwise run through the air).
    The stretch takes in the nodes before it whose rays pass one side's part only: on a mirror-symmetric mesh the
    twin part is there too, and the rays just miss its edge."""
    start = len(node_layers)
    while start > 0 and _beside(node_layers[start - 1], depth, tolerance):
        start -= 1
    if start < len(node_layers):  # before it, nodes whose rays miss one twin (a thin ear's noisy edge) join it
        while start > 0 and len(node_layers[start - 1]) and not _holds(node_layers[start - 1].tolist(), depth):
            start -= 1
    if start == len(node_layers) or (leaf and start >= 2 and _holds(node_layers[start - 1].tolist(), depth)):
        return start, True
    return len(node_layers), False


def _beside(layer, depth, tolerance):
    """Whether one node's depth ``layer`` flanks the plane at ``depth``: two or more intervals, none holding it,
    mirroring each other across it (plain floats, as in ``_track``, which asks this of every node)."""
    if len(layer) < 2:
        return False
    intervals = layer.tolist()  # the k-th interval's low end mirrors the k-th from the back's high end
    if _holds(intervals, depth):
        return False
    return max(abs(2 * depth - low - high) for (low, _), (_, high) in zip(intervals, reversed(intervals))) <= tolerance


def _holds(intervals, depth):
    """Whether one of a node's depth ``intervals`` ((low, high) pairs of plain floats) contains ``depth``."""
    return any(low <= depth <= high for low, high in intervals)


def layer_count(node_layers, tuning):
    """How many separate parts a chain runs through, judged over its outer nodes (all but the first
    ``1 / near_parent_divisor``: near its parent it often runs into the body): the fewest parts (more than one) that a
    ``split_share`` of those nodes cross, else the most frequent count; fewer still, k > 1, when from the chain's start
    up to its first node crossing more than k parts the nodes crossing k outnumber the unsplit ones.
    Fewest, because parts split further towards the tip (a dinosaur's feet, each with its toes) are still one limb
    each, however far the toes run; a hand whose fingers part one after another is split as far as they go."""
    counts = np.array([len(layer) for layer in node_layers])
    outer = counts[len(counts) // tuning.near_parent_divisor:]
    outer = outer[outer > 0]
    if not len(outer):
        return 1
    frequency = np.bincount(outer)
    several = np.flatnonzero(frequency[2:] >= tuning.split_share * len(outer)) + 2
    if not len(several):
        return int(np.argmax(frequency))
    seen = counts[counts > 0]
    for fewer in range(2, int(several[0])):
        before = seen[:int(np.argmax(seen > fewer))]
        if (before == fewer).sum() > (before < fewer).sum():
            return fewer
    return int(several[0])


def _follow(node_layers, copies, start, mirror=None):
    """Depth along a chain for each of its ``copies`` (one unless it is split), always the middle of an interval.

    A single chain follows, from its start, the interval nearest the previous depth; on a ``mirror`` plane ((depth,
    tolerance) or None) it stays there across nodes whose rays pass only beside it (ears on each side of a head), not
    stepping to the one side or the other. Copy k of a split chain is anchored at interval k (front to back) of the
    outermost node crossing exactly ``copies`` intervals and followed from there both ways by nearest depth, so it
    never jumps to the other part where some node sees the parts merged or an extra part: towards the parent it is
    centred in its part while the parts are apart (a splayed leg's middle, not its foot's depth) and keeps its depth
    while an interval holds it where they are not (they merge with each other and the body there), and past the
    anchor it never steps into an interval another copy is in (two arms seen one behind the other, where the rays
    past the front one's wrist hit only the back one: the front arm's copy keeps its depth), nor into one another
    copy nearer to it steps into (past the shorter fingers' tips the longest finger's copy goes on; the others keep
    their depths rather than all running into it).
    """
    if copies == 1:
        depths = np.full(len(node_layers), np.nan)
        _track(node_layers, range(len(node_layers)), start, depths, mirror=mirror)
        return [depths]
    anchor = _anchor(node_layers, copies)
    followed = [np.full(len(node_layers), np.nan) for _ in range(copies)]
    for copy, depths in enumerate(followed):
        depths[anchor] = _middle(node_layers[anchor][copy])
        _track(node_layers, range(anchor - 1, -1, -1), depths[anchor], depths, stay=copies)
    for i in range(anchor + 1, len(node_layers)):
        intervals = node_layers[i].tolist()
        held = [next((k for k, (low, high) in enumerate(intervals) if low <= depths[i - 1] <= high), None)
                for depths in followed]
        for depths in followed:
            depths[i] = depths[i - 1]
        taken = set(held) - {None}
        steps = sorted((max(low - depths[i - 1], 0.0) + max(depths[i - 1] - high, 0.0), copy, k)
                       for copy, depths in enumerate(followed) if held[copy] is None
                       for k, (low, high) in enumerate(intervals) if k not in taken)
        moved = set()
        for _, copy, k in steps:  # the nearest copy steps into a free interval; one copy per interval
            if copy not in moved and k not in taken:
                followed[copy][i] = 0.5 * (intervals[k][0] + intervals[k][1])
                moved.add(copy)
                taken.add(k)
    return followed


def _merged_again(parts):
    """Whether the parts a chain's rays cross come together again before its tip: past the outermost node crossing
    two or more, the rays cross one part at every node (three at least), and at the first of them that part spans
    the gap between the outer two (a head with eye holes or horns seen edge-on, not two ears or legs, which end
    apart, nor an arm behind a shorter one, whose hand the rays past the front wrist cross alone)."""
    apart = [i for i, layer in enumerate(parts) if len(layer) >= 2]
    if not apart or len(parts) - 1 - apart[-1] < 3 or any(len(layer) != 1 for layer in parts[apart[-1] + 1:]):
        return False
    outer, (low, high) = parts[apart[-1]], parts[apart[-1] + 1][0]
    return low <= outer[0][1] and high >= outer[-1][0]


def _anchor(node_layers, copies):
    """The outermost node crossing exactly ``copies`` intervals: where a split chain's copies are surely apart."""
    return max(i for i, layer in enumerate(node_layers) if len(layer) == copies)


def _twin_parts(parts, depth, tolerance):
    """Whether a chain split in two runs through parts that mirror each other across the plane at ``depth`` (at the
    outermost node that sees them apart: a pair of legs or ears seen from the side), not parts on one side of it
    (fingers seen edge-on)."""
    return _beside(parts[_anchor(parts, 2)], depth, tolerance)


def _twin_copies(followed, depth):
    """The two ``followed`` copies of a chain split into twin parts (:func:`_twin_parts`) as twins: the copy that
    keeps to one side of the plane at more nodes, and its mirror image, since where one part hides the other the
    other copy may have stepped across to it. Where the kept copy itself stepped across into its twin's part (a foot
    among splayed toes), it takes that depth's mirror image, in its own part: twins never cross the plane."""
    sides = [np.sign(copy - depth) for copy in followed]
    kept = max((0, 1), key=lambda k: abs(sides[k].sum()))
    own = np.where(sides[kept] == -np.sign(sides[kept].sum()), 2 * depth - followed[kept], followed[kept])
    image = 2 * depth - own
    return [own, image] if kept == 0 else [image, own]


def _track(node_layers, order, previous, depths, stay=0, mirror=None):
    """Follow a part along its chain: at each node take the interval the previous depth lies in, else the one
    nearest to it (distance to the interval, not to its middle, so a thick neighbour does not steal the track),
    and centre in it — or, with ``stay`` (a chain's copy count), keep the previous depth while an interval still
    contains it at nodes that do not cross that many parts (where they merge); on the ``mirror`` plane, keep it where
    the intervals flank the plane (``_beside``)."""
    for i in order:  # plain floats: the intervals are few, and numpy's per-call cost would dominate
        layer = node_layers[i]
        on_plane = mirror is not None and abs(previous - mirror[0]) <= mirror[1]
        if len(layer) and not (on_plane and _beside(layer, *mirror)):
            gap, low, high = min((max(low - previous, 0.0) + max(previous - high, 0.0), low, high)
                                 for low, high in layer.tolist())
            if not (stay and gap == 0.0 and len(layer) != stay):
                previous = 0.5 * (low + high)
        depths[i] = previous


def resolve_occlusion(sil, points, radius, node_layers, depths, placing, siblings=()):
    """Where a node's interval is much thicker than its part is wide, take the depth from the side view instead,
    choosing among the side-view candidates the one closest to the previous node's depth (so a chain never
    hops between two legs that the side view shows at the same height). A thick interval at one node alone, between
    nodes that see the part by itself, is a slip of the ray casting (hits paired across two legs), not an arm in
    front of the body: it is left alone. So is one that holds a ``siblings`` depth, the other copies of a split
    chain: there the parts merge (a cow's thighs into its hips) and each copy keeps its own side, rather than two of
    them taking the same side-view part."""
    side_axis, tuning = placing.side_axis, placing.tuning
    if side_axis is None:
        return depths
    out = depths.copy()
    previous = depths[0]
    typical = max(float(np.median(radius)), sil.cell)  # not the tip's vanishing radius
    limits = (tuning.occlusion_ratio * 2 * np.maximum(radius, typical)).tolist()
    chosen = [min(layer.tolist(), key=lambda interval: abs(0.5 * (interval[0] + interval[1]) - depth))
              if len(layer) else None for layer, depth in zip(node_layers, depths.tolist())]
    thick = np.array([c is not None and c[1] - c[0] > limit for c, limit in zip(chosen, limits)])
    for other in siblings:
        thick &= [c is None or not c[0] <= d <= c[1] for c, d in zip(chosen, other.tolist())]
    thick &= np.r_[False, thick[:-1]] | np.r_[thick[1:], False]  # a single node is a tracing slip, not a body
    lifted = sil.lift(points, 0.0) if thick.any() else None
    for i, interval in enumerate(chosen):
        if thick[i]:
            found = side_axis.depth_at(lifted[i], radius[i], interval, previous, tuning.side_width_cost)
            if found is not None:
                out[i] = found
        previous = out[i]
    return out


class SideAxis:
    """The chordal axis of the perpendicular silhouette, indexed for depth look-ups.

    The two views share the axis ``w`` perpendicular to both directions. A primary node at height ``w`` is matched
    with side-view axis nodes at the same ``w``; their coordinate along the primary direction is the depth.
    """

    def __init__(self, side_sil, points, radius, primary_sil):
        """``points`` (n, 2) and ``radius`` (n,): the side view's chordal axis nodes in ``side_sil``'s plane; depths
        are in ``primary_sil``'s frame."""
        world = side_sil.lift(points, 0.0)
        self.w_axis = np.cross(primary_sil.direction, side_sil.direction)
        self.w = world @ self.w_axis
        self.depth = world @ primary_sil.direction - float(primary_sil.origin @ primary_sil.direction)
        self.radius = radius
        self.cell = side_sil.cell

    def depth_at(self, point, radius, interval, previous, width_cost):
        """Depth (in the primary view's frame) of the side-view part matching a primary node at ``point`` (3D, on
        the primary view's plane), inside ``interval``: of the side-view axis nodes at the node's height, the one
        nearest ``previous``, a width difference costing ``width_cost`` per unit of depth; None if no side-view
        node fits."""
        depth = self.depth
        near = np.abs(self.w - float(point @ self.w_axis)) <= max(radius, self.cell)
        near &= (depth >= interval[0]) & (depth <= interval[1])
        if not near.any():
            return None
        candidates = np.flatnonzero(near)
        cost = np.abs(depth[candidates] - previous) + width_cost * np.abs(self.radius[candidates] - radius)
        return float(depth[candidates[np.argmin(cost)]])
