"""The ``rigify`` output target: the Rigify metarig that ``core.metarig`` chooses for the body plan, fitted to the
skeleton and generated into a control rig by Blender's bundled Rigify add-on.

The metarig is added with Rigify's own operator (its rig types, parameters and bone collections are Rigify's), its
bones are read as ``core.metarig.MetaBone`` data, moved where ``core.metarig.fit_metarig`` puts them (bones the model
lacks removed, their children hung from the nearest kept bone above) and generated into the armature the pipeline
skins to. The metarig is kept, hidden, beside the rig: unhide it, edit it and press Generate Rig to regenerate the
same rig, as in Rigify (the mesh stays bound: Rigify keeps the rig object and its DEF bone names).

Rigify works in the armature's own space with Z up and the front at -Y; the metarig and the rig get the character's
frame (``Fit.frame``) as their rotation, so a model facing any way gets IK controls that point the right way.
Rigify generates the rig without the metarig's transform and keeps the rig's own when regenerating, so the rig gets
the metarig's once, after the first generation.
"""
import contextlib
import io

import addon_utils
import bpy
import numpy as np
from mathutils import Matrix, Vector

from ..core.metarig import METARIGS, MetaBone, choose_metarig, fit_metarig
from ..core.roles import BoneRole
from ..core.skeleton import Skeleton
from ..core.targets import TargetFailed
from .headless import blender_message
from .meshdata import world_points

ADDON = "rigify"
METARIG_PROPERTY = "rigger_metarig"  # custom property on the generated rig: its metarig object
KIND_PROPERTY = "rigger_metarig_kind"  # custom property on the metarig: which of Rigify's metarigs it is
DEFORM_PREFIX, ORIGINAL_PREFIX = "DEF-", "ORG-"  # Rigify's deforming bones and the metarig's bones in the rig
SHORTEST_BONE = 1e-4  # the shortest metarig bone built (Blender lengthens bones under about 1e-6)


def ensure_rigify():
    """Enable Blender's bundled Rigify add-on unless it is enabled already; ValueError saying how when it cannot
    be."""
    if hasattr(bpy.types, "ARMATURE_MT_rigify_metarigs") or addon_utils.check(ADDON)[1]:
        return
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            module = addon_utils.enable(ADDON, default_set=True)
    except Exception as error:  # noqa: BLE001 - any failure of a third-party add-on's registration
        module, why = None, f": {type(error).__name__}: {error}"
    else:
        why = ""
    if module is None or not hasattr(bpy.ops.pose, "rigify_generate"):
        raise ValueError(f"the rigify target needs Blender's bundled Rigify add-on, which could not be enabled{why}; "
                         f"enable Rigify in Edit > Preferences > Add-ons, or choose another target")


def build_rigify(skeleton, name, collection, frame, mesh=None):
    """The ``rigify`` target's builder (``blender.targets.build``): a ``targets.Built`` whose armature is the rig
    Rigify generated, named ``name``, its DEF bones as ``bones`` and the metarig (hidden) in ``objects``.
    ``mesh`` is the rigged (vertices, triangles) in the world, for the heels; ``frame`` is not needed (the fit finds
    the character's own). ValueError when no metarig fits or Rigify fails; nothing is left behind then."""
    from .targets import Built  # targets imports this module for its BUILDERS

    if mesh is None:
        raise ValueError("the rigify target needs the rigged mesh (for the heels)")
    ensure_rigify()
    metarig_name = choose_metarig(skeleton)
    _object_mode()
    metarig = add_metarig(metarig_name, f"{name}_metarig", collection)
    rig = None
    try:
        fit = fit_metarig(skeleton, mesh, metarig_name, read_metarig(metarig))
        scale = working_scale(fit)
        metarig.matrix_world = Matrix(fit.frame.tolist()).to_4x4() @ Matrix.Scale(1.0 / scale, 4)
        place_bones(metarig, fit, scale)
        rig = bpy.data.objects.new(name, bpy.data.armatures.new(name))
        collection.objects.link(rig)
        generate(metarig, rig)
        rig.matrix_world = metarig.matrix_world
    except Exception:
        remove_generated(metarig, rig)
        raise
    rig[METARIG_PROPERTY] = metarig
    metarig.hide_set(True)
    metarig.hide_render = True
    warnings = [f"Rigify's {metarig_name} metarig: {note}" for note in fit.notes]
    return Built(rig, deform_skeleton(rig, fit.roles), [metarig], warnings)


def _object_mode():
    if bpy.context.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')


def add_metarig(metarig_name, name, collection):
    """Rigify's metarig ``metarig_name`` (``human``, ``basic_quadruped``, ...) as a new object ``name`` at the origin,
    in ``collection`` only, with the bones ``core.metarig`` adds to it (``MetarigSpec.added``)."""
    operator = getattr(bpy.ops.object, f"armature_{metarig_name}_metarig_add", None)
    if operator is None:
        raise ValueError(f"Rigify has no {metarig_name} metarig in this Blender")
    before = set(bpy.data.objects)
    with contextlib.redirect_stdout(io.StringIO()):
        operator()
    metarig = next(obj for obj in bpy.data.objects if obj not in before and obj.type == 'ARMATURE')
    metarig.name = metarig.data.name = name
    metarig[KIND_PROPERTY] = metarig_name
    for other in list(metarig.users_collection):
        other.objects.unlink(metarig)
    collection.objects.link(metarig)
    metarig.matrix_world = Matrix.Identity(4)
    added = METARIGS[metarig_name].added
    if added:
        _edit(metarig, lambda bones: [_new_bone(bones, bone) for bone, _ in added])
        for bone, rig_type in added:
            metarig.pose.bones[bone.name].rigify_type = rig_type
    return metarig


def _new_bone(bones, data):
    bone = bones.new(data.name)
    bone.head, bone.tail = Vector(data.head), Vector(data.tail)
    bone.align_roll(Vector(data.z_axis))
    bone.parent = bones[data.parent]
    bone.use_connect = data.connected


def _edit(armature, change):
    """Run ``change(edit_bones)`` on ``armature`` in Edit Mode, back in Object Mode after."""
    view_layer = bpy.context.view_layer
    view_layer.objects.active = armature
    armature.select_set(True)
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        change(armature.data.edit_bones)
    finally:
        bpy.ops.object.mode_set(mode='OBJECT')


def read_metarig(metarig):
    """The bones of metarig object ``metarig`` as ``core.metarig.MetaBone`` data, in its own frame."""
    bones = []
    for bone in metarig.data.bones:
        bones.append(MetaBone(bone.name, tuple(bone.head_local), tuple(bone.tail_local),
                              bone.parent.name if bone.parent else None, tuple(bone.matrix_local.col[2][:3]),
                              bone.use_connect))
    return bones


def working_scale(fit):
    """1, or the power of two (exact) by which the metarig's bones are magnified in its own space, its object
    shrinking them back, so that the shortest fitted bone is at least ``SHORTEST_BONE`` long: Blender lengthens
    shorter bones, which then no longer meet their parents, and Rigify's chains break (a model made in metres
    read as kilometres)."""
    shortest = min(float(np.linalg.norm(np.subtract(fit.tails[name], fit.heads[name]))) for name in fit.heads)
    if shortest >= SHORTEST_BONE:
        return 1.0
    return float(2.0 ** np.ceil(np.log2(SHORTEST_BONE / max(shortest, 1e-300))))


def place_bones(metarig, fit, scale=1.0):
    """Move the metarig's bones where ``fit`` (a ``core.metarig.Fit``) puts them, magnified ``scale`` times
    (``working_scale``), remove the ones it removed (their children hang from the nearest kept bone above) and roll
    each as the metarig rolled it; a bone stays connected to its parent where its head still lies on the parent's
    tail."""
    def change(bones):
        connected = {bone.name for bone in bones if bone.use_connect}
        ends = scale * np.array([end for name in fit.heads for end in (fit.heads[name], fit.tails[name])])
        size = max(float(np.ptp(ends, axis=0).max()), 1e-300)
        removed = set(fit.removed)
        for bone in bones:
            bone.use_connect = False
        for bone in bones:
            parent = bone.parent
            while parent is not None and parent.name in removed:
                parent = parent.parent
            bone.parent = parent
        for name in fit.removed:
            bones.remove(bones[name])
        for name in fit.heads:
            bone = bones[name]
            bone.head = Vector(scale * np.asarray(fit.heads[name]))
            bone.tail = Vector(scale * np.asarray(fit.tails[name]))
            bone.align_roll(Vector(fit.z_axes[name]))
        for bone in bones:
            if bone.name in connected and bone.parent is not None and \
                    (bone.head - bone.parent.tail).length <= 1e-6 * size:
                bone.use_connect = True

    _edit(metarig, change)


def generate(metarig, rig):
    """Rigify's Generate Rig from ``metarig`` into armature object ``rig``; ``core.targets.TargetFailed`` with
    Rigify's message when it fails."""
    metarig.data.rigify_target_rig = rig
    view_layer = bpy.context.view_layer
    for other in view_layer.objects.selected:
        other.select_set(False)
    view_layer.objects.active = metarig
    metarig.select_set(True)
    printed = io.StringIO()
    before = set(bpy.data.armatures)
    try:  # Rigify prints its progress, and a traceback when it fails: the error says what went wrong
        with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
            result = bpy.ops.pose.rigify_generate()
    except RuntimeError as error:
        raise TargetFailed(f"Rigify could not generate the rig: {blender_message(error)}") from None
    finally:  # the copy of the metarig's armature Rigify generates from, left unused
        for data in [data for data in bpy.data.armatures if data not in before and data.users == 0]:
            bpy.data.armatures.remove(data)
    if 'FINISHED' not in result:
        raise TargetFailed(f"Rigify could not generate the rig: {printed.getvalue().strip()[-300:]}")
    _object_mode()


def deform_skeleton(rig, roles=None):
    """The rig's deforming bones as a ``Skeleton`` in the world: each hangs from the nearest deforming bone above it,
    where a metarig bone (``ORG-``) above stands for its own ``DEF-`` bone. With ``roles`` ({metarig bone:
    ``BoneRole``}, ``Fit.roles``) each gets the role of the metarig bone it deforms for (Rigify splits a limb bone
    into ``DEF-thigh.L`` and ``DEF-thigh.L.001``), counted along its chain."""
    deform = [bone for bone in rig.data.bones if bone.use_deform]
    index = {bone.name: k for k, bone in enumerate(deform)}
    parents = []
    for bone in deform:
        parent, found = bone.parent, -1
        while parent is not None and found < 0:
            twin = DEFORM_PREFIX + parent.name[len(ORIGINAL_PREFIX):] if parent.name.startswith(ORIGINAL_PREFIX) \
                else None
            if parent.name in index:
                found = index[parent.name]
            elif twin in index and twin != bone.name:
                found = index[twin]
            parent = parent.parent
        parents.append(found)
    ends = np.array([(bone.head_local, bone.tail_local) for bone in deform], dtype=np.float64)
    world = world_points(ends, rig.matrix_world)
    skeleton = Skeleton([bone.name for bone in deform], world[:, 0], world[:, 1], np.array(parents, dtype=np.int32))
    if roles is not None:
        skeleton.roles = _counted([_metarig_role(bone.name, roles) for bone in deform])
    return skeleton


def _metarig_role(name, roles):
    """The role of DEF bone ``name``: its metarig bone's (``DEF-thigh.L.001`` deforms for ``thigh.L``)."""
    base = name[len(DEFORM_PREFIX):]
    if base not in roles and len(base) > 4 and base[-4] == "." and base[-3:].isdigit():
        base = base[:-4]
    return roles.get(base, BoneRole("other"))


def _counted(roles):
    """``roles`` with each one's index counted along the bones of its role, side and digit, in order."""
    counts, counted = {}, []
    for role in roles:
        key = (role.role, role.side, role.digit)
        counted.append(BoneRole(role.role, role.side, counts.get(key, 0), role.digit))
        counts[key] = counts.get(key, 0) + 1
    return counted


def remove_generated(metarig, rig):
    """Remove what generating ``rig`` from ``metarig`` made: the rig (its armature data unless shared), Rigify's
    widgets collection and its objects, its rig UI script and the metarig."""
    if metarig is not None:
        widgets = getattr(metarig.data, "rigify_widgets_collection", None)
        if widgets is not None:
            for obj in list(widgets.all_objects):
                data = obj.data
                bpy.data.objects.remove(obj)
                if data is not None and data.users == 0:
                    bpy.data.meshes.remove(data)
            bpy.data.collections.remove(widgets)
        script = getattr(metarig.data, "rigify_rig_ui", None)
        if script is not None:
            bpy.data.texts.remove(script)
        data = metarig.data
        bpy.data.objects.remove(metarig)
        if data.users == 0:
            bpy.data.armatures.remove(data)
    if rig is not None:
        data = rig.data
        bpy.data.objects.remove(rig)
        if data.users == 0:
            bpy.data.armatures.remove(data)


def remove_extras(armature):
    """Before Rigger removes ``armature``: when Rigify generated it, remove its metarig, widgets and rig UI script
    too (``pipeline.remove_rig``)."""
    metarig = armature.get(METARIG_PROPERTY)
    if isinstance(metarig, bpy.types.Object) and metarig.name in bpy.data.objects:
        remove_generated(metarig, None)
