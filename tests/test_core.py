"""The bpy-free core: mesh validation, polygon triangulation, skeleton trees and parameter coercion."""
import json

import numpy as np
import pytest

from rigger.core import bvh, objfile
from rigger.core.accessories import barycentric, boneless_parts, part_means, surface_entries
from rigger.core.graphs import loose_parts
from rigger.core.mesh import Mesh, triangulate_polygons
from rigger.core.params import Param, resolve
from rigger.core.skeleton import Skeleton
from rigger.core.stages import Joints

TETRA_VERTICES = [(0, 0, 0), (2, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_TRIANGLES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


# --- Mesh -----------------------------------------------------------------------------------------------------------

def test_mesh_holds_read_only_float64_and_int32_copies():
    vertices = np.array(TETRA_VERTICES, dtype=np.int64)
    mesh = Mesh(vertices, TETRA_TRIANGLES)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (4, 3)
    assert mesh.triangles.dtype == np.int32 and mesh.triangles.shape == (4, 3)
    assert mesh.degenerate_count == 0
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 5.0
    vertices[0, 0] = 9
    assert mesh.vertices[0, 0] == 0


def test_mesh_geometry_ignores_loose_vertices():
    mesh = Mesh(TETRA_VERTICES + [(100, 100, 100)], TETRA_TRIANGLES)
    np.testing.assert_array_equal(mesh.bbox, [[0, 0, 0], [2, 1, 1]])
    assert mesh.scale == 2.0
    np.testing.assert_allclose(mesh.centroid, [0.5, 0.25, 0.25])


def test_mesh_drops_degenerate_faces_and_counts_them():
    mesh = Mesh(TETRA_VERTICES, TETRA_TRIANGLES + [(1, 1, 2), (3, 0, 3)])
    assert mesh.degenerate_count == 2
    np.testing.assert_array_equal(mesh.triangles, TETRA_TRIANGLES)


@pytest.mark.parametrize("vertices, triangles, fragment", [
    ([], TETRA_TRIANGLES, "no vertices"),
    (TETRA_VERTICES, [], "no triangles"),
    (np.zeros((4, 2)), TETRA_TRIANGLES, "shape (N, 3)"),
    (np.zeros((2, 4, 3)), TETRA_TRIANGLES, "shape (N, 3)"),
    (TETRA_VERTICES, [(0, 1, 2, 3)], "shape (M, 3)"),
    ([(0, 0, 0), (1, 0)], TETRA_TRIANGLES, "rectangular array"),
    ([("a", "b", "c")] * 4, TETRA_TRIANGLES, "real numbers"),
    (np.ones((4, 3), dtype=bool), TETRA_TRIANGLES, "real numbers"),
    (TETRA_VERTICES, np.array(TETRA_TRIANGLES, dtype=float), "integer vertex indices"),
    (TETRA_VERTICES[:3] + [(0, np.nan, 1)], TETRA_TRIANGLES, "NaN or infinite coordinates (the first is vertex 3)"),
    (TETRA_VERTICES[:3] + [(0, np.inf, 1)], TETRA_TRIANGLES, "NaN or infinite"),
    (TETRA_VERTICES, TETRA_TRIANGLES + [(0, 1, 4)], "reference vertex 4 but the mesh has only 4 vertices"),
    (TETRA_VERTICES, TETRA_TRIANGLES + [(0, -1, 2)], "negative vertex index -1"),
    (TETRA_VERTICES, [(0, 0, 1), (2, 2, 2)], "all 2 triangles are degenerate"),
    ([(1, 1, 1)] * 4, TETRA_TRIANGLES, "zero size"),
    ([(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 3, 3)], [(0, 1, 2), (1, 2, 3)], "on one line"),
    (np.array(TETRA_VERTICES) * 1e-310, TETRA_TRIANGLES, "too small: its size 2e-310 is below float64's normal"),
    ([(-1e308, 0, 0), (1e308, 0, 0), (0, 1e308, 0), (0, 0, 1e308)], TETRA_TRIANGLES, "too large: its extent"),
    (np.array(TETRA_VERTICES) * 2.0 ** 1022, TETRA_TRIANGLES, "reaches float64's limit (2**1023)"),
])
def test_mesh_rejects_bad_input_with_a_clear_message(vertices, triangles, fragment):
    with pytest.raises(ValueError) as error:
        Mesh(vertices, triangles)
    assert fragment in str(error.value)


def test_line_check_is_scale_and_position_free():
    vertices = np.array(TETRA_VERTICES, dtype=float)
    for scale, offset in ((1e-3, 1e3), (1e3, -1e3), (1e-300, 0.0), (1e300, -1e300)):
        Mesh(vertices * scale + offset, TETRA_TRIANGLES)


def test_a_mesh_goes_to_unit_size_by_an_exact_power_of_two():
    mesh = Mesh(np.array(TETRA_VERTICES, dtype=float) * 3e200, TETRA_TRIANGLES)
    assert 0.5 <= mesh.scale * mesh.unit_factor < 1 and np.log2(mesh.unit_factor).is_integer()
    turned = mesh.at_unit_size(np.eye(3)[[1, 2, 0]])
    np.testing.assert_array_equal(turned.vertices, mesh.vertices[:, [1, 2, 0]] * mesh.unit_factor)
    assert turned.triangles is mesh.triangles and not turned.vertices.flags.writeable
    assert turned.scale == mesh.scale * mesh.unit_factor and turned.unit_factor == 1.0
    np.testing.assert_array_equal(turned.centroid, mesh.centroid[[1, 2, 0]] * mesh.unit_factor)
    scaled = mesh.at_unit_size()  # unturned: the measures carry over, as computing them again would give them
    fresh = Mesh(mesh.vertices * mesh.unit_factor, TETRA_TRIANGLES)
    for name in ("bbox", "scale", "centroid", "flat_normal"):
        np.testing.assert_array_equal(getattr(scaled, name), getattr(fresh, name), err_msg=name)
    assert scaled.at_unit_size() is scaled  # at unit size already: nothing to copy
    assert scaled.at_unit_size(np.eye(3)[[1, 2, 0]]) is not scaled


def test_a_loose_vertex_too_far_to_scale_with_its_mesh_is_refused():
    mesh = Mesh(np.vstack([np.array(TETRA_VERTICES) * 1e-300, [(1e10, 0, 0)]]), TETRA_TRIANGLES)
    with pytest.raises(ValueError, match="vertex 4 at .* lies too far from a mesh 2e-300 big"):
        mesh.at_unit_size()


def test_a_flat_mesh_is_accepted():
    mesh = Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [(0, 1, 2), (1, 3, 2)])
    assert mesh.scale == 1.0


def test_triangulate_polygons_fans_each_face_in_order():
    triangles = triangulate_polygons([(0, 1, 2), (3, 4, 5, 6), (7, 8, 9, 10, 11)])
    assert triangles.dtype == np.int32
    np.testing.assert_array_equal(triangles, [(0, 1, 2), (3, 4, 5), (3, 5, 6), (7, 8, 9), (7, 9, 10), (7, 10, 11)])
    assert triangulate_polygons([]).shape == (0, 3)


@pytest.mark.parametrize("faces, fragment", [
    ([(0, 1, 2), (3, 4)], "face 1 has 2 vertices"),
    ([(0, 1.5, 2)], "must be integers"),
    ([(0, 1, 2**40)], "32 bits"),
])
def test_triangulate_polygons_rejects_bad_faces(faces, fragment):
    with pytest.raises(ValueError) as error:
        triangulate_polygons(faces)
    assert fragment in str(error.value)


# --- Skeleton -------------------------------------------------------------------------------------------------------

def arm():
    """root -> upper -> lower, with a second child 'side' of root starting away from root's tail."""
    names = ["root", "upper", "lower", "side"]
    heads = [(0, 0, 0), (0, 0, 1), (0, 0, 2), (1, 0, 0)]
    tails = [(0, 0, 1), (0, 0, 2), (0, 0, 3), (2, 0, 0)]
    return Skeleton(names, heads, tails, [-1, 0, 1, 0], stages={"note": Joints(np.zeros((1, 3)))},
                    timings={"cut": 0.25}, params={"bones": 4})


def test_skeleton_tree_queries():
    skeleton = arm()
    assert len(skeleton) == 4
    assert skeleton.roots == (0,)
    assert skeleton.children(0) == (1, 3) and skeleton.children(2) == ()
    assert skeleton.parents.dtype == np.int32
    assert list(skeleton.stages) == ["note"] and skeleton.timings == {"cut": 0.25} and skeleton.params == {"bones": 4}
    # heads of all bones plus tails of the leaves 'lower' and 'side'
    np.testing.assert_array_equal(skeleton.joints(), [(0, 0, 0), (0, 0, 1), (0, 0, 2), (1, 0, 0), (0, 0, 3), (2, 0, 0)])


def test_joints_lists_coincident_heads_once():
    skeleton = Skeleton(["a", "b", "c"], [(0, 0, 0), (0, 0, 1), (0, 0, 1)], [(0, 0, 1), (1, 0, 1), (-1, 0, 1)],
                        [-1, 0, 0])
    np.testing.assert_array_equal(skeleton.joints(), [(0, 0, 0), (0, 0, 1), (1, 0, 1), (-1, 0, 1)])


def test_parents_may_come_after_children_and_several_roots_are_allowed():
    skeleton = Skeleton(["hand", "arm", "prop"], [(0, 0, 1), (0, 0, 0), (5, 5, 5)], [(0, 0, 2), (0, 0, 1), (5, 5, 6)],
                        [1, -1, -1])
    assert skeleton.roots == (1, 2) and skeleton.children(1) == (0,)


@pytest.mark.parametrize("names, heads, tails, parents, fragment", [
    ([], [], [], [], "at least one bone"),
    ("ab", [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 0], "not one string"),
    (["a", "a"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 0], "'a' is used twice"),
    (["a", ""], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 0], "non-empty strings"),
    (["a", 3], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 0], "non-empty strings"),
    (["a", "b"], [(0, 0, 0)], [(0, 0, 1)] * 2, [-1, 0], "heads must have shape (2, 3)"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1), (0, np.nan, 1)], [-1, 0], "tails contain NaN"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1), (0, 0, 0)], [-1, 0], "bone 'b' has zero length"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 2], "between 0 and 1"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-2, 0], "between 0 and 1"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1.0, 0.0], "integer bone indices"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1], "integer bone indices"),
    (["a", "b"], [(0, 0, 0)] * 2, [(0, 0, 1)] * 2, [-1, 1], "cycle: b"),
    (["a", "b", "c"], [(0, 0, 0)] * 3, [(0, 0, 1)] * 3, [1, 2, 0], "cycle: a -> b -> c"),
    (["r", "a", "b"], [(0, 0, 0)] * 3, [(0, 0, 1)] * 3, [-1, 2, 1], "cycle: a -> b"),
])
def test_skeleton_rejects_invalid_trees(names, heads, tails, parents, fragment):
    with pytest.raises(ValueError) as error:
        Skeleton(names, heads, tails, parents)
    assert fragment in str(error.value)


def test_to_dict_round_trips_through_json():
    skeleton = arm()
    data = json.loads(json.dumps(skeleton.to_dict()))
    assert data["bones"][0] == {"name": "root", "head": [0.0, 0.0, 0.0], "tail": [0.0, 0.0, 1.0], "parent": None}
    assert [bone["parent"] for bone in data["bones"]] == [None, "root", "upper", "root"]
    data["bones"].reverse()  # parents listed after their children
    back = Skeleton.from_dict(data)
    assert back.names == tuple(reversed(skeleton.names))
    order = [back.names.index(name) for name in skeleton.names]
    np.testing.assert_array_equal(back.heads[order], skeleton.heads)
    np.testing.assert_array_equal(back.tails[order], skeleton.tails)
    assert [back.names[p] if p >= 0 else None for p in back.parents[order]] == [None, "root", "upper", "root"]


@pytest.mark.parametrize("data, fragment", [
    ({}, "needs 'bones'"),
    ({"bones": [{"name": "a", "head": [0, 0, 0], "tail": [0, 0, 1]}]}, "needs 'bones'"),
    ({"bones": [{"name": "a", "head": [0, 0, 0], "tail": [0, 0, 1], "parent": "b"}]}, "parent 'b' is not a bone"),
])
def test_from_dict_rejects_malformed_data(data, fragment):
    with pytest.raises(ValueError) as error:
        Skeleton.from_dict(data)
    assert fragment in str(error.value)


def test_transformed_applies_an_affine_matrix_and_keeps_the_tree():
    skeleton = arm()
    matrix = np.array([[0, -2, 0, 10], [2, 0, 0, 0], [0, 0, 2, -1], [0, 0, 0, 1]], dtype=float)
    moved = skeleton.transformed(matrix)
    np.testing.assert_allclose(moved.heads[3], [10, 2, -1])
    np.testing.assert_allclose(moved.tails[2], [10, 0, 5])
    np.testing.assert_array_equal(moved.parents, skeleton.parents)
    assert moved.names == skeleton.names and moved.stages is skeleton.stages
    assert (moved.timings, moved.params) == (skeleton.timings, skeleton.params)
    back = moved.transformed(np.linalg.inv(matrix))
    np.testing.assert_allclose(back.heads, skeleton.heads, atol=1e-12)


@pytest.mark.parametrize("matrix, fragment", [
    (np.eye(3), "4x4"),
    (np.full((4, 4), np.nan), "4x4"),
    (np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]), "affine"),
    (np.diag([1, 0, 1, 1]), "singular"),
])
def test_transformed_rejects_bad_matrices(matrix, fragment):
    with pytest.raises(ValueError) as error:
        arm().transformed(matrix)
    assert fragment in str(error.value)


def test_skeleton_arrays_are_read_only():
    skeleton = arm()
    for array in (skeleton.heads, skeleton.tails, skeleton.parents):
        with pytest.raises(ValueError):
            array[0] = 0


# --- Param and resolve ----------------------------------------------------------------------------------------------

PARAMS = (
    Param("bone_angle", "float", 30.0, min=0, max=180, description="Turn that starts a new bone, degrees"),
    Param("bones", "int", 3, min=1, max=64),
    Param("mirror", "bool", True),
    Param("axis", "enum", "AUTO", items=("AUTO", "X", "Y", "Z")),
    Param("view", "vector", (0, 0, 1), min=-1, max=1),
)


def test_resolve_fills_defaults_and_coerces_python_values():
    assert resolve(PARAMS, {}) == {"bone_angle": 30.0, "bones": 3, "mirror": True, "axis": "AUTO",
                                   "view": (0.0, 0.0, 1.0)}
    values = resolve(PARAMS, {"bone_angle": np.float32(45), "bones": np.int64(5), "mirror": 0, "axis": "Y",
                              "view": np.array([0, 1, 0])})
    assert values == {"bone_angle": 45.0, "bones": 5, "mirror": False, "axis": "Y", "view": (0.0, 1.0, 0.0)}
    assert type(values["bones"]) is int and type(values["bone_angle"]) is float


def test_resolve_coerces_command_line_strings():
    values = resolve(PARAMS, {"bone_angle": " 12.5", "bones": "7", "mirror": "off", "axis": "x",
                              "view": "0, -1 0"})
    assert values == {"bone_angle": 12.5, "bones": 7, "mirror": False, "axis": "X", "view": (0.0, -1.0, 0.0)}
    assert resolve(PARAMS, {"mirror": "YES", "bones": "4.0"})["mirror"] is True


@pytest.mark.parametrize("given, fragment", [
    ({"bone_angle": "wide"}, "'bone_angle': expected a finite number, got 'wide'"),
    ({"bone_angle": float("nan")}, "expected a finite number"),
    ({"bone_angle": True}, "expected a finite number"),
    ({"bone_angle": 181}, "181.0 is above the maximum 180"),
    ({"bones": 0}, "0 is below the minimum 1"),
    ({"bones": 2.5}, "expected an integer"),
    ({"bones": "three"}, "expected an integer"),
    ({"mirror": "maybe"}, "expected a boolean"),
    ({"mirror": 2}, "expected a boolean"),
    ({"axis": "W"}, "expected one of AUTO, X, Y, Z"),
    ({"axis": 1}, "expected one of AUTO, X, Y, Z"),
    ({"view": "0,1"}, "expected three numbers"),
    ({"view": 5}, "expected three numbers"),
    ({"view": (0, 2, 0)}, "2.0 is above the maximum 1"),
    ({"view": ("a", 0, 0)}, "three finite numbers"),
    ({"bone_angel": 3, "bonez": 1},
     "unknown parameters bone_angel, bonez; valid: bone_angle, bones, mirror, axis, view"),
])
def test_resolve_rejects_bad_values_with_the_parameter_named(given, fragment):
    with pytest.raises(ValueError) as error:
        resolve(PARAMS, given)
    assert fragment in str(error.value)


def test_resolve_with_no_declared_params():
    assert resolve((), {}) == {}
    with pytest.raises(ValueError, match="unknown parameter x; valid: none"):
        resolve((), {"x": 1})


def test_param_label_defaults_from_the_name():
    assert PARAMS[0].label == "Bone angle"
    assert Param("x", "bool", False, label="Mirror X").label == "Mirror X"


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(name="bad name", type="int", default=1), "Python identifier"),
    (dict(name="n", type="string", default="a"), "type must be one of"),
    (dict(name="n", type="int", default=0, min=1), "0 is below the minimum 1"),
    (dict(name="n", type="int", default=1, min=2, max=1), "min 2 exceeds max 1"),
    (dict(name="n", type="int", default=1, min=float("inf")), "finite numbers"),
    (dict(name="n", type="bool", default=True, max=1), "only to float, int and vector"),
    (dict(name="n", type="enum", default="A"), "needs items"),
    (dict(name="n", type="enum", default="A", items="AB"), "needs items"),
    (dict(name="n", type="enum", default="A", items=("A", "a")), "differ ignoring case"),
    (dict(name="n", type="enum", default="C", items=("A", "B")), "expected one of A, B"),
    (dict(name="n", type="float", default=1.0, items=("A",)), "only to enum"),
    (dict(name="n", type="float", default=1.0, description=None), "must be strings"),
])
def test_param_declaration_is_validated(kwargs, fragment):
    with pytest.raises(ValueError) as error:
        Param(**kwargs)
    assert fragment in str(error.value)


def test_concatenated_ranges_match_a_loop():
    from rigger.core.arrays import concatenated_ranges

    starts, counts = np.array([5, 0, 9, 2]), np.array([3, 0, 1, 2])
    expected = np.concatenate([np.arange(s, s + c) for s, c in zip(starts, counts)])
    np.testing.assert_array_equal(concatenated_ranges(starts, counts), expected)
    assert len(concatenated_ranges(np.zeros(0, int), np.zeros(0, int))) == 0


def test_every_body_plan_fills_the_plain_target_and_unknown_targets_are_named():
    from rigger.core.bodyplan import BodyPlan
    from rigger.core.targets import TARGETS, check_target, choose_target

    for plan in (None, BodyPlan("other", 0.5, "no legs"), BodyPlan("humanoid", 0.9, "2 legs")):
        assert choose_target("plain", plan) == (TARGETS["plain"], None)
    with pytest.raises(ValueError, match="unknown target 'mocap'; targets are plain"):
        check_target("mocap")


BVH = """HIERARCHY
ROOT Hips
{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT Spine
\t{
\t\tOFFSET 0 1 0
\t\tCHANNELS 3 Zrotation Yrotation Xrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 1 0
\t\t}
\t}
}
MOTION
Frames:\t2
Frame Time: 0.04
0 0 0 0 0 0 0 0 0
0 0 1 0 0 0 10 0 0
"""


def test_a_bvh_file_is_checked_without_blender(tmp_path):
    path = tmp_path / "walk.bvh"
    path.write_text(BVH)
    assert bvh.check(path) == bvh.BvhSummary(("Hips", "Spine"), 9, 2, 0.04)
    path.write_text(BVH.replace("MOTION\n", "motion\n\n").replace("Frame Time:", "frame time:")
                    .replace("End Site", "end site"))  # as lenient as Blender's importer
    assert bvh.check(path) == bvh.BvhSummary(("Hips", "Spine"), 9, 2, 0.04)
    path.write_bytes(b"\xef\xbb\xbf" + BVH.encode())  # a byte order mark before HIERARCHY
    assert bvh.check(path) == bvh.BvhSummary(("Hips", "Spine"), 9, 2, 0.04)


@pytest.mark.parametrize("text, message", [
    ("", "not a BVH file (no MOTION section)"),
    ("v 0 0 0\nf 1 2 3\n", "not a BVH file (no MOTION section)"),
    (BVH.replace("HIERARCHY", "HIERARCHIES"), "not a BVH file (it does not begin with HIERARCHY and a ROOT joint)"),
    (BVH.replace("\t}\n}", "\t}\n"), "the HIERARCHY's braces do not balance"),
    (BVH.replace("\t\tCHANNELS", "\t\tCHANNELZ"), "unexpected 'CHANNELZ' in the HIERARCHY"),
    (BVH.replace("Frames:\t2", "Frames: 0"), "the BVH file holds no frames: a motion needs two or more"),
    (BVH.replace("Frames:\t2", "Frames: 1"), "the BVH file holds one frame: a motion needs two or more"),
    (BVH.replace("Frames:\t2", "Frames: two"), "'Frames:' is not followed by a number"),
    (BVH.replace("Frame Time: 0.04", "Frame Time: 0"), "'Frame Time:' must be a positive number"),
    (BVH.replace("Frames:\t2", "Frames: 3"), "holds 2 frame lines of the 3 it announces (cut short?)"),
    (BVH.replace("0 0 1 0 0 0 10 0 0", "0 0 1 0 0 0 10 0"), "frame 2 has 8 values, not the 9 the HIERARCHY's"),
    (BVH.replace("0 0 1 0 0 0 10 0 0", "0 0 1 0 0 0 ten 0 0"), "frame 2 holds 'ten', not a finite number"),
    (BVH.replace("0 0 1 0 0 0 10 0 0", "0 0 1 0 0 0 nan 0 0"), "frame 2 holds 'nan', not a finite number"),
])
def test_a_file_that_is_no_readable_bvh_says_why_in_one_line(tmp_path, text, message):
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    with pytest.raises(bvh.BvhError) as error:
        bvh.check(path)
    assert message in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize("coordinate", ["nan", "-NaN", "inf", "-Infinity", "1e999", "-1E+400", "1e39", "-4E+038",
                                        "abc", "2x"])
def test_an_obj_vertex_that_is_no_finite_number_is_named_by_its_line(tmp_path, monkeypatch, coordinate):
    """Blender's OBJ importer reads these as 0 without a word (its coordinates are 32-bit floats; "2x" it reads as
    2): a spike to the origin. Lines are counted across the chunks the file is read in."""
    monkeypatch.setattr(objfile, "CHUNK_BYTES", 7)
    path = tmp_path / "bad.obj"
    path.write_text(f"mtllib info.mtl\no Infantry\nv 0 0 0\nv 3e38 1e-400 0\nv 0 {coordinate} 0\nf 1 2 3\n")
    with pytest.raises(objfile.ObjError) as error:
        objfile.check(path)
    assert f"line 5: vertex coordinate {coordinate!r} is not a finite number" in str(error.value)
    path.write_text("mtllib info.mtl\no Infantry\nusemtl nan\nv 0 0 0\r\nv 3E+38 1e-400 0 # far\nvt 0.5 0.5\n"
                    "f 1 2 1\n")
    # words elsewhere, the largest 32-bit floats, an underflow to 0 and a comment are sound; its faces are counted
    assert objfile.check(path) == 1
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf\t3 2 1\nfo 1 2 3\n")
    assert objfile.check(path) == 2


def test_a_blender_operator_error_is_one_clause():
    """bpy puts "Error:" before an operator's message, and an add-on's operator may put its whole traceback there
    (Blender's BVH importer, Rigify's generate): the last line says what went wrong."""
    from rigger.blender.headless import blender_message

    assert blender_message(RuntimeError("Error: Cannot read file\n")) == "Cannot read file"
    traceback = "Error: Python: Traceback (most recent call last):\n  File \"x.py\", line 3\nIndexError: list index\n"
    assert blender_message(RuntimeError(traceback)) == "IndexError: list index"
    assert blender_message(RuntimeError("")) == "no reason given"
    with pytest.raises(KeyboardInterrupt):  # Ctrl-C inside an operator is Ctrl-C
        blender_message(RuntimeError("Error: Python: Traceback ...\nKeyboardInterrupt\nLocation: ops.py:109\n"))


def test_the_character_is_the_main_mesh_and_what_reaches_it_not_a_floor_or_a_mesh_apart():
    """The main mesh is the first that is no slab (a floor with more vertices than the character comes first in a
    file's order); a hat, a sword and a flat card (an eye) at the body stay; a floor, a 10 cm stage and another
    character 3 m away go; turning the whole scene about any axis changes nothing."""
    from rigger.core.scene import character_parts

    rng = np.random.default_rng(0)
    body = rng.uniform([-0.3, -0.2, 0.0], [0.3, 0.2, 1.8], (500, 3))
    hat = rng.uniform([-0.2, -0.2, 1.8], [0.2, 0.2, 2.0], (50, 3))  # on it
    sword = rng.uniform([0.35, -0.02, 0.5], [0.45, 0.02, 1.0], (40, 3))  # beside it, within a tenth of its size
    floor = np.column_stack([rng.uniform(-3, 3, (900, 2)), np.zeros(900)])  # flat, under it, larger, denser
    card = np.column_stack([rng.uniform(-0.1, 0.1, 40), np.full(40, 0.25), rng.uniform(1.5, 1.7, 40)])  # flat, small
    stage = rng.uniform([-2.0, -2.0, -0.1], [2.0, 2.0, 0.0], (60, 3))  # a slab 10 cm thick
    friend = body + [3.0, 0.0, 0.0]  # another character, apart
    parts = [("floor", floor), ("body", body), ("hat", hat), ("sword", sword), ("card", card), ("stage", stage),
             ("friend", friend)]
    slab = "flat and larger than 'body': a floor, a stage or a backdrop"
    expected = ([1, 2, 3, 4], [(0, slab), (5, slab), (6, "apart from 'body'")])
    assert character_parts(parts) == expected
    turn = np.array([[0.6, -0.64, 0.48], [0.8, 0.48, -0.36], [0.0, 0.6, 0.8]])  # a rotation
    assert character_parts([(name, points @ turn.T) for name, points in parts]) == expected


def cube(centre, half):
    """A closed box's 8 corners and 12 triangles."""
    corners = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half + np.array(centre)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
             (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return corners, np.array(faces)


def test_accessories_are_the_loose_parts_no_bone_runs_through_the_body_never_one():
    parts = [cube((0, 0, 0), 1.0), cube((0, 0, 3), 0.2), cube((3, 0, 0), 0.2), cube((0, 0, 9), 0.1)]
    points = np.concatenate([corners for corners, _ in parts])
    triangles = np.concatenate([faces + 8 * k for k, (_, faces) in enumerate(parts)])
    points = np.vstack([points, [(5.0, 5.0, 5.0)]])  # a point in no triangle: a part of its own
    heads, tails = np.array([(0, 0, -0.5), (0, 0, 2.5)]), np.array([(0, 0, 2.5), (0, 0, 3.5)])  # into the 2nd box
    part_of = loose_parts(len(points), triangles)
    boneless = boneless_parts(part_of, points, heads, tails)
    assert part_of.tolist() == [0] * 8 + [1] * 8 + [2] * 8 + [3] * 8 + [4]
    assert boneless.tolist() == [False, False, True, True, True]
    boneless = boneless_parts(part_of, points, heads + 10, tails + 10)  # no bone anywhere near
    assert boneless.tolist() == [False, True, True, True, True]  # the largest part stays the body


def test_points_on_a_surface_take_the_blend_of_their_corners_and_a_part_their_mean():
    a, b, c = np.eye(3)
    points = np.array([(a + b + c) / 3, a, 0.5 * (b + c)])
    coordinates = barycentric(points, np.tile(a, (3, 1)), np.tile(b, (3, 1)), np.tile(c, (3, 1)))
    np.testing.assert_allclose(coordinates, [(1 / 3, 1 / 3, 1 / 3), (1, 0, 0), (0, 0.5, 0.5)], atol=1e-12)
    donors = (np.array([0, 1, 1, 2]), np.array([0, 0, 1, 1]), np.array([1.0, 0.5, 0.5, 1.0]))  # vertex, bone, weight
    point, bone, weight = surface_entries(np.tile([0, 1, 2], (3, 1)), coordinates, donors)
    dense = np.zeros((3, 2))
    dense[point, bone] = weight
    np.testing.assert_allclose(dense, [(0.5, 0.5), (1.0, 0.0), (0.25, 0.75)], atol=1e-12)

    touching = np.array([0.0, 0.0, 0.05])  # the third point lies its part's extent x CONTACT (0.05) off: half as much
    part, bone, weight = part_means(np.array([0, 1, 1]), np.eye(3), touching, (point, bone, weight))
    dense = np.zeros((2, 2))
    dense[part, bone] = weight
    np.testing.assert_allclose(dense, [(0.5, 0.5), (2 / 3 * 1.0 + 1 / 3 * 0.25, 1 / 3 * 0.75)], atol=1e-12)
