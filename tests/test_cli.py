"""``python -m rigger``: rig files end to end in child processes, as a pipeline would, including the error paths."""
import json
import subprocess
import sys

import numpy as np
import pytest

from characters import load_character, winding_numbers

pytest.importorskip("bpy")

import rigger  # noqa: E402

# How Blender's OBJ importer turns the OBJ's Y-up frame into its Z-up world (file x, y, z → x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def run(*args, timeout=180):
    return subprocess.run([sys.executable, "-m", "rigger", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def write_obj(path, vertices, triangles):
    with open(path, "w") as out:
        out.write("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices))
        out.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))
    return path


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
    assert (winding_numbers(in_file, triangles, heads) > 0.5).mean() >= 0.9  # inside the mesh of the v lines

    # exactly the skeleton the core makes from the mesh as Blender sees it, mapped back into the file's frame
    expected = rigger.rig_mesh(in_file @ Y_UP_TO_Z_UP.T, triangles, bone_length=0.12)
    assert names == list(expected.names)
    np.testing.assert_allclose(heads, expected.heads @ Y_UP_TO_Z_UP, atol=1e-4)


def test_a_rigged_glb_can_be_rigged_again_to_blend(rigged_glb, tmp_path):
    _, folder = rigged_glb
    result = run("rig", folder / "humanoid.glb", "-o", tmp_path / "again.blend", "--report", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "again.blend").stat().st_size > 0
    assert json.loads((tmp_path / "r.json").read_text())["bones"]


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
    ("flat", "flat"),
    ("bad_set", "unknown parameter"),
    ("bad_value", "above the maximum"),
    ("bad_method", "unknown method"),
    ("bad_output", "cannot write"),
])
def test_errors_exit_non_zero_with_a_message_and_write_nothing(case, message, humanoid_obj, tmp_path):
    source = humanoid_obj[0]
    extra = []
    if case == "missing":
        source = tmp_path / "missing.obj"
    elif case == "no_mesh":
        source = tmp_path / "points.obj"
        source.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    elif case == "flat":
        source = write_obj(tmp_path / "flat.obj", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [(0, 1, 2), (1, 3, 2)])
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


def test_batch_rigs_a_folder_in_parallel_and_summarises(humanoid_obj, tmp_path):
    folder = tmp_path / "models"
    folder.mkdir()
    vertices, triangles = load_character("snake")
    write_obj(folder / "snake.obj", vertices, triangles)
    (folder / "a_broken.obj").write_text("v 0 0 0\n")
    (folder / "notes.txt").write_text("not a model")
    out = tmp_path / "rigged"
    result = run("batch", folder, "-o", out, "--jobs", 2, "--format", "glb")
    assert result.returncode == 1  # one file failed
    assert "1 of 2 rigged" in result.stdout and "2/2" in result.stderr
    rows = {row["file"]: row for row in json.loads((out / "summary.json").read_text())}
    assert rows["snake.obj"]["status"] == "ok" and rows["snake.obj"]["bones"] > 0
    assert rows["a_broken.obj"]["status"] == "failed" and "no mesh" in rows["a_broken.obj"]["message"]
    assert sorted(leaves_nothing(out)) == ["snake.glb", "snake.json", "summary.json"]


def test_batch_on_a_missing_folder_is_an_error(tmp_path):
    result = run("batch", tmp_path / "nope", "-o", tmp_path / "out")
    assert result.returncode == 1 and "no such folder" in result.stderr
    assert not (tmp_path / "out").exists()
