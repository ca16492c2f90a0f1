"""Graph helpers shared by the methods and the Blender layer."""
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
