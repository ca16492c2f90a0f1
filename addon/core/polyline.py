"""Measuring along and to polylines (axis chains, placed 3D chains, bones): lengths, points at arc lengths, nearest
points and distances to segments."""
import numpy as np


def arc_lengths(line):
    """Cumulative length along a polyline, from 0 at its first point."""
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))]


def length(line):
    """Total length of a polyline (0 for a single point)."""
    return float(np.linalg.norm(np.diff(line, axis=0), axis=1).sum()) if len(line) > 1 else 0.0


def point_at(line, arc, at):
    """The point(s) at arc length(s) ``at`` along a polyline whose cumulative arc lengths are ``arc``."""
    return np.stack([np.interp(at, arc, line[:, d]) for d in range(3)], axis=-1)


def resampled(line, count):
    """``count`` points evenly spaced by arc length along a polyline."""
    arc = arc_lengths(line)
    return point_at(line, arc, np.linspace(0.0, arc[-1], count))


def nearest_on_segments(points, starts, ends):
    """The (P, S, 3) points of each segment ``starts[k]``–``ends[k]`` nearest each of the (P, 3) ``points``."""
    seg = ends - starts
    length2 = np.maximum((seg * seg).sum(axis=1), 1e-300)
    t = np.clip(((points[:, None, :] - starts[None]) * seg[None]).sum(axis=2) / length2, 0.0, 1.0)
    return starts[None] + t[..., None] * seg[None]


def segment_distances(points, starts, ends):
    """(P, S) distances from each of the (P, 3) ``points`` to each segment ``starts[k]``–``ends[k]``."""
    seg = ends - starts
    length2 = np.maximum((seg * seg).sum(axis=1), 1e-300)
    apart = points[:, None, :] - starts[None]
    t = np.clip(np.einsum("psk,sk->ps", apart, seg) / length2, 0.0, 1.0)
    apart -= t[..., None] * seg[None]
    return np.sqrt(np.einsum("psk,psk->ps", apart, apart))


def arc_nearest(line, arc, point):
    """The arc length along a polyline (cumulative arc lengths ``arc``) of its point nearest ``point``."""
    starts, ends = line[:-1], line[1:]
    nearest = nearest_on_segments(np.asarray(point, dtype=np.float64)[None], starts, ends)[0]
    k = int(np.argmin(np.linalg.norm(nearest - point, axis=1)))
    span = np.linalg.norm(ends[k] - starts[k])
    return float(arc[k] + (np.linalg.norm(nearest[k] - starts[k]) if span > 0 else 0.0))
