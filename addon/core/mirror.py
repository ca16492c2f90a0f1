"""A mesh's mirror plane, and mirror twins among chains (3D polylines): which chain is which one's image, on which
side of the plane a chain lies, and limbs completed from a longer twin's image."""
from dataclasses import dataclass, replace

import numpy as np

from .polyline import length, resampled, segment_distances
from .tuning import TuningTable, tuned


@dataclass(frozen=True)
class MirrorTuning(TuningTable):
    """The tuned numbers of mirror symmetry (shares of the mesh size, or of the twin tolerance)."""

    plane_match: float = tuned(0.01, "the mirror tolerance, a share of the size: a vertex whose image lies near a "
                                     "vertex (``plane_reach``) is symmetric")
    plane_samples: int = tuned(600, "vertices tested for a mirror image (at most)")
    plane_pool: int = tuned(10000, "vertices an image in doubt is measured against (at most: every k-th)")
    plane_reach: float = tuned(1.75, "a vertex has a mirror image when its image lies within this many tolerances "
                                     "of a vertex")
    plane_share: float = tuned(0.95, "a plane holds when this share of the vertices tested has a mirror image (loose "
                                     "bits and seams aside)")
    twin_tolerance: float = tuned(0.05, "the twin tolerance, a share of the size: how closely twin chains mirror")
    side_share: float = tuned(0.02, "a chain whose tip (or middle) lies farther off the plane than this share of the "
                                    "size is on a side (legs close together from the middle of the hips)")
    twin_ends: float = tuned(2.0, "chains whose ends lie this many twin tolerances in all from each other's mirror "
                                  "images are twins")
    cover_start: float = tuned(2.0, "a chain covers another's image when their starts lie this many twin tolerances "
                                    "apart at most ...")
    cover_tip: float = tuned(1.0, "... and the image's tip lies this many twin tolerances off the chain at most")
    same_shape: float = tuned(0.6, "twins whose lines lie this many twin tolerances apart at most are one limb "
                                   "traced twice")
    shape_samples: int = tuned(9, "points along each twin compared to find whether their shapes match")
    rough_match: float = tuned(0.03, "a body without an exact plane has sides when its vertices mirror within this "
                                     "share of the size (a hand-made or posed figure)")
    rough_twin_tolerance: float = tuned(0.1, "on such a body, the twin tolerance (share of the size) for naming "
                                             "twins")
    rough_step: float = tuned(0.001, "on such a body, twins mirror across where the mesh mirrors best, found to "
                                     "this share of the size")
    square_least: float = tuned(2.0, "degrees: a mirror plane off the axes by less than this is no turn ...")
    square_sample: int = tuned(50000, "... whether a mesh mirrors about one is judged on about this many of "
                                      "its vertices ...")
    square_probes: int = tuned(300, "... and its plane refined on pairs: this many sample vertices ...")
    square_pool: int = tuned(1000, "... each paired with the nearest of this many vertices to its mirror image ...")
    square_rounds: int = tuned(8, "... in this many rounds at most ...")
    square_near: float = tuned(0.5, "... then, when this share of them pairs, ...")
    square_exact_rounds: int = tuned(8, "... this many rounds more at most, with twice the samples ...")
    square_exact_pool: int = tuned(8000, "... pairing with the nearest of this many")


@dataclass(frozen=True)
class Symmetry:
    """A mirror ``plane`` (axis 0, 1 or 2, offset), the ``tolerance`` (mesh units) within which chains mirror each
    other, the ``tuning``, and how far off the plane the tip of a chain that leaves it lies on a side
    (``side_tolerance``, mesh units; None: the tolerance). For a body that only roughly mirrors (hand-made, posed)
    ``middle`` is the offset along the plane's axis where it mirrors best, which twins' joints mirror across; None
    when the mesh mirrors exactly about ``plane``."""

    plane: tuple
    tolerance: float
    tuning: MirrorTuning
    side_tolerance: float = None
    middle: float = None

    @property
    def exact(self):
        """Whether the mesh is a mirror image about the plane."""
        return self.middle is None

    @property
    def twin_plane(self):
        """The plane twins' joints mirror across: the mirror plane, or the rough body's ``middle``."""
        return self.plane if self.exact else (self.plane[0], self.middle)

    def reflect(self, points):
        """``mirrored(points, plane)``."""
        return mirrored(points, self.plane)

    def ends_misfit(self, line, other):
        """How far the ends of polyline ``other`` lie from the mirror images of ``line``'s ends, summed."""
        ends = np.array([line[0], line[-1]])
        return float(np.linalg.norm(self.reflect(ends) - np.array([other[0], other[-1]]), axis=1).sum())

    def whole_twins(self, line, other):
        """Whether two polylines are whole mirror twins: their ends' ``ends_misfit`` within ``twin_ends``
        tolerances."""
        return self.ends_misfit(line, other) <= self.tuning.twin_ends * self.tolerance

    def covers(self, gaps):
        """Whether a polyline covers another whose ``covering_fit`` against it is ``gaps``: their starts within
        ``cover_start`` tolerances, the other's tip within ``cover_tip`` of the polyline."""
        start_gap, tip_gap = gaps
        return (start_gap <= self.tuning.cover_start * self.tolerance
                and tip_gap <= self.tuning.cover_tip * self.tolerance)

    def agree(self, line, other):
        """Whether two polylines are one limb traced twice: every point of the shorter lies within ``same_shape``
        tolerances of the longer (a leg stepping forward does not agree with one standing)."""
        shorter, longer = (line, other) if length(line) <= length(other) else (other, line)
        gaps = segment_distances(shorter, longer[:-1], longer[1:]).min(axis=1)
        return gaps.max() <= self.tuning.same_shape * self.tolerance

    def same_shape(self, line, other):
        """Whether two polylines have one shape: ``shape_samples`` points evenly along each (by arc length) lie
        within ``same_shape`` tolerances of each other's."""
        count = self.tuning.shape_samples
        return (np.linalg.norm(resampled(line, count) - resampled(other, count), axis=1).max()
                <= self.tuning.same_shape * self.tolerance)

    def side(self, line, by_tip=False):
        """+1 on the plane's positive side, -1 on its negative side, 0 for a chain on the plane (its middle within
        the tolerance), or with ``by_tip`` for one whose tip is on it too (within ``side_tolerance``: legs close
        together leaving the middle of the hips are on their tips' sides)."""
        axis, offset = self.plane
        distance = float(np.mean(line[:, axis])) - offset
        if abs(distance) > self.tolerance:
            return int(np.sign(distance))
        tip = float(line[-1, axis]) - offset
        if by_tip and abs(tip) > (self.tolerance if self.side_tolerance is None else self.side_tolerance):
            return int(np.sign(tip))
        return 0


def mirrored(points, plane):
    """A copy of ``points`` (..., 3) reflected across ``plane`` = (axis, offset)."""
    axis, offset = plane
    image = np.array(points, dtype=float)
    image[..., axis] = 2 * offset - image[..., axis]
    return image


def mirror_plane(vertices, bounds, tolerance, tuning):
    """The axis (0, 1, 2) and offset of a plane the ``vertices`` are mirror-symmetric about, or None: of the
    ``symmetric_planes`` within ``tolerance``, the one most vertices fit."""
    planes = symmetric_planes(vertices, bounds, tolerance, tuning, shares=True)
    return max(planes, key=lambda plane: plane[2])[:2] if planes else None


def symmetric_planes(vertices, bounds, tolerance, tuning, shares=False):
    """(axis, offset, share) of each plane the ``vertices`` are mirror-symmetric about within ``tolerance``, by axis
    (``_fitting_planes``); the share of vertices that fit is exact with ``shares`` (to rank planes), else it may be
    less where that decides nothing."""
    return sorted(_fitting_planes(vertices, bounds, tolerance, tuning, shares))


def mirrors_about_an_axis_plane(vertices, bounds, tolerance, tuning):
    """Whether the ``vertices`` are mirror-symmetric about an axis plane within ``tolerance``: the likeliest plane
    first, and no more once one holds."""
    return next(_fitting_planes(vertices, bounds, tolerance, tuning, False), None) is not None


def _fitting_planes(vertices, bounds, tolerance, tuning, shares):
    """The planes ``symmetric_planes`` finds, the one most vertices surely fit first, each found when asked for.

    Tries the planes through the centre of ``bounds`` (their (2, 3) bounding box) perpendicular to X, Y and Z where
    the box is more than two ``tolerance`` deep (across a flat mesh's own plane nothing has a side); a plane fits
    when a ``plane_share`` of (up to ``plane_samples``) vertices have a mirror image within ``plane_reach``
    tolerances of a vertex, by exact distances, so the answer does not hang on where grid cells fall: a mesh moved
    keeps its plane. Vertices are hashed to a grid of cells whose diagonal is that reach: an image in a cell holding
    a vertex has one, an image with no vertex in the cells within reach has none, and only the images in between are
    measured (against every k-th vertex, at most ``plane_pool``), where that decides or ranks.
    """
    low, high = bounds
    reach = tuning.plane_reach * tolerance
    cell = reach / np.sqrt(3.0)
    origin = low - 3 * cell
    span = np.floor((high - low) / cell).astype(np.int64) + 7
    keys = _cell_keys(np.floor((vertices - origin) / cell).astype(np.int64), span)
    occupied = _CellSet(keys, span)
    probe = vertices[::max(1, len(vertices) // tuning.plane_samples)]
    pool_step = max(1, len(vertices) // tuning.plane_pool)
    pool_keys = keys[::pool_step]
    least = tuning.plane_share * len(probe)
    tried = []
    for axis in np.flatnonzero(high - low > 2 * tolerance):
        centre = 0.5 * (low[axis] + high[axis])
        images = mirrored(probe, (axis, centre))
        where = (images - origin) / cell  # in cells
        # an image off the grid is put in an empty cell at its edge: in doubt at most, and measured
        cells = np.minimum(np.maximum(np.floor(where).astype(np.int64), 2), span - 3)
        found = occupied.holds(_cell_keys(cells, span))  # a vertex in its own cell lies within reach
        rest = np.flatnonzero(~found)
        block = cells[rest][:, None, :] + _WITHIN_TWO[None]  # the cells a point of which may lie within reach
        owner, which = np.nonzero(occupied.holds(_cell_keys(block.reshape(-1, 3), span)).reshape(block.shape[:2]))
        if found.sum() + len(np.unique(owner)) >= least:
            tried.append((-found.sum(), int(axis), centre, found, images[rest], where[rest], block[owner, which],
                          owner, rest))
    for _, axis, centre, found, images, where, block, owner, rest in sorted(tried, key=lambda each: each[:2]):
        if len(owner) and (shares or found.sum() < least):
            gaps = np.maximum(np.maximum(block - where[owner], where[owner] - block - 1), 0.0)
            within = (gaps ** 2).sum(axis=1) <= 3.0  # cells with a point within reach: a diagonal, 3 squared cells
            looked, owner = _cell_keys(block[within], span), owner[within]
            near = _CellSet(looked, span).holds(pool_keys)
            at, owner = _in_cells(pool_keys[near], looked, owner)
            at = np.flatnonzero(near)[at] * pool_step
            close = ((vertices[at] - images[owner]) ** 2).sum(axis=1) <= reach * reach
            found = found.copy()
            found[rest[owner[close]]] = True
        if found.sum() >= least:
            yield axis, centre, float(found.mean())


def _in_cells(keys, looked, owner):
    """(at, owner): the index into ``keys`` (cell keys of points) of every point in a cell of ``looked`` (cell keys),
    in the order of the cells, and the ``owner`` (one per cell of ``looked``) of the cell it is in."""
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]
    starts = np.searchsorted(ordered, looked)
    counts = np.searchsorted(ordered, looked, side="right") - starts
    at = np.repeat(starts - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
    return order[at], np.repeat(owner, counts)


def sided_symmetry(vertices, bounds, size, lines, tuning):
    """For a body that is no exact mirror image (hand-made, posed) but has a left and a right: the ``Symmetry``
    whose sides name its bones, or None. A plane qualifies when the ``vertices`` are symmetric about it within
    ``rough_match`` of the ``size`` and the trunk (``lines[0]``, the chain the root bone starts) lies on it within
    the twin tolerance, as a spine does (a side-view cut-out of an animal is symmetric front to back, but its spine
    crosses that plane); of those, moved to pass through the trunk, the plane across which most chains (``lines``)
    pair as twins, within ``rough_twin_tolerance``, with its ``middle`` where the mesh mirrors best
    (``best_offset``)."""
    best, most = None, 0
    for axis, offset, _ in symmetric_planes(vertices, bounds, tuning.rough_match * size, tuning):
        if not lines or np.abs(lines[0][:, axis] - offset).max() > tuning.twin_tolerance * size:
            continue
        spine = float(np.mean(lines[0][:, axis]))  # a posed body's middle: its spine, not its bounding box's
        symmetry = Symmetry((axis, spine), tuning.rough_twin_tolerance * size, tuning, tuning.side_share * size)
        pairs = len(mirror_chain_pairs(lines, symmetry))
        if pairs > most:
            best, most = symmetry, pairs
    return None if best is None else replace(best, middle=best_offset(vertices, best.plane, size, tuning))


def best_offset(vertices, plane, size, tuning):
    """The offset, within the twin tolerance of ``plane``'s (axis, offset), of the plane across its axis the
    ``vertices`` mirror best about: where the median distance from mirrored vertices to the nearest vertex is least.
    A median: a raised arm or a prop on one side does not pull the plane, as it pulls a posed body's box or spine.

    Searched in eighths of the tolerance with a quarter of the ``plane_samples`` probes, against every k-th vertex
    (some 4 to 8 times ``plane_samples`` of them), and distances up to ``rough_match`` of the ``size`` (a coarse mesh's
    vertices mirror only that closely), then in ``rough_step`` about the best with all probes and vertices and
    distances up to twice the median found, scaled to the denser vertices' spacing (few neighbours to compare on a
    dense mesh); while the best median reaches that cap (half the distances cut short), again with the cap doubled,
    at least twice the first search's median, up to ``rough_match`` (``_least_median``)."""
    (axis, around), reach = plane, tuning.twin_tolerance * size
    probe = vertices[::max(1, len(vertices) // tuning.plane_samples)]
    sparse = vertices[::max(1, len(vertices) // (4 * tuning.plane_samples))]
    centre, rough = _least_median(around + np.linspace(-reach, reach, 17), probe[::4], sparse, axis,
                                  tuning.rough_match * size)
    step = tuning.rough_step * size
    fine = centre + step * np.arange(-np.ceil(reach / 8 / step), np.ceil(reach / 8 / step) + 1)
    cap = max(2 * rough * np.sqrt(len(sparse) / len(vertices)), step)
    while True:
        offset, median = _least_median(fine, probe, vertices, axis, cap)
        if median < cap or cap >= tuning.rough_match * size:
            return float(offset)
        cap = min(max(2 * cap, 2 * rough), tuning.rough_match * size)


CROWD = 16  # vertices per grid cell, about, that _least_median compares with (a dense mesh's cells hold more)
CROWD_SAMPLE = 20_000  # nearby vertices sampled to count the cells they occupy


def _least_median(offsets, probe, vertices, axis, cap):
    """(offset, median) of the ``offsets`` along ``axis`` where the median over the ``probe`` points of the distance
    from their mirror image to the nearest of the ``vertices``, at most ``cap``, is least.

    Each probe's candidates are gathered once for all offsets (a mirror image moves only along the axis): the vertices
    in a grid of cells ``cap`` wide within ``cap`` of the segment its images run along. Where those cells hold more
    than ``CROWD`` vertices on average, an even share of them (picked by a hash of their index) stands for the rest,
    so the work is bounded on a dense mesh whose images lie far from it (a hand-made body): the median is then
    several times the thinned vertices' spacing, and thinning moves it little."""
    offsets = np.asarray(offsets, dtype=float)
    low, high = float(offsets.min()), float(offsets.max())
    origin = vertices.min(axis=0) - 2 * cap
    origin[axis] = min(origin[axis], 2 * low - probe[:, axis].max() - 2 * cap)
    top = vertices.max(axis=0) + 2 * cap
    top[axis] = max(top[axis], 2 * high - probe[:, axis].min() + 2 * cap)
    span = np.floor((top - origin) / cap).astype(np.int64) + 1

    reach = int(np.ceil((high - low) / cap)) + 1  # cells along the axis either side of the middle image's
    shifts = np.zeros((2 * reach + 1, 3), np.int64)
    shifts[:, axis] = np.arange(-reach, reach + 1)
    around = (_NEIGHBOURS[_NEIGHBOURS[:, axis] == 0][:, None, :] + shifts[None]).reshape(-1, 3)
    images = np.floor((mirrored(probe, (axis, 0.5 * (low + high))) - origin) / cap).astype(np.int64)
    looked = _cell_keys(np.clip((images[:, None, :] + around[None]).reshape(-1, 3), 0, span - 1), span)

    keys = _cell_keys(np.floor((vertices - origin) / cap).astype(np.int64), span)
    near = _CellSet(looked, span).holds(keys)
    vertices, keys = vertices[near], keys[near]
    step = max(1, len(keys) // CROWD_SAMPLE)
    crowd = len(keys) / _occupied(len(np.unique(keys[::step])), len(keys), 1.0 / step)
    if crowd > CROWD:
        index = np.flatnonzero(near).astype(np.uint64)
        keep = (index * np.uint64(2654435761)) % np.uint64(1 << 32) < np.uint64(CROWD / crowd * (1 << 32))
        vertices, keys = vertices[keep], keys[keep]
    at, owner = _in_cells(keys, looked, np.repeat(np.arange(len(probe)), len(around)))
    across = np.delete(np.arange(3), axis)
    squares = ((vertices[at][:, across] - probe[owner][:, across]) ** 2).sum(axis=1)
    sums = vertices[at, axis] + probe[owner, axis]  # a vertex lies sums - 2 * offset along the axis from an image
    close = (squares < cap * cap) & (sums > 2 * low - cap) & (sums < 2 * high + cap)
    squares, sums, owner = squares[close], sums[close], owner[close]
    nearest = np.full((len(probe), len(offsets)), cap * cap)
    if len(owner):
        firsts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
        gaps = squares[:, None] + (sums[:, None] - 2 * offsets[None]) ** 2
        nearest[owner[firsts]] = np.minimum(np.minimum.reduceat(gaps, firsts, axis=0), cap * cap)
    medians = np.median(np.sqrt(nearest), axis=0)
    best = int(np.lexsort((np.abs(offsets - 0.5 * (low + high)), medians))[0])  # of equals, the middlemost
    return offsets[best], float(medians[best])


def _occupied(hit, count, share):
    """How many cells ``count`` points occupy, about, when a ``share`` of them sampled hit ``hit`` cells: the cells
    C with C * (1 - (1 - share) ** (count / C)) = hit (as many points in each), by bisection."""
    low, high = float(max(hit, 1)), float(max(count, 1))
    for _ in range(50):
        cells = 0.5 * (low + high)
        if cells * (1.0 - (1.0 - share) ** (count / cells)) < hit:
            low = cells
        else:
            high = cells
    return high


_NEIGHBOURS = np.array([(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)])
# the cells a point of which may lie within a cell's diagonal of a point in the middle one (three away never do)
_WITHIN_TWO = np.array([(dx, dy, dz) for dx in range(-2, 3) for dy in range(-2, 3) for dz in range(-2, 3)])


def _cell_keys(cells, span):
    return (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]


class _CellSet:
    """The cells of a grid ``span`` cells wide that hold one of ``keys``: a flag per cell where the grid has at most
    ``DENSE_CELLS`` (one pass over the keys, where sorting them would dominate on a large mesh), else the sorted
    keys."""

    DENSE_CELLS = 1 << 24

    def __init__(self, keys, span):
        if np.prod(span) <= self.DENSE_CELLS:
            self.flags = np.zeros(int(np.prod(span)), dtype=bool)
            self.flags[keys] = True
        else:
            self.flags, self.sorted = None, np.unique(keys)

    def holds(self, keys):
        """Which of ``keys`` (cells within the grid) hold a key of the set."""
        if self.flags is not None:
            return self.flags[keys]
        at = np.minimum(np.searchsorted(self.sorted, keys), len(self.sorted) - 1)
        return self.sorted[at] == keys


def mirror_chain_pairs(lines, symmetry):
    """Pairs (i, j), i < j, of chains (3D polylines) that are mirror twins: their ends match the mirrored ends
    (within ``twin_ends`` tolerances summed); then, among the chains left, those whose starts match and where one's
    tip lies on the other's image (``Symmetry.covers``: a hand whose finger's branch was pruned on one side only, so
    one arm runs on into the hand). Each pass pairs the best fits first, so fingers close together pair with their
    own images; whole twins pair before partial ones, so a stub off a shoulder never takes an arm from its exact
    twin. Chains on the plane are never paired; one that lies on it on average but whose tip is off it (legs from
    the middle of the hips) is on its tip's side."""
    side = np.array([symmetry.side(line, by_tip=True) for line in lines])
    pairs, taken = [], np.zeros(len(lines), bool)
    for partial in (False, True):
        fits = []  # (misfit, i, j) of the candidate twins
        for i, j in zip(*np.nonzero((side[:, None] == -side[None, :]) & (side[:, None] > 0))):
            if taken[i] or taken[j]:
                continue
            if partial:
                image = symmetry.reflect(lines[i])
                gaps = min((covering_fit(image, lines[j]), covering_fit(lines[j], image)), key=sum)
                if symmetry.covers(gaps):
                    fits.append((sum(gaps), min(i, j), max(i, j)))
            elif symmetry.whole_twins(lines[i], lines[j]):
                fits.append((symmetry.ends_misfit(lines[i], lines[j]), min(i, j), max(i, j)))
        for _, i, j in sorted(fits):
            if not taken[i] and not taken[j]:
                pairs.append((int(i), int(j)))
                taken[[i, j]] = True
    return sorted(pairs)


def covering_fit(long, short):
    """(start gap, tip gap) of polyline ``short`` against ``long``: how far apart their starts lie and how far the
    tip of ``short`` lies off ``long`` (for ``Symmetry.covers``)."""
    return (float(np.linalg.norm(short[0] - long[0])),
            float(segment_distances(short[-1:], long[:-1], long[1:]).min()))


def mirror_completed(limbs, symmetry):
    """The (polyline, half-widths) ``limbs`` with each one that a longer mirror twin covers (``Symmetry.covers``)
    replaced by the twin's mirror image: a view's triangulation is not symmetric, and may prune one ear's tip but not
    the other's. A limb's twin is the one whose image fits it best, so a short limb beside a long one (a leg below an
    antenna) keeps its own; each twin replaces one limb, the one it fits best. A limb whose middle lies off the plane
    and whose image no limb on the other side covers or fits into gets that image as a limb of its own: the view may
    have pruned one ear's whole tip (the mesh is symmetric, so its skeleton is)."""
    lines = [line for line, _ in limbs]
    side = [symmetry.side(line, by_tip=True) for line in lines]
    images = [symmetry.reflect(line) for line in lines]
    fits = {}  # twin -> (misfit, limb it replaces)
    for j, line in enumerate(lines):
        twins = [i for i in range(len(lines)) if side[i] != 0 and side[i] == -side[j]]
        if not twins:
            continue
        gaps = np.array([covering_fit(images[i], line) for i in twins])  # (start gap, tip gap) per twin
        misfits = gaps.sum(axis=1)
        best = int(np.argmin(misfits))
        i = twins[best]
        covered = symmetry.covers(gaps[best]) and length(line) < length(lines[i])
        if covered and misfits[best] < fits.get(i, (np.inf,))[0]:
            fits[i] = (misfits[best], j)
    result = list(limbs)
    for i, (_, j) in fits.items():
        result[j] = (images[i], limbs[i][1])
    for j, line in enumerate(lines):
        paired = any(side[i] == -side[j] and (symmetry.covers(covering_fit(images[j], lines[i]))
                                              or symmetry.covers(covering_fit(lines[i], images[j])))
                     for i in range(len(lines)))
        if symmetry.side(line) != 0 and not paired:
            result.append((images[j], limbs[j][1]))
    return result


def square_turn(mesh, tuning=MirrorTuning()):
    """A rotation (rows: the new axes) that turns ``mesh`` (a ``core.mesh.Mesh``) so the plane it mirrors about lies
    square to the axis nearest its normal, the least turn that does; None when it mirrors about an axis plane already
    (within ``rough_match`` of its size), or about none. A mirror plane's normal is one of the vertices' principal
    axes when their spreads differ (mirroring leaves the spread alike on both sides), so each is a first guess, made
    exact by :func:`_refined_normal`: a character turned about its up axis and saved so rigs as if it faced along an
    axis, its up kept."""
    tolerance = tuning.rough_match * mesh.scale
    vertices = mesh.used_vertices[::max(1, len(mesh.used_vertices) // tuning.square_sample)]
    if mirrors_about_an_axis_plane(vertices, mesh.bbox, tolerance, tuning):
        return None
    probe = vertices[::max(1, len(vertices) // (2 * tuning.square_probes))]
    pool = vertices[::max(1, len(vertices) // tuning.square_exact_pool)]
    best, least = None, np.inf
    for guess in mesh.principal_axes.T:
        normal, centre = _refined_normal(vertices, guess, tolerance, tuning)
        axis = int(np.argmax(np.abs(normal)))
        if abs(normal[axis]) > np.cos(np.radians(tuning.square_least)):
            continue  # square already: the axis planes were tried
        rotation = _turned_onto(normal, np.sign(normal[axis]) * np.eye(3)[axis])
        turned = vertices @ rotation.T
        if not mirrors_about_an_axis_plane(turned, np.stack([turned.min(axis=0), turned.max(axis=0)]), tolerance,
                                           tuning):
            continue  # squaring one principal axis squares the others: the plane found may be another's
        misfit = _refitted(probe, pool, normal, centre, tolerance)[3]
        if misfit < least:  # of planes that hold, the one the mesh mirrors about most closely
            best, least = rotation, misfit
    return best


def _refined_normal(vertices, normal, tolerance, tuning):
    """(unit normal, a point on it) of the mirror plane nearest to ``normal`` (a guess): refitted (:func:`_refitted`)
    up to ``square_rounds`` times to ``square_probes`` sample vertices paired with the nearest of ``square_pool``
    others to their mirror images; when ``square_near`` of them pair or more (a plane is near), up to
    ``square_exact_rounds`` more times, while no fewer pair, with twice the samples and up to ``square_exact_pool``
    vertices, where a mirror-modelled mesh's exact twins are."""
    centre, share = vertices.mean(axis=0), 0.0
    for probes, pool_size, rounds in ((tuning.square_probes, tuning.square_pool, tuning.square_rounds),
                                      (2 * tuning.square_probes, tuning.square_exact_pool,
                                       tuning.square_exact_rounds)):
        if pool_size == tuning.square_exact_pool and (share < tuning.square_near or np.abs(normal).max() > np.cos(
                np.radians(tuning.square_least))):
            break  # no plane near, or one square already (the axis planes do not hold: a snake's S-curve)
        probe = vertices[::max(1, len(vertices) // probes)]
        pool = vertices[::max(1, len(vertices) // pool_size)]
        for _ in range(rounds):
            refitted, moved, paired, _ = _refitted(probe, pool, normal, centre, tolerance)
            if pool_size == tuning.square_exact_pool and paired < share:
                break  # pairing fewer: no nearer plane to find (an asymmetric mesh's wobble)
            settled = refitted @ normal > 1.0 - 1e-15
            normal, centre, share = refitted, moved, paired
            if settled:
                break
    return normal, centre


def _refitted(probe, pool, normal, centre, tolerance):
    """(normal, centre, share, misfit): the ``probe`` points are mirrored across the plane through ``centre`` with
    unit ``normal`` and paired with the ``pool`` point nearest each image (``misfit``: their mean distance, each at
    most ``tolerance``; pairs farther apart dropped, ``share`` of them kept); the plane refitted to the pairs is the
    one along whose normal they lie apart, through their midpoints. The plane as it was when fewer than three pair."""
    image = probe - 2.0 * ((probe - centre) @ normal)[:, None] * normal
    ranking = image @ (-2.0 * pool.T)
    ranking += np.einsum("ij,ij->i", pool, pool)  # the squared distance but the image's own length: same order
    nearest = np.argmin(ranking, axis=1)
    distance = np.linalg.norm(image - pool[nearest], axis=1)
    near = distance <= tolerance
    misfit = float(np.mean(np.minimum(distance, tolerance)))
    if np.count_nonzero(near) < 3:
        return normal, centre, 0.0, misfit
    apart = probe[near] - pool[nearest[near]]
    refitted = np.linalg.eigh(apart.T @ apart)[1][:, -1]
    return (refitted if refitted @ normal >= 0 else -refitted,
            0.5 * (probe[near] + pool[nearest[near]]).mean(axis=0), float(np.mean(near)), misfit)


def _turned_onto(a, b):
    """The least rotation taking unit vector ``a`` onto unit vector ``b`` (not its opposite): Rodrigues' formula."""
    cross, dot = np.cross(a, b), float(a @ b)
    skew = np.array([[0.0, -cross[2], cross[1]], [cross[2], 0.0, -cross[0]], [-cross[1], cross[0], 0.0]])
    return np.eye(3) + skew + skew @ skew / (1.0 + dot)
