"""Batch throughput (issue 30): ``python -m rigger batch`` with the local engine at 1 and 2 jobs against the Ray
engine at 1 and 2 workers, on the same generated models.

Models: the sample characters (``rigger.samples``) at Skin level 3 (10k to 35k vertices; Blender, in a child
process), each turned about the vertical axis in ``--turns`` steps of 5 degrees: 12 x 16 = 192 distinct OBJ files
that take a second or more each, almost all of it one core's work (import, rig, bone-heat skinning, save).

Each configuration runs the command line as a user would, into a fresh folder, as a child process; its wall time
gives the throughput. The run's active span runs from the first file's start to the last file's end (the summary
rows' ``finished_at`` less ``seconds``); the rest of the wall time is the run's fixed cost (the driver's start, Ray's
start and shut-down, the workers' Blender start-up), and the span alone gives the steady state, what a library of
thousands of models sees. A file's own time (``work_seconds``) is measured inside the process that rigs it; a
1-job run's per-file overhead is its span per file minus the mean of those. Memory: the Ray workers' peak resident
memory (``peak_mb`` rows), and for the local engine the largest process of the run (``wait4``), a Blender child.

The machine is shared: before each run the benchmark waits (up to ``--quiet-wait`` seconds) for the 1-minute load
average to drop below ``--load-limit``, records the load before and after, and runs a configuration again (up to
``--tries`` times, keeping the least loaded) when other work raised the load during it. The Ray instances the runs
start are on loopback, send no usage statistics, use no token file, and keep their session files in a temporary folder.
Writes ``bench/results/batch.md`` and ``bench/results/batch.png``.

    .venv/bin/python bench/batch.py              # the full run, about 20 minutes on a quiet 2-core machine
    .venv/bin/python bench/batch.py --turns 1    # 6 models, a smoke test
"""
import argparse
import datetime
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchkit import RESULTS_DIR, cpu_model, described_commit, markdown_table  # noqa: E402

GENERATE_FLAG = "--generate-models"  # child-process mode: write the models into a folder
SKIN_LEVEL = 3
TURN_DEGREES = 5.0
CONFIGS = (("local", 1), ("local", 2), ("ray", 1), ("ray", 2))
TARGET_SPEEDUP = 1.8  # Ray at 2 workers against 1 worker
TARGET_OVERHEAD = 0.10  # Ray's per-file overhead, as a fraction of a median file's own time
RUN_TIMEOUT = 3600
# The Ray instances of the runs: no token file in the home folder, no usage statistics (the engine itself keeps a
# Ray instance it starts on loopback).
RAY_ENV = {"RAY_AUTH_MODE": "disabled", "RAY_USAGE_STATS_ENABLED": "0", "RAY_ADDRESS": ""}


def write_models(folder, turns):
    """Child-process side: every character at Skin level SKIN_LEVEL, turned ``turns`` ways, as Y-up OBJ files."""
    from rigger.blender.headless import empty_scene, temporary_user_folder

    temporary_user_folder()
    from rigger import samples
    from rigger.blender.samples import character_arrays

    empty_scene()
    for name in samples.CHARACTERS:
        vertices, triangles = character_arrays(name, subdivisions=SKIN_LEVEL)
        for turn in range(turns):
            angle = math.radians(TURN_DEGREES * turn)
            cos, sin = math.cos(angle), math.sin(angle)
            turned = vertices @ np.array([[cos, sin, 0.0], [-sin, cos, 0.0], [0.0, 0.0, 1.0]])
            with open(Path(folder) / f"{name}_{turn * TURN_DEGREES:03.0f}.obj", "w") as out:
                # Blender's Z-up world into the OBJ's Y-up frame (file x, y, z = world x, z, -y)
                out.write("".join(f"v {x!r} {z!r} {-y!r}\n" for x, y, z in turned))
                out.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))


def wait_until_quiet(limit, longest):
    """Wait until the 1-minute load average is below ``limit`` (at most ``longest`` seconds); the load then."""
    deadline = time.monotonic() + longest
    while os.getloadavg()[0] >= limit and time.monotonic() < deadline:
        time.sleep(10)
    return os.getloadavg()


def run_batch(models, engine, jobs, scratch):
    """One batch over the folder ``models`` as a child process: wall seconds, the largest process's peak memory
    (MB), the summary rows, the load before and after."""
    out = Path(tempfile.mkdtemp(prefix=f"{engine}{jobs}-", dir=scratch))
    ray_folder = tempfile.mkdtemp(prefix="ray-", dir="/tmp")  # short: Ray's socket paths below it must fit
    command = [sys.executable, "-m", "rigger", "batch", str(models), "-o", str(out), "--engine", engine,
               "--jobs", str(jobs)]
    env = {**os.environ, **RAY_ENV, "RAY_TMPDIR": ray_folder}
    load_before = os.getloadavg()
    start = time.perf_counter()
    driver_cpu = 0.0
    with open(out.parent / f"{out.name}.log", "w") as log:
        child = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=env)
        while not (ended := os.wait4(child.pid, os.WNOHANG))[0]:
            driver_cpu = process_cpu_seconds(child.pid) or driver_cpu
            time.sleep(0.2)
    _, status, usage = ended
    wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    shutil.rmtree(ray_folder, ignore_errors=True)
    rows = json.loads((out / "summary.json").read_text())
    failed = [row for row in rows if row["status"] != "ok"]
    if child.returncode or failed:
        raise RuntimeError(f"{engine} --jobs {jobs} failed: {failed[:3]}; see {out.parent / (out.name + '.log')}")
    return {"engine": engine, "jobs": jobs, "wall": wall, "max_rss_mb": usage.ru_maxrss / 1024, "rows": rows,
            "driver_cpu": driver_cpu,
            "out": out, "load_before": load_before, "load_after": os.getloadavg()}


def quiet_run(run, limit):
    """Whether other work stayed below ``limit`` cores during ``run``: the 1-minute load at its end, less its own
    jobs."""
    return run["load_after"][0] - run["jobs"] < limit


def process_cpu_seconds(pid):
    """CPU seconds (user and system) process ``pid`` has used itself, or None once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime: fields 14 and 15


def bones_agree(first, second):
    """How many files the two runs rigged with identical bones, of how many."""
    same = 0
    for row in first["rows"]:
        stem = row["output"].rsplit(".", 1)[0]
        reports = [json.loads((run["out"] / f"{stem}.json").read_text())["bones"] for run in (first, second)]
        same += reports[0] == reports[1]
    return same, len(first["rows"])


def figures(run):
    """Throughput (models per minute) over the whole run and in its active span, the fixed cost, the span per file
    and job, mean and median of the files' own time, and the per-file overhead (meaningful for 1-job runs)."""
    rows = run["rows"]
    count = len(rows)
    work = [row["work_seconds"] for row in rows]
    work_cpu = [row["work_cpu_seconds"] for row in rows]
    span = max(row["finished_at"] for row in rows) - min(row["finished_at"] - row["seconds"] for row in rows)
    per_file = span * run["jobs"] / count
    written = [(run["out"] / row["output"]).stat().st_size + (run["out"] / row["output"]).with_suffix(".json")
               .stat().st_size for row in rows]
    return {"count": count, "wall": run["wall"], "whole": 60 * count / run["wall"], "steady": 60 * count / span,
            "written_mb": statistics.mean(written) / 2 ** 20,
            "fixed": run["wall"] - span, "per_file": per_file, "mean_work": statistics.mean(work),
            "median_work": statistics.median(work), "overhead": per_file - statistics.mean(work),
            "mean_cpu": statistics.mean(work_cpu)}


def worker_memory(run):
    """{worker: its peak resident memory (MB)} of a Ray run."""
    peaks = {}
    for row in run["rows"]:
        peaks[row["worker"]] = max(peaks.get(row["worker"], 0.0), row["peak_mb"])
    return peaks


def worker_peak(run):
    """The largest peak resident memory of a run's Blender processes (MB): Ray's workers report theirs; a local run's
    largest process is one of its children."""
    return max(worker_memory(run).values()) if run["engine"] == "ray" else run["max_rss_mb"]


def markdown(runs, numbers, agreement, notes, meta):
    load = lambda values: ", ".join(f"{value:.2f}" for value in values)  # noqa: E731
    ray1, ray2 = numbers[("ray", 1)], numbers[("ray", 2)]
    local1 = numbers[("local", 1)]
    speedup_whole, speedup_steady = ray2["whole"] / ray1["whole"], ray2["steady"] / ray1["steady"]
    overhead_share = ray1["overhead"] / ray1["median_work"]
    memory = worker_memory(runs[("ray", 2)])
    verdict = lambda ok: "PASS" if ok else "FAIL"  # noqa: E731
    lines = [
        "# Batch throughput: local engine against Ray (issue 30)",
        "",
        f"Generated by `python bench/batch.py` on {meta['date']} in {meta['minutes']:.0f} min; rigger at "
        f"`{meta['commit']}`.",
        "",
        f"- Machine: {cpu_model()}, {os.cpu_count()} cores, 24 GB, shared with other agents; Python "
        f"{platform.python_version()}, Linux {platform.release()}, bpy 5.0.1, ray {meta['ray']}. The load averages "
        "(1, 5, 15 min) before and after each run are in its row: a load above the 2 cores means the run waited for "
        "a core part of the time.",
        f"- Models: {numbers[('local', 1)]['count']} OBJ files, the {len(meta['characters'])} sample characters "
        f"({', '.join(meta['characters'])}) at Skin level {SKIN_LEVEL} ({meta['vertices']}), each turned about the "
        f"vertical axis in steps of {TURN_DEGREES:g} degrees; default settings, skinned, saved as .blend.",
        "- Each run is `python -m rigger batch MODELS -o OUT --engine E --jobs N` in a fresh output folder; Ray "
        "without `--address`, so each Ray run starts and stops a Ray instance of its own on loopback.",
        "- A file's own time is measured inside the process that rigs it (import to save, `work_seconds`), with the "
        "CPU time that process spent meanwhile (`work_cpu_seconds`, all its threads): own time well above CPU time "
        "means the file waited for a core. A run's "
        "active span runs from its first file's start to its last file's end; the rest of its wall time is its fixed "
        "cost (the driver, Ray's start and shut-down, the workers' Blender start-up), and the span alone gives the "
        "steady state. Per-file overhead at 1 job: the span per file minus the mean own time of the files. Driver CPU: "
        "the CPU time of the `python -m rigger batch` process itself (start-up included) per file.",
        *(f"- {note}" for note in notes),
        "",
        "## Targets",
        "",
        f"- Ray, 2 workers against 1, on {ray1['count']} models: ≥ {TARGET_SPEEDUP}x throughput: "
        f"**{verdict(speedup_whole >= TARGET_SPEEDUP)}: {speedup_whole:.2f}x over the whole run** "
        f"({ray1['whole']:.1f} → {ray2['whole']:.1f} models/min), {speedup_steady:.2f}x in the steady state.",
        f"- Ray's per-file overhead ≤ {TARGET_OVERHEAD:.0%} of a median file's time: "
        f"**{verdict(overhead_share <= TARGET_OVERHEAD)}: {ray1['overhead'] * 1000:.0f} ms, "
        f"{overhead_share:.1%} of the median file's {ray1['median_work']:.2f} s** (the local engine's: "
        f"{local1['overhead']:.2f} s per file, {local1['overhead'] / local1['median_work']:.0%}: a fresh Blender "
        f"per file; so Ray's overhead over the local engine is {ray1['overhead'] - local1['overhead']:+.2f} s).",
        "",
        "## Runs",
        "",
        *markdown_table(
            ("engine", "jobs", "models", "wall", "fixed cost", "models/min", "steady models/min",
             "span per file and job", "mean / median own time", "own CPU time (mean)", "per-file overhead",
             "driver CPU per file",
             "memory per worker", "written per file", "load before", "load after"),
            [(key[0], key[1], numbers[key]["count"], f"{numbers[key]['wall']:.1f} s", f"{numbers[key]['fixed']:.1f} s",
              f"{numbers[key]['whole']:.1f}", f"{numbers[key]['steady']:.1f}", f"{numbers[key]['per_file']:.2f} s",
              f"{numbers[key]['mean_work']:.2f} / {numbers[key]['median_work']:.2f} s",
              f"{numbers[key]['mean_cpu']:.2f} s",
              f"{numbers[key]['overhead']:.2f} s" if key[1] == 1 else "",
              f"{runs[key]['driver_cpu'] / numbers[key]['count'] * 1000:.0f} ms",
              f"{worker_peak(runs[key]):.0f} MB", f"{numbers[key]['written_mb']:.2f} MB",
              load(runs[key]["load_before"]), load(runs[key]["load_after"]))
             for key in CONFIGS]),
        "",
        "## Memory",
        "",
        "Ray workers (peak resident memory after their last file): "
        + ", ".join(f"{mb:.0f} MB" for mb in memory.values()) +
        f". The local engine's largest process (a Blender child rigging one file): "
        f"{runs[('local', 2)]['max_rss_mb']:.0f} MB. A long-lived worker keeps the largest file it has rigged in its "
        "peak; Blender's empty file between models frees the scene.",
        "",
        "## Results agree",
        "",
        f"Bones identical between the local engine (1 job) and Ray (2 workers) on {agreement[0]} of {agreement[1]} "
        "models.",
        "",
        "![throughput per configuration, and per-file time split into the file's own time and overhead](batch.png)",
        "",
    ]
    return "\n".join(lines)


def plot(numbers, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    labels = [f"{engine}\n{jobs} {'job' if engine == 'local' else 'worker'}{'s' if jobs > 1 else ''}"
              for engine, jobs in CONFIGS]
    x = np.arange(len(CONFIGS))
    left.bar(x - 0.2, [numbers[key]["whole"] for key in CONFIGS], 0.4, label="whole run")
    left.bar(x + 0.2, [numbers[key]["steady"] for key in CONFIGS], 0.4, label="steady state")
    left.set_xticks(x, labels)
    left.set_ylabel("models per minute")
    left.set_title("Throughput")
    left.legend()
    engines = [("local", 1), ("ray", 1)]
    work = [numbers[key]["mean_work"] for key in engines]
    overhead = [max(numbers[key]["overhead"], 0.0) for key in engines]
    right.bar(range(2), work, 0.5, label="file's own time (mean)")
    right.bar(range(2), overhead, 0.5, bottom=work, label="overhead")
    right.set_xticks(range(2), ["local, 1 job", "ray, 1 worker"])
    right.set_ylabel("seconds per file")
    right.set_title("Per-file time at 1 job (active span)")
    right.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--turns", type=int, default=16, help="turned copies of each sample character (default 16)")
    parser.add_argument("--load-limit", type=float, default=1.5, help="wait for a 1-minute load below this")
    parser.add_argument("--quiet-wait", type=float, default=600, help="longest wait for that, seconds")
    parser.add_argument("--tries", type=int, default=3, help="runs of a configuration while other work loads the "
                                                             "machine during it (the least loaded one counts)")
    parser.add_argument("--output-dir", type=Path, default=RESULTS_DIR)
    args = parser.parse_args()
    import ray

    from rigger import samples

    began = time.monotonic()
    notes = []
    with tempfile.TemporaryDirectory(prefix="rigger-bench-batch-") as scratch:
        models = Path(scratch, "models")
        models.mkdir()
        subprocess.run([sys.executable, __file__, GENERATE_FLAG, str(models), str(args.turns)], check=True,
                       timeout=RUN_TIMEOUT, capture_output=True)
        sizes = [sum(line.startswith("v ") for line in open(path)) for path in models.iterdir()]
        runs = {}
        for engine, jobs in CONFIGS:
            attempts = []
            while len(attempts) < args.tries and not (attempts and quiet_run(attempts[-1], args.load_limit)):
                wait_until_quiet(args.load_limit, args.quiet_wait)
                attempts.append(run_batch(models, engine, jobs, scratch))
                print(f"{engine} --jobs {jobs}: {attempts[-1]['wall']:.1f} s, load after "
                      f"{attempts[-1]['load_after'][0]:.2f}", file=sys.stderr)
            best = runs[(engine, jobs)] = min(attempts, key=lambda run: run["load_after"][0] - run["jobs"])
            for attempt in attempts:
                if attempt is not best:
                    shutil.rmtree(attempt["out"])
            if not quiet_run(best, args.load_limit):
                notes.append(f"The {engine} {jobs}-job run shared the machine with other work in all {len(attempts)} "
                             f"tries: the best had a 1-minute load of {best['load_after'][0]:.2f} at its end, "
                             f"{best['load_after'][0] - jobs:.2f} above its own {jobs} job(s).")
            elif len(attempts) > 1:
                notes.append(f"The {engine} {jobs}-job run was repeated {len(attempts) - 1} time(s): other work "
                             f"loaded the machine during the earlier tries.")
        numbers = {key: figures(run) for key, run in runs.items()}
        agreement = bones_agree(runs[("local", 1)], runs[("ray", 2)])
    meta = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "minutes": (time.monotonic() - began) / 60, "commit": described_commit(), "ray": ray.__version__,
            "characters": list(samples.CHARACTERS),
            "vertices": f"{min(sizes):,} to {max(sizes):,} vertices, median {int(statistics.median(sizes)):,}"}
    args.output_dir.mkdir(parents=True, exist_ok=True)
    text = markdown(runs, numbers, agreement, notes, meta)
    (args.output_dir / "batch.md").write_text(text)
    plot(numbers, args.output_dir / "batch.png")
    print(text)


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == GENERATE_FLAG:
        write_models(sys.argv[2], int(sys.argv[3]))
    else:
        main()
