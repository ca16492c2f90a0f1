"""The game target's skeleton (``rigger.core.game``) and the mocap mapping (``rigger.core.retarget``), bpy-free."""
from dataclasses import replace

import numpy as np
import pytest

import rigger
from rigger import samples
from characters import load_character
from conftest import shared_path
from rigdata import load_ground_truth, load_obj
from rigger.core.bodyplan import recognise
from rigger.core.game import game_skeleton, missing_humanoid_bones
from rigger.core.retarget import Clip, RetargetError, aliases, captured, map_joints, normalised, sole_points
from rigger.core.roles import landmarks, named_joints
from rigger.core.skeleton import Skeleton
from rigger.core.targets import choose_target

MIXAMO = {"Hips", "Spine", "Spine1", "Spine2", "Neck", "Head"} | {
    f"{side}{word}" for side in ("Left", "Right")
    for word in ("Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot")}
CMU = ["Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RHipJoint", "RightUpLeg", "RightLeg",
       "RightFoot", "RightToeBase", "LowerBack", "Spine", "Spine1", "Neck", "Neck1", "Head", "LeftShoulder", "LeftArm",
       "LeftForeArm", "LeftHand", "LeftFingerBase", "LeftHandIndex1", "LThumb", "RightShoulder", "RightArm",
       "RightForeArm", "RightHand", "RightFingerBase", "RightHandIndex1", "RThumb"]
CMU_PARENTS = [-1, 0, 1, 2, 3, 4, 0, 6, 7, 8, 9, 0, 11, 12, 13, 14, 15, 13, 17, 18, 19, 20, 21, 20, 13, 24, 25, 26,
               27, 28, 27]


def rigged(name):
    vertices, triangles = load_character(name)
    skeleton = rigger.rig_mesh(vertices, triangles)
    return skeleton, game_skeleton(skeleton, vertices), vertices


def test_the_sample_humanoid_gets_mixamo_names_under_one_root_on_the_ground():
    skeleton, game, vertices = rigged("humanoid")
    bones = game.skeleton
    assert MIXAMO <= set(bones.names)
    assert bones.roots == (bones.names.index("root"),)
    parent = {name: bones.names[p] if p >= 0 else None for name, p in zip(bones.names, bones.parents)}
    assert parent["Hips"] == "root" and parent["Spine"] == "Hips" and parent["Spine2"] == "Spine1"
    assert parent["LeftUpLeg"] == "Hips" and parent["LeftShoulder"] == "Spine2" and parent["Neck"] == "Spine2"
    assert parent["LeftForeArm"] == "LeftArm" and parent["Head"] == "Neck"
    root, hips = bones.heads[bones.names.index("root")], bones.heads[bones.names.index("Hips")]
    assert root[2] == pytest.approx(vertices[:, 2].min()) and root[:2] == pytest.approx(hips[:2])


def test_game_joints_are_the_named_joints_and_every_bone_is_taken_over():
    skeleton, game, _ = rigged("humanoid")
    joints = named_joints(skeleton)
    bones = game.skeleton
    for name, key in (("LeftUpLeg", ("thigh", "L", None)), ("RightLeg", ("shin", "R", None)),
                      ("LeftFoot", ("foot", "L", None)), ("LeftArm", ("upper_arm", "L", None)),
                      ("RightForeArm", ("forearm", "R", None)), ("LeftHand", ("hand", "L", None)),
                      ("Neck", ("neck", None, None)), ("Head", ("head", None, None)),
                      ("Hips", ("hips", None, None)), ("Spine", ("spine", None, None)),
                      ("Spine2", ("chest", None, None))):
        assert bones.heads[bones.names.index(name)] == pytest.approx(joints[key], abs=1e-6), name  # twins mirrored
    assert len(game.owners) == len(skeleton) and min(game.owners) >= 1  # every Rigger bone has a game bone (not root)
    for bone, owner in enumerate(game.owners):  # ... that lies along it
        middle = 0.5 * (skeleton.heads[bone] + skeleton.tails[bone])
        head, tail = bones.heads[owner], bones.tails[owner]
        along = np.clip((middle - head) @ (tail - head) / ((tail - head) @ (tail - head)), 0, 1)
        assert np.linalg.norm(head + along * (tail - head) - middle) < 0.1


@pytest.mark.parametrize("name", ["humanoid", "humanoid_a_pose", "quadruped"])
def test_twins_mirror_across_the_mirror_plane(name):
    _, game, _ = rigged(name)
    bones = game.skeleton
    pairs = [(k, bones.names.index("Right" + n[4:])) for k, n in enumerate(bones.names) if n.startswith("Left")]
    assert pairs
    for left, right in pairs:
        for points in (bones.heads, bones.tails):
            assert points[left] * [-1, 1, 1] == pytest.approx(points[right], abs=1e-6)


def test_twin_shoulders_begin_alike_whatever_moved_between_them():
    """BrainStem's game LeftShoulder began at its named joint and its RightShoulder at the spine's end, 0.02 of the
    size from the mirror image: the right shoulder, judged first, ended where the spine ends, which had it stay (a
    shoulder may not move farther than that short bone allows); the neck, judged next, moved the spine's end by a
    hair, so for the left shoulder no bone ended there. Twins are judged on the bones as they were."""
    vertices, triangles, _ = load_ground_truth(shared_path("models", "gt", "BrainStem"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    plane, size = skeleton.stages["mirror_plane"], float(np.ptp(vertices, axis=0).max())
    pairs = [(k, bones.names.index("Right" + n[4:])) for k, n in enumerate(bones.names) if n.startswith("Left")]
    assert len(pairs) >= 8
    for left, right in pairs:
        for points in (bones.heads, bones.tails):
            assert np.linalg.norm(plane.reflect(points[right]) - points[left]) <= 0.005 * size, bones.names[left]


def test_numbered_twins_are_numbered_alike_on_both_sides():
    """rignet_1347, a rock monster, has a spike on each elbow and claws on each hand, all ``Extra`` chains numbered
    ``_2``, ``_3``...: the left elbow spike was ``LeftExtra1_3``, the right one ``RightExtra1``, so twins went by
    different names, and making twins' parents alike then hung a right claw from the arm. A right chain mirroring a
    left one takes its number. (Turned Z up, as Blender imports it.)"""
    vertices, triangles, _ = load_ground_truth(shared_path("models", "gt", "rignet_1347"))
    vertices = np.column_stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]])  # Y up to Blender's Z up
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    plane, size = skeleton.stages["mirror_plane"], float(np.ptp(vertices, axis=0).max())
    parent = {name: bones.names[p] if p >= 0 else None for name, p in zip(bones.names, bones.parents)}
    extras = [name for name in bones.names if name.startswith("LeftExtra") and "Right" + name[4:] in parent]
    assert len(extras) >= 9
    for left in extras:
        right = bones.names.index("Right" + left[4:])
        for points in (bones.heads, bones.tails):
            assert np.linalg.norm(plane.reflect(points[right]) - points[bones.names.index(left)]) <= 0.02 * size
        assert parent["Right" + left[4:]] == "Right" + parent[left][4:]


def test_a_mesh_scaled_or_moved_keeps_its_game_names_on_the_same_bones():
    """The four-armed sample's second arms are ``Extra`` chains numbered ``_2``, ``_3``: numbered in the order the
    skeleton's bones came in, which a scale or a move reshuffled, so ``LeftExtra1`` went from one arm to the other.
    The bones now come in the order of their names, and chains of one name are numbered by where they lie."""
    vertices, triangles = load_character("four_arms")
    size = float(np.ptp(vertices, axis=0).max())
    reference = game_skeleton(rigger.rig_mesh(vertices, triangles), vertices).skeleton
    assert any("Extra" in name for name in reference.names)
    for scale, shift in ((3.0, 0.0), (1.0, np.array([3.3, -1.7, 0.9]) * size)):
        moved = vertices * scale + shift
        bones = game_skeleton(rigger.rig_mesh(moved, triangles), moved).skeleton
        assert sorted(bones.names) == sorted(reference.names)
        for name, head, tail in zip(bones.names, bones.heads, bones.tails):
            k = reference.names.index(name)
            assert np.linalg.norm((head - shift) / scale - reference.heads[k]) < 1e-6 * size, name
            assert np.linalg.norm((tail - shift) / scale - reference.tails[k]) < 1e-6 * size, name


@pytest.mark.parametrize("degrees", [90, 180])
def test_a_figure_whose_skeleton_has_no_feet_keeps_its_own_left_however_it_is_turned(degrees):
    """rignet_smith's stubby feet get no foot bones, so which way he faces came from Blender's convention, ``.L`` on
    +X: turned about his up axis, his game ``LeftHand`` went to his right hand. The way his mesh's feet point below
    his ankles says which way he faces."""
    vertices, triangles, _ = load_ground_truth(shared_path("models", "gt", "rignet_smith"))
    angle = np.radians(degrees)
    turn = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]])
    hands = []
    for points in (vertices, vertices @ turn.T):
        bones = game_skeleton(rigger.rig_mesh(points, triangles), points).skeleton
        hands.append(bones.heads[bones.names.index("LeftHand")] @ (np.eye(3) if points is vertices else turn))
    assert hands[0][0] > 0 and hands[1][0] > 0  # the character's left, facing +Z: +X


def test_a_quadruped_follows_the_same_scheme_from_its_hips():
    _, game, _ = rigged("quadruped")
    names = set(game.skeleton.names)
    assert {"root", "Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "Tail1", "Tail2", "LeftUpLeg", "RightLeg",
            "LeftArm", "RightForeArm"} <= names
    bones = game.skeleton
    assert bones.roots == (bones.names.index("root"),)
    assert bones.parents[bones.names.index("Hips")] == bones.names.index("root")
    assert bones.parents[bones.names.index("Tail1")] == bones.names.index("Hips")


def test_a_quadruped_s_hind_leg_bends_at_its_knee_and_its_hock():
    """The sample dog's game hind leg was an UpLeg running from the hip through the stifle (its knee) down to the hock,
    and a Leg from there to the paw: lifting the paw could not bend the knee. Now UpLeg, Leg and Foot meet at the knee
    and the hock (a share of the size)."""
    _, game, vertices = rigged("quadruped")
    bones = game.skeleton
    size = np.ptp(vertices, axis=0).max()
    position = {joint.name: np.array(joint.position) for joint in samples.character_joints("quadruped")}
    for side, word in (("L", "Left"), ("R", "Right")):
        thigh, shin, foot = (bones.names.index(f"{word}{part}") for part in ("UpLeg", "Leg", "Foot"))
        assert bones.parents[shin] == thigh and bones.parents[foot] == shin
        assert np.linalg.norm(bones.heads[shin] - position[f"thigh.{side}"]) <= 0.03 * size
        assert np.linalg.norm(bones.heads[foot] - position[f"shin.{side}"]) <= 0.03 * size


def test_a_bear_s_head_and_front_paws_get_their_own_bones():
    """The bear's skeleton ends at its head, where its ears join, by a link of no length: the head role fell on that
    link, so its game skeleton had Neck to Neck3 and no Head. And its front legs end in a bone running forward along
    the ground to the paw's tip, but the ankle was the joint nearest the ankle's height, that tip: the paw was part of
    the ForeArm and could not bend at the wrist."""
    skeleton, game, _ = rigged("bear")
    bones = game.skeleton
    parent = {name: bones.names[p] if p >= 0 else None for name, p in zip(bones.names, bones.parents)}
    assert parent["Head"].startswith("Neck") and parent["LeftEar1"] == parent["RightEar1"] == "Head"
    position = {joint.name: np.array(joint.position) for joint in samples.character_joints("bear")}
    size = np.ptp(load_character("bear")[0], axis=0).max()
    for side, word in (("L", "Left"), ("R", "Right")):
        hand = bones.names.index(f"{word}Hand")
        assert parent[f"{word}Hand"] == f"{word}ForeArm"
        assert np.linalg.norm(bones.heads[hand] - position[f"front_leg.{side}"]) <= 0.05 * size  # the wrist
        assert bones.tails[hand][1] < bones.heads[hand][1]  # forward (-Y), along the paw


def test_a_cow_s_front_legs_end_in_a_hoof_of_their_own():
    """The cow's skeleton has no joint above its front hooves, so its game ForeArm ran down to the ground and the hoof
    could not bend; a humanoid's forearm that ends without a hand got one, a quadruped's did not. Now its Hand runs
    from the named wrist, low on the leg, to the hoof's tip."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "cow.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    up = np.asarray(skeleton.body_plan.up)
    ground, top = (vertices @ up).min(), (vertices @ up).max()
    for word in ("Left", "Right"):
        hand = bones.names.index(f"{word}Hand")
        assert bones.names[bones.parents[hand]] == f"{word}ForeArm"
        assert bones.heads[hand] @ up - ground <= 0.15 * (top - ground)  # low on the leg
        assert bones.tails[hand] @ up < bones.heads[hand] @ up  # down to the hoof


def test_a_bird_s_one_neck_bone_gets_a_head_after_it():
    """rignet_17872, a bird, turned Z up as Blender imports it, with its neck cut to the first bone (as the skeleton
    once had it): its game skeleton had no Head, as only humanoids' necks were completed. Now every plan's are, on
    along the neck."""
    vertices, triangles, _ = load_ground_truth(shared_path("models", "gt", "rignet_17872"))
    vertices = np.column_stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]])  # Y up to Blender's Z up
    whole = rigger.rig_mesh(vertices, triangles)
    neck = [bone for bone, role in enumerate(whole.roles) if role.role in ("neck", "head")]
    kept = [bone for bone in range(len(whole)) if bone not in neck[1:]]  # no bone hangs from the neck's others
    skeleton = Skeleton([whole.names[bone] for bone in kept], whole.heads[kept], whole.tails[kept],
                        [kept.index(whole.parents[bone]) if whole.parents[bone] >= 0 else -1 for bone in kept],
                        whole.stages)
    skeleton.body_plan, skeleton.roles = recognise(skeleton, (vertices, triangles),
                                                   plane=whole.stages.get("mirror_plane"))
    assert skeleton.body_plan.kind == "bird"
    assert [role.role for role in skeleton.roles].count("neck") == 1 and "head" not in {r.role for r in skeleton.roles}
    bones = game_skeleton(skeleton, vertices).skeleton
    head, neck = bones.names.index("Head"), bones.names.index("Neck")
    assert bones.parents[head] == neck and bones.heads[head] == pytest.approx(bones.tails[neck])
    along = bones.tails[neck] - bones.heads[neck]
    assert (bones.tails[head] - bones.heads[head]) @ along > 0


def test_an_animal_s_neck_bends_along_its_length_and_its_ears_turn_with_its_head():
    """The deer's neck, three bones of Rigger's from the withers up to the skull, was one game bone, so it could only
    turn stiffly at its base; and its ears, which begin beside the head bone's start, hung from that Neck, so nodding
    the head left them behind. An animal's neck keeps its joints (Neck, Neck1, Neck2, as Mixamo numbers its spine) and
    ears hang from the Head."""
    vertices, triangles, _ = load_ground_truth(shared_path("models", "gt", "Quaternius_Deer"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    parent = {name: bones.names[p] if p >= 0 else None for name, p in zip(bones.names, bones.parents)}
    necks = sum(role.role == "neck" for role in skeleton.roles)
    assert necks >= 2
    assert [name for name in bones.names if name.startswith("Neck")] == ["Neck"] + [f"Neck{k}" for k in range(1, necks)]
    assert parent["Head"] == f"Neck{necks - 1}"
    assert parent["LeftEar1"] == parent["RightEar1"] == "Head"


@pytest.mark.parametrize("turn", [np.eye(3), np.diag([-1.0, 1.0, -1.0])])
def test_left_bones_are_on_the_character_s_left_whichever_way_it_faces(turn):
    """spot, a cartoon cow, faces -Z in its file, and turned about Y it faces +Z. Bone names put .L on +X, Blender's
    convention for a character facing the front view; facing away, the cow had its Left bones on its right, so a
    walk's left leg moved its right one."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "spot.obj"))
    vertices = vertices @ turn.T
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    middle = {name: 0.5 * (head + tail) for name, head, tail in zip(bones.names, bones.heads, bones.tails)}
    up = np.asarray(skeleton.body_plan.up)
    left = np.cross(up, middle["Neck"] - middle["Hips"])  # the neck's end is its front
    for word in ("Arm", "UpLeg"):
        assert (middle[f"Left{word}"] - middle[f"Right{word}"]) @ left > 0


def test_the_chain_going_on_from_a_bone_takes_the_name_and_a_branch_off_it_the_number():
    """spot's front legs each have a stub branching off the upper leg (a bump seen from the front), above where the
    lower leg goes on from it. Both are forearms; the stub, starting higher, took ``LeftForeArm`` and the lower leg
    ``LeftForeArm_2``, and Rigify's front leg followed the stub into the belly."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "spot.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    up = np.asarray(skeleton.body_plan.up)
    for side in ("Left", "Right"):
        forearms = [k for k, name in enumerate(bones.names) if name.startswith(f"{side}ForeArm")]
        assert len(forearms) == 2
        lowest = min(forearms, key=lambda k: bones.tails[k] @ up)
        assert bones.names[lowest] == f"{side}ForeArm"
        assert np.allclose(bones.heads[lowest], bones.tails[bones.names.index(f"{side}Arm")])


def test_a_foot_the_skeleton_lacks_runs_forward_along_the_ground():
    """homer's legs end at the ankles: his game Foot went on down the shin, 0.04 long, with no ToeBase, where game
    engines and foot IK expect a foot from the ankle to the ball and a toe on to the tip. He faces +Z."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "homer.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    size, ground = float(np.ptp(vertices, axis=0).max()), float(vertices[:, 1].min())
    for side in ("Left", "Right"):
        foot, toe = bones.names.index(f"{side}Foot"), bones.names.index(f"{side}ToeBase")
        assert bones.parents[toe] == foot and np.allclose(bones.tails[foot], bones.heads[toe])
        assert bones.tails[toe][2] - bones.heads[foot][2] >= 0.08 * size  # ahead ...
        assert bones.tails[toe][1] - ground <= 0.01 * size  # ... on the ground


def test_the_spine_ends_on_the_midline_where_the_neck_begins():
    """rignet_8333's shoulders begin at their named joints, off the midline: moving a shoulder's head there also moved
    the end of ``Spine2``, which all of them start from, so the spine ended 2.6% of the size off the midline, at one
    shoulder, and the neck began elsewhere."""
    vertices, triangles = load_obj(shared_path("models", "gt", "rignet_8333", "rignet_8333.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    plane, size = skeleton.stages["mirror_plane"], float(np.ptp(vertices, axis=0).max())
    end = bones.tails[bones.names.index("Spine2")]
    assert abs(end[plane.axis] - plane.offset) <= 1e-9 * size
    np.testing.assert_allclose(end, bones.heads[bones.names.index("Neck")], atol=1e-9 * size)


def test_a_plan_the_game_target_cannot_fill_falls_back_to_plain_saying_why():
    vertices, triangles = load_character("octopus")
    plan = rigger.rig_mesh(vertices, triangles).body_plan
    assert plan.kind == "other"
    target, warning = choose_target("game", plan)
    assert target.name == "plain" and "game target" in warning and "other" in warning


def test_cmu_and_mixamo_joints_map_onto_the_game_names():
    game = ["root", *sorted(MIXAMO), "LeftToeBase"]
    mapping = map_joints(CMU, CMU_PARENTS, game)
    by_name = {name: CMU[joint] for name, joint in mapping.driven.items()}
    assert by_name["Hips"] == "Hips" and by_name["LeftUpLeg"] == "LeftUpLeg" and by_name["RightForeArm"] == \
        "RightForeArm"
    assert [by_name[name] for name in ("Spine", "Spine1", "Spine2")] == ["LowerBack", "Spine", "Spine1"]
    # CMU's neck has two joints; the game's one Neck takes the one the head sits on (its turn is the upper neck's)
    assert by_name["Neck"] == "Neck1" and by_name["Head"] == "Head" and by_name["LeftToeBase"] == "LeftToeBase"
    assert {"LHipJoint", "Neck"} <= set(mapping.unused) and not mapping.undriven
    mixamo = [f"mixamorig:{name}" for name in ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftUpLeg",
                                               "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot",
                                               "LeftArm", "LeftForeArm", "RightArm", "RightForeArm")]
    parents = [-1, 0, 1, 2, 3, 4, 0, 6, 7, 0, 9, 10, 3, 12, 3, 14]
    mapping = map_joints(mixamo, parents, game)
    assert {name: mixamo[j].split(":")[1] for name, j in mapping.driven.items() if name.startswith("Spine")} == \
        {"Spine": "Spine", "Spine1": "Spine1", "Spine2": "Spine2"}
    assert normalised("mixamorig1_Left_Hand") == "lefthand" and "lthigh" in aliases("LeftUpLeg")


def test_a_clip_s_first_frame_is_left_out_when_it_is_a_reference_pose():
    """CMU's BVH files start with a reference pose, every joint at rest, before the captured motion: a walk baked
    from frame 1 flashed a T-pose at every loop. A clip that starts moving is kept whole."""
    frames = 20
    poses = np.tile(np.eye(4), (frames, 3, 1, 1))
    poses[:, :, 1, 3] = np.linspace(0.0, 0.2, frames)[:, None]  # walking 1 cm a frame
    poses[:, 2, 2, 3] = -0.5  # the hand hangs below the shoulder
    clip = Clip(("Hips", "Arm", "Hand"), np.array([-1, 0, 1]), np.tile(np.eye(4), (3, 1, 1)), poses, 120.0)
    assert captured(clip) == (clip, 0)
    reference = poses.copy()
    reference[0, 2, 2, 3] = 0.0  # the arm held out
    kept, skipped = captured(Clip(clip.names, clip.parents, clip.rest, reference, clip.fps))
    assert skipped == 1 and np.array_equal(kept.poses, poses[1:])


def test_a_motion_that_cannot_drive_the_legs_names_the_bones_and_joints():
    with pytest.raises(RetargetError) as error:
        map_joints(["Bone", "Bone1", "Bone2"], [-1, 0, 1], ["root", *sorted(MIXAMO)])
    message = str(error.value)
    assert "LeftUpLeg" in message and "Hips" in message and "Bone1" in message


def test_sole_points_hold_a_turned_foots_lowest_point():
    rng = np.random.default_rng(3)
    foot = rng.normal(size=(4000, 3))
    foot *= [0.04, 0.12, 0.03] / np.linalg.norm(foot, axis=1, keepdims=True)  # a foot-like ellipsoid, Z up
    sole = sole_points(foot, np.array([0.0, 0.0, 1.0]))
    assert len(sole) < len(foot) / 4 and all(any((point == foot).all(1)) for point in sole)
    for _ in range(200):  # turned up to 80 degrees about a level axis: the lowest point is a sole point
        angle = np.radians(rng.uniform(-80, 80))
        axis = np.r_[rng.normal(size=2), 0.0]
        axis /= np.linalg.norm(axis)
        cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        turn = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
        assert (sole @ turn.T)[:, 2].min() == pytest.approx((foot @ turn.T)[:, 2].min(), abs=0.001)


def test_a_second_arm_s_forearm_and_hand_take_its_number():
    """rignet_17364 has two arms a side: each forearm and hand takes the number of the arm it hangs from, and twins
    hang from one bone or from twins."""
    vertices, triangles = load_obj(shared_path("models", "gt", "rignet_17364", "rignet_17364.obj"))
    bones = game_skeleton(rigger.rig_mesh(vertices, triangles), vertices).skeleton
    chained = [name for name in bones.names if name.split("_")[0].endswith(("ForeArm", "Hand"))]
    assert {"LeftForeArm_2", "RightHand_2"} <= set(chained)
    for name in chained:
        parent = bones.names[bones.parents[bones.names.index(name)]]
        assert parent.partition("_")[2] == name.partition("_")[2], (name, parent)
    for left, name in enumerate(bones.names):  # twins hang from one bone or from twins (both shoulders: the Neck)
        if name.startswith("Left"):
            right = bones.names.index("Right" + name[4:])
            a, b = (bones.names[bones.parents[k]] for k in (left, right))
            assert a == b or (a.startswith("Left") and b == "Right" + a[4:]), (name, a, b)


@pytest.mark.parametrize("path", [("nogt", "homer.obj"),
                                  ("gt", "magicarticulate_0a59c5ff", "magicarticulate_0a59c5ff.obj")])
def test_a_humanoid_game_rig_has_hands_and_feet_though_its_limbs_end_without(path):
    """homer's legs end above its shoes and magicarticulate's fingers fork at the wrist: no Rigger bone is a foot or a
    hand. Game engines' humanoids need both: each forearm gets a Hand from its end, each shin a Foot, fingers on the
    Hand."""
    vertices, triangles = load_obj(shared_path("models", *path))
    bones = game_skeleton(rigger.rig_mesh(vertices, triangles), vertices).skeleton
    names = list(bones.names)
    for side in ("Left", "Right"):
        for limb, end in (("ForeArm", "Hand"), ("Leg", "Foot")):
            limb_at, end_at = names.index(side + limb), names.index(side + end)
            assert bones.parents[end_at] == limb_at
            assert bones.heads[end_at] == pytest.approx(bones.tails[limb_at])
            assert np.linalg.norm(bones.tails[end_at] - bones.heads[end_at]) > 0
        fingers = [k for k, name in enumerate(names) if name.startswith(f"{side}Hand") and name[-1] == "1"]
        assert all(names[bones.parents[k]] == f"{side}Hand" for k in fingers)


@pytest.mark.parametrize("name", ["ogre", "woody"])
def test_a_thigh_starts_at_the_hip_joint_wherever_the_skeleton_s_leg_began(name):
    """The ogre's loincloth hides the top of its legs: Rigger's leg chains run in from the pelvis down to where the
    thighs show, far below the hip joints, and the thigh bones are short; the game's UpLeg began there, the Hips
    holding the top of the thigh. woody's legs run up into his chest, far above his hip joints, and his UpLeg began
    there. It begins at the hip joint, up or down the skeleton's leg."""
    vertices, triangles = load_obj(shared_path("models", "nogt", f"{name}.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints, bones = named_joints(skeleton), game_skeleton(skeleton, vertices).skeleton
    size = float(np.ptp(vertices, axis=0).max())
    for side, word in (("L", "Left"), ("R", "Right")):
        thigh = bones.names.index(f"{word}UpLeg")  # twins mirrored after
        assert np.linalg.norm(bones.heads[thigh] - joints[("thigh", side, None)]) < 1e-3 * size
        assert bones.tails[thigh] == pytest.approx(bones.heads[bones.names.index(f"{word}Leg")])


def test_a_short_torso_s_spine_runs_up_from_the_hips_below_where_the_legs_hang_and_carries_the_arms():
    """woody's legs and arms all leave one junction of his skeleton, at 0.56 of his height, in his chest. The game's
    Hips began there and his arms hung from it: twisting his spine left his arms be. His Hips begin at the hips
    joint below, his spine runs up through the junction, his arms hang from it and his legs from the Hips."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "woody.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints, bones = named_joints(skeleton), game_skeleton(skeleton, vertices).skeleton
    names, up = list(bones.names), np.asarray(skeleton.body_plan.up)
    hips = names.index("Hips")
    assert bones.heads[hips] == pytest.approx(joints[("hips", None, None)])
    for side in ("Left", "Right"):
        shoulder = names.index(f"{side}Shoulder")
        assert names[bones.parents[shoulder]].startswith("Spine")
        assert bones.heads[hips] @ up < bones.heads[shoulder] @ up - 0.1 * np.ptp(vertices @ up)
        assert names[bones.parents[names.index(f"{side}UpLeg")]] == "Hips"


def test_a_leg_s_shin_begins_at_its_knee_not_at_a_turn_of_its_trousers_hem():
    """rignet_smith's trouser hem zigzags his leg's path just above the ankle. Seen from the leg's first and last
    joints that turn was taken for his knee: the game's Leg began at the hem, 0.12 of his height, while the knee's
    named joint lies at 0.22 (the artist's at 0.24). A leg's shin begins at the joint nearest the knee's place."""
    vertices, triangles = load_obj(shared_path("models", "gt", "rignet_smith", "rignet_smith.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints, bones = named_joints(skeleton), game_skeleton(skeleton, vertices).skeleton
    up = np.asarray(skeleton.body_plan.up)
    low, height = float((vertices @ up).min()), float(np.ptp(vertices @ up))
    for side, word in (("L", "Left"), ("R", "Right")):
        knee = bones.heads[bones.names.index(f"{word}Leg")]
        assert np.linalg.norm(knee - joints[("shin", side, None)]) < 0.01 * height
        assert (knee @ up - low) / height > 0.18


def test_a_leg_too_short_to_bend_gets_a_shin_from_its_knee():
    """cheburashka's stubby legs are one thigh bone each down to the ankle: the game rig had an UpLeg and nothing
    below, warned of the missing Leg and Foot, and no motion could walk it. The thigh is split at the named knee;
    the shin runs on to the ankle and gets its foot."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "cheburashka.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    assert not any(role.role == "shin" for role in skeleton.roles)
    joints, bones = named_joints(skeleton), game_skeleton(skeleton, vertices).skeleton
    names = list(bones.names)
    assert missing_humanoid_bones(names) == []
    size = float(np.ptp(vertices, axis=0).max())
    for side, word in (("L", "Left"), ("R", "Right")):
        thigh, shin, foot = (names.index(f"{word}{bone}") for bone in ("UpLeg", "Leg", "Foot"))
        assert bones.parents[shin] == thigh and bones.parents[foot] == shin
        assert np.linalg.norm(bones.heads[shin] - joints[("shin", side, None)]) < 1e-3 * size  # twins mirrored
        assert bones.tails[thigh] == pytest.approx(bones.heads[shin])
        assert bones.tails[shin] == pytest.approx(bones.heads[foot])


def test_a_spine_along_a_chain_named_for_a_side_stays_the_body_s_middle():
    """A mesh with every other face deleted rigged into a skeleton whose spine runs along a chain named ``.L``: its
    spine and chest bones took the side from the names, and the game target, which names a trunk only on the
    middle, crashed. The spine stays unsided, and the game skeleton has its Spine."""
    vertices, triangles = load_character("humanoid")
    skeleton = rigger.rig_mesh(vertices, triangles)
    names = [f"{name}.L" if role.role in ("spine", "chest") else name
             for name, role in zip(skeleton.names, skeleton.roles)]
    renamed = Skeleton(names, skeleton.heads, skeleton.tails, skeleton.parents, skeleton.stages)
    renamed.body_plan, renamed.roles = recognise(renamed, (vertices, triangles),
                                                 plane=skeleton.stages.get("mirror_plane"))
    assert all(role.side is None for role in renamed.roles if role.role in ("spine", "chest"))
    assert {"Hips", "Spine", "Spine1", "Spine2"} <= set(game_skeleton(renamed, vertices).skeleton.names)


@pytest.mark.parametrize("vertices, message", [(np.full((5, 3), np.nan), "NaN or infinite coordinates"),
                                               (np.zeros((0, 3)), "mesh has no vertices")])
def test_the_game_skeleton_of_a_mesh_with_bad_vertices_is_a_clear_error(vertices, message):
    skeleton, _, _ = rigged("humanoid")
    with pytest.raises(ValueError, match=message):
        game_skeleton(skeleton, vertices)


def test_a_missing_foot_is_the_mesh_ahead_of_its_own_ankle():
    """``foot_ahead`` on points: ankle at the origin, front +Y, up +Z, a foot 1 long expected. A paw of another leg
    1.6 ahead with nothing between is no foot (the sample quadruped's hind foot ran to its front paw). A foot whose
    vertices below the ankle begin only at its toes, 0.7 ahead, its instep above the ankle's height between, is one
    (rignet_smith's). So is a box foot with no vertex between its back, 0.3 ahead, and its toe."""
    from rigger.core.facing import Facing, foot_ahead

    faced = Facing(np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]), np.array([-1.0, 0.0, 0.0]), np.zeros(3),
                   False)
    ankle = np.zeros(3)

    def points(*rows):
        return np.array([(x, y, z) for y, z in rows for x in (-0.1, 0.1)])

    assert foot_ahead(points((1.6, -0.1), (1.8, -0.1), (-0.1, -0.1)), ankle, faced, 1.0) is None
    smith = foot_ahead(points((0.71, -0.3), (0.95, -0.3), (0.2, 0.1), (0.45, 0.1), (0.6, 0.05)), ankle, faced, 1.0)
    assert smith is not None and smith[1][1] == pytest.approx(0.95)
    box = foot_ahead(points((0.3, -0.1), (1.0, -0.1)), ankle, faced, 1.0)
    assert box is not None and box[1][1] == pytest.approx(1.0)


def test_a_hand_resting_on_the_hip_ends_at_its_fingertips_not_in_the_pelvis():
    """The hands-on-hips humanoid's arm ends where its hand touches the hip. The mesh on past that end, the hip's,
    counted as the hand's reach: the arm's roles had no hand, so the game rig's Hand went on from the forearm's end
    into the pelvis (0.16 off the fingertips) and would weigh the hip."""
    from rigger import samples

    skeleton, game, _ = rigged("humanoid_hips")
    assert {role.side for role in skeleton.roles if role.role == "hand"} == {"L", "R"}
    truth = samples.ground_truth_bones("humanoid_hips")
    tips = [truth.tails[truth.names.index(f"hand.{side}")] for side in "LR"]
    for side in ("Left", "Right"):
        end = game.skeleton.tails[game.skeleton.names.index(f"{side}Hand")]
        assert min(np.linalg.norm(end - tip) for tip in tips) < 0.05


def test_a_neck_running_into_a_round_head_gets_a_head():
    """A neck bone running into the middle of a round head with no bone going on (woody's skeleton with its head
    bones read as neck): the game rig's Head hangs from the Neck's end and reaches the top of the head, as Mixamo's
    do."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "woody.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    roles = [replace(role, role="neck") if role.role == "head" else role for role in skeleton.roles]
    necked = Skeleton(skeleton.names, skeleton.heads, skeleton.tails, skeleton.parents, roles=roles,
                      body_plan=skeleton.body_plan)
    bones = game_skeleton(necked, vertices).skeleton
    names = list(bones.names)
    neck, head = names.index("Neck"), names.index("Head")
    assert bones.parents[head] == neck and bones.roles[head].role == "head"
    assert bones.heads[head] == pytest.approx(bones.tails[neck])
    assert bones.tails[head] == pytest.approx(landmarks(skeleton)[("head_top", None, None)])
    assert {"LeftArm", "LeftForeArm", "LeftHand", "RightArm", "RightForeArm", "RightHand"} <= set(names)
