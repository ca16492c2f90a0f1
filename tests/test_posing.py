"""The posing benchmark's maths (bench/posing_math.py): poses, skinning, the fit and the measures."""
import numpy as np
import pytest

import posing_math as pm
import rigdata
from conftest import shared_path

RING = 8  # vertices around each tube ring
ALONG = np.linspace(0.05, 0.95, 6)  # where the rings sit along each bone: the tubes do not touch


def tube(joints, parents, radius=0.05):
    """A mesh of one open tube per bone (joint ``parents[j]`` to joint ``j``) and its weights: each ring follows the
    bone's head joint, blended linearly into the parent joint over the bone's first third.

    Returns vertices (V, 3), triangles (M, 3) and a dense (V, J) weight matrix.
    """
    vertices, triangles, rows = [], [], []
    for joint, parent in enumerate(parents):
        if parent < 0:
            continue
        head, tail = joints[parent], joints[joint]
        axis = (tail - head) / np.linalg.norm(tail - head)
        side = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        up = np.cross(axis, side)
        start = len(vertices)
        for ring, along in enumerate(ALONG):
            centre = head + along * (tail - head)
            blend = min(along / 0.34, 1.0)
            for k in range(RING):
                angle = 2 * np.pi * k / RING
                vertices.append(centre + radius * (np.cos(angle) * side + np.sin(angle) * up))
                row = np.zeros(len(joints))
                row[parent] += blend
                grandparent = parents[parent]
                row[grandparent if grandparent >= 0 else parent] += 1.0 - blend
                rows.append(row)
            if ring:
                for k in range(RING):
                    a, b = start + (ring - 1) * RING + k, start + (ring - 1) * RING + (k + 1) % RING
                    triangles += [(a, b, b + RING), (a, b + RING, a + RING)]
    return np.array(vertices), np.array(triangles), np.array(rows)


# A two-armed body, mirror-symmetric in x only: a spine up from the pelvis (joint 0), arms out from the chest, a leg
# down on each side with a foot pointing to -y.
BODY_JOINTS = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.4], [0.0, 0.0, 1.7],  # pelvis, chest, head top
                        [0.3, 0.0, 1.4], [0.6, 0.0, 1.4], [-0.3, 0.0, 1.4], [-0.6, 0.0, 1.4],  # arms
                        [0.15, 0.0, 0.5], [0.15, 0.0, 0.0], [0.15, -0.2, 0.0],  # legs and feet
                        [-0.15, 0.0, 0.5], [-0.15, 0.0, 0.0], [-0.15, -0.2, 0.0]])
BODY_PARENTS = np.array([-1, 0, 1, 1, 3, 1, 5, 0, 7, 8, 0, 10, 11])


@pytest.fixture(scope="module")
def body():
    vertices, triangles, weights = tube(BODY_JOINTS, BODY_PARENTS)
    return vertices, triangles, pm.SkinnedRig.of(BODY_JOINTS, BODY_PARENTS, weights)


def fitted_errors(rig, vertices, targets):
    fitter = pm.Fitter(rig, vertices)
    size = np.ptp(vertices, axis=0).max()
    return np.array([np.linalg.norm(pm.deformed(rig, fitter.fit(target)[0], vertices) - target, axis=1).mean()
                     for target in targets]) / size


def test_random_poses_turn_every_joint_within_the_limit_and_move_the_mesh(body):
    vertices, _, rig = body
    rotations = pm.random_rotations(500, 35.0, np.random.default_rng(1))
    angles = np.degrees(np.arccos(np.clip((np.trace(rotations, axis1=1, axis2=2) - 1) / 2, -1, 1)))
    assert angles.max() <= 35.0 + 1e-9 and angles.max() > 30.0
    assert np.allclose(np.einsum("nij,nkj->nik", rotations, rotations), np.eye(3))
    poses = pm.random_poses(rig, 3, 35.0, np.random.default_rng(2))
    moved = [pm.deformed(rig, pose, vertices) for pose in poses]
    assert all(np.linalg.norm(m - vertices, axis=1).max() > 0.05 for m in moved)
    # a child's head goes where its parent carries it: the chain stays connected
    world_r, world_t = poses[0]
    for joint in range(1, len(rig)):
        parent = rig.parents[joint]
        assert np.allclose(world_r[joint] @ rig.heads[joint] + world_t[joint],
                           world_r[parent] @ rig.heads[joint] + world_t[parent])


def test_the_rest_pose_leaves_the_mesh_where_it_is(body):
    vertices, _, rig = body
    identity = pm.posed_from_local(rig, np.tile(np.eye(3), (len(rig), 1, 1)))
    assert np.allclose(pm.deformed(rig, identity, vertices), vertices)


def test_a_rig_fitted_to_its_own_poses_reproduces_them(body):
    vertices, _, rig = body
    targets = [pm.deformed(rig, pose, vertices) for pose in pm.random_poses(rig, 3, 35.0, np.random.default_rng(3))]
    assert fitted_errors(rig, vertices, targets).max() < 1e-6


def test_the_stick_floor_reproduces_poses_far_worse_than_the_rig(body):
    vertices, _, rig = body
    targets = [pm.deformed(rig, pose, vertices) for pose in pm.random_poses(rig, 3, 35.0, np.random.default_rng(4))]
    stick = pm.nearest_bone_rig([[0.0, 0.0, 0.0], [0.0, 0.0, 0.85]], [[0.0, 0.0, 0.85], [0.0, 0.0, 1.7]], [-1, 0],
                                vertices)
    assert fitted_errors(stick, vertices, targets).mean() > 0.01
    # the fit never does worse than its first pass, and a rig with a bone that moves nothing still fits
    spare = pm.SkinnedRig.of(np.vstack([BODY_JOINTS, [[0.0, 0.0, 1.9]]]), np.r_[BODY_PARENTS, 2],
                             np.hstack([tube(BODY_JOINTS, BODY_PARENTS)[2], np.zeros((len(vertices), 1))]))
    assert fitted_errors(spare, vertices, targets).max() < 1e-6


def test_a_crack_is_the_gap_between_split_duplicates_that_follow_different_bones(body):
    vertices, _, rig = body
    ring = np.flatnonzero(np.isclose(vertices[:, 0], 0.3 + 0.3 * ALONG[2]))  # a ring of the right forearm: joint 3
    assert len(ring) == RING
    split = np.vstack([vertices, vertices[ring]])
    weights = np.vstack([tube(BODY_JOINTS, BODY_PARENTS)[2], np.eye(len(rig))[np.full(len(ring), 4)]])
    same = np.vstack([tube(BODY_JOINTS, BODY_PARENTS)[2], tube(BODY_JOINTS, BODY_PARENTS)[2][ring]])
    size = np.ptp(split, axis=0).max()
    pairs = pm.coincident_pairs(split, size)
    assert sorted(map(tuple, np.sort(pairs, axis=1))) == sorted(zip(ring, len(vertices) + np.arange(RING)))
    pose = pm.random_poses(rig, 1, 35.0, np.random.default_rng(5))[0]
    torn = pm.deformed(pm.SkinnedRig.of(BODY_JOINTS, BODY_PARENTS, weights), pose, split)
    gap, worst = pm.crack(torn, pairs)
    expected = np.linalg.norm(torn[ring] - torn[len(vertices):], axis=1).max()
    assert gap == pytest.approx(expected) and gap > 0.01
    welded = pm.deformed(pm.SkinnedRig.of(BODY_JOINTS, BODY_PARENTS, same), pose, split)
    assert pm.crack(welded, pairs)[0] < 1e-12
    assert pm.crack(vertices, np.zeros((0, 2), dtype=int)) == (0.0, -1)


def bones_of(joints, parents):
    """Bones (heads, tails, parents) of a joint tree, one per parent→child pair, as the benchmark's skeletons."""
    children = np.flatnonzero(parents >= 0)
    bone_of_joint = np.full(len(parents), -1)
    bone_of_joint[children] = np.arange(len(children))
    return joints[parents[children]], joints[children], bone_of_joint[parents[children]]


def test_limb_recall_is_one_for_a_skeleton_against_itself_and_names_a_missed_limb():
    heads, tails, parents = bones_of(BODY_JOINTS, BODY_PARENTS)
    recall, outcome = pm.limb_recall(BODY_JOINTS, BODY_PARENTS, heads, tails, parents, 1.7)
    assert recall == 1.0 and len(outcome) == 5  # the head, two arms, two legs
    # without the right arm (joints 5, 6) one chain of five is lost, and it is the one ending at joint 6
    keep = np.array([joint not in (5, 6) for joint in range(len(BODY_JOINTS))])
    joints = BODY_JOINTS[keep]
    kept_parents = rigdata.kept_ancestors(BODY_PARENTS, keep)
    recall, outcome = pm.limb_recall(BODY_JOINTS, BODY_PARENTS, *bones_of(joints, kept_parents), 1.7)
    assert recall == pytest.approx(0.8)
    assert [chain[-1] for chain, followed in outcome if not followed] == [6]


def test_a_skeleton_shifted_by_more_than_the_tolerance_no_longer_follows():
    heads, tails, parents = bones_of(BODY_JOINTS, BODY_PARENTS)
    near = pm.limb_recall(BODY_JOINTS, BODY_PARENTS, heads + [0, 0.02, 0], tails + [0, 0.02, 0], parents, 1.0)[0]
    far = pm.limb_recall(BODY_JOINTS, BODY_PARENTS, heads + [0, 0.04, 0], tails + [0, 0.04, 0], parents, 1.0)[0]
    assert near == 1.0 and far == 0.0


def test_the_mirror_plane_of_a_two_sided_body_and_its_twins(body):
    vertices, triangles, _ = body
    size = np.ptp(vertices, axis=0).max()
    plane = pm.mirror_plane(vertices + [0.2, 0.0, 0.0], triangles, size)
    assert plane.axis == 0 and plane.offset == pytest.approx(0.2) and plane.two_sided()
    names = ["spine", "arm.L", "arm.R", "hand.L", "hand.R", "tail", "ear"]
    heads = np.array([[0, 0, 1.0], [0.1, 0, 1.4], [-0.1, 0, 1.4], [0.6, 0, 1.4], [-0.6, 0, 1.4], [0, 0, 1.0],
                      [0.2, 0, 1.7]])
    tails = heads + [[0, 0, 0.4], [0.5, 0, 0], [-0.5, 0, 0], [0.1, 0, 0], [-0.1, 0, 0], [0, -0.3, 0], [0.1, 0, 0.1]]
    centred = pm.MirrorPlane(0, 0.0, 0.0)
    assert pm.twin_mismatches(names, heads, tails, centred, 1.0) == {"arm": 0.0, "hand": 0.0}
    tails[4] += [0.0, 0.0, 0.03]  # the right hand's tail moves 0.03 up: its twin's mirror image is that far off
    assert pm.twin_mismatches(names, heads, tails, centred, 1.0)["hand"] == pytest.approx(0.03)
    assert pm.unsided_off_plane(names, heads, tails, centred, 1.0) == ["ear"]


def test_the_mirror_plane_of_a_body_holding_a_prop_to_one_side_is_the_body_s(body):
    vertices, triangles, _ = body
    size = np.ptp(vertices, axis=0).max()
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    prop = np.array([[x, y, z] for x in (high[0], high[0] + 0.1 * size) for y in (0.0, 0.01) for z in (1.0, 1.01)])
    faces = len(vertices) + np.array([[0, 1, 2], [1, 3, 2], [4, 6, 5], [5, 6, 7]])
    plane = pm.mirror_plane(np.vstack([vertices, prop]), np.vstack([triangles, faces]), size)
    assert 0.5 * (low[0] + high[0] + 0.1 * size) > 0.04 * size  # the box's centre is off the body's plane ...
    assert plane.axis == 0 and abs(plane.offset) <= pm.PLANE_STEP * size and plane.two_sided()  # ... the plane is not


def test_a_body_without_a_mirror_plane_is_not_two_sided():
    rng = np.random.default_rng(6)
    vertices = rng.uniform(0.0, 1.0, (400, 3)) ** [1.0, 3.0, 0.5]
    triangles = rng.integers(0, 400, (300, 3))
    assert not pm.mirror_plane(vertices, triangles, 1.0).two_sided()


def test_a_rig_rejects_a_vertex_without_weights():
    with pytest.raises(ValueError, match="1 vertices have no skin weight"):
        pm.SkinnedRig.of(BODY_JOINTS[:2], [-1, 0], np.array([[1.0, 0.0], [0.0, 0.0]]))


@pytest.mark.parametrize("name", ["CesiumMan", "rignet_8338"])
def test_an_artist_rig_fitted_to_its_own_poses_lands_at_zero_and_follows_its_own_limbs(name):
    folder = shared_path("models", "gt", name)
    vertices, _, rig = rigdata.load_ground_truth(folder)
    artist = pm.artist_rig(rig)
    targets = [pm.deformed(artist, pose, vertices)
               for pose in pm.random_poses(artist, 2, 35.0, np.random.default_rng(7))]
    assert fitted_errors(artist, vertices, targets).max() < 1e-5
    skeleton = rigdata.armature_skeleton(rig)[0]
    size = np.ptp(vertices, axis=0).max()
    recall, outcome = pm.limb_recall(rig.positions, rig.parents, skeleton.heads, skeleton.tails, skeleton.parents,
                                     size)
    assert recall == 1.0 and len(outcome) >= 5


def test_the_benchmark_measures_every_rig_on_a_real_model():
    pytest.importorskip("bpy")
    import posing

    record = posing.measure(shared_path("models", "gt", "rignet_15930"), seeds=[3], poses=2)
    assert record["errors"] == {} and record["bones"]["rigger"] > 3
    rigs = record["seeds"]["3"]["rigs"]
    assert rigs["artist"]["mean"] < 1e-5 and len(rigs["artist"]["per_pose"]) == 2
    assert rigs["stick"]["mean"] > 3 * max(rigs["artist_skin"]["mean"], rigs["rigger"]["mean"])
    assert record["seeds"]["3"]["excess"] == pytest.approx(rigs["rigger"]["mean"] - rigs["artist_skin"]["mean"])
    assert "game" not in rigs and "game_error" not in record  # a legless bust's plan: no game target to measure
    skeleton = record["skeleton"]
    assert skeleton["own_recall"] == 1.0 and 0.0 <= skeleton["limb_recall"] <= 1.0
    assert skeleton["plane"]["two_sided"] and set(skeleton["twins"]) and skeleton["unsided"] is not None


def test_the_benchmark_measures_the_game_target_where_the_plan_fills_it():
    pytest.importorskip("bpy")
    import posing

    record = posing.measure(shared_path("models", "gt", "rignet_2982"), seeds=[3], poses=2)  # a quadruped
    rigs = record["seeds"]["3"]["rigs"]
    assert "game_error" not in record and 3 < record["game_bones"] < record["bones"]["rigger"]
    assert record["seeds"]["3"]["game_excess"] == pytest.approx(rigs["game"]["mean"] - rigs["artist_skin"]["mean"])
