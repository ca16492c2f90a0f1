"""Speed of ``rigger.silhouette.trace`` against the exact union of the projected triangles (shapely), 1e3 to 1e6.

Real models from ../shared/models are subdivided (every triangle split in four at its edge midpoints, shared
midpoints welded) into series of growing size with the same silhouette. For each mesh the public ``trace`` call is
timed (input validation and output conversion included) at the default resolution, and the exact union with
shapely (projection, polygon construction and ``union_all``) as the reference it replaces; each traced outline is
checked against that union (area IoU) so a broken run is never reported as fast. A second table shows the accuracy
and the cost against the grid resolution. Prints the tables and writes ``bench/results/silhouette.md`` and
``bench/results/silhouette.png``.

    make bench-silhouette                         # full run, up to ~1.5 million triangles
    .venv/bin/python bench/silhouette.py --quick  # series up to ~100k triangles, no shapely beyond 30k
"""
import argparse
import datetime
import os
import platform
import statistics
import sys
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import numpy as np

from benchkit import RESULTS_DIR, SHARED_MODELS, cpu_model, format_seconds, midpoint_subdivided
from rigdata import load_obj
from union_reference import exact_union, iou, traced_region

from rigger import silhouette

# (series name, model path under models/, subdivision levels to time)
SERIES = (
    ("rignet_2586 (character)", "gt/rignet_2586/rignet_2586.obj", range(1, 6)),
    ("CesiumMan (character)", "gt/CesiumMan/CesiumMan.obj", range(0, 5)),
    ("BrainStem (427 parts)", "gt/BrainStem/BrainStem.obj", range(0, 3)),
)
DIRECTION = "Y"  # the front view
MAX_QUICK_TRIANGLES = 120_000
SHAPELY_LIMIT_S = 60.0  # a series stops running shapely once one union takes longer than this
SHAPELY_QUICK_TRIANGLES = 30_000
TARGET_MILLION_S = 0.25  # issue 3: a 1M-triangle mesh in at most 0.25 s on one core,
TARGET_SPEEDUP = 20.0  # at least 20x faster than the shapely union, with cost growing linearly
ACCURACY_MODELS = ("gt/CesiumMan/CesiumMan.obj", "gt/Quaternius_Fox/Quaternius_Fox.obj", "nogt/homer.obj")
ACCURACY_RESOLUTIONS = (128, 256, 512, 1024, 2048)


def runs_for(triangles):
    if triangles < 10_000:
        return 21
    if triangles < 200_000:
        return 9
    return 5


# ---------------------------------------------------------------- meshes


def series_meshes(path, levels, max_triangles):
    vertices, triangles = load_obj(path)
    for level in range(max(levels) + 1):
        if level in levels and len(triangles) <= max_triangles:
            yield vertices, triangles
        vertices, triangles = midpoint_subdivided(vertices, triangles)


# ---------------------------------------------------------------- timing


@dataclass
class Timing:
    seconds: float  # median wall clock
    cpu: float  # median CPU time of this process
    runs: int


def timed(call, runs):
    """Median wall and CPU time of `runs` calls (after one untimed call when calls are short), and the last result."""
    walls, cpus, result = [], [], None
    if runs > 1:
        result = call()
    for _ in range(runs):
        wall, cpu = time.perf_counter(), time.process_time()
        result = call()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return Timing(statistics.median(walls), statistics.median(cpus), runs), result


@dataclass
class Row:
    series: str
    triangles: int
    ours: Timing
    loops: int
    points: int
    shapely: Timing | None
    iou: float | None


def run_series(quick):
    rows = []
    for name, relative, levels in SERIES:
        path = SHARED_MODELS / relative
        shapely_on = True
        for vertices, triangles in series_meshes(path, set(levels), MAX_QUICK_TRIANGLES if quick else 2_000_000):
            n = len(triangles)
            ours, sil = timed(lambda: silhouette.trace(vertices, triangles, DIRECTION), runs_for(n))
            reference, score = None, None
            if shapely_on and (not quick or n <= SHAPELY_QUICK_TRIANGLES):
                reference, union = timed(lambda: exact_union(sil, vertices, triangles), 3 if n < 20_000 else 1)
                score = iou(traced_region(sil.loops), union)
                shapely_on = reference.seconds <= SHAPELY_LIMIT_S
            rows.append(Row(name, n, ours, len(sil.loops), sum(map(len, sil.loops)), reference, score))
            print(f"  {name:26} {n:>10,} triangles  trace {format_seconds(ours.seconds):>9} "
                  f"(CPU {format_seconds(ours.cpu)})  shapely "
                  f"{format_seconds(reference.seconds) if reference else '—':>9}  "
                  f"IoU {f'{score:.5f}' if score is not None else '—'}", flush=True)
    return rows


@dataclass
class Accuracy:
    resolution: int
    worst_iou: float
    mean_iou: float
    points: float
    seconds: float


def run_accuracy():
    """IoU against the exact union, outline points and trace time against resolution, front and side views."""
    cases = []
    for relative in ACCURACY_MODELS:
        vertices, triangles = load_obj(SHARED_MODELS / relative)
        for direction in ("Y", "X"):
            sil = silhouette.trace(vertices, triangles, direction)
            cases.append((vertices, triangles, direction, exact_union(sil, vertices, triangles)))
    out = []
    for resolution in ACCURACY_RESOLUTIONS:
        scores, points, times = [], [], []
        for vertices, triangles, direction, union in cases:
            timing, sil = timed(lambda: silhouette.trace(vertices, triangles, direction, resolution=resolution), 5)
            scores.append(iou(traced_region(sil.loops), union))
            points.append(sum(map(len, sil.loops)))
            times.append(timing.seconds)
        out.append(Accuracy(resolution, min(scores), statistics.mean(scores), statistics.mean(points),
                            statistics.mean(times)))
        print(f"  resolution {resolution:5}: worst IoU {min(scores):.5f}, mean points {statistics.mean(points):.0f}")
    return out


# ---------------------------------------------------------------- reporting


def growth(rows):
    """Per series, the slope of log time over log triangles between its smallest and largest mesh (1 = linear)."""
    slopes = {}
    for name in dict.fromkeys(r.series for r in rows):
        own = [r for r in rows if r.series == name and r.triangles >= 10_000]
        if len(own) >= 2:
            slopes[name] = (np.log(own[-1].ours.cpu / own[0].ours.cpu) /
                            np.log(own[-1].triangles / own[0].triangles))
    return slopes


def verdicts(rows):
    """The issue's targets on the meshes of about a million triangles (budget scaled linearly above 1M), the growth
    of the cost, and for information the lowest speed-up at any size."""
    lines = []
    for r in (r for r in rows if 500_000 <= r.triangles <= 2_000_000):
        budget = TARGET_MILLION_S * max(1.0, r.triangles / 1e6)
        verdict = "PASS" if max(r.ours.seconds, r.ours.cpu) <= budget else "FAIL"
        lines.append(f"{r.series}, {r.triangles:,} triangles within {format_seconds(budget)}: {verdict} "
                     f"{format_seconds(r.ours.seconds)} (CPU {format_seconds(r.ours.cpu)})")
        if r.shapely is not None:
            speedup = r.shapely.seconds / r.ours.seconds
            lines.append(f"{r.series}, {r.triangles:,} triangles at least {TARGET_SPEEDUP:.0f}× faster than the "
                         f"shapely union: {'PASS' if speedup >= TARGET_SPEEDUP else 'FAIL'} {speedup:.0f}×")
    for name, slope in growth(rows).items():
        lines.append(f"{name}, from 10k triangles up: time ∝ N^{slope:.2f} "
                     f"({'PASS' if slope <= 1.1 else 'FAIL'}: linear or better)")
    compared = [r for r in rows if r.shapely is not None]
    if compared:
        slowest = min(compared, key=lambda r: r.shapely.seconds / r.ours.seconds)
        lowest = slowest.shapely.seconds / slowest.ours.seconds
        lines.append(f"for information, the lowest speed-up at any size: {lowest:.0f}× ({slowest.series}, "
                     f"{slowest.triangles:,} triangles: large triangles cross many grid lines, a cost that does not "
                     "shrink with the triangle count)")
        lines.append(f"outline IoU against the exact union, every mesh: worst {min(r.iou for r in compared):.5f}")
    return lines


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(7.5, 5))
    for colour, name in zip(("C0", "C1", "C2"), dict.fromkeys(r.series for r in rows)):
        own = [r for r in rows if r.series == name]
        axes.loglog([r.triangles for r in own], [r.ours.seconds for r in own], "o-", color=colour,
                    label=f"rigger trace — {name}")
        ref = [r for r in own if r.shapely is not None]
        axes.loglog([r.triangles for r in ref], [r.shapely.seconds for r in ref], "s--", color=colour, alpha=0.6,
                    label=f"shapely union — {name}")
    axes.axhline(TARGET_MILLION_S, color="grey", lw=0.8, ls=":")
    axes.axvline(1e6, color="grey", lw=0.8, ls=":")
    axes.set_xlabel("triangles")
    axes.set_ylabel("seconds per call (median)")
    axes.set_title("Silhouette of a subdivided mesh, front view, default resolution")
    axes.grid(True, which="both", lw=0.3)
    axes.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def machine():
    return f"{cpu_model()}, {os.cpu_count()} cores, {platform.machine()}"


def markdown(rows, accuracy, command, started, loads):
    out = [
        "# Silhouette benchmark",
        "",
        f"Generated by `{command}` on {started:%Y-%m-%d %H:%M} UTC.",
        "",
        f"- Machine: {machine()}, shared with other jobs (load average {loads[0]:.2f} before, {loads[1]:.2f} "
        "after); everything runs on one core.",
        f"- Python {platform.python_version()}, numpy {np.__version__}, shapely {metadata.version('shapely')}; "
        f"rigger {metadata.version('rigger')}.",
        f"- Meshes: real models subdivided 1 → 4 per level (same silhouette, more triangles), viewed along "
        f"{DIRECTION}. `trace` runs at the default resolution ({silhouette.DEFAULT_RESOLUTION} cells on the longest "
        f"side) and tolerance ({silhouette.DEFAULT_TOLERANCE} cell), input checks and output conversion included; "
        "the reference is shapely's exact union of the projected triangles (polygon construction included).",
        "- Times are medians of the runs in brackets, wall clock and CPU time of this process (CPU time is what "
        "other jobs on the shared cores cannot inflate). Each outline is checked against the exact union (IoU).",
        "",
        "## Time against mesh size",
        "",
        "| series | triangles | trace | trace CPU | µs per 1k triangles | loops | points | shapely union | speed-up "
        "| IoU |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        ref = f"{format_seconds(r.shapely.seconds)} [{r.shapely.runs}]" if r.shapely else "—"
        speed = f"{r.shapely.seconds / r.ours.seconds:.0f}×" if r.shapely else "—"
        out.append(f"| {r.series} | {r.triangles:,} | {format_seconds(r.ours.seconds)} [{r.ours.runs}] | "
                   f"{format_seconds(r.ours.cpu)} | {r.ours.cpu / r.triangles * 1e9:.0f} | {r.loops} | {r.points:,} | "
                   f"{ref} | {speed} | {f'{r.iou:.5f}' if r.iou is not None else '—'} |")
    out += ["", "## Targets (issue 3)", ""] + [f"- {line}" for line in verdicts(rows)]
    out += [
        "",
        "## Accuracy against resolution",
        "",
        f"{', '.join(Path(m).stem for m in ACCURACY_MODELS)}, front (Y) and side (X) views, default tolerance: "
        "area IoU against the exact union, outline points, mean trace time.",
        "",
        "| resolution | worst IoU | mean IoU | mean points | mean trace time |",
        "|---:|---:|---:|---:|---:|",
    ]
    for a in accuracy:
        out.append(f"| {a.resolution} | {a.worst_iou:.5f} | {a.mean_iou:.5f} | {a.points:.0f} | "
                   f"{format_seconds(a.seconds)} |")
    out += ["", "![trace and shapely union time against triangles, log-log](silhouette.png)", ""]
    return "\n".join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="smaller meshes, shapely only up to 30k triangles")
    args = parser.parse_args(argv)
    missing = [relative for _, relative, _ in SERIES if not (SHARED_MODELS / relative).exists()]
    if missing:
        print(f"bench/silhouette.py: models not found under {SHARED_MODELS} ({', '.join(missing)}); the shared "
              "data must sit beside the repository. Nothing measured.", file=sys.stderr)
        return 2
    started = datetime.datetime.now(datetime.timezone.utc)
    load_before = os.getloadavg()[0]
    print("time against mesh size:")
    rows = run_series(args.quick)
    print("accuracy against resolution:")
    accuracy = run_accuracy()
    loads = (load_before, os.getloadavg()[0])
    for line in verdicts(rows):
        print(line)
    if args.quick:
        print("quick run: results not written")
        return 0
    RESULTS_DIR.mkdir(exist_ok=True)
    command = "python bench/silhouette.py"
    (RESULTS_DIR / "silhouette.md").write_text(markdown(rows, accuracy, command, started, loads))
    plot(rows, RESULTS_DIR / "silhouette.png")
    print(f"wrote {RESULTS_DIR / 'silhouette.md'} and {RESULTS_DIR / 'silhouette.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
