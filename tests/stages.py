"""Reading a skeleton's stage data as the stage interface defines it (bpy-free, for the method and overlay tests)."""
import numpy as np


def lift(stages, points):
    """Silhouette-plane points (P, 2) to 3D: on the plane through the mesh's centroid, across the view."""
    frame = stages["silhouette"]
    points = np.asarray(points)
    return (frame["origin"] + frame["depth"] * frame["direction"] + points[:, :1] * frame["u"]
            + points[:, 1:] * frame["v"])
