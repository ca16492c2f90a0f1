"""A skeleton built as the armature of an output target (``rigger.core.targets`` says which target a body plan
fills): one builder per target, each making the armature and saying which bones deform."""
from dataclasses import dataclass, field

import bpy

from ..core.skeleton import Skeleton
from . import game
from .armature import build_armature
from .rigify import build_rigify


@dataclass
class Built:
    """What a target's builder made: the ``armature`` object to skin to, its deforming ``bones`` as a skeleton in
    world space (what reports list), the other ``objects`` it made and ``warnings``."""

    armature: bpy.types.Object
    bones: Skeleton
    objects: list = field(default_factory=list)
    warnings: list = field(default_factory=list)


def build(target, skeleton, name, collection, frame, mesh=None):
    """Build ``skeleton`` as ``target``'s armature (a ``core.targets.Target``) named ``name`` in ``collection``;
    ``frame`` is the rigged object's rotation (``armature.build_armature``), ``mesh`` the rigged (vertices,
    triangles) in world space. A :class:`Built`."""
    return BUILDERS[target.name](skeleton, name, collection, frame, mesh)


def skinned(target, mesh_obj, armature, report):
    """What target ``target`` (its name) does after ``mesh_obj`` was skinned to its ``armature`` (the game target
    keeps at most 4 weights per vertex); it notes that as a stage of the skinning ``report``."""
    finish = FINISHERS.get(target)
    if finish is not None:
        finish(mesh_obj, armature, report)


def _plain(skeleton, name, collection, frame, mesh=None):
    """The method's bones as they are."""
    return Built(build_armature(skeleton, name, collection, frame=frame), skeleton)


BUILDERS = {"plain": _plain, "game": game.build, "rigify": build_rigify}
FINISHERS = {"game": game.finish_skin}
