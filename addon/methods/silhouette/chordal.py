"""Chordal axis of a triangulated silhouette (Prasad's chordal axis transform, as used by Pan et al. 2009).

Each triangle of the constrained Delaunay triangulation is classified by how many of its edges lie on the outline:
two make a *terminal* triangle (a branch ends), one a *sleeve* (a branch runs through), none a *junction* (branches
meet) and three an *isolated* triangle (a whole island). The axis joins the midpoints of the internal edges: a sleeve
links its two, a junction links its three to its centre, a terminal links its one to its tip.

The result is a :class:`ChordalAxis`: points in the silhouette plane with the radius of the part there (half the
chord, or the junction's circumradius) and undirected links.
"""
from dataclasses import dataclass, replace

import numpy as np

from ...core.graphs import components
from ...core.stages import SLEEVE, TERMINAL


@dataclass(frozen=True)
class ChordalAxis:
    """A planar graph along the middle of a shape.

    Attributes:
        points: (n, 2) node positions in the silhouette plane.
        radius: (n,) half-width of the shape at each node.
        junction: (n,) bool, True where branches meet (junction or isolated triangles).
        links: (m, 2) int node pairs.
        island: (n,) int, the connected part of the silhouette each node belongs to.
        passing: (n, 2) points and (n,) radii where each node sits should the axis only pass through it
            (``passed_through``), or None: where it is.
    """

    points: np.ndarray
    radius: np.ndarray
    junction: np.ndarray
    links: np.ndarray
    island: np.ndarray
    passing: tuple = None

    def centred_on_mirror(self, hubs, mirror):
        """A copy with each of the nodes ``hubs`` (int array) whose mirror image lies within its disc (``mirror``
        reflects (P, 2) points across the mesh's mirror plane) moved to the midpoint of it and its image, onto the
        mirror line. The triangulation of a symmetric outline is not symmetric: a body's centre left off the line
        would hang a figure's left and right limbs from it at different angles."""
        near = on_mirror_line(self.points[hubs], self.radius[hubs], mirror)
        points = self.points.copy()
        points[hubs[near]] = 0.5 * (points[hubs[near]] + mirror(points[hubs[near]]))
        return replace(self, points=points)

    def passed_through(self, nodes):
        """A copy with the ``nodes`` (int array) the axis only passes through, once their other branches are pruned,
        moved to where they sit then (``passing``). A junction whose triangle is obtuse sits at its centroid, off
        the middle of the part: a dense convex outline (a rounded head, a pebble seen flat) gives such triangles
        across the part, each with a one-triangle spur to a notch of the outline, alternately above and below the
        middle, and an axis through their centroids zigzags. Passed through, such a junction is a sleeve, and sits
        on the middle of its longest edge, the chord across the part."""
        if self.passing is None or not len(nodes):
            return self
        points, radius = self.points.copy(), self.radius.copy()
        points[nodes], radius[nodes] = self.passing[0][nodes], self.passing[1][nodes]
        return replace(self, points=points, radius=radius)


def on_mirror_line(points, radius, mirror):
    """Which of the (P, 2) ``points`` of a view lie on its mirror line: their discs (``radius``) hold their mirror
    images (``mirror`` reflects (P, 2) points across the mesh's mirror plane)."""
    return np.linalg.norm(mirror(points) - points, axis=1) <= radius


def triangle_classes(tri):
    """Class of every triangle of a ``rigger.cdt`` triangulation (``core.stages``' TERMINAL, SLEEVE, JUNCTION or
    ISOLATED): 3 minus its internal edges."""
    internal = (tri.neighbors >= 0) & ~tri.constrained
    return 3 - internal.sum(axis=1)


def chordal_axis(tri, classes):
    """The chordal axis of a ``rigger.cdt.Triangulation`` made in mode ``"inside"`` whose triangles are of
    ``classes`` (``triangle_classes``), as a :class:`ChordalAxis`."""
    corners = tri.vertices[tri.triangles]                       # (T, 3, 2)
    internal = (tri.neighbors >= 0) & ~tri.constrained          # (T, 3): edge opposite corner k is internal
    count = len(tri.triangles)

    # one node per internal edge, numbered from the triangle with the lower index
    owner_t, owner_k = np.nonzero(internal & (np.arange(count)[:, None] < tri.neighbors))
    edge_a = corners[owner_t, (owner_k + 1) % 3]
    edge_b = corners[owner_t, (owner_k + 2) % 3]
    edge_id = np.full((count, 3), -1, dtype=np.int64)
    edge_id[owner_t, owner_k] = np.arange(len(owner_t))
    twin_t = tri.neighbors[owner_t, owner_k]
    twin_k = np.argmax(tri.neighbors[twin_t] == owner_t[:, None], axis=1)
    edge_id[twin_t, twin_k] = np.arange(len(owner_t))
    edge_points = (edge_a + edge_b) / 2
    edge_radius = np.linalg.norm(edge_a - edge_b, axis=1) / 2

    # one node per junction, terminal and isolated triangle
    centre_tris = np.flatnonzero(classes != SLEEVE)
    centre_points, centre_radius, chord_points, chord_radius = _triangle_centres(corners[centre_tris],
                                                                               classes[centre_tris])
    centre_id = np.full(count, -1, dtype=np.int64)
    centre_id[centre_tris] = len(owner_t) + np.arange(len(centre_tris))

    links = []
    sleeves = np.flatnonzero(classes == SLEEVE)
    pair = edge_id[sleeves][internal[sleeves]].reshape(-1, 2)
    links.append(pair)
    for k in range(3):
        has = internal[centre_tris, k]
        links.append(np.stack([centre_id[centre_tris[has]], edge_id[centre_tris[has], k]], axis=1))
    links = np.concatenate(links).astype(np.int64) if links else np.zeros((0, 2), np.int64)

    points = np.concatenate([edge_points, centre_points])
    radius = np.concatenate([edge_radius, centre_radius])
    junction = np.concatenate([np.zeros(len(edge_points), bool), classes[centre_tris] != TERMINAL])
    passing = np.concatenate([edge_points, chord_points]), np.concatenate([edge_radius, chord_radius])
    return ChordalAxis(points, radius, junction, links, components(len(points), links), passing)


def _triangle_centres(corners, classes):
    """(centres, radii, passing centres, passing radii) of triangles: junctions sit at the circumcentre when it lies
    inside the triangle (the centre of the largest disc touching the three outline points), otherwise at the
    centroid; terminals sit at their centroid, near the branch tip. Passed through (``ChordalAxis.passed_through``),
    a junction at its centroid sits on the middle of its longest edge instead. A radius is the distance to the
    nearest corner."""
    centroid = corners.mean(axis=1)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, ac = b - a, c - a
    denom = 2 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        ux = (ac[:, 1] * (ab ** 2).sum(1) - ab[:, 1] * (ac ** 2).sum(1)) / denom
        uy = (ab[:, 0] * (ac ** 2).sum(1) - ac[:, 0] * (ab ** 2).sum(1)) / denom
    circum = a + np.stack([ux, uy], axis=1)
    inside = np.isfinite(circum).all(axis=1) & _inside_triangle(circum, a, b, c)
    use_circum = inside & (classes != TERMINAL)
    centre = np.where(use_circum[:, None], circum, centroid)
    edges = np.stack([c - b, a - c, b - a], axis=1)  # edge k lies opposite corner k
    longest = np.argmax((edges ** 2).sum(axis=2), axis=1)
    rows = np.arange(len(corners))
    chord = 0.5 * (corners[rows, (longest + 1) % 3] + corners[rows, (longest + 2) % 3])
    passing = np.where(((classes != TERMINAL) & ~inside)[:, None], chord, centre)
    return centre, _nearest_corner(corners, centre), passing, _nearest_corner(corners, passing)


def _nearest_corner(corners, points):
    """Per triangle (``corners`` (T, 3, 2)), the distance from its point in ``points`` (T, 2) to its nearest corner."""
    return np.linalg.norm(corners - points[:, None, :], axis=2).min(axis=1)


def _inside_triangle(p, a, b, c):
    def side(u, w):
        return (w[:, 0] - u[:, 0]) * (p[:, 1] - u[:, 1]) - (w[:, 1] - u[:, 1]) * (p[:, 0] - u[:, 0])
    return (side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)
