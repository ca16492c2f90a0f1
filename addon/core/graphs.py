"""Graph helpers shared by the methods and the Blender layer: components, neighbours, chains between key nodes,
shortest paths."""
import heapq

import numpy as np


def components(count, links):
    """Connected component label of each of ``count`` nodes joined by ``links`` ((L, 2) node indices), numbered
    0 .. parts - 1 in order of their smallest node; a node in no link is a part of its own.

    Hooks every link's larger root onto its smaller one, then shortcuts every node to its root, until no link joins
    two roots: a few vectorised rounds instead of a Python loop.
    """
    parent = np.arange(count)
    a, b = links[:, 0], links[:, 1]
    while True:
        ra, rb = parent[a], parent[b]
        apart = ra != rb
        if not apart.any():
            break
        a, b, ra, rb = a[apart], b[apart], ra[apart], rb[apart]  # joined ends stay joined: drop those links
        np.minimum.at(parent, np.maximum(ra, rb), np.minimum(ra, rb))
        while True:
            grand = parent[parent]
            if (grand == parent).all():
                break
            parent = grand
    return np.unique(parent, return_inverse=True)[1]


def loose_parts(count, triangles):
    """The loose part (``components``) of each of ``count`` mesh vertices joined by ``triangles`` ((T, 3))."""
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    return components(count, np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]]]))


def neighbour_lists(count, links):
    """For each of ``count`` nodes, the list of nodes ``links`` ((L, 2) node indices) join it to, in link order."""
    neighbours = [[] for _ in range(count)]
    for a, b in links.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    return neighbours


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


def links_of(chains):
    """(L, 2) int64 links between consecutive nodes of the node-list ``chains``."""
    pairs = [(c[i], c[i + 1]) for c in chains for i in range(len(c) - 1)]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def shortest_paths(source, adjacency, lengths):
    """Dijkstra from ``source`` over a graph of edges with ``lengths``, ``adjacency`` mapping a node to its
    (neighbour, edge) pairs: the distance to every node reached, and the edge each was reached through."""
    dist = {source: 0.0}
    via = {}
    heap = [(0.0, source)]
    while heap:
        d, node = heapq.heappop(heap)
        if d > dist[node]:
            continue
        for other, edge in adjacency.get(node, ()):
            nd = d + lengths[edge]
            if nd < dist.get(other, np.inf):
                dist[other] = nd
                via[other] = edge
                heapq.heappush(heap, (nd, other))
    return dist, via
