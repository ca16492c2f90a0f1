"""rigger.silhouette against exact references.

The outline is compared with the exact union of the projected triangles computed by shapely (area IoU, islands and
holes, loop validity) on generated shapes, random soups and the real models in ../shared/models; depth() and
layers() are compared with brute-force ray casting.

Memory checks, run once outside this suite on the final C code (2026-11-21):
- a standalone C driver calling sil_trace / sil_depth / sil_layers on seven meshes (generated shapes, a Quaternius
  model, cheburashka) in four directions at resolutions 64, 300 and 1024 (tolerances 0, 1 and 0.05), 400 random
  soups half on an integer lattice (exact degeneracies, cell refinement, pinch points) and every error code:
  valgrind memcheck 0 errors, "All heap blocks were freed"; the same driver built with
  -fsanitize=address,undefined (LeakSanitizer included): clean.
- ``PYTHONMALLOC=malloc valgrind --leak-check=full .venv/bin/python -m pytest tests/test_silhouette.py -k
  "generated or layers or bad_input or touching or depth_is_nan or frame"``: 30 passed; no error or leak record has
  a frame in rigger._rigger_silhouette (the records left are CPython's and numpy's own).
"""
import functools

import numpy as np
import pytest
import shapely
from conftest import SHARED, shared_path
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from rigger import silhouette

from meshes import box, combine, far_apart_cubes, grid_surface, uv_sphere
from rigdata import load_obj
from union_reference import exact_union, frame_points, iou, traced_region

MIN_IOU = 0.995
BIG_FEATURE = 8  # islands and holes above this many square cells must match
TOUCH = 0.01  # cells: parts meeting closer than this may merge or split

# ------------------------------------------------------------------------------------------------ meshes


def torus(major=1.0, minor=0.3, center=(0, 0, 0), n=48):
    def point(s, t):
        a, b = 2 * np.pi * s, 2 * np.pi * t
        return np.add(center, [(major + minor * np.cos(b)) * np.cos(a), (major + minor * np.cos(b)) * np.sin(a),
                               minor * np.sin(b)])
    return grid_surface(point, n, n // 2)


def sphere(center=(0, 0, 0), radius=1.0, n=24):
    """A closed UV sphere: n - 1 rings of n vertices between two poles."""
    vertices, triangles = uv_sphere(rings=n, segments=n)
    return np.add(center, radius * vertices), triangles


def prism(polygon, depth=0.2):
    """A star-shaped polygon (fanned from its first point's centroid) extruded along z."""
    polygon = np.asarray(polygon, float)
    n = len(polygon)
    centre = polygon.mean(axis=0)
    ring = np.concatenate([np.c_[polygon, np.zeros(n)], np.c_[polygon, np.full(n, depth)]])
    v = np.concatenate([ring, [[*centre, 0.0], [*centre, depth]]])
    t = []
    for i in range(n):
        j = (i + 1) % n
        t += [[2 * n, j, i], [2 * n + 1, n + i, n + j], [i, j, n + j], [i, n + j, n + i]]
    return v, np.array(t)


def star(points=7, inner=0.35, outer=1.0):
    angles = np.arange(2 * points) * np.pi / points
    radii = np.where(np.arange(2 * points) % 2 == 0, outer, inner)
    return prism(np.c_[radii * np.cos(angles), radii * np.sin(angles)])


GLYPHS = {  # 5 x 7 pixel letters; strokes of A, B, O, R and X meet at pixel corners only, 0 and 8 are solid
    "A": [" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"],
    "B": ["#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### "],
    "O": [" ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "],
    "R": ["#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"],
    "X": ["#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #"],
    "0": ["#####", "#   #", "#   #", "#   #", "#   #", "#   #", "#####"],
    "8": ["#####", "#   #", "#   #", "#####", "#   #", "#   #", "#####"],
}


def word(text):
    """Pixel letters as unit cubes: shared faces, coincident edges and diagonal pixels touching at corners."""
    cubes = []
    for k, letter in enumerate(text):
        for row, line in enumerate(GLYPHS[letter]):
            for col, pixel in enumerate(line):
                if pixel == "#":
                    x, y = 6 * k + col, 6 - row
                    cubes.append(box((x, y, 0), (x + 1, y + 1, 1)))
    return combine(*cubes)


def figure_with_hole():
    """A body with a hand on the hip: upper arm and forearm close a hole against the torso. Overlapping parts share
    no vertices, so each is a closed part of its own."""
    return combine(
        box((-0.5, -0.3, 0.0), (0.5, 0.3, 1.6)),       # torso
        sphere((0, 0, 1.9), 0.35),                       # head, resting on the torso
        box((0.5, -0.15, 1.3), (1.3, 0.15, 1.55)),       # upper arm, out from the shoulder
        box((1.05, -0.14, 0.65), (1.29, 0.14, 1.5)),     # forearm down
        box((0.3, -0.15, 0.6), (1.3, 0.15, 0.85)),       # hand back onto the hip
        box((-1.6, -0.15, 1.3), (-0.5, 0.15, 1.5)),      # the other arm, straight out
        box((-0.45, -0.2, -1.5), (-0.1, 0.2, 0.0)),      # legs
        box((0.1, -0.2, -1.5), (0.45, 0.2, 0.0)))


def hand(gap):
    """A palm with five fingers `gap` apart (in units where the hand is 3 tall)."""
    width = 0.3
    parts = [box((0, 0, 0), (5 * width + 4 * gap, 0.2, 1.5))]
    for k in range(5):
        x = k * (width + gap)
        parts.append(box((x, 0.02, 1.5), (x + width, 0.18, 3.0 - 0.2 * abs(k - 2))))
    return combine(*parts)


def scene(seed=3):
    """Spheres, boxes and a torus scattered so that some overlap and some stand alone."""
    rng = np.random.default_rng(seed)
    parts = [torus(center=(4, 4, 0))]
    for _ in range(6):
        c = rng.uniform(-3, 3, 3)
        parts.append(sphere(c, rng.uniform(0.3, 0.9), n=16))
        parts.append(box(c + 1.2, c + 1.2 + rng.uniform(0.2, 1.0, 3)))
    return combine(*parts)


GENERATED = {
    "torus": (torus(), ["Z", "Y", (1, 2, 3)]),
    "letters": (word("ABORX"), ["Z", "-Z", (0.3, -0.2, 1.0)]),
    "star": (star(), ["Z", (0.4, 0.1, 1.0)]),
    "scene": (scene(), ["X", "Y", "Z", (1, -1, 1)]),
    "figure with a hole": (figure_with_hole(), ["Y", "-Y", (0.2, 1.0, 0.1)]),
}


def real_models():
    """Model paths relative to ../shared/models, small enough for the exact reference to stay quick."""
    folder = SHARED / "models"
    if not folder.is_dir():
        return ["(absent)"]
    paths = sorted(folder.glob("gt/*/*.obj")) + sorted(folder.glob("nogt/*.obj"))
    return [str(p.relative_to(folder)) for p in paths
            if "_remesh" not in p.name and p.stat().st_size < 1_500_000]


@functools.cache
def real_model(relative):
    return load_obj(shared_path("models", relative))


# ------------------------------------------------------------------------------------------------ references


def features(geom):
    """(kind, region, ring) of every island (its filled region) and hole."""
    out = []
    for poly in getattr(geom, "geoms", [geom]):
        if poly.geom_type != "Polygon" or poly.is_empty:
            continue
        out.append(("island", poly, poly.exterior))
        out += [("hole", shapely.Polygon(r), shapely.LinearRing(r)) for r in poly.interiors]
    return out


def topology_errors(traced, exact, cell):
    """Islands and holes above BIG_FEATURE square cells that one side has and the other lacks.

    Where parts meet within TOUCH cells they may merge or split (both are right for parts touching at a point): a
    reference feature whose ring comes that close to another ring need not be matched, and a traced feature may match
    the reference dilated by TOUCH.
    """
    big, near = BIG_FEATURE * cell**2, TOUCH * cell
    ours, theirs = features(traced), features(exact)
    rings = [ring for _, _, ring in theirs]
    tree = shapely.STRtree(rings)
    ours_by_kind = {kind: shapely.union_all([r for k, r, _ in ours if k == kind]) for kind in ("island", "hole")}
    errors = []
    for i, (kind, region, ring) in enumerate(theirs):
        if region.area <= big:
            continue
        pinched = any(j != i and shapely.dwithin(ring, rings[j], near) for j in tree.query(ring.buffer(cell)))
        if not pinched and region.intersection(ours_by_kind[kind]).area <= 0.5 * region.area:
            errors.append(("missing", kind, round(region.area / cell**2, 1)))
    closed = features(exact.buffer(near))
    for kind in ("island", "hole"):
        reference = shapely.union_all([r for k, r, _ in theirs + closed if k == kind])
        for k, region, _ in ours:
            if k == kind and region.area > big and region.intersection(reference).area < 0.5 * region.area:
                errors.append(("extra", kind, round(region.area / cell**2, 1)))
    return errors


def assert_valid_loops(loops):
    """Closed float64 loops that are simple, never touch one another, and run counter-clockwise exactly when they are
    nested an even number of times (outer boundaries) and clockwise otherwise (holes)."""
    for loop in loops:
        assert loop.dtype == np.float64 and loop.ndim == 2 and loop.shape[1] == 2 and len(loop) >= 3
        assert np.isfinite(loop).all()
    if not loops:
        return
    assert shapely.MultiLineString([np.vstack([loop, loop[:1]]) for loop in loops]).is_simple
    polygons = [shapely.Polygon(loop) for loop in loops]
    tree = shapely.STRtree(polygons)
    for i, (loop, polygon) in enumerate(zip(loops, polygons)):
        start = shapely.Point(loop[0])
        depth = sum(1 for j in tree.query(start) if j != i and polygons[j].contains(start))
        assert polygon.exterior.is_ccw == (depth % 2 == 0)


def check_against_union(vertices, triangles, direction, **options):
    sil = silhouette.trace(vertices, triangles, direction, **options)
    assert_valid_loops(sil.loops)
    exact = exact_union(sil, vertices, triangles)
    traced = traced_region(sil.loops)
    return sil, iou(traced, exact), topology_errors(traced, exact, sil.cell)


# ------------------------------------------------------------------------------------------------ outline


@pytest.mark.parametrize("name,direction", [(n, d) for n, (_, ds) in GENERATED.items() for d in ds])
def test_generated_shapes_match_the_exact_union(name, direction):
    (vertices, triangles), _ = GENERATED[name]
    sil, overlap, errors = check_against_union(vertices, triangles, direction)
    assert overlap >= MIN_IOU
    assert errors == []


def test_expected_islands_and_holes():
    """Counts on shapes whose topology is known by construction."""
    def counts(vertices, triangles, direction):
        loops = silhouette.trace(vertices, triangles, direction).loops
        ccw = [shapely.LinearRing(loop).is_ccw for loop in loops]
        return sum(ccw), len(ccw) - sum(ccw)

    assert counts(*torus(), "Z") == (1, 1)
    assert counts(*torus(), "X") == (1, 0)
    assert counts(*figure_with_hole(), "Y") == (1, 1)
    assert counts(*figure_with_hole(), "X") == (1, 0)
    assert counts(*word("8"), "Z") == (1, 2)
    assert counts(*word("080"), "Z") == (3, 4)
    assert counts(*combine(sphere((0, 0, 0)), sphere((3, 0, 0)), sphere((6, 0, 0))), "Y") == (3, 0)


@pytest.mark.parametrize("gap", [0.004, 0.01])
def test_fingers_stay_separate_lobes(gap):
    """Gaps of 1.4 and 3.4 default cells between fingers: a line across the fingers meets five separate pieces."""
    vertices, triangles = hand(gap)
    sil = silhouette.trace(vertices, triangles, "Y")
    region = traced_region(sil.loops)
    height = frame_points(sil, [[0, 0, 2.2]])[0, 1]
    across = shapely.LineString([(-10, height), (10, height)]).intersection(region)
    assert len(getattr(across, "geoms", [across])) == 5


def test_loops_feed_the_triangulation():
    cdt = pytest.importorskip("rigger.cdt")
    vertices, triangles = figure_with_hole()
    sil = silhouette.trace(vertices, triangles, "Y")
    points = np.concatenate(sil.loops)
    ends = np.cumsum([len(loop) for loop in sil.loops])
    starts = ends - [len(loop) for loop in sil.loops]
    segments = np.concatenate([np.c_[np.arange(s, e), np.r_[np.arange(s + 1, e), s]] for s, e in zip(starts, ends)])
    tri = cdt.triangulate(points, segments, mode="inside")
    corners = tri.vertices[tri.triangles]
    area = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]).sum()
    assert area == pytest.approx(traced_region(sil.loops).area, rel=1e-9)
    assert tri.steiner_count == 0


@pytest.mark.parametrize("direction", ["Y", "X"])
@pytest.mark.parametrize("relative", real_models())
def test_real_models_match_the_exact_union(relative, direction):
    vertices, triangles = real_model(relative)
    try:
        sil, overlap, errors = check_against_union(vertices, triangles, direction)
    except ValueError as error:  # the flat models (woody, alligator) have no silhouette from the side
        assert "zero area" in str(error)
        assert np.ptp(vertices, axis=0).min() == 0
        return
    assert overlap >= MIN_IOU
    assert errors == []


@pytest.mark.parametrize("resolution,tolerance", [(64, 0.0), (256, 0.05), (2048, 0.05), (1024, 1.0)])
def test_resolution_and_tolerance(resolution, tolerance):
    vertices, triangles = figure_with_hole()
    sil, overlap, errors = check_against_union(vertices, triangles, "Y", resolution=resolution, tolerance=tolerance)
    assert sil.cell == pytest.approx((np.ptp(frame_points(sil, vertices), axis=0).max()) / resolution)
    assert overlap >= (0.99 if resolution <= 64 or tolerance == 1.0 else MIN_IOU)
    assert errors == []


def test_simplification_keeps_the_outline_within_tolerance():
    vertices, triangles = torus()
    full = silhouette.trace(vertices, triangles, (1, 2, 3), tolerance=0)
    simple = silhouette.trace(vertices, triangles, (1, 2, 3), tolerance=1)
    assert sum(map(len, simple.loops)) < sum(map(len, full.loops)) / 5
    traced = shapely.MultiLineString([np.vstack([loop, loop[:1]]) for loop in simple.loops])
    assert max(traced.distance(shapely.Point(p)) for loop in full.loops for p in loop) <= full.cell * 1.000001


def test_every_kind_of_soup():
    """Duplicate and flipped faces, degenerate faces, inner shells, open patches and non-manifold fans."""
    v, t = combine(box((0, 0, 0), (2, 2, 2)), box((0.5, 0.5, 0.5), (1, 1, 1)), sphere((3, 1, 1), 0.8))
    degenerate = [[0, 0, 1], [2, 2, 2], [5, 1, 5]]  # repeated corners
    fan = [[0, 3, 20], [0, 3, 30], [0, 3, 40]]  # one edge shared by five faces
    soup = np.concatenate([t, t[:5], t[:, ::-1][5:9], degenerate, fan])
    sil, overlap, errors = check_against_union(v, soup, (0.3, 1.0, 0.2))
    assert overlap >= MIN_IOU and errors == []


coordinates = st.one_of(st.integers(-3, 3).map(float), st.floats(-1, 1, allow_nan=False, width=32))


@settings(max_examples=120)
@given(st.lists(st.tuples(coordinates, coordinates, coordinates), min_size=3, max_size=30),
       st.sampled_from(["X", "Y", "Z", (0.3, 0.5, 0.8)]), st.sampled_from([16, 33, 256]))
def test_random_soups(points, direction, resolution):
    """Any soup traces to valid loops whose area error is bounded by its vertices' share of the cells."""
    vertices = np.array(points, float)[: len(points) // 3 * 3]
    triangles = np.arange(len(vertices)).reshape(-1, 3)
    try:
        sil = silhouette.trace(vertices, triangles, direction, resolution=resolution, tolerance=0)
    except ValueError as error:
        assert "zero area" in str(error)
        return
    assert_valid_loops(sil.loops)
    exact = exact_union(sil, vertices, triangles)
    traced = traced_region(sil.loops)
    corners = len(shapely.get_coordinates(exact))
    assert shapely.symmetric_difference(traced, exact).area <= sil.cell**2 * (corners + 4)
    assert topology_errors(traced, exact, sil.cell) == []


def test_touching_parts_give_strictly_simple_loops():
    """Squares meeting at corners and along edges, a checkerboard with every corner a pinch point."""
    cells = [(0, 0), (1, 1), (2, 0), (2, 2), (0, 2), (1, 0), (3, 1), (3, 3)]
    vertices, triangles = combine(*[box((x, y, 0), (x + 1, y + 1, 1)) for x, y in cells])
    for resolution in (8, 64, 256, 1024):
        sil = silhouette.trace(vertices, triangles, "Z", resolution=resolution)
        assert_valid_loops(sil.loops)
        assert traced_region(sil.loops).area == pytest.approx(8.0, rel=4.0 / resolution)


# ------------------------------------------------------------------------------------------------ frame


def test_frame_for_the_axes():
    vertices, triangles = box((0, 0, 0), (1, 2, 3))
    expected = {"Y": ([1, 0, 0], [0, 0, 1]), "X": ([0, -1, 0], [0, 0, 1]), "-Z": ([1, 0, 0], [0, 1, 0])}
    for name, (u, v) in expected.items():
        sil = silhouette.trace(vertices, triangles, name)
        assert np.allclose(sil.u, u) and np.allclose(sil.v, v)
        assert np.allclose(np.cross(sil.u, sil.v), -sil.direction)
    assert np.allclose(silhouette.trace(vertices, triangles, "x").direction, [1, 0, 0])


@pytest.mark.parametrize("direction", [(1, 2, 3), (0, 0, 5), (-1e-30, 0, 1e-30), (0.001, -0.001, -1)])
def test_frame_is_orthonormal_and_points_lift_back(direction):
    vertices, triangles = torus()
    sil = silhouette.trace(vertices, triangles, direction)
    basis = np.array([sil.u, sil.v, sil.direction])
    assert np.allclose(basis @ basis.T, np.eye(3))
    assert np.allclose(sil.direction, np.array(direction) / np.linalg.norm(direction))
    depth = (vertices - sil.origin) @ sil.direction
    assert np.allclose(sil.lift(frame_points(sil, vertices), depth), vertices)
    frame, depth_again = sil.project(vertices)
    assert np.allclose(sil.lift(frame, depth_again), vertices)


def test_encloses_is_the_hull_seen_along_the_view():
    """Within the silhouette and between the nearest and farthest surface: a gap across the view is outside, a gap
    along it (between two boxes one behind the other) is not; so is an open sheet's own plane, given slack."""
    near, far = box((0, 0, 0), (1, 1, 1)), box((0, 3, 0), (1, 4, 1))
    beside = box((2, 0, 0), (3, 1, 1))
    sil = silhouette.trace(*combine(near, far, beside), "Y")
    points = [[0.5, 0.5, 0.5], [0.5, 2.0, 0.5], [0.5, 4.5, 0.5], [1.5, 0.5, 0.5], [2.5, 0.5, 0.5]]
    assert sil.encloses(points).tolist() == [True, True, False, False, True]
    square = np.array([[0, 0, 0.3], [1, 0, 0.3], [1, 1, 0.3], [0, 1, 0.3]], float)
    sheet = silhouette.trace(square, [[0, 1, 2], [0, 2, 3]], "Z")
    assert sheet.encloses([[0.5, 0.5, 0.3]], 1e-9).tolist() == [True]
    assert sheet.encloses([[0.5, 0.5, 0.4]], 1e-9).tolist() == [False]


# ------------------------------------------------------------------------------------------------ depth


def brute_force_hits(sil, vertices, triangles, points):
    """Per point, (depth, part) of every triangle the ray hits, sorted by depth, or None where the point lies within
    1e-4 cells of a triangle edge (the tracer snaps points by up to 1e-5 cells). Parts are connected components of
    the mesh with vertices at equal positions welded."""
    triangles = np.asarray(triangles)
    _, weld = np.unique(vertices, axis=0, return_inverse=True)
    edges = weld.ravel()[triangles][:, [0, 1, 1, 2]].reshape(-1, 2)
    graph = csr_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(weld.max() + 1,) * 2)
    part = connected_components(graph, directed=False)[1][weld.ravel()[triangles[:, 0]]]
    corners = frame_points(sil, vertices)[triangles]
    depths = ((vertices - sil.origin) @ sil.direction)[triangles]
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    area = np.cross(b - a, c - a)
    keep = area != 0
    a, b, c, area, depths, part = a[keep], b[keep], c[keep], area[keep], depths[keep], part[keep]
    lengths = np.stack([np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1), np.linalg.norm(b - a, axis=1)], 1)
    margin = 1e-4 * sil.cell * lengths / np.abs(area)[:, None]  # 1e-4 cells as a barycentric weight
    out = []
    for p in points:
        w = np.stack([np.cross(c - b, p - b), np.cross(a - c, p - c), np.cross(b - a, p - a)], axis=1) / area[:, None]
        if ((w > -margin).all(axis=1) & (w < margin).any(axis=1)).any():
            out.append(None)
            continue
        hit = (w > 0).all(axis=1)
        order = np.argsort((w[hit] * depths[hit]).sum(axis=1))
        out.append(np.c_[(w[hit] * depths[hit]).sum(axis=1)[order], part[hit][order]])
    return out


def depth_cases():
    yield "torus", *torus(), (1, 2, 3)
    yield "scene", *scene(), "Z"
    yield "figure", *figure_with_hole(), "Y"
    if (SHARED / "models").is_dir():
        for name in ("nogt/spot.obj", "gt/Quaternius_Fox/Quaternius_Fox.obj"):
            if (SHARED / "models" / name).exists():
                yield name, *real_model(name), "X"


@pytest.mark.parametrize("case", list(depth_cases()), ids=lambda c: c[0])
def test_depth_matches_ray_casting(case):
    _, vertices, triangles, direction = case
    sil = silhouette.trace(vertices, triangles, direction)
    rng = np.random.default_rng(7)
    lo, hi = frame_points(sil, vertices).min(axis=0), frame_points(sil, vertices).max(axis=0)
    points = rng.uniform(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo), (400, 2))
    points = np.concatenate([points, np.concatenate(sil.loops)[::7][:100]])  # and right on the outline
    front, back = sil.depth(points)
    extent = np.ptp(vertices, axis=0).max()
    checked = 0
    for p, f, b, hits in zip(points, front, back, brute_force_hits(sil, vertices, triangles, points)):
        if hits is None:
            continue
        checked += 1
        if len(hits) == 0:
            assert np.isnan(f) and np.isnan(b)
        else:
            assert f == pytest.approx(hits[0, 0], abs=1e-9 * extent)
            assert b == pytest.approx(hits[-1, 0], abs=1e-9 * extent)
    assert checked > 300


def test_depth_is_nan_outside_and_validates_points():
    sil = silhouette.trace(*box((0, 0, 0), (1, 1, 1)), "Y")
    front, back = sil.depth([[0, 0], [5, 5], [-1e300, 1e300]])
    assert front.tolist()[0] == -0.5 and back.tolist()[0] == 0.5
    assert np.isnan(front[1:]).all() and np.isnan(back[1:]).all()
    assert sil.depth(np.zeros((0, 2)))[0].shape == (0,)
    for bad in ([[np.nan, 0]], [[0, 0, 0]], "points"):
        with pytest.raises(ValueError):
            sil.depth(bad)


# ------------------------------------------------------------------------------------------------ layers


def test_layers_separate_overlapping_parts():
    near, far = box((0, 0, 0), (1, 1, 1)), box((0, 3, 0), (1, 4, 1))
    sil = silhouette.trace(*combine(near, far), "Y")
    assert np.allclose(sil.layers([0, 0])[0], [[-2, -1], [1, 2]])


def test_layers_merge_nested_and_intersecting_parts():
    outer, inner, crossing = box((0, 0, 0), (4, 4, 4)), box((1, 1, 1), (2, 2, 2)), box((1, 3, 1), (2, 6, 2))
    sil = silhouette.trace(*combine(outer, inner, crossing), "Y")
    x, y = frame_points(sil, [[1.5, 0, 1.5]])[0]
    front, back = [(p - sil.origin) @ sil.direction for p in ([0, 0, 0], [0, 6, 0])]
    assert np.allclose(sil.layers([x, y])[0], [[front, back]])


def unwelded(vertices, triangles):
    """The same triangles, each with vertices of its own (as glTF seams leave a mesh)."""
    corners = vertices[triangles].reshape(-1, 3)
    return corners, np.arange(len(corners)).reshape(-1, 3)


def test_layers_weld_split_vertices():
    """A closed box whose faces do not share vertices (as glTF seams leave it) still pairs front with back."""
    sil = silhouette.trace(*unwelded(*box((0, 0, 0), (1, 1, 1))), "Y")
    assert np.allclose(sil.layers([[0.1, 0.2]])[0], [[-0.5, 0.5]])


def test_sealed_joins_pieces_that_abut_along_an_open_seam():
    """A box built of two open pieces whose seam vertices lie a hair apart (as game meshes built of pieces are):
    sealed, a ray through the bottom and the lid sees one solid. A lid lifted by more than the seam gap stays a part
    of its own (each open piece hit once is a zero-thickness layer), and a mesh of one piece comes back as given."""
    v, t = box((0, 0, 0), (1, 1, 1))
    lid = (v[t][:, :, 2] == 1).all(axis=1)
    assert silhouette.sealed(v, t) is v
    for lift in (1e-5, 0.1):
        vertices, triangles = combine((v, t[~lid]), (v + [0, 0, lift], t[lid]))
        sil = silhouette.trace(silhouette.sealed(vertices, triangles), triangles, "Z")
        bottom, top = [(np.array(p) - sil.origin) @ sil.direction for p in ([0, 0, 0], [0, 0, 1 + lift])]
        layers = sil.layers(frame_points(sil, [[0.3, 0.4, 0.0]]))[0]
        if lift < silhouette.SEAM_GAP:
            np.testing.assert_allclose(layers, [[bottom, top]], atol=1e-4)
        else:
            np.testing.assert_allclose(layers, [[bottom, bottom], [top, top]], atol=1e-12)


def test_sealed_seams_are_the_same_however_the_vertices_are_numbered():
    """A seam's vertices a hair apart move onto the middle of their cluster, not onto whichever of them comes first:
    the same mesh with its vertices numbered backwards, or mirrored, seals to the same points (mirrored)."""
    v, t = box((-1, 0, 0), (1, 1, 1))
    lid = (v[t][:, :, 2] == 1).all(axis=1)
    vertices, triangles = combine((v, t[~lid]), (v + [2e-5, 0, 1e-5], t[lid]))
    sealed = silhouette.sealed(vertices, triangles)
    backwards = np.arange(len(vertices))[::-1]
    renumbered = silhouette.sealed(vertices[backwards], np.argsort(backwards)[triangles])
    np.testing.assert_array_equal(renumbered, sealed[backwards])
    mirrored = silhouette.sealed(vertices * [-1, 1, 1], triangles[:, ::-1])
    np.testing.assert_array_equal(mirrored, sealed * [-1, 1, 1])


def test_layers_keep_overlapping_pieces_of_one_part_solid():
    """Two closed, consistently wound shells of one part (sharing a vertex) that overlap: where both enclose the ray
    it is inside, by winding, not outside, by parity; turned inside out, the same."""
    a, b = box((0, 0, 0), (2, 1, 1)), box((1, 0.2, 0.2), (3, 0.8, 0.8))
    b[0][0] = a[0][0]  # one corner of the second shell pulled onto the first's: one part
    vertices, triangles = combine(a, b)
    for winding in (triangles, triangles[:, ::-1]):
        sil = silhouette.trace(vertices, winding, "Z")
        bottom, top = [(np.array(p) - sil.origin) @ sil.direction for p in ([0, 0, 0], [0, 0, 1])]
        np.testing.assert_allclose(sil.layers(frame_points(sil, [[1.5, 0.5, 0.0]]))[0], [[bottom, top]])


def test_layers_with_parts_shared_from_another_view_match_their_own():
    """The welded parts are the mesh's, not the view's: a view that takes them from another gives the same layers."""
    v, t = box((0, 0, 0), (1, 1, 1))
    mesh = combine(unwelded(v, t), box((0, 3, 0), (1, 4, 1)), box((0.2, 0.2, 0.2), (0.6, 0.6, 0.6)))
    points = np.random.default_rng(3).uniform(-1, 1.5, (200, 2))
    for direction in ("X", "Z", (1, 2, 3)):
        own = silhouette.trace(*mesh, direction)
        shared = silhouette.trace(*mesh, direction)
        shared.share_parts(silhouette.trace(*mesh, "Y"))
        for a, b in zip(own.layers(points), shared.layers(points)):
            np.testing.assert_array_equal(a, b)
    nested = silhouette.trace(*mesh, "Z")
    nested.share_parts(nested)  # its own parts: found once, kept
    for a, b in zip(silhouette.trace(*mesh, "Z").layers(points), nested.layers(points)):
        np.testing.assert_array_equal(a, b)
    other = silhouette.trace(v, t, "Y")
    with pytest.raises(ValueError, match="different meshes"):
        shared.share_parts(other)
    turned = silhouette.trace(v, t[:, ::-1], "Y")  # the same vertices, other triangles
    with pytest.raises(ValueError, match="different meshes"):
        turned.share_parts(other)
    with pytest.raises(TypeError, match="another Silhouette"):
        shared.share_parts(None)


def test_layers_of_open_surfaces():
    """A single sheet is a zero-thickness layer; a tube open at both ends is entered and left."""
    sheet = (np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    tube = grid_surface(lambda s, t: [3 + np.cos(2 * np.pi * s), 2 * t, np.sin(2 * np.pi * s)], 32, 2, False)
    sil = silhouette.trace(*combine(sheet, tube), "Z")
    sheet_point, tube_point = frame_points(sil, [[0.5, 0.5, 0], [3, 1, 0]])
    sheet_layer, tube_layer = sil.layers([sheet_point, tube_point])
    assert sheet_layer.shape == (1, 2) and sheet_layer[0, 0] == sheet_layer[0, 1]
    assert tube_layer.shape == (1, 2) and tube_layer[0, 1] - tube_layer[0, 0] == pytest.approx(2.0, rel=1e-3)
    assert sil.layers([[100, 100]])[0].shape == (0, 2)


@pytest.mark.parametrize("case", list(depth_cases())[:3], ids=lambda c: c[0])
def test_layers_pair_hits_by_parity_on_closed_meshes(case):
    """Closed parts: each part's hits pair up in depth order, and the parts' intervals merge where they overlap."""
    _, vertices, triangles, direction = case
    sil = silhouette.trace(vertices, triangles, direction)
    rng = np.random.default_rng(11)
    points = np.concatenate(sil.loops)[rng.choice(sum(map(len, sil.loops)), 150)]
    points = points * 0.85 + frame_points(sil, vertices).mean(axis=0) * 0.15
    compared = 0
    for layer, hits in zip(sil.layers(points), brute_force_hits(sil, vertices, triangles, points)):
        if hits is None:
            continue
        intervals = []
        for part in np.unique(hits[:, 1]):
            depths = hits[hits[:, 1] == part, 0]
            assert len(depths) % 2 == 0
            intervals += depths.reshape(-1, 2).tolist()
        merged = []
        for a, b in sorted(intervals):
            if merged and a <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], b)
            else:
                merged.append([a, b])
        assert np.allclose(layer, np.reshape(merged, (-1, 2)), atol=1e-9)
        compared += 1
    assert compared > 100


# ------------------------------------------------------------------------------------------------ bad input


def test_bad_input_is_a_value_error():
    v, t = box((0, 0, 0), (1, 1, 1))
    cases = [
        (np.where(np.arange(24).reshape(8, 3) == 5, np.nan, v), t, "Y", {}),
        (np.where(np.arange(24).reshape(8, 3) == 5, np.inf, v), t, "Y", {}),
        (v, t + 1, "Y", {}),
        (v, t - 1, "Y", {}),
        (v, t.astype(float) + 0.5, "Y", {}),
        (np.zeros((0, 3)), np.zeros((0, 3), int), "Y", {}),
        (v, np.zeros((0, 3), int), "Y", {}),
        (v[:, :2], t, "Y", {}),
        (v, t[:, :2], "Y", {}),
        ("mesh", t, "Y", {}),
        (v, t, "W", {}),
        (v, t, "--X", {}),
        (v, t, (0, 0, 0), {}),
        (v, t, (0, np.nan, 1), {}),
        (v, t, (1, 2), {}),
        (v, t, "Y", {"resolution": 4}),
        (v, t, "Y", {"resolution": 100_000}),
        (v, t, "Y", {"resolution": 512.5}),
        (v, t, "Y", {"resolution": True}),
        (v, t, "Y", {"tolerance": -0.1}),
        (v, t, "Y", {"tolerance": 2}),
        (v, t, "Y", {"tolerance": float("nan")}),
        (np.c_[v[:, :2], np.zeros(8)], t, "Y", {}),  # flat along the view: zero-area projection
        (np.full((3, 3), 1e308) * [[1, 1, 1], [-1, 1, 1], [1, -1, 1]], [[0, 1, 2]], "Z", {}),  # overflows
    ]
    for vertices, triangles, direction, options in cases:
        with pytest.raises(ValueError):
            silhouette.trace(vertices, triangles, direction, **options)


def test_zero_area_message():
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1.0]])
    with pytest.raises(silhouette.NoSilhouette, match="zero area"):
        silhouette.trace(flat, [[0, 1, 2]], "X")
    assert len(silhouette.trace(flat, [[0, 1, 2]], "Y").loops) == 1


def test_parts_smaller_than_a_cell_give_no_silhouette_not_an_empty_one():
    """Two unit cubes 1e5 apart: at 384 cells each covers no cell, so there is no outline to give."""
    far_apart = far_apart_cubes()
    with pytest.raises(silhouette.NoSilhouette, match="too small for the space between them"):
        silhouette.trace(*far_apart, "Y", resolution=384)
    assert len(silhouette.trace(*far_apart, "X", resolution=384).loops) == 1  # end-on they overlap


def test_read_only_arrays_are_accepted():
    """Meshes arrive as read-only views (rigger.core.mesh.Mesh); the binding must not ask for writable buffers."""
    vertices, triangles = box((0, 0, 0), (1, 2, 3))
    vertices = np.array(vertices, dtype=np.float64)
    triangles = np.array(triangles, dtype=np.int32)
    vertices.setflags(write=False)
    triangles.setflags(write=False)
    sil = silhouette.trace(vertices, triangles, "X")
    assert len(sil.loops) == 1
    assert abs(shapely.Polygon(sil.loops[0]).area) == pytest.approx(6.0, rel=1e-3)
