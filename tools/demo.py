"""``make demo``: rig the project's own sample character in Blender and write what it produced to ``out/``.

Builds the sample humanoid with Blender's Skin modifier (bpy from PyPI, headless; no third-party data), rigs and skins
it through the add-on's Blender layer, and writes:
- ``out/humanoid.blend``: mesh, armature, weights and the stage overlays (View3D > Sidebar > Rigger toggles them),
- ``out/humanoid.glb``: the rigged, skinned character,
- ``out/humanoid_report.json``: bones, timings, skinning outcome, and the distance to the known skeleton,
- ``out/humanoid.png``: a Workbench render of the see-through mesh with the overlays and the bones.
"""
import json
import math
import pathlib
import sys

import numpy as np

from rigger.blender.headless import empty_scene, temporary_user_folder

OUT = pathlib.Path(__file__).resolve().parents[1] / "out"
RENDER_SIZE = (960, 1080)
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


def render(bpy, overlays, obj, skeleton, path):
    """A Workbench render from the front: the mesh see-through, the overlays (but the triangulation, which would
    hide the rest from the front) and the bones as octahedra in front.

    Renders leave out armatures and the overlays' default ``hide_render``, so the picture gets its own bone mesh and
    shows the overlays; none of this is saved in the .blend (written before).
    """
    scene = bpy.context.scene
    for overlay in bpy.data.collections[overlays.COLLECTION_NAME].objects:
        overlay.hide_render = overlay[overlays.KIND_KEY] in HIDDEN_IN_PICTURE
    bones = bpy.data.objects.new("bones", bone_mesh(bpy, skeleton))
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


def bone_mesh(bpy, skeleton, width=BONE_WIDTH):
    """Blender's octahedral bone shape for every bone of ``skeleton`` (its ``heads`` and ``tails``): a point at head
    and tail, a square a tenth of the way up, ``width`` bone lengths from the axis."""
    vertices, faces = [], []
    for head, tail in zip(skeleton.heads, skeleton.tails):
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
