"""The ``game`` target in Blender: the armature of ``rigger.core.game``'s skeleton, and at most ``INFLUENCES``
normalised weights per vertex after skinning (what game engines take: glTF's one JOINTS_0/WEIGHTS_0 set)."""
import time

import numpy as np

from ..core.game import ROOT, game_skeleton, missing_humanoid_bones
from .armature import build_armature
from .skinning import SkinStage

INFLUENCES = 4


def build(skeleton, name, collection, frame, mesh=None):
    """The game armature of Rigger's ``skeleton`` (``core.game.game_skeleton``) rigging ``mesh`` ((vertices,
    triangles) in world space; the ground is its lowest point), as a ``blender.targets.Built``. The ``root`` bone
    deforms nothing; its bones are the report's ``bones``."""
    from .targets import Built

    if mesh is None:
        raise ValueError("the game target needs the rigged mesh (its ground is the mesh's lowest point)")
    game = game_skeleton(skeleton, mesh[0])
    armature = build_armature(game.skeleton, name, collection, frame=frame)
    armature.data.bones[ROOT].use_deform = False
    missing = missing_humanoid_bones(game.skeleton.names) if skeleton.body_plan.kind == "humanoid" else []
    warnings = [f"the humanoid's game rig has no {', '.join(missing)}: Rigger's skeleton shows no such part, and "
                f"a motion's joints for them drive nothing"] if missing else []
    return Built(armature, game.skeleton, warnings=warnings)


def finish_skin(mesh_obj, armature, report):
    """Keep each vertex's ``INFLUENCES`` largest weights of ``armature``'s deforming bones (ties: the bone first in
    the armature), normalised to sum 1; a stage of the skinning ``report`` says how many vertices lost some. The same
    weights in give the same weights out, so a seam's welded copies stay alike."""
    started = time.perf_counter()
    trimmed = limit_influences(mesh_obj, armature, INFLUENCES)
    report.stages.append(SkinStage(f"at most {INFLUENCES} influences", time.perf_counter() - started,
                                   note=f"{trimmed} vertices kept their {INFLUENCES} largest weights"))


def limit_influences(mesh_obj, armature, count):
    """Keep at most ``count`` weights of ``armature``'s deforming bones per vertex of ``mesh_obj``, normalised;
    zero weights go too, vertex groups of other bones stay. Returns how many vertices lost weights."""
    order = {bone.name: k for k, bone in enumerate(armature.data.bones) if bone.use_deform}
    groups = {group.index: group for group in mesh_obj.vertex_groups if group.name in order}
    rank = {index: order[group.name] for index, group in groups.items()}
    trimmed = 0
    for vertex in mesh_obj.data.vertices:
        entries = [(element.group, element.weight) for element in vertex.groups if element.group in groups]
        if not entries:
            continue
        entries.sort(key=lambda entry: (-entry[1], rank[entry[0]]))
        kept = [entry for entry in entries[:count] if entry[1] > 0]
        dropped = [entry for entry in entries if entry not in kept]
        total = sum(weight for _, weight in kept)
        for group, _ in dropped:
            groups[group].remove([vertex.index])
        if dropped or not np.isclose(total, 1.0):
            for group, weight in kept:
                groups[group].add([vertex.index], weight / total, 'REPLACE')
        trimmed += any(weight > 0 for _, weight in dropped)
    return trimmed
