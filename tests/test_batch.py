"""``python -m rigger batch`` with the local engine: the INPUTS forms and result names, resume, retries, timeouts and
the error paths. The Ray engine's tests are in test_batch_ray.py."""
import json
import pathlib
import subprocess
import sys

import pytest

from characters import load_character, write_obj
from commands import files_below, run_cli
from rigger.batch import BatchError, inputs
from rigger.batch.work import CRASH_HOOK, HANG_HOOK
from rigger.cli import INPUTS


def found(*texts, output, fmt="glb"):
    """{summary name: (results' stem, problem)} for the INPUTS ``texts``."""
    return {source.name: (source.stem.as_posix(), source.problem)
            for source in inputs.sources([str(text) for text in texts], output, fmt, INPUTS)}


def touch(folder, *names):
    for name in names:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text("")


def test_a_folder_is_searched_recursively_for_model_files_skipping_hidden_ones_and_the_results(tmp_path):
    touch(tmp_path, "a.obj", "B.GLB", "notes.txt", "sub/deep/c.fbx", ".hidden/d.obj", ".e.obj", "out/old.glb")
    assert found(tmp_path, output=tmp_path / "out") == {
        "B.GLB": ("B", None), "a.obj": ("a", None), "sub/deep/c.fbx": ("sub/deep/c", None)}


def test_results_never_share_a_name_nor_replace_an_input_or_the_summary(tmp_path):
    touch(tmp_path, "a.glb", "b.obj", "summary.obj", "snake.obj", "snake.fbx", "sub/summary.obj")
    beside = found(tmp_path, output=tmp_path)  # results written into the input folder
    assert beside == {"a.glb": ("a_glb", None), "b.obj": ("b", None), "snake.fbx": ("snake_fbx", None),
                      "snake.obj": ("snake_obj", None), "summary.obj": ("summary_obj", None),
                      "sub/summary.obj": ("sub/summary", None)}
    assert found(tmp_path, output=tmp_path / "elsewhere")["a.glb"] == ("a", None)


def test_a_list_file_names_model_files_relative_to_itself(tmp_path):
    touch(tmp_path, "lib/a.obj", "lib/sub/b.glb", "other/c.obj")
    listing = tmp_path / "lib" / "models.txt"
    listing.write_text(f"# my models\na.obj\n\n  sub/b.glb  \nmissing.obj\nnotes.txt\n{tmp_path / 'other' / 'c.obj'}\n")
    result = found(listing, output=tmp_path / "out")
    outside = str(tmp_path / "other" / "c.obj")
    assert result == {"a.obj": ("a", None), "sub/b.glb": ("sub/b", None),
                      "missing.obj": ("missing", f"{tmp_path / 'lib' / 'missing.obj'}: no such file"),
                      "notes.txt": ("notes", f"{tmp_path / 'lib' / 'notes.txt'}: cannot read .txt; use "
                                             f"{', '.join(INPUTS)}"),
                      outside: (pathlib.Path(outside).relative_to("/").with_suffix("").as_posix(), None)}


def test_a_glob_matches_model_files_named_below_its_fixed_folders(tmp_path):
    touch(tmp_path, "lib/x/a.obj", "lib/y/z/b.obj", "lib/y/z/c.glb", "lib/out/d.obj")
    assert found(f"{tmp_path}/lib/**/*.obj", output=tmp_path / "lib" / "out") == {
        "x/a.obj": ("x/a", None), "y/z/b.obj": ("y/z/b", None)}


def test_a_file_named_twice_is_rigged_once_and_two_files_cannot_share_results(tmp_path):
    touch(tmp_path, "one/a.obj", "two/a.obj")
    result = list(inputs.sources([str(tmp_path / "one"), str(tmp_path / "one" / "a.obj"), str(tmp_path / "two")],
                                 tmp_path / "out", "glb", INPUTS))
    assert [(source.path, source.problem) for source in result] == [
        (tmp_path / "one" / "a.obj", None), (tmp_path / "two" / "a.obj", "its results would overwrite those of a.obj")]


def test_inputs_that_are_none_of_the_forms_are_an_error(tmp_path):
    with pytest.raises(BatchError, match="nope: no such file or folder"):
        found(tmp_path / "nope", output=tmp_path)
    (tmp_path / "picture.png").write_bytes(bytes(range(256)))
    with pytest.raises(BatchError, match="neither a model file .* nor a text file listing model files"):
        found(tmp_path / "picture.png", output=tmp_path)


@pytest.fixture(scope="module")
def characters_folder(tmp_path_factory):
    """Two generated characters and a corrupt file, the hook names of a crash and a hang, in one folder."""
    folder = tmp_path_factory.mktemp("models")
    for name in ("snake", "tree"):
        write_obj(folder / f"{name}.obj", *load_character(name))
    (folder / "snake.fbx").write_text("not an FBX")  # the same stem: the results must not share a name
    (folder / "notes.txt").write_text("not a model")
    return folder


def test_batch_rigs_a_folder_in_parallel_and_summarises(characters_folder, tmp_path):
    out = tmp_path / "rigged"
    result = run_cli("batch", characters_folder, "-o", out, "--jobs", 2, "--format", "glb", "--timeout", 300,
                     "--up", "Z")
    assert result.returncode == 1, result.stderr  # one file failed
    assert "2 of 3 rigged" in result.stdout and "3/3" in result.stderr and "warning" not in result.stderr
    assert json.loads((out / "tree.json").read_text())["axes"] == {"up": "Z", "forward": "Y"}
    rows = {row["file"]: row for row in json.loads((out / "summary.json").read_text())}
    assert rows["snake.obj"]["status"] == "ok" and rows["snake.obj"]["bones"] > 0
    assert rows["snake.obj"]["output"] == "snake_obj.glb" and rows["tree.obj"]["output"] == "tree.glb"
    assert rows["snake.fbx"]["status"] == "failed" and "could not import" in rows["snake.fbx"]["message"]
    assert files_below(out) == ["snake_obj.glb", "snake_obj.json", "summary.json", "tree.glb", "tree.json"]


def test_a_child_that_crashes_is_retried_once_and_one_that_hangs_times_out(characters_folder, tmp_path):
    """The test hooks make the child rigging crash.obj kill itself mid-file, and the one rigging hang.obj sleep."""
    folder = tmp_path / "models"
    folder.mkdir()
    for name in ("crash", "hang"):
        (folder / f"{name}.obj").write_bytes((characters_folder / "tree.obj").read_bytes())
    out = tmp_path / "out"
    result = run_cli("batch", folder, "-o", out, "--timeout", 20, env={CRASH_HOOK: "crash.obj", HANG_HOOK: "hang.obj"})
    assert result.returncode == 1
    rows = {row["file"]: row for row in json.loads((out / "summary.json").read_text())}
    assert rows["crash.obj"]["message"] == "crashed (killed by signal 9); retried once, it died again"
    assert rows["crash.obj"]["attempts"] == 2
    assert rows["hang.obj"]["message"] == "timed out after 20 s" and rows["hang.obj"]["seconds"] >= 20
    assert files_below(out) == ["summary.json"]  # the models both saved before the hooks struck are gone too


def test_resume_skips_only_files_complete_with_the_same_settings(characters_folder, tmp_path):
    out = tmp_path / "out"
    models = [characters_folder / "snake.obj", characters_folder / "tree.obj"]
    assert run_cli("batch", *models, "-o", out, "--format", "fbx").returncode == 0
    done = {path.name: path.stat().st_mtime_ns for path in out.iterdir()}
    (out / "tree.json").unlink()  # as when a process is killed between saving the model and writing the report
    (out / ".rigger-partial.tree.json.abcd1234").mkdir()  # the temporary folder it left behind
    (out / ".cache.packages").mkdir()  # a folder of the user's own that looks alike

    again = run_cli("batch", *models, "-o", out, "--format", "fbx", "--resume")
    assert again.returncode == 0, again.stderr
    assert "ok (resumed)" in again.stdout and "2 of 2 rigged (1 by an earlier run)" in again.stdout
    rows = {row["file"]: row for row in json.loads((out / "summary.json").read_text())}
    assert rows["snake.obj"]["resumed"] and rows["snake.obj"]["bones"] > 0 and "resumed" not in rows["tree.obj"]
    assert (out / "snake_obj.fbx").stat().st_mtime_ns == done["snake_obj.fbx"]  # snake.fbx lies beside it
    assert files_below(out) == [".cache.packages", "snake_obj.fbx", "snake_obj.json", "summary.json", "tree.fbx",
                                "tree.json"]

    other = run_cli("batch", models[0], "-o", out, "--format", "fbx", "--resume", "--set", "bone_length=0.2")
    assert other.returncode == 0 and "resumed" not in other.stdout  # other parameters: rigged again
    turned = run_cli("batch", models[0], "-o", out, "--format", "fbx", "--resume", "--set", "bone_length=0.2",
                     "--up", "Z")
    assert turned.returncode == 0 and "resumed" not in turned.stdout  # other axes: rigged again
    edited = tmp_path / "edited.obj"
    edited.write_bytes(models[1].read_bytes())
    assert run_cli("batch", edited, "-o", out, "--format", "fbx").returncode == 0
    with edited.open("a") as obj:
        obj.write("# edited\n")
    again = run_cli("batch", edited, "-o", out, "--format", "fbx", "--resume")
    assert again.returncode == 0 and "resumed" not in again.stdout  # another version of the input: rigged again


@pytest.mark.parametrize("extra, message", [
    (("--engine", "local", "--address", "127.0.0.1:1"), "--address needs --engine ray"),
    (("--jobs", "0"), "--jobs must be at least 1"),
    (("--set", "bone_lenght=0.1"), "unknown parameter"),
])
def test_bad_options_are_an_error_before_any_work(extra, message, characters_folder, tmp_path):
    result = run_cli("batch", characters_folder, "-o", tmp_path / "out", *extra)
    assert result.returncode == 1 and message in result.stderr, result.stderr
    assert not (tmp_path / "out").exists()


def test_batch_on_a_missing_folder_or_one_without_models_is_an_error(tmp_path):
    result = run_cli("batch", tmp_path / "nope", "-o", tmp_path / "out")
    assert result.returncode == 1 and "nope: no such file or folder" in result.stderr
    (tmp_path / "empty").mkdir()
    result = run_cli("batch", tmp_path / "empty", "-o", tmp_path / "out")
    assert result.returncode == 1 and "no model files" in result.stderr
    assert not (tmp_path / "out").exists()


def test_batch_results_under_a_file_are_an_error(characters_folder, tmp_path):
    (tmp_path / "a_file").write_text("")
    result = run_cli("batch", characters_folder, "-o", tmp_path / "a_file" / "out")
    assert result.returncode == 1 and "a_file: is not a folder, so the results cannot go in" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_ray_engine_without_ray_says_how_to_install_it(characters_folder, tmp_path):
    """ray made unimportable in the child, whether or not it is installed here."""
    argv = ["batch", str(characters_folder), "-o", str(tmp_path / "out"), "--engine", "ray"]
    code = f"import sys; sys.modules['ray'] = None; from rigger.cli import main; sys.exit(main({argv!r}))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        "rigger: error: --engine ray needs the ray package, which is not installed here: "
        "pip install -r requirements-ray.txt (or pip install 'rigger[ray]')"]
    assert not (tmp_path / "out").exists()
