"""``python -m rigger batch --engine ray``: long-lived Blender workers as Ray actors.

The module starts one Ray instance of its own on loopback (``ray start --head --block``, ended when the module is
done) and its batches join it with ``--address``. That instance's workers have the test hooks of
``rigger.batch.work`` set: a worker rigging crash.obj kills itself mid-file, one rigging hang.obj never finishes.
"""
import json
import os
import pathlib
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

import pytest

from characters import load_character, write_obj
from commands import files_below, run_cli

pytest.importorskip("bpy")
pytest.importorskip("ray", reason="ray is not installed here (make test installs it from requirements-ray.txt)")

from rigger.batch.work import CRASH_HOOK, HANG_HOOK  # noqa: E402

# Ray's one-machine mode (on loopback; Ray reads this variable on every platform), and for the tests' instances
# neither a token file in the home folder nor usage statistics.
LOOPBACK = {"RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0", "RAY_AUTH_MODE": "disabled", "RAY_USAGE_STATS_ENABLED": "0"}
QUIET = {key: LOOPBACK[key] for key in ("RAY_AUTH_MODE", "RAY_USAGE_STATS_ENABLED")}
TIMEOUT = 15  # seconds per file: a generated character takes well under one in a started worker
GOOD = ("humanoid.obj", "quadruped.obj", "snake.obj", "sub/tree.obj")
START_SECONDS = 120
STOP_SECONDS = 120  # for the workers to be killed and Ray left after Ctrl-C (about a second)


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def processes_mentioning(text):
    """Ids of the processes whose command line holds ``text``."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and text.encode() in (entry / "cmdline").read_bytes():
                found.append(int(entry.name))
        except OSError:  # gone meanwhile
            pass
    return found


@pytest.fixture(scope="module")
def cluster():
    """The address of a Ray instance started for this module, two CPUs, the test hooks in its workers' environment."""
    folder = tempfile.mkdtemp(prefix="rigger-ray-")  # short: Ray's socket paths below it must fit
    port = free_port()
    log = pathlib.Path(folder) / "head.log"
    with open(log, "w") as output:
        head = subprocess.Popen(
            [pathlib.Path(sys.executable).with_name("ray"), "start", "--head", "--block", f"--port={port}",
             "--num-cpus=2", "--include-dashboard=false", "--disable-usage-stats", f"--temp-dir={folder}"],
            stdout=output, stderr=subprocess.STDOUT,
            env={**os.environ, **LOOPBACK, CRASH_HOOK: "crash.obj", HANG_HOOK: "hang.obj"})
    try:
        deadline = time.monotonic() + START_SECONDS
        while "Ray runtime started" not in log.read_text():
            assert head.poll() is None and time.monotonic() < deadline, f"ray start failed:\n{log.read_text()}"
            time.sleep(0.2)
        yield f"127.0.0.1:{port}"
    finally:
        head.terminate()  # --block: it ends the Ray processes it started
        try:
            head.wait(timeout=90)
        except subprocess.TimeoutExpired:
            head.kill()
            head.wait()
        shutil.rmtree(folder, ignore_errors=True)


def batch(*args, cluster, **options):
    return run_cli("batch", *args, "--engine", "ray", "--address", cluster, env=LOOPBACK, **options)


def character(path, name):
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_obj(path, *load_character(name))


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """Generated characters (one in a subfolder), a corrupt file, and the hooks' crash.obj and hang.obj; good.txt
    lists the good ones."""
    folder = tmp_path_factory.mktemp("library")
    for name in GOOD:
        character(folder / name, pathlib.Path(name).stem)
    for name in ("crash.obj", "hang.obj"):
        shutil.copy(folder / "snake.obj", folder / name)
    (folder / "corrupt.glb").write_bytes(b"glTF" + bytes(range(256)) * 8)
    (folder / "good.txt").write_text("\n".join(GOOD) + "\n")
    return folder


@pytest.fixture(scope="module")
def local_run(library, tmp_path_factory):
    """The good files rigged by the local engine, for comparison."""
    out = tmp_path_factory.mktemp("local")
    result = run_cli("batch", library / "good.txt", "-o", out, "--jobs", 2)
    assert result.returncode == 0, result.stderr
    return out


@pytest.fixture(scope="module")
def ray_run(library, cluster, tmp_path_factory):
    out = tmp_path_factory.mktemp("ray")
    return batch(library, "-o", out, "--jobs", 2, "--timeout", TIMEOUT, cluster=cluster), out


def rows_of(out):
    return {row["file"]: row for row in json.loads((out / "summary.json").read_text())}


def test_every_good_file_is_rigged_and_every_bad_one_is_a_failed_row_with_its_reason(ray_run):
    result, out = ray_run
    assert result.returncode == 1, result.stderr  # some files failed
    assert "4 of 7 rigged" in result.stdout and "7/7" in result.stderr
    assert "worker died" not in result.stdout  # Ray's own notes on dead workers go to stderr
    rows = rows_of(out)
    assert sorted(rows) == sorted([*GOOD, "corrupt.glb", "crash.obj", "hang.obj"])
    for name in GOOD:
        assert rows[name]["status"] == "ok" and rows[name]["bones"] > 0 and rows[name]["worker"], rows[name]
    assert rows["crash.obj"]["message"].startswith("the worker process died mid-file (")
    assert rows["crash.obj"]["message"].endswith("; retried once, it died again")
    assert rows["crash.obj"]["attempts"] == 2
    assert rows["hang.obj"]["message"] == f"timed out after {TIMEOUT} s"
    assert rows["hang.obj"]["seconds"] >= TIMEOUT
    assert "Blender could not import it" in rows["corrupt.glb"]["message"]
    results = sorted(f"{name.removesuffix('.obj')}{suffix}" for name in GOOD for suffix in (".blend", ".json"))
    assert files_below(out) == sorted([*results, "sub", "summary.json"])  # nothing half-written


def test_the_good_files_rig_as_with_the_local_engine(ray_run, local_run):
    _, out = ray_run
    for name in GOOD:
        report = f"{name.removesuffix('.obj')}.json"
        ours, theirs = (json.loads((folder / report).read_text()) for folder in (out, local_run))
        assert ours["bones"] == theirs["bones"] and ours["params"] == theirs["params"], name


def _interruptible():
    """Let Ctrl-C reach the driver: a shell starts a background job (a CI run, say) with SIGINT ignored, and Python
    keeps a signal ignored that it was started with."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_an_interrupted_batch_resumes_where_it_stopped(cluster, library, tmp_path):
    folder = tmp_path / "models"
    folder.mkdir()
    for name, model in (("a", "snake"), ("b", "humanoid"), ("hang", "snake"), ("z", "quadruped")):
        shutil.copy(library / f"{model}.obj", folder / f"{name}.obj")
    out = tmp_path / "out"
    command = [sys.executable, "-m", "rigger", "batch", str(folder), "-o", str(out), "--engine", "ray", "--address",
               cluster, "--jobs", "1"]
    driver = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env={**os.environ, **LOOPBACK}, preexec_fn=_interruptible)
    deadline = time.monotonic() + START_SECONDS
    while not ((out / "b.json").exists() and list(out.glob(".rigger-partial.hang.json.*"))):  # hang.obj mid-file
        if driver.poll() is not None or time.monotonic() > deadline:
            driver.kill()  # hang.obj never ends: only a killed driver can tell what it printed
            raise AssertionError(driver.communicate())
        time.sleep(0.2)
    driver.send_signal(signal.SIGINT)
    try:
        _, stderr = driver.communicate(timeout=STOP_SECONDS)
    except subprocess.TimeoutExpired:
        driver.kill()
        raise AssertionError(f"still running {STOP_SECONDS} s after Ctrl-C: {driver.communicate()}") from None
    assert driver.returncode == 130 and "interrupted" in stderr and "--resume" in stderr, stderr
    assert files_below(out) == ["a.blend", "a.json", "b.blend", "b.json", "summary.json"]
    assert sorted(rows_of(out)) == ["a.obj", "b.obj"]
    before = (out / "a.blend").stat().st_mtime_ns

    result = batch(folder, "-o", out, "--jobs", 1, "--timeout", TIMEOUT, "--resume", cluster=cluster)
    assert result.returncode == 1, result.stderr  # hang.obj
    rows = rows_of(out)
    assert rows["a.obj"]["resumed"] and rows["b.obj"]["resumed"] and rows["z.obj"]["status"] == "ok"
    assert rows["hang.obj"]["message"] == f"timed out after {TIMEOUT} s"
    assert (out / "a.blend").stat().st_mtime_ns == before
    assert files_below(out) == ["a.blend", "a.json", "b.blend", "b.json", "summary.json", "z.blend", "z.json"]


def test_without_an_address_a_ray_instance_of_its_own_is_started_and_shut_down(library, tmp_path):
    ray_folder = tempfile.mkdtemp(prefix="rigger-ray-")  # where that instance keeps its session (RAY_TMPDIR)
    try:
        result = run_cli("batch", library / "snake.obj", "-o", tmp_path / "out", "--engine", "ray", "--jobs", 1,
                         env={**QUIET, "RAY_TMPDIR": ray_folder, "RAY_ADDRESS": ""})
        assert result.returncode == 0, result.stderr
        assert rows_of(tmp_path / "out")["snake.obj"]["status"] == "ok"
        sessions = list(pathlib.Path(ray_folder, "ray").glob("session_2*"))
        assert len(sessions) == 1
        assert "node_address=127.0.0.1" in (sessions[0] / "logs" / "gcs_server.out").read_text()  # on loopback
        assert processes_mentioning(ray_folder) == []  # every process it started has ended
    finally:
        shutil.rmtree(ray_folder, ignore_errors=True)
