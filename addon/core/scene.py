"""Which meshes of a file's scene (or of a selection) make the character Rigger rigs (bpy-free).

A file holds a character, often of several meshes (body, clothes, eyes, a sword in its hand), and sometimes more: a
floor or a stage it stands on, a backdrop, a prop or another character standing apart. Rigged together, a floor seen
from above is the widest silhouette there is and the character's rig is lost in it. The character is its main mesh
(the first given that is no slab) and the meshes that reach into the space around it; a mesh apart from that space,
or a slab larger than the character (a floor, a stage, a backdrop), is left out, unrigged.
"""
import numpy as np

NEAR = 0.1  # a part reaching within this share of the main mesh's size of its box belongs to it
SLAB = 0.1  # a mesh thinner than this share of its size, across its flattest direction, is a slab


def character_parts(parts):
    """(indices of the ``parts`` that make the character, the main one first; [(index, why it is left out)]) for
    ``parts``, a list of (name, world vertices (N, 3)), the likeliest main mesh first (the active one, or the one
    with the most vertices): the main mesh is the first that is no slab. Boxes are taken along the main mesh's own
    axes (its principal directions), so turning the scene changes nothing. Vertices that are not finite do not count
    here (rigging reports them)."""
    parts = [(name, vertices[np.isfinite(vertices).all(axis=1)]) for name, vertices in parts]
    parts = [(name, vertices if len(vertices) else np.zeros((1, 3))) for name, vertices in parts]
    frames = [_principal_axes(vertices) for _, vertices in parts]
    slabs = [_thickness(vertices, axes) <= SLAB * _extent(vertices) for (_, vertices), axes in zip(parts, frames)]
    main = next((k for k, slab in enumerate(slabs) if not slab), 0)
    name, vertices = parts[main]
    axes = frames[main]
    low, high = (vertices @ axes.T).min(axis=0), (vertices @ axes.T).max(axis=0)
    size = _extent(vertices)
    reach_low, reach_high = low - NEAR * size, high + NEAR * size
    kept, left = [main], []
    for index, (_, points) in enumerate(parts):
        if index == main:
            continue
        along = points @ axes.T
        if (along.max(axis=0) < reach_low).any() or (along.min(axis=0) > reach_high).any():
            left.append((index, f"apart from {name!r}"))
        elif slabs[index] and _extent(points) > size:
            left.append((index, f"flat and larger than {name!r}: a floor, a stage or a backdrop"))
        else:
            kept.append(index)
    return kept, left


def _extent(vertices):
    return float(np.ptp(vertices, axis=0).max())


def _principal_axes(vertices):
    """(3, 3) rows: the principal directions of ``vertices``, largest spread first."""
    centred = vertices - vertices.mean(axis=0)
    return np.linalg.svd(centred[::max(1, len(centred) // 10_000)], full_matrices=False)[2]


def _thickness(vertices, axes):
    """The extent of ``vertices`` across their flattest direction (the last of their principal ``axes``)."""
    return float(np.ptp((vertices - vertices.mean(axis=0)) @ axes[-1]))
