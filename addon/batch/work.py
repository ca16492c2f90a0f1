"""The work on one file, in a process that has imported ``bpy``: rig it, save the model, write its report.

``python -m rigger rig`` (and so every child process of the local batch engine) and the Ray engine's long-lived
workers both go through :func:`rig_to_files`, so a file is rigged alike whichever engine ran it.

Test hooks (for the batch tests only; nothing else sets them): a process whose environment has
``RIGGER_TEST_CRASH_ON=NAME`` kills itself with SIGKILL, and one with ``RIGGER_TEST_HANG_ON=NAME`` sleeps for good,
when it rigs the input file called NAME, mid-file: after the model is saved, while the report is being written.
"""
import dataclasses
import json
import os
import pathlib
import signal
import socket
import sys
import time

from ..axes import AXIS_SUFFIXES
from ..core.files import replaced_on_success

CRASH_HOOK = "RIGGER_TEST_CRASH_ON"
HANG_HOOK = "RIGGER_TEST_HANG_ON"


class FileFailed(Exception):
    """A file that could not be rigged (unreadable, no mesh, rigging failed, cannot be written), in one line."""


@dataclasses.dataclass(frozen=True)
class Settings:
    """How every file is rigged: the method's name, its resolved parameters, the output target asked for, whether
    to skin, the file axes given (``--up``, ``--forward``; None: not given), the ``--set`` pairs as given (what
    the local engine hands its child processes) and a BVH to retarget onto the rig (``rig --animate``)."""

    method: str
    params: dict
    target: str = "plain"
    skin: bool = True
    up: str = None
    forward: str = None
    pairs: tuple = ()
    animate: pathlib.Path = None

    def axes_for(self, source):
        """(up, forward) to read model file ``source`` with: the settings' for OBJ and FBX files, (None, None) for
        the others (glTF is Y up by its specification, a .blend in Blender's world)."""
        if pathlib.Path(source).suffix.lower() in AXIS_SUFFIXES:
            return self.up, self.forward
        return None, None

    def options(self, source):
        """The ``rig`` command's options that rig ``source`` with these settings."""
        up, forward = self.axes_for(source)
        return [f"--method={self.method}", f"--target={self.target}", *(f"--set={pair}" for pair in self.pairs),
                *([] if self.skin else ["--no-skin"]), *([f"--up={up}"] if up else []),
                *([f"--forward={forward}"] if forward else [])]


def prepare():
    """Once per process before its first file: import bpy and register the add-on (the properties Rigger keeps on
    scenes and objects). FileFailed when Rigger's compiled modules do not load here."""
    from .. import register
    from ..compat import compiled_problem

    problem = compiled_problem()
    if problem:
        raise FileFailed(problem)
    register()


def rig_to_files(source, output, report, settings):
    """Rig model file ``source`` with ``settings`` (a :class:`Settings`), save it to ``output`` and, unless
    ``report`` is None, the JSON report there; return the report. Both files go through temporary files renamed into
    place, the model first. The report's ``timings["file"]`` is the whole file's time (import to save), and
    ``timings["file_cpu"]`` the CPU time the process spent on it meanwhile (less than that when it waited for a
    core). FileFailed says what went wrong."""
    from ..blender import scenefiles
    from ..blender.headless import blender_message

    start, cpu = time.perf_counter(), time.process_time()
    try:
        stamp = input_stamp(source)  # before reading: an input changed meanwhile is rigged again on --resume
        up, forward = settings.axes_for(source)
        data = scenefiles.rig_file(source, output, settings.method, settings.params, target=settings.target,
                                   skin=settings.skin, up=up, forward=forward, animate=settings.animate)
        data["timings"].update(file=time.perf_counter() - start, file_cpu=time.process_time() - cpu)
        data["input_stamp"] = stamp
        if report is not None:
            with replaced_on_success(report) as path:
                _test_hooks(source)
                path.write_text(json.dumps(data, indent=2))
    except ValueError as error:
        raise FileFailed(str(error)) from None
    except RuntimeError as error:  # a Blender operator failed (an exporter, say)
        raise FileFailed(f"{source}: {blender_message(error)}") from None
    except OSError as error:  # a folder that cannot be written, a full disk
        raise FileFailed(f"{error.filename or output}: {error.strerror or error}") from None
    return data


def input_stamp(source):
    """What tells a model file's versions apart without reading it: its size and modification time."""
    status = os.stat(source)
    return {"bytes": status.st_size, "modified_ns": status.st_mtime_ns}


def _test_hooks(source):
    name = os.path.basename(source)
    if os.environ.get(CRASH_HOOK) == name:
        os.kill(os.getpid(), signal.SIGKILL)
    if os.environ.get(HANG_HOOK) == name:
        while True:
            time.sleep(60)


def failed_row(message, seconds=0.0):
    """The summary fields of a file that failed: status, the ``message`` saying why, the ``seconds`` it took."""
    return {"status": "failed", "message": message, "seconds": seconds}


def rigged_row(report):
    """The summary fields of a file rigged with ``report``: status, bone count, skinning outcome, warnings, and the
    seconds the file took inside its process, wall-clock and CPU (``work_seconds``, ``work_cpu_seconds``; absent
    from reports older than those timings)."""
    row = {"status": "ok", "bones": len(report["bones"]), "skinning": report["skinning"]["summary"],
           "message": "; ".join(report["warnings"])}
    timings = report.get("timings", {})
    for key, timing in (("work_seconds", "file"), ("work_cpu_seconds", "file_cpu")):
        if timing in timings:
            row[key] = round(timings[timing], 3)
    return row


class Worker:
    """A long-lived Blender process of the Ray engine (``ray.remote`` makes it an actor): it imports bpy and Rigger
    once, then rigs file after file with one :class:`Settings`."""

    def __init__(self, settings):
        prepare()
        self._settings = settings

    def ready(self):
        """Where this worker runs, once it can take files (bpy imported)."""
        return {"worker": f"{socket.gethostname()}:{os.getpid()}", "peak_mb": peak_memory_mb()}

    def rig(self, source, output, report):
        """Rig one file (see :func:`rig_to_files`); its summary fields, a failed row for a file that failed."""
        try:
            row = rigged_row(rig_to_files(source, output, report, self._settings))
        except FileFailed as failure:
            row = failed_row(str(failure))
        return {**row, **self.ready()}


def peak_memory_mb():
    """This process's peak resident memory so far, in MB (Linux reports kilobytes, macOS bytes); None on Windows."""
    try:
        import resource
    except ImportError:
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return round(peak / (2 ** 20 if sys.platform == "darwin" else 2 ** 10), 1)
