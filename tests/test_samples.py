"""The sample characters: valid skeleton data, and meshes that are closed, sensible and hold their true skeleton."""
import importlib.util
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

from characters import load_character, winding_numbers
from rigger import samples

NAMES = list(samples.CHARACTERS)
SIDED = [name for name in NAMES if any(joint.name.endswith(".L") for joint in samples.character_joints(name))]
MIRRORED = [name for name in SIDED if name not in samples.NEAR_SYMMETRIC]
SAMPLES_PER_BONE = 9  # points tested for insideness along every bone, both ends included
MIRROR_TOLERANCE = 1e-5  # metres: Blender computes in float32, so mirror images agree to rounding


BUILD_IN_BLENDER = textwrap.dedent("""
    import bpy
    import pytest
    from rigger.blender.headless import empty_scene
    from rigger.blender.samples import build_character, character_arrays

    empty_scene()
    characters = bpy.data.collections.new("Characters")
    bpy.context.scene.collection.children.link(characters)
    obj = build_character("quadruped", subdivisions=1, collection=characters)
    assert obj.type == "MESH" and obj.name == "quadruped" and obj.data.name == "quadruped"
    assert list(obj.users_collection) == [characters] and not obj.modifiers
    assert list(bpy.data.meshes) == [obj.data] and len(obj.data.polygons) > 500
    for bad in ({"name": "dragon"}, {"name": "snake", "subdivisions": 9}, {"name": "snake", "subdivisions": 1.5}):
        with pytest.raises(ValueError):
            build_character(**bad)
    vertices, triangles = character_arrays("snake", subdivisions=0)
    assert vertices.shape[1] == triangles.shape[1] == 3 and len(triangles) > 2 * len(vertices) - 10
    assert list(bpy.data.meshes) == [obj.data] and list(bpy.data.objects) == [obj]
""")


def _mirror_name(name):
    """The name of the other side's joint: ``.L`` and ``.R`` swapped, anything else unchanged."""
    if name is None or not name.endswith((".L", ".R")):
        return name
    return name[:-2] + (".R" if name.endswith(".L") else ".L")


def _front_silhouette(name):
    """The character seen from the front (-Y): the union of its triangles projected onto the XZ plane."""
    vertices, triangles = load_character(name)
    corners = vertices[triangles][:, :, [0, 2]]
    edge_a, edge_b = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    visible = np.abs(edge_a[:, 0] * edge_b[:, 1] - edge_a[:, 1] * edge_b[:, 0]) > 1e-14  # edge-on ones add nothing
    return shapely.union_all(shapely.polygons(corners[visible]))


def test_the_required_characters_exist():
    assert {"humanoid", "humanoid_hips", "quadruped", "octopus", "tree", "snake", "humanoid_a_pose",
            "humanoid_handmade", "head_with_nose", "bear", "humanoid_knees", "four_arms"} <= set(NAMES)
    assert samples.NEAR_SYMMETRIC <= set(SIDED)


def test_the_data_module_does_not_need_bpy():
    check = "import sys, rigger.samples; sys.exit('bpy' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", check]).returncode == 0


def test_building_in_blender_links_one_finished_object_and_leaves_nothing_else():
    if importlib.util.find_spec("bpy") is None:
        pytest.skip("bpy is not installed")
    result = subprocess.run([sys.executable, "-c", BUILD_IN_BLENDER], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr


def test_an_unknown_character_is_a_value_error():
    with pytest.raises(ValueError, match="unknown sample character 'dragon'"):
        samples.ground_truth_bones("dragon")
    with pytest.raises(ValueError, match="unknown sample character"):
        load_character("dragon")


@pytest.mark.parametrize("name", NAMES)
def test_ground_truth_is_one_tree_of_named_bones(name):
    joints = samples.character_joints(name)
    bones = samples.ground_truth_bones(name)
    assert [joint.parent for joint in joints].count(None) == 1
    skeleton_joints = [joint for joint in joints if not joint.skin_only]
    assert len(bones.names) == len(set(bones.names)) == len(skeleton_joints) - 1
    assert set(bones.names) == {joint.name for joint in skeleton_joints if joint.parent is not None}
    assert bones.heads.shape == bones.tails.shape == (len(bones.names), 3)
    assert np.all(np.linalg.norm(bones.tails - bones.heads, axis=1) > 0.01)
    for index, parent in enumerate(bones.parents):
        assert -1 <= parent < index  # parents come first, so following parents always reaches a root
        if parent >= 0:
            np.testing.assert_array_equal(bones.heads[index], bones.tails[parent])
    assert all(joint.radius > 0 for joint in joints)


@pytest.mark.parametrize("name", MIRRORED)
def test_left_and_right_joints_mirror_each_other_in_x(name):
    joints = {joint.name: joint for joint in samples.character_joints(name)}
    for joint in joints.values():
        other = joints[_mirror_name(joint.name)]
        assert other.parent == _mirror_name(joint.parent)
        assert other.radius == joint.radius
        np.testing.assert_allclose(other.position, np.multiply(joint.position, (-1.0, 1.0, 1.0)), atol=1e-12)
        if joint.name.endswith(".L"):
            assert joint.position[0] > 0.0  # the character's left is +X


@pytest.mark.parametrize("name", sorted(samples.NEAR_SYMMETRIC))
def test_near_symmetric_characters_pair_every_side_but_miss_the_mirror_by_a_few_percent(name):
    joints = {joint.name: joint for joint in samples.character_joints(name)}
    height = max(joint.position[2] for joint in joints.values())
    gaps = []
    for joint in joints.values():
        other = joints[_mirror_name(joint.name)]
        assert other.parent == _mirror_name(joint.parent)
        if joint.name.endswith(".L"):
            assert joint.position[0] > 0.0 > other.position[0]
            gaps.append(np.linalg.norm(np.multiply(other.position, (-1.0, 1.0, 1.0)) - joint.position))
    assert 0.02 * height < max(gaps) < 0.1 * height  # no mirror plane within 1% of the size, yet plainly two-sided


def test_skin_only_points_shape_the_body_but_add_no_bones():
    joints = {joint.name: joint for joint in samples.character_joints("humanoid_knees")}
    bones = samples.ground_truth_bones("humanoid_knees")
    thigh = bones.names.index("thigh.L")
    assert joints["thigh_bulge.L"].skin_only and "thigh_bulge.L" not in bones.names
    np.testing.assert_array_equal(bones.heads[thigh], joints["pelvis.L"].position)  # the bone runs through the bulge
    assert bones.names[bones.parents[bones.names.index("shin.L")]] == "thigh.L"
    knee = joints["thigh.L"].radius
    assert knee < 0.6 * joints["thigh_bulge.L"].radius and knee < 0.8 * joints["calf.L"].radius  # a narrow knee


@pytest.mark.parametrize("name", MIRRORED)
def test_mirrored_characters_have_mirror_symmetric_meshes(name):
    vertices, _ = load_character(name)
    distances, _ = cKDTree(vertices).query(vertices * (-1.0, 1.0, 1.0))
    assert distances.max() < MIRROR_TOLERANCE


@pytest.mark.parametrize("name", NAMES)
def test_meshes_are_closed_oriented_manifolds_in_one_piece(name):
    vertices, triangles = load_character(name)
    assert vertices.dtype == np.float64 and triangles.dtype == np.int32
    assert triangles.min() == 0 and triangles.max() == len(vertices) - 1
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]).astype(np.int64)
    keys = directed[:, 0] * len(vertices) + directed[:, 1]
    reversed_keys = directed[:, 1] * len(vertices) + directed[:, 0]
    assert len(np.unique(keys)) == len(keys)  # no edge is used twice in one direction
    assert np.isin(reversed_keys, keys).all()  # every edge is used once in each direction: closed, consistently wound
    edges = len(keys) // 2
    assert len(vertices) - edges + len(triangles) == 2  # the skin of a tree is a sphere: one piece, no handles
    volume = np.einsum("ij,ij->i", vertices[triangles[:, 0]],
                       np.cross(vertices[triangles[:, 1]], vertices[triangles[:, 2]])).sum() / 6.0
    assert volume > 0.0  # normals point outwards


@pytest.mark.parametrize("name", NAMES)
def test_meshes_have_sensible_sizes(name):
    vertices, triangles = load_character(name)
    assert 2_000 <= len(vertices) <= 20_000
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    assert 0.5 < extent.max() < 3.0
    assert -0.01 < vertices[:, 2].min() < 0.1  # standing on the ground


def test_the_humanoid_is_about_1_8_m_tall_and_faces_minus_y():
    vertices, _ = load_character("humanoid")
    assert 1.75 < vertices[:, 2].max() < 1.85
    bones = samples.ground_truth_bones("humanoid")
    foot = bones.names.index("foot.L")
    assert bones.tails[foot, 1] < bones.heads[foot, 1]  # toes point forward, to -Y


@pytest.mark.parametrize("name", NAMES)
def test_every_true_bone_lies_inside_its_mesh(name):
    vertices, triangles = load_character(name)
    bones = samples.ground_truth_bones(name)
    weights = np.linspace(0.0, 1.0, SAMPLES_PER_BONE)[None, :, None]
    points = (bones.heads[:, None, :] * (1.0 - weights) + bones.tails[:, None, :] * weights).reshape(-1, 3)
    winding = winding_numbers(vertices, triangles, points)
    assert winding.min() > 0.5, f"outside: {points[winding <= 0.5]}"


def test_winding_numbers_tell_inside_from_outside():
    vertices, triangles = load_character("humanoid")
    points = np.array([[0.0, 0.0, 1.2], [0.0, 0.0, 2.5], [0.3, 0.0, 1.0], [0.11, 0.0, 0.5]])
    np.testing.assert_allclose(winding_numbers(vertices, triangles, points), [1.0, 0.0, 0.0, 1.0], atol=1e-6)


def test_hands_on_hips_leave_a_hole_on_each_side_seen_from_the_front():
    silhouette = _front_silhouette("humanoid_hips")
    assert silhouette.geom_type == "Polygon"
    holes = [shapely.Polygon(ring) for ring in silhouette.interiors]
    large = [hole for hole in holes if hole.area > 2e-3]  # m²: more than a pinhole between overlapping triangles
    assert len(large) == 2
    assert sorted(np.sign(hole.centroid.x) for hole in large) == [-1.0, 1.0]


def test_arms_out_leave_a_gap_to_the_body_seen_from_the_front():
    silhouette = _front_silhouette("humanoid")
    assert silhouette.geom_type == "Polygon"
    assert all(shapely.Polygon(ring).area < 1e-4 for ring in silhouette.interiors)
    for side in (-1.0, 1.0):
        assert not silhouette.contains(shapely.Point(side * 0.3, 1.1))  # below the arm, beside the body
        assert silhouette.contains(shapely.Point(side * 0.6, 1.18))  # on the forearm


def test_the_quadrupeds_legs_overlap_in_a_side_view():
    bones = samples.ground_truth_bones("quadruped")
    for name in ("upper_arm", "forearm", "thigh", "shin"):
        left, right = bones.names.index(f"{name}.L"), bones.names.index(f"{name}.R")
        np.testing.assert_array_equal(bones.tails[left, 1:], bones.tails[right, 1:])
        assert bones.tails[left, 0] > 0.05 and bones.tails[right, 0] < -0.05
