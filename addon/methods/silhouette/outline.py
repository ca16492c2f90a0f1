"""Outline preparation: a silhouette's loops as the triangulation's input, and as edges for distances to it."""
import numpy as np

from ...core.arrays import concatenated_ranges


def without_small_holes(loops, fraction):
    """Drop the holes (clockwise loops) smaller than ``fraction`` of the silhouette's area: gaps between parts,
    not an arm on the hip."""
    areas = [0.5 * float(np.sum(l[:, 0] * np.roll(l[:, 1], -1) - np.roll(l[:, 0], -1) * l[:, 1])) for l in loops]
    total = sum(a for a in areas if a > 0)
    return [l for l, a in zip(loops, areas) if a > 0 or -a >= fraction * total]


def outline_segments(loops, spacing):
    """Loop points and closing segments, edges longer than ``spacing`` times the outline's size subdivided (no point
    moves, so loops stay simple)."""
    everything = np.concatenate(loops)
    step = spacing * float(np.max(everything.max(axis=0) - everything.min(axis=0)))
    points, segments, offset = [], [], 0
    for loop in loops:
        nxt = np.roll(loop, -1, axis=0)
        pieces = np.maximum(1, np.ceil(np.linalg.norm(nxt - loop, axis=1) / step).astype(int))
        t = concatenated_ranges(np.zeros_like(pieces), pieces) / np.repeat(pieces, pieces)
        start = np.repeat(np.arange(len(loop)), pieces)
        dense = loop[start] + t[:, None] * (nxt[start] - loop[start])
        count = len(dense)
        points.append(dense)
        segments.append(offset + np.stack([np.arange(count), (np.arange(count) + 1) % count], axis=1))
        offset += count
    return np.concatenate(points), np.concatenate(segments)


def loop_edges(loops):
    """Every edge of the loops as (starts, ends), each (K, 2): for distances to the outline."""
    return np.concatenate(loops), np.concatenate([np.roll(loop, -1, axis=0) for loop in loops])
