"""The exact reference a traced silhouette is judged against: the shapely union of the projected triangles.

Shared by ``bench/silhouette.py`` and ``tests/test_silhouette.py``.
"""
import numpy as np
import shapely


def frame_points(sil, vertices):
    """3D points in the silhouette's (u, v) frame."""
    offset = np.asarray(vertices, float) - sil.origin
    return np.c_[offset @ sil.u, offset @ sil.v]


def exact_union(sil, vertices, triangles):
    """The union of the projected triangles, in the silhouette's frame."""
    corners = frame_points(sil, vertices)[np.asarray(triangles)]
    polygons = shapely.polygons(np.concatenate([corners, corners[:, :1]], axis=1))
    return shapely.union_all(polygons[shapely.area(polygons) > 0])


def traced_region(loops):
    """The region the loops bound, by the even-odd rule (valid because loops never cross)."""
    region = shapely.Polygon()
    for loop in loops:
        region = shapely.symmetric_difference(region, shapely.Polygon(loop))
    return region


def iou(a, b):
    return shapely.intersection(a, b).area / shapely.union(a, b).area
