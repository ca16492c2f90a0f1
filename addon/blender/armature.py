"""A :class:`~rigger.core.skeleton.Skeleton` as a Blender armature object, ready to edit or skin."""
import bpy
import numpy as np

CONNECT_TOLERANCE = 1e-6  # a head within this fraction of the skeleton's size from its parent's tail is connected
VERTICAL = 0.95  # bones more aligned with world Z than this (|cos|) take their roll from the front axis instead


def build_armature(skeleton, name, collection=None, frame=None):
    """A new armature object ``name`` holding ``skeleton``'s bones (heads and tails in world space).

    The object sits at the origin with an identity matrix, so bone coordinates equal world coordinates. Parents
    follow the skeleton; a bone is connected to its parent where its head meets the parent's tail. Rolls follow one
    rule for every bone: the bone's Z axis points as close to the character's up as the bone allows (to its front,
    -Y, for near-vertical bones), so mirrored limbs get mirrored rolls. ``frame`` is a 3x3 matrix whose columns are
    the character's X, Y, Z axes in world space (the rigged object's rotation; default the world axes). Returns the
    object, in Object Mode, linked into ``collection`` (default: the scene's) and made active. If that fails, the
    half-made armature is removed again before the error propagates.
    """
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    obj.show_in_front = True
    try:
        (collection or bpy.context.scene.collection).objects.link(obj)
        _edit_bones(obj, skeleton, np.eye(3) if frame is None else _orthonormal(frame))
    except Exception:
        delete_armature(obj)
        raise
    return obj


def delete_armature(obj):
    """Remove armature object ``obj``, and its armature data and actions (its own and its NLA strips') unless
    something else uses them too: an exporter writes the actions it finds, and the file's old motion does not fit
    the new bones."""
    data = obj.data
    actions = actions_of(obj.animation_data)
    bpy.data.objects.remove(obj)
    if data.users == 0:
        bpy.data.armatures.remove(data)
    for action in actions:
        if action.users == 0:
            bpy.data.actions.remove(action)


def actions_of(animation):
    """The actions of ``animation`` (an object's animation data, or None): its own and its NLA strips'."""
    if animation is None:
        return set()
    strips = {strip.action for track in animation.nla_tracks for strip in track.strips}
    return (strips | {animation.action}) - {None}


def _edit_bones(obj, skeleton, frame):
    """Make ``obj`` the only selected and active object and add the bones in Edit Mode, back in Object Mode after."""
    view_layer = bpy.context.view_layer
    if bpy.context.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for other in view_layer.objects.selected:
        other.select_set(False)
    view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        _add_bones(obj.data, skeleton, frame)
    finally:
        bpy.ops.object.mode_set(mode='OBJECT')


def _add_bones(data, skeleton, frame):
    size = skeleton.extent
    bones = []
    for name, head, tail in zip(skeleton.names, skeleton.heads, skeleton.tails):
        bone = data.edit_bones.new(name)
        bone.head, bone.tail = head, tail
        bone.align_roll(_roll_reference(tail - head, frame))
        bones.append(bone)
    for index, parent in enumerate(skeleton.parents):
        if parent < 0:
            continue
        bones[index].parent = bones[parent]
        gap = np.linalg.norm(skeleton.heads[index] - skeleton.tails[parent])
        bones[index].use_connect = bool(gap <= CONNECT_TOLERANCE * size)


def _roll_reference(direction, frame):
    up, front = frame[:, 2], -frame[:, 1]
    return front if abs(direction @ up) > VERTICAL * np.linalg.norm(direction) else up


def _orthonormal(frame):
    """The rotation part of ``frame`` (scale and shear removed), so rolls do not depend on object scale."""
    u, _, vt = np.linalg.svd(np.asarray(frame, dtype=np.float64)[:3, :3])
    return u @ vt
