"""The engine-neutral half of a batch: stream the input files through an engine, a bounded number at a time, skip
those a previous run finished (``resume``), retry a file once when its worker process died, keep the progress bar
and write the summary.

An engine runs files in Blender processes. It offers ``slots`` (how many files it works on at once),
``start(job)`` (only while fewer than ``slots`` are started and not finished), ``finished()`` (block until at
least one started file is done; a list of ``(job, row, crashed)``, ``crashed`` when the process rigging it died, the
row holding ``status``, ``message`` and ``seconds`` at least) and ``stop()`` (end the work in flight; the engine is
not used afterwards). The driver never holds more than ``slots`` started files plus one retry each, so a list of
10^5 inputs is read as the work goes.
"""
import collections
import contextlib
import dataclasses
import json
import pathlib
import sys
import time

from ..axes import axes_field, file_axes
from ..core.files import remove_leftover_folders, remove_leftovers, replaced_on_success
from .work import failed_row, input_stamp, rigged_row

SUMMARY = "summary.json"
# The first bytes of a complete model file of each output format: .blend plain or zstd-compressed, binary glTF, FBX.
MAGIC = {".blend": (b"BLENDER", b"\x28\xb5\x2f\xfd"), ".glb": (b"glTF",), ".fbx": (b"Kaydara FBX Binary",)}


@dataclasses.dataclass
class Job:
    """One file to rig (an ``inputs.Source``), where its model and report go, and which attempt this is."""

    source: object
    output: pathlib.Path
    report: pathlib.Path
    attempt: int = 1


def run(sources, total, engine, output, fmt, settings, resume=False, progress=sys.stderr):
    """Rig ``sources`` (``inputs.Source``; about ``total`` of them, for the progress bar) with ``engine`` into folder
    ``output`` as ``<stem>.<fmt>`` and ``<stem>.json``; write ``summary.json`` there and return its rows.

    Rows of rigged and failed files hold ``seconds`` (wall time of the last attempt, from when a worker took the
    file) and ``finished_at`` (when the driver got the result, seconds since the epoch). Folders a killed process
    left half-written in ``output`` are removed first. With ``resume``, a file whose model and report are there and
    were made with these settings is not rigged again (its row says ``resumed``). A file whose process died is
    retried once; a failed file leaves no results behind. When interrupted (Ctrl-C, or any exception) the engine is
    stopped, the files in flight are cleaned up and the rows so far are written as the summary before the exception
    goes on.
    """
    remove_leftover_folders(output)
    rows, retries, running = [], collections.deque(), []
    bar = _Bar(total, progress)
    pending = iter(sources)

    def next_job():
        """The next file to start; rows for the files that need no work on the way."""
        if retries:
            return retries.popleft()
        for source in pending:
            job = Job(source, output / f"{source.stem}.{fmt}", output / f"{source.stem}.json")
            if source.problem:
                rows.append(_row(job, failed_row(source.problem)))
            elif resume and (report := finished_report(job, settings)):
                rows.append(_row(job, {**rigged_row(report), "seconds": 0.0, "resumed": True}))
            else:
                return job
            bar.step()
        return None

    try:
        while True:
            while len(running) < engine.slots and (job := next_job()) is not None:
                engine.start(job)
                running.append(job)
            if not running:
                break
            for job, row, crashed in engine.finished():
                row["finished_at"] = round(time.time(), 3)
                running.remove(job)
                if row["status"] != "ok":
                    discard(job, output)
                if crashed and job.attempt == 1:
                    retries.append(dataclasses.replace(job, attempt=2))
                    continue
                if crashed:
                    row = {**row, "message": f"{row['message']}; retried once, it died again"}
                rows.append(_row(job, {**row, "attempts": job.attempt} if job.attempt > 1 else row))
                bar.step()
    except BaseException:
        engine.stop()
        for job in running:
            discard(job, output)
        bar.close()
        with contextlib.suppress(OSError):  # the interruption matters more than a summary that cannot be written
            write_summary(output, rows)
        raise
    bar.close()
    return write_summary(output, rows)


def _row(job, fields):
    """A summary row: the file's name first, then ``fields``, and its model's path below the output folder when it
    was rigged."""
    row = {"file": job.source.name, "status": fields["status"], "bones": 0, "skinning": "", **fields}
    if row["status"] == "ok":
        row["output"] = job.source.stem.with_name(job.output.name).as_posix()
    return row


def finished_report(job, settings):
    """The report of the file a previous run rigged into ``job``'s output and report with ``settings``, or None when
    either is missing or incomplete, or they were made from another version of the input file (``input_stamp``), with
    another method, other parameters, another target asked for, other axes or skinning."""
    output, report = job.output, job.report
    try:
        with open(output, "rb") as model:
            head = model.read(32)
        data = json.loads(pathlib.Path(report).read_text(encoding="utf-8"))
        stamp = input_stamp(job.source.path)
    except (OSError, ValueError):
        return None
    axes = file_axes(job.source.path.suffix, *settings.axes_for(job.source.path))
    expected = {"method": settings.method, "params": json.loads(json.dumps(settings.params)),
                "asked_target": settings.target, "axes": axes_field(axes), "input_stamp": stamp}
    if not (isinstance(data, dict) and head.startswith(MAGIC.get(pathlib.Path(output).suffix.lower(), ()))
            and all(data.get(key) == value for key, value in expected.items())
            and isinstance(data.get("bones"), list) and isinstance(data.get("skinning"), dict)
            and data["skinning"].get("summary", "").startswith("not skinned") != settings.skin):
        return None
    return data


def discard(job, output):
    """Remove whatever an attempt at ``job`` left: its model, its report, their half-written folders, and the
    folders below ``output`` made for them that are empty then."""
    for path in (job.output, job.report):
        remove_leftovers(path)
        path.unlink(missing_ok=True)
    folder, root = job.output.parent, pathlib.Path(output)
    while folder != root and root in folder.parents:
        try:
            folder.rmdir()
        except OSError:  # not empty: another file's results are there
            break
        folder = folder.parent


def write_summary(output, rows):
    """``rows`` sorted by file, written to ``output``/summary.json (atomically); returned."""
    rows = sorted(rows, key=lambda row: row["file"])
    with replaced_on_success(output / SUMMARY) as path:
        path.write_text(json.dumps(rows, indent=2))
    return rows


def summary_table(rows):
    """The summary as a markdown table, with a closing count."""
    header = ("file", "status", "bones", "seconds", "skinning / message")
    lines = [" | ".join(header), " | ".join("---" for _ in header)]
    for row in rows:
        note = row["message"] if row["status"] != "ok" else row["skinning"]
        status = "ok (resumed)" if row.get("resumed") else row["status"]
        lines.append(" | ".join(str(value) for value in (row["file"], status, row["bones"], row["seconds"], note)))
    ok = sum(row["status"] == "ok" for row in rows)
    resumed = sum(bool(row.get("resumed")) for row in rows)
    return "\n".join(lines) + f"\n{ok} of {len(rows)} rigged" + (f" ({resumed} by an earlier run)" if resumed else "")


class _Bar:
    """``[#####.....] done/total`` on one line of ``stream``."""

    def __init__(self, total, stream, width=30):
        self.done, self.total, self.stream, self.width = 0, max(total, 1), stream, width
        self._draw()

    def step(self):
        self.done += 1
        self.total = max(self.total, self.done)  # the inputs may have grown since they were counted
        self._draw()

    def _draw(self):
        if self.stream is not None:
            filled = round(self.width * self.done / self.total)
            print(f"\r[{'#' * filled}{'.' * (self.width - filled)}] {self.done}/{self.total}", end="",
                  file=self.stream, flush=True)

    def close(self):
        if self.stream is not None:
            print(file=self.stream, flush=True)
