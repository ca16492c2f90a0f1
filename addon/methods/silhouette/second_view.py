"""Limbs the primary view hides: leaf chains of the perpendicular view that the primary skeleton does not reach.

The primary view shows the mesh widest, which can hide limbs behind the body (a bird's legs under its spread wings,
seen from above; a fish's side fins or a fox's ears, seen from the side). A perpendicular view shows them. Its placed
chains are compared with the primary skeleton in the perpendicular view's own plane: a leaf chain whose tip lies
farther than ``reach`` from every primary chain there is a limb the primary skeleton lacks; its part beyond the last
point the primary skeleton comes within ``reach`` of is added, from the first node outside that reach (the covered
node's depth is the body's, often a merged blob's centre far behind the limb). Parts both views show (a wing seen
edge-on) are never doubled.
"""
from functools import cached_property

import numpy as np

from ...core.polyline import length, segment_distances
from .depth import PlacedIsland, Placing, placed_islands
from .tree import islands, pruned_tree


class HiddenLimbs:
    """The limbs the primary view (``sil``) hides behind the body that the perpendicular ``View`` ``view`` shows:
    its tree, pruned at ``hidden_prune`` of ``prune`` (with the mirror plane when the view looks across it: a wolf's
    ears, seen end-on, are kept as a pair), is built once; its chains are placed in depth when first needed, when a
    leaf tip lies off the primary skeleton."""

    def __init__(self, sil, view, rules):
        self.sil, self.view, self.rules = sil, view, rules
        params, tuning = rules.params, rules.tuning
        self.pruning = rules.pruning(view.sil, tuning.hidden_prune * params.prune)
        self.graph, self.alive, _, kept = pruned_tree(view.axis_graph, params.merge, self.pruning)
        self.kept = _without_bumps(self.graph, self.alive, kept, self.pruning.min_reach)
        ends, count = np.unique(self.kept, return_counts=True)
        self.tips = view.sil.lift(self.graph.points[ends[count == 1]], 0.0) if len(self.kept) else None
        self.across = rules.plane is not None and abs(view.sil.direction[rules.plane[0]]) <= tuning.along_plane

    def limbs(self, lines):
        """The hidden limbs, compared with the primary skeleton's chains ``lines``."""
        if not len(self.kept):
            return []
        tuning = self.rules.tuning
        cover = Cover(lines, self.view.sil.direction, tuning.hidden_reach * self.rules.unit,
                      self.rules.symmetry if self.across else None)
        if cover.covered(self.tips).all():
            return []  # every leaf tip is on the primary skeleton: no need to place the view's chains in depth
        return [limb for chains in self._placed for limb in
                uncovered_limbs(chains, cover, self.sil, self.pruning.min_reach, tuning)]

    @cached_property
    def _placed(self):
        """The placed chains of each of the view's islands (``PlacedIsland.chains``)."""
        self.view.sil.share_parts(self.sil)  # the mesh's welded parts, found once for the primary view
        # placed without the plane: only the limbs off the skeleton are kept, and add_limbs completes their pairs
        tuning = self.rules.tuning
        placing = Placing(tuning, speck=tuning.speck * self.rules.unit, split=self.rules.params.split_layers)
        return [placed.chains for placed in placed_islands(self.view.sil, self.graph, self.alive, self.kept, placing)
                if isinstance(placed, PlacedIsland)]


def _without_bumps(graph, alive, links, min_reach):
    """The ``links`` of a view's pruned tree without its islands that are one chain lying within the disc of its
    widest node, give or take ``min_reach``: a round part seen that way (a column end-on), whose outline's wiggles
    left junctions on its rim once pruning had taken its other spurs. No limb hangs there."""
    kept = []
    for nodes, sub, _ in islands(graph, alive, links):
        if len(sub) and np.bincount(sub.ravel()).max() <= 2:
            widest = nodes[int(np.argmax(graph.radius[nodes]))]
            reach = np.linalg.norm(graph.points[nodes] - graph.points[widest], axis=1) + graph.radius[nodes]
            if reach.max() - graph.radius[widest] <= min_reach:
                continue
        kept.append(sub)
    return np.concatenate(kept) if kept else np.zeros((0, 2), dtype=np.int64)


class Cover:
    """The primary skeleton as a perpendicular view sees it: its chains flattened along the view ``direction`` once,
    and which points they cover (come within ``reach`` of, both projected along the direction). With a ``symmetry``
    the view looks across (its plane seen edge-on), a point off the plane is covered only by chains on its side:
    ears beside the head's chain, seen end-on, are limbs the skeleton lacks."""

    def __init__(self, primary_lines, direction, reach, symmetry=None):
        self.direction, self.reach, self.symmetry = direction, reach, symmetry
        self.starts, self.ends = _segments(primary_lines, direction)
        self.low = np.minimum(self.starts, self.ends) - reach  # each segment's box, grown by the reach
        self.high = np.maximum(self.starts, self.ends) + reach
        if symmetry is not None:
            self.sides = np.concatenate([np.full(len(line) - 1, symmetry.side(line, by_tip=True))
                                         for line in primary_lines if len(line) > 1] or [np.zeros(0, int)])

    def covered(self, points, sided=True):
        """Whether each of the 3D ``points`` lies within ``reach`` of a primary chain, seen along the direction
        (segments whose grown box misses the points' box cannot cover any of them, and are not measured); without
        ``sided``, of any chain whatever its side."""
        flat = _flattened(points, self.direction)
        if not len(flat):
            return np.zeros(0, bool)
        near = ((self.low <= flat.max(axis=0)) & (self.high >= flat.min(axis=0))).all(axis=1)
        if self.symmetry is None or not sided:
            return _distance_to_segments(flat, self.starts[near], self.ends[near]) <= self.reach
        sides = self._sides(points)
        covered = np.zeros(len(points), bool)
        for side in np.unique(sides):
            on = sides == side
            by = near & ((self.sides == side) if side else True)
            covered[on] = _distance_to_segments(flat[on], self.starts[by], self.ends[by]) <= self.reach
        return covered

    def beside(self, points, tip):
        """Whether each of the 3D ``points`` lies on the same side of the plane as ``tip`` (all, without a plane):
        an ear's chain off the plane begins where it leaves the head's middle."""
        if self.symmetry is None:
            return np.ones(len(points), bool)
        return self._sides(points) == self._sides(tip)[0]

    def _sides(self, points):
        axis, offset = self.symmetry.plane
        off = points[:, axis] - offset
        return np.where(np.abs(off) > self.symmetry.side_tolerance, np.sign(off), 0).astype(int)


def uncovered_limbs(placed, cover, primary_sil, min_length, tuning):
    """The outer parts of the leaf chains in ``placed`` that the primary skeleton does not cover.

    Args:
        placed: the perpendicular view's chains, as ``depth.place_chains`` gives them: (polyline (k, 3), parent,
            half-widths (k,)).
        cover: the primary skeleton's ``Cover`` along the perpendicular view's direction.
        primary_sil: the primary ``Silhouette``: a limb counts only where it is hidden there, its tip's ray running
            through the mesh for much longer than the limb is wide (a foot under a body); a tip the primary view
            shows plainly (the edge of a thin sheet) was seen there and judged no limb.
        min_length: shorter uncovered parts are dropped.
        tuning: the method's (``occlusion_ratio``).

    Returns a list of (polyline, half-widths), each starting at the node past the last one the primary skeleton
    covers.
    """
    parents = {parent for _, parent, _ in placed}
    limbs = []
    for index, (line, _, widths) in enumerate(placed):
        if index in parents or len(line) < 2:
            continue
        tip = line[-1:]  # the cheap tests first: most leaf chains end on the primary skeleton
        width = 2 * tuning.occlusion_ratio * float(np.median(widths))
        if cover.covered(tip)[0] or not hidden(primary_sil, tip, width)[0]:
            continue
        first = _first_uncovered(line, widths, tip, cover)
        part = line[first:]
        if len(part) >= 2 and length(part) >= min_length:
            limbs.append((part, widths[first:]))
    return limbs


def _first_uncovered(line, widths, tip, cover):
    """Where a limb ending at ``tip`` begins on its ``line``: past the last node the primary skeleton covers (not
    the covered node: its depth is the body's). Across a mirror plane, a tip off it is covered only on its own side
    (``Cover``): an ear beside the head's chain begins where it leaves the head's middle, so long as its nodes'
    depths run on without a leap of more than the part's width (into the body behind the head)."""
    def after(mask):
        nodes = np.flatnonzero(mask)
        return int(nodes[-1]) + 1 if len(nodes) else 0

    first = after(cover.covered(line, sided=False))
    if cover.symmetry is None:
        return first
    sided = after(cover.covered(line) | ~cover.beside(line, tip))
    depth = line @ cover.direction
    leaps = np.abs(np.diff(depth)) > 2 * np.maximum(widths[1:], widths[:-1])  # between node k and k + 1
    return max(sided, after(leaps[:first])) if sided < first else first


def hidden(sil, points, width):
    """Which 3D ``points`` are hidden in ``sil``: their view ray runs through the mesh, from first entry to last exit,
    for longer than ``width`` — behind or along something, like a foot under a body or a leg seen end-on, not at the
    edge of a thin sheet."""
    front, back = sil.depth(sil.project(points)[0])
    return ~np.isnan(front) & (back - front > width)


def _flattened(points, direction):
    return points - np.outer(points @ direction, direction)


def _segments(lines, direction):
    starts = np.concatenate([line[:-1] for line in lines if len(line) > 1] or [np.zeros((0, 3))])
    ends = np.concatenate([line[1:] for line in lines if len(line) > 1] or [np.zeros((0, 3))])
    return _flattened(starts, direction), _flattened(ends, direction)


def _distance_to_segments(points, starts, ends):
    """Distance from each point to the nearest of the segments (inf without segments)."""
    if not len(starts):
        return np.full(len(points), np.inf)
    return segment_distances(points, starts, ends).min(axis=1)
