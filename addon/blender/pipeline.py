"""Rigging a Blender mesh object: evaluated mesh → method → skeleton → armature (+ overlays), shared by the
operators and the command line so both do exactly the same thing."""
import contextlib
import re
from dataclasses import dataclass

import bpy
import numpy as np

from ..api import rig_mesh
from ..core.scene import character_parts
from ..core.targets import TargetFailed, check_target, choose_target
from ..core.timing import StageClock
from . import overlays, skinning, targets
from .armature import actions_of, delete_armature
from .meshdata import combined_arrays, evaluated_vertices
from .properties import ARMATURE_POINTER
from .rigify import remove_extras

METHOD_PROPERTY = "rigger_method"  # custom property on the armature: the method that made it
TARGET_PROPERTY = "rigger_target"  # ... and the output target it was built as
BONE_PATH = re.compile(r'pose\.bones\["(.+?)"\]')  # an animation curve's path to the pose bone it keys
OVERLAYS_PROPERTY = "rigger_overlays"  # ... and the owner its overlays were drawn for (its mesh's name then)
FAR_SPACING = 0.01  # a mesh whose 32-bit coordinates are this coarse (a share of its size) is too far to rig


@dataclass
class RigResult:
    """What :func:`rig_object` made: the armature object, the meshes it was made for, the method's skeleton (with
    its stages and roles), the ``core.targets.Target`` built and the armature's deforming bones as a skeleton in
    world space (the method's skeleton itself for ``plain``), whether a previous Rigger armature was replaced (and
    what became of its motion, which the new one took over), seconds per step, the overlay objects by stage name (none
    unless asked for) and warnings (a target that fell back, say)."""

    armature: bpy.types.Object
    meshes: list
    skeleton: object
    target: object
    bones: object
    replaced: bool
    timings: dict
    overlays: dict
    warnings: list
    motion: str = None  # what became of the previous armature's motion, in words (None: it had none)


def rig_object(obj, method="silhouette", params=None, *, target="plain", parts=(), show_overlays=None,
               progress=None):
    """Rig mesh object ``obj`` (together with the mesh objects ``parts``, e.g. a character's separate clothes) with
    ``method`` as output target ``target`` (a name in ``core.targets.TARGETS``) and return a :class:`RigResult`.

    The meshes are read as evaluated (modifiers applied, Rigger's previous armatures at rest) in world space. The new
    armature ("<mesh>_rig", identity world matrix, parented to ``obj``'s parent if it has one) goes into the first of
    the mesh's collections shown in the view layer and becomes ``rigger_armature`` of every mesh, replacing
    (deleting) the armatures Rigger made for them before. ``show_overlays`` maps stage names to whether their
    overlays start shown (None: build none; a stage it does not name starts as its type says);
    ``progress(fraction)`` is called between steps. A target the skeleton's body plan cannot fill falls back
    (``core.targets.choose_target``) with a warning, and so does one whose builder fails on it
    (``core.targets.TargetFailed``: Rigify refusing the fitted metarig). ValueError for bad meshes (one too far from
    the origin for Blender's coordinates among them), methods, parameters or targets; nothing is created when
    rigging fails.
    """
    check_target(target)
    report = progress or (lambda fraction: None)
    clock = StageClock()
    meshes = [obj, *(part for part in parts if part != obj)]
    with _without_previous_rigs(meshes):
        vertices, triangles = combined_arrays(meshes)
    clock.lap("read_mesh")
    report(0.1)
    _check_near_origin(vertices)
    skeleton = rig_mesh(vertices, triangles, method, axes=own_axes(obj), **(params or {}))
    chosen, fell_back = choose_target(target, skeleton.body_plan)
    clock.lap("rig")
    report(0.7)
    parent = _rig_parent(obj)
    motion = _previous_motion(meshes)
    replaced = any([remove_rig(mesh) for mesh in meshes])
    collection = shown_collection(obj, bpy.context.view_layer)
    frame = np.array(obj.matrix_world, dtype=np.float64)[:3, :3]
    while True:
        try:
            built = targets.build(chosen, skeleton, f"{obj.name}_rig", collection, frame, mesh=(vertices, triangles))
            break
        except TargetFailed as error:  # nothing of it is left behind: the target it falls back to instead
            chosen, further = choose_target(chosen.fallback, skeleton.body_plan)
            fell_back = "; ".join(filter(None, [fell_back, f"{error}: built the {chosen.name} target instead",
                                                further]))
    armature = built.armature
    if parent is not None:  # skinning makes the mesh the armature's child: the rig keeps following what moved it
        armature.parent = parent
        armature.matrix_parent_inverse = parent.matrix_world.inverted_safe()
    carried = _take_motion(armature, *motion) if motion is not None else None
    armature[METHOD_PROPERTY] = method if isinstance(method, str) else method.name
    armature[TARGET_PROPERTY] = chosen.name
    for mesh in meshes:
        setattr(mesh, ARMATURE_POINTER, armature)
    clock.lap("armature")
    report(0.8)
    drawn = {}
    if show_overlays is not None:
        drawn = overlays.build_overlays(skeleton.stages, obj.name, visible=show_overlays)
        armature[OVERLAYS_PROPERTY] = obj.name
        clock.lap("overlays")
    report(1.0)
    warnings = [fell_back] if fell_back else []
    return RigResult(armature, meshes, skeleton, chosen, built.bones, replaced, clock.laps, drawn,
                     warnings + built.warnings, carried)


def _check_near_origin(vertices):
    """ValueError when the mesh lies so far from the origin that Blender's 32-bit coordinates there are coarser than
    ``FAR_SPACING`` of its size: its shape is lost (vertices collapse onto a few points) and a rig's bones would be
    too."""
    if not len(vertices):
        return
    far = float(np.abs(vertices).max())
    spacing = far * 2.0 ** -23  # between neighbouring 32-bit floats that large
    size = float(np.ptp(vertices, axis=0).max())
    if 0 < FAR_SPACING * size < spacing:  # a mesh of no size is rig_mesh's to refuse
        raise ValueError(f"the mesh lies {far:.3g} from the origin, where Blender's coordinates are {spacing:.3g} "
                         f"apart: too coarse for a mesh {size:.3g} across; move it near the origin")


def _previous_motion(meshes):
    """The motion of the armature Rigger made for ``meshes`` before, to carry over to the new one (on the bones of the
    same names): (its action, its NLA tracks as [(name, [(strip name, start frame, action)])], each action's
    fake-user flag, each pose bone's rotation mode), or None. The actions are held by a fake user meanwhile (deleting
    an armature deletes the actions nothing else uses; they keep it if the new rig fails, so no motion is lost)."""
    armature = next((getattr(mesh, ARMATURE_POINTER) for mesh in meshes if getattr(mesh, ARMATURE_POINTER, None)),
                    None)
    animation = armature.animation_data if armature is not None else None
    if animation is None:
        return None
    tracks = [(track.name, [(strip.name, strip.frame_start, strip.action) for strip in track.strips if strip.action])
              for track in animation.nla_tracks]
    actions = actions_of(animation)
    if not actions:
        return None
    flags = {action: action.use_fake_user for action in actions}
    for action in actions:
        action.use_fake_user = True
    return animation.action, tracks, flags, {bone.name: bone.rotation_mode for bone in armature.pose.bones}


def _take_motion(armature, action, tracks, flags, rotation_modes):
    """Give ``armature`` the previous armature's motion (``_previous_motion``); a few words on it for the report:
    whether it keys any of the new bones."""
    for each, flag in flags.items():
        each.use_fake_user = flag
    for bone in armature.pose.bones:
        bone.rotation_mode = rotation_modes.get(bone.name, bone.rotation_mode)
    animation = armature.animation_data_create()
    if action is not None:
        animation.action = action
        _slotted(animation, action)
    for name, strips in tracks:
        track = animation.nla_tracks.new()
        track.name = name
        for strip_name, start, strip_action in strips:
            _slotted(track.strips.new(strip_name, int(start), strip_action), strip_action)
    names = ", ".join(sorted(repr(each.name) for each in flags))
    if _keyed_bones(flags) & set(armature.pose.bones.keys()):
        return f"its animation {names} goes on, on the bones of the same names"
    return f"its animation {names} is kept, but keys none of the new bones"


def _slotted(user, action):
    """Give ``user`` (animation data or an NLA strip) the action's first slot where it took none (Blender 4.4+)."""
    if getattr(user, "action_slot", False) is None and len(getattr(action, "slots", ())):
        user.action_slot = action.slots[0]


def _keyed_bones(actions):
    """The names of the pose bones ``actions`` key (their curves: the action's own before Blender 4.4, its layers'
    channel bags since)."""
    curves = []
    for action in actions:
        curves += list(getattr(action, "fcurves", ()) or ())
        for layer in getattr(action, "layers", ()):
            for strip in layer.strips:
                for bag in getattr(strip, "channelbags", ()):
                    curves += list(bag.fcurves)
    return {match.group(1) for curve in curves if (match := BONE_PATH.match(curve.data_path))}


def character_meshes(meshes):
    """(the ``meshes`` that make the character, [(mesh, why it is left out)]): ``core.scene.character_parts``, the
    first mesh the main one (a floor or a crate standing apart, box-selected or in a file with the character, stays
    out of its rig)."""
    if len(meshes) < 2:
        return list(meshes), []
    depsgraph = bpy.context.evaluated_depsgraph_get()
    kept, left = character_parts([(mesh.name, evaluated_vertices(mesh, depsgraph)) for mesh in meshes])
    return [meshes[k] for k in kept], [(meshes[k], why) for k, why in left]


def own_axes(obj):
    """The axes ``rig_mesh`` rigs ``obj`` along: its own X, Y, Z in the world (rows; the one a mirroring scale
    flips is taken back), when they are off the world's axes (a character turned 30° about Z to face a camera), else
    None: an object square to the world (turned by quarter turns, or not at all) rigs along the world's own."""
    left, _, right = np.linalg.svd(np.array(obj.matrix_world, dtype=np.float64)[:3, :3])
    rotation = left @ right  # the nearest orthogonal matrix (polar factor): scale and shear left out
    if np.linalg.det(rotation) < 0:
        rotation[:, 2] = -rotation[:, 2]  # the same three axes, one reversed: a rotation
    if np.allclose(np.abs(rotation).max(axis=0), 1.0, atol=1e-6):
        return None
    return rotation.T


@contextlib.contextmanager
def _without_previous_rigs(meshes):
    """Turn off, meanwhile, the Armature modifiers by which the armatures Rigger made for ``meshes`` deform them: a
    mesh is rigged as it rests, not as the old rig posed it (rigging again removes the old rig, and the pose with
    it), and exactly so (an armature at its rest pose still moves vertices by float rounding, and a rig made of
    those differs from the first where a choice is close)."""
    armatures = {getattr(mesh, ARMATURE_POINTER, None) for mesh in meshes} - {None}
    modifiers = [modifier for mesh in meshes for modifier in mesh.modifiers
                 if modifier.type == 'ARMATURE' and modifier.object in armatures and modifier.show_viewport]
    for modifier in modifiers:
        modifier.show_viewport = False
    try:
        yield
    finally:
        for modifier in modifiers:
            modifier.show_viewport = True


def _rig_parent(obj):
    """The object the new armature hangs from: the mesh's parent, or the parent of the Rigger armature the mesh is
    bound to (about to be replaced)."""
    parent = obj.parent
    if parent is not None and parent == getattr(obj, ARMATURE_POINTER, None):
        parent = parent.parent
    return parent


def shown_collection(obj, view_layer):
    """The first of ``obj``'s collections that ``view_layer`` shows, else the scene's own: an armature put into an
    excluded collection could not be made active for editing, and one in a hidden collection would be invisible."""
    shown = []
    layers = [view_layer.layer_collection]
    while layers:
        layer = layers.pop()
        if layer.is_visible:
            shown.append(layer.collection)
            layers.extend(layer.children)
    return next((collection for collection in obj.users_collection if collection in shown),
                bpy.context.scene.collection)


def skin_meshes(meshes, armature, progress=None):
    """Skin every mesh of ``meshes`` to ``armature``, then let its output target finish the weights
    (``targets.skinned``): {mesh name: skinning report}, and warnings of our own.

    Weights live in the mesh data, so a mesh object sharing its data with other objects (a linked duplicate) first
    gets its own copy: otherwise skinning one copy would rewrite the weights of the others.
    """
    outcomes, warnings = {}, []
    for done, mesh in enumerate(meshes, start=1):
        if mesh.data.users > 1:
            warnings.append(f"{mesh.name} shared its mesh data {mesh.data.name!r} with other objects; it got its own "
                            f"copy so that its weights are its own")
            mesh.data = mesh.data.copy()
        outcomes[mesh.name] = skinning.skin(mesh, armature)
        targets.skinned(armature.get(TARGET_PROPERTY), mesh, armature, outcomes[mesh.name])
        if progress is not None:
            progress(done / len(meshes))
    return outcomes, warnings


def skin_summary(outcomes):
    """One line for the ``skin_meshes`` reports: each report's summary (each names its mesh)."""
    return "; ".join(outcome.summary() for outcome in outcomes.values())


def remove_rig(obj):
    """Delete the armature Rigger made for ``obj`` earlier (with what its target made beside it: Rigify's metarig
    and widgets; and its overlays), and unbind every mesh made with it (their Armature modifiers, Rigger's vertex
    groups, the parenting; meshes keep their place). True when there was one."""
    armature = getattr(obj, ARMATURE_POINTER, None)
    if armature is None:
        return False
    for mesh in [o for o in bpy.data.objects if getattr(o, ARMATURE_POINTER, None) == armature]:
        skinning.unbind(mesh, armature)
        setattr(mesh, ARMATURE_POINTER, None)
    remove_extras(armature)
    if OVERLAYS_PROPERTY in armature:  # drawn for the mesh under the name it had then
        overlays.remove_overlays(armature[OVERLAYS_PROPERTY])
    delete_armature(armature)
    return True
