"""The silhouette tracer against exact references: shapely unions of the projected triangles, brute-force rays."""
import sys

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from characters import load_character
from conftest import ROOT, shared_path
from rigger import silhouette

sys.path.insert(0, str(ROOT / "bench"))
from rigdata import load_obj  # noqa: E402  (the benchmarks' OBJ reader)


def box(centre, size):
    """A closed axis-aligned box (8 vertices, 12 triangles)."""
    c, s = np.asarray(centre, float), np.asarray(size, float) / 2
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * s + c
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return corners, np.array(faces)


def scene(*parts):
    vertices, triangles, offset = [], [], 0
    for v, t in parts:
        vertices.append(v)
        triangles.append(t + offset)
        offset += len(v)
    return np.concatenate(vertices), np.concatenate(triangles)


def reference_union(sil, vertices, triangles):
    """The exact union of the projected triangles, in the silhouette's (u, v) frame."""
    rel = vertices - sil.origin
    flat = np.stack([rel @ sil.u, rel @ sil.v], axis=1)[triangles]
    polys = [Polygon(t) for t in flat if abs(np.cross(t[1] - t[0], t[2] - t[0])) > 1e-15]
    return shapely.union_all(polys)


def traced_region(sil):
    outers = [l for l in sil.loops if signed_area(l) > 0]
    holes = [l for l in sil.loops if signed_area(l) < 0]
    region = shapely.union_all([Polygon(l) for l in outers])
    return region.difference(shapely.union_all([Polygon(l) for l in holes])) if holes else region


def signed_area(loop):
    return 0.5 * float(np.sum(loop[:, 0] * np.roll(loop[:, 1], -1) - np.roll(loop[:, 0], -1) * loop[:, 1]))


def iou(a, b):
    return a.intersection(b).area / a.union(b).area


def check_against_reference(vertices, triangles, direction, minimum_iou=0.995):
    sil = silhouette.trace(vertices, triangles, direction)
    truth = reference_union(sil, vertices, triangles)
    region = traced_region(sil)
    assert iou(region, truth) >= minimum_iou
    for loop in sil.loops:
        assert Polygon(loop).is_valid and abs(signed_area(loop)) > 0  # simple, oriented
    # islands and holes of a few cells or more must all be there (specks smaller than a cell are dropped by design)
    speck = 4 * sil.cell ** 2
    parts = [p for p in getattr(truth, "geoms", [truth]) if p.area > speck]
    holes = [h for p in parts for h in p.interiors if Polygon(h).area > speck]
    assert sum(1 for l in sil.loops if signed_area(l) > speck) == len(parts)
    assert sum(1 for l in sil.loops if signed_area(l) < -speck) == len(holes)
    return sil


def test_separate_boxes_are_separate_islands():
    vertices, triangles = scene(box((0, 0, 0), (1, 1, 1)), box((3, 0, 0), (1, 2, 1)), box((0, 5, 0), (2, 1, 1)))
    check_against_reference(vertices, triangles, "Z")


def test_a_frame_has_a_hole():
    vertices, triangles = scene(box((0, 0, 0), (4, 0.5, 1)), box((0, 3, 0), (4, 0.5, 1)),
                                box((-1.75, 1.5, 0), (0.5, 3.5, 1)), box((1.75, 1.5, 0), (0.5, 3.5, 1)))
    sil = check_against_reference(vertices, triangles, "Z")
    assert sum(1 for l in sil.loops if signed_area(l) < 0) == 1


@pytest.mark.parametrize("name, direction", [("humanoid", "Y"), ("humanoid_hips", "Y"), ("quadruped", "X"),
                                             ("octopus", "Z"), ("tree", (1, 1, 0))])
def test_generated_characters_match_the_exact_union(name, direction):
    vertices, triangles = load_character(name)
    check_against_reference(vertices, triangles, direction)


@pytest.mark.parametrize("name", ["CesiumMan", "Quaternius_Fox", "rignet_2982"])
def test_real_models_match_the_exact_union(name):
    path = shared_path("models", "gt", name, f"{name}.obj")
    vertices, triangles = load_obj(path)
    for direction in "XYZ":
        check_against_reference(vertices, triangles, direction)


def test_depth_agrees_with_brute_force_rays():
    vertices, triangles = load_character("quadruped")
    sil = silhouette.trace(vertices, triangles, "X")
    rng = np.random.default_rng(0)
    low, high = np.min(np.concatenate(sil.loops), axis=0), np.max(np.concatenate(sil.loops), axis=0)
    points = rng.uniform(low, high, (200, 2))
    front, back = sil.depth(points)
    layers = sil.layers(points)
    for p, f, b, layer in zip(points, front, back, layers):
        hits = ray_hits(sil, vertices, triangles, p)
        if not len(hits):
            assert np.isnan(f) and np.isnan(b) and len(layer) == 0
            continue
        assert f == pytest.approx(hits.min(), abs=1e-9) and b == pytest.approx(hits.max(), abs=1e-9)
        assert len(layer) >= 1 and layer[0, 0] == pytest.approx(hits.min(), abs=1e-9)


def ray_hits(sil, vertices, triangles, point):
    """Depths where the ray through ``point`` crosses the mesh (Möller-Trumbore, every triangle)."""
    origin = sil.origin + point[0] * sil.u + point[1] * sil.v
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    pvec = np.cross(sil.direction, e2)
    det = (e1 * pvec).sum(1)
    ok = np.abs(det) > 1e-14
    inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
    tvec = origin - a
    u = (tvec * pvec).sum(1) * inv
    qvec = np.cross(tvec, e1)
    v = (sil.direction * qvec).sum(1) * inv
    t = (e2 * qvec).sum(1) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    return t[hit]


def test_stacked_legs_give_separate_layers():
    vertices, triangles = scene(box((0, -1, 0), (0.5, 0.5, 2)), box((0, 1, 0), (0.5, 0.5, 2)))
    sil = silhouette.trace(vertices, triangles, "Y")
    centre = -sil.origin  # the world origin in the silhouette frame
    layers = sil.layers(np.array([[centre @ sil.u, centre @ sil.v]]))[0]
    depths = np.sort(layers.ravel() + sil.origin @ sil.direction)
    assert np.allclose(np.abs(depths), [1.25, 0.75, 0.75, 1.25])


@pytest.mark.parametrize("vertices, triangles, direction, message", [
    (np.zeros((0, 3)), np.zeros((0, 3), int), "Z", "empty"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0.0]]), [[0, 1, 2]], "Z", "finite"),
    (np.eye(3), [[0, 1, 5]], "Z", "index"),
    (np.eye(3), [[0, 1, 2]], (0, 0, 0), "direction"),
    (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), [[0, 1, 2]], "Z", "area"),
])
def test_bad_input_gets_a_clear_error(vertices, triangles, direction, message):
    with pytest.raises(ValueError, match=message):
        silhouette.trace(vertices, triangles, direction)


def test_read_only_arrays_are_accepted():
    vertices, triangles = box((0, 0, 0), (1, 2, 3))
    vertices.setflags(write=False)
    triangles = triangles.astype(np.int32)
    triangles.setflags(write=False)
    sil = silhouette.trace(vertices, triangles, "X")
    assert len(sil.loops) == 1 and abs(signed_area(sil.loops[0])) == pytest.approx(6.0, rel=1e-3)
