"""The local engine: each file in a child process of its own (``python -m rigger rig``), ``jobs`` at a time.

A fresh process per file pays for Blender's start-up every time, but a file can take nothing with it into the next
one, and a child that crashes or hangs takes only its own file down.
"""
import concurrent.futures
import json
import subprocess
import sys
import threading
import time

from .work import failed_row, rigged_row


class LocalEngine:
    """Up to ``jobs`` child processes at once; each gets ``timeout`` seconds (None: no limit) for its file."""

    def __init__(self, jobs, timeout, settings):
        self.slots = jobs
        self._timeout = timeout
        self._settings = settings
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=jobs)
        self._futures = {}
        self._children = set()
        self._lock = threading.Lock()
        self._stopping = False

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.stop()

    def start(self, job):
        self._futures[self._pool.submit(self._rig, job)] = job

    def finished(self):
        done, _ = concurrent.futures.wait(self._futures, return_when=concurrent.futures.FIRST_COMPLETED)
        return [(self._futures.pop(future), *future.result()) for future in done]

    def stop(self):
        """Kill the children still running and wait for their threads."""
        with self._lock:
            self._stopping = True
            for child in self._children:
                child.kill()
        self._pool.shutdown(wait=True, cancel_futures=True)

    def _rig(self, job):
        """(row, crashed) for one file rigged in a child process; a failed row, never an exception, when the child
        cannot even be started (no memory or file handles left) or its report is not one."""
        try:
            return self._run_child(job)
        except Exception as error:
            return failed_row(f"{type(error).__name__}: {error}"), False

    def _run_child(self, job):
        command = [sys.executable, "-m", __package__.rpartition(".")[0], "rig", str(job.source.path),
                   "-o", str(job.output), "--report", str(job.report), *self._settings.options(job.source.path)]
        start = time.perf_counter()
        with self._lock:
            if self._stopping:
                return failed_row("stopped"), False
            child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     encoding="utf-8", errors="replace")  # Blender may echo paths in any encoding
            self._children.add(child)
        timed_out = False
        try:
            _, stderr = child.communicate(timeout=self._timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            child.kill()
            _, stderr = child.communicate()
        finally:
            with self._lock:
                self._children.discard(child)
        seconds = round(time.perf_counter() - start, 2)
        if timed_out:
            return failed_row(f"timed out after {self._timeout:g} s", seconds), False
        if child.returncode:
            return failed_row(_failure(child.returncode, stderr), seconds), child.returncode < 0
        try:
            row = rigged_row(json.loads(job.report.read_text()))
        except (OSError, ValueError, KeyError, TypeError) as error:
            row = failed_row(f"finished without a readable report: {error}")
        return {**row, "seconds": seconds}, False


def _failure(returncode, stderr):
    """What went wrong in a failed child: its ``rigger: error:`` line, else how it ended and its last output."""
    lines = [line for line in stderr.splitlines() if line.startswith("rigger: error:")]
    if lines:
        return lines[-1].removeprefix("rigger: error: ")
    how = f"killed by signal {-returncode}" if returncode < 0 else f"exit status {returncode}"
    tail = stderr.strip()[-300:]
    return f"crashed ({how})" + (f": {tail}" if tail else "")
