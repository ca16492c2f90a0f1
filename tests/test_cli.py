"""``python -m rigger``: rig files end to end in child processes, as a pipeline would, including the error paths."""
import json
import pathlib

import numpy as np
import pytest

from characters import load_character, strictly_inside_fraction, write_obj
from commands import files_below, run_cli as run

bpy = pytest.importorskip("bpy")

import rigger  # noqa: E402
from bpy_extras.io_utils import axis_conversion  # noqa: E402  (Blender's own axis table)
from rigger import axes  # noqa: E402
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
    # ... built as the default target, with the body plan and every bone's role and side
    assert report["target"] == "plain"
    assert report["body_plan"] == expected.body_plan.to_dict() and report["body_plan"]["kind"] == "humanoid"
    assert [(bone["role"], bone["side"]) for bone in bones] == [(role.role, role.side) for role in expected.roles]


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


def test_a_floor_and_a_mesh_standing_apart_are_left_out_of_the_rig(scene, tmp_path):
    """A humanoid on a floor plane, a crate standing 3 m away: rigged together, the floor seen from above is the
    widest silhouette and the rig is lost in it. Both are left out, with a warning each, and saved unrigged."""
    build_character("humanoid", subdivisions=0)
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(3.0, 0.0, 0.25))
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    result = run("rig", tmp_path / "scene.blend", "-o", tmp_path / "rigged.glb", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["body_plan"]["kind"] == "humanoid" and list(report["skinning"]["meshes"]) == ["humanoid"]
    assert "left out 'Plane' (flat and larger than 'humanoid': a floor, a stage or a backdrop): it is saved as it " \
           "was, unrigged" in report["warnings"]
    assert "left out 'Cube' (apart from 'humanoid'): it is saved as it was, unrigged" in report["warnings"]
    assert sorted(mesh["name"] for mesh in glb_document(tmp_path / "rigged.glb")["meshes"]) == \
        ["Cube", "Plane", "humanoid"]


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
    assert sorted(files_below(tmp_path)) == ["a_file", "model.glb", "taken.glb"]


def test_faces_blenders_obj_importer_drops_are_a_warning(humanoid_obj, tmp_path):
    """Blender's OBJ importer drops a face naming a vertex the file lacks (or one vertex twice) without a word: a
    mesh with holes rigged as if whole. The warning counts them."""
    source = tmp_path / "holes.obj"
    source.write_text(humanoid_obj[0].read_text() + "f 1 2 99999\nf 1 1 2\n")
    report = tmp_path / "holes.json"
    result = run("rig", source, "-o", tmp_path / "holes.glb", "--report", report, "--no-skin")
    assert result.returncode == 0, result.stderr
    faces = len(humanoid_obj[2])
    warning = (f"Blender's OBJ importer kept {faces} of the file's {faces + 2} faces: it drops those it cannot read "
               f"(naming a vertex the file lacks, or one vertex twice)")
    assert warning in json.loads(report.read_text())["warnings"] and f"warning: {warning}" in result.stderr
    result = run("rig", humanoid_obj[0], "-o", tmp_path / "whole.glb", "--no-skin")
    assert "OBJ importer" not in result.stderr


def test_no_skin_and_fbx_output(humanoid_obj, tmp_path):
    result = run("rig", humanoid_obj[0], "-o", tmp_path / "out.fbx", "--no-skin", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out.fbx").read_bytes()[:18] == b"Kaydara FBX Binary"
    assert json.loads((tmp_path / "r.json").read_text())["skinning"]["summary"].startswith("not skinned")


@pytest.mark.parametrize("case, message", [
    ("missing", "no such file"),
    ("no_mesh", "no mesh"),
    ("line", "on one line"),
    ("bad_set", "unknown parameter"),
    ("bad_value", "above the maximum"),
    ("bad_method", "unknown method"),
    ("bad_target", "invalid choice: 'nope'"),
    ("bad_output", "cannot write"),
    ("unreadable", "Blender could not import it"),
    ("nan_vertex", "line 3: vertex coordinate 'nan' is not a finite number"),  # Blender would read 0
    ("folder", "is a folder, not a model file"),
    ("refusing_folder", "/proc: cannot write there"),
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
    elif case == "nan_vertex":
        source = tmp_path / "nan.obj"
        source.write_text("o Infantry\nv 0 0 0\nv nan 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
    elif case == "unreadable":
        source = tmp_path / "empty.glb"
        source.write_bytes(b"")
    elif case == "bad_set":
        extra = ["--set", "bone_lenght=0.1"]
    elif case == "bad_value":
        extra = ["--set", "bone_length=7"]
    elif case == "bad_method":
        extra = ["--method", "nope"]
    elif case == "bad_target":
        extra = ["--target", "nope"]
    elif case == "folder":
        source = tmp_path
    out = tmp_path / "out"
    out.mkdir()
    output = out / ("rig.txt" if case == "bad_output" else "rig.blend")
    if case == "refusing_folder":  # writable by its permissions, but it makes no files (root may write anywhere else)
        output = pathlib.Path("/proc/rig.blend")
    before = set(files_below(tmp_path))
    result = run("rig", source, "-o", output, "--report", out / "report.json", *extra)
    assert result.returncode == 1
    assert message in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and result.stderr.startswith("rigger: error: ")
    assert files_below(out) == []
    assert set(files_below(tmp_path)) == before


# --up and --forward (issue 28, defect 8)

AXIS_PAIRS = [(up, forward) for up in axes.AXES for forward in axes.AXES if up[-1] != forward[-1]]


def test_axes_turn_a_file_as_blenders_obj_importer_does(scene, tmp_path):
    """For each of the 24 (up, forward) pairs, the rotation the report maps bones back through is the one Blender's
    OBJ importer puts the file in its world with (and Blender's own axis table)."""
    source = write_obj(tmp_path / "corner.obj", [(1.0, 2.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)], [(0, 1, 2)])
    for up, forward in AXIS_PAIRS:
        scene_objects = bpy.context.scene.objects
        for obj in list(scene_objects):
            bpy.data.objects.remove(obj)
        bpy.ops.wm.obj_import(filepath=str(source), up_axis=up.replace("-", "NEGATIVE_"),
                              forward_axis=forward.replace("-", "NEGATIVE_"))
        (obj,) = scene_objects
        turn = axes.to_blender(up, forward)
        np.testing.assert_allclose(np.array(obj.matrix_world)[:3, :3] @ obj.data.vertices[0].co, turn @ [1, 2, 3],
                                   atol=1e-6, err_msg=f"up {up}, forward {forward}")
        np.testing.assert_allclose(turn, np.array(axis_conversion(from_forward=forward, from_up=up, to_forward="Y",
                                                                  to_up="Z")), atol=1e-12)


def saved_scene(path):
    """Open a .blend the CLI saved: (its mesh's world vertices, {bone: world head} of its armature)."""
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    mesh = next(obj for obj in bpy.data.objects if obj.type == 'MESH')
    armature = next(obj for obj in bpy.data.objects if obj.type == 'ARMATURE')
    vertices = np.array([mesh.matrix_world @ vertex.co for vertex in mesh.data.vertices])
    heads = {bone.name: np.array(armature.matrix_world @ bone.head_local) for bone in armature.data.bones}
    return vertices, heads


@pytest.mark.parametrize("up, forward, options", [("Z", "Y", ["--up", "Z"]),
                                                  ("-X", "Z", ["--up", "-X", "--forward", "z"])])
def test_an_obj_read_with_its_own_up_axis_stands_upright_and_reports_its_own_coordinates(
        scene, tmp_path, up, forward, options):
    """The humanoid written with another up axis (Z up, as CesiumMan's OBJ; or -X up): read with --up (and
    --forward), it stands in Blender as generated, Z up, and the report's bones are in the file's coordinates."""
    vertices, triangles = load_character("humanoid")
    turn = axes.to_blender(up, forward)
    source = write_obj(tmp_path / "upright.obj", vertices @ turn, triangles)  # rows: file = turn^T @ world
    result = run("rig", source, "-o", tmp_path / "out.blend", "--report", tmp_path / "r.json", *options)
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["axes"] == {"up": up, "forward": forward}
    assert f"read with up {up}, forward {forward}" in report["frame"]

    world, heads = saved_scene(tmp_path / "out.blend")
    np.testing.assert_allclose(world, vertices, atol=1e-5)  # upright: exactly the generated, Z-up character
    bones = {bone["name"]: bone for bone in report["bones"]}
    for name, head in heads.items():  # the report's bones are the armature's, in the file's coordinates
        np.testing.assert_allclose(bones[name]["head"], head @ turn, atol=1e-5)
    root = next(bone["name"] for bone in report["bones"] if bone["parent"] is None)
    top = max(heads, key=lambda name: heads[name][2])
    rise = heads[top] - heads[root]
    assert rise[2] > 0.9 * np.linalg.norm(rise) and rise[2] > 0.5  # from the hips up to the head, along +Z


def test_a_z_up_obj_read_with_the_default_axes_lies_on_its_side(scene, tmp_path):
    vertices, triangles = load_character("humanoid")
    source = write_obj(tmp_path / "upright.obj", vertices, triangles)
    result = run("rig", source, "-o", tmp_path / "out.blend", "--report", tmp_path / "r.json", "--no-skin")
    assert result.returncode == 0, result.stderr
    assert json.loads((tmp_path / "r.json").read_text())["axes"] == {"up": "Y", "forward": "-Z"}
    world, _ = saved_scene(tmp_path / "out.blend")
    np.testing.assert_allclose(world, vertices @ Y_UP_TO_Z_UP.T, atol=1e-5)  # the file's Z became Blender's -Y


def test_an_fbx_is_read_with_its_own_axes_unless_told_otherwise(scene, humanoid_obj, tmp_path):
    """Blender writes FBX files Y up, forward -Z, and says so in the file: read as they are by default or with those
    axes given; told Z up, Blender's importer turns the file's Y-up data onto its back."""
    assert run("rig", humanoid_obj[0], "-o", tmp_path / "in.fbx", "--no-skin").returncode == 0
    worlds = {}
    for options in ((), ("--up", "Y", "--forward", "-Z"), ("--up", "Z")):
        result = run("rig", tmp_path / "in.fbx", "-o", tmp_path / "out.blend", "--report", tmp_path / "r.json",
                     "--no-skin", *options)
        assert result.returncode == 0, result.stderr
        report = json.loads((tmp_path / "r.json").read_text())
        assert report["frame"].startswith("blender world") and report["axes"] == (
            dict(zip(("up", "forward"), axes.file_axes(".fbx", *options[1::2]))) if options else None)
        worlds[options] = saved_scene(tmp_path / "out.blend")[0]
    upright, given, on_its_back = worlds.values()
    np.testing.assert_allclose(upright, humanoid_obj[1] @ Y_UP_TO_Z_UP.T, atol=1e-5)
    np.testing.assert_allclose(given, upright, atol=1e-5)
    np.testing.assert_allclose(on_its_back, upright @ Y_UP_TO_Z_UP, atol=1e-5)


@pytest.mark.parametrize("source, options, message", [
    ("model.obj", ["--up", "W"], "--up must be one of X, Y, Z, -X, -Y, -Z, got 'W'"),
    ("model.obj", ["--up", "Z", "--forward", "-Z"], "--up Z and --forward -Z lie on one axis"),
    ("model.obj", ["--forward=y"], "--up Y and --forward Y lie on one axis"),
    ("model.glb", ["--up", "Z"], "--up and --forward apply to OBJ and FBX files only; glTF is Y-up"),
    ("model.blend", ["--forward", "X"], "--up and --forward apply to OBJ and FBX files only; a .blend file is in "
                                        "Blender's Z-up world already"),
])
def test_bad_axes_are_one_error_line_before_anything_is_read(tmp_path, source, options, message):
    (tmp_path / source).write_text("never read")
    for command in (["rig", tmp_path / source, "-o", tmp_path / "out" / "x.blend"],
                    ["batch", tmp_path, "-o", tmp_path / "out"]):
        if command[0] == "batch" and source != "model.obj":
            continue  # a batch applies the axes to its OBJ and FBX files only, and warns about the others
        result = run(*command, *options)
        assert result.returncode == 1 and result.stderr.startswith(f"rigger: error: {message}"), result.stderr
        assert len(result.stderr.strip().splitlines()) == 1
        assert not (tmp_path / "out").exists()


def test_a_batch_gives_the_axes_to_its_obj_and_fbx_files_only(tmp_path):
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "scene.glb").write_bytes(b"not a glTF")
    result = run("batch", folder, "-o", tmp_path / "out", "--up", "Z")
    assert "warning: --up and --forward apply to OBJ and FBX files only; 1 glTF or .blend file(s) keep their own " \
           "frames" in result.stderr
    (row,) = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert row["status"] == "failed" and "could not import" in row["message"]  # not refused for its axes


def test_methods_lists_every_method_and_its_parameters():
    result = run("methods")
    assert result.returncode == 0
    assert "silhouette:" in result.stdout and "--set bone_length=VALUE" in result.stdout
    assert "tuning (" not in result.stdout
    tuned = run("methods", "--tuning")
    assert tuned.returncode == 0 and "tuning (rigger.methods.silhouette.tuning." in tuned.stdout
    assert "body plan and bone roles (after every method):" in tuned.stdout and "knee_at = " in tuned.stdout
    assert "[rigger.core.metarig.MetarigTuning]" in tuned.stdout and "[rigger.core.facing.FootTuning]" in tuned.stdout


def test_ctrl_c_is_one_line_and_the_shell_s_status(monkeypatch, capsys, tmp_path):
    """Interrupted while rigging (outputs go through temporary files, so none is half-written): one line, no
    traceback, status 130 as a shell gives a command ended by Ctrl-C."""
    from rigger import cli

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_run_rig", interrupted)
    assert cli.main(["rig", str(tmp_path / "model.obj")]) == 130
    assert capsys.readouterr().err == "rigger: interrupted; nothing was written\n"
