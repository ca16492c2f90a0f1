"""From a chordal-axis graph to a rooted tree of chains: blob merging, spur pruning, cycle cutting, rooting.

A *chain* is a polyline of axis nodes between two *key* nodes (ends and branch points). The steps:

1. Blob merging (Pan's "merge the triangles that lie within one maximal inscribed disc"): every junction, largest
   first, swallows the axis nodes it reaches without leaving its disc, so a round head becomes one node.
2. Spur pruning (``prune_spurs``): branches that are bumps or outline noise go, repeatedly, since removing one can
   expose another; junctions the kept axis zigzags through move onto the chords across the part (``_zigzag``).
3. Rooting at the most central branch point, then cutting every cycle (holes in the silhouette) where two parts
   touch (``_cut_cycle``).
"""
from dataclasses import dataclass

import numpy as np

from ...core.graphs import chains_of, links_of, neighbour_lists, shortest_paths
from ...core.polyline import arc_lengths, length, segment_distances
from .chordal import on_mirror_line
from .tuning import Tuning


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
    neighbours = neighbour_lists(count, links)
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


@dataclass(frozen=True)
class Pruning:
    """What spur pruning keeps in one view (``prune_spurs``).

    Attributes:
        prune: a branch sticking out of its base's disc by at most this many times its width is a bump ...
        min_reach: ... and so is one sticking out by at most this (mesh units), however thin ...
        max_reach: ... but never one reaching this far (mesh units): a cow's short thick neck with its head (as far
            as the spurs pruned off its end reached: noise that forks its outline earlier does not shorten it).
        pair_prune: two twin spurs sticking out more than this many times their width (and ``min_reach``) stay;
            None: spurs never pair.
        mirror: a function reflecting (P, 2) points of the view across the mesh's mirror plane, or None.
        local_pairs: without a mirror plane, pair spurs alike in size (``_local_pairs``).
        ground: (low (2,), high (2,), tolerance) of the view's outline: a stubby spur standing on a side of it that a
            kept leaf (or another stubby spur) stands on too stays (``_standing``); None: no such rule.
        heads: a spur running on past a round part (``_round_part_on``) goes only beyond it (the primary view's
            heads; the hidden views look for limbs, and a remnant there is no limb).
        outline: the view's outline edges (starts, ends), for a branch's width where its axis jumps off the base's
            disc (``_jump_width``); None: widths from the nodes alone.
        tuning: the method's tuning (``round_tip``, ``local_pair``, ``width_nodes``).
    """

    prune: float
    min_reach: float = 0.0
    max_reach: float = np.inf
    pair_prune: float = None
    mirror: object = None
    local_pairs: bool = False
    ground: tuple = None
    heads: bool = False
    outline: tuple = None
    tuning: Tuning = Tuning()


def pruned_tree(graph, merge, pruning):
    """Blob merging (discs grown ``merge`` times) and spur pruning (``pruning``) of a ``ChordalAxis``, its junctions
    being the blobs that keep a spur ending in one. Returns (graph, alive nodes, merged links, kept links): the
    graph with the junctions the kept links zigzag through on their chords (``_zigzag``) and, with a mirror, its
    blobs near the mirror line centred on it (``ChordalAxis.centred_on_mirror``), which the stages show and the
    bones follow."""
    representative, merged = merge_discs(graph.points, graph.radius, graph.junction, graph.links, merge)
    alive = np.unique(representative)
    if pruning.mirror is not None:
        graph = graph.centred_on_mirror(alive[graph.junction[alive]], pruning.mirror)
    _, chains = chains_of(alive.tolist(), merged)
    kept = prune_spurs(graph.points, graph.radius, chains, pruning, blobs=graph.junction)
    return graph.passed_through(_zigzag(graph, kept)), alive, merged, kept


def _zigzag(graph, kept):
    """The junctions the ``kept`` links pass through (two links each) that lie off the middle of the part to the
    other side than a linked such junction: the axis zigzags between them (``ChordalAxis.passed_through``). Such
    junctions all off to one side are a bend, or a part whose middle bends that way."""
    if not len(kept) or graph.passing is None:
        return np.zeros(0, dtype=np.int64)
    through = graph.junction & (np.bincount(kept.ravel(), minlength=len(graph.junction)) == 2)
    pairs = kept[through[kept[:, 0]] & through[kept[:, 1]]]
    off = graph.points[pairs] - graph.passing[0][pairs]  # (pairs, 2, 2): from its chord's middle to where it sits
    crossing = (off[:, 0] * off[:, 1]).sum(axis=1) < 0
    return np.unique(pairs[crossing])


def removed_links(before, after):
    """The links of ``before`` that ``after`` lacks, each as sorted node pairs."""
    kept = set(map(tuple, np.sort(after, axis=1).tolist())) if len(after) else set()
    gone = [pair for pair in np.sort(before, axis=1).tolist() if tuple(pair) not in kept]
    return np.array(gone, dtype=np.int64).reshape(-1, 2)


def islands(graph, alive, links):
    """(nodes, links, size) per island of the live nodes ``alive`` joined by ``links``, the largest (most axis
    length) first."""
    result = []
    node_island = graph.island[alive]
    link_island = graph.island[links[:, 0]] if len(links) else np.zeros(0, graph.island.dtype)  # links join live nodes
    for island in np.unique(node_island):
        nodes = alive[node_island == island]
        sub = links[link_island == island]
        size = float(np.linalg.norm(graph.points[sub[:, 0]] - graph.points[sub[:, 1]], axis=1).sum())
        size += float(graph.radius[nodes].max())
        result.append((size, nodes.tolist(), sub))
    result.sort(key=lambda item: -item[0])
    return [(nodes, sub, size) for size, nodes, sub in result]


def prune_spurs(points, radius, chains, pruning, blobs=None):
    """Drop leaf chains (``chains``: node lists) that are bumps by the rules of ``pruning``, until none is; returns
    the surviving links.

    A limb is long for its width where it leaves the base (a leg, a finger, a tail, a neck with its head) while
    outline noise and bumps (an ear on a round head, a belly) are not, whatever their size, up to ``max_reach``;
    with an ``outline``, an axis jumping off the base's disc into a corner is as wide there as the outline says
    (``_jump_width``).
    With ``blobs``, a (n,) mask of the nodes that stand for a round part (junctions, which swallow the axis within
    their disc), a spur reaching ``min_reach`` and ending in one whose centre lies off the base's disc and whose
    width is at least ``round_tip`` times the base's is kept: a gingerbread man's head sits on its shoulders without
    a neck. With a ``mirror``, a spur whose mirror image is a branch kept off the same base stays too (a figure's two
    arms, each near the threshold, are kept or dropped together), and with ``pair_prune`` two spurs off one base
    that mirror each other stay: a pair is a limb where a lone bump of that size is not (a dog's ears; outline noise
    is not symmetric); and a spur on the mirror plane going on from a chain on it stays (``_not_going_on``: a head
    on its neck). With ``pair_prune`` and ``local_pairs`` instead, two such spurs off one base that stick out
    about as far and are about as wide stay, and so does one such spur beside a kept leaf it is that alike to
    (``_local_pairs``). With ``pair_prune`` and a ``ground``, such a spur stays when its tip stands where a kept
    leaf stands, or in a view with no mirror another such spur off another base (``_standing``): a cat's stubby front
    legs beside its hind legs, a cartoon cow's four, seen from the side.
    """
    prune, min_reach, max_reach, pair_prune = pruning.prune, pruning.min_reach, pruning.max_reach, pruning.pair_prune
    tuning = pruning.tuning
    chains = [list(c) for c in chains]
    dropped = []  # with local_pairs, the pairable spurs removed so far (``pairable`` entries below)
    stood = {}  # node -> the sides of the outline its removed spurs stood on (a leg keeps its foot's footing)
    reached = {}  # node -> the tips of the spurs removed off it: a part keeps its corners' reach
    reaching = None if pruning.ground is None else _sides_reached(points, radius, pruning.ground)
    while True:
        degree = {}
        for chain in chains:
            for end in (chain[0], chain[-1]):
                degree[end] = degree.get(end, 0) + 1
        # chain -> (base, tip) of the spurs; chain -> (base, nodes from base to tip, reach beyond the base, width) of
        # those that may pair; (chain, base, its nodes outside the base's disc) of the kept leaves and those that may
        # pair
        spurs, pairable, leaves, heads = {}, {}, [], {}  # heads: spur -> its nodes up to a round part on it
        kept_leaves = []  # (base, nodes from base to tip, reach, width) of the leaves that are no spurs
        for i, chain in enumerate(chains):
            for base, tip in ((chain[0], chain[-1]), (chain[-1], chain[0])):
                if degree[tip] == 1 and degree[base] >= 3:
                    apart = np.linalg.norm(points[tip] - points[base])
                    beyond = apart + radius[tip] - radius[base]
                    # width where the branch leaves the base disc: a neck, not the head it carries
                    ordered = np.array(chain if chain[0] == base else chain[::-1])
                    outside = ordered[np.linalg.norm(points[ordered] - points[base], axis=1) > radius[base]]
                    width = 2 * float(radius[outside[:tuning.width_nodes]].mean()) if len(outside) else (
                        2 * float(radius[tip]))
                    if pruning.outline is not None:
                        width = max(width, _jump_width(ordered, points, radius, pruning.outline))
                    bump = beyond <= prune * width and not (  # the round-part test only where it can matter
                        blobs is not None and _round_part(apart, radius, blobs, base, tip, tuning.round_tip))
                    reach = beyond if tip not in reached else float(  # to the spurs cut off its end, too
                        (np.linalg.norm(points[[tip, *reached[tip]]] - points[base], axis=1)
                         + radius[[tip, *reached[tip]]]).max() - radius[base])
                    spur = reach < max_reach and (beyond <= min_reach or bump)
                    part = _round_part_on(ordered, points, radius, blobs, min_reach, tuning.round_tip) \
                        if spur and pruning.heads and blobs is not None else None
                    if part is not None:
                        heads[i] = ordered[:part + 1].tolist()
                    may_pair = spur and pair_prune is not None and beyond > max(min_reach, pair_prune * width)
                    if spur:
                        spurs[i] = base, tip
                    if may_pair:
                        pairable[i] = base, ordered, beyond, width
                    elif not spur:
                        kept_leaves.append((base, ordered, beyond, width))
                    if may_pair or not spur:
                        leaves.append((i, base, outside))
                    break
        if spurs and pruning.mirror is not None:
            spurs = _unmirrored(spurs, pairable, leaves, points, radius, pruning.mirror, tuning.local_pair)
            spurs = _not_going_on(spurs, chains, points, radius, pruning.mirror, tuning)
        if spurs and pruning.ground is not None:
            spurs = _standing(spurs, pairable, leaves, chains, points, radius, reaching, stood,
                              spurs_stand=pruning.mirror is None)
        trims = {i: heads[i] for i in spurs if i in heads}  # a head the spur runs on past: only the rest goes
        spurs = {i: ends for i, ends in spurs.items() if i not in trims}
        if not spurs and not trims:
            links = links_of(chains)
            if not dropped:
                return links
            return np.vstack([links, links_of(_local_pairs(dropped, kept_leaves, links, points,
                                                           tuning.local_pair))])
        if pruning.local_pairs:
            dropped += [pairable[i] for i in spurs if i in pairable]
        if pruning.ground is not None:
            for base, tip in spurs.values():
                stood[base] = stood.get(base, set()) | stood.get(tip, set()) | _sides(tip, reaching)
        for base, tip in spurs.values():
            reached[base] = reached.get(base, []) + [tip] + reached.get(tip, [])
        # every spur goes at once: the two corner branches at the end of a limb leave the limb ending at their fork
        kept = [trims.get(i, c) for i, c in enumerate(chains) if i not in spurs]
        if not kept:
            return np.zeros((0, 2), dtype=np.int64)
        _, chains = chains_of(sorted({n for c in kept for n in c}), links_of(kept))


def _jump_width(ordered, points, radius, outline):
    """The width where a leaf chain (``ordered``: base first) leaves its base's disc when its axis jumps there, its
    first node outside lying farther beyond the disc's edge than that node is wide: twice the distance from where
    the jump crosses the edge to the ``outline`` (segment starts and ends). Such a jump crosses a fan of triangles
    into a concave corner of the outline, where the nodes' widths are the corner's, not the part's; 0 otherwise
    (and for a chain with no node outside the disc)."""
    base = points[ordered[0]]
    apart = np.linalg.norm(points[ordered] - base, axis=1)
    k = int(np.argmax(apart > radius[ordered[0]]))  # the first node outside; 0 (the base) when there is none
    if apart[k] - radius[ordered[0]] <= 2 * radius[ordered[k]]:
        return 0.0
    before = points[ordered[k - 1]]  # inside the disc: apart[k - 1] <= radius < apart[k]
    share = (radius[ordered[0]] - apart[k - 1]) / (apart[k] - apart[k - 1])
    edge = before + share * (points[ordered[k]] - before)
    return 2 * float(segment_distances(edge[None], *outline).min())


def _sides_reached(points, radius, ground):
    """Per node, whether its disc reaches each side of the view's outline (``ground``: its low and high corner and a
    tolerance): (high (n, 2), low (n, 2)) flags as lists, for :func:`_sides`."""
    low, high, tolerance = ground
    return ((points + radius[:, None] >= np.asarray(high, dtype=np.float64) - tolerance).tolist(),
            (points - radius[:, None] <= np.asarray(low, dtype=np.float64) + tolerance).tolist())


def _sides(node, reaching):
    """The sides ((axis, 0 for low or 1 for high)) of the view's outline that ``node``'s disc reaches
    (``reaching``: :func:`_sides_reached`)."""
    high, low = reaching[0][node], reaching[1][node]
    return {(axis, end) for axis in range(2) for end, touches in ((1, high[axis]), (0, low[axis])) if touches}


def _standing(spurs, pairable, leaves, chains, points, radius, reaching, stood, spurs_stand=True):
    """The ``spurs`` (chain -> (base, tip)) without the ``pairable`` ones that stand on a side of the view's outline
    (``reaching``: which side each node's disc reaches, :func:`_sides_reached`), with a node or through spurs
    already removed from one (``stood``: a leg whose foot's corners went), that a kept leaf stands on too, their tips
    farther apart than either is wide: legs reach the ground together, however stubby (a foot's toe beside its own
    leg's foot is no leg). With ``spurs_stand`` (a view with no mirror in it), a pairable spur off another base
    standing there counts as a kept leaf: every leg of a cartoon cow seen from the side is stubby. Spurs off one base
    (a forked tail fin), and twins across a mirror, pair by the pairing rules alone."""
    def sides(chain, base):
        nodes = [node for node in chains[chain] if node != base]
        return set().union(*(_sides(node, reaching) | stood.get(node, set()) for node in nodes))

    def tip(chain, base):
        return chains[chain][-1] if chains[chain][0] == base else chains[chain][0]

    # (sides, tip, base, how wide it is if a spur) of the leaves another spur may stand beside
    standing = [(sides(j, other_base), tip(j, other_base), other_base, pairable[j][3] if j in spurs else None)
                for j, other_base, _ in leaves if spurs_stand or j not in spurs]
    result = {}
    for i, (base, end) in spurs.items():
        width = pairable[i][3] if i in pairable else None
        stands = width is not None and any(
            sides(i, base) & on and not (other_width is not None and other_base == base)
            and np.linalg.norm(points[end] - points[other]) > max(width, 2 * radius[other], *(
                () if other_width is None else (other_width, 2 * radius[end])))  # two spurs: both stay or go
            for on, other, other_base, other_width in standing)
        if not stands:
            result[i] = base, end
    return result


def _round_part(apart, radius, blobs, base, tip, round_tip):
    """Whether leaf node ``tip``, ``apart`` from ``base``, is a blob at least ``round_tip`` as wide as the base (a
    part of its own), lying off the disc of ``base``."""
    return bool(blobs[tip]) and radius[tip] >= round_tip * radius[base] and apart > radius[base]


def _round_part_on(ordered, points, radius, blobs, min_reach, round_tip):
    """The index along a leaf chain (``ordered``: base first) of the farthest node before its tip that is a round
    part (:func:`_round_part`) reaching more than ``min_reach`` beyond the base's disc, the chain's tip no farther
    from it than its radius and a half, else None: a head whose other branches went, leaving the chain running on
    from it to a corner of its outline (however the axis wiggles on the way)."""
    base = ordered[0]
    tip = points[ordered[-1]]
    for k in range(len(ordered) - 2, 0, -1):
        node = ordered[k]
        apart = float(np.linalg.norm(points[node] - points[base]))
        if (_round_part(apart, radius, blobs, base, node, round_tip) and apart + radius[node] - radius[base] > min_reach
                and np.linalg.norm(tip - points[node]) <= 1.5 * radius[node]):
            return k
    return None


def _unmirrored(spurs, pairable, leaves, points, radius, mirror, most_unlike):
    """The ``spurs`` (chain -> (base, tip)) without a twin: another leaf off the same base (``leaves``: (chain,
    base, its nodes outside the base's disc) each) that stays, with a node whose disc holds the spur tip's mirror
    image. A kept leaf is a twin to every spur. Two ``pairable`` spurs (long enough for limbs when they come in pairs)
    are twins when each one's image lies on the other, or, alike in reach and width as ``_local_pairs`` asks
    (``most_unlike``), within the other's width of its tip (two arms whose chains end in different corners of their
    hands), so that two ears each under the threshold stay together, and neither stays for lying on a longer one
    that goes. The base's own disc covers the body, so a bump whose image falls on it still goes."""
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
        if i in pairable:  # twins alike whose images miss each other's tips by less than a width
            own = pairable[i][2:]  # (reach, width)
            lying_on[i] |= {j for j, (other, ordered, *size) in pairable.items() if j != i and other == base
                            and np.linalg.norm(points[ordered[-1]] - image) <= size[1]
                            and _unlike(own, size) <= most_unlike}
    return {i: spurs[i] for i, twins in lying_on.items() if not any(
        chain not in spurs or (i in pairable and i in lying_on[chain]) for chain in twins)}


def _not_going_on(spurs, chains, points, radius, mirror, tuning):
    """The ``spurs`` (chain -> (base, tip)) but those on the mirror plane that go on straight from another chain on
    it through their base (within ``straight_on`` degrees), reaching beyond its disc by ``straight_reach`` of its
    radius: a head on its neck going on from the spine, however stubby it is for the width of the shoulders' disc
    (a bump on the body's middle line is no part). On the plane: the node's disc holds its mirror image."""
    def on_plane(nodes):
        return on_mirror_line(points[nodes], radius[nodes], mirror)

    going_on = set()
    for i, (base, tip) in spurs.items():
        reach = np.linalg.norm(points[tip] - points[base]) + radius[tip] - radius[base]
        if reach <= tuning.straight_reach * radius[base] or not on_plane([base, tip]).all():
            continue
        ahead = (points[tip] - points[base]) / max(np.linalg.norm(points[tip] - points[base]), 1e-300)
        for k, chain in enumerate(chains):
            if k == i or k in spurs or base not in (chain[0], chain[-1]):
                continue
            ordered = chain if chain[0] == base else chain[::-1]
            out = [n for n in ordered[1:] if np.linalg.norm(points[n] - points[base]) > radius[base]]
            node = out[0] if out else ordered[-1]
            back = points[node] - points[base]
            if on_plane([node])[0] and ahead @ back <= -np.cos(np.radians(tuning.straight_on)) * np.linalg.norm(back):
                going_on.add(i)
                break
    return {i: ends for i, ends in spurs.items() if i not in going_on}


def _local_pairs(dropped, kept, links, points, most_unlike):
    """Node lists of the spurs among ``dropped`` ((base, nodes from base to tip, reach, width) each, pruned although
    they stick out enough to be limbs in a pair) that pair up, with each other or with one of the ``kept`` leaves
    (the same form), off a base the kept tree (``links``) still runs through (two links at least: not the end a
    limb's two corner branches forked from): the ratio of their reaches times the ratio of their widths at most
    ``most_unlike``, their tips farther apart than either is wide, the most alike paired first. A hand-made figure's
    two stubby arms or ears are never exact mirror images, while outline noise does not come in such pairs; twins
    near the threshold stay or go together, not one arm kept and its twin pruned."""
    degree = np.bincount(links.ravel(), minlength=len(points))
    by_base = {}
    for leaf, was_dropped in [(spur, True) for spur in dropped] + [(leaf, False) for leaf in kept]:
        if degree[leaf[0]] >= 2:
            by_base.setdefault(leaf[0], []).append((leaf, was_dropped))
    restored = []
    for leaves in by_base.values():
        pairs = []
        for a in range(len(leaves)):
            for b in range(a):
                ((_, nodes_a, reach_a, width_a), dropped_a), ((_, nodes_b, reach_b, width_b), dropped_b) = \
                    leaves[a], leaves[b]
                if not (dropped_a or dropped_b):
                    continue
                unlike = _unlike((reach_a, width_a), (reach_b, width_b))
                apart = np.linalg.norm(points[nodes_a[-1]] - points[nodes_b[-1]])
                if unlike <= most_unlike and apart > max(width_a, width_b):
                    pairs.append((unlike, a, b))
        used = set()
        for _, a, b in sorted(pairs):
            if a not in used and b not in used:
                used |= {a, b}
                restored += [list(leaves[k][0][1]) for k in (a, b) if leaves[k][1]]
    return restored


def _unlike(a, b):
    """How unlike two branches ((reach, width) each) are: their reach ratio times their width ratio, 1 or more."""
    return max(a[0] / b[0], b[0] / a[0]) * max(a[1] / b[1], b[1] / a[1])


def rooted_chains(points, keys, chains, radius, tuning):
    """Root the chain graph at its most central branch point (smallest largest distance to any end) and cut its
    cycles; returns (root, [Chain]) ordered parents first. A graph without branch points: ``_root_single_path``."""
    lengths = [length(points[c]) for c in chains]
    adjacency = {}
    for i, c in enumerate(chains):
        adjacency.setdefault(c[0], []).append((c[-1], i))
        adjacency.setdefault(c[-1], []).append((c[0], i))
    branch_points = [k for k in keys if len(adjacency.get(k, ())) >= 3]
    if branch_points:
        root = min(branch_points, key=lambda k: (max(shortest_paths(k, adjacency, lengths)[0].values()), -radius[k]))
    else:
        return _root_single_path(chains, keys, radius, tuning)
    dist, via = shortest_paths(root, adjacency, lengths)
    tree = set(via.values())
    ordered = []
    chain_of_end = {}
    # chains on shortest paths, parents first (by distance of their near end)
    for i in sorted(tree, key=lambda i: min(dist[chains[i][0]], dist[chains[i][-1]])):
        nodes = chains[i] if dist[chains[i][0]] <= dist[chains[i][-1]] else chains[i][::-1]
        chain_of_end[nodes[-1]] = len(ordered)
        ordered.append(Chain(nodes, chain_of_end.get(nodes[0], -1) if nodes[0] != root else -1))
    # cycles: cut each remaining chain where two parts touch
    for i in range(len(chains)):
        if i in tree:
            continue
        for half in _cut_cycle(chains[i], points, radius, tuning):
            if len(half) > 1:
                ordered.append(Chain(half, chain_of_end.get(half[0], -1) if half[0] != root else -1))
    return root, ordered


def _cut_cycle(nodes, points, radius, tuning):
    """The chain ``nodes`` that closes a cycle (a hole in the silhouette), cut into the parts that hang from its ends.
    Where it narrows to ``contact`` of its median width, two parts touch there (a curled tail's tip on the back): it
    is cut there and the longer half stays alone (the tail; the shorter is the back's side of the contact, no limb).
    Else it is a limb resting on the body (an arm whose hand rests on the hip), cut where it touches: a limb tapers
    to its tip, so it hangs whole from the end farther from its narrowest node (the shoulder, not the hip)."""
    inner = radius[nodes[1:-1]]
    if not len(inner):
        return []  # a single link closing the cycle: dropping it opens it
    cut = 1 + int(np.argmin(inner))
    if inner.min() < tuning.contact * np.median(inner):
        halves = (nodes[:cut + 1], nodes[cut:][::-1])
        return [max(halves, key=lambda half: length(points[half]))]
    steps = arc_lengths(points[nodes])
    return [nodes[1:][::-1]] if steps[cut] < 0.5 * steps[-1] else [nodes[:-1]]


def _root_single_path(chains, keys, radius, tuning):
    """A graph without branch points is one path. Root it at its widest node, the body (a bird with spread wings,
    a fish), with a chain each way; a path about as wide everywhere (a column, a tentacle) is rooted at its thicker
    end instead, one chain from its base, as an artist would rig it."""
    nodes = chains[0] if chains else sorted(keys)
    width = radius[nodes]
    quarter = max(1, len(nodes) // tuning.end_divisor)  # the very ends taper to a point whatever the part's width
    if width.max() <= tuning.column_ratio * np.median(width):
        if width[-quarter:].mean() > width[:quarter].mean():
            nodes = nodes[::-1]
        return nodes[0], [Chain(list(nodes), -1)] if len(nodes) > 1 else []
    middle = int(np.argmax(width))
    halves = [nodes[middle:], nodes[:middle + 1][::-1]]
    return nodes[middle], [Chain(h, -1) for h in halves if len(h) > 1]
