"""The game target in Blender: the armature, its weights, glTF and FBX round trips, and ``rig --animate`` end to end
(on a short BVH written here; ``../shared/anim`` is not needed)."""
import codecs
import json
import math
import pathlib

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import rigger  # noqa: E402
from characters import load_character  # noqa: E402
from conftest import shared_path  # noqa: E402
from rigger.blender.armature import build_armature  # noqa: E402
from rigger.blender.game import INFLUENCES  # noqa: E402
from rigger.blender.pipeline import rig_object, skin_meshes  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402
from rigger.blender.scenefiles import save_scene  # noqa: E402
from rigger.core.game import ROOT  # noqa: E402
from rigger.core.skeleton import Skeleton  # noqa: E402
from test_cli import Y_UP_TO_Z_UP, glb_document, run, write_obj  # noqa: E402

FRAMES = 12


def game_character(name="humanoid"):
    rigger.register()
    obj = build_character(name, subdivisions=1)
    result = rig_object(obj, "silhouette", target="game")
    outcomes, _ = skin_meshes([obj], result.armature)
    return obj, result, outcomes[obj.name]


def vertex_weights(obj):
    names = {group.index: group.name for group in obj.vertex_groups}
    return [{names[e.group]: e.weight for e in vertex.groups if e.weight > 0} for vertex in obj.data.vertices]


def bones_of(armature):
    matrix = np.array(armature.matrix_world)
    return {bone.name: ((matrix @ np.r_[bone.head_local, 1])[:3], bone.parent.name if bone.parent else None)
            for bone in armature.data.bones}


def test_a_humanoid_game_rig_without_forearms_says_which_bones_it_lacks(scene):
    """Arms that end at the upper arm (the method found no forearm, as on homer seen from the front): the game rig
    has no ForeArm or Hand, and a warning names them, since a motion's elbows and wrists will drive nothing."""
    from rigger.blender import game

    vertices, triangles = load_character("humanoid")
    full = rigger.rig_mesh(vertices, triangles)
    keep = [b for b, role in enumerate(full.roles) if role.role not in ("forearm", "hand", "finger")]
    index = {b: k for k, b in enumerate(keep)}
    armless = Skeleton([full.names[b] for b in keep], full.heads[keep], full.tails[keep],
                       [index[full.parents[b]] if full.parents[b] >= 0 else -1 for b in keep],
                       roles=[full.roles[b] for b in keep], body_plan=full.body_plan)
    built = game.build(armless, "armless", scene.collection, np.eye(3), mesh=(vertices, triangles))
    assert {"LeftArm", "RightArm"} <= set(built.bones.names) and "LeftForeArm" not in built.bones.names
    assert built.warnings == ["the humanoid's game rig has no LeftForeArm, LeftHand, RightForeArm, RightHand: "
                              "Rigger's skeleton shows no such part, and a motion's joints for them drive nothing"]
    assert game.build(full, "full", scene.collection, np.eye(3), mesh=(vertices, triangles)).warnings == []


def test_game_armature_weights_and_mirrored_rolls(scene):
    obj, result, report = game_character()
    armature = result.armature
    assert result.target.name == "game" and armature["rigger_target"] == "game"
    assert not armature.data.bones[ROOT].use_deform and ROOT in result.bones.names
    weights = vertex_weights(obj)
    assert all(weights) and max(len(w) for w in weights) <= INFLUENCES
    assert max(abs(sum(w.values()) - 1) for w in weights) < 1e-5
    assert not any(ROOT in w for w in weights)
    assert report.stages[-1].name == f"at most {INFLUENCES} influences"
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode='EDIT')
    axes = {bone.name: (bone.roll, np.array(bone.z_axis)) for bone in armature.data.edit_bones}
    bpy.ops.object.mode_set(mode='OBJECT')
    twins = [name for name in axes if name.startswith("Left")]
    assert len(twins) >= 7
    for name in twins:
        roll, z_axis = axes[name]
        twin_roll, twin_z = axes["Right" + name[4:]]
        assert twin_roll == pytest.approx(-roll, abs=1e-4)
        assert twin_z * [-1, 1, 1] == pytest.approx(z_axis, abs=1e-4)


@pytest.mark.parametrize("suffix", [".glb", ".fbx"])
def test_names_hierarchy_and_weights_survive_glb_and_fbx(scene, tmp_path, suffix):
    obj, result, _ = game_character()
    bones, weights = bones_of(result.armature), vertex_weights(obj)
    path = tmp_path / f"game{suffix}"
    save_scene(path, [obj, result.armature])
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    if suffix == ".glb":
        bpy.ops.import_scene.gltf(filepath=str(path))
    else:
        bpy.ops.import_scene.fbx(filepath=str(path))
    armature = next(o for o in bpy.data.objects if o.type == 'ARMATURE')
    mesh = next(o for o in bpy.data.objects if o.type == 'MESH' and o.vertex_groups)
    back = bones_of(armature)
    assert set(back) == set(bones)
    for name, (head, parent) in bones.items():
        assert back[name][1] == parent
        assert back[name][0] == pytest.approx(head, abs=1e-4)
    back_weights = vertex_weights(mesh)
    assert len(back_weights) == len(weights)
    for mine, theirs in zip(weights, back_weights):  # glTF stores weights as 16-bit fractions
        assert all(theirs.get(name, 0) == pytest.approx(mine.get(name, 0), abs=1e-3) for name in {*mine, *theirs})


def short_bvh(path, names=None, motion=None):
    """A 12-frame BVH with CMU's joint names (or ``names`` for its 19 joints). ``motion(frame)`` gives the root's
    position and each joint's (Z, Y, X) rotation in degrees; by default a step forward, the left knee bending, the
    arms swinging down from a T-pose."""
    names = names or ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg",
                      "RightFoot", "RightToeBase", "Spine", "Spine1", "Neck", "Head", "LeftShoulder", "LeftArm",
                      "LeftForeArm", "RightShoulder", "RightArm", "RightForeArm"]
    offsets = [(0, 0, 0), (1.8, -1.7, 0.8), (2.0, -6.8, 0), (2.0, -7.0, 0), (0.2, -0.5, 2.0), (-1.8, -1.7, 0.8),
               (-2.0, -6.8, 0), (-2.0, -7.0, 0), (-0.2, -0.5, 2.0), (0, 2.2, 0), (0, 2.2, 0), (0, 2.5, 0),
               (0, 1.5, 0), (1.0, 1.5, 0), (3.0, 0, 0), (5.0, 0, 0), (-1.0, 1.5, 0), (-3.0, 0, 0), (-5.0, 0, 0)]
    parents = [-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 10, 13, 14, 10, 16, 17]
    children = {k: [c for c, p in enumerate(parents) if p == k] for k in range(len(names))}
    lines = ["HIERARCHY"]

    def joint(k, depth):
        pad = "\t" * depth
        lines.append(f"{pad}{'ROOT' if k == 0 else 'JOINT'} {names[k]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}\tOFFSET {' '.join(f'{v:.4f}' for v in offsets[k])}")
        lines.append(f"{pad}\tCHANNELS " + ("6 Xposition Yposition Zposition " if k == 0 else "3 ")
                     + "Zrotation Yrotation Xrotation")
        for child in children[k]:
            joint(child, depth + 1)
        if not children[k]:
            lines.extend([f"{pad}\tEnd Site", f"{pad}\t{{", f"{pad}\t\tOFFSET 0 1 0", f"{pad}\t}}"])
        lines.append(f"{pad}}}")

    def step(frame):
        values = np.zeros((len(names), 3))
        phase = math.sin(2 * math.pi * frame / FRAMES)
        values[1] = (0, 0, -20 * phase)  # left thigh swings (about X: the last channel)
        values[2] = (0, 0, 30 * max(phase, 0))  # left knee bends back
        values[14] = (-60, 0, 0)  # left arm down from the T-pose (about Z)
        values[17] = (60, 0, 0)
        return (0.0, 16.0, 2.0 * frame), values

    joint(0, 0)
    lines += ["MOTION", f"Frames: {FRAMES}", "Frame Time: 0.0333333"]
    for frame in range(FRAMES):
        at, values = (motion or step)(frame)
        row = [*at] + [v for k in range(len(names)) for v in values[k]]
        lines.append(" ".join(f"{v:.4f}" for v in row))
    pathlib.Path(path).write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def humanoid_file(tmp_path_factory):
    vertices, triangles = load_character("humanoid")
    return write_obj(tmp_path_factory.mktemp("game") / "humanoid.obj", vertices @ Y_UP_TO_Z_UP, triangles)


def test_rig_animate_bakes_the_motion_into_the_glb(humanoid_file, tmp_path):
    bvh = short_bvh(tmp_path / "step.bvh")
    output, report = tmp_path / "step.glb", tmp_path / "step.json"
    result = run("rig", humanoid_file, "--animate", bvh, "-o", output, "--report", report)
    assert result.returncode == 0, result.stderr
    data = json.loads(report.read_text())
    assert data["target"] == "game" and data["animation"]["frames"] == FRAMES
    assert data["animation"]["undriven"] == [] or "Neck" not in data["animation"]["undriven"]
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    bpy.ops.import_scene.gltf(filepath=str(output))
    armature = next(o for o in bpy.data.objects if o.type == 'ARMATURE')
    assert armature.animation_data is not None and armature.animation_data.action is not None
    scene = bpy.context.scene
    heads = []
    for frame in (int(scene.frame_start), int(scene.frame_end)):
        scene.frame_set(frame)
        pose = armature.pose.bones
        heads.append({name: np.array(armature.matrix_world @ pose[name].head) for name in ("Hips", "LeftHand")})
    # glTF is Y up: the hips walked forward (the BVH's +Z is the character's front, Blender's -Y) ...
    assert np.linalg.norm(heads[1]["Hips"] - heads[0]["Hips"]) > 0.05
    # ... and the arms hang down, not out as at rest
    assert heads[0]["LeftHand"][2] < heads[0]["Hips"][2] + 0.3


def test_an_unmappable_bvh_names_what_it_could_not_place(humanoid_file, tmp_path):
    bvh = short_bvh(tmp_path / "odd.bvh", [f"Bone{k}" for k in range(19)])
    output = tmp_path / "odd.glb"
    result = run("rig", humanoid_file, "--animate", bvh, "-o", output)
    assert result.returncode == 1 and not output.exists()
    error = result.stderr.strip().splitlines()[-1]
    assert error.startswith("rigger: error:") and "LeftUpLeg" in error and "Bone3" in error


def test_a_bvh_that_is_no_motion_is_one_error_line_before_the_rigging(humanoid_file, tmp_path):
    cut = tmp_path / "cut.bvh"
    cut.write_text("".join(short_bvh(tmp_path / "step.bvh").read_text().splitlines(keepends=True)[:-3]))
    for bvh, message in ((cut, "holds 9 frame lines of the 12 it announces (cut short?)"),
                         (humanoid_file, "not a BVH file (no MOTION section)")):
        output = tmp_path / "x.glb"
        result = run("rig", humanoid_file, "--animate", bvh, "-o", output)
        assert result.returncode == 1 and not output.exists()
        assert result.stderr.strip() == f"rigger: error: {bvh}: {message}"
        assert not result.stdout.strip()  # before Blender imported the model


def test_a_bvh_starting_with_a_byte_order_mark_animates(humanoid_file, tmp_path):
    """Blender's importer reads a byte-order mark as part of HIERARCHY and fails, after the rigging, with its own
    traceback; Rigger's check took the file. It is imported from a copy without the mark."""
    marked = tmp_path / "marked.bvh"
    marked.write_bytes(codecs.BOM_UTF8 + short_bvh(tmp_path / "step.bvh").read_bytes())
    output = tmp_path / "marked.glb"
    result = run("rig", humanoid_file, "--animate", marked, "-o", output)
    assert result.returncode == 0, result.stderr
    assert f"animated with {marked}: {FRAMES} frames" in result.stdout and output.exists()


def test_a_replaced_armature_takes_its_motion_along(scene, tmp_path):
    """A file's armature with a motion of its own: the rig replaces both, so the glTF written holds the new motion
    alone, not the old bones' too (players play the first one), and the exporter has nothing to warn about."""
    body = build_character("humanoid", subdivisions=0)
    old = build_armature(Skeleton(["old"], [(0, 0, 0)], [(0, 0, 1)], [-1]), "OldRig")
    body.vertex_groups.new(name="old").add(range(len(body.data.vertices)), 1.0, 'REPLACE')
    body.modifiers.new("Armature", 'ARMATURE').object = old
    old.pose.bones["old"].rotation_mode = 'XYZ'
    for frame, angle in ((1, 0.0), (10, 1.0)):
        old.pose.bones["old"].rotation_euler = (angle, 0.0, 0.0)
        old.pose.bones["old"].keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    bpy.ops.export_scene.gltf(filepath=str(tmp_path / "scene.glb"), export_format='GLB')
    bvh = short_bvh(tmp_path / "step.bvh")
    for source, output in (("scene.blend", "rigged.blend"), ("scene.glb", "rigged.glb")):
        result = run("rig", tmp_path / source, "--animate", bvh, "-o", tmp_path / output)
        assert result.returncode == 0 and "warning: replaced the file's armature 'OldRig'" in result.stderr
    animations = glb_document(tmp_path / "rigged.glb")["animations"]
    assert [animation["name"] for animation in animations] == ["humanoid_rig|step"]
    assert "not found" not in result.stdout

    result = run("rig", tmp_path / "rigged.blend", "-o", tmp_path / "again.blend")  # Rigger's own rig, rigged again
    assert result.returncode == 0 and "warning: replaced the armature Rigger made for the file before" in result.stderr


def test_animate_needs_the_game_target(humanoid_file, tmp_path):
    bvh = short_bvh(tmp_path / "step.bvh")
    result = run("rig", humanoid_file, "--animate", bvh, "--target", "plain", "-o", tmp_path / "x.glb")
    assert result.returncode == 1 and "game target" in result.stderr


@pytest.mark.parametrize("turn", [(25, 0, 0), (0, 0, 30)], ids=["twisted", "pitched"])
def test_a_planted_foot_rests_its_sole_on_the_ground(scene, tmp_path, turn):
    # standing still, the left foot turned in the last third of the frames: twisted about its own line (capture
    # solvers leave that loose) or pitched toes down; the foot's skin neither sinks into the ground nor floats
    def standing(frame):
        values = np.zeros((19, 3))
        values[14], values[17] = (-60, 0, 0), (60, 0, 0)
        if frame >= 2 * FRAMES // 3:
            values[3] = turn
        return (0.0, 16.0, 0.0), values

    from rigger.blender.animate import animate
    obj, result, _ = game_character()
    animate(result.armature, short_bvh(tmp_path / "stand.bvh", motion=standing))
    weights = vertex_weights(obj)
    foot = [i for i, w in enumerate(weights) if w.get("LeftFoot", 0) + w.get("LeftToeBase", 0) > 0.5]
    scene = bpy.context.scene
    rest = np.array([obj.matrix_world @ v.co for v in obj.data.vertices])
    size, ground = np.ptp(rest, axis=0).max(), rest[:, 2].min()
    for frame in range(scene.frame_start + 1, scene.frame_end + 1):
        scene.frame_set(frame)
        posed = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices
        lowest = min((obj.matrix_world @ posed[i].co)[2] for i in foot)
        assert abs(lowest - ground) < 0.001 * size, frame


def test_a_character_whose_legs_end_without_feet_still_walks_on_its_soles(scene, tmp_path):
    """A game rig whose legs end without Foot bones (homer's, its feet taken off by hand): the motion drives the legs
    all the same, and the skin each Leg carries keeps its lowest point on the ground while the character stands."""
    def standing(frame):
        values = np.zeros((19, 3))
        values[14], values[17] = (-60, 0, 0), (60, 0, 0)
        values[1], values[2] = (0, 0, -10 * (frame % 3)), (0, 0, 15 * (frame % 3))  # a knee bends a little
        return (0.0, 16.0, 0.0), values

    from rigger.blender.animate import animate
    rigger.register()
    bpy.ops.wm.obj_import(filepath=str(shared_path("models", "nogt", "homer.obj")))
    obj = next(o for o in bpy.context.scene.objects if o.type == 'MESH')
    result = rig_object(obj, "silhouette", target="game")
    armature = result.armature
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode='EDIT')
    for bone in [bone for bone in armature.data.edit_bones if bone.name.endswith(("Foot", "ToeBase"))]:
        armature.data.edit_bones.remove(bone)
    bpy.ops.object.mode_set(mode='OBJECT')
    skin_meshes([obj], armature)
    assert "LeftFoot" not in armature.data.bones and "LeftLeg" in armature.data.bones
    animate(armature, short_bvh(tmp_path / "stand.bvh", motion=standing))
    weights = vertex_weights(obj)
    rest = np.array([obj.matrix_world @ v.co for v in obj.data.vertices])
    size, ground = np.ptp(rest, axis=0).max(), rest[:, 2].min()
    scene = bpy.context.scene
    for side in ("Left", "Right"):
        carried = [i for i, w in enumerate(weights) if w.get(f"{side}Leg", 0) > 0.5]
        for frame in range(scene.frame_start + 1, scene.frame_end + 1):
            scene.frame_set(frame)
            posed = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices
            lowest = min((obj.matrix_world @ posed[i].co)[2] for i in carried)
            assert abs(lowest - ground) < 0.005 * size, (side, frame)


def test_a_retargeted_motion_poses_a_character_alike_at_any_size(scene, tmp_path):
    """The knee's two-bone IK aimed at a point one unit ahead of the knee: on a character hundreds of units tall (a
    model in centimetres, woody) that point lay on the knee, so the knee kept whatever way the mocap's turns put it,
    on splayed legs backwards. The sample humanoid made 100 times larger is posed as the small one, scaled."""
    from rigger.blender.animate import animate

    bvh = short_bvh(tmp_path / "step.bvh")
    posed = []
    for scale in (1.0, 100.0):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        rigger.register()
        obj = build_character("humanoid", subdivisions=0)
        obj.data.transform(np.diag([scale, scale, scale, 1.0]).tolist())
        result = rig_object(obj, "silhouette", target="game")
        skin_meshes([obj], result.armature)
        animate(result.armature, bvh)
        scene = bpy.context.scene
        heads = []
        for frame in range(scene.frame_start + 1, scene.frame_end + 1):
            scene.frame_set(frame)
            pose = result.armature.pose.bones
            heads.append([np.array(result.armature.matrix_world @ pose[name].head) / scale
                          for name in ("LeftUpLeg", "LeftLeg", "LeftFoot", "RightLeg")])
        posed.append(np.array(heads))
    assert posed[1] == pytest.approx(posed[0], abs=1e-3)
