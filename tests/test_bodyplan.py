"""Body plan and bone roles (rigger.core.bodyplan, rigger.core.roles): the sample characters' true skeletons and
Rigger's own get the right plan and sensible roles, twins get twin roles, and bad input gets a clear error."""
from collections import Counter

import numpy as np
import pytest

import rigger
from characters import load_character
from conftest import shared_path
from meshes import box, combine, cylinder
from bodyplan import load as load_blender_frame
from rigdata import load_ground_truth, load_obj
from rigger import samples
from rigger.core import rooting
from rigger.core.body import read_body
from rigger.core.bodyplan import KINDS, BodyPlan, recognise
from rigger.core.mesh import Mesh
from rigger.core.game import game_skeleton
from rigger.core.roles import LANDMARKS, ROLES, BoneRole, Roles, landmarks, named_joints, within_reach
from rigger.core.skeleton import Skeleton
from rigger.core.stages import Labels, MirrorPlane

PLANS = {"humanoid": "humanoid", "humanoid_hips": "humanoid", "quadruped": "quadruped", "octopus": "other",
         "tree": "other", "snake": "fish"}
Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Blender's world (Z up) to an OBJ's (Y up)


@pytest.fixture(scope="module")
def rigged():
    """Rigger's skeleton of every sample character."""
    return {name: rigger.rig_mesh(*load_character(name)) for name in PLANS}


def truth(name):
    """(plan, roles) of the sample's true skeleton on its mesh."""
    return recognise(samples.ground_truth_bones(name), load_character(name))


def counted(roles):
    """How many bones have each (role, side)."""
    return Counter((role.role, role.side) for role in roles)


def has_sides(roles, *names):
    """Whether ``roles`` hold each of ``names`` on both sides."""
    found = counted(roles)
    return all(found[(name, "L")] and found[(name, "R")] for name in names)


@pytest.mark.parametrize("name", PLANS)
def test_the_true_skeletons_get_the_right_plan(name):
    plan, roles = truth(name)
    assert plan.kind == PLANS[name], plan.reason
    assert 0 < plan.confidence <= 1 and plan.reason
    assert len(roles) == len(samples.ground_truth_bones(name)) and all(role.role in ROLES for role in roles)


@pytest.mark.parametrize("name", PLANS)
def test_rigger_s_skeletons_get_the_right_plan(rigged, name):
    skeleton = rigged[name]
    assert skeleton.body_plan.kind == PLANS[name], skeleton.body_plan.reason
    assert len(skeleton.roles) == len(skeleton)


@pytest.mark.parametrize("name", ["humanoid", "humanoid_hips"])
def test_a_true_humanoid_has_two_legs_two_arms_and_a_head(name):
    plan, roles = truth(name)
    bones = dict(zip(samples.ground_truth_bones(name).names, roles))
    assert has_sides(roles, "thigh", "shin", "foot", "upper_arm", "forearm", "hand")
    assert plan.parts == {"legs": 2, "arms": 2}
    for side in "LR":  # each true bone gets its own role: the sample names its bones after their roles
        assert [bones[f"{bone}.{side}"].role for bone in ("thigh", "shin", "foot", "upper_arm", "forearm", "hand")] \
            == ["thigh", "shin", "foot", "upper_arm", "forearm", "hand"]
        assert bones[f"pelvis.{side}"].role == "hips" and bones[f"shoulder.{side}"].role == "shoulder"
    assert {bones[bone].role for bone in ("head", "head_top")} == {"head"} and bones["neck"].role == "neck"
    assert bones["spine"].role == "hips" and bones["chest"].role in ("spine", "chest")


def test_rigger_s_humanoid_has_two_legs_two_arms_and_a_head(rigged):
    roles = rigged["humanoid"].roles
    assert has_sides(roles, "thigh", "shin", "foot", "upper_arm", "forearm", "hand")
    assert counted(roles)[("head", None)] >= 1 and counted(roles)[("hips", None)] == 1


def test_rigger_s_humanoid_with_hands_on_hips_keeps_its_legs_arms_and_head(rigged):
    """Each hand rests on a hip, closing a loop the method cuts where the hand touches: the arms hang from the
    shoulders and are named as arms, though they bend down to the hips."""
    roles = rigged["humanoid_hips"].roles
    assert has_sides(roles, "thigh", "shin", "foot", "upper_arm", "forearm")
    assert counted(roles)[("head", None)] >= 1


def test_a_quadruped_has_four_legs_a_tail_and_a_head(rigged):
    for roles in (truth("quadruped")[1], rigged["quadruped"].roles):
        assert has_sides(roles, "thigh", "shin", "upper_arm", "forearm")  # hind and front legs
        assert counted(roles)[("head", None)] >= 1 and counted(roles)[("tail", None)] >= 1
    bones = dict(zip(samples.ground_truth_bones("quadruped").names, truth("quadruped")[1]))
    assert [bones[f"tail_0{k}"].role for k in (1, 2, 3)] == ["tail"] * 3
    assert [bones[f"tail_0{k}"].index for k in (1, 2, 3)] == [0, 1, 2]  # counted from the body outwards
    assert bones["thigh.L"].side == "L" and bones["upper_arm.R"].side == "R"


def test_a_snake_is_a_head_a_spine_and_a_tail_from_its_thick_end(rigged):
    for skeleton, roles in ((samples.ground_truth_bones("snake"), truth("snake")[1]),
                            (rigged["snake"], rigged["snake"].roles)):
        assert {role.role for role in roles} == {"head", "spine", "tail"}
        heads = [bone for bone, role in enumerate(roles) if role.role == "head"]
        tails = [bone for bone, role in enumerate(roles) if role.role == "tail"]
        head_end = skeleton.heads[heads].mean(axis=0)
        assert head_end[1] < skeleton.heads[tails].mean(axis=0)[1]  # the head lies at the -Y end


@pytest.mark.parametrize("path", [("nogt", "homer.obj"),
                                  ("gt", "magicarticulate_0a59c5ff", "magicarticulate_0a59c5ff.obj")])
def test_twin_limbs_get_twin_roles_though_the_mesh_differs_a_little_side_to_side(path):
    """homer's arms and magicarticulate's fingers: the thickness and reach measured on each side differ a little,
    which cut homer's arms at different joints and named the two hands' fingers differently."""
    vertices, triangles = load_obj(shared_path("models", *path))
    skeleton = rigger.rig_mesh(vertices, triangles)
    names = list(skeleton.names)
    twins = [(k, names.index(name[:-2] + ".R")) for k, name in enumerate(names)
             if name.endswith(".L") and name[:-2] + ".R" in names]
    assert twins
    for left, right in twins:
        a, b = skeleton.roles[left], skeleton.roles[right]
        assert (a.role, a.index, a.digit, a.side, b.side) == (b.role, b.index, b.digit, "L", "R"), names[left]


def test_a_head_on_the_midline_whose_tip_turns_aside_is_a_neck_and_head_not_an_arm():
    """homer's head chain runs up the mirror plane and ends aside: it is the neck and head (from halfway up, not at
    the crown), and the arms are two."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "homer.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    assert skeleton.body_plan.kind == "humanoid" and skeleton.body_plan.parts["arms"] == 2
    top = int(np.argmax(skeleton.tails @ np.asarray(skeleton.body_plan.up)))  # the head's chain reaches highest
    chain = skeleton.names[top].rsplit(".", 1)[0]
    bones = [k for k, name in enumerate(skeleton.names) if name.rsplit(".", 1)[0] == chain]
    roles = [skeleton.roles[k].role for k in bones]
    necks = roles.count("neck")
    assert roles == ["neck"] * necks + ["head"] * (len(roles) - necks) and necks >= 2 and len(roles) - necks >= 2
    assert all(skeleton.roles[k].side is None for k in bones)
    heights = skeleton.heads[bones] @ np.asarray(skeleton.body_plan.up)
    top = skeleton.tails[bones[-1]] @ np.asarray(skeleton.body_plan.up)
    assert 0.4 < (heights[necks] - heights[0]) / (top - heights[0]) < 0.7  # the head from about halfway up


def test_the_bone_the_ears_hang_from_is_the_head():
    """The Fox as Blender imports it (Z up): its neck runs to the ear base inside the skull, and a snout bone on from
    there. The narrowest joint is at the ear base, so the bone carrying the ears was a neck bone and turning "head"
    moved the muzzle alone. Ears are on the skull: the bone they hang from begins the head (a neck bone stays)."""
    vertices, triangles = load_obj(shared_path("models", "gt", "Quaternius_Fox", "Quaternius_Fox.obj"))
    skeleton = rigger.rig_mesh(vertices @ np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]).T, triangles)
    roles = skeleton.roles
    ears = [b for b, role in enumerate(roles) if role.role == "ear" and roles[skeleton.parents[b]].role != "ear"]
    assert len(ears) == 2 and {roles[skeleton.parents[b]].role for b in ears} == {"head"}
    assert "neck" in {role.role for role in roles}


def test_ears_hung_just_past_the_start_of_the_head_leave_the_spine_in_the_head():
    """The Shiba Inu in its file's frame: its ears hang from the snout bone, a hair past its start. The joint graph
    linked them to that bone's end, so the spine ran out along the snout and back to the ears' base, and the snout
    bone, taken for the last bone before the head, was a neck: the dog had no head. Hung at the bone's start, the
    spine ends at the snout and the bone the ears hang from is the head."""
    vertices, triangles = load_obj(shared_path("models", "gt", "Quaternius_ShibaInu", "Quaternius_ShibaInu.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    roles = skeleton.roles
    ears = [b for b, role in enumerate(roles) if role.role == "ear" and roles[skeleton.parents[b]].role != "ear"]
    assert ears and {roles[skeleton.parents[b]].role for b in ears} == {"head"}


def test_a_deer_s_head_begins_where_its_neck_turns_into_the_skull():
    """The deer's neck rises to its skull and its head points forward from there, 90 degrees on. Its neck was
    narrowest one joint lower, so its head began 0.16 of the size below the artist's Head joint, under the jaw, and
    Rigify's head control nodded it from the upper neck. A quadruped's head begins at a sharp turn past the neck's
    narrowest joint."""
    vertices, triangles, rig = load_ground_truth(shared_path("models", "gt", "Quaternius_Deer"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    size = np.ptp(vertices, axis=0).max()
    head = named_joints(skeleton)[("head", None, None)]
    assert np.linalg.norm(head - rig.positions[rig.names.index("Head")]) < 0.03 * size


def test_arms_reaching_out_from_where_the_legs_hang_are_arms():
    """woody, a gingerbread figure, has one junction for a torso: its arms leave it where its legs do. Arms that reach
    out level, not down to the ground, are arms there too."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "woody.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    assert skeleton.body_plan.kind == "humanoid" and skeleton.body_plan.parts == {"legs": 2, "arms": 2}
    for side in "LR":
        arm = [role.role for role in skeleton.roles if role.side == side and role.role not in ("hips", "thigh", "shin",
                                                                                             "foot", "toe")]
        assert {"shoulder", "upper_arm", "forearm", "hand"} <= set(arm), arm


def test_a_gingerbread_man_s_legs_hang_from_his_hips_not_his_chest():
    """woody's legs run up into the junction his arms leave (0.56 of his height): his hip joints were put 0.89 of
    the way up there, in his chest (0.50), and his knees above his crotch. A humanoid's hip joints lie no higher
    above the crotch than the legs lie off the mirror plane there, so the knees bend below it, in the legs."""
    vertices, triangles, _, _ = load_blender_frame("woody")
    skeleton = rigger.rig_mesh(vertices, triangles)
    height = np.ptp(vertices[:, 2])
    middle = np.abs(vertices[:, 0] - 0.5 * (vertices[:, 0].min() + vertices[:, 0].max())) < 0.01 * height
    crotch = np.sort(vertices[middle, 2])[0]  # the lowest vertex on the middle: the top of the gap between the legs
    joints = named_joints(skeleton)
    for side in "LR":
        hip, knee, ankle = (joints[(role, side, None)] for role in ("thigh", "shin", "foot"))
        assert crotch < hip[2] < crotch + 0.15 * height
        assert ankle[2] < knee[2] < crotch
    assert joints[("hips", None, None)][2] < joints[("upper_arm", "L", None)][2] - 0.1 * height


def test_feet_meeting_under_a_big_headed_figure_are_no_crotch():
    """cheburashka's big feet meet under him, just above his ankles' height: read as his crotch, it pulled his hip
    joints down his short legs and his knees to within 0.035 of his height of his ankles (the retargeted walk's knees
    then bent backwards in some frames). A crotch lies above the ankles."""
    vertices, triangles, _, _ = load_blender_frame("cheburashka")
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints, height = named_joints(skeleton), np.ptp(vertices[:, 2])
    for side in "LR":
        assert joints[("shin", side, None)][2] - joints[("foot", side, None)][2] > 0.045 * height


def test_a_gingerbread_man_s_head_sits_on_the_joint_his_arms_and_legs_leave():
    """woody's arms and legs all leave one joint, at 0.56 of his height: his trunk's first bones above it were
    read as his torso, up into his round head, and his head began at 0.83, at his eyes. A cut-out's half-width is
    the distance to its outline (the nearest vertex may lie anywhere on the sheet): his neck is the narrowing under
    his head, at 0.69, and his head begins there."""
    vertices, triangles, _, _ = load_blender_frame("woody")
    skeleton = rigger.rig_mesh(vertices, triangles)
    height = np.ptp(vertices[:, 2])
    head = (named_joints(skeleton)[("head", None, None)][2] - vertices[:, 2].min()) / height
    assert 0.66 < head < 0.72
    assert [role.role for role in skeleton.roles if role.side is None][:2] == ["hips", "neck"]


@pytest.mark.parametrize("blender", [False, True])
def test_a_big_headed_figure_s_short_legs_and_arms_are_legs_and_arms_and_its_ears_are_ears(blender):
    """cheburashka in its file's frame (Y up) and as Blender imports it (Z up): a head as wide as the figure is tall
    carries two big ears, and its short legs hang from 0.18 of the height. Its legs are legs, under an upright torso
    (a lying fish's low fins are not), and its arms are the limbs hanging below the head, not the longer ears at the
    spine's top end."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "cheburashka.obj"))
    skeleton = rigger.rig_mesh(vertices @ Y_UP.T if blender else vertices, triangles)
    plan, roles = skeleton.body_plan, skeleton.roles
    assert plan.kind == "humanoid" and plan.parts == {"legs": 2, "arms": 2, "ears": 2}, plan.reason
    assert has_sides(roles, "thigh", "upper_arm", "ear") and "head" in {role.role for role in roles}
    height = {role: max(skeleton.heads[b][2 if blender else 1] for b, r in enumerate(roles) if r.role == role)
              for role in ("upper_arm", "ear")}
    assert height["upper_arm"] < height["ear"]
    assert roles[skeleton.parents.tolist().index(-1)].role == "hips"


@pytest.mark.parametrize("name", ["octopus", "tree"])
def test_an_unknown_plan_keeps_plain_roles_and_says_why(rigged, name):
    for plan, roles in (truth(name), (rigged[name].body_plan, rigged[name].roles)):
        assert plan.kind == "other" and not plan.recognised
        assert {role.role for role in roles} == {"other"}
        assert plan.warning.startswith("body plan not recognised (") and plan.reason in plan.warning


def test_a_plan_recognised_without_much_confidence_says_so():
    """The flat alligator, all its vertices in one plane, is read as a fish with a confidence of 0.44, and the CLI
    said nothing. A plan recognised with a confidence under 0.5 now comes with a warning; a sure one with none."""
    vertices, triangles, _, _ = load_blender_frame("alligator")
    plan = rigger.rig_mesh(vertices, triangles).body_plan
    assert plan.recognised and plan.confidence < 0.5
    assert plan.warning.startswith(f"body plan {plan.kind} recognised with a low confidence") and plan.reason in \
        plan.warning
    sure = BodyPlan("quadruped", 0.9, "4 legs standing front and back under a body")
    assert sure.warning is None


@pytest.mark.parametrize("name", ["humanoid", "quadruped", "octopus"])
def test_twins_get_twin_roles(rigged, name):
    """Every role on one side has its twin on the other, index for index."""
    for roles in (truth(name)[1], rigged[name].roles):
        left = Counter((role.role, role.index, role.digit) for role in roles if role.side == "L")
        right = Counter((role.role, role.index, role.digit) for role in roles if role.side == "R")
        assert left == right and left


def test_a_chain_named_right_is_on_the_right_though_the_body_s_path_runs_through_it():
    """cheburashka read Y up has no mirror plane within 1%, and the body's longest path runs through its right ear:
    those bones got no side while their left twins had one."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "cheburashka.obj"))
    skeleton = rigger.rig_mesh(vertices @ Y_UP.T, triangles)  # as Blender imports it
    sided = [(name[-1], role.side) for name, role in zip(skeleton.names, skeleton.roles) if name[-2:] in (".L", ".R")]
    assert {side for side, _ in sided} == {"L", "R"} and all(side == given for side, given in sided)


@pytest.mark.parametrize("path, turn, head_towards, kind", [
    (("models", "nogt", "alligator.obj"), Y_UP, [-1.0, 0.0, 0.0], "fish"),
    (("models", "gt", "rignet_11814", "rignet_11814.obj"), np.eye(3), [0.0, 0.0, 1.0], None)])
def test_a_fish_s_head_is_its_wide_end(path, turn, head_towards, kind):
    """The alligator as Blender imports it (a flat side profile, thick at its head at -X, tapering to its tail) and
    rignet_11814 (a fish whose head, at +Z, has an open mouth): their joints lie near the surface at the head end,
    whose mesh radius looked thinner, so the head was taken for the tail. The head (else the neck) is the end the
    mesh is wider across. rignet_11814's plan is not asked: its pectoral fins reach the ground, and whether they
    are fins or a bird's legs sits on the leg test's threshold (``bench/results/robustness.md``)."""
    vertices, triangles = load_obj(shared_path(*path))
    skeleton = rigger.rig_mesh(vertices @ turn.T, triangles)
    assert kind is None or skeleton.body_plan.kind == kind
    front = "head" if any(given.role == "head" for given in skeleton.roles) else "neck"
    head, tail = (np.mean([skeleton.tails[b] for b, given in enumerate(skeleton.roles) if given.role == role], axis=0)
                  for role in (front, "tail"))
    assert (head - tail) @ head_towards > 0


@pytest.mark.parametrize("turn, head_towards", [(Y_UP, [0.0, -1.0, 0.0]), (np.eye(3), [0.0, 0.0, 1.0])])
def test_a_quadruped_s_head_is_its_higher_end_though_its_neck_is_thin(turn, head_towards):
    """rignet_15446, a crocodile with a big head: its spine ends in the thin neck at the head end and in the wide rump
    at the other. Read as Blender imports it, its head end was taken for the tail, its front legs for the hind ones:
    the higher end, the head's, lost to the thicker one."""
    vertices, triangles = load_obj(shared_path("models", "gt", "rignet_15446", "rignet_15446.obj"))
    skeleton = rigger.rig_mesh(vertices @ turn.T, triangles)
    assert skeleton.body_plan.kind == "quadruped"
    ends = {role: np.mean([skeleton.tails[b] for b, given in enumerate(skeleton.roles) if given.role in roles],
                          axis=0) for role, roles in (("head", ("head",)), ("tail", ("tail",)),
                                                      ("front", ("upper_arm", "forearm", "hand")),
                                                      ("hind", ("thigh", "shin", "foot")))}
    assert (ends["head"] - ends["tail"]) @ head_towards > 0
    assert (ends["front"] - ends["hind"]) @ head_towards > 0


def test_twins_named_joints_mirror_where_the_mesh_mirrors_only_nearly():
    """homer read as Blender imports it: its arms are mirror twins, but the mesh is a little thicker at one shoulder,
    so the shoulder joint was found one joint farther out on that arm than on the other. Its game skeleton's
    RightShoulder came out less than half as long as its LeftShoulder."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "homer.obj"))
    skeleton = rigger.rig_mesh(vertices @ Y_UP.T, triangles)
    plane, size = skeleton.stages["mirror_plane"], float(np.ptp(vertices, axis=0).max())
    joints = named_joints(skeleton)
    twins = [(joints[(role, "L", digit)], joints[(role, "R", digit)]) for role, side, digit in joints
             if side == "L" and (role, "R", digit) in joints]
    assert len(twins) >= 6
    for left, right in twins:
        assert np.linalg.norm(plane.reflect(left[None])[0] - right) <= 0.005 * size


def test_sides_follow_the_bone_names_and_the_mirror_plane(rigged):
    skeleton = rigged["humanoid"]
    for name, role in zip(skeleton.names, skeleton.roles):
        if name.endswith((".L", ".R")):
            assert role.side == name[-1]
    plan, roles = recognise(Skeleton(["b%02d" % k for k in range(len(skeleton))], skeleton.heads, skeleton.tails,
                                     skeleton.parents), load_character("humanoid"))  # no names to go by
    for role, head, tail in zip(roles, skeleton.heads, skeleton.tails):
        if role.side:
            assert np.sign((head + tail)[0]) == (1 if role.side == "L" else -1)  # Blender's +X is the left


def test_named_joints_are_where_roles_begin():
    skeleton = samples.ground_truth_bones("humanoid")
    plan, roles = truth("humanoid")
    joints = named_joints(skeleton, roles)
    position = {joint.name: joint.position for joint in samples.character_joints("humanoid")}
    np.testing.assert_allclose(joints[("shin", "L", None)], position["thigh.L"])  # the knee: where the thigh ends
    np.testing.assert_allclose(joints[("thigh", "R", None)], position["pelvis.R"])
    np.testing.assert_allclose(joints[("hips", None, None)], position["root"])
    with pytest.raises(ValueError, match="one role per bone"):
        named_joints(skeleton)  # a skeleton not recognised yet


def test_named_joints_run_along_the_trunk_whichever_way_its_bones_point():
    """A quadruped's trunk rooted at the withers, its bones pointing back to the hips (as the silhouette method roots
    a deer), and the same trunk rooted at the hips: either way the hips begin at the rump, then the spine, the chest
    and the neck, each where the role before it ends."""
    front_to_back = np.array([[0, 0.6, 1], [0, 0.2, 1], [0, -0.2, 1], [0, -0.6, 1]], dtype=float)
    neck = np.array([[0, 0.6, 1], [0, 0.9, 1.3]], dtype=float)
    roles = [BoneRole("chest"), BoneRole("spine"), BoneRole("hips"), BoneRole("neck")]
    rooted_at_withers = Skeleton(("a", "b", "c", "d"), np.r_[front_to_back[:3], neck[:1]],
                                 np.r_[front_to_back[1:], neck[1:]], [-1, 0, 1, 0])
    rooted_at_hips = Skeleton(("a", "b", "c", "d"), np.r_[front_to_back[1:], neck[:1]],
                              np.r_[front_to_back[:3], neck[1:]], [1, 2, -1, 0])
    for skeleton in (rooted_at_withers, rooted_at_hips):
        joints = named_joints(skeleton, roles)
        for role, expected in (("hips", front_to_back[3]), ("spine", front_to_back[2]),
                               ("chest", front_to_back[1]), ("neck", front_to_back[0])):
            np.testing.assert_allclose(joints[(role, None, None)], expected)


# Where each role of the sample humanoid begins: the true joint a named joint should lie at (the sample names a
# joint after the bone that ends there: its "thigh.L" joint is the knee).
TRUE_JOINTS = {("hips", None): "root", ("thigh", "L"): "pelvis.L", ("shin", "L"): "thigh.L", ("foot", "L"): "shin.L",
               ("thigh", "R"): "pelvis.R", ("shin", "R"): "thigh.R", ("foot", "R"): "shin.R",
               ("forearm", "L"): "upper_arm.L", ("hand", "L"): "forearm.L", ("neck", None): "chest"}


@pytest.mark.parametrize("source, within", [("true", 0.025), ("rigger", 0.045)])
def test_named_joints_lie_where_the_humanoid_s_joints_are(rigged, source, within):
    """The knee, ankle, hip joint, wrist... of the sample humanoid, placed along its chains (not at bone ends), lie
    near the true joints (a share of its size), on the true skeleton and on Rigger's (whose shoulder joints, found
    where the arm leaves the torso, lie 0.04 off the true ones)."""
    if source == "true":
        skeleton = samples.ground_truth_bones("humanoid")
        skeleton.body_plan, skeleton.roles = truth("humanoid")
    else:
        skeleton = rigged["humanoid"]
    vertices, _ = load_character("humanoid")
    size = np.ptp(vertices, axis=0).max()
    position = {joint.name: np.array(joint.position) for joint in samples.character_joints("humanoid")}
    joints = named_joints(skeleton)
    for (role, side), name in TRUE_JOINTS.items():
        assert np.linalg.norm(joints[(role, side, None)] - position[name]) <= within * size, (role, side)
    ends = np.concatenate([skeleton.heads, skeleton.tails])
    knee = joints[("shin", "L", None)]
    assert np.linalg.norm(ends - knee, axis=1).min() > 1e-6  # between bone ends: on a bone, not at its end


def test_named_joints_and_landmarks_follow_the_skeleton_when_it_moves(rigged):
    skeleton = rigged["humanoid"]
    turn = np.array([[0.0, -2.0, 0.0, 1.0], [2.0, 0.0, 0.0, -3.0], [0.0, 0.0, 2.0, 0.5], [0.0, 0.0, 0.0, 1.0]])
    moved = skeleton.transformed(turn)
    for places in (named_joints, landmarks):
        before, after = places(skeleton), places(moved)
        assert before.keys() == after.keys() and before
        for key, point in before.items():
            np.testing.assert_allclose(after[key], turn[:3, :3] @ point + turn[:3, 3], atol=1e-9)


def test_landmarks_mark_the_ends_of_the_body(rigged):
    """Head top, hand and toe tips reach the mesh's ends; heels lie on the ground behind the ankles (the humanoid
    faces -Y); twins mirror."""
    skeleton = rigged["humanoid"]
    vertices, _ = load_character("humanoid")
    size = np.ptp(vertices, axis=0).max()
    found = landmarks(skeleton)
    joints = named_joints(skeleton)
    assert {key[0] for key in found} <= set(LANDMARKS)
    assert abs(found[("head_top", None, None)][2] - vertices[:, 2].max()) <= 0.03 * size
    for side, sign in (("L", 1), ("R", -1)):
        assert sign * found[("hand_tip", side, None)][0] >= 0.97 * sign * vertices[:, 0].max() * sign
        heel, toe, ankle = (found[("heel", side, None)], found[("toe_tip", side, None)], joints[("foot", side, None)])
        assert abs(heel[2] - vertices[:, 2].min()) <= 0.01 * size and heel[1] > ankle[1] > toe[1]
    mirrored = found[("heel", "R", None)] * [-1, 1, 1]
    assert np.linalg.norm(found[("heel", "L", None)] - mirrored) <= 0.02 * size
    assert landmarks(samples.ground_truth_bones("humanoid")) == {}  # not recognised yet


def test_rerooting_across_a_gap_keeps_one_tree():
    """A trunk bone hanging off its parent's end with a gap (no joint there) still turns and still hangs from it."""
    skeleton = Skeleton(("trunk.00", "trunk.01", "leg.L", "leg.R"), [[0, 0, 2.0], [0, 0, 1.45], [0, 0, 1], [0, 0, 1]],
                        [[0, 0, 1.5], [0, 0, 1.0], [0.3, 0, 0], [-0.3, 0, 0]], [-1, 0, 1, 1])
    moved = rooting.rerooted(skeleton, 1, 1)
    assert moved.parents.tolist() == [-1, 0, 0, 0] and moved.roots == (0,)
    np.testing.assert_array_equal(moved.heads[:2], [[0, 0, 1.0], [0, 0, 1.5]])


def test_rerooting_a_root_off_the_way_hangs_it_from_the_new_tree():
    """Rooted at a neck bone with the spine and the front legs hanging from its head (spot, as its file has it):
    the spine turns, and the neck, not on the way, hangs from the bone now ending where it starts: one root, at the
    hips. So do the front legs: hanging from the neck, turning the head swung them."""
    skeleton = Skeleton(("trunk.00", "limb01.00", "limb01.01", "leg.L", "leg.R", "arm.L", "arm.R"),
                        [[0, 0, 2.0], [0, 0, 2.0], [0, 0, 1.5], [0, 0, 1], [0, 0, 1], [0, 0, 2.0], [0, 0, 2.0]],
                        [[0, 0.5, 2.5], [0, 0, 1.5], [0, 0, 1.0], [0.3, 0, 0], [-0.3, 0, 0], [0.3, 0, 1.0],
                         [-0.3, 0, 1.0]], [-1, 0, 1, 2, 2, 0, 0])
    moved = rooting.rerooted(skeleton, 2, 1)
    assert moved.roots == (0,) and moved.names[:3] == ("limb01.00", "limb01.01", "trunk.00")
    np.testing.assert_array_equal(moved.heads[:3], [[0, 0, 1.0], [0, 0, 1.5], [0, 0, 2.0]])
    # the neck and the front legs from the spine's end, the legs from the root
    assert moved.parents.tolist() == [-1, 0, 1, 0, 0, 1, 1]


@pytest.mark.parametrize("name, within", [("head_with_nose", 0.016), ("four_arms", 0.06)])
def test_a_humanoid_s_head_begins_where_its_neck_meets_the_skull(name, within):
    """The mesh is thinnest near the crown of a head as wide as its neck, so the neck's thinnest joint there put the
    head's start near the top (0.022 and 0.076 of the size off): turning the head left the face behind. A humanoid's
    head begins in the lower part of the way from the neck's base to the head's top, where the artists put it."""
    vertices, triangles = load_character(name)
    truth = samples.ground_truth_bones(name)
    true_head = truth.heads[truth.names.index("head")]
    head = named_joints(rigger.rig_mesh(vertices, triangles))[("head", None, None)]
    assert np.linalg.norm(head - true_head) <= within * np.ptp(vertices, axis=0).max()


def test_a_mirror_plane_runs_along_the_body_not_across_it():
    """A lying body's joints in a line pair across any plane cut through them: no mirror plane is fitted there."""
    vertices = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 0.13) for z in (0.0, 0.1 + 0.07 * x)])
    vertices[7] += [0.0, 0.05, 0.02]  # no symmetry of the mesh either
    triangles = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                          [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    points = np.array([[x, 0.06, 0.06] for x in np.linspace(0.05, 0.95, 7)])
    log = Skeleton([f"b{k}" for k in range(6)], points[:-1], points[1:], [-1, 0, 1, 2, 3, 4])
    assert read_body(log, Mesh(vertices, triangles)).plane is None


def test_a_floating_figure_does_not_stand_on_a_flat_patch_atop_its_head():
    """Flat faces at an end that spread little across the body are no base to stand on: up stays the preferred +Z
    (a post with a pointed foot, a small flat top and two crossed bars for arms and wings, whose flat ends are small
    too)."""
    def box(low, high):
        corners = [[x, y, z] for z in (low[2], high[2]) for x, y in ((low[0], low[1]), (high[0], low[1]),
                                                                    (high[0], high[1]), (low[0], high[1]))]
        return np.array(corners, dtype=float)

    faces = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                      [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    parts = [box((-0.05, -0.05, 0.1), (0.05, 0.05, 1.0)), box((-0.5, -0.05, 0.7), (0.5, 0.05, 0.8)),
             box((-0.05, -0.5, 0.7), (0.05, 0.5, 0.8))]
    vertices = np.concatenate(parts + [[[0.0, 0.0, 0.0]]])
    triangles = np.concatenate([faces[2:]] + [faces + 8 * k for k in (1, 2)]
                               + [[[24, 1, 0], [24, 2, 1], [24, 3, 2], [24, 0, 3]]])  # the post's foot: a point
    figure = Skeleton(["post", "arm.L", "arm.R"], [[0, 0, 0.05], [0, 0, 0.75], [0, 0, 0.75]],
                      [[0, 0, 0.95], [0.45, 0, 0.75], [-0.45, 0, 0.75]], [-1, 0, 0])
    plan, _ = recognise(figure, Mesh(vertices, triangles))
    np.testing.assert_allclose(plan.up, [0, 0, 1], atol=1e-9)


def test_the_plan_stands_in_an_obj_s_frame_and_at_any_scale():
    """Turned Y up (an OBJ read as it is) and scaled, the humanoid keeps its plan and roles, up from its legs."""
    skeleton = samples.ground_truth_bones("humanoid")
    vertices, triangles = load_character("humanoid")
    plan, roles = truth("humanoid")
    for turn, scale in ((Y_UP, 1.0), (Y_UP, 1e-200), (np.eye(3), 1e200)):
        moved = Skeleton(skeleton.names, skeleton.heads @ turn.T * scale, skeleton.tails @ turn.T * scale,
                         skeleton.parents)
        turned_plan, turned_roles = recognise(moved, (vertices @ turn.T * scale, triangles))
        assert turned_plan.kind == "humanoid" and turned_roles == roles
        np.testing.assert_allclose(turned_plan.up, turn @ [0, 0, 1], atol=1e-9)


def test_rig_mesh_fills_in_the_plan_the_roles_and_their_labels(rigged):
    skeleton = rigged["humanoid"]
    assert isinstance(skeleton.body_plan, BodyPlan) and skeleton.timings["body_plan"] > 0
    stage = skeleton.stages["roles"]
    assert isinstance(stage, Roles) and stage.texts == tuple(role.label for role in skeleton.roles)
    drawing = stage.drawing()
    assert isinstance(drawing, Labels) and len(drawing.points) == len(skeleton)
    np.testing.assert_allclose(drawing.points, 0.5 * (skeleton.heads + skeleton.tails))
    bones = skeleton.to_dict()["bones"]
    assert [(bone["role"], bone["side"], bone["role_index"], bone["digit"]) for bone in bones] == \
        [(role.role, role.side, role.index, role.digit) for role in skeleton.roles]
    assert set(skeleton.body_plan.to_dict()) == {"kind", "confidence", "reason", "parts"}  # no points: frame-free
    moved = skeleton.transformed(np.diag([2.0, 2.0, 2.0, 1.0]))
    assert moved.roles == skeleton.roles and moved.body_plan is skeleton.body_plan


def descendants(skeleton, bone):
    """Every bone below ``bone`` in the hierarchy."""
    below, todo = set(), [bone]
    while todo:
        found = set(skeleton.children(todo.pop())) - below
        below |= found
        todo += found
    return below


@pytest.mark.parametrize("name", ["quadruped", "bear"])
def test_a_body_with_legs_hangs_from_its_pelvis(name):
    """The silhouette method roots these at the withers (their most central branch point), so turning a spine bone
    swung the hind legs and the hips hung from the chest. rig_mesh roots them where the hind legs start: the trunk
    runs from the hips forwards, each bone from its parent's end, and no spine bone carries a leg."""
    skeleton = rigger.rig_mesh(*load_character(name))
    (root,) = skeleton.roots
    assert skeleton.names[root] == "trunk.00" and skeleton.roles[root].label == "hips"
    legs = [bone for bone, role in enumerate(skeleton.roles) if role.side and role.role == "hips"]
    assert len(legs) == 2 and all(skeleton.parents[leg] == root for leg in legs)
    np.testing.assert_allclose(skeleton.heads[legs], skeleton.heads[[root, root]], atol=1e-12)
    trunk = [bone for bone, role in enumerate(skeleton.roles) if role.role in ("spine", "chest")]
    assert trunk and all(np.allclose(skeleton.heads[bone], skeleton.tails[skeleton.parents[bone]]) for bone in trunk)
    leg_bones = set(legs).union(*(descendants(skeleton, leg) for leg in legs))
    assert not any(descendants(skeleton, bone) & leg_bones for bone in trunk)


def test_rerooting_turns_the_bones_between_the_old_root_and_the_new_one():
    """A trunk rooted at the chest (a, then b down to the hips), legs from its lower end, a neck from its upper end
    with an ear hanging off it near its start (no joint), and a second root: rooted at the hips, a and b turn round
    and trade places (and so names: the root is bone 0, trunk.00, as before), the legs hang from the new root, the
    neck from the bone now ending at the chest, the ear from the neck still and the other root stays; the joints
    and the plan's named places are where they were."""
    chest, middle, hips, knee_l, knee_r = [0, 0, 2.0], [0, 0, 1.5], [0, 0, 1.0], [0.3, 0, 0.5], [-0.3, 0, 0.5]
    neck_top, ear_head, ear_tip, rock = [0, 0.2, 2.5], [0.1, 0.05, 2.1], [0.3, 0.2, 2.9], [3.0, 0, 0]
    heads = [chest, middle, hips, hips, chest, ear_head, rock]
    tails = [middle, hips, knee_l, knee_r, neck_top, ear_tip, [3.0, 0, 1.0]]
    names = ("trunk.00", "trunk.01", "limb01.00.L", "limb01.00.R", "limb02.00", "limb03.00", "rock.00")
    roles = [BoneRole("chest"), BoneRole("hips"), BoneRole("thigh", "L"), BoneRole("thigh", "R"), BoneRole("neck"),
             BoneRole("other"), BoneRole("other")]
    skeleton = Skeleton(names, heads, tails, [-1, 0, 1, 1, 0, 4, -1], roles=roles,
                        body_plan=BodyPlan("humanoid", 1.0, "test", joints={("hips", None, None): ((1, 1.0, 1.0),)}))
    assert rooting.pelvis(skeleton) == (1, 1)
    moved = rooting.rerooted(skeleton, 1, 1)
    assert moved.names == names
    np.testing.assert_array_equal(moved.heads[:2], [hips, middle])
    np.testing.assert_array_equal(moved.tails[:2], [middle, chest])
    assert moved.parents.tolist() == [-1, 0, 0, 0, 1, 4, -1]
    assert moved.roles == (roles[1], roles[0], *roles[2:]) and rooting.pelvis(moved) is None
    np.testing.assert_array_equal(np.unique(moved.joints(), axis=0), np.unique(skeleton.joints(), axis=0))
    np.testing.assert_allclose(named_joints(moved)[("hips", None, None)], hips)


def test_labels_read_well():
    assert BoneRole("thigh", "L").label == "thigh.L"
    assert BoneRole("spine", None, 2).label == "spine.2"
    assert BoneRole("finger", "R", 1, "index").label == "finger.index.1.R"
    assert BoneRole("finger", "R").to_dict() == {"role": "finger", "side": "R", "index": 0, "digit": None}


def test_a_plain_stick_is_no_known_plan():
    vertices = np.array([[x, y, z] for x in (0, 0.1) for y in (0, 0.1) for z in (0, 1)], dtype=float)
    triangles = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                          [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    stick = Skeleton(["stick"], [[0.05, 0.05, 0.0]], [[0.05, 0.05, 1.0]], [-1])
    plan, roles = recognise(stick, Mesh(vertices, triangles))
    assert plan.kind == "other" and roles == (BoneRole("other"),) and plan.kind in KINDS


def test_two_parts_far_apart_across_their_mirror_plane_stand_some_way():
    """Two cubes 1000 apart along x: thin along y and z beside that, and the mirror plane's normal is x, so no axis
    is a candidate for up among the thick ones: up is then chosen among all, and a plan read."""
    vertices, triangles = combine(box((0, 0, 0), (1, 1, 1)), box((1000, 0, 0), (1001, 1, 1)))
    two = Skeleton(["left", "right"], [[0.5, 0.0, 0.5], [1000.5, 0.0, 0.5]], [[0.5, 1.0, 0.5], [1000.5, 1.0, 0.5]],
                   [-1, -1])
    plane = MirrorPlane(0, 500.5, np.eye(3)[0])
    plan, roles = recognise(two, Mesh(vertices, triangles), plane=plane)
    assert plan.kind in KINDS and len(roles) == 2


@pytest.mark.parametrize("arguments, message", [
    (("not a skeleton", None), "needs a rigger Skeleton"),
    ((samples.ground_truth_bones("snake"), "no mesh"), "Mesh or a \\(vertices, triangles\\) pair"),
    ((samples.ground_truth_bones("snake"), (np.zeros((3, 3)), [[0, 1, 2]])), "zero size"),
])
def test_bad_input_gets_a_clear_error(arguments, message):
    with pytest.raises(ValueError, match=message):
        recognise(*arguments)


def test_bad_settings_and_values_get_a_clear_error():
    skeleton = samples.ground_truth_bones("snake")
    with pytest.raises(ValueError, match="prefer_up must be a non-zero 3D vector"):
        recognise(skeleton, load_character("snake"), prefer_up=(0, 0, 0))
    with pytest.raises(ValueError, match="unknown bone role 'wing_tip'"):
        BoneRole("wing_tip")
    with pytest.raises(ValueError, match="side is 'L', 'R' or None"):
        BoneRole("thigh", "left")
    with pytest.raises(ValueError, match="only fingers have a digit"):
        BoneRole("hand", "L", 0, "thumb")
    with pytest.raises(ValueError, match="one rigger.core.roles.BoneRole per bone"):
        skeleton.roles = [BoneRole("spine")]
    with pytest.raises(ValueError, match="must be a rigger.core.bodyplan.BodyPlan"):
        skeleton.body_plan = "humanoid"
    with pytest.raises(ValueError, match="one string per point"):
        Labels(np.zeros((2, 3)), ("only one",))


def test_how_finely_a_spine_is_cut_does_not_decide_a_legless_plan():
    """The penguin's flippers leave its spine a third of the way up. Whether they are "arms high on an upright body"
    is a share of the spine's length, not of its joints: the plan stays a bird with its head cut in one bone. (Turned
    Z up, as Blender imports it: the plan prefers Z up, so read in the file's frame it lies down.)"""
    vertices, triangles = load_obj(shared_path("models", "gt", "rignet_8184", "rignet_8184.obj"))
    vertices = vertices @ np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]).T
    skeleton = rigger.rig_mesh(vertices, triangles)
    up = np.asarray(skeleton.body_plan.up)
    middle = [bone for bone, name in enumerate(skeleton.names) if not name.endswith((".L", ".R"))]
    last = max(middle, key=lambda bone: skeleton.tails[bone] @ up)
    merged = skeleton.parents[last]  # the head's last two bones become one
    assert merged in middle and skeleton.names[merged].rsplit(".", 1)[0] == skeleton.names[last].rsplit(".", 1)[0]
    keep = [bone for bone in range(len(skeleton)) if bone != last]
    tails = skeleton.tails.copy()
    tails[merged] = skeleton.tails[last]
    index = {bone: k for k, bone in enumerate(keep)}
    coarser = Skeleton([skeleton.names[b] for b in keep], skeleton.heads[keep], tails[keep],
                       [index[skeleton.parents[b]] if skeleton.parents[b] >= 0 else -1 for b in keep])
    plan, _ = recognise(coarser, (vertices, triangles), plane=skeleton.stages.get("mirror_plane"), prefer_up=up)
    assert plan.kind == "bird"


def test_a_wing_s_bones_in_the_body_are_its_shoulder():
    """The penguin's flipper chains start on its spine: their first bone, inside the chest, was a `wing` bone, so
    raising "the wing" turned the flipper about the chest's middle and carried the chest with it. Bones up to where
    the wing leaves the body are its shoulder, as an arm's are; the wing's own bones start where the artist's do."""
    vertices, triangles, rig = load_ground_truth(shared_path("models", "gt", "rignet_8184"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    assert skeleton.body_plan.kind == "bird"
    size = np.ptp(vertices, axis=0).max()
    for side, artist in (("L", "joint_7"), ("R", "joint_0")):
        shoulders = [bone for bone, role in enumerate(skeleton.roles) if role.role == "shoulder" and role.side == side]
        wings = [bone for bone, role in enumerate(skeleton.roles) if role.role == "wing" and role.side == side]
        assert shoulders and wings
        first = min(wings, key=lambda bone: abs(skeleton.heads[bone, 0]))
        assert skeleton.parents[first] in shoulders
        assert np.linalg.norm(skeleton.heads[first] - rig.positions[rig.names.index(artist)]) < 0.02 * size


def test_a_knee_bends_below_where_the_thigh_begins():
    """The ogre's legs slant out from its belly through its loincloth before they turn down: the corner where they
    turn down was taken for the knee, and the hip joint, on the thigh's line up from the knee, fell near the middle
    of the belly. The knee is a bend below where the thigh's bones begin; the hip joint then stands above it."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "ogre.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints, up = named_joints(skeleton), np.asarray(skeleton.body_plan.up)
    height = float(np.ptp(vertices @ up))
    for side in ("L", "R"):
        thighs = [bone for bone, role in enumerate(skeleton.roles) if role.role == "thigh" and role.side == side]
        top = max(float(skeleton.heads[bone] @ up) for bone in thighs)  # where the thigh's bones begin
        hip, knee = joints[("thigh", side, None)], joints[("shin", side, None)]
        assert knee @ up < top - 0.02 * height
        rise = hip - knee
        assert rise @ up > np.cos(np.radians(30)) * np.linalg.norm(rise)  # the thigh stands up from the knee


def test_a_quadruped_s_hind_leg_stands_on_its_toes(rigged):
    """The sample dog's hind leg bends forward at its knee (the stifle, 0.35 m up) and back at its hock (0.14 m up),
    and stands on its paw. Its roles were a human leg's: the knee at the hock, the ankle on the ground, so the game
    skeleton's thigh ran straight through the stifle and could not bend there. A quadruped's hind ankle is its hock:
    the foot begins there and the knee lies between it and the hip joint."""
    skeleton = rigged["quadruped"]
    vertices, _ = load_character("quadruped")
    size = np.ptp(vertices, axis=0).max()
    position = {joint.name: np.array(joint.position) for joint in samples.character_joints("quadruped")}
    joints = named_joints(skeleton)
    for side in ("L", "R"):
        assert np.linalg.norm(joints[("shin", side, None)] - position[f"thigh.{side}"]) <= 0.03 * size
        assert np.linalg.norm(joints[("foot", side, None)] - position[f"shin.{side}"]) <= 0.03 * size
        foot = next(bone for bone, role in enumerate(skeleton.roles) if role.role == "foot" and role.side == side)
        assert np.linalg.norm(skeleton.heads[foot] - position[f"shin.{side}"]) <= 0.03 * size


def test_a_target_s_knee_moves_up_past_a_stub_of_shin():
    """The cow's skeleton has a joint just above its hock and none at its knee: the game's knee stayed there, its Leg
    a stub 0.04 of the height long that squashed the hock when the knee bent, because the named knee lay farther off
    than the stub's length allows. A stub the move only lengthens does not limit it; a named joint past a short
    bone's end, or off to the side, stays out of reach."""
    joint, ends = np.zeros(3), [np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -0.1])]
    assert within_reach(joint, [0.0, 0.0, 0.3], ends)  # up the long bone: the stub grows
    assert not within_reach(joint, [0.0, 0.0, 0.9], ends)  # the long bone would shrink to a tenth
    assert not within_reach(joint, [0.0, 0.0, -0.3], ends)  # past the stub's end
    assert not within_reach(joint, [0.3, 0.0, 0.0], ends)  # off to the side
    assert not within_reach(joint, [0.0, 0.0, 0.3], [ends[0], np.array([0.0, 0.0, -0.3])])  # no stub: as before
    vertices, triangles = load_obj(shared_path("models", "nogt", "cow.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    bones = game_skeleton(skeleton, vertices).skeleton
    joints, height = named_joints(skeleton), float(np.ptp(vertices @ np.asarray(skeleton.body_plan.up)))
    knees = [joints[("shin", side, None)] for side in ("L", "R")]  # the game's Left is the cow's own left
    for word in ("Left", "Right"):
        leg = bones.names.index(f"{word}Leg")
        assert min(np.linalg.norm(bones.heads[leg] - knee) for knee in knees) <= 1e-9 * height
        assert np.linalg.norm(bones.tails[leg] - bones.heads[leg]) > 0.08 * height


def test_an_arm_turning_at_its_deltoid_has_its_elbow_farther_down():
    """The ogre's arm turns by 26 degrees under its deltoid, a fifth of the way from the shoulder joint to the hand's
    end, and by 25 at its elbow, a third of the way: the sharper was taken for the elbow, and bending the forearm
    folded the biceps. A bend counts the less the farther it lies from where an elbow belongs."""
    vertices, triangles = load_obj(shared_path("models", "nogt", "ogre.obj"))
    skeleton = rigger.rig_mesh(vertices, triangles)
    joints = named_joints(skeleton)
    for side in ("L", "R"):
        shoulder, tip = joints[("upper_arm", side, None)], landmarks(skeleton)[("hand_tip", side, None)]
        for elbow in (joints[("forearm", side, None)],
                      *[skeleton.heads[bone] for bone, role in enumerate(skeleton.roles)
                        if role.role == "forearm" and role.side == side and role.index == 0]):
            along = np.linalg.norm(elbow - shoulder) / np.linalg.norm(tip - shoulder)
            assert 0.3 < along < 0.5


def clean_and_noisy(name, seed):
    """((vertices, noisy vertices), triangles) of a ``../shared`` artist-rigged model as Blender imports it (Z up),
    the noise a twentieth of a percent of its size per vertex position (seams stay closed), seeded."""
    vertices, triangles = load_obj(shared_path("models", "gt", name, f"{name}.obj"))
    vertices = vertices @ np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]).T
    _, position = np.unique(vertices, axis=0, return_inverse=True)
    size = float(np.ptp(vertices, axis=0).max())
    noise = np.random.default_rng(seed).normal(0.0, 0.0005 * size, (position.max() + 1, 3))
    return (vertices, vertices + noise[position.ravel()]), triangles


def test_arms_high_on_a_legless_body_are_judged_by_height_not_by_the_spine_s_length():
    """rignet_15930, a legless ghost (Z up, as Blender imports it), with noise a twentieth of a percent of its size:
    its head grows a nose, the spine runs out along it and wiggles, and its arms, a little above halfway up the body,
    left the spine before halfway along it: the ghost was no humanoid. How high the arms hang is a height."""
    meshes, triangles = clean_and_noisy("rignet_15930", seed=0)
    for mesh in meshes:
        skeleton = rigger.rig_mesh(mesh, triangles)
        assert skeleton.body_plan.kind == "humanoid", skeleton.body_plan.summary()


def test_a_log_whose_spine_runs_into_one_end_cap_does_not_taper():
    """A column lying down is a log, no fish: it neither tapers nor curves. Noise too small to see can make its
    spine run on to the middle of one end cap, where the mesh is no thickness at all; each end's thickness is the
    thickest the body is there, so that tip does not make the log taper."""
    vertices, triangles = cylinder(0.06, 0.5)
    vertices = vertices[:, [2, 1, 0]]  # lying along x, Z up
    joints = np.column_stack([np.linspace(0.0, 0.45, 6), np.zeros(6), np.zeros(6)])  # from one cap's centre
    skeleton = Skeleton([f"trunk.{k:02d}" for k in range(5)], joints[:-1], joints[1:], [-1, 0, 1, 2, 3])
    plane = MirrorPlane(1, 0.0, np.array([0.0, 1.0, 0.0]))  # the log's left and right, as the method finds them
    plan, _ = recognise(skeleton, (vertices, triangles), plane=plane, prefer_up=np.array([0.0, 0.0, 1.0]))
    assert plan.kind == "other" and "neither tapers nor curves" in plan.reason, plan.summary()


def test_a_foot_turned_along_the_ground_leaves_a_leg_a_leg():
    """rignet_8338, a quadruped (Z up, as Blender imports it), with noise a twentieth of a percent of its size: a
    front foot grows a bone turned in along the ground. A leg runs down at least 0.45 of its length; the bone after
    the foot has reached the ground no longer counts against it, so the front legs stay legs and the plan a
    quadruped."""
    meshes, triangles = clean_and_noisy("rignet_8338", seed=1)
    for mesh in meshes:
        skeleton = rigger.rig_mesh(mesh, triangles)
        assert skeleton.body_plan.kind == "quadruped", skeleton.body_plan.summary()


def test_a_leg_whose_foot_curls_in_to_the_middle_keeps_its_side():
    """A leg reaching out to one side and down, its foot turned in to the mirror plane (a crow's toes, a cow's
    horns meeting over its head): a limb is on the side it reaches farthest into, not only where its tip ends."""
    vertices, triangles = box((-0.3, -0.1, 0.0), (0.3, 0.1, 1.0))
    joints = {"hips": (0.0, 0.0, 0.5), "chest": (0.0, 0.0, 0.9)}
    heads, tails, parents, names = [joints["hips"]], [joints["chest"]], [-1], ["trunk.00"]
    for sign, side in ((1, "L"), (-1, "R")):
        path = [joints["hips"], (0.2 * sign, 0.0, 0.4), (0.2 * sign, 0.0, 0.05), (0.0, 0.0, 0.0)]
        for k, (head, tail) in enumerate(zip(path, path[1:])):
            parents.append(0 if k == 0 else len(heads) - 1)
            heads.append(head)
            tails.append(tail)
            names.append(f"limb01.{k:02d}.{side}")
    skeleton = Skeleton(names, np.array(heads), np.array(tails), parents)
    body = read_body(skeleton, Mesh(vertices, triangles), plane=MirrorPlane(0, 0.0, np.array([1.0, 0.0, 0.0])))
    assert sorted(limb.side for limb in body.limbs) == [-1, 1]
