"""The quality benchmark's data and scoring library (bench/rigdata.py) and its baseline skeleton helpers."""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.sparse import csr_matrix

import quality
import rigdata
from conftest import shared_path

CUBE_VERTICES = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
# Outward-facing quads of the unit cube (vertex index = 4x + 2y + z).
CUBE_QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def cube_triangles(quads=CUBE_QUADS):
    return np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


# --- OBJ loader ---------------------------------------------------------------------------------------------------

def test_obj_polygons_are_fan_triangulated_and_corner_forms_read(tmp_path):
    path = write(tmp_path, "poly.obj", "\n".join([
        "# a quad and a pentagon", "o thing",
        *(f"v {x} {y} 0 1.0" for x, y in [(0, 0), (1, 0), (1, 1), (0, 1), (2, 0), (2, 1), (1.5, 2)]),
        "vt 0 0", "vn 0 0 1",
        "f 1/1/1 2/1/1 3//1 4",
        "f 2/1 5/1 6/1 7/1 3/1",
        "l 1 2",
    ]))
    vertices, triangles = rigdata.load_obj(path)
    assert vertices.shape == (7, 3) and vertices[6].tolist() == [1.5, 2.0, 0.0]
    assert triangles.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 6], [1, 6, 2]]


def test_obj_negative_indices_count_back_from_the_face(tmp_path):
    path = write(tmp_path, "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4/1 -3/1 -1/1\n")
    vertices, triangles = rigdata.load_obj(path)
    assert triangles.tolist() == [[0, 1, 2], [0, 1, 3]]


@pytest.mark.parametrize("text, message", [
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "index 0"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "out of range"),
    ("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", "out of range"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "at least 3 corners"),
    ("v 0 0\n", "3 coordinates"),
    ("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite"),
    ("v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "unreadable"),
    ("# nothing\n", "no vertices"),
])
def test_obj_bad_input_is_a_clear_value_error(tmp_path, text, message):
    with pytest.raises(ValueError, match=message):
        rigdata.load_obj(write(tmp_path, "bad.obj", text))


# --- rig_info parser and helper filter ----------------------------------------------------------------------------

RIG_TEXT = """joints hips 0 1 0
joints spine 0 2 0
joints PoleTarget.L 1 1 1
joints foot 0 0 1
joints head 0 3 0
root hips
hier hips spine
hier spine head
hier hips PoleTarget.L
hier PoleTarget.L foot
skin 0 hips 0.25 spine 0.75
skin 2 head 1.0
"""


def test_rig_parser_reads_joints_hierarchy_and_sparse_skin(tmp_path):
    rig = rigdata.load_rig(write(tmp_path, "r_rig.txt", RIG_TEXT), n_vertices=4)
    assert rig.names == ("hips", "spine", "PoleTarget.L", "foot", "head") and rig.root == "hips"
    assert rig.positions[3].tolist() == [0.0, 0.0, 1.0]
    assert rig.parents.tolist() == [-1, 0, 0, 2, 1]
    assert rig.skin.shape == (4, 5)
    assert rig.skin.toarray()[0].tolist() == [0.25, 0.75, 0, 0, 0] and rig.skin[2, 4] == 1.0 and rig.skin[1].nnz == 0


def test_helper_joints_are_dropped_and_their_children_reparented(tmp_path):
    rig = rigdata.load_rig(write(tmp_path, "r_rig.txt", RIG_TEXT)).without_helpers()
    assert rig.names == ("hips", "spine", "foot", "head")
    assert rig.parents.tolist() == [-1, 0, 0, 1]
    assert rig.skin.shape[1] == 4
    bones = rig.bones()
    assert bones.heads.tolist() == [[0, 1, 0], [0, 1, 0], [0, 2, 0]]
    assert bones.tails.tolist() == [[0, 2, 0], [0, 0, 1], [0, 3, 0]]
    assert bones.parents.tolist() == [-1, -1, 0]


def test_parts_off_the_root_are_attached_to_the_nearest_joint_under_it():
    # an IK-driven foot kept as a root of its own (as in Quaternius rigs), with a toe under it
    skin = csr_matrix(np.eye(5))
    rig = rigdata.Rig(("hips", "knee", "ankle", "foot", "toe"),
                      np.array([[0, 0, 1], [0, 0, 0.5], [0, 0, 0.1], [0, 0, 0], [0, -0.2, 0]], dtype=float),
                      np.array([-1, 0, 1, -1, 3]), "hips", skin)
    attached = rig.attached()
    assert attached.parents.tolist() == [-1, 0, 1, 2, 3]
    assert attached.names == rig.names and attached.skin is skin and rig.parents.tolist() == [-1, 0, 1, -1, 3]


@pytest.mark.parametrize("extra, message", [
    ("hier hips ghost\n", "unknown joint"),
    ("hier head hips\n", "two parents|cycle"),
    ("joints hips 0 0 0\n", "twice"),
    ("skin 0 ghost 1.0\n", "unknown joint"),
    ("joints arm 0 x 0\n", "unreadable number"),
    ("bones a b\n", "unrecognised"),
])
def test_rig_parser_bad_input_is_a_clear_value_error(tmp_path, extra, message):
    with pytest.raises(ValueError, match=message):
        rigdata.load_rig(write(tmp_path, "bad_rig.txt", RIG_TEXT + extra))


def test_rig_parser_rejects_a_hierarchy_cycle(tmp_path):
    text = "joints a 0 0 0\njoints b 1 0 0\njoints c 2 0 0\nhier a b\nhier c a\nhier b c\n"
    with pytest.raises(ValueError, match="cycle"):
        rigdata.load_rig(write(tmp_path, "cycle_rig.txt", text))


# --- joint sets, bone samples, normalisation, metrics -------------------------------------------------------------

def chain(*points):
    points = np.array(points, dtype=float)
    return rigdata.Bones(points[:-1], points[1:], np.arange(-1, len(points) - 2))


def test_joint_set_is_heads_plus_leaf_tails_once_each():
    # Two bones sharing the root head, the first one with a child whose head is detached from its parent's tail.
    bones = rigdata.Bones([[0, 0, 0], [0, 0, 0], [2, 2, 0]], [[1, 0, 0], [0, 1, 0], [3, 3, 0]], [-1, -1, 0])
    assert sorted(map(tuple, bones.joints())) == [(0, 0, 0), (0, 1, 0), (2, 2, 0), (3, 3, 0)]


def test_bone_samples_are_at_most_a_step_apart_with_both_ends():
    bones = chain([0, 0, 0], [0.012, 0, 0], [0.012, 0, 0])
    samples = bones.samples(step=0.005)
    assert np.allclose(samples[:4, 0], [0, 0.004, 0.008, 0.012]) and (samples[:, 1:] == 0).all()
    assert np.allclose(samples[4:], [[0.012, 0, 0], [0.012, 0, 0]])  # a zero-length bone is its two ends


def test_normalisation_scales_the_largest_extent_to_one():
    vertices = np.array([[10, 20, 30], [12, 24, 31]], dtype=float)
    normalisation = rigdata.Normalisation.of_mesh(vertices)
    unit = normalisation.points(vertices)
    assert np.allclose(unit, [[-0.25, -0.5, -0.125], [0.25, 0.5, 0.125]])
    with pytest.raises(ValueError, match="no extent"):
        rigdata.Normalisation.of_mesh(np.ones((3, 3)))


def scores(predicted, truth):
    return rigdata.skeleton_distances(predicted.joints(), predicted.samples(), truth.joints(), truth.samples())


def test_identical_skeletons_score_zero():
    bones = chain([0, 0, 0], [0, 0.3, 0], [0.2, 0.5, 0.1])
    assert scores(bones, bones) == {"cd_j2j": 0.0, "cd_j2b": 0.0, "cd_b2b": 0.0}


def test_shifted_skeleton_scores_the_shift():
    truth = chain([0, 0, 0], [0, 0.3, 0], [0, 0.6, 0])
    shifted = chain([0.02, 0, 0], [0.02, 0.3, 0], [0.02, 0.6, 0])
    assert scores(shifted, truth) == pytest.approx({"cd_j2j": 0.02, "cd_j2b": 0.02, "cd_b2b": 0.02})


def test_chamfer_distances_average_both_directions():
    predicted, truth = np.array([[0.0, 0, 0]]), np.array([[0.0, 0, 0], [1.0, 0, 0]])
    assert rigdata.chamfer_distance(predicted, truth) == pytest.approx((0 + 0.5) / 2)
    # A joint in the middle of a true bone is on it (distance 0); the true joints are 0.5 from the lone joint.
    result = rigdata.skeleton_distances(np.array([[0.5, 0, 0]]), np.array([[0.5, 0, 0]]), truth,
                                        chain([0, 0, 0], [1, 0, 0]).samples())
    assert result["cd_j2b"] == pytest.approx((0 + 0.5) / 2)
    with pytest.raises(ValueError, match="non-empty"):
        rigdata.chamfer_distance(np.zeros((0, 3)), truth)


# --- winding number -----------------------------------------------------------------------------------------------

def test_winding_number_is_one_inside_a_cube_and_zero_outside():
    points = np.array([[0.5, 0.5, 0.5], [0.1, 0.9, 0.2], [1.5, 0.5, 0.5], [-3, 4, 0.2]])
    winding = rigdata.winding_numbers(points, CUBE_VERTICES, cube_triangles(), chunk_pairs=5)
    assert np.allclose(winding, [1, 1, 0, 0], atol=1e-9)
    assert rigdata.inside_fraction(points, CUBE_VERTICES, cube_triangles()) == 0.5


def test_winding_number_of_inward_faces_and_open_meshes():
    inward = cube_triangles()[:, ::-1]
    assert rigdata.winding_numbers([[0.5, 0.5, 0.5]], CUBE_VERTICES, inward) == pytest.approx([-1])
    assert rigdata.inside_fraction([[0.5, 0.5, 0.5]], CUBE_VERTICES, inward) == 1.0
    open_box = cube_triangles(CUBE_QUADS[1:])  # one face missing: the centre sees 5/6 of the full solid angle
    assert rigdata.winding_numbers([[0.5, 0.5, 0.5]], CUBE_VERTICES, open_box) == pytest.approx([5 / 6])


# --- tree checks and the skeletor baseline's forest-to-tree conversion --------------------------------------------

def test_tree_problem_names_what_is_wrong():
    heads = np.zeros((3, 3))
    tails = np.ones((3, 3))
    assert rigdata.tree_problem(rigdata.Bones(heads, tails, [-1, 0, 1])) is None
    assert "2 root" in rigdata.tree_problem(rigdata.Bones(heads, tails, [-1, -1, 1]))
    assert "cycle" in rigdata.tree_problem(rigdata.Bones(heads, tails, [-1, 2, 1]))
    assert "out of range" in rigdata.tree_problem(rigdata.Bones(heads, tails, [-1, 0, 3]))
    assert "non-finite" in rigdata.tree_problem(rigdata.Bones(heads, np.full((3, 3), np.nan), [-1, 0, 1]))
    assert rigdata.tree_problem(rigdata.Bones(np.zeros((0, 3)), np.zeros((0, 3)), [])) == "no bones"


def test_forest_becomes_one_tree_parented_to_the_largest_piece():
    # Piece one: node 0 with children 1 and 2, node 3 under 2. Piece two: node 4 -> 5, near node 1.
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 2, 0], [1.1, 0.1, 0], [2, 0, 0]], dtype=float)
    bones = quality.bones_from_forest(np.array([-1, 0, 0, 2, -1, 4]), positions)
    assert rigdata.tree_problem(bones) is None
    assert bones.heads.tolist() == [[0, 0, 0], [0, 0, 0], [0, 1, 0], [1.1, 0.1, 0]]
    assert bones.parents.tolist() == [-1, 0, 1, 0]


def test_stick_baseline_spans_the_main_axis_with_a_middle_joint():
    rng = np.random.default_rng(7)
    vertices = rng.normal(size=(500, 3)) * [0.1, 3.0, 0.2] + [5, 6, 7]
    bones, _ = quality.principal_stick(vertices, None)
    assert rigdata.tree_problem(bones) is None and len(bones.joints()) == 3
    direction = bones.tails[1] - bones.heads[0]
    assert abs(direction[1]) / np.linalg.norm(direction) > 0.99
    assert np.ptp(vertices[:, 1]) * 0.95 < np.linalg.norm(direction)


# --- one real model -----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def deer():
    """The antlered deer's ground truth (rignet_2982), loaded once."""
    return quality.GroundTruth(shared_path("models", "gt", "rignet_2982"))


@pytest.fixture(scope="module")
def deer_rigged(deer):
    """Rigger's scored record on the deer, with its default settings."""
    return quality.evaluate(deer, "rigger", {}, timeout=60)


def test_real_model_loads_and_scores_in_the_rignet_convention(deer):
    assert deer.vertices.shape == (935, 3) and deer.triangles.shape == (1866, 3)
    assert len(deer.rig.names) == 27 and (deer.rig.parents < 0).sum() == 1
    assert len(deer.joints) == 25  # RigNet's root_dup_* joints repeat the root's position: one joint each place
    assert np.ptp(deer.unit_vertices, axis=0).max() == pytest.approx(1.0)
    assert deer.inside == 1.0  # the artist's bones lie inside this watertight mesh
    record = quality.evaluate(deer, "stick", {}, timeout=60)
    assert 0.1 < record["cd_j2j"] < 0.2 and record["joints"] == 3 and record["tree_problem"] is None


def test_detail_sweep_reports_each_setting_and_the_models_out_of_range(monkeypatch, deer, deer_rigged):
    """Fewer bones at ``min_branch`` 3 on the antlered deer; every setting gets a row and a table line."""
    monkeypatch.setattr(quality, "DETAIL_SETTINGS", ({}, {"min_branch": 3.0}))
    rows = quality.detail_sweep([deer], {}, 60, [deer_rigged])
    assert [row["setting"] for row in rows] == ["defaults", "min_branch=3.0"]
    (low, high), (sparse_low, sparse_high) = (row["ratio_range"] for row in rows)
    assert low == high and sparse_low == sparse_high and sparse_high < high
    for row in rows:
        assert set(row["over"]) | set(row["under"]) <= {deer.name} and row["failed"] == 0
        assert (deer.name in row["over"]) == (row["ratio_range"][1] > quality.TARGETS["joint_ratio"][1])
    table = quality.detail_lines(rows)[-2:]
    assert table[0].startswith("| defaults |") and table[1].startswith("| min_branch=3.0 |")


def test_density_lines_measure_the_artists_joint_spacing_and_rigger_s_extra_parts(deer):
    """The deer's joints over its bones against a 3-joint stick 2 long; only the stick's rig is 2× longer (the
    deer's a little longer than the artist's, under ``MUCH_LONGER``)."""
    stick = rigdata.Bones(np.array([[0.0, 0, 0], [1, 0, 0]]), np.array([[1.0, 0, 0], [2, 0, 0]]), np.array([-1, 0]))
    assert stick.total_length() == 2.0
    sparse = SimpleNamespace(name="stick", joints=stick.joints(), length=stick.total_length())
    records = [{"model": "stick", "length_ratio": 2.0}, {"model": deer.name, "length_ratio": 1.2}]
    text = quality.density_lines([sparse, deer], records)[-1]
    dense = len(deer.joints) / deer.length
    assert text.startswith(f"The artists place 1.5 (stick) to {dense:.1f} ({deer.name}) ")
    assert f"a factor {dense / 1.5:.2f}, where the 0.7–1.5× window is a factor 2.14 wide." in text
    assert text.endswith("length on stick 2.00×: more of the mesh has bones than in the artist's rig.")


def test_real_rig_helper_joints_are_ignored():
    folder = shared_path("models", "gt", "Quaternius_Fox")
    rig = rigdata.load_rig(folder / "Quaternius_Fox_rig.txt")
    kept = rig.without_helpers()
    assert len(rig.names) == 51 and len(kept.names) == 47
    assert not any("PoleTarget" in name for name in kept.names)


def test_artist_rig_as_armature_bones_drops_zero_length_bones():
    # root r with a duplicate joint at its place (RigNet's root_dup), which carries the spine; a leaf hand on the arm
    skin = csr_matrix(np.array([[0.2, 0.0, 0.8, 0.0, 0.0], [0.0, 0.0, 0.0, 0.3, 0.7], [0.0] * 5, [0.5, 0, 0, 0.4, 0]]))
    rig = rigdata.Rig(("r", "dup", "spine", "arm", "hand"),
                      np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1], [1, 0, 0], [2, 0, 0]], dtype=float),
                      np.array([-1, 0, 1, 0, 3]), "r", skin)
    skeleton, head_joint = rigdata.armature_skeleton(rig)
    assert skeleton.names == ("bone_000", "bone_001", "bone_002")
    assert skeleton.heads.tolist() == [[0, 0, 0], [0, 0, 0], [1, 0, 0]]
    assert skeleton.tails.tolist() == [[0, 0, 1], [1, 0, 0], [2, 0, 0]]
    assert skeleton.parents.tolist() == [-1, -1, 1] and head_joint.tolist() == [1, 0, 3]
    # a weight on a leaf joint belongs to the bone ending there, i.e. to its parent joint's bone
    assert rigdata.weight_owners(rig.parents).tolist() == [0, 1, 1, 3, 3]
    assert rigdata.dominant_joints(rig).tolist() == [1, 3, -1, 0]
