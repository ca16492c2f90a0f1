"""Validity checks for ``rigger.cdt`` results, shared by the CDT tests.

Every geometric decision is exact and independent of the code under test: a float evaluation with a forward error
bound (Shewchuk's static filter, with a safety factor) settles the clear cases, and exact integer arithmetic (every
float is an integer times a power of two) settles the rest. Only Steiner points, rounded by construction, are
compared with a small tolerance.
"""
import bisect
import math
from collections import Counter
from fractions import Fraction

import numpy as np

_EPS = 2.0 ** -53
_ORIENT_BOUND = 4 * (3 + 16 * _EPS) * _EPS
_INCIRCLE_BOUND = 4 * (10 + 96 * _EPS) * _EPS
# Outside this range products may underflow or overflow and the float filter proves nothing.
_TINY, _HUGE = 2.0 ** -900, 2.0 ** 900
# How far (relative to the coordinate scale) a constraint chain may stray from its input segment: rounded crossing
# points land within a few ulps of both segments, and a crossing that rounds onto an existing vertex goes through it.
STEINER_TOLERANCE = 1e-12


def _filtered_signs(det, bound, exact, rows):
    """Signs of ``det`` where the bound proves them; ``exact(i)`` decides the other rows."""
    sure = (np.abs(det) > bound) & (bound > _TINY) & (bound < _HUGE)
    signs = np.where(sure, np.sign(det), 0).astype(np.int8)
    for i in np.flatnonzero(~sure):
        signs.flat[i] = exact(rows(i))
    return signs


def _sign(value):
    return (value > 0) - (value < 0)


def _as_integers(*pairs):
    """The coordinates scaled by one common power of two to integers: signs of homogeneous determinants keep."""
    ratios = [float(v).as_integer_ratio() for pair in pairs for v in pair]
    common = max(den for _, den in ratios)
    values = [num * (common // den) for num, den in ratios]
    return list(zip(values[::2], values[1::2]))


def _orient_exact(a, b, c):
    (ax, ay), (bx, by), (cx, cy) = _as_integers(a, b, c)
    return _sign((ax - cx) * (by - cy) - (ay - cy) * (bx - cx))


def _incircle_exact(a, b, c, d):
    (ax, ay), (bx, by), (cx, cy), (dx, dy) = _as_integers(a, b, c, d)
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    return _sign((adx * adx + ady * ady) * (bdx * cdy - bdy * cdx)
                 + (bdx * bdx + bdy * bdy) * (cdx * ady - cdy * adx)
                 + (cdx * cdx + cdy * cdy) * (adx * bdy - ady * bdx))


def orient(a, b, c):
    """Exact orient2d sign for three (x, y) float pairs: the scalar twin of :func:`orient_signs`."""
    left = (a[0] - c[0]) * (b[1] - c[1])
    right = (a[1] - c[1]) * (b[0] - c[0])
    bound = _ORIENT_BOUND * (abs(left) + abs(right))
    if abs(left - right) > bound and _TINY < bound < _HUGE:
        return _sign(left - right)
    return _orient_exact(a, b, c)


def orient_signs(a, b, c):
    """Exact sign of orient2d for broadcastable (..., 2) arrays: +1 when a, b, c turn counter-clockwise."""
    a, b, c = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (a, b, c)))
    with np.errstate(all="ignore"):
        left = (a[..., 0] - c[..., 0]) * (b[..., 1] - c[..., 1])
        right = (a[..., 1] - c[..., 1]) * (b[..., 0] - c[..., 0])
        det = left - right
        bound = _ORIENT_BOUND * (np.abs(left) + np.abs(right))
    flat = [v.reshape(-1, 2) for v in (a, b, c)]
    return _filtered_signs(det, bound, lambda rows: _orient_exact(*rows), lambda i: [v[i] for v in flat])


def incircle_signs(a, b, c, d):
    """Exact in-circle sign: +1 when d is strictly inside the circle through counter-clockwise a, b, c."""
    a, b, c, d = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (a, b, c, d)))
    with np.errstate(all="ignore"):
        adx, ady = a[..., 0] - d[..., 0], a[..., 1] - d[..., 1]
        bdx, bdy = b[..., 0] - d[..., 0], b[..., 1] - d[..., 1]
        cdx, cdy = c[..., 0] - d[..., 0], c[..., 1] - d[..., 1]
        alift, blift, clift = adx * adx + ady * ady, bdx * bdx + bdy * bdy, cdx * cdx + cdy * cdy
        det = (alift * (bdx * cdy - bdy * cdx) + blift * (cdx * ady - cdy * adx)
               + clift * (adx * bdy - ady * bdx))
        permanent = ((np.abs(bdx * cdy) + np.abs(bdy * cdx)) * alift + (np.abs(cdx * ady) + np.abs(cdy * adx)) * blift
                     + (np.abs(adx * bdy) + np.abs(ady * bdx)) * clift)
        bound = _INCIRCLE_BOUND * permanent
    flat = [v.reshape(-1, 2) for v in (a, b, c, d)]
    return _filtered_signs(det, bound, lambda rows: _incircle_exact(*rows), lambda i: [v[i] for v in flat])


def convex_hull(xy):
    """Indices of the strict corners of the convex hull of ``xy`` (distinct points), counter-clockwise, exact.

    Fewer than three corners means the points are all collinear (or fewer than three)."""
    order = np.lexsort((xy[:, 1], xy[:, 0])).tolist()
    pairs = xy.tolist()

    def chain(indices):
        out = []
        for i in indices:
            while len(out) >= 2 and orient(pairs[out[-2]], pairs[out[-1]], pairs[i]) <= 0:
                out.pop()
            out.append(i)
        return out

    lower, upper = chain(order), chain(order[::-1])
    hull = lower[:-1] + upper[:-1]
    return hull if len(hull) >= 3 else []


def triangle_areas(vertices, triangles):
    """Float areas (positive for counter-clockwise triangles)."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def polygon_area(xy):
    """Shoelace area of a closed polygon given by its vertices in order (positive when counter-clockwise)."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * math.fsum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def edge_twins(triangles):
    """For every (triangle, k) the (triangle, k) across the edge opposite vertex k, or (-1, -1) on the boundary.

    Asserts that no directed edge occurs twice (triangles overlap or disagree in orientation otherwise)."""
    if not len(triangles):
        return np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64)
    count = int(triangles.max()) + 1
    start = triangles[:, [1, 2, 0]].astype(np.int64)
    end = triangles[:, [2, 0, 1]].astype(np.int64)
    keys = (start * count + end).ravel()
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    repeated = sorted_keys[1:] == sorted_keys[:-1]
    assert not repeated.any(), f"directed edge {divmod(int(sorted_keys[1:][repeated][0]), count)} is used twice"
    reverse = (end * count + start).ravel()
    pos = np.minimum(np.searchsorted(sorted_keys, reverse), len(keys) - 1)
    found = sorted_keys[pos] == reverse
    twin = np.where(found, order[pos], -1)
    return np.where(twin >= 0, twin // 3, -1).reshape(-1, 3), np.where(twin >= 0, twin % 3, -1).reshape(-1, 3)


def check_arrays(tri, n_points):
    """Shapes, dtypes and index ranges promised by the Triangulation docstring."""
    k, t = len(tri.vertices), len(tri.triangles)
    for name, dtype, width in (("vertices", np.float64, 2), ("triangles", np.int32, 3), ("neighbors", np.int32, 3),
                               ("constrained", np.bool_, 3), ("segments", np.int32, 2)):
        array = getattr(tri, name)
        assert array.dtype == dtype and array.ndim == 2 and array.shape[1] == width, (
            f"{name} is {array.dtype} {array.shape}, expected {np.dtype(dtype)} (?, {width})")
    assert tri.neighbors.shape[0] == tri.constrained.shape[0] == t, "one neighbors/constrained row per triangle"
    assert tri.vertex_map.dtype == np.int32 and tri.vertex_map.shape == (n_points,), (
        f"vertex_map is {tri.vertex_map.dtype} {tri.vertex_map.shape} for {n_points} points")
    assert k >= n_points and tri.steiner_count == k - n_points, f"{k} vertices for {n_points} input points"
    if t:
        assert tri.triangles.min() >= 0 and tri.triangles.max() < k, "triangle index out of range"
        assert tri.neighbors.min() >= -1 and tri.neighbors.max() < t, "neighbour index out of range"
    if len(tri.segments):
        low, high = tri.segments[:, 0], tri.segments[:, 1]
        assert (low < high).all(), "segments must be (low, high) pairs"
        assert low.min() >= 0 and high.max() < k, "segment index out of range"
        keys = low.astype(np.int64) * k + high
        assert (np.diff(keys) > 0).all(), "segments must be sorted and unique"


def check_vertex_map(tri, points):
    """Rows 0..N-1 are the input as given; exact duplicates map to the lowest index and are never used."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    assert np.array_equal(tri.vertices[:len(points)], points), "input points were not kept as given"
    first = {}
    expected = np.array([first.setdefault((float(x), float(y)), i) for i, (x, y) in enumerate(points)], np.int32)
    bad = np.flatnonzero(tri.vertex_map != expected)
    assert not len(bad), f"vertex_map[{bad[0]}] is {tri.vertex_map[bad[0]]}, expected {expected[bad[0]]}"
    duplicates = np.flatnonzero(expected != np.arange(len(points)))
    used = np.union1d(tri.triangles.ravel(), tri.segments.ravel())
    reused = np.intersect1d(duplicates, used)
    assert not len(reused), f"duplicate point {reused[0]} is used instead of {expected[reused[0]]}"


def check_orientation(tri):
    """Every triangle is strictly counter-clockwise (exact)."""
    v = tri.vertices[tri.triangles]
    signs = orient_signs(v[:, 0], v[:, 1], v[:, 2]) if len(v) else np.zeros(0)
    bad = np.flatnonzero(signs <= 0)
    assert not len(bad), f"{len(bad)} triangles not strictly CCW, e.g. #{bad[0]} {tri.triangles[bad[0]].tolist()}"


def check_neighbors(tri):
    """``neighbors`` is exactly the adjacency implied by shared edges (mutual, across the same edge)."""
    twin_t, _ = edge_twins(tri.triangles)
    bad = np.argwhere(tri.neighbors != twin_t)
    assert not len(bad), (f"neighbors[{bad[0][0]}, {bad[0][1]}] is {tri.neighbors[tuple(bad[0])]}, "
                          f"the shared edge says {twin_t[tuple(bad[0])]}")


def check_constraint_flags(tri, whole_hull):
    """``constrained`` flags exactly the edges listed in ``segments``, on both sides. ``segments`` holds every piece
    of the input segments whatever the mode, so with the whole hull kept each piece is a triangle edge."""
    k = len(tri.vertices)
    start, end = tri.triangles[:, [1, 2, 0]], tri.triangles[:, [2, 0, 1]]
    edge_keys = np.minimum(start, end).astype(np.int64) * k + np.maximum(start, end)
    seg_keys = tri.segments[:, 0].astype(np.int64) * k + tri.segments[:, 1]
    expected = np.isin(edge_keys, seg_keys)
    bad = np.argwhere(tri.constrained != expected)
    assert not len(bad), f"constrained[{bad[0][0]}, {bad[0][1]}] should be {expected[tuple(bad[0])]}"
    if whole_hull and len(tri.triangles):
        missing = np.flatnonzero(~np.isin(seg_keys, edge_keys))
        assert not len(missing), f"segment {tri.segments[missing[0]].tolist()} is not an edge of any triangle"


def check_delaunay(tri):
    """Constrained Delaunay: across every unconstrained interior edge the far apex is not strictly inside (exact)."""
    twin_t, twin_k = edge_twins(tri.triangles)
    t, k = np.nonzero((twin_t >= 0) & ~tri.constrained)
    if not len(t):
        return
    v = tri.vertices
    tris = tri.triangles[t]
    apex = tri.triangles[twin_t[t, k], twin_k[t, k]]
    signs = incircle_signs(v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]], v[apex])
    bad = np.flatnonzero(signs > 0)
    assert not len(bad), (f"{len(bad)} edges fail the in-circle test, e.g. apex {apex[bad[0]]} inside the "
                          f"circumcircle of triangle #{t[bad[0]]} {tris[bad[0]].tolist()}")


def check_boundary_constrained(tri):
    """mode="inside": the kept region is bounded by constraint edges only."""
    twin_t, _ = edge_twins(tri.triangles)
    bad = np.argwhere((twin_t < 0) & ~tri.constrained)
    assert not len(bad), f"boundary edge opposite vertex {bad[0][1]} of triangle #{bad[0][0]} is not a constraint"


def _direction_key(a, b):
    """A function ordering points along the line a -> b: their projection onto it, so that a vertex snapped onto the
    segment beside an endpoint (sharing its coordinate along either axis) still comes before that endpoint. Exact
    rationals: in floats that projection can round to the endpoint's own."""
    ax, ay = Fraction(a[0]), Fraction(a[1])
    dx, dy = Fraction(b[0]) - ax, Fraction(b[1]) - ay
    return lambda p: (Fraction(p[0]) - ax) * dx + (Fraction(p[1]) - ay) * dy


def _near_line(p, a, b):
    """Is p (a rounded crossing point, or a vertex one snapped to) within STEINER_TOLERANCE of the line a-b?"""
    scale = max(np.abs(a).max(), np.abs(b).max(), np.hypot(*(b - a)))
    cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    return abs(cross) / np.hypot(*(b - a)) <= STEINER_TOLERANCE * scale


def _input_vertices_inside(pairs, a, b, sorted_by):
    """Distinct input vertices strictly inside segment a-b (exact), among those in its bounding box.
    ``sorted_by[axis]`` holds (sorted coordinates, vertex indices) of the distinct inputs along that axis."""
    (ax, ay), (bx, by) = pairs[a], pairs[b]
    axis = 0 if abs(bx - ax) <= abs(by - ay) else 1  # search along the narrower side of the box
    values, indices = sorted_by[axis]
    lo = bisect.bisect_left(values, min(pairs[a][axis], pairs[b][axis]))
    hi = bisect.bisect_right(values, max(pairs[a][axis], pairs[b][axis]))
    other = 1 - axis
    low, high = min(pairs[a][other], pairs[b][other]), max(pairs[a][other], pairs[b][other])
    return {w for w in indices[lo:hi] if w != a and w != b and low <= pairs[w][other] <= high
            and orient(pairs[a], pairs[b], pairs[w]) == 0}


def _chain_along(a, b, adjacent, v, pairs):
    """A path of pieces from a to b, each step moving forward along a-b to a vertex on it (exactly or within
    STEINER_TOLERANCE), or None. Depth-first: a vertex merely near the line may be a dead end."""
    key = _direction_key(v[a], v[b])
    end = key(v[b])
    paths = [[a]]
    while paths:
        path = paths.pop()
        if path[-1] == b:
            return path
        here = key(v[path[-1]])
        along = {w: key(v[w]) for w in adjacent.get(path[-1], ())}
        ahead = [w for w, at in along.items() if here < at <= end
                 and (orient(pairs[a], pairs[b], pairs[w]) == 0 or _near_line(v[w], v[a], v[b]))]
        paths += [path + [w] for w in sorted(ahead, key=lambda w: -along[w])]
    return None


def check_segments_covered(tri, segments):
    """Every input segment of nonzero length is a chain of ``segments`` pieces lying on it (exactly, or within
    STEINER_TOLERANCE at rounded crossings) that passes through every input vertex lying exactly on it.
    Returns how many input segments cover each piece."""
    n = len(tri.vertex_map)
    v = tri.vertices
    pairs = v.tolist()
    distinct = np.flatnonzero(tri.vertex_map == np.arange(n))
    sorted_by = []
    for axis in (0, 1):
        indices = distinct[np.argsort(v[distinct, axis], kind="stable")].tolist()
        sorted_by.append(([pairs[w][axis] for w in indices], indices))
    adjacent = {}
    for low, high in tri.segments.tolist():
        adjacent.setdefault(low, []).append(high)
        adjacent.setdefault(high, []).append(low)
    cover = Counter()
    for i, (a, b) in enumerate(np.asarray(segments, dtype=np.int64).reshape(-1, 2).tolist()):
        a, b = int(tri.vertex_map[a]), int(tri.vertex_map[b])
        if a == b:
            continue
        chain = _chain_along(a, b, adjacent, v, pairs)
        assert chain, f"input segment {i} ({a}, {b}) is not a chain of constraint edges lying on it"
        skipped = _input_vertices_inside(pairs, a, b, sorted_by) - set(chain)
        assert not skipped, f"input segment {i} ({a}, {b}) is not split at vertices {sorted(skipped)} lying on it"
        cover.update((min(p, q), max(p, q)) for p, q in zip(chain[:-1], chain[1:]))
    return cover


def check_convex_hull(tri):
    """mode="all": the triangles tile the convex hull of the vertices, using every vertex but duplicates.

    The boundary edges must be exactly the hull's edges split at the vertices on them. With every triangle
    counter-clockwise and no directed edge repeated, the triangles then sum to the hull's winding number, 1 inside
    and 0 outside: they tile it without overlap (so their area is the hull's, exactly)."""
    n = len(tri.vertex_map)
    live = np.concatenate([np.flatnonzero(tri.vertex_map == np.arange(n)), np.arange(n, len(tri.vertices))])
    hull = live[convex_hull(tri.vertices[live])] if len(live) >= 3 else []
    if len(hull) < 3:
        assert len(tri.triangles) == 0, f"{len(tri.triangles)} triangles for collinear points"
        return
    unused = np.setdiff1d(live, tri.triangles.ravel())
    assert not len(unused), f"vertex {unused[0]} {tri.vertices[unused[0]].tolist()} is not used by any triangle"
    expected = set()
    for start, end in zip(hull, np.roll(hull, -1)):
        a, b = tri.vertices[start], tri.vertices[end]
        key = _direction_key(a, b)
        end = key(b)  # key(a) is 0
        along = {w: key(tri.vertices[w]) for w in live[orient_signs(a, b, tri.vertices[live]) == 0].tolist()}
        on_edge = sorted((w for w, at in along.items() if 0 <= at <= end), key=along.get)
        expected.update(zip(on_edge[:-1], on_edge[1:]))
    twin_t, _ = edge_twins(tri.triangles)
    t, k = np.nonzero(twin_t < 0)
    boundary = set(zip(tri.triangles[t, (k + 1) % 3].tolist(), tri.triangles[t, (k + 2) % 3].tolist()))
    assert boundary == expected, (f"boundary is not the convex hull: extra {sorted(boundary - expected)[:5]}, "
                                  f"missing {sorted(expected - boundary)[:5]}")


def check_triangulation(tri, points, segments=None, mode="all", holes=None):
    """Assert every property of a valid result of ``triangulate(points, segments, mode=mode, holes=holes)``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    segments = np.zeros((0, 2), np.int64) if segments is None else np.asarray(segments).reshape(-1, 2)
    whole_hull = mode == "all" and (holes is None or len(holes) == 0)
    check_arrays(tri, len(points))
    check_vertex_map(tri, points)
    check_orientation(tri)
    check_neighbors(tri)
    check_constraint_flags(tri, whole_hull)
    check_delaunay(tri)
    stray = set(map(tuple, tri.segments.tolist())) - set(check_segments_covered(tri, segments))
    assert not stray, f"constraint edges {sorted(stray)[:5]} lie on no input segment"
    if whole_hull:
        check_convex_hull(tri)
    elif mode == "inside":
        check_boundary_constrained(tri)


def coordinate_triples(tri):
    """Each triangle as the set of its corner coordinates, in triangle order: a key independent of numbering."""
    return [frozenset(map(tuple, corners)) for corners in tri.vertices[tri.triangles].tolist()]


def check_even_odd(inside, everything, points, segments):
    """``inside`` (mode="inside") keeps exactly the triangles of ``everything`` (mode="all", same input) that lie
    inside the segments by the even-odd rule. Parity is found exactly, by walking ``everything`` from the hull:
    crossing a piece covered by k input segments flips it k times. Needs closed curves (see
    :func:`has_closed_curves`), which make that parity consistent, as asserted."""
    cover = check_segments_covered(everything, segments)
    tris = everything.triangles
    twin_t, _ = edge_twins(tris)

    def flips(t, k):
        a, b = tris[t, (k + 1) % 3], tris[t, (k + 2) % 3]
        return cover[(min(a, b), max(a, b))] % 2

    parity = np.full(len(tris), -1)
    stack = []
    for t, k in np.argwhere(twin_t < 0).tolist():
        if parity[t] < 0:
            parity[t] = flips(t, k)
            stack.append(t)
        assert parity[t] == flips(t, k), f"parity of triangle #{t} is ambiguous: the segments are not closed curves"
    while stack:
        t = stack.pop()
        for k in range(3):
            n = twin_t[t, k]
            if n >= 0:
                if parity[n] < 0:
                    parity[n] = parity[t] ^ flips(t, k)
                    stack.append(n)
                assert parity[n] == parity[t] ^ flips(t, k), "parity is ambiguous: the segments are not closed curves"
    kept = set(coordinate_triples(inside))
    expected = {key for key, odd in zip(coordinate_triples(everything), parity) if odd}
    assert kept == expected, (f"mode='inside' keeps {len(kept)} triangles, the even-odd rule {len(expected)}: "
                              f"{len(kept - expected)} extra, {len(expected - kept)} missing")


def has_closed_curves(segments, vertex_map):
    """True when every vertex touches an even number of (nonzero-length) segments, so even-odd is well defined."""
    ends = vertex_map[np.asarray(segments, dtype=np.int64).reshape(-1, 2)]
    ends = ends[ends[:, 0] != ends[:, 1]]
    return bool((np.bincount(ends.ravel(), minlength=1) % 2 == 0).all())


def touches_cocircular_quad(tri):
    """Per triangle: is the far apex across one of its unconstrained edges exactly on its circumcircle? Only such
    triangles may differ between two valid CDTs of the same input (any flip of a cocircular quad is Delaunay)."""
    twin_t, twin_k = edge_twins(tri.triangles)
    t, k = np.nonzero((twin_t >= 0) & ~tri.constrained)
    flags = np.zeros(len(tri.triangles), bool)
    if len(t):
        corners = tri.vertices[tri.triangles[t]]
        apex = tri.vertices[tri.triangles[twin_t[t, k], twin_k[t, k]]]
        flags[t[incircle_signs(corners[:, 0], corners[:, 1], corners[:, 2], apex) == 0]] = True
    return flags


def assert_same_up_to_cocircular(first, second, first_keys, second_keys):
    """Two valid results of congruent inputs agree: the same triangles (as the given keys), except triangles
    touching an exactly cocircular quad, which must then cover the same area."""
    first_set, second_set = set(first_keys), set(second_keys)
    only_first = [i for i, key in enumerate(first_keys) if key not in second_set]
    only_second = [i for i, key in enumerate(second_keys) if key not in first_set]
    if not only_first and not only_second:
        return
    first_tie, second_tie = touches_cocircular_quad(first), touches_cocircular_quad(second)
    unexplained = ([first.triangles[i].tolist() for i in only_first if not first_tie[i]]
                   + [second.triangles[i].tolist() for i in only_second if not second_tie[i]])
    assert not unexplained, f"triangles differ away from cocircular points: {unexplained[:4]}"
    area_first = math.fsum(triangle_areas(first.vertices, first.triangles[only_first]))
    area_second = math.fsum(triangle_areas(second.vertices, second.triangles[only_second]))
    assert math.isclose(area_first, area_second, rel_tol=1e-9), "the differing triangles cover different areas"
