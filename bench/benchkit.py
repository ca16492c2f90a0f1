"""Helpers the benchmarks share: the machine's CPU, time formatting, mesh refinement."""
import numpy as np


def cpu_model():
    """The CPU model from /proc/cpuinfo, or "unknown CPU"."""
    try:
        with open("/proc/cpuinfo") as info:
            return next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        return "unknown CPU"


def format_seconds(seconds):
    if seconds < 1e-3:
        return f"{seconds * 1e6:.0f} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def midpoint_subdivided(vertices, triangles):
    """Each triangle split into four at its edge midpoints, corners wound as the original's.

    Neighbouring triangles share the midpoint of their common edge, so a closed mesh stays closed; the surface is
    unchanged, so only the vertex count grows (about fourfold).
    """
    count = len(vertices)
    a, b, c = (np.asarray(triangles[:, k], dtype=np.int64) for k in range(3))
    starts, ends = np.concatenate([a, b, c]), np.concatenate([b, c, a])
    keys, edge_of_side = np.unique(np.minimum(starts, ends) * count + np.maximum(starts, ends), return_inverse=True)
    midpoints = 0.5 * (vertices[keys // count] + vertices[keys % count])
    ab, bc, ca = (count + edge_of_side).reshape(3, -1)
    quarters = [np.stack(corners, axis=1) for corners in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
    return np.concatenate([vertices, midpoints]), np.concatenate(quarters).astype(np.int32)
