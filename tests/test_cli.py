"""``python -m rigger``: rig files end to end in child processes, as a pipeline would, including the error paths."""
import json

import numpy as np
import pytest

from characters import load_character, strictly_inside_fraction, write_obj
from commands import run_cli as run

bpy = pytest.importorskip("bpy")

import rigger  # noqa: E402
from rigger.blender.armature import build_armature  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402
from rigger.core.skeleton import Skeleton  # noqa: E402

# How Blender's OBJ importer turns the OBJ's Y-up frame into its Z-up world (file x, y, z → x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@pytest.fixture(scope="module")
def humanoid_obj(tmp_path_factory):
    """The humanoid as a conventional Y-up OBJ (its Z-up arrays turned into the file frame)."""
    vertices, triangles = load_character("humanoid")
    in_file = vertices @ Y_UP_TO_Z_UP  # row vectors: world = C @ file, so file = C^T @ world
    return write_obj(tmp_path_factory.mktemp("obj") / "humanoid.obj", in_file, triangles), in_file, triangles


@pytest.fixture(scope="module")
def rigged_glb(humanoid_obj, tmp_path_factory):
    folder = tmp_path_factory.mktemp("glb")
    result = run("rig", humanoid_obj[0], "-o", folder / "humanoid.glb", "--report", folder / "report.json",
                 "--set", "bone_length=0.12")
    return result, folder


def test_rig_an_obj_to_glb_with_a_report_in_the_obj_frame(humanoid_obj, rigged_glb):
    result, folder = rigged_glb
    assert result.returncode == 0, result.stderr
    assert (folder / "humanoid.glb").read_bytes()[:4] == b"glTF"
    report = json.loads((folder / "report.json").read_text())
    assert report["params"]["bone_length"] == 0.12
    assert report["skinning"]["summary"] and isinstance(report["warnings"], list)
    assert report["timings"]["rig"] > 0 and report["timings"]["method.total"] > 0

    _, in_file, triangles = humanoid_obj
    bones = report["bones"]
    names = [bone["name"] for bone in bones]
    assert len(set(names)) == len(names) and sum(bone["parent"] is None for bone in bones) == 1
    heads = np.array([bone["head"] for bone in bones])
    assert strictly_inside_fraction(in_file, triangles, heads) >= 0.9  # inside the mesh of the v lines

    # exactly the skeleton the core makes from the mesh as Blender sees it, mapped back into the file's frame
    expected = rigger.rig_mesh(in_file @ Y_UP_TO_Z_UP.T, triangles, bone_length=0.12)
    assert names == list(expected.names)
    np.testing.assert_allclose(heads, expected.heads @ Y_UP_TO_Z_UP, atol=1e-4)


def glb_document(path):
    """The JSON chunk of a binary glTF file."""
    data = path.read_bytes()
    assert data[:4] == b"glTF" and data[16:20] == b"JSON"
    return json.loads(data[20:20 + int.from_bytes(data[12:16], "little")])


def test_a_rigged_glb_rigged_again_holds_one_skin_of_its_own_mesh(rigged_glb, tmp_path):
    """The glTF importer adds a hidden bone-shape mesh and the file's own armature: neither joins the new rig."""
    _, folder = rigged_glb
    result = run("rig", folder / "humanoid.glb", "-o", tmp_path / "again.glb", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert list(report["skinning"]["meshes"]) == ["humanoid"]
    assert "replaced the file's armature 'humanoid_rig'" in report["warnings"]
    document = glb_document(tmp_path / "again.glb")
    assert [mesh["name"] for mesh in document["meshes"]] == ["humanoid"]
    assert len(document["skins"]) == 1 and len(document["skins"][0]["joints"]) == len(report["bones"])


def test_a_blend_is_rigged_as_its_scene_shows_it(scene, tmp_path):
    """Only the meshes the scene shows are rigged (not those in excluded or hidden collections, nor other scenes);
    an armature that already deformed them is replaced; cameras and lights stay."""
    body = build_character("humanoid", subdivisions=0)
    old = build_armature(Skeleton(["old"], [(0, 0, 0)], [(0, 0, 1)], [-1]), "OldRig")
    body.vertex_groups.new(name="old").add(range(len(body.data.vertices)), 1.0, 'REPLACE')
    body.modifiers.new("Armature", 'ARMATURE').object = old
    body.parent = old
    for name, kind in (("Excluded", "snake"), ("Hidden", "octopus")):  # both bigger than the body
        collection = bpy.data.collections.new(name)
        scene.collection.children.link(collection)
        build_character(kind, subdivisions=0, collection=collection)
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True
    bpy.data.collections["Hidden"].hide_viewport = True
    build_character("tree", subdivisions=0, collection=bpy.data.scenes.new("Other").collection)
    scene.collection.objects.link(bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera")))
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))

    result = run("rig", tmp_path / "scene.blend", "-o", tmp_path / "rigged.blend", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert list(report["skinning"]["meshes"]) == ["humanoid"]
    assert "replaced the file's armature 'OldRig'" in report["warnings"]
    with bpy.data.libraries.load(str(tmp_path / "rigged.blend")) as (saved, _):
        objects = set(saved.objects)
    assert {"humanoid", "humanoid_rig", "Camera", "snake", "octopus", "tree"} <= objects
    assert "OldRig" not in objects


def test_outputs_never_overwrite_the_input_or_each_other(rigged_glb, tmp_path):
    source = tmp_path / "model.glb"
    source.write_bytes((rigged_glb[1] / "humanoid.glb").read_bytes())
    (tmp_path / "taken.glb").mkdir()
    (tmp_path / "a_file").write_text("")
    for extra, message in [(("-o", source), "the output would overwrite the input"),
                           (("-o", tmp_path / "a_file" / "out.blend"), "a_file: is not a folder, so the output"),
                           (("-o", tmp_path / "out.blend", "--report", tmp_path / "a_file" / "deeper" / "r.json"),
                            "a_file: is not a folder, so the report"),
                           (("-o", tmp_path / "out.blend", "--report", source), "the report would overwrite the input"),
                           (("-o", tmp_path / "out.blend", "--report", tmp_path / "out.blend"),
                            "the report would overwrite the output"),
                           (("-o", tmp_path / "taken.glb"), "is a folder")]:
        result = run("rig", source, *extra)
        assert result.returncode == 1 and message in result.stderr, result.stderr
    assert source.read_bytes() == (rigged_glb[1] / "humanoid.glb").read_bytes()
    assert sorted(leaves_nothing(tmp_path)) == ["a_file", "model.glb", "taken.glb"]


def test_no_skin_and_fbx_output(humanoid_obj, tmp_path):
    result = run("rig", humanoid_obj[0], "-o", tmp_path / "out.fbx", "--no-skin", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out.fbx").read_bytes()[:18] == b"Kaydara FBX Binary"
    assert json.loads((tmp_path / "r.json").read_text())["skinning"]["summary"].startswith("not skinned")


def leaves_nothing(folder):
    return [path.name for path in folder.iterdir()]


@pytest.mark.parametrize("case, message", [
    ("missing", "no such file"),
    ("no_mesh", "no mesh"),
    ("line", "on one line"),
    ("bad_set", "unknown parameter"),
    ("bad_value", "above the maximum"),
    ("bad_method", "unknown method"),
    ("bad_output", "cannot write"),
    ("unreadable", "Blender could not import it"),
])
def test_errors_exit_non_zero_with_a_message_and_write_nothing(case, message, humanoid_obj, tmp_path):
    source = humanoid_obj[0]
    extra = []
    if case == "missing":
        source = tmp_path / "missing.obj"
    elif case == "no_mesh":
        source = tmp_path / "points.obj"
        source.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    elif case == "line":
        source = write_obj(tmp_path / "line.obj", [(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 3, 3)], [(0, 1, 2), (1, 3, 2)])
    elif case == "unreadable":
        source = tmp_path / "empty.glb"
        source.write_bytes(b"")
    elif case == "bad_set":
        extra = ["--set", "bone_lenght=0.1"]
    elif case == "bad_value":
        extra = ["--set", "bone_length=7"]
    elif case == "bad_method":
        extra = ["--method", "nope"]
    out = tmp_path / "out"
    out.mkdir()
    output = out / ("rig.txt" if case == "bad_output" else "rig.blend")
    before = set(leaves_nothing(tmp_path))
    result = run("rig", source, "-o", output, "--report", out / "report.json", *extra)
    assert result.returncode != 0
    assert message in result.stderr, result.stderr
    assert "Traceback" not in result.stderr
    assert leaves_nothing(out) == []
    assert set(leaves_nothing(tmp_path)) == before


def test_methods_lists_every_method_and_its_parameters():
    result = run("methods")
    assert result.returncode == 0
    assert "silhouette:" in result.stdout and "--set bone_length=VALUE" in result.stdout
