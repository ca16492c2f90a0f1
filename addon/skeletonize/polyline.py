"""Measuring along polylines (axis-node chains, placed 3D chains): shared by the tree, second-view and bone steps."""
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
