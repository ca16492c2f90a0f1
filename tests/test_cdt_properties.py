"""Property tests of rigger.cdt: invariants on random near-degenerate input, and agreement with Triangle.

Inputs live on small integer grids on purpose: that is where duplicates, collinear runs, cocircular quads, points on
segments and crossing or overlapping segments are common.
"""
import dataclasses
import math

import numpy as np
import pytest
import triangle
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from cdt_checks import (assert_same_up_to_cocircular, check_convex_hull, check_delaunay, check_even_odd,
                        check_neighbors, check_orientation, check_triangulation, check_vertex_map, coordinate_triples,
                        has_closed_curves, incircle_signs, orient_signs, triangle_areas)
from rigger.cdt import incircle, orient2d, triangulate


def budget(examples):
    """Hypothesis settings with a bounded example count (the whole file stays well under a minute)."""
    return settings(max_examples=examples, suppress_health_check=[HealthCheck.too_slow])


GRID = st.integers(-4, 4)
# Arbitrary floats, but no magnitude below 2**-40 besides zero: Shewchuk-style predicates are exact only while their
# products do not underflow, and coordinates spanning ~150 orders of magnitude are outside this project's scope.
FINITE = st.floats(-4, 4, allow_nan=False, allow_infinity=False).filter(lambda v: v == 0 or abs(v) >= 2 ** -40)


def index_triples(triangles):
    """Triangles as a set of sorted vertex-index triples (for results sharing one numbering)."""
    return {tuple(sorted(t)) for t in np.asarray(triangles).tolist()}


@st.composite
def messy_inputs(draw):
    """Grid points, dyadic points exactly on segments, duplicates and a few arbitrary floats, with random
    segments among them (crossing, overlapping, zero-length, through points)."""
    points = [tuple(map(float, p)) for p in draw(st.lists(st.tuples(GRID, GRID), min_size=1, max_size=24))]
    index = st.integers(0, len(points) - 1)
    segments = draw(st.lists(st.tuples(index, index), max_size=12))
    for a, b in draw(st.lists(st.sampled_from(segments), max_size=4)) if segments else []:
        f = draw(st.sampled_from([0.25, 0.5, 0.75]))
        (ax, ay), (bx, by) = points[a], points[b]
        points.append((ax + f * (bx - ax), ay + f * (by - ay)))
    points += [points[i] for i in draw(st.lists(st.integers(0, len(points) - 1), max_size=4))]
    points += draw(st.lists(st.tuples(FINITE, FINITE), max_size=4))
    return np.array(points, np.float64), np.array(segments, np.int64).reshape(-1, 2)


def near_grid_input(seed):
    """Points within 1e-9 of a 1/8 grid, so nearly coincident, nearly collinear and nearly on segments, with random
    segments or one closed polyline through them: crossings that round onto or next to existing vertices. Drawn
    from a seed (uniform, unlike Hypothesis's small-value bias; the seed reproduces a failure)."""
    rng = np.random.default_rng(seed)
    n = rng.integers(8, 40)
    points = rng.integers(0, 9, (n, 2)) / 8 + rng.integers(-1, 2, (n, 2)) * 1e-9
    if rng.random() < 0.5:
        loop = rng.integers(0, n, rng.integers(4, 30))
        return points, np.stack([loop, np.roll(loop, -1)], axis=1)
    return points, rng.integers(0, n, (rng.integers(4, 30), 2))


@st.composite
def closed_curves(draw):
    """Grid points and closed polylines through them (they may cross, overlap, double back or repeat a point)."""
    points = np.array(draw(st.lists(st.tuples(GRID, GRID), min_size=3, max_size=20)), np.float64)
    index = st.integers(0, len(points) - 1)
    segments = []
    for loop in draw(st.lists(st.lists(index, min_size=2, max_size=6), min_size=1, max_size=3)):
        segments += [(loop[i], loop[(i + 1) % len(loop)]) for i in range(len(loop))]
    return points, np.array(segments, np.int64)


@st.composite
def nested_rectangles(draw):
    """Disjoint cells, each with 1-3 strictly nested rectangles (a polygon, its hole, an island in the hole), some
    given twice (a doubled boundary cancels), plus grid points on and inside them. Returns the even-odd area too."""
    points, segments, area = [], [], 0
    for cell in range(draw(st.integers(1, 3))):
        depth = draw(st.integers(1, 3))
        x_margins, y_margins = (sorted(draw(st.sets(st.integers(0, 4), min_size=depth, max_size=depth)))
                                for _ in range(2))
        x0, inside = 12 * cell, False
        for level, (mx, my) in enumerate(zip(x_margins, y_margins)):
            corners = [(x0 + mx, my), (x0 + 10 - mx, my), (x0 + 10 - mx, 10 - my), (x0 + mx, 10 - my)]
            if draw(st.booleans()):
                corners.reverse()
            ring = [(len(points) + i, len(points) + (i + 1) % 4) for i in range(4)]
            points += corners
            doubled = draw(st.integers(0, 4)) == 0
            segments += ring * (2 if doubled else 1)
            inside ^= not doubled
            inner = ((10 - 2 * x_margins[level + 1]) * (10 - 2 * y_margins[level + 1])) if level + 1 < depth else 0
            area += inside * ((10 - 2 * mx) * (10 - 2 * my) - inner)
        points += [(x0 + x, y) for x, y in draw(st.lists(st.tuples(st.integers(0, 10), st.integers(0, 10)),
                                                              max_size=8))]
    return np.array(points, np.float64), np.array(segments, np.int64), area


def check_both_modes(points, segments):
    """Valid in both modes; mode="inside" keeps a subset of mode="all", exactly the even-odd one when closed."""
    everything = triangulate(points, segments, mode="all")
    check_triangulation(everything, points, segments, mode="all")
    if not len(segments):
        return everything, None
    inside = triangulate(points, segments, mode="inside")
    check_triangulation(inside, points, segments, mode="inside")
    assert np.array_equal(inside.vertices, everything.vertices)
    assert set(coordinate_triples(inside)) <= set(coordinate_triples(everything))
    if has_closed_curves(segments, everything.vertex_map):
        check_even_odd(inside, everything, points, segments)
    return everything, inside


@budget(400)
@given(messy_inputs())
def test_messy_input_is_valid_in_both_modes(case):
    check_both_modes(*case)


@budget(300)
@given(st.integers(0, 2 ** 32 - 1))
@example(17554)  # four points within 1e-16 of one line: see the next test
def test_near_degenerate_input_is_valid_in_both_modes(seed):
    check_both_modes(*near_grid_input(seed))


def test_a_segment_routed_through_a_vertex_an_ulp_from_its_end_is_a_chain_along_it():
    """Vertex 2 lies within SNAP of segment 0-1, an ulp from its end 1 (the same x): the segment is 0-2, 2-1."""
    points = np.array([[0.0, -2.0], [2.0, -4.0], [2.0, -3.9999999999999996]])
    check_both_modes(points, np.array([[0, 1]]))


def test_a_crossing_next_to_a_vertex_an_ulp_from_a_segments_end_stays_delaunay():
    """Found by Hypothesis: vertex 7 lies an ulp from vertex 2, the end of segment 0-2, which crosses 1-6 at Steiner
    vertex 8. The piece 8-2 is routed through 7, so edge 8-2, until then behind the constraint 0-2, must be flipped.
    The chain 0-8-7-2 also tests the checker: 7's projection onto 0-2 rounds to 2's in floats."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, -4.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, -1.0],
                       [2.0, -3.9999999999999996]])
    check_both_modes(points, np.array([[0, 2], [1, 6]]))


def test_a_segment_through_two_nearly_collinear_vertices_is_split_at_both():
    """Segment 3-2 passes within rounding of vertex 1 and then vertex 0. Routing through 0 along the existing edge
    3-0 must not skip 1, the apex of the sliver beside that edge; the pieces are 3-1, 1-0, 0-2."""
    points = np.array([[0.249999999, 0.749999999], [0.375000001, 0.875000001], [0.0, 0.5], [0.5, 1.0]])
    tri = triangulate(points, [(3, 2)], mode="all")
    assert sorted(map(tuple, tri.segments.tolist())) == [(0, 1), (0, 2), (1, 3)]
    check_both_modes(points, np.array([(0, 3), (3, 2)]))


@budget(10)
@given(st.integers(0, 2 ** 32 - 1))
def test_a_long_self_crossing_loop_fills_by_even_odd(seed):
    """80 random chords through 200 random points: hundreds of rounded crossings, some close to each other."""
    rng = np.random.default_rng(seed)
    points = rng.random((200, 2))
    loop = rng.integers(0, len(points), 80)
    check_both_modes(points, np.stack([loop, np.roll(loop, -1)], axis=1))


@budget(300)
@given(closed_curves())
def test_closed_curves_fill_by_even_odd(case):
    check_both_modes(*case)


@budget(150)
@given(nested_rectangles())
def test_polygons_with_holes_and_islands_have_the_even_odd_area(case):
    points, segments, area = case
    _, inside = check_both_modes(points, segments)
    assert math.fsum(triangle_areas(inside.vertices, inside.triangles)) == area


@budget(150)
@given(st.lists(st.tuples(GRID, GRID), min_size=1, max_size=30))
def test_unconstrained_grid_points_are_delaunay(raw):
    points = np.array(raw, np.float64)
    check_triangulation(triangulate(points, mode="all"), points, mode="all")


@budget(150)
@given(st.tuples(GRID, GRID), st.tuples(st.integers(-3, 3), st.integers(-3, 3)),
       st.lists(st.integers(-6, 6), min_size=1, max_size=12), st.data())
def test_all_collinear_input_gives_no_triangles(origin, step, offsets, data):
    points = np.array([(origin[0] + t * step[0], origin[1] + t * step[1]) for t in offsets], np.float64)
    index = st.integers(0, len(points) - 1)
    segments = np.array(data.draw(st.lists(st.tuples(index, index), max_size=5)), np.int64).reshape(-1, 2)
    for mode in ("all", "inside") if len(segments) else ("all",):
        tri = triangulate(points, segments, mode=mode)
        assert len(tri.triangles) == 0
        check_triangulation(tri, points, segments, mode=mode)


@budget(150)
@given(messy_inputs(), st.integers(-40, 40))
def test_scaling_by_a_power_of_two_changes_nothing(case, exponent):
    points, segments = case
    base = triangulate(points, segments, mode="all")
    scaled = triangulate(np.ldexp(points, exponent), segments, mode="all")
    assert index_triples(scaled.triangles) == index_triples(base.triangles)
    np.testing.assert_allclose(np.ldexp(base.vertices, exponent), scaled.vertices, rtol=1e-12, atol=0)
    assert np.array_equal(scaled.segments, base.segments)


@budget(100)
@given(nested_rectangles(), st.tuples(st.integers(-10 ** 6, 10 ** 6), st.integers(-10 ** 6, 10 ** 6)))
def test_translation_by_integers_changes_nothing_but_cocircular_ties(case, shift):
    """Rectangles do not cross, so no Steiner point rounds differently: only exactly cocircular quads may be
    triangulated the other way, as any valid Delaunay choice is accepted there."""
    points, segments, _ = case
    for mode in ("all", "inside"):
        base = triangulate(points, segments, mode=mode)
        moved = triangulate(points + shift, segments, mode=mode)
        assert moved.steiner_count == base.steiner_count == 0
        assert np.array_equal(moved.segments, base.segments)
        assert_same_up_to_cocircular(base, moved, [tuple(sorted(t)) for t in base.triangles.tolist()],
                                     [tuple(sorted(t)) for t in moved.triangles.tolist()])


def _nudged(values, ulps):
    """Each nonzero value moved by one ulp in the direction of ``ulps`` (zero would become subnormal)."""
    return np.array([np.nextafter(v, math.copysign(math.inf, u)) if u and v else v for v, u in zip(values, ulps)])


@budget(400)
@given(st.tuples(FINITE, FINITE), st.tuples(FINITE, FINITE), st.floats(-2, 2, allow_nan=False),
       st.lists(st.integers(-1, 1), min_size=2, max_size=2))
def test_orient2d_is_exact(a, b, t, ulps):
    c = _nudged([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], ulps)
    assert orient2d(a, b, c) == orient_signs(a, b, c)
    assert orient2d(b, a, c) == -orient_signs(a, b, c)


PYTHAGOREAN = [(5, 0), (4, 3), (3, 4), (0, 5), (-3, 4), (-4, 3), (-5, 0), (-4, -3), (-3, -4), (0, -5), (3, -4), (4, -3)]


@budget(400)
@given(st.permutations(PYTHAGOREAN), st.tuples(FINITE, FINITE), st.integers(-30, 30),
       st.lists(st.integers(-1, 1), min_size=2, max_size=2))
def test_incircle_is_exact(circle, center, exponent, ulps):
    """Four points of one integer circle, scaled by a power of two (exactly cocircular) and moved to ``center``
    (cocircular up to rounding), the last nudged by an ulp: the hardest in-circle signs."""
    a, b, c, d = (np.ldexp(np.array(p, np.float64), exponent) + center for p in circle[:4])
    if orient_signs(a, b, c) < 0:
        a, b = b, a
    d = _nudged(d, ulps)
    assert incircle(a, b, c, d) == incircle_signs(a, b, c, d)


def _flip_first_interior_edge(tri):
    t, k = np.argwhere((tri.neighbors >= 0) & ~tri.constrained)[0]
    n = tri.neighbors[t, k]
    a, b, c = np.roll(tri.triangles[t], -k)
    d = next(v for v in tri.triangles[n] if v not in (b, c))
    triangles = tri.triangles.copy()
    triangles[t], triangles[n] = (a, b, d), (a, d, c)
    return dataclasses.replace(tri, triangles=triangles)


def test_checks_reject_broken_triangulations():
    """The validity checks are not vacuous: each catches its kind of damage."""
    rng = np.random.default_rng(7)
    points = rng.random((40, 2))
    tri = triangulate(points, mode="all")
    with pytest.raises(AssertionError, match="in-circle"):
        check_delaunay(_flip_first_interior_edge(tri))
    with pytest.raises(AssertionError, match="CCW"):
        check_orientation(dataclasses.replace(tri, triangles=tri.triangles[:, ::-1].copy()))
    with pytest.raises(AssertionError, match="neighbors"):
        check_neighbors(dataclasses.replace(tri, neighbors=np.roll(tri.neighbors, 1, axis=1)))
    with pytest.raises(AssertionError, match="convex hull"):
        check_convex_hull(dataclasses.replace(tri, triangles=tri.triangles[1:]))
    with pytest.raises(AssertionError, match="vertex_map"):
        check_vertex_map(dataclasses.replace(tri, vertex_map=np.zeros_like(tri.vertex_map)), points)
    square = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float64)
    diagonal = triangulate(square, [(0, 2)], mode="all")
    with pytest.raises(AssertionError, match="not a chain"):
        check_triangulation(diagonal, square, [(1, 3)], mode="all")


@budget(80)
@given(st.integers(0, 2 ** 32 - 1), st.integers(3, 2000))
def test_matches_triangle_on_random_points(seed, n):
    points = np.random.default_rng(seed).random((n, 2))
    ours = triangulate(points, mode="all")
    assert index_triples(ours.triangles) == index_triples(triangle.triangulate({"vertices": points}, "Q")["triangles"])


def inside_rings(xy, rings):
    """Even-odd point-in-polygon by a ray to +x (float; fine for random points off the boundary)."""
    inside = np.zeros(len(xy), bool)
    for ring in rings:
        for a, b in zip(ring, np.roll(ring, -1, axis=0)):
            straddles = (a[1] > xy[:, 1]) != (b[1] > xy[:, 1])
            with np.errstate(all="ignore"):
                cross_x = a[0] + (xy[:, 1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            inside ^= straddles & (cross_x > xy[:, 0])
    return inside


def random_star(rng, m, r_low, r_high):
    """A simple polygon around the origin: m vertices at jittered, evenly spread angles (every gap under 1.8 of the
    mean, so the origin is inside) and random radii."""
    angles = 2 * np.pi * (np.arange(m) + 0.8 * rng.random(m)) / m
    radii = r_low + (r_high - r_low) * rng.random(m)
    return np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)


@budget(80)
@given(st.integers(0, 2 ** 32 - 1), st.integers(8, 200), st.integers(0, 400), st.booleans())
def test_matches_triangle_on_random_polygons(seed, m, n_inner, with_hole):
    """A random polygon (optionally with a polygonal hole around the origin) and random points inside it. With at
    least 8 outer vertices the outer ring contains the disc of radius 0.38, so the hole (radii <= 0.3) fits."""
    rng = np.random.default_rng(seed)
    rings = [random_star(rng, m, 0.5, 1.0)] + ([random_star(rng, max(4, m // 2), 0.1, 0.3)] if with_hole else [])
    boundary = np.concatenate(rings)
    starts = np.cumsum([0] + [len(r) for r in rings])
    segments = np.concatenate([np.stack([np.arange(s, e), np.r_[s + 1:e, s]], axis=1)
                               for s, e in zip(starts[:-1], starts[1:])])
    candidates = rng.uniform(-1, 1, (n_inner, 2))
    points = np.concatenate([boundary, candidates[inside_rings(candidates, rings)]])
    holes = np.zeros((1, 2)) if with_hole else np.zeros((0, 2))
    spec = {"vertices": points, "segments": segments} | ({"holes": holes} if with_hole else {})
    for mode, switches in (("inside", "pQ"), ("all", "pcQ")):
        reference = triangle.triangulate(spec, switches)
        assert len(reference["vertices"]) == len(points)
        ours = triangulate(points, segments, mode=mode, holes=holes if mode == "all" else None)
        assert index_triples(ours.triangles) == index_triples(reference["triangles"]), mode
