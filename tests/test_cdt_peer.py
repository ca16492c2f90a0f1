"""The peer suite: rigger.cdt against other libraries' fixtures in ../shared/cdt (see its README for the formats).

artem-ogre/CDT results are compared geometrically: triangles as sets of corner coordinates, Steiner points matched
within a small tolerance. Where four points are exactly cocircular any valid Delaunay choice is accepted.
"""
import itertools
import json
import math
from dataclasses import dataclass

import numpy as np
import pytest
from conftest import SHARED, shared_path

from cdt_checks import (check_even_odd, check_triangulation, coordinate_triples, has_closed_curves,
                        incircle_signs, orient, polygon_area, touches_cocircular_quad, triangle_areas)
from rigger.cdt import triangulate

PEER_DIR = ("cdt", "artem-ogre-CDT")
NONE = 4294967295  # the peer's "no neighbour"
SUPER = 3  # the peer's `all` section keeps its super-triangle as vertices 0, 1, 2
# The peer rounds its own crossing points (we rebuild them from its split map): match ours within this, relative.
PEER_STEINER_TOLERANCE = 1e-7
# Peer section -> our mode. `super` is the peer's convex hull triangulation; `auto` removes the outside and holes by
# the even-odd depth of the constraint boundaries (overlap counts included, so a doubled edge cancels, as ours).
MODES = {"all": "all", "super": "all", "auto": "inside"}


def read_peer_input(path):
    """(points (N, 2) float64, edges (M, 2) int64) from ``nVertices nEdges`` then the vertex and edge lines."""
    tokens = path.read_text().split()
    n_points, n_edges = int(tokens[0]), int(tokens[1])
    points = np.array(tokens[2:2 + 2 * n_points], dtype=np.float64).reshape(n_points, 2)
    edges = np.array(tokens[2 + 2 * n_points:], dtype=np.int64).reshape(n_edges, 2)
    return points, edges


@dataclass
class PeerResult:
    triangles: np.ndarray  # (T, 3) counter-clockwise
    neighbors: np.ndarray  # (T, 3): across edge (v_k, v_k+1), NONE on the boundary
    fixed: set  # constraint edges as sorted vertex pairs
    split: dict  # piece (a, b) -> the original edges it belongs to


def read_peer_expected(path):
    """The four blank-line separated blocks: triangles with neighbours, fixed edges, overlaps (unused), split map."""
    blocks = path.read_text().split("\n\n")
    rows = [line.split() for line in blocks[0].splitlines()[1:]]
    triangles = np.array([r[:3] for r in rows], dtype=np.int64).reshape(-1, 3)
    neighbors = np.array([r[3:] for r in rows], dtype=np.int64).reshape(-1, 3)
    fixed = {tuple(sorted(map(int, line.split()))) for line in blocks[1].splitlines()[1:]}
    split, lines = {}, blocks[3].splitlines()[1:]
    while lines:
        piece, count = tuple(map(int, lines[0].split())), int(lines[1])
        split[piece] = [tuple(map(int, line.split())) for line in lines[2:2 + count]]
        lines = lines[2 + count:]
    return PeerResult(triangles, neighbors, fixed, split)


def peer_coordinates(points, peer, offset):
    """Coordinates of every peer vertex: inputs shifted by ``offset``, then the Steiner points the peer created,
    each rebuilt as the intersection of two of the original edges its pieces came from (NaN for super vertices)."""
    count = max(int(peer.triangles.max(initial=-1)), max(itertools.chain([-1], *peer.fixed))) + 1
    coords = np.full((max(count, offset + len(points)), 2), np.nan)
    coords[offset:offset + len(points)] = points
    for vertex in range(offset + len(points), count):
        originals = sorted({tuple(sorted(e)) for piece, edges in peer.split.items() if vertex in piece for e in edges})
        coords[vertex] = next(p for e, f in itertools.combinations(originals, 2)
                              if (p := _line_intersection(*coords[list(e) + list(f)])) is not None)
    return coords


def _line_intersection(p, q, r, s):
    """Where line p-q meets line r-s (float), or None when they are parallel."""
    d = (q[0] - p[0]) * (s[1] - r[1]) - (q[1] - p[1]) * (s[0] - r[0])
    if d == 0:
        return None
    t = ((r[0] - p[0]) * (s[1] - r[1]) - (r[1] - p[1]) * (s[0] - r[0])) / d
    return p + t * (q - p)


def has_crossing_edges(points, edges):
    """Do two edges cross at an interior point or overlap along part of their length (exact duplicates and
    zero-length edges aside)?"""
    pts = points.tolist()
    distinct = np.array(sorted({tuple(sorted(e)) for e in edges.tolist() if e[0] != e[1]}), np.int64).reshape(-1, 2)
    ends = points[distinct]
    low, high = ends.min(axis=1), ends.max(axis=1)
    boxes_meet = ((low[:, None] <= high[None, :]) & (low[None, :] <= high[:, None])).all(axis=2)
    for i, j in np.argwhere(np.triu(boxes_meet, 1)):
        (a, b), (c, d) = distinct[i].tolist(), distinct[j].tolist()
        if len({a, b, c, d}) < 4:
            shared = ({a, b} & {c, d}).pop()
            p, q = (b if shared == a else a), (d if shared == c else c)
            # Touching at a shared endpoint: they cross only if they overlap along the same ray.
            if orient(pts[shared], pts[p], pts[q]) == 0 and np.dot(np.subtract(pts[p], pts[shared]),
                                                                    np.subtract(pts[q], pts[shared])) > 0:
                return True
            continue
        o1, o2 = orient(pts[a], pts[b], pts[c]), orient(pts[a], pts[b], pts[d])
        o3, o4 = orient(pts[c], pts[d], pts[a]), orient(pts[c], pts[d], pts[b])
        if o1 * o2 < 0 and o3 * o4 < 0:
            return True
        if o1 == o2 == 0 and _overlap_length(pts[a], pts[b], pts[c], pts[d]) > 0:
            return True
    return False


def _overlap_length(a, b, c, d):
    """Signed length of the common part of collinear segments a-b and c-d along their main axis."""
    axis = 0 if abs(b[0] - a[0]) >= abs(b[1] - a[1]) else 1
    lo1, hi1 = sorted((a[axis], b[axis]))
    lo2, hi2 = sorted((c[axis], d[axis]))
    return min(hi1, hi2) - max(lo1, lo2)


def peer_cases():
    """One case per distinct expected result of each input for sections all/super/auto: f64 precision only,
    strategy `resolve`, or `ignore` when the input has no crossing edges (then the two strategies agree)."""
    root = SHARED.joinpath(*PEER_DIR)
    if not root.exists():
        return [pytest.param(None, None, None, id="shared-data-missing")]
    cases, seen, crossing = [], set(), {}
    # `resolve` files first, so that an identical `ignore` file adds no case.
    for path in sorted((root / "expected").glob("*__*.txt"), key=lambda p: ("_ignore_" in p.name, p.name)):
        name, variant = path.stem.split("__")
        flags = variant.split("_")
        section, strategy = flags[-1], flags[-2]
        if section not in MODES or {"f32", "conforming"} & set(flags) or not (root / "inputs" / f"{name}.txt").exists():
            continue
        if strategy == "ignore":
            if name not in crossing:
                crossing[name] = has_crossing_edges(*read_peer_input(root / "inputs" / f"{name}.txt"))
            if crossing[name]:
                continue
        key = (name, section, path.read_text())
        if key not in seen:
            seen.add(key)
            cases.append(pytest.param(name, section, path.name, id=f"{name}-{variant}"))
    return cases


def _steiner_match(ours, peer_coords, first_steiner):
    """Map each peer Steiner vertex to the coordinates of our Steiner vertex at the same place (within tolerance)."""
    n = len(ours.vertex_map)
    mapped = {}
    for vertex in range(first_steiner, len(peer_coords)):
        p = peer_coords[vertex]
        scale = max(1.0, np.abs(p).max())
        distance = np.hypot(*(ours.vertices[n:] - p).T) if ours.steiner_count else np.zeros(0)
        assert len(distance) and distance.min() <= PEER_STEINER_TOLERANCE * scale, (
            f"the peer's Steiner point {p.tolist()} has no counterpart among ours {ours.vertices[n:].tolist()}")
        mapped[vertex] = tuple(ours.vertices[n + int(distance.argmin())].tolist())
    return mapped


def _peer_cocircular(peer, coords, t):
    """Is an apex across one of the peer triangle's unconstrained edges exactly on its circumcircle?"""
    apexes = []
    for k in range(3):
        n = peer.neighbors[t, k]
        edge = (peer.triangles[t, k], peer.triangles[t, (k + 1) % 3])
        if n != NONE and tuple(sorted(edge)) not in peer.fixed:
            apexes += [coords[v] for v in peer.triangles[n] if v not in edge and v >= 0 and not np.isnan(coords[v][0])]
    return any(incircle_signs(*coords[peer.triangles[t]], apex) == 0 for apex in apexes)


def compare_with_peer(ours, peer, coords, kept, offset):
    """Same triangles as the peer's ``kept`` ones, up to flips inside exactly cocircular quads; the same constraint
    pieces (both sides list every piece of the input segments, whatever was removed)."""
    steiner = _steiner_match(ours, coords, offset + len(ours.vertex_map))

    def key(vertex):
        return steiner.get(vertex) or tuple(coords[vertex].tolist())

    theirs = [frozenset(map(key, t)) for t in peer.triangles[kept].tolist()]
    ours_keys = coordinate_triples(ours)
    their_constraints = {frozenset(map(key, e)) for e in peer.fixed}
    our_constraints = {frozenset(map(tuple, ours.vertices[e].tolist())) for e in ours.segments}
    assert our_constraints == their_constraints, (
        f"constraint edges differ: ours only {len(our_constraints - their_constraints)}, "
        f"peer only {len(their_constraints - our_constraints)}")
    if set(ours_keys) == set(theirs):
        return
    # Not identical: acceptable only as another Delaunay choice where points are exactly cocircular.
    our_area = math.fsum(triangle_areas(ours.vertices, ours.triangles))
    their_area = math.fsum(triangle_areas(coords, peer.triangles[kept]))
    assert math.isclose(our_area, their_area, rel_tol=1e-9), f"covered area {our_area} != peer's {their_area}"
    their_set, our_set = set(theirs), set(ours_keys)
    only_ours = [t for t, k in enumerate(ours_keys) if k not in their_set]
    only_theirs = [t for t, k in zip(np.flatnonzero(kept), theirs) if k not in our_set]
    our_ties = touches_cocircular_quad(ours)
    bad_ours = [ours.triangles[t].tolist() for t in only_ours if not our_ties[t]]
    bad_theirs = [peer.triangles[t].tolist() for t in only_theirs if not _peer_cocircular(peer, coords, t)]
    assert not bad_ours and not bad_theirs, (
        f"{len(only_ours)} of our triangles differ from the peer's, not explained by cocircular points: "
        f"ours {bad_ours[:3]}, peer's {bad_theirs[:3]}")


@pytest.mark.parametrize("name, section, expected_file", peer_cases())
def test_artem_ogre_cdt_expected_output(name, section, expected_file):
    """Ours is valid and geometrically the peer's result for the matching mode."""
    root = shared_path(*PEER_DIR)
    points, edges = read_peer_input(root / "inputs" / f"{name}.txt")
    peer = read_peer_expected(root / "expected" / expected_file)
    mode = MODES[section]
    if mode == "inside" and not len(edges):
        # The peer keeps nothing; our contract rejects mode="inside" without segments.
        assert len(peer.triangles) == 0
        with pytest.raises(ValueError, match="needs constraint segments"):
            triangulate(points, edges, mode=mode)
        return
    ours = triangulate(points, edges, mode=mode)
    check_triangulation(ours, points, edges, mode=mode)
    offset = SUPER if section == "all" else 0
    coords = peer_coordinates(points, peer, offset)
    # The `all` section is the peer's CDT of the input plus three far-away super vertices. A triangle without a
    # super vertex has a circumcircle free of every input point it can see, so it is a CDT triangle of the input
    # alone: those triangles are exactly ours in mode="all" wherever they tile the hull, which they do in every
    # fixture (asserted, so a fixture where the far vertices steal thin hull triangles cannot pass silently).
    kept = (peer.triangles >= offset).all(axis=1)
    if section == "all":
        kept_area = math.fsum(triangle_areas(coords, peer.triangles[kept]))
        hull_area = math.fsum(triangle_areas(ours.vertices, ours.triangles))
        assert math.isclose(kept_area, hull_area, rel_tol=1e-9), "peer's non-super triangles do not tile the hull"
    compare_with_peer(ours, peer, coords, kept, offset)


def peer_inputs():
    """Every peer input name (expected outputs or not), or a placeholder that skips when the data is absent."""
    root = SHARED.joinpath(*PEER_DIR, "inputs")
    names = sorted(p.stem for p in root.glob("*.txt")) if root.exists() else []
    return names or [pytest.param(None, id="shared-data-missing")]


@pytest.mark.parametrize("name", peer_inputs())
def test_artem_ogre_cdt_inputs_are_valid_in_both_modes(name):
    """Every peer input, with or without expected output: valid in both modes, inside = even-odd when closed."""
    points, edges = read_peer_input(shared_path(*PEER_DIR, "inputs") / f"{name}.txt")
    everything = triangulate(points, edges, mode="all")
    check_triangulation(everything, points, edges, mode="all")
    if not len(edges):
        return
    inside = triangulate(points, edges, mode="inside")
    check_triangulation(inside, points, edges, mode="inside")
    if has_closed_curves(edges, everything.vertex_map):
        check_even_odd(inside, everything, points, edges)


def fixture_names(folder, suffix):
    """File names of one fixture folder, or a placeholder that skips when the data is absent."""
    root = SHARED / "cdt" / folder
    names = sorted(p.name for p in root.glob(f"*{suffix}")) if root.exists() else []
    return names or [pytest.param(None, id="shared-data-missing")]


@pytest.mark.parametrize("name", fixture_names("delaunator", ".json"))
def test_delaunator_fixture(name):
    """Unconstrained near-degenerate sets: exactly Delaunay everywhere and tiling the convex hull."""
    points = np.array(json.loads((shared_path("cdt", "delaunator") / name).read_text()), dtype=np.float64)
    tri = triangulate(points, mode="all")
    check_triangulation(tri, points, mode="all")
    assert len(tri.triangles) > 0


def read_poly2tri(path):
    """(polygon vertices in order, free interior points after a STEINER line)."""
    polygon, steiner = [], []
    current = polygon
    for line in path.read_text().splitlines():
        if line.strip().upper() == "STEINER":
            current = steiner
        elif line.strip():
            current.append([float(v) for v in line.split()])
    return np.array(polygon), np.array(steiner).reshape(-1, 2)


@pytest.mark.parametrize("name", fixture_names("poly2tri", ".dat"))
def test_poly2tri_polygon(name):
    """mode="inside" fills exactly the polygon (even-odd when it self-intersects), with the shoelace area and the
    Euler triangle count when it is simple."""
    polygon, free = read_poly2tri(shared_path("cdt", "poly2tri") / name)
    points = np.concatenate([polygon, free])
    n = len(polygon)
    ring = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    inside = triangulate(points, ring, mode="inside")
    everything = triangulate(points, ring, mode="all")
    check_triangulation(inside, points, ring, mode="inside")
    check_triangulation(everything, points, ring, mode="all")
    check_even_odd(inside, everything, points, ring)
    if not has_crossing_edges(polygon, ring):
        area = math.fsum(triangle_areas(inside.vertices, inside.triangles))
        assert math.isclose(area, abs(polygon_area(polygon)), rel_tol=1e-9)
        assert inside.steiner_count == 0
        # Euler: a simple n-gon with s interior points has n + 2s - 2 triangles.
        assert len(inside.triangles) == n + 2 * len(free) - 2
