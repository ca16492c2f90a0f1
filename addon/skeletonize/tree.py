"""From a chordal-axis graph to a rooted tree of chains: blob merging, spur pruning, cycle cutting, rooting.

A *chain* is a polyline of axis nodes between two *key* nodes (ends and branch points). The steps:

1. Blob merging (Pan's "merge the triangles that lie within one maximal inscribed disc"): every junction, largest
   first, swallows the axis nodes it reaches without leaving its disc. A round head or belly thus becomes one node
   instead of a tree of spurious little branches.
2. Spur pruning: a branch that pokes out of the disc it hangs on by less than ``prune`` times its own width is a
   bump or outline noise, not a limb; it is removed, repeatedly, since removing one can expose another. A branch
   reaching far enough is kept however wide, and so is one ending in a round part of its own (a head without a
   neck), one whose mirror image is kept, or a mirror pair of stubbier ones (two ears); on a mesh without a mirror
   plane, a pair of stubbier ones alike in size (a hand-made figure's arms).
3. Rooting at the most central branch point (smallest largest distance to any end), then cutting every cycle (holes
   in the silhouette) where the two ways around it from the root meet. A path without branch points is rooted at
   its widest node, or at its thicker end when it is about equally wide throughout.
"""
import heapq
from dataclasses import dataclass

import numpy as np

from .polyline import arc_lengths, length

UNIFORM = 1.25  # a path whose widest node is at most this many times its median width is a column, not a body
LOCAL_PAIR = 1.5  # spurs off one base are a pair when (ratio of their reaches) x (ratio of their widths) <= this
ROUND_TIP = 0.7  # a spur ending in a blob at least this share of its base's width, outside the base's disc, is a part


@dataclass
class Chain:
    """A polyline of axis nodes from ``nodes[0]`` (towards the root) to ``nodes[-1]``; ``parent`` is the index of
    the chain it hangs from (-1 for chains leaving the root)."""

    nodes: list
    parent: int


def merge_discs(points, radius, junction, links, scale=1.0):
    """Contract the nodes each junction's disc (radius times ``scale``) reaches into that junction.

    Returns (representative, links): ``representative[i]`` is the node that node ``i`` became, and the links
    between representatives (no self-links, no duplicates).
    """
    count = len(points)
    neighbours = _adjacency(count, links)
    owner = np.full(count, -1, dtype=np.int64)
    for centre in np.flatnonzero(junction)[np.argsort(-radius[junction], kind="stable")]:
        if owner[centre] >= 0:
            continue
        owner[centre] = centre
        reach = (scale * radius[centre]) ** 2
        stack = [centre]
        while stack:
            node = stack.pop()
            for other in neighbours[node]:
                if owner[other] < 0 and ((points[other] - points[centre]) ** 2).sum() <= reach:
                    owner[other] = centre
                    stack.append(other)
    representative = np.where(owner >= 0, owner, np.arange(count))
    merged = representative[links] if len(links) else links
    merged = merged[merged[:, 0] != merged[:, 1]]
    merged = np.unique(np.sort(merged, axis=1), axis=0) if len(merged) else merged.reshape(0, 2)
    return representative, merged


def chains_of(nodes, links):
    """Split the graph on ``nodes`` into chains between key nodes (degree other than 2). Returns (keys, chains)
    with chains as node lists; a cycle without key node is opened at its lowest node."""
    neighbours = {n: [] for n in nodes}
    for a, b in links.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    keys = {n for n, adj in neighbours.items() if len(adj) != 2}
    arrived = set()  # (key, node before it) of every chain walked: its far end, not to be walked back
    chains = []
    for start in sorted(keys):
        for first in neighbours[start]:
            if (start, first) not in arrived:
                chains.append(_walk(start, first, neighbours, keys, arrived))
    walked = {n for chain in chains for n in chain}
    for start in sorted(neighbours):  # pure cycles
        if start not in keys and start not in walked:
            keys.add(start)
            chain = _walk(start, neighbours[start][0], neighbours, keys, arrived)
            walked.update(chain)
            chains.append(chain)
    return keys, chains


def _walk(start, first, neighbours, keys, arrived):
    path = [start, first]
    before, here = start, first
    while here not in keys:
        a, b = neighbours[here]
        before, here = here, (a if a != before else b)
        path.append(here)
    arrived.add((here, before))
    return path


def prune_spurs(points, radius, chains, prune, min_reach=0.0, max_reach=np.inf, mirror=None, blobs=None,
                pair_prune=None, local_pairs=False):
    """Drop leaf chains that stick out of the disc of the node they hang on by less than ``prune`` times their own
    width, or by less than ``min_reach``, but never by ``max_reach`` or more, until none does. ``chains`` are node
    lists; returns the surviving links.

    A limb is long for its width where it leaves the base (a leg, a finger, a tail, a neck with its head) while
    outline noise and bumps (an ear on a round head, a belly) are not, whatever their size, up to ``max_reach``: a
    part reaching that far needs bones of its own however wide it is (a cow's short thick neck with its head).
    With ``blobs``, a (n,) mask of the nodes that stand for a round part (junctions, which swallow the axis within
    their disc), a spur reaching ``min_reach`` and ending in one whose centre lies outside the base's disc and
    whose width is at least ``ROUND_TIP`` times the base's is kept: a gingerbread man's head sits on its shoulders
    without a neck, and a cartoon's round feet hang straight off its hips.
    With ``mirror``, a function reflecting (P, 2) points across the mesh's mirror plane, a spur whose mirror image
    is a branch kept off the same base stays too: a figure's two arms off its chest, each near the threshold, are
    kept or dropped together. With ``pair_prune`` as well, two spurs off one base that mirror each other and stick
    out by more than ``min_reach`` and ``pair_prune`` times their width both stay: a pair is a limb where a lone
    bump of that size is not (a dog's two ears on its head; outline noise is not symmetric). With ``pair_prune`` and
    ``local_pairs`` instead (a mesh without a mirror plane), two such spurs off one base that stick out about as far
    and are about as wide both stay (``_local_pairs``).
    """
    chains = [list(c) for c in chains]
    dropped = []  # with local_pairs, the pairable spurs removed so far (``pairable`` entries below)
    while True:
        degree = {}
        for chain in chains:
            for end in (chain[0], chain[-1]):
                degree[end] = degree.get(end, 0) + 1
        # chain -> (base, tip) of the spurs; chain -> (base, nodes from base to tip, reach beyond the base, width) of
        # those that may pair; (chain, base, its nodes outside the base's disc) of the kept leaves and those that may
        # pair
        spurs, pairable, leaves = {}, {}, []
        for i, chain in enumerate(chains):
            for base, tip in ((chain[0], chain[-1]), (chain[-1], chain[0])):
                if degree[tip] == 1 and degree[base] >= 3:
                    apart = np.linalg.norm(points[tip] - points[base])
                    beyond = apart + radius[tip] - radius[base]
                    # width where the branch leaves the base disc: a neck, not the head it carries
                    ordered = np.array(chain if chain[0] == base else chain[::-1])
                    outside = ordered[np.linalg.norm(points[ordered] - points[base], axis=1) > radius[base]]
                    width = 2 * float(radius[outside[:3]].mean()) if len(outside) else 2 * float(radius[tip])
                    bump = beyond <= prune * width and not (  # the round-part test only where it can matter
                        blobs is not None and _round_part(apart, radius, blobs, base, tip))
                    spur = beyond < max_reach and (beyond <= min_reach or bump)
                    may_pair = spur and pair_prune is not None and beyond > max(min_reach, pair_prune * width)
                    if spur:
                        spurs[i] = base, tip
                    if may_pair:
                        pairable[i] = base, ordered, beyond, width
                    if may_pair or not spur:
                        leaves.append((i, base, outside))
                    break
        if spurs and mirror is not None:
            spurs = _unmirrored(spurs, pairable, leaves, points, radius, mirror)
        if not spurs:
            links = _links_of(chains)
            return np.vstack([links, _links_of(_local_pairs(dropped, links, points))]) if dropped else links
        if local_pairs:
            dropped += [pairable[i] for i in spurs if i in pairable]
        # every spur goes at once: the two corner branches at the end of a limb leave the limb ending at their fork
        kept = [c for i, c in enumerate(chains) if i not in spurs]
        if not kept:
            return np.zeros((0, 2), dtype=np.int64)
        _, chains = chains_of(sorted({n for c in kept for n in c}), _links_of(kept))


def _round_part(apart, radius, blobs, base, tip):
    """Whether leaf node ``tip``, ``apart`` from ``base``, is a blob as wide as a part of its own, lying off the disc
    of ``base``."""
    return bool(blobs[tip]) and radius[tip] >= ROUND_TIP * radius[base] and apart > radius[base]


def _unmirrored(spurs, pairable, leaves, points, radius, mirror):
    """The ``spurs`` (chain -> (base, tip)) without a twin: another leaf off the same base (``leaves``: (chain,
    base, its nodes outside the base's disc) each) that stays, with a node whose disc holds the spur tip's mirror
    image. A kept leaf is a twin to every spur. Two ``pairable`` spurs (long enough for limbs when they come in pairs)
    are twins when each one's image lies on the other, so that two ears each under the threshold stay together,
    and neither stays for lying on a longer one that goes. The base's own disc covers the body, so a bump whose
    image falls on it still goes."""
    beside = {}
    for chain, base, outside in leaves:
        beside.setdefault(base, []).append((chain, outside))
    beside = {base: (np.concatenate([outside for _, outside in parts]),
                     np.concatenate([np.full(len(outside), chain) for chain, outside in parts]))
              for base, parts in beside.items()}
    images = mirror(points[[tip for _, tip in spurs.values()]])
    lying_on = {}  # spur -> the leaves off its base whose discs hold its tip's image
    for (i, (base, _)), image in zip(spurs.items(), images):
        nodes, owners = beside.get(base, (np.zeros(0, np.int64), np.zeros(0, np.int64)))
        lying_on[i] = set(owners[np.linalg.norm(points[nodes] - image, axis=1) <= radius[nodes]].tolist()) - {i}
    return {i: spurs[i] for i, twins in lying_on.items() if not any(
        chain not in spurs or (i in pairable and i in lying_on[chain]) for chain in twins)}


def _local_pairs(dropped, links, points):
    """Node lists of the spurs among ``dropped`` ((base, nodes from base to tip, reach, width) each, pruned although
    they stick out enough to be limbs in a pair) that pair up off a base the kept tree (``links``) still runs through
    (two links at least: not the end a limb's two corner branches forked from): the ratio of their reaches times the
    ratio of their widths at most ``LOCAL_PAIR``, their tips farther apart than either is wide, the most alike paired
    first. A hand-made figure's two stubby arms or ears are never exact mirror images, while outline noise does not
    come in such pairs."""
    degree = np.bincount(links.ravel(), minlength=len(points))
    by_base = {}
    for spur in dropped:
        if degree[spur[0]] >= 2:
            by_base.setdefault(spur[0], []).append(spur)
    restored = []
    for spurs in by_base.values():
        pairs = []
        for a in range(len(spurs)):
            for b in range(a):
                (_, nodes_a, reach_a, width_a), (_, nodes_b, reach_b, width_b) = spurs[a], spurs[b]
                unlike = max(reach_a / reach_b, reach_b / reach_a) * max(width_a / width_b, width_b / width_a)
                apart = np.linalg.norm(points[nodes_a[-1]] - points[nodes_b[-1]])
                if unlike <= LOCAL_PAIR and apart > max(width_a, width_b):
                    pairs.append((unlike, a, b))
        used = set()
        for _, a, b in sorted(pairs):
            if a not in used and b not in used:
                used |= {a, b}
                restored += [list(spurs[a][1]), list(spurs[b][1])]
    return restored


def _links_of(chains):
    pairs = [(c[i], c[i + 1]) for c in chains for i in range(len(c) - 1)]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def rooted_chains(points, keys, chains, radius):
    """Root the chain graph at its most central branch point and cut its cycles; returns (root, [Chain])
    ordered parents first."""
    lengths = [length(points[c]) for c in chains]
    adjacency = {}
    for i, c in enumerate(chains):
        adjacency.setdefault(c[0], []).append((c[-1], i))
        adjacency.setdefault(c[-1], []).append((c[0], i))
    branch_points = [k for k in keys if len(adjacency.get(k, ())) >= 3]
    if branch_points:
        root = min(branch_points, key=lambda k: (max(_distances(k, adjacency, lengths).values()), -radius[k]))
    else:
        return _root_single_path(chains, keys, radius)
    dist, via = _shortest_paths(root, adjacency, lengths)
    tree = set(via.values())
    ordered = []
    chain_of_end = {}
    # chains on shortest paths, parents first (by distance of their near end)
    for i in sorted(tree, key=lambda i: min(dist[chains[i][0]], dist[chains[i][-1]])):
        nodes = chains[i] if dist[chains[i][0]] <= dist[chains[i][-1]] else chains[i][::-1]
        chain_of_end[nodes[-1]] = len(ordered)
        ordered.append(Chain(nodes, chain_of_end.get(nodes[0], -1) if nodes[0] != root else -1))
    # cycles: cut each remaining chain where the ways round from the root meet
    for i in range(len(chains)):
        if i in tree:
            continue
        nodes = chains[i]
        steps = arc_lengths(points[nodes])
        from_start = dist[nodes[0]] + steps
        from_end = dist[nodes[-1]] + (steps[-1] - steps)
        cut = int(np.clip(np.searchsorted(from_start - from_end, 0.0), 1, len(nodes) - 1))
        for half in (nodes[:cut], nodes[cut:][::-1]):
            if len(half) > 1:
                ordered.append(Chain(half, chain_of_end.get(half[0], -1) if half[0] != root else -1))
    return root, ordered


def _root_single_path(chains, keys, radius):
    """A graph without branch points is one path. Root it at its widest node, the body (a bird with spread wings,
    a fish), with a chain each way; a path about as wide everywhere (a column, a tentacle) is rooted at its thicker
    end instead, one chain from its base, as an artist would rig it."""
    nodes = chains[0] if chains else sorted(keys)
    width = radius[nodes]
    quarter = max(1, len(nodes) // 4)  # the very ends taper to a point whatever the part's width
    if width.max() <= UNIFORM * np.median(width):
        if width[-quarter:].mean() > width[:quarter].mean():
            nodes = nodes[::-1]
        return nodes[0], [Chain(list(nodes), -1)] if len(nodes) > 1 else []
    middle = int(np.argmax(width))
    halves = [nodes[middle:], nodes[:middle + 1][::-1]]
    return nodes[middle], [Chain(h, -1) for h in halves if len(h) > 1]


def _distances(source, adjacency, lengths):
    return _shortest_paths(source, adjacency, lengths)[0]


def _shortest_paths(source, adjacency, lengths):
    """Dijkstra over the chain graph: distance to every key node and the chain each was reached through."""
    dist = {source: 0.0}
    via = {}
    heap = [(0.0, source)]
    while heap:
        d, node = heapq.heappop(heap)
        if d > dist[node]:
            continue
        for other, chain in adjacency.get(node, ()):
            nd = d + lengths[chain]
            if nd < dist.get(other, np.inf):
                dist[other] = nd
                via[other] = chain
                heapq.heappush(heap, (nd, other))
    return dist, via


def _adjacency(count, links):
    neighbours = [[] for _ in range(count)]
    for a, b in links.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    return neighbours
