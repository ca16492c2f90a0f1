"""The Ray engine: a pool of long-lived Blender workers (Ray actors) on a Ray cluster, or on a Ray instance of this
machine's own that it starts and shuts down.

Each worker (``work.Worker``) imports bpy and Rigger once and rigs one file at a time, so no file pays for
Blender's start-up. The engine replaces workers itself rather than through Ray's ``max_restarts``: it must know
which file a dead worker held, to hand the driver that file for its one retry, and a file's ``timeout`` clock starts
only when a worker that has finished starting takes it, so a replacement's Blender start-up never counts against a
file. A worker running past the timeout is killed (``ray.kill``) and replaced; the file's row says so.
"""
import collections
import logging
import os
import time

from . import BatchError
from .work import Worker, failed_row

INSTALL = "pip install -r requirements-ray.txt (or pip install 'rigger[ray]')"
POLL_SECONDS = 1.0  # longest wait for results before timeouts are looked at again
START_LIMIT = 600.0  # seconds the workers may all spend starting while files wait, before the batch gives up
KILL_WAIT = 30.0  # seconds to wait for Ray to confirm that a killed worker is gone


class RayEngine:
    """``jobs`` workers (default one per CPU of the cluster) on the Ray cluster at ``address`` (default
    ``RAY_ADDRESS``; when neither is given, a new Ray instance of this machine, on loopback, without the dashboard,
    which ``stop`` shuts down again). Each file gets ``timeout`` seconds (None: no limit)."""

    def __init__(self, jobs, timeout, settings, address=None):
        address = address or os.environ.get("RAY_ADDRESS") or None
        self._ray = ray = _import_ray(local=address is None)
        options = {"log_to_driver": False, "logging_level": logging.ERROR}  # the rows say what went wrong
        try:
            if address is None:
                ray.init(address="local", num_cpus=jobs or os.cpu_count(), include_dashboard=False, **options)
            else:
                ray.init(address=address, **options)
        except (ConnectionError, RuntimeError, ValueError) as error:
            where = f"the Ray cluster at {address}" if address else "a local Ray instance"
            raise BatchError(f"cannot start or reach {where}: {error}") from None
        try:  # the instance started above goes down again if the pool cannot be set up
            self.slots = jobs or max(1, int(ray.cluster_resources().get("CPU", 1)))
            self._timeout = timeout
            self._actor = ray.remote(Worker).options(num_cpus=1, max_restarts=0)
            self._settings = settings
            self._queue = collections.deque()
            self._started = False  # whether any worker has ever started
            self._workers = [_Slot() for _ in range(self.slots)]
            for worker in self._workers:
                self._replace(worker)
        except BaseException:
            ray.shutdown()
            raise

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.stop()

    def start(self, job):
        self._queue.append(job)
        self._dispatch()

    def finished(self):
        ray = self._ray
        results = []
        while not results:
            waiting = {worker.ref: worker for worker in self._workers if worker.ref is not None}
            ready, _ = ray.wait(list(waiting), num_returns=1, timeout=self._wait_seconds())
            if ready:
                ready, _ = ray.wait(list(waiting), num_returns=len(waiting), timeout=0)
            for ref in ready:
                results += self._collect(waiting[ref])
            results += self._expire()
            self._dispatch()
            self._check_started()
        return results

    def stop(self):
        """Kill every worker, wait until Ray has them gone, and disconnect (shutting down the Ray instance this engine
        started)."""
        ray = self._ray
        if not ray.is_initialized():  # stopped already
            return
        busy = [worker.ref for worker in self._workers if worker.job is not None]
        for worker in self._workers:
            ray.kill(worker.actor)
        if busy:
            ray.wait(busy, num_returns=len(busy), timeout=KILL_WAIT)
        ray.shutdown()

    def _replace(self, worker):
        """Start a new worker process in ``worker``'s place."""
        worker.actor = self._actor.remote(self._settings)
        worker.ref, worker.job, worker.since = worker.actor.ready.remote(), None, time.monotonic()

    def _dispatch(self):
        """Hand queued files to the workers that are started and free."""
        for worker in self._workers:
            if self._queue and worker.ref is None:
                job = worker.job = self._queue.popleft()
                worker.since = time.monotonic()
                worker.ref = worker.actor.rig.remote(str(job.source.path), str(job.output), str(job.report))

    def _collect(self, worker):
        """The driver's results from ``worker``'s finished call: none when it finished starting. A worker that
        fails to start stops the batch while none ever has (nothing could rig a file); after that it is started
        again (a node lost, say)."""
        exceptions = self._ray.exceptions
        job, seconds = worker.job, round(time.monotonic() - worker.since, 2)
        try:
            value = self._ray.get(worker.ref)
        except exceptions.RayTaskError as error:  # an exception from Rigger's own code; the worker lives on
            if job is None:
                return self._not_started(worker, _last_line(error))
            worker.ref = worker.job = None
            return [(job, failed_row(_last_line(error), seconds), False)]
        except exceptions.RayError as error:  # the worker process died (killed, segfault, out of memory, lost node)
            if job is None:
                return self._not_started(worker, _reason(error))
            self._replace(worker)
            return [(job, failed_row(f"the worker process died mid-file ({_reason(error)})", seconds), True)]
        worker.ref = worker.job = None
        self._started = True
        return [] if job is None else [(job, {**value, "seconds": seconds}, False)]

    def _not_started(self, worker, reason):
        if not self._started:
            raise BatchError(f"a Ray worker could not start: {reason}")
        self._replace(worker)
        return []

    def _expire(self):
        """Kill and replace the workers whose file has run past the timeout; their files' failed rows."""
        results = []
        for worker in self._workers:
            if worker.job is not None and self._timeout is not None \
                    and time.monotonic() - worker.since > self._timeout:
                self._ray.kill(worker.actor)
                self._ray.wait([worker.ref], timeout=KILL_WAIT)  # gone before the driver cleans up after it
                seconds = round(time.monotonic() - worker.since, 2)
                results.append((worker.job, failed_row(f"timed out after {self._timeout:g} s", seconds), False))
                self._replace(worker)
        return results

    def _wait_seconds(self):
        """How long the next wait for results may take: until the first timeout due, at most POLL_SECONDS."""
        due = [worker.since + self._timeout - time.monotonic() for worker in self._workers
               if worker.job is not None and self._timeout is not None]
        return max(0.0, min([POLL_SECONDS, *due]))

    def _check_started(self):
        """BatchError when files wait while every worker has been starting for START_LIMIT seconds (a cluster
        without free CPUs, or whose nodes cannot import bpy and Rigger and say nothing)."""
        now = time.monotonic()
        if self._queue and all(worker.job is None and worker.ref is not None and now - worker.since > START_LIMIT
                               for worker in self._workers):
            raise BatchError(f"no Ray worker started within {START_LIMIT:g} s; the cluster has "
                             f"{self._ray.cluster_resources().get('CPU', 0):g} CPUs, and every node needs bpy and "
                             f"Rigger installed as on this one")


class _Slot:
    """One worker of the pool: its actor, the call it is waiting for (``ready`` while starting, ``rig`` while busy,
    None while free), the file it holds and since when."""

    actor = ref = job = None
    since = 0.0


def _import_ray(local):
    """The ray module, or BatchError saying how to install it. A Ray instance started here (``local``) is for this
    machine alone: Ray's one-machine mode keeps it on loopback, and it sends no usage statistics."""
    if local:
        os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    try:
        import ray
    except ImportError:
        raise BatchError(f"--engine ray needs the ray package, which is not installed here: {INSTALL}") from None
    return ray


def _reason(error):
    """Why Ray says a worker died, in a clause."""
    text = " ".join(str(error).split())
    for marker in ("Worker exit detail: ", "The actor is dead because ", "The actor died because "):
        if marker in text:
            return text.split(marker, 1)[1].split(" Some common causes")[0].strip()[:300]
    return text[:300]


def _last_line(error):
    """The last line of a remote exception's text: its type and message, without Ray's traceback."""
    lines = str(error).strip().splitlines()
    return lines[-1].strip() if lines else type(error).__name__
