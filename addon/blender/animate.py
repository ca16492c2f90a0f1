"""``--animate``: a BVH motion retargeted onto a game armature (``rigger.core.retarget`` does the mapping and the
arithmetic) and baked as the armature's action."""
import codecs
import pathlib
import shutil
import tempfile

import bpy
import numpy as np

from ..core import bvh
from ..core.game import ROOT
from ..core.retarget import Clip, Rig, retarget, sole_bones, sole_points
from .headless import blender_message
from .skinning import weight_entries

CARRIED = 0.5  # a skin vertex rides rigidly enough on the bone that carries more than this share of it


def animate(armature, path):
    """Retarget the BVH file ``path`` onto game ``armature`` (built by the ``game`` target, with its ``root`` on the
    ground) and bake it as the armature's action, one key per frame from the scene's first frame; the scene's frame
    rate and range become the clip's. Returns a report (the action, frames, fps, the frames left out at the start
    as a reference pose, the scale, which game bones no joint drives and which joints drove nothing). ValueError
    (``core.retarget.RetargetError`` for a motion that cannot drive the armature) when it cannot; the imported BVH
    armature is removed in any case."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such BVH file")
    bvh.check(path)
    if ROOT not in armature.data.bones or "Hips" not in armature.data.bones:
        raise ValueError(f"{armature.name} is no game armature (no {ROOT!r} and 'Hips' bones): rig with the game "
                         f"target to animate")
    clip = read_clip(path, armature)
    rig = game_rig(armature)
    motion = retarget(clip, rig)
    scene = bpy.context.scene
    action = bake(armature, rig, motion, f"{armature.name}|{path.stem}", scene.frame_start)
    scene.frame_end = scene.frame_start + len(motion.rotations) - 1
    return {"bvh": str(path), "action": action.name, "frames": len(motion.rotations), "fps": clip.fps,
            "skipped_frames": motion.skipped, "scale": motion.scale, "undriven": motion.mapping.undriven,
            "unused_joints": motion.mapping.unused}


def read_clip(path, armature):
    """The motion of BVH file ``path`` as a ``core.retarget.Clip`` in ``armature``'s space; the scene takes its
    frame rate. The imported BVH armature is removed again."""
    scene = bpy.context.scene
    source = _imported(path)
    try:
        return _clip(source, armature, scene)
    finally:
        _remove(source)


def _imported(path):
    """Import the BVH (frame rate and range into the scene) and return its armature object. A file that starts with
    a byte-order mark, which Blender's importer reads as part of its first keyword, is imported from a copy
    without it."""
    before = set(bpy.data.objects)
    with tempfile.TemporaryDirectory(prefix="rigger-bvh-") as folder:
        readable = _without_bom(pathlib.Path(path), pathlib.Path(folder))
        try:
            bpy.ops.import_anim.bvh(filepath=str(readable), update_scene_fps=True, update_scene_duration=True)
        except RuntimeError as error:
            raise ValueError(f"{path}: Blender could not read it as BVH: {blender_message(error)}") from None
    made = [obj for obj in bpy.data.objects if obj not in before and obj.type == 'ARMATURE']
    if not made:
        raise ValueError(f"{path}: the BVH file holds no skeleton")
    for obj in bpy.data.objects:
        if obj not in before and obj not in made[:1]:
            bpy.data.objects.remove(obj)
    return made[0]


def _without_bom(path, folder):
    """``path``, or a copy of it in ``folder`` (same name) without the UTF-8 byte-order mark it starts with."""
    with open(path, "rb") as file:
        if file.read(len(codecs.BOM_UTF8)) != codecs.BOM_UTF8:
            return path
        copy = folder / path.name
        with open(copy, "wb") as out:
            shutil.copyfileobj(file, out)
    return copy


def _remove(source):
    data = source.data
    action = source.animation_data.action if source.animation_data else None
    source.select_set(False)  # a removed object left selected stays in the view layer's selection as None
    bpy.data.objects.remove(source)
    bpy.context.view_layer.update()
    if data.users == 0:
        bpy.data.armatures.remove(data)
    if action is not None and action.users == 0:
        bpy.data.actions.remove(action)


def _clip(source, armature, scene):
    """The BVH armature's motion as a ``core.retarget.Clip`` in ``armature``'s space."""
    to_armature = np.linalg.inv(np.array(armature.matrix_world)) @ np.array(source.matrix_world)
    bones = list(source.data.bones)
    names = tuple(bone.name for bone in bones)
    parents = np.array([names.index(bone.parent.name) if bone.parent else -1 for bone in bones])
    rest = np.array([to_armature @ np.array(bone.matrix_local) for bone in bones])
    action = source.animation_data.action if source.animation_data else None
    if action is None:
        raise ValueError(f"{source.name}: the BVH file holds no motion")
    first, last = (int(round(frame)) for frame in action.frame_range)
    poses = []
    current = scene.frame_current
    for frame in range(first, last + 1):
        scene.frame_set(frame)
        poses.append([to_armature @ np.array(pose.matrix) for pose in source.pose.bones])
    scene.frame_set(current)
    up = to_armature[:3, :3] @ np.array([0.0, 0.0, 1.0])  # Blender's BVH importer reads files Y up, into +Z
    return Clip(names, parents, rest, np.array(poses), scene.render.fps / scene.render.fps_base, up)


def game_rig(armature):
    """The game armature at rest as a ``core.retarget.Rig``: its up is the root bone's direction, its ground the
    root's head, and its soles come from the meshes the armature deforms (:func:`_soles`)."""
    bones = list(armature.data.bones)
    names = tuple(bone.name for bone in bones)
    parents = np.array([names.index(bone.parent.name) if bone.parent else -1 for bone in bones])
    rest = np.array([np.array(bone.matrix_local) for bone in bones])
    tails = np.array([np.array(bone.tail_local) for bone in bones])
    root = armature.data.bones[ROOT]
    up = np.array(root.tail_local) - np.array(root.head_local)
    up /= np.linalg.norm(up)
    return Rig(names, parents, rest, tails, up, float(np.array(root.head_local) @ up), _soles(armature, names, up))


def _soles(armature, names, up):
    """``Rig.soles``: per bone a leg stands on (``core.retarget.sole_bones``), the sole points
    (``core.retarget.sole_points``) of the vertices that bone carries more than ``CARRIED`` of, over the meshes
    ``armature`` deforms, in its space at rest."""
    feet = [name for side in ("Left", "Right") for name in sole_bones(names, side)]
    carried = {name: [] for name in feet}
    to_armature = np.linalg.inv(np.array(armature.matrix_world))
    for obj in bpy.data.objects:
        if obj.type != 'MESH' or not any(modifier.type == 'ARMATURE' and modifier.object == armature
                                         for modifier in obj.modifiers):
            continue
        vertices, bones, weights = weight_entries(obj, feet)
        if not len(vertices):
            continue
        points = np.empty(len(obj.data.vertices) * 3)
        obj.data.vertices.foreach_get("co", points)
        matrix = to_armature @ np.array(obj.matrix_world)
        points = points.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
        for bone, name in enumerate(feet):
            carried[name].append(points[vertices[(bones == bone) & (weights > CARRIED)]])
    return {names.index(name): sole_points(np.concatenate(parts), up)
            for name, parts in carried.items() if parts and sum(map(len, parts))}


def bake(armature, rig, motion, name, start):
    """A new action ``name`` on ``armature``: every bone's rotation (quaternion) and the Hips' location, one key per
    frame from frame ``start``. It replaces the armature's action, which goes when nothing else uses it (exporters
    write the actions they find)."""
    if armature.animation_data is None:
        armature.animation_data_create()
    action = bpy.data.actions.new(name)
    previous, armature.animation_data.action = armature.animation_data.action, action
    if previous is not None and previous.users == 0:
        bpy.data.actions.remove(previous)
    frames = start + np.arange(len(motion.rotations), dtype=np.float64)
    channels = [(bone, "rotation_quaternion", motion.rotations[:, k]) for k, bone in enumerate(rig.names)]
    channels.append((rig.names[motion.hips], "location", motion.location))
    for bone, channel, values in channels:
        pose = armature.pose.bones[bone]
        pose.rotation_mode = 'QUATERNION'
        for index in range(values.shape[1]):
            curve = _curve(action, armature, f'pose.bones["{bone}"].{channel}', index, bone)
            curve.keyframe_points.add(len(frames))
            curve.keyframe_points.foreach_set("co", np.column_stack([frames, values[:, index]]).ravel())
            curve.keyframe_points.foreach_set("interpolation", [_LINEAR] * len(frames))
            curve.update()
    return action


_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value


def _curve(action, armature, data_path, index, group):
    """An F-curve of ``action`` for ``armature``: through the action's slot where actions have slots (Blender 4.4
    and later), else the action's own list."""
    if hasattr(action, "fcurve_ensure_for_datablock"):
        return action.fcurve_ensure_for_datablock(armature, data_path, index=index, group_name=group)
    return action.fcurves.new(data_path, index=index, action_group=group)


