"""Small generated meshes the tests share: boxes, capped cylinders, UV spheres and ellipsoids, parametric surfaces,
and soups of several meshes."""
import numpy as np


def box(lo, hi):
    """An axis-aligned box: 8 vertices, 12 outward triangles."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)], float)
    t = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return v, np.array(t)


def cylinder(radius, length, around=48, along=40):
    """A closed tube along z from 0 to ``length``: ``along`` rings of ``around`` vertices, and a fan on each end."""
    angles = np.linspace(0.0, 2 * np.pi, around, endpoint=False)
    ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    rings = [np.column_stack([ring, np.full(around, z)]) for z in np.linspace(0.0, length, along)]
    vertices = np.vstack(rings + [[[0.0, 0.0, 0.0], [0.0, 0.0, length]]])
    bottom, top, last = len(vertices) - 2, len(vertices) - 1, (along - 1) * around
    triangles = []
    for j in range(around):
        following = (j + 1) % around
        triangles += [(bottom, following, j), (top, last + j, last + following)]
        for i in range(along - 1):
            here, there = i * around + j, i * around + following
            triangles += [(here, there, there + around), (here, there + around, here + around)]
    return vertices, np.array(triangles)


def combine(*meshes):
    """One soup from several meshes."""
    vertices, triangles, offset = [], [], 0
    for v, t in meshes:
        vertices.append(v)
        triangles.append(np.asarray(t) + offset)
        offset += len(v)
    return np.concatenate(vertices), np.concatenate(triangles)


def far_apart_cubes():
    """Two unit cubes 1e5 apart along x: parts too small for the space between them, seen from the side."""
    return combine(box((0, 0, 0), (1, 1, 1)), box((1e5, 0, 0), (1e5 + 1, 1, 1)))


def uv_sphere(rings=16, segments=32):
    """A closed unit UV sphere: ``rings`` bands from pole to pole, ``segments`` around."""
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                     np.repeat(np.cos(theta)[:, None], segments, axis=1)], axis=2).reshape(-1, 3)
    vertices = np.vstack([ring, [(0, 0, 1), (0, 0, -1)]])
    top, bottom = len(ring), len(ring) + 1
    triangles = []
    for r in range(rings - 2):
        for k in range(segments):
            a, b = r * segments + k, r * segments + (k + 1) % segments
            triangles += [(a, b + segments, b), (a, a + segments, b + segments)]
    for k in range(segments):
        triangles += [(top, k, (k + 1) % segments)]
        last = (rings - 2) * segments
        triangles += [(bottom, last + (k + 1) % segments, last + k)]
    return vertices, np.array(triangles)


def ellipsoids(parts):
    """One closed UV-sphere mesh per (centre, semi-axes) part, all in one vertex and triangle array."""
    sphere, sphere_triangles = uv_sphere()
    return combine(*((sphere * size + centre, sphere_triangles) for centre, size in parts))


def grid_surface(point, nu, nv, closed_v=True):
    """Triangles of a (nu x nv) parametric surface ``point(s, t)``, wrapping in u always and in v when closed_v."""
    us, vs = np.arange(nu), np.arange(nv)
    vertices = np.array([point(i / nu, j / (nv if closed_v else nv - 1)) for i in us for j in vs])
    rows = nv if closed_v else nv - 1
    tris = []
    for i in us:
        for j in range(rows):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            tris += [[a, b, c], [a, c, d]]
    return vertices, np.array(tris)
