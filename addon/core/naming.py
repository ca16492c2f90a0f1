"""Bone names from chains (``trunk.00``, ``limb03.01``, ``.L`` / ``.R`` across a mirror plane) and an order by them."""
import numpy as np

from .mirror import mirror_chain_pairs


def bone_names(chain_of_bone, index_in_chain, lines, symmetry=None):
    """Names by chain and place in it: ``trunk.00``, ``limb03.01`` …, limbs numbered from 1 by where they lie
    (``_placed``), not by the order the method found them, so a mesh scaled, moved or renumbered keeps its names.

    With a ``symmetry``, every bone of a chain off the plane (on average; for a chain with a mirror twin, at its
    tip) gets ``.L`` on the side of the plane's positive axis (Blender's convention for a character's left) or
    ``.R``, and mirror twins share their number, so ``limb02.01.L`` and ``limb02.01.R`` are a left and a right bone
    in the same place.
    """
    label = list(range(len(lines)))
    suffix = [""] * len(lines)
    if symmetry is not None:
        paired = set()
        for i, j in mirror_chain_pairs(lines, symmetry):
            label[j] = label[i] = min(i, j)
            paired |= {i, j}
        for c, line in enumerate(lines):
            suffix[c] = {1: ".L", -1: ".R", 0: ""}[symmetry.side(line, by_tip=c in paired)]
    places = {}  # label -> its chains' places: twins share a label, and the trunk's (chain 0's) keeps number 0
    for c, line in enumerate(lines):
        places.setdefault(label[c], []).append(_placed(line, lines[0][0]))
    ranked = sorted(places, key=lambda value: (value != 0, min(places[value])))
    number = {value: k for k, value in enumerate(ranked)}
    base = ["trunk" if number[label[c]] == 0 else f"limb{number[label[c]]:02d}" for c in range(len(lines))]
    names = [f"{base[c]}.{k:02d}{suffix[c]}" for c, k in zip(chain_of_bone, index_in_chain)]
    seen = {}
    for i, name in enumerate(names):  # two unpaired chains on one side can share a label only by mistake; be safe
        if name in seen:
            names[i] = f"{name}.{i:03d}"
        seen[name] = i
    return names


def _placed(line, root):
    """A chain's place for numbering: how far from the ``root`` (the trunk's start) it starts, then ends; ties (a
    chain and its unpaired mirror image) by its start's, then its end's, coordinates, larger first (``.L`` before
    ``.R``). Distances stay in order however the mesh is scaled, moved or its vertices numbered."""
    start, end = line[0], line[-1]
    return (float(np.linalg.norm(start - root)), float(np.linalg.norm(end - root)), *(-start).tolist(),
            *(-end).tolist())


def in_name_order(names, heads, tails, parents):
    """The bones (``names`` and their (B, 3) ``heads``, ``tails`` and ``parents``) reordered depth first from the
    roots, a bone's children (and the roots) in the order of their names: an order given by the names, so by where
    the bones are, not by the order a method found them in. Returns (names, heads, tails, parents)."""
    children = {}
    for bone, parent in enumerate(parents):
        children.setdefault(int(parent), []).append(bone)
    order, stack = [], sorted(children.get(-1, []), key=names.__getitem__, reverse=True)
    while stack:
        bone = stack.pop()
        order.append(bone)
        stack.extend(sorted(children.get(bone, []), key=names.__getitem__, reverse=True))
    place = np.empty(len(order), dtype=np.int64)
    place[order] = np.arange(len(order))
    parents = np.asarray(parents, dtype=np.int64)[order]
    return ([names[bone] for bone in order], np.asarray(heads)[order], np.asarray(tails)[order],
            np.where(parents >= 0, place[np.maximum(parents, 0)], -1))
