"""rigger.cdt input handling: bad input is a clear ValueError; holes, nesting, doubled segments and extreme
coordinate ranges behave as the docstring says."""
import math
import re

import numpy as np
import pytest

from cdt_checks import assert_same_up_to_cocircular, check_even_odd, check_triangulation, triangle_areas
from rigger.cdt import triangulate

SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]
RING = [(0, 1), (1, 2), (2, 3), (3, 0)]


def nested_squares(half_sides):
    """Concentric axis-aligned squares around the origin: (points, segments), four corners and a ring each."""
    points, segments = [], []
    for h in half_sides:
        start = len(points)
        points += [(-h, -h), (h, -h), (h, h), (-h, h)]
        segments += [(start + a, start + b) for a, b in RING]
    return np.array(points, np.float64), np.array(segments, np.int64)


def area(tri):
    """Total area of the kept triangles."""
    return math.fsum(triangle_areas(tri.vertices, tri.triangles))


@pytest.mark.parametrize("bad, fragment", [
    ([(0, 0), (1, np.nan), (0, 1)], "finite; row 1"),
    ([(0, 0), (1, 0), (np.inf, 1)], "finite; row 2"),
    ([(0, 0), (1, 0), (0, -np.inf)], "finite"),
    ([0.0, 1.0, 2.0], "shape (N, 2)"),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0)], "shape (N, 2)"),
    ([[(0, 0)], [(1, 1)]], "shape (N, 2)"),
    ([("a", "b"), ("c", "d")], "numeric"),
    ([(0, 0), (1, 0), (0, {})], "numeric"),
])
def test_bad_points_raise_a_clear_value_error(bad, fragment):
    with pytest.raises(ValueError, match=re.escape(fragment)):
        triangulate(bad, mode="all")


@pytest.mark.parametrize("bad, fragment", [
    ([(0, 1.5)], "integer point indices"),
    ([(0, np.nan)], "integer point indices"),
    ([("0", "1")], "integer point indices"),
    ([(0, -1)], r"segment 0 \[0, -1\] indexes outside the 4 points"),
    ([(0, 1), (2, 4)], r"segment 1 \[2, 4\] indexes outside the 4 points"),
    ([(0, 1, 2)], r"shape \(M, 2\)"),
    ([0, 1], r"shape \(M, 2\)"),
])
def test_bad_segments_raise_a_clear_value_error(bad, fragment):
    for mode in ("all", "inside"):
        with pytest.raises(ValueError, match=fragment):
            triangulate(SQUARE, bad, mode=mode)


def test_bad_holes_raise_a_clear_value_error():
    with pytest.raises(ValueError, match="holes must be finite"):
        triangulate(SQUARE, RING, holes=[(0.5, np.nan)])
    with pytest.raises(ValueError, match=r"holes must have shape \(N, 2\)"):
        triangulate(SQUARE, RING, holes=[0.5, 0.5, 0.5])


def test_unknown_mode_and_inside_without_segments_raise():
    with pytest.raises(ValueError, match="mode must be one of"):
        triangulate(SQUARE, RING, mode="outside")
    for segments in (None, [], np.zeros((0, 2), np.int64)):
        with pytest.raises(ValueError, match="needs constraint segments"):
            triangulate(SQUARE, segments, mode="inside")


def test_integral_float_indices_are_accepted():
    tri = triangulate(SQUARE, np.array(RING, np.float64))
    assert np.array_equal(tri.segments, [(0, 1), (0, 3), (1, 2), (2, 3)])
    assert len(tri.triangles) == 2


@pytest.mark.parametrize("points", [[], np.zeros((0, 2)), [(1, 2)], [(1, 2), (3, 4)], [(1, 2), (1, 2), (1, 2)]])
def test_fewer_than_three_distinct_points_give_no_triangles(points):
    """The docstring's rule for tiny input: zero triangles with well-formed arrays, not an error."""
    tri = triangulate(points, mode="all")
    check_triangulation(tri, np.asarray(points, np.float64).reshape(-1, 2), mode="all")
    assert tri.triangles.shape == (0, 3) and tri.vertex_map.shape == (len(points),)


def test_holes_outside_the_triangulation_are_ignored():
    plain = triangulate(SQUARE, RING)
    for mode in ("all", "inside"):
        seeded = triangulate(SQUARE, RING, mode=mode, holes=[(5, 5), (-1, 0.5), (1e300, -1e300)])
        assert np.array_equal(seeded.triangles, plain.triangles)


@pytest.mark.parametrize("mode", ["all", "inside"])
def test_a_hole_seed_removes_exactly_the_enclosed_region(mode):
    points, segments = nested_squares([3, 1])
    points = np.concatenate([points, [(0.25, 0.5), (2, 2.5), (-2, 0)]])
    tri = triangulate(points, segments, mode=mode, holes=[(0.1, -0.2)])
    check_triangulation(tri, points, segments, mode=mode, holes=[(0.1, -0.2)])
    assert area(tri) == 36 - 4
    centroids = tri.vertices[tri.triangles].mean(axis=1)
    assert (np.abs(centroids).max(axis=1) > 1).all(), "a triangle inside the seeded square survived"
    ring_seeded = triangulate(points, segments, mode=mode, holes=[(2.5, 2.5)])
    assert area(ring_seeded) == (4 if mode == "all" else 0), "a seed between the squares removes the ring only"


def test_a_seed_inside_an_island_removes_only_the_island():
    points, segments = nested_squares([3, 2, 1])
    tri = triangulate(points, segments, mode="all", holes=[(0, 0)])
    assert area(tri) == 36 - 4


def test_inside_uses_even_odd_for_nested_squares():
    """Square in square in square: the outer ring and the innermost square are in, the middle ring is a hole."""
    points, segments = nested_squares([3, 2, 1])
    inside = triangulate(points, segments)
    everything = triangulate(points, segments, mode="all")
    check_triangulation(inside, points, segments, mode="inside")
    check_even_odd(inside, everything, points, segments)
    assert area(inside) == (36 - 16) + 4


def test_a_segment_given_twice_cancels():
    """The middle square given twice no longer bounds anything: the outer square minus the inner one is in."""
    points, segments = nested_squares([3, 2, 1])
    doubled = np.concatenate([segments, segments[4:8][:, ::-1]])
    inside = triangulate(points, doubled)
    check_triangulation(inside, points, doubled, mode="inside")
    check_even_odd(inside, triangulate(points, doubled, mode="all"), points, doubled)
    assert area(inside) == 36 - 4
    assert np.array_equal(inside.segments, triangulate(points, segments).segments)


def test_several_disjoint_polygons_with_holes():
    first, first_segments = nested_squares([3, 1])
    second, second_segments = nested_squares([2])
    points = np.concatenate([first, second + (10, 0)])
    segments = np.concatenate([first_segments, second_segments + len(first)])
    inside = triangulate(points, segments)
    check_triangulation(inside, points, segments, mode="inside")
    assert area(inside) == (36 - 4) + 16


@pytest.mark.parametrize("offset", [1e6, 1e12, -3e12])
def test_large_offsets_stay_valid(offset):
    rng = np.random.default_rng(5)
    points, segments = nested_squares([3, 2, 1])
    points = np.concatenate([points, rng.uniform(-3, 3, (200, 2))]) + (offset, -offset / 2)
    for mode in ("all", "inside"):
        tri = triangulate(points, segments, mode=mode)
        check_triangulation(tri, points, segments, mode=mode)


@pytest.mark.parametrize("scale", [1e-12, 3e-15, 1e12])
def test_tiny_and_huge_scales_stay_valid(scale):
    rng = np.random.default_rng(6)
    points, segments = nested_squares([3, 2, 1])
    points = np.concatenate([points, [(i, j) for i in range(-2, 3) for j in (-2, 2)], rng.uniform(-3, 3, (200, 2))])
    # A self-crossing hourglass over the middle square (two edges shared with it) and a triangle through random
    # points: exact and rounded crossings, overlaps, points on segments, all on closed curves.
    crossing = np.array([(4, 6), (6, 5), (5, 7), (7, 4), (22, 23), (23, 24), (24, 22)])
    segments = np.concatenate([segments, crossing])
    everything = triangulate(points * scale, segments, mode="all")
    check_triangulation(everything, points * scale, segments, mode="all")
    inside = triangulate(points * scale, segments)
    check_triangulation(inside, points * scale, segments, mode="inside")
    check_even_odd(inside, everything, points * scale, segments)


def test_many_duplicates_of_the_same_point():
    points = np.array([(0, 0)] * 50 + [(1, 0)] * 50 + [(0, 1)] * 50, np.float64)
    segments = [(0, 50), (51, 100), (101, 1), (2, 2)]
    tri = triangulate(points, segments)
    check_triangulation(tri, points, segments, mode="inside")
    assert tri.triangles.tolist() in ([[0, 50, 100]], [[50, 100, 0]], [[100, 0, 50]])
    assert set(tri.vertex_map.tolist()) == {0, 50, 100}


def test_negative_zero_is_the_same_point():
    points = [(0.0, 0.0), (1, 0), (0, 1), (-0.0, -0.0), (0.0, -0.0)]
    tri = triangulate(points, mode="all")
    check_triangulation(tri, points, mode="all")
    assert tri.vertex_map.tolist() == [0, 1, 2, 0, 0]


def corner_keys(tri):
    """Each triangle as the sorted coordinates of its corners (indices of Steiner vertices differ with the input)."""
    return [tuple(sorted(map(tuple, corners))) for corners in tri.vertices[tri.triangles].tolist()]


def test_a_large_input_triangulates_as_its_distinct_points_do():
    """Large inputs are renumbered in insertion order for memory locality (the compiled module does so from 16384
    points), small ones are not: messy input (duplicates, collinear runs, crossing and overlapping segments) and the
    same points repeated until it is large meet the full contract, and the repeats change nothing."""
    rng = np.random.default_rng(11)
    points = rng.integers(0, 12, (300, 2)).astype(float) * 0.1 + 5.0
    segments = rng.integers(0, 300, (40, 2))
    repeated = np.tile(points, (100, 1))  # 30,000 points, every one a duplicate of the first 300
    for mode in ("all", "inside"):
        small, large = (triangulate(given, segments, mode=mode) for given in (points, repeated))
        check_triangulation(small, points, segments, mode=mode)
        check_triangulation(large, repeated, segments, mode=mode)
        np.testing.assert_array_equal(large.vertex_map, np.tile(small.vertex_map, 100))
        assert_same_up_to_cocircular(small, large, *(corner_keys(tri) for tri in (small, large)))
    reference = triangulate(points, segments, mode="all")
    assert reference.vertex_map.tolist() == [int(np.flatnonzero((points == p).all(axis=1))[0]) for p in points]
