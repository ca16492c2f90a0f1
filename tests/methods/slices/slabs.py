"""Cutting vertices into slabs along an axis."""
import numpy as np


def slab_centres(vertices, axis, count):
    """The centroid of each of ``count`` equal slabs along ``axis``, and which slab each vertex is in."""
    along = vertices[:, axis]
    edges = np.linspace(along.min(), along.max(), count + 1)
    members = np.clip(np.searchsorted(edges, along, side="right") - 1, 0, count - 1)
    return np.array([vertices[members == k].mean(axis=0) for k in range(count)]), members


def slab_rings(vertices, centres, members, axis):
    """Per slab: its centre, the largest distance of its vertices from the axis through it, and the axis."""
    across = np.delete(np.arange(3), axis)
    radii = np.array([np.linalg.norm((vertices[members == k] - centre)[:, across], axis=1).max()
                      for k, centre in enumerate(centres)])
    return centres, radii, axis
