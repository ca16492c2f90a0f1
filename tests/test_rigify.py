"""The ``rigify`` output target: Rigify's metarig fitted to the skeleton (``rigger.core.metarig``), generated into a
control rig (``rigger.blender.rigify``), the mesh skinned to its DEF bones; the fallback of a plan it cannot fill,
regenerating from the kept metarig, and the command line. Rigify's generation takes a few tenths of a second to a few
seconds, so the rigs are made once per module where the tests can share them (the sample humanoid first, then the
tests that reset the scene)."""
import json
import subprocess
import sys

import numpy as np
import pytest

from characters import load_character, strictly_inside_fraction
from conftest import shared_path
from rigdata import load_obj

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402  (Blender's own module, importable once bpy is)
from mathutils import Matrix, Vector  # noqa: E402

import rigger  # noqa: E402
from rigger.blender import rigify  # noqa: E402
from rigger.blender.headless import empty_scene  # noqa: E402
from rigger.blender.pipeline import TARGET_PROPERTY, rig_object, skin_meshes  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402
from rigger.core.bodyplan import BodyPlan  # noqa: E402
from rigger.core.facing import TORSO  # noqa: E402
from rigger.core.metarig import METARIGS, MetarigTuning, choose_metarig, fit_metarig  # noqa: E402
from rigger.core.roles import BoneRole, named_joints  # noqa: E402
from rigger.core.skeleton import Skeleton  # noqa: E402
from rigger.core.targets import TargetFailed, choose_target  # noqa: E402

Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Blender's OBJ import: x, -z, y


@pytest.fixture(scope="module")
def registered():
    rigger.register()
    yield
    rigger.unregister()


@pytest.fixture(scope="module")
def metarigs(registered):
    """The bones of each metarig Rigger uses, read from Rigify's own (with the bones Rigger adds)."""
    rigify.ensure_rigify()
    empty_scene()
    bones = {}
    for name in METARIGS:
        metarig = rigify.add_metarig(name, name, bpy.context.scene.collection)
        bones[name] = rigify.read_metarig(metarig)
        rigify.remove_generated(metarig, None)
    return bones


@pytest.fixture(scope="module")
def humanoid():
    vertices, triangles = load_character("humanoid")
    return rigger.rig_mesh(vertices, triangles), (vertices, triangles)


@pytest.fixture(scope="module")
def rigged(metarigs):
    """The sample humanoid rigged as ``rigify`` and skinned, in a scene of its own (tests using it come first)."""
    empty_scene()
    obj = build_character("humanoid")
    result = rig_object(obj, "silhouette", target="rigify")
    outcomes, _ = skin_meshes([obj], result.armature)
    return obj, result, outcomes[obj.name]


def mirrored(point, middle):
    return np.array([2 * middle - point[0], point[1], point[2]])


# The fit, bpy-free (the metarigs' bones read from Rigify once).

def test_every_bone_the_fit_names_is_in_rigifys_metarig_and_the_human_loses_only_its_face(metarigs):
    for name, spec in METARIGS.items():
        names = {bone.name for bone in metarigs[name]}
        named = {bone for chain in spec.chains for side in (("L", "R") if chain.sided else (None,))
                 for bone in chain.names(side)}
        named |= {template.replace("{s}", side) for template in (*spec.heels, *(name for name, _ in spec.derived))
                  for side in "LR"}
        assert named <= names, (name, sorted(named - names))
    human = {bone.name: bone for bone in metarigs["human"]}

    def under_face(bone):
        while bone is not None:
            if bone == "face":
                return True
            bone = human[bone].parent
        return False

    face = {name for name in human if under_face(name)}
    assert len(face) > 50
    spec = METARIGS["human"]
    placed = {bone for chain in spec.chains for side in ("L", "R") for bone in chain.names(side)}
    placed |= {template.replace("{s}", side) for template in (*spec.heels, *(name for name, _ in spec.derived))
               for side in "LR"}
    assert set(human) - placed == face  # everything but the face rig is placed


def test_the_fit_puts_the_joints_at_the_humanoids_named_joints_and_twins_mirror(metarigs, humanoid):
    skeleton, mesh = humanoid
    assert choose_metarig(skeleton) == "basic_human"  # the sample's hands show no fingers
    fit = fit_metarig(skeleton, mesh, "basic_human", metarigs["basic_human"])
    np.testing.assert_allclose(fit.frame, np.eye(3), atol=1e-9)  # Z up, facing -Y, .L on +X: Blender's convention
    joints = named_joints(skeleton)
    size = np.ptp(mesh[0], axis=0).max()
    expected = {"spine": ("hips", None), "thigh.L": ("thigh", "L"), "thigh.R": ("thigh", "R"),
                "foot.L": ("foot", "L"), "upper_arm.L": ("upper_arm", "L"), "forearm.R": ("forearm", "R"),
                "hand.L": ("hand", "L"), "spine.004": ("neck", None), "spine.006": ("head", None)}
    for bone, (role, side) in expected.items():
        assert np.linalg.norm(fit.heads[bone] - joints[(role, side, None)]) < 0.01 * size, bone
    # the knee at the shin's start, moved forward (-Y) at most by what makes it bend the right way
    knee = joints[("shin", "L", None)]
    leg = np.linalg.norm(fit.tails["shin.L"] - fit.heads["thigh.L"])
    assert np.linalg.norm(fit.heads["shin.L"] - knee) <= MetarigTuning().bend * leg + 1e-9
    assert fit.heads["shin.L"][1] <= knee[1] + 1e-12
    # the chain is whole: each bone starts where the one before it ends
    for first, second in (("thigh.L", "shin.L"), ("shin.L", "foot.L"), ("foot.L", "toe.L"), ("spine.003", "spine.004")):
        np.testing.assert_allclose(fit.tails[first], fit.heads[second], atol=1e-12)
    # twins are exact mirror images across the midline, the spine on it
    middle = fit.heads["spine"][0]
    for name in fit.heads:
        if name.endswith(".L"):
            twin = name[:-2] + ".R"
            np.testing.assert_allclose(fit.heads[twin], mirrored(fit.heads[name], middle), atol=1e-9)
            np.testing.assert_allclose(fit.tails[twin], mirrored(fit.tails[name], middle), atol=1e-9)
    # the heel lies on the ground behind the ankle, across the foot
    heel_head, heel_tail = fit.heads["heel.02.L"], fit.tails["heel.02.L"]
    assert abs(heel_head[2] - mesh[0][:, 2].min()) < 0.01 * size and heel_head[1] > fit.heads["foot.L"][1]
    assert heel_tail[0] > heel_head[0]  # from inside out
    assert "face" not in fit.heads and set(fit.removed) == {bone.name for bone in metarigs["basic_human"]} - \
        set(fit.heads)


def hand_made_humanoid(pinky_right=True):
    """A stick humanoid facing -Y with both hands' five fingers (the right pinky optional), with its roles."""
    bones = []  # (name, head, tail, parent, role)

    def add(name, head, tail, parent, role):
        bones.append((name, head, tail, parent, role))

    add("hips", (0, 0, 1.0), (0, 0, 1.2), None, BoneRole("hips"))
    add("spine", (0, 0, 1.2), (0, 0, 1.3), "hips", BoneRole("spine"))
    add("chest", (0, 0, 1.3), (0, 0, 1.42), "spine", BoneRole("chest"))
    add("neck", (0, 0, 1.42), (0, -0.01, 1.55), "chest", BoneRole("neck"))
    add("head", (0, -0.01, 1.55), (0, -0.02, 1.78), "neck", BoneRole("head"))
    for side, sign in (("L", 1), ("R", -1)):
        def x(point):
            return (sign * point[0], point[1], point[2])

        add(f"shoulder.{side}", (0, 0, 1.42), x((0.16, 0, 1.45)), "chest", BoneRole("shoulder", side))
        add(f"upper_arm.{side}", x((0.16, 0, 1.45)), x((0.42, 0.02, 1.45)), f"shoulder.{side}",
            BoneRole("upper_arm", side))
        add(f"forearm.{side}", x((0.42, 0.02, 1.45)), x((0.68, 0, 1.45)), f"upper_arm.{side}",
            BoneRole("forearm", side))
        add(f"hand.{side}", x((0.68, 0, 1.45)), x((0.76, 0, 1.45)), f"forearm.{side}", BoneRole("hand", side))
        fingers = {"thumb": (0.71, -0.04), "index": (0.76, -0.024), "middle": (0.765, -0.008), "ring": (0.76, 0.008),
                   "pinky": (0.755, 0.024)}
        for digit, (base, across) in fingers.items():
            if digit == "pinky" and side == "R" and not pinky_right:
                continue
            parent = f"hand.{side}"
            for k in range(3):
                start, end = base + 0.025 * k, base + 0.025 * (k + 1)
                forward = -0.02 * k if digit == "thumb" else 0.0
                name = f"{digit}{k}.{side}"
                add(name, x((start, across + forward, 1.45)), x((end, across + forward - (0.02 if digit == "thumb"
                                                                                         else 0), 1.45)),
                    parent, BoneRole("finger", side, k, digit))
                parent = name
        add(f"pelvis.{side}", (0, 0, 1.0), x((0.1, 0, 0.94)), "hips", BoneRole("hips", side))
        add(f"thigh.{side}", x((0.1, 0, 0.94)), x((0.1, -0.01, 0.5)), f"pelvis.{side}", BoneRole("thigh", side))
        add(f"shin.{side}", x((0.1, -0.01, 0.5)), x((0.1, 0, 0.09)), f"thigh.{side}", BoneRole("shin", side))
        add(f"foot.{side}", x((0.1, 0, 0.09)), x((0.1, -0.16, 0.02)), f"shin.{side}", BoneRole("foot", side))
    names = [bone[0] for bone in bones]
    skeleton = Skeleton(names, [bone[1] for bone in bones], [bone[2] for bone in bones],
                        [-1 if bone[3] is None else names.index(bone[3]) for bone in bones],
                        roles=[bone[4] for bone in bones],
                        body_plan=BodyPlan("humanoid", 1.0, "hand-made", {"legs": 2, "arms": 2}))
    # a mesh for the heels: feet boxes on the ground (the rest of the body does not matter here)
    grid = np.stack(np.meshgrid([0.06, 0.14], np.linspace(-0.18, 0.05, 6), [0.0, 0.1]), -1).reshape(-1, 3)
    vertices = np.concatenate([grid, grid * [-1, 1, 1], np.array([[0, 0, 1.8], [0.8, 0, 1.45], [-0.8, 0, 1.45]])])
    return skeleton, (vertices, np.array([[0, 1, 2]]))


def test_hands_that_show_fingers_get_the_human_metarig_with_palms_and_fingers_placed_on_them(metarigs):
    skeleton, mesh = hand_made_humanoid(pinky_right=False)
    assert choose_metarig(skeleton) == "human"
    fit = fit_metarig(skeleton, mesh, "human", metarigs["human"])
    heads = dict(zip(skeleton.names, skeleton.heads))
    tails = dict(zip(skeleton.names, skeleton.tails))
    for digit, prefix in (("index", "f_index"), ("middle", "f_middle"), ("thumb", "thumb")):
        np.testing.assert_allclose(fit.heads[f"{prefix}.01.L"], heads[f"{digit}0.L"], atol=1e-9)  # on its base
        np.testing.assert_allclose(fit.tails[f"{prefix}.03.L"], tails[f"{digit}2.L"], atol=1e-9)  # to its tip
    # a palm runs from inside the hand to its finger's base
    np.testing.assert_allclose(fit.tails["palm.01.L"], heads["index0.L"], atol=1e-9)
    wrist, base = heads["hand.L"], heads["index0.L"]
    share = (fit.heads["palm.01.L"] - wrist) @ (base - wrist) / ((base - wrist) @ (base - wrist))
    assert 0.2 < share < 0.6
    np.testing.assert_allclose(fit.heads["hand.L"], wrist, atol=1e-9)
    # the right hand has no pinky: its palm and finger go, with a note; the face goes too
    assert {"palm.04.R", "f_pinky.01.R", "f_pinky.03.R"} <= set(fit.removed) and "palm.04.L" in fit.heads
    assert any(note.startswith("no pinky finger (R) found on the model") for note in fit.notes)
    assert "face" in fit.removed and "lip.T.L" in fit.removed
    # the elbow bends back (+Y) by at least the tuned share of the arm's reach
    reach = np.linalg.norm(fit.tails["forearm.L"] - fit.heads["upper_arm.L"])
    assert fit.heads["forearm.L"][1] - fit.heads["upper_arm.L"][1] >= MetarigTuning().bend * reach * 0.99


def test_a_limb_end_the_skeleton_lacks_is_placed_on_the_mesh_and_the_fit_says_so(metarigs):
    """homer's arms end at the elbows (his forearms point at the viewer) and his legs at the ankles: the fit placed
    hands and feet where the mesh goes on, and said nothing of it. His feet went on down the shins, the toes below
    the mesh and the IK controls pointing down; a foot runs forward along the ground."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "homer.obj"))
    vertices = vertices @ Y_UP_TO_Z_UP.T
    skeleton = rigger.rig_mesh(vertices, triangles)
    assert not any(role.role == "hand" for role in skeleton.roles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_human", metarigs["basic_human"])
    assert "hand.L" in fit.heads and "hand.R" in fit.heads
    size = float(np.ptp(vertices, axis=0).max())
    for side in ("L", "R"):
        assert any(note.startswith(f"the skeleton has no hand ({side})") for note in fit.notes)
        ankle, tip = fit.heads[f"foot.{side}"], fit.tails[f"toe.{side}"]  # the metarig's frame: front -Y, up +Z
        assert ankle[1] - tip[1] >= 0.05 * size  # ahead ...
        assert ankle[2] - tip[2] <= 0.1 * size  # ... rather than down


@pytest.mark.parametrize("name", ["ogre", "woody"])
def test_a_thigh_starts_at_the_hip_joint_wherever_the_skeleton_s_leg_began(metarigs, name):
    """The ogre's loincloth hides the top of its legs: Rigger's leg chains run in from the pelvis to where the thighs
    show, far below the hip joints. Rigify's thighs began there, a quarter of the ogre's leg long, and posing one
    left the top of the thigh with the torso. woody's legs run up into his chest, far above his hip joints. The
    thigh begins at the hip joint, up or down the skeleton's leg."""
    vertices, triangles = load_obj(shared_path("models", "nogt", f"{name}.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_human", metarigs["basic_human"])
    joints, size = named_joints(skeleton), float(np.ptp(vertices, axis=0).max())
    for side in ("L", "R"):  # twins mirrored after
        hip = joints[("thigh", fit.roles[f"thigh.{side}"].side, None)]
        assert np.linalg.norm(fit.frame @ fit.heads[f"thigh.{side}"] - hip) < 1e-3 * size


def test_a_short_torso_s_spine_starts_at_the_hips_below_where_the_legs_hang(metarigs):
    """woody's legs and arms all leave one joint of his skeleton, at 0.56 of his height, in his chest: Rigify's spine
    began there, no spine bone below it and his hips control at his chest. It begins at the hips' named joint."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "woody.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_human", metarigs["basic_human"])
    joints, size = named_joints(skeleton), float(np.ptp(vertices, axis=0).max())
    up = np.asarray(skeleton.body_plan.up)  # the spine's head on the midline, level with the hips' joint
    assert abs((fit.frame @ fit.heads["spine"] - joints[("hips", None, None)]) @ up) < 1e-3 * size
    torso = [fit.frame @ fit.heads[name] @ up for name in ("spine", "spine.001", "spine.002", "spine.003", "spine.004")]
    assert torso == sorted(torso)  # up from the hips to the neck, not back down the one bone above the joint
    assert fit.frame @ fit.heads["spine"] @ up < fit.frame @ fit.heads["upper_arm.L"] @ up - 0.1 * size


def test_a_hind_leg_bends_at_its_hock_where_the_skeleton_does(metarigs):
    """The fox's hind leg bends back at its hock, high above the paw, but its roles start the foot near the ground:
    Rigify's shin ran straight from the knee to the paw, most of it outside the leg, and a paw lifted by IK moved
    the lower leg as one stick."""
    vertices, triangles = load_obj(shared_path("models", "gt", "Quaternius_Fox", "Quaternius_Fox.obj"))
    vertices = vertices @ Y_UP_TO_Z_UP.T
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_quadruped", metarigs["basic_quadruped"])
    for side in ("L", "R"):  # the metarig's frame: front -Y, up +Z
        knee, hock, ball = (fit.heads[f"{bone}.{side}"] for bone in ("shin", "foot", "toe"))
        line = (ball - knee) / np.linalg.norm(ball - knee)
        off = (hock - knee) - ((hock - knee) @ line) * line
        assert off[1] > 0.15 * np.linalg.norm(ball - knee)  # the hock lies behind the line from the knee to the paw
        assert hock[2] - ball[2] > 0.3 * (knee[2] - ball[2])  # ... high above the paw


@pytest.mark.parametrize("name, metarig", [("humanoid", "basic_human"), ("bear", "basic_quadruped"),
                                           ("quadruped", "basic_quadruped")])
def test_rigifys_pelvis_and_breast_helpers_stay_inside_the_body(metarigs, name, metarig):
    """Rigify's pelvis and breast bones deform the hips and the chest. Placed among their nearest joints, the legs'
    among them, they spread as the legs did: the sample humanoid's breasts lay wholly outside its chest, and the
    bear's were 3.6 times Rigify's size, so moving a front paw dented the chest. The sample quadruped's chest is
    thinner than the metarig's proportions make it: its breasts stood half out of it."""
    vertices, triangles = load_character(name)
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), metarig, metarigs[metarig])
    bones = {bone.name: bone for bone in metarigs[metarig]}
    torso = [bone for chain in METARIGS[metarig].chains if TORSO in chain.roles for bone in chain.names(None)]

    def share_of_torso(heads, tails, bone):  # a bone's length as a share of the torso's
        return np.linalg.norm(np.subtract(tails[bone], heads[bone])) / sum(
            np.linalg.norm(np.subtract(tails[other], heads[other])) for other in torso)

    meta_heads, meta_tails = ({bone: getattr(bones[bone], end) for bone in bones} for end in ("head", "tail"))
    for helper in ("pelvis.L", "pelvis.R", "breast.L", "breast.R"):
        head, tail = (point @ fit.frame.T for point in (fit.heads[helper], fit.tails[helper]))  # the mesh's frame
        assert strictly_inside_fraction(vertices, triangles, head + np.linspace(0, 1, 11)[:, None] * (tail - head)) \
            >= 0.9, helper
        assert share_of_torso(fit.heads, fit.tails, helper) <= 1.2 * share_of_torso(meta_heads, meta_tails, helper)


def test_a_front_leg_hangs_from_the_end_of_its_shoulder_blade(metarigs):
    """The bear's front legs run forward and down from the withers along the shoulder blade before they turn down.
    The shoulder joint, named at a share of the leg's height, lay on the blade above where the roles begin the
    upper arm: Rigify's shoulder ended a third of the leg above where its front leg began, and the paw lifted by IK
    folded at the wrist."""
    vertices, triangles = load_character("bear")
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_quadruped", metarigs["basic_quadruped"])
    size = float(np.ptp(vertices, axis=0).max())
    for side in ("L", "R"):
        assert np.linalg.norm(fit.tails[f"shoulder.{side}"] - fit.heads[f"front_thigh.{side}"]) < 1e-6 * size


def test_a_stub_off_a_leg_is_not_the_leg(metarigs):
    """spot's front legs each have a two-bone stub off the upper leg (a bump seen from the front), shorter than the
    leg and farther out: the fit took the piece farthest out for the front leg, and Rigify's front paw hung in the
    belly. A side's pieces much shorter than its longest do not compete."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "spot.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    fit = fit_metarig(skeleton, (vertices, triangles), "basic_quadruped", metarigs["basic_quadruped"])
    size = float(np.ptp(vertices, axis=0).max())
    ground = float(min(fit.tails[name][2] for name in fit.tails))  # the metarig's frame: up is +Z
    for side in ("L", "R"):
        assert fit.tails[f"front_toe.{side}"][2] - ground <= 0.05 * size


def test_the_human_metarig_with_fingers_generates(metarigs):
    empty_scene()
    skeleton, mesh = hand_made_humanoid()
    built = rigify.build_rigify(skeleton, "hand_made_rig", bpy.context.scene.collection, np.eye(3), mesh)
    names = set(built.bones.names)
    assert {"DEF-f_index.01.L", "DEF-thumb.03.R", "DEF-palm.04.R", "DEF-spine.006", "DEF-toe.L"} <= names
    assert not any("lip" in name or "jaw" in name for name in names)
    assert all(name.startswith("DEF-") for name in names)


def test_which_metarig_each_plan_gets_and_who_falls_back(humanoid):
    skeleton, _ = humanoid
    assert choose_metarig(skeleton) == "basic_human"
    quadruped = rigger.rig_mesh(*load_character("quadruped"))
    assert choose_metarig(quadruped) == "basic_quadruped"
    snake = rigger.rig_mesh(*load_character("snake"))
    with pytest.raises(ValueError, match="no Rigify metarig fits a fish"):
        choose_metarig(snake)
    target, warning = choose_target("rigify", snake.body_plan)
    assert target.name == "game" and "rigify target needs" in warning and "fish" in warning
    flying = BodyPlan("bird", 0.5, "a pair of long limbs on a small body: wings, no legs", {"wings": 2})
    target, warning = choose_target("rigify", flying)  # a bird in flight is two wings: no body to hang a rig from
    assert target.name == "game" and "needs a bird with legs" in warning


# The generated rig (the sample humanoid, rigged once).

def test_the_rig_has_rigifys_bones_and_ik_controls_and_reports_its_def_bones(rigged):
    obj, result, _ = rigged
    rig = result.armature
    assert result.target.name == "rigify" and rig[TARGET_PROPERTY] == "rigify"
    names = [bone.name for bone in rig.data.bones]
    for prefix in ("DEF-", "ORG-", "MCH-"):
        assert any(name.startswith(prefix) for name in names), prefix
    for control in ("foot_ik.L", "foot_ik.R", "hand_ik.L", "hand_ik.R", "torso", "root"):
        assert control in names
    deform = [bone.name for bone in rig.data.bones if bone.use_deform]
    assert list(result.bones.names) == deform and all(name.startswith("DEF-") for name in deform)
    world = np.array(rig.matrix_world)
    heads = np.array([world[:3, :3] @ np.array(rig.data.bones[name].head_local) + world[:3, 3] for name in deform])
    np.testing.assert_allclose(result.bones.heads, heads, atol=1e-6)
    roles = dict(zip(result.bones.names, result.bones.roles))  # each DEF bone with its metarig bone's role
    assert (roles["DEF-thigh.L"], roles["DEF-thigh.L.001"]) == (BoneRole("thigh", "L", 0), BoneRole("thigh", "L", 1))
    assert roles["DEF-spine"].role == "hips" and roles["DEF-spine.006"].role == "head"
    assert roles["DEF-breast.R"] == BoneRole("chest", "R") and roles["DEF-hand.R"] == BoneRole("hand", "R")
    parents = dict(zip(result.bones.names, result.bones.parents))
    assert result.bones.names[parents["DEF-shin.L"]] == "DEF-thigh.L.001"
    assert result.bones.names[parents["DEF-thigh.L"]] == "DEF-spine"  # through ORG-spine
    metarig = rig[rigify.METARIG_PROPERTY]
    assert metarig.hide_get() and metarig.data.rigify_target_rig == rig and metarig.name == "humanoid_rig_metarig"


def test_the_mesh_is_skinned_to_the_def_bones_only_every_vertex_weighted(rigged):
    obj, result, report = rigged
    assert report.unweighted == 0
    groups = {group.index: group.name for group in obj.vertex_groups}
    assert groups and all(name.startswith("DEF-") for name in groups.values())
    weighted = np.zeros(len(obj.data.vertices), dtype=bool)
    for vertex in obj.data.vertices:
        weighted[vertex.index] = any(element.weight > 0 for element in vertex.groups)
    assert weighted.all()


def posed_points(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        return np.array([tuple(obj.matrix_world @ vertex.co) for vertex in mesh.vertices])
    finally:
        evaluated.to_mesh_clear()


def test_the_ik_controls_move_the_mesh_knees_forward_and_elbows_back(rigged):
    obj, result, _ = rigged
    rig = result.armature
    rest = posed_points(obj)
    knee = np.array(rig.matrix_world @ rig.pose.bones["DEF-shin.L"].head)
    elbow = np.array(rig.matrix_world @ rig.pose.bones["DEF-forearm.R"].head)
    foot, hand = rig.pose.bones["foot_ik.L"], rig.pose.bones["hand_ik.R"]
    saved = foot.matrix.copy(), hand.matrix.copy()
    try:
        foot.matrix = Matrix.Translation(Vector((0.0, 0.0, 0.3))) @ foot.matrix  # raise the foot
        hand.matrix = Matrix.Translation(Vector((0.2, 0.0, 0.0))) @ hand.matrix  # the hand towards the shoulder
        bpy.context.view_layer.update()
        moved_knee = np.array(rig.matrix_world @ rig.pose.bones["DEF-shin.L"].head) - knee
        moved_elbow = np.array(rig.matrix_world @ rig.pose.bones["DEF-forearm.R"].head) - elbow
        moved = np.linalg.norm(posed_points(obj) - rest, axis=1)
    finally:
        foot.matrix, hand.matrix = saved
        bpy.context.view_layer.update()
    assert moved_knee[1] < -0.1 and abs(moved_knee[0]) < 0.3 * abs(moved_knee[1])  # forward (-Y), not sideways
    assert moved_elbow[1] > 0.02  # back (+Y)
    assert (moved > 0.05).sum() > 0.1 * len(moved)  # the leg and the arm went with them


def test_editing_the_metarig_and_regenerating_updates_the_same_rig_and_keeps_the_mesh_bound(rigged):
    obj, result, _ = rigged
    rig = result.armature
    metarig = rig[rigify.METARIG_PROPERTY]
    metarig.hide_set(False)
    bpy.context.view_layer.objects.active = metarig
    bpy.ops.object.mode_set(mode='EDIT')
    head = metarig.data.edit_bones["spine.006"]
    head.tail = head.tail + Vector((0.0, 0.0, 0.1))  # a taller head
    bpy.ops.object.mode_set(mode='OBJECT')
    before = np.array(rig.data.bones["DEF-spine.006"].tail_local)
    assert bpy.ops.pose.rigify_generate() == {'FINISHED'}
    assert metarig.data.rigify_target_rig == rig and rig.name in bpy.data.objects
    after = np.array(rig.data.bones["DEF-spine.006"].tail_local)
    np.testing.assert_allclose(after - before, [0.0, 0.0, 0.1], atol=1e-5)
    modifier = next(m for m in obj.modifiers if m.type == 'ARMATURE')
    assert modifier.object == rig
    assert {group.name for group in obj.vertex_groups} <= {bone.name for bone in rig.data.bones if bone.use_deform}
    assert rig[rigify.METARIG_PROPERTY] == metarig and rig[TARGET_PROPERTY] == "rigify"  # Rigger still knows it


# Each of these in a scene of its own.

def scene_objects():
    return sorted(obj.name for obj in bpy.data.objects if not obj.name.startswith("WGT-"))


def test_rigging_again_replaces_the_rig_its_metarig_and_rigifys_widgets(registered):
    empty_scene()
    obj = build_character("humanoid")
    rig_object(obj, "silhouette", target="rigify")
    widgets = {collection.name for collection in bpy.data.collections}
    rig_object(obj, "silhouette", target="rigify")
    assert scene_objects() == ["humanoid", "humanoid_rig", "humanoid_rig_metarig"]
    assert sorted(data.name for data in bpy.data.armatures) == ["humanoid_rig", "humanoid_rig_metarig"]  # no copy
    assert {collection.name for collection in bpy.data.collections} == widgets == {"WGTS_humanoid_rig"}
    assert len(bpy.data.texts) == 1
    rig_object(obj, "silhouette", target="plain")  # and a plain rig leaves nothing of Rigify behind
    assert scene_objects() == ["humanoid", "humanoid_rig"] and not bpy.data.collections and not bpy.data.texts


def test_a_model_a_million_times_smaller_gets_the_same_rig_scaled(registered, rigged):
    """A humanoid modelled in kilometres (1e-6 of the sample's size): Blender lengthens bones under about 1e-6, so
    the metarig is built magnified in its own space and its object, like the rig's, shrinks it back. The rig is the
    full-size one's, shrunk: the same DEF bones at a millionth of their places, every vertex weighted."""
    _, full, _ = rigged
    empty_scene()
    obj = build_character("humanoid")
    obj.data.transform(Matrix.Scale(1e-6, 4))
    result = rig_object(obj, "silhouette", target="rigify")
    assert list(result.bones.names) == list(full.bones.names)
    np.testing.assert_allclose(result.bones.heads, 1e-6 * full.bones.heads, atol=1e-3 * 1e-6)
    outcomes, _ = skin_meshes([obj], result.armature)
    assert outcomes[obj.name].unweighted == 0


def test_a_snake_falls_back_to_the_game_rig_with_a_message(registered):
    empty_scene()
    result = rig_object(build_character("snake"), "silhouette", target="rigify")
    assert result.target.name == "game"
    assert any("rigify target needs a humanoid or quadruped or bird body plan" in warning and "fish" in warning
               for warning in result.warnings)
    assert not any(obj.name.endswith("metarig") for obj in bpy.data.objects)


def test_a_rig_rigify_refuses_falls_back_to_the_game_rig_with_rigifys_reason(registered, monkeypatch):
    """Rigify may refuse a metarig fitted to a broken mesh's skeleton ("Incorrect armature for type 'chain_rigs'",
    seen on a character with every other face deleted): the command failed. The game rig is built instead, the
    warning gives Rigify's reason, and nothing of the failed attempt stays."""
    def refuse(metarig, rig):
        raise TargetFailed("Rigify could not generate the rig: Incorrect armature for type 'chain_rigs'")

    empty_scene()
    before = set(bpy.data.objects)
    monkeypatch.setattr(rigify, "generate", refuse)
    obj = build_character("humanoid", subdivisions=0)
    result = rig_object(obj, "silhouette", target="rigify")
    assert result.target.name == "game" and "LeftUpLeg" in result.bones.names
    assert result.warnings[0] == ("Rigify could not generate the rig: Incorrect armature for type 'chain_rigs': "
                                  "built the game target instead")
    assert set(bpy.data.objects) - before == {obj, result.armature}


def test_a_quadruped_gets_rigifys_quadruped_with_paws_tail_and_neck(registered):
    empty_scene()
    obj = build_character("quadruped")
    result = rig_object(obj, "silhouette", target="rigify")
    names = set(result.bones.names)
    assert {"DEF-front_thigh.L", "DEF-toe.R", "DEF-spine.003", "DEF-spine.011"} <= names  # legs, tail, head
    assert result.armature[rigify.METARIG_PROPERTY][rigify.KIND_PROPERTY] == "basic_quadruped"
    front = -np.array(result.armature.matrix_world)[:3, 1]
    head = np.array(result.armature.matrix_world @ result.armature.data.bones["DEF-spine.011"].head_local)
    hips = np.array(result.armature.matrix_world @ result.armature.data.bones["DEF-spine.004"].head_local)
    assert (head - hips) @ front > 0  # the rig faces where the head is


def test_a_quadruped_s_hind_paws_stay_under_their_legs_and_its_ik_bends_the_knees_forward(registered):
    """The sample quadruped's hind legs end on stumps that bend back. The fit looked for a foot ahead of the ankle
    and found the front paw, 1.6 foot lengths ahead: the hind foot ran under the belly to it, and moving the hind
    paw's IK control towards the hip bent the knee backward."""
    empty_scene()
    rig = rig_object(build_character("quadruped"), "silhouette", target="rigify").armature
    world = rig.matrix_world
    front = -np.array(world)[:3, 1]
    for side in ("L", "R"):
        hip = np.array(world @ rig.data.bones[f"ORG-thigh.{side}"].head_local)
        knee = np.array(world @ rig.data.bones[f"DEF-shin.{side}"].head_local)
        toe = np.array(world @ rig.data.bones[f"DEF-toe.{side}"].tail_local)
        assert abs((toe - knee) @ front) < 0.5 * np.linalg.norm(hip - toe)  # under the leg, not at the front paws
        control = rig.pose.bones[f"foot_ik.{side}"]
        saved = control.matrix.copy()
        try:
            control.matrix = Matrix.Translation(Vector(0.3 * (hip - np.array(control.head)))) @ control.matrix
            bpy.context.view_layer.update()
            moved = np.array(world @ rig.pose.bones[f"DEF-shin.{side}"].head) - knee
        finally:
            control.matrix = saved
            bpy.context.view_layer.update()
        assert moved @ front > 0.02  # the knee goes forward


def test_a_tail_curling_up_over_the_back_keeps_its_twist_and_the_mesh_its_rest_shape(registered):
    """The Husky's tail curls up over its back, past where the metarig's tail points. Each bone took the metarig's
    own roll, which turned the tip half a turn from the bone before it, and Rigify's bendy tail crumpled it: 84
    vertices up to 0.043 of the size off the mesh with nothing posed."""
    empty_scene()
    vertices, triangles = load_obj(shared_path("models", "gt", "Quaternius_Husky", "Quaternius_Husky.obj"))
    mesh = bpy.data.meshes.new("husky")
    mesh.from_pydata((vertices @ Y_UP_TO_Z_UP.T).tolist(), [], triangles.tolist())
    obj = bpy.data.objects.new("husky", mesh)
    bpy.context.scene.collection.objects.link(obj)
    rest = np.array([tuple(vertex.co) for vertex in mesh.vertices])
    rig = rig_object(obj, "silhouette", target="rigify").armature
    skin_meshes([obj], rig)
    moved = np.linalg.norm(posed_points(obj) - rest, axis=1)
    assert moved.max() < 1e-4 * np.ptp(rest, axis=0).max()


def test_rigify_is_enabled_when_it_is_not_and_a_clear_error_says_how_when_it_cannot_be(registered, monkeypatch):
    addon_utils.disable("rigify", default_set=True)
    assert not hasattr(bpy.ops.pose, "rigify_generate") or not addon_utils.check("rigify")[1]
    rigify.ensure_rigify()
    assert addon_utils.check("rigify")[1] and hasattr(bpy.ops.pose, "rigify_generate")
    addon_utils.disable("rigify", default_set=True)
    monkeypatch.setattr(addon_utils, "enable", lambda *args, **kwargs: None)
    try:
        with pytest.raises(ValueError, match="Edit > Preferences > Add-ons"):
            rigify.ensure_rigify()
    finally:
        monkeypatch.undo()
        rigify.ensure_rigify()


def run(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "rigger", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def test_the_command_line_reports_the_def_bones_in_the_files_frame(registered, tmp_path):
    vertices, triangles = load_character("humanoid")
    in_file = vertices @ Y_UP_TO_Z_UP  # the humanoid as a Y-up OBJ
    source = tmp_path / "humanoid.obj"
    source.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in in_file) +
                      "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))
    result = run("rig", source, "-o", tmp_path / "rigged.blend", "--report", tmp_path / "report.json",
                 "--target", "rigify")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["target"] == "rigify"
    assert all(mesh["unweighted"] == 0 for mesh in report["skinning"]["meshes"].values())
    bones = report["bones"]
    assert bones and all(bone["name"].startswith("DEF-") for bone in bones)
    assert {(bone["name"], bone["role"], bone["side"]) for bone in bones} >= {("DEF-shin.L", "shin", "L"),
                                                                              ("DEF-spine.003", "chest", None)}
    heads = np.array([bone["head"] for bone in bones])
    assert strictly_inside_fraction(in_file, triangles, heads) >= 0.8  # in the OBJ's own frame, inside its mesh
    # ... and they are the saved rig's DEF bones, mapped back into the file's frame
    empty_scene()
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "rigged.blend"))
    rig = next(obj for obj in bpy.data.objects if obj.type == 'ARMATURE' and obj.get("rigger_target") == "rigify")
    world = np.array(rig.matrix_world)
    saved = {bone.name: world[:3, :3] @ np.array(bone.head_local) + world[:3, 3]
             for bone in rig.data.bones if bone.use_deform}
    assert set(saved) == {bone["name"] for bone in bones}
    for bone in bones:
        np.testing.assert_allclose(bone["head"], saved[bone["name"]] @ Y_UP_TO_Z_UP, atol=1e-4)
    assert any(obj.name.endswith("_metarig") for obj in bpy.data.objects)  # the metarig is saved with the rig
    empty_scene()
