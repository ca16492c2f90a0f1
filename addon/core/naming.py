"""Bone names from chains: ``trunk.00``, ``limb03.01``, with ``.L`` / ``.R`` across a mirror plane."""
from .mirror import mirror_chain_pairs


def bone_names(chain_of_bone, index_in_chain, lines, symmetry=None):
    """Names by chain and place in it: ``trunk.00``, ``limb03.01`` …, chains numbered in order from 1.

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
    number = {value: k for k, value in enumerate(sorted(set(label)))}  # the trunk (chain 0) keeps 0
    base = ["trunk" if number[label[c]] == 0 else f"limb{number[label[c]]:02d}" for c in range(len(lines))]
    names = [f"{base[c]}.{k:02d}{suffix[c]}" for c, k in zip(chain_of_bone, index_in_chain)]
    seen = {}
    for i, name in enumerate(names):  # two unpaired chains on one side can share a label only by mistake; be safe
        if name in seen:
            names[i] = f"{name}.{i:03d}"
        seen[name] = i
    return names
