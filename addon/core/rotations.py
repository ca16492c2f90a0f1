"""Rotation matrices (3x3) the core builds from directions: the smallest turn between two, and a turn about an axis."""
import numpy as np


def between(a, b):
    """The smallest rotation taking direction ``a`` onto direction ``b`` (half a turn about an axis across ``a``
    when they are opposite)."""
    a, b = (np.asarray(v, dtype=np.float64) / np.linalg.norm(v) for v in (a, b))
    axis = np.cross(a, b)
    sine, cosine = np.linalg.norm(axis), float(a @ b)
    if sine < 1e-12:
        if cosine > 0:
            return np.eye(3)
        other = np.eye(3)[np.argmin(np.abs(a))]
        axis = np.cross(a, other)
        axis /= np.linalg.norm(axis)
        return 2 * np.outer(axis, axis) - np.eye(3)
    return _turn(axis / sine, sine, cosine)


def about(axis, angle):
    """The rotation by ``angle`` radians about unit ``axis`` (right-handed)."""
    return _turn(np.asarray(axis, dtype=np.float64), np.sin(angle), np.cos(angle))


def _turn(axis, sine, cosine):
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + sine * cross + (1 - cosine) * cross @ cross
