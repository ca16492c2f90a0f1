"""Rigger: automatic rigging of arbitrary meshes.

Importable outside Blender as ``rigger``: the geometry core (``rigger.cdt``, ``rigger.silhouette``, methods) needs
only numpy and the bundled compiled modules. Inside Blender, ``register()`` loads the Blender layer
(``rigger.blender``): the generated method properties, the operators
``rigger.rig|skin|rig_skin|clear_overlays|direction_from_view`` and the panel in View3D > Sidebar > Rigger.
"""

bl_info = {
    "name": "Rigger",
    "author": "Rigger developers",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "View3D > Sidebar > Rigger",
    "description": "Automatic rigging: skeleton from the mesh's silhouette, armature, skinning, stage overlays",
    "category": "Rigging",
}


def register():
    """Register the Blender UI; when the compiled modules do not load here (a zip for another platform or Blender),
    register only a panel saying what is wrong and which zip to install."""
    from .compat import compiled_problem
    problem = compiled_problem()
    if problem:
        from .blender import problem as problem_panel
        problem_panel.register(problem)
        return
    from .blender import registration
    registration.register()


def unregister():
    from .blender import problem as problem_panel
    if problem_panel.unregister():  # the problem panel stood in for the real UI
        return
    from .blender import registration
    registration.unregister()


def __getattr__(name):
    """Load ``rig_mesh`` and ``Skeleton`` on first use: ``import rigger`` stays cheap and never needs numpy or bpy."""
    if name == "rig_mesh":
        from .api import rig_mesh
        return rig_mesh
    if name == "Skeleton":
        from .core.skeleton import Skeleton
        return Skeleton
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
