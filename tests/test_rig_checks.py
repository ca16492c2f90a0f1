"""The rig checks of ``rig_checks`` on hand-built skeletons whose answers are known, and on the true skeletons of the
generated characters (no Blender needed)."""
import numpy as np
import pytest

import rig_checks as rc
from rigger import samples
from rigger.core.skeleton import Skeleton


def skeleton(bones):
    """A ``Skeleton`` from (name, head, tail, parent name or None) rows."""
    names = [name for name, _, _, _ in bones]
    return Skeleton(names, [head for _, head, _, _ in bones], [tail for _, _, tail, _ in bones],
                    np.array([names.index(parent) if parent else -1 for _, _, _, parent in bones], dtype=np.int32))


def figure(arm_tip=(0.8, 0.0, 1.4), right_arm_tip=None):
    """A stick figure 2 m tall: a spine from the hips up to a head, two arms off the chest, two legs off the hips
    (the hips are the root joint of the spine and both legs). ``arm_tip``: the left hand's end."""
    left, right = np.array(arm_tip), np.array(right_arm_tip if right_arm_tip is not None else
                                              np.multiply(arm_tip, (-1.0, 1.0, 1.0)))
    return skeleton([
        ("spine", (0, 0, 1.0), (0, 0, 1.4), None),
        ("head", (0, 0, 1.4), (0, 0, 2.0), "spine"),
        ("arm.L", (0, 0, 1.4), (0.4, 0, 1.4), "spine"),
        ("hand.L", (0.4, 0, 1.4), tuple(left), "arm.L"),
        ("arm.R", (0, 0, 1.4), (-0.4, 0, 1.4), "spine"),
        ("hand.R", (-0.4, 0, 1.4), tuple(right), "arm.R"),
        ("leg.L", (0, 0, 1.0), (0.2, 0, 0.0), None),
        ("leg.R", (0, 0, 1.0), (-0.2, 0, 0.0), None),
    ])


def test_sides_are_read_from_blender_suffixes():
    assert [rc.side_of(name) for name in ("limb02.01.L", "arm.R", "trunk.00", "L", "x.l")] == ["L", "R", None, None,
                                                                                               None]
    assert rc.side_counts(figure()) == (3, 3)
    unnamed = skeleton([("spine", (0, 0, 0), (0, 0, 1), None), ("arm", (0, 0, 1), (0.5, 0, 1), "spine")])
    assert rc.side_counts(unnamed) == (0, 0)


def test_unsided_bones_are_those_off_the_plane_without_a_side():
    bones = skeleton([("spine", (0, 0, 0), (0, 0, 1), None), ("arm", (0, 0, 1), (0.5, 0, 1), "spine"),
                      ("arm.L", (0, 0, 1), (0.5, 0, 1), "spine"), ("tail", (0, 0, 0), (0.05, 0, -1), "spine")])
    assert rc.unsided_off_plane(bones, 2.0) == ["arm"]  # the tail's midpoint is 0.025 off: on the plane
    assert rc.unsided_off_plane(bones, 2.0, plane=(0, 0.5)) == ["spine", "arm", "tail"]


def test_twins_of_a_mirror_image_match_and_a_moved_hand_is_measured():
    assert rc.twin_mismatches(figure(), 2.0) == {"arm": 0.0, "hand": 0.0, "leg": 0.0}
    moved = rc.twin_mismatches(figure(right_arm_tip=(-0.8, 0.0, 1.3)), 2.0)
    assert moved["arm"] == 0.0 and moved["hand"] == pytest.approx(0.05)  # 0.1 m off in a 2 m figure
    bones = figure()
    shifted = Skeleton(bones.names, bones.heads + (0.1, 0, 0), bones.tails + (0.1, 0, 0), bones.parents)
    assert max(rc.twin_mismatches(shifted, 1.0, plane=(0, 0.1)).values()) == pytest.approx(0.0, abs=1e-12)
    assert rc.twin_mismatches(shifted, 1.0)["hand"] == pytest.approx(0.2)


def test_chains_run_from_a_root_or_a_branch_to_a_leaf_or_the_next_branch():
    bones = figure()
    found = [[bones.names[bone] for bone in chain] for chain in rc.chains(bones)]
    assert found == [["spine"], ["head"], ["arm.L", "hand.L"], ["arm.R", "hand.R"], ["leg.L"], ["leg.R"]]
    by_first = {bones.names[chain[0]]: chain for chain in rc.chains(bones)}
    assert rc.chain_parent(bones, by_first["arm.L"]) == bones.names.index("spine")
    assert rc.chain_parent(bones, by_first["leg.R"]) == -1


def test_chains_in_a_ball_count_the_chains_running_through_it_not_those_grazing_it():
    head = figure()
    assert len(rc.chains_in_ball(head, (0, 0, 1.7), 0.3)) == 1  # the head; the spine ends where the ball begins
    doubled = skeleton([*[(name, head_, tail, parent) for name, head_, tail, parent in [
        ("spine", (0, 0, 1.0), (0, 0, 1.4), None), ("head", (0, 0, 1.4), (0, 0, 2.0), "spine")]],
        ("nose", (0, 0, 1.4), (0, -0.1, 1.9), "spine")])
    chains = rc.chains_in_ball(doubled, (0, 0, 1.7), 0.3)
    assert [[doubled.names[bone] for bone in chain] for chain in chains] == [["head"], ["nose"]]
    assert len(rc.chains_in_ball(doubled, (0, 0, 1.7), 0.3, min_inside=2.1)) == 0  # neither holds 0.63 m inside


def test_nearest_joint_and_bone():
    bones = figure()
    distance, joint = rc.nearest_joint(bones, (0.45, 0.0, 1.45))
    assert distance == pytest.approx(np.hypot(0.05, 0.05)) and joint.tolist() == [0.4, 0.0, 1.4]
    index, distance = rc.nearest_bone(bones, (0.6, 0.1, 1.4))
    assert bones.names[index] == "hand.L" and distance == pytest.approx(0.1)


def test_stray_joints_are_those_far_from_every_true_joint():
    truth = figure()
    bent = skeleton([("spine", (0, 0, 1.0), (0, 0, 1.4), None), ("head", (0, 0, 1.4), (0, 0, 2.0), "spine"),
                     ("leg.L", (0, 0, 1.0), (0.1, 0, 0.5), None), ("shin.L", (0.1, 0, 0.5), (0.21, 0, 0.0), "leg.L")])
    assert rc.stray_joints(bent, truth, 2.0).tolist() == [[0.1, 0.0, 0.5]]  # mid-leg; the foot is 1 cm off: near
    assert len(rc.stray_joints(truth, truth, 2.0)) == 0


def test_a_skeleton_follows_every_limb_of_itself():
    truth = figure()
    limbs = rc.limbs(truth, truth, 2.0)
    assert set(limbs) == {"head", "hand.L", "hand.R", "leg.L", "leg.R"}  # leaves, each from the root or a branch
    assert limbs["hand.L"].bones == ("arm.L", "hand.L") and limbs["leg.R"].bones == ("leg.R",)
    assert all(limb.distance == pytest.approx(0.0, abs=1e-12) and limb.followed() for limb in limbs.values())
    hand = limbs["hand.L"]
    assert [truth.names[bone] for bone in hand.path] == ["hand.L", "arm.L", "spine"]
    assert [truth.names[bone] for bone in hand.carrying] == ["arm.L", "hand.L"]  # from the top down
    assert rc.limb_recall(truth, truth, 2.0) == 1.0


def test_a_missing_limb_is_not_followed_and_a_near_one_is():
    truth = figure()
    without_hand = skeleton([row for row in [("spine", (0, 0, 1.0), (0, 0, 1.4), None),
                                             ("head", (0, 0, 1.4), (0, 0, 2.0), "spine"),
                                             ("arm.L", (0, 0, 1.4), (0.4, 0, 1.4), "spine"),
                                             ("leg.L", (0, 0, 1.0), (0.2, 0, 0.0), None),
                                             ("leg.R", (0, 0, 1.0), (-0.2, 0, 0.0), None)]])
    limbs = rc.limbs(truth, without_hand, 2.0)
    assert not limbs["hand.R"].followed() and limbs["hand.R"].distance > 0.1
    assert not limbs["hand.L"].followed()  # half of it, the hand, 0.1-0.4 m from the arm's end
    assert limbs["head"].followed() and limbs["leg.L"].followed()
    assert rc.limb_recall(truth, without_hand, 2.0) == pytest.approx(3 / 5)
    lifted = figure()
    lifted = Skeleton(lifted.names, lifted.heads + (0, 0.05, 0), lifted.tails + (0, 0.05, 0), lifted.parents)
    assert rc.limbs(truth, lifted, 2.0)["head"].distance == pytest.approx(0.025)  # 5 cm in 2 m
    assert rc.limb_recall(truth, lifted, 2.0) == 1.0 and rc.limb_recall(truth, lifted, 2.0, tolerance=0.02) == 0.0


@pytest.mark.parametrize("name", [name for name in samples.CHARACTERS if name not in samples.NEAR_SYMMETRIC and any(
    joint.name.endswith(".L") for joint in samples.character_joints(name))])
def test_true_skeletons_of_mirrored_characters_pass_their_own_checks(name):
    truth = samples.ground_truth_bones(name)
    size = truth.extent
    assert set(rc.twin_mismatches(truth, size).values()) == {0.0}
    assert rc.unsided_off_plane(truth, size) == []
    left, right = rc.side_counts(truth)
    assert left == right > 0
    assert rc.limb_recall(truth, truth, size) == 1.0


def test_the_near_symmetric_human_s_true_twins_miss_by_a_few_percent():
    truth = samples.ground_truth_bones("humanoid_handmade")
    size = truth.extent
    worst = max(rc.twin_mismatches(truth, size).values())
    assert 0.01 < worst < 0.1
