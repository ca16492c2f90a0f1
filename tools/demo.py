"""``make demo``: rig the project's own sample character in Blender and write what it produced to ``out/``.

Builds the sample humanoid with Blender's Skin modifier (bpy from PyPI, headless; no third-party data), rigs and skins
it through the add-on's Blender layer, and writes:
- ``out/humanoid.blend``: mesh, armature, weights and the stage overlays (View3D > Sidebar > Rigger toggles them),
- ``out/humanoid.glb``: the rigged, skinned character,
- ``out/humanoid_report.json``: bones, timings, skinning outcome, and the distance to the known skeleton,
- ``out/humanoid.png``: a Workbench render of the see-through mesh with the overlays and the bones;
- ``out/humanoid_walk.{glb,gif}``: the CMU walk (``../shared/anim``, read in place) retargeted onto the humanoid's
  ``game`` rig through the Mixamo names, and a few seconds of it rendered (skipped, saying why, without the clip).
"""
import json
import math
import os
import pathlib
import sys
import tempfile

import numpy as np

from rigger.blender.headless import empty_scene, temporary_user_folder

OUT = pathlib.Path(__file__).resolve().parents[1] / "out"
RENDER_SIZE = (960, 1080)
WALK = pathlib.Path(os.environ.get("RIGGER_SHARED", pathlib.Path(__file__).resolve().parents[2] / "shared")) / \
    "anim" / "cmu_07_01_walk.bvh"
GIF_SIZE = (360, 400)
GIF_STEP = 6  # render every 6th frame of the 120 fps clip: a 20 fps GIF
BONE_WIDTH = 0.06  # octahedral bone display: the widest section's half width, in bone lengths
BONE_COLOUR = (0.05, 0.05, 0.05, 1.0)
HIDDEN_IN_PICTURE = {"cdt", "merged"}  # stages whose overlays would hide the others from the front
SKIN_COLOUR = (0.8, 0.8, 0.8, 0.2)  # Workbench draws material alpha as transparency: the skeleton shows through


def main(name="humanoid"):
    temporary_user_folder()  # before bpy reads one
    import bpy

    import rigger
    from rigger import samples
    from rigger.blender import overlays, skinning
    from rigger.blender.meshdata import mesh_vertices
    from rigger.blender.pipeline import rig_object
    from rigger.blender.samples import build_character
    from rigger.blender.scenefiles import rig_report, save_scene

    OUT.mkdir(exist_ok=True)
    empty_scene()
    rigger.register()
    obj = build_character(name)
    result = rig_object(obj, "silhouette")
    outcome = skinning.skin(obj, result.armature)
    save_scene(OUT / f"{name}.glb")

    report = rig_report(result, {obj.name: outcome})
    truth = samples.ground_truth_bones(name)
    joints, true_joints = result.skeleton.joints(), truth.joints()
    gaps = np.linalg.norm(joints[:, None] - true_joints[None], axis=2)
    size = float(np.ptp(mesh_vertices(obj.data), axis=0).max())
    report["model"] = {"name": name, "vertices": len(obj.data.vertices), "faces": len(obj.data.polygons)}
    report["joint_chamfer_to_truth"] = 0.5 * float(gaps.min(axis=1).mean() + gaps.min(axis=0).mean()) / size
    (OUT / f"{name}_report.json").write_text(json.dumps(report, indent=2))

    overlays.build_overlays(result.skeleton.stages, obj.name)
    save_scene(OUT / f"{name}.blend")
    render(bpy, overlays, obj, result.skeleton, OUT / f"{name}.png")
    print(f"rigged {name}: {len(result.skeleton)} bones in {sum(result.timings.values()) * 1e3:.0f} ms; "
          f"{outcome.summary()}; joint distance to the true skeleton {report['joint_chamfer_to_truth']:.3f} of its "
          f"size")
    print("wrote " + ", ".join(str(OUT / f"{name}{suffix}") for suffix in
                               (".blend", ".glb", "_report.json", ".png")))
    walk(name)


def walk(name):
    """The CMU walk on the character's game rig: ``out/<name>_walk.glb`` and ``out/<name>_walk.gif``."""
    if not WALK.is_file():
        print(f"skipped the walk: {WALK} is not there (clone the project beside ../shared for the mocap clip)")
        return
    import bpy
    from PIL import Image

    from rigger.blender.animate import animate
    from rigger.blender.pipeline import rig_object, skin_meshes
    from rigger.blender.samples import build_character
    from rigger.blender.scenefiles import save_scene

    empty_scene()
    obj = build_character(name)
    result = rig_object(obj, "silhouette", target="game")
    skin_meshes([obj], result.armature)
    motion = animate(result.armature, WALK)
    save_scene(OUT / f"{name}_walk.glb", [obj, result.armature])
    with tempfile.TemporaryDirectory(prefix="rigger-walk-") as folder:
        frames = walk_frames(bpy, obj, result.armature, pathlib.Path(folder))
        images = [Image.open(frame).convert("RGB").quantize(colors=64) for frame in frames]
        images[0].save(OUT / f"{name}_walk.gif", save_all=True, append_images=images[1:], loop=0,
                       duration=round(1000 * GIF_STEP / motion["fps"]), optimize=True)
    print(f"retargeted {WALK.name} onto the game rig ({motion['frames']} frames; no joint for "
          f"{', '.join(motion['undriven']) or 'no bone'}); wrote {OUT / f'{name}_walk.glb'}, "
          f"{OUT / f'{name}_walk.gif'}")


def walk_frames(bpy, obj, armature, folder):
    """Workbench renders into ``folder`` of every ``GIF_STEP``-th frame, seen from the front and side, the camera
    keeping up with the hips, on a floor at the ground; the PNG paths."""
    scene = bpy.context.scene
    ground = armature.data.bones["root"].head_local[2]
    bpy.ops.mesh.primitive_plane_add(size=40.0, location=(0.0, 0.0, ground))
    floor = bpy.context.object
    floor.data.materials.append(bpy.data.materials.new("floor"))
    floor.data.materials[0].diffuse_color = (0.35, 0.38, 0.42, 1.0)
    obj.data.materials.append(bpy.data.materials.new("skin"))
    obj.data.materials[0].diffuse_color = (0.85, 0.62, 0.45, 1.0)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = 'ORTHO'
    camera.data.ortho_scale = 2.3
    camera.rotation_euler = (math.radians(80), 0.0, math.radians(50))
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = GIF_SIZE
    scene.display.shading.color_type = 'MATERIAL'
    paths = []
    for frame in range(scene.frame_start + 1, scene.frame_end + 1, GIF_STEP):  # frame 1: CMU's reference pose
        scene.frame_set(frame)
        hips = armature.matrix_world @ armature.pose.bones["Hips"].head
        camera.location = (hips[0] + 7.0, hips[1] - 5.9, ground + 2.5)
        scene.render.filepath = str(folder / f"{frame:04d}.png")
        bpy.ops.render.render(write_still=True)
        paths.append(scene.render.filepath)
    return paths


def render(bpy, overlays, obj, skeleton, path):
    """A Workbench render from the front: the mesh see-through, the overlays (but the triangulation, which would
    hide the rest from the front) and the bones as octahedra in front.

    Renders leave out armatures and the overlays' default ``hide_render``, so the picture gets its own bone mesh and
    shows the overlays; none of this is saved in the .blend (written before).
    """
    scene = bpy.context.scene
    for overlay in bpy.data.collections[overlays.COLLECTION_NAME].objects:
        overlay.hide_render = overlay[overlays.KIND_KEY] in HIDDEN_IN_PICTURE
    bones = bpy.data.objects.new("bones", bone_mesh(bpy, skeleton.heads, skeleton.tails))
    material = bpy.data.materials.new("bones")
    material.diffuse_color = BONE_COLOUR
    bones.data.materials.append(material)
    bones.show_in_front = True
    scene.collection.objects.link(bones)
    skin = bpy.data.materials.new("skin")
    skin.diffuse_color = SKIN_COLOUR
    obj.data.materials.append(skin)

    low, high = np.array(obj.bound_box).min(axis=0), np.array(obj.bound_box).max(axis=0)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = 'ORTHO'
    camera.data.ortho_scale = 1.1 * max(high[2] - low[2], (high[0] - low[0]) * RENDER_SIZE[1] / RENDER_SIZE[0])
    camera.location = ((low[0] + high[0]) / 2, low[1] - 10.0, (low[2] + high[2]) / 2)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = RENDER_SIZE
    scene.render.film_transparent = False
    shading = scene.display.shading
    shading.light = 'FLAT'
    shading.color_type = 'MATERIAL'
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def bone_mesh(bpy, heads, tails, width=BONE_WIDTH):
    """Blender's octahedral bone shape for every bone from ``heads`` to ``tails``: a point at head and tail, a square
    a tenth of the way up, ``width`` bone lengths from the axis."""
    vertices, faces = [], []
    for head, tail in zip(heads, tails):
        along = tail - head
        length = np.linalg.norm(along)
        side = np.cross(along, [0.0, 0.0, 1.0] if abs(along[2]) < 0.9 * length else [1.0, 0.0, 0.0])
        side *= width * length / np.linalg.norm(side)
        other = np.cross(along / length, side)
        ring = head + 0.1 * along
        start = len(vertices)
        vertices += [head, tail, ring + side, ring + other, ring - side, ring - other]
        for k in range(4):
            a, b = start + 2 + k, start + 2 + (k + 1) % 4
            faces += [(start, b, a), (start + 1, a, b)]
    mesh = bpy.data.meshes.new("bones")
    mesh.from_pydata(np.array(vertices).tolist(), [], faces)
    return mesh


if __name__ == "__main__":
    main(*sys.argv[1:])
