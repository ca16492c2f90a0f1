"""Model files in and out of a headless Blender for the command line: import, rig, skin, save, report."""
import contextlib
import pathlib

import bpy
import numpy as np

from ..axes import axes_field, file_axes, to_blender
from ..core import objfile
from ..core.files import replaced_on_success
from . import overlays, skinning
from .armature import delete_armature
from .headless import blender_message, empty_scene
from .pipeline import METHOD_PROPERTY, TARGET_PROPERTY, character_meshes, rig_object, skin_meshes, skin_summary
from .properties import ARMATURE_POINTER


def rig_file(source, output, method, params, *, target="plain", skin=True, up=None, forward=None, animate=None):
    """Rig the meshes of model file ``source`` together as output target ``target`` (``core.targets``), skin them,
    save them with their armature to ``output`` and return the report (bones in the file's frame, the axes it was
    read with, timings, skinning outcome, warnings).

    ``animate``: a BVH file retargeted onto the rig (``rigger.blender.animate``; the game target on a humanoid) and
    saved as its action; the report's ``animation`` says how.

    ``up`` and ``forward`` are the file axes that become Blender's +Z and +Y (``rigger.axes``: OBJ and FBX only; None
    takes the defaults, up Y and forward -Z for OBJ, the file's own axes for FBX).

    The meshes are those the file's scene shows that make the character (``core.scene``: not a floor, nor a mesh
    standing apart): importers' hidden helpers (glTF's bone shapes) and excluded collections are left alone, and so
    are the meshes left out, with a warning each (the output keeps them as they were). Armatures the file already
    deformed them with are replaced: unbound, and deleted when they deform nothing else, so the output holds one
    rig. ValueError when the file cannot be imported, holds no mesh or rigging fails; ``output`` is written only
    after everything succeeded (through a temporary file renamed into place).
    """
    source, output = pathlib.Path(source), pathlib.Path(output)
    axes = file_axes(source.suffix, up, forward)
    empty_scene()
    try:
        *frame, faces = _import(source, axes)
    except RuntimeError as error:
        raise ValueError(f"{source}: Blender could not import it: {blender_message(error)}") from None
    meshes = shown_meshes(bpy.context.view_layer)
    if not meshes:
        raise ValueError(f"{source}: the file holds no mesh with faces that its scene shows")
    meshes.sort(key=lambda obj: -len(obj.data.vertices))
    character, left_out = character_meshes(meshes)
    warnings = [f"left out {mesh.name!r} ({why}): it is saved as it was, unrigged" for mesh, why in left_out]
    imported = sum(len(obj.data.polygons) for obj in bpy.data.objects if obj.type == 'MESH')
    if faces is not None and imported < faces:
        warnings.append(f"Blender's OBJ importer kept {imported} of the file's {faces} faces: it drops those it cannot "
                        f"read (naming a vertex the file lacks, or one vertex twice)")
    warnings += release_from_armatures(character)
    result = rig_object(character[0], method, params, target=target, parts=character[1:])
    warnings += ["replaced the armature Rigger made for the file before"] if result.replaced else []
    outcomes = None
    if skin:
        outcomes, skin_warnings = skin_meshes(character, result.armature)
        warnings += skin_warnings
    animation = None if animate is None else _animated(result, animate)
    save_scene(output, [*meshes, result.armature])
    report = rig_report(result, outcomes, *frame, warnings=warnings, axes=axes)
    if animation is not None:
        report["animation"] = animation
        report["warnings"] += [f"no joint of {pathlib.Path(animate).name} drives {', '.join(animation['undriven'])}; "
                               f"they turn with their parents"] if animation["undriven"] else []
    return {"input": str(source), "output": str(output), "asked_target": target, **report}


def _animated(result, bvh):
    """Retarget ``bvh`` onto the rig of ``result`` (a ``pipeline.RigResult``); ValueError unless the rig is a
    humanoid's game armature."""
    from .animate import animate

    plan = result.skeleton.body_plan
    if result.target.name != "game" or plan is None or plan.kind != "humanoid":
        kind = "unknown" if plan is None else plan.kind
        raise ValueError(f"--animate needs a humanoid game rig, and this {kind} body got the {result.target.name} "
                         f"target: a motion's joints are a human's")
    return animate(result.armature, bvh)


def shown_meshes(view_layer):
    """The mesh objects with faces that ``view_layer`` shows, Rigger's overlays aside."""
    return [obj for obj in view_layer.objects if obj.type == 'MESH' and len(obj.data.polygons)
            and obj.visible_get(view_layer=view_layer) and overlays.KIND_KEY not in obj]


def release_from_armatures(meshes):
    """Unbind ``meshes`` from every armature that deforms them, deleting each such armature that then drives
    nothing else (a glTF or FBX mesh has one skin: the output must hold ours alone); a warning per armature.
    Rigger's own earlier armatures are left to :func:`rig_object`, which replaces them where they hang."""
    armatures = {}
    for mesh in meshes:
        for modifier in mesh.modifiers:
            if modifier.type == 'ARMATURE' and modifier.object not in (None, getattr(mesh, ARMATURE_POINTER, None)):
                armatures[modifier.object.name] = modifier.object
    warnings = []
    for name, armature in armatures.items():
        for mesh in meshes:
            skinning.unbind(mesh, armature)
        if _drives_something(armature):
            warnings.append(f"unbound the rigged meshes from the file's armature {name!r}, which stays for the "
                            f"objects it still drives")
            continue
        delete_armature(armature)
        warnings.append(f"replaced the file's armature {name!r}")
    return warnings


def _drives_something(armature):
    return any(obj.parent == armature or any(modifier.type == 'ARMATURE' and modifier.object == armature
                                             for modifier in obj.modifiers)
               for obj in bpy.data.objects)


def rig_report(result, outcomes, to_world=np.eye(3), frame="blender world", warnings=(), axes=None):
    """The JSON-ready report of a rig: method, parameters, the output target built, the body plan (kind,
    confidence, reason, parts), bones (the built armature's deforming bones, with their roles and sides where the
    target keeps them; mapped from Blender's world into the frame named ``frame`` by the inverse of ``to_world``),
    the (up, forward) ``axes`` the file was read with (None: Blender's importer chose), timings, the skinning outcome
    per mesh (``outcomes``: mesh name → skinning report, or None when not skinned) and warnings (``warnings``, the
    rig's own, meshes rigged together, the skinning's, and last why the body plan was not recognised).

    Timings are plain floats whatever number type the method recorded (numpy scalars are not JSON).
    """
    to_frame = np.eye(4)
    to_frame[:3, :3] = np.linalg.inv(to_world)
    meshes = result.meshes
    warnings = [*warnings, *result.warnings]
    if len(meshes) > 1:
        warnings.append(f"rigged {len(meshes)} mesh objects together: {', '.join(m.name for m in meshes)}")
    skinning_outcome = {"summary": "not skinned", "meshes": {}}
    if outcomes is not None:
        skinning_outcome = {"summary": skin_summary(outcomes),
                            "meshes": {name: report.as_dict() for name, report in outcomes.items()}}
        warnings += [warning for report in outcomes.values() for warning in report.warnings]
    skeleton = result.skeleton
    plan = skeleton.body_plan
    if plan is not None and plan.warning:
        warnings.append(plan.warning)
    timings = {**result.timings, **{f"method.{k}": v for k, v in skeleton.timings.items()}}
    return {
        "frame": frame,
        "axes": axes_field(axes),
        "method": result.armature.get(METHOD_PROPERTY),
        "params": skeleton.params,
        "target": result.armature.get(TARGET_PROPERTY),
        "body_plan": None if plan is None else plan.to_dict(),
        "bones": result.bones.transformed(to_frame).to_dict()["bones"],
        "timings": {name: float(seconds) for name, seconds in timings.items()},
        "skinning": skinning_outcome,
        "warnings": warnings,
    }


def _import(source, axes):
    """Import ``source`` into the empty scene, read with ``axes`` (``rigger.axes.file_axes``); (3x3 matrix from the
    file's frame to Blender's world, the frame's name, the number of faces the file holds for an OBJ, else None)."""
    suffix = source.suffix.lower()
    path = str(source)
    if suffix == ".obj":
        faces = objfile.check(source)  # refuses what the importer would read as 0; counts the faces it may drop
        up, forward = axes
        bpy.ops.wm.obj_import(filepath=path, up_axis=_enum(up), forward_axis=_enum(forward))
        return to_blender(up, forward), f"file (the OBJ's v coordinates, read with up {up}, forward {forward})", faces
    if suffix in (".glb", ".gltf"):
        bpy.ops.import_scene.gltf(filepath=path)
        return to_blender(*axes), "file (glTF, Y up)", None
    if suffix == ".fbx":
        if axes is None:
            bpy.ops.import_scene.fbx(filepath=path)
            return np.eye(3), "blender world (FBX axes and units converted by Blender's importer)", None
        up, forward = axes
        bpy.ops.import_scene.fbx(filepath=path, use_manual_orientation=True, axis_up=up, axis_forward=forward)
        return np.eye(3), f"blender world (FBX read with up {up}, forward {forward}, units converted by Blender's " \
                          f"importer)", None
    if suffix == ".blend":
        bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
        return np.eye(3), "blender world", None
    raise ValueError(f"{source}: unsupported file type {suffix!r}")


def _enum(axis):
    """Blender's OBJ importer's name for ``axis``: 'NEGATIVE_Z' for '-Z'."""
    return axis.replace("-", "NEGATIVE_")


def save_scene(output, objects=None):
    """Save the scene to ``output`` (.blend, .glb or .fbx) through a temporary file renamed into place. glTF and FBX
    get ``objects`` (default: the scene's meshes and armatures, not Rigger's overlays or other helpers)."""
    suffix = output.suffix.lower()
    exported = _exported() if objects is None else objects
    with replaced_on_success(output) as path:
        name = str(path)
        if suffix == ".blend":
            bpy.ops.wm.save_as_mainfile(filepath=name, copy=True)
        elif suffix == ".glb":
            with _selected(exported):
                bpy.ops.export_scene.gltf(filepath=name, export_format='GLB', use_selection=True)
        elif suffix == ".fbx":
            with _selected(exported):
                bpy.ops.export_scene.fbx(filepath=name, use_selection=True, object_types={'ARMATURE', 'MESH'},
                                         add_leaf_bones=False)
        else:
            raise ValueError(f"{output}: unsupported output type {suffix!r}")


def _exported():
    """The objects a glTF or FBX file gets by default: meshes and armatures, not overlays."""
    return [obj for obj in bpy.context.scene.objects
            if obj.type in ('MESH', 'ARMATURE') and overlays.KIND_KEY not in obj]


@contextlib.contextmanager
def _selected(objects):
    """Select exactly ``objects`` for an exporter's use_selection, restoring the selection afterwards."""
    view_layer = bpy.context.view_layer
    before = list(view_layer.objects.selected)
    for obj in before:
        obj.select_set(False)
    for obj in objects:
        obj.select_set(True)
    try:
        yield
    finally:
        for obj in objects:
            obj.select_set(False)
        for obj in before:
            obj.select_set(True)
