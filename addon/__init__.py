"""Rigger: automatic rigging of arbitrary meshes.

Importable outside Blender as ``rigger``: the geometry core (``rigger.cdt``, ``rigger.silhouette``, methods) needs
only numpy and the bundled compiled modules.
"""


def __getattr__(name):
    """Load ``rig_mesh`` and ``Skeleton`` on first use: ``import rigger`` stays cheap and never needs numpy or bpy."""
    if name == "rig_mesh":
        from .api import rig_mesh
        return rig_mesh
    if name == "Skeleton":
        from .core.skeleton import Skeleton
        return Skeleton
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
