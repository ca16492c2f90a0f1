"""Which meshes of a file's scene make the character the command line rigs (bpy-free).

A file holds a character, often of several meshes (body, clothes, eyes, a sword in its hand), and sometimes more: a
floor it stands on, a backdrop, a prop or another character standing apart. Rigged together, a floor plane seen from
above is the widest silhouette there is and the character's rig is lost in it. The character is the mesh with the
most vertices and the meshes that reach into the space around it; a mesh apart from that space, or a flat one
larger than the character (a floor, a backdrop), is left out, unrigged.
"""
import numpy as np

NEAR = 0.1  # a part reaching within this share of the main mesh's size of its bounding box belongs to it
FLAT = 1e-3  # a mesh thinner than this share of its size, across its flattest direction, is flat


def character_parts(parts):
    """(indices of the ``parts`` that make the character, [(index, why it is left out)]) for ``parts``, a list of
    (name, world vertices (N, 3)) with the main mesh first (the one with the most vertices)."""
    _, main = parts[0]
    low, high = main.min(axis=0), main.max(axis=0)
    size = float(np.ptp(main, axis=0).max())
    reach_low, reach_high = low - NEAR * size, high + NEAR * size
    kept, left = [0], []
    for index, (name, vertices) in enumerate(parts[1:], start=1):
        extent = float(np.ptp(vertices, axis=0).max())
        if (vertices.max(axis=0) < reach_low).any() or (vertices.min(axis=0) > reach_high).any():
            left.append((index, f"apart from {parts[0][0]!r}"))
        elif extent > size and _thickness(vertices) <= FLAT * extent:
            left.append((index, f"flat and larger than {parts[0][0]!r}: a floor or a backdrop"))
        else:
            kept.append(index)
    return kept, left


def _thickness(vertices):
    """The extent of ``vertices`` across their flattest direction."""
    centred = vertices - vertices.mean(axis=0)
    flattest = np.linalg.svd(centred[::max(1, len(centred) // 10_000)], full_matrices=False)[2][-1]
    return float(np.ptp(centred @ flattest))
