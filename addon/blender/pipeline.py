"""Rigging a Blender mesh object: evaluated mesh → method → skeleton → armature (+ overlays), shared by the
operators and the command line so both do exactly the same thing."""
import time
from dataclasses import dataclass, field

import bpy
import numpy as np

from ..api import rig_mesh
from . import overlays, skinning
from .armature import build_armature
from .meshdata import combined_arrays
from .properties import ARMATURE_POINTER

METHOD_PROPERTY = "rigger_method"  # custom property on the armature: the method that made it


@dataclass
class RigResult:
    """What :func:`rig_object` made: the armature object, the meshes it was made for, the skeleton (with its
    stages), the overlay objects by kind, whether a previous Rigger armature was replaced, and seconds per step."""

    armature: bpy.types.Object
    meshes: list
    skeleton: object
    overlays: dict
    replaced: bool
    timings: dict = field(default_factory=dict)


def rig_object(obj, method="silhouette", params=None, *, parts=(), show_overlays=None, progress=None):
    """Rig mesh object ``obj`` (together with the mesh objects ``parts``, e.g. a character's separate clothes) with
    ``method`` and return a :class:`RigResult`.

    The meshes are read as evaluated (modifiers applied) in world space; the new armature ("<mesh>_rig", identity
    matrix) goes into the mesh's first collection and becomes ``rigger_armature`` of every mesh, replacing (deleting)
    the armatures Rigger made for them before. ``show_overlays`` maps overlay kinds to visibility (None: build none);
    ``progress(fraction)`` is called between steps. ValueError for bad meshes, methods or parameters; nothing is
    created when rigging fails.
    """
    report = progress or (lambda fraction: None)
    timings = {}
    start = time.perf_counter()
    meshes = [obj, *(part for part in parts if part != obj)]
    vertices, triangles = combined_arrays(meshes)
    timings["read_mesh"] = time.perf_counter() - start
    report(0.1)
    skeleton = rig_mesh(vertices, triangles, method, **(params or {}))
    timings["rig"] = time.perf_counter() - start - sum(timings.values())
    report(0.7)
    replaced = any([remove_rig(mesh) for mesh in meshes])
    collection = obj.users_collection[0] if obj.users_collection else bpy.context.scene.collection
    frame = np.array(obj.matrix_world, dtype=np.float64)[:3, :3]
    armature = build_armature(skeleton, f"{obj.name}_rig", collection, frame=frame)
    armature[METHOD_PROPERTY] = method if isinstance(method, str) else method.name
    for mesh in meshes:
        setattr(mesh, ARMATURE_POINTER, armature)
    timings["armature"] = time.perf_counter() - start - sum(timings.values())
    report(0.8)
    made = {}
    if show_overlays is not None:
        made = overlays.build_overlays(skeleton.stages, obj.name, visible=show_overlays)
        timings["overlays"] = time.perf_counter() - start - sum(timings.values())
    report(1.0)
    return RigResult(armature, meshes, skeleton, made, replaced, timings)


def remove_rig(obj):
    """Delete the armature Rigger made for ``obj`` earlier, and unbind every mesh made with it (their Armature
    modifiers, Rigger's vertex groups, the parenting; meshes keep their place). True when there was one."""
    armature = getattr(obj, ARMATURE_POINTER, None)
    if armature is None:
        return False
    for mesh in [o for o in bpy.data.objects if getattr(o, ARMATURE_POINTER, None) == armature]:
        skinning.unbind(mesh, armature)
        setattr(mesh, ARMATURE_POINTER, None)
    data = armature.data
    bpy.data.objects.remove(armature)
    if data.users == 0:
        bpy.data.armatures.remove(data)
    return True
