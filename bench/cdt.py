"""Speed of ``rigger.cdt.triangulate`` against Triangle, Blender's mathutils CDT and scipy's Delaunay.

Three inputs at each N: uniform random points (plain Delaunay of the convex hull), a smooth closed outline and a
saw-tooth star outline (long thin spikes, the stress case), the outlines triangulated inside only. Every library is
timed in this one process on the same arrays, input conversion included, and its first result per cell is checked
for a plausible triangle count and total area so a broken run is never reported as fast. Prints a table and writes
``bench/results/cdt.md`` and ``bench/results/cdt.png``.

    make bench                                   # full run, N = 1e3 .. 1e6
    .venv/bin/python bench/cdt.py --quick        # stop at N = 1e5
    .venv/bin/python bench/cdt.py --sizes 1e3,1e4
"""
import argparse
import datetime
import gc
import os
import math
import platform
import random
import statistics
import sys
import time
from dataclasses import dataclass, field
from importlib import metadata

import numpy as np

from benchkit import RESULTS_DIR, cpu_model, format_seconds

FULL_SIZES = (1_000, 10_000, 100_000, 1_000_000)
QUICK_SIZES = FULL_SIZES[:3]
CASES = ("random", "smooth", "saw")
CASE_TITLES = {
    "random": "uniform random points",
    "smooth": "smooth outline r = 1 + 0.3 sin 5θ",
    "saw": "saw-tooth star, radii 1 / 0.05",
}
# Targets from issue 2: rigger's time over Triangle's, per case, at every N.
RATIO_TARGETS = {"random": 1.0, "smooth": 1.0, "saw": 1.5}
SMALL_OUTLINE_N = 1_000
SMALL_OUTLINE_TARGET_S = 1e-3
SMALL_OUTLINE_RUNS = 300
CELL_BUDGET_S = 15.0  # stop repeating a cell once its runs add up to this (always at least one run)
PASSES = 5  # each library's runs of one cell are split over this many passes in shuffled library order
SLOW_CALL_S = 20.0  # a library slower than this at some N is not run at larger N of that case (>= 10x longer)
WARM_CALL_LIMIT_S = 0.05  # a pass of calls shorter than this starts with an untimed call
SEED = 20250106


def runs_for(n):
    """Many runs where a call is short, few where it is long, to keep the whole bench near ten minutes."""
    if n <= 1_000:
        return 101
    if n <= 10_000:
        return 21
    if n <= 100_000:
        return 11
    return 5


# ---------------------------------------------------------------- inputs


@dataclass(frozen=True)
class Workload:
    """One input: points, optional closed-outline segments, and what a correct triangulation of it must give."""

    case: str
    points: np.ndarray
    segments: np.ndarray | None
    expected_triangles: int
    expected_area: float


def make_workload(case, n):
    if case == "random":
        return _random_points(n)
    theta = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    if case == "smooth":
        radius = 1.0 + 0.3 * np.sin(5.0 * theta)
    else:
        radius = np.where(np.arange(n) % 2 == 0, 1.0, 0.05)
    points = np.column_stack([radius * np.cos(theta), radius * np.sin(theta)])
    index = np.arange(n, dtype=np.int32)
    segments = np.column_stack([index, np.roll(index, -1)])
    x, y = points[:, 0], points[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    return Workload(case, points, segments, n - 2, float(area))


def _random_points(n):
    from scipy.spatial import ConvexHull

    points = np.random.default_rng(SEED + n).random((n, 2))
    hull = ConvexHull(points)
    return Workload("random", points, None, 2 * n - len(hull.vertices) - 2, float(hull.volume))


# ---------------------------------------------------------------- libraries


@dataclass
class Library:
    """A triangulator: ``run`` is the timed call, ``mesh`` turns its result into (vertices, triangles) arrays."""

    name: str
    version: str
    run: object = None  # (Workload) -> native result; None when the library could not be imported
    mesh: object = None  # (native result) -> (vertices (K, 2), triangles (T, 3))
    constraints: bool = True
    missing: str = ""


def load_libraries():
    return [_rigger(), _triangle(), _mathutils(), _scipy()]


def _rigger():
    try:
        from rigger import cdt
    except ImportError as exc:
        return Library("rigger", "not built", missing=f"rigger.cdt unavailable ({exc}); run `make build`")

    def run(work):
        mode = "all" if work.segments is None else "inside"
        return cdt.triangulate(work.points, work.segments, mode=mode)

    return Library("rigger", _version("rigger"), run, lambda tri: (tri.vertices, tri.triangles))


def _triangle():
    import triangle

    def run(work):
        if work.segments is None:
            return triangle.triangulate({"vertices": work.points}, "Q")
        return triangle.triangulate({"vertices": work.points, "segments": work.segments}, "pQ")

    return Library("triangle", _version("triangle"), run, lambda out: (out["vertices"], out["triangles"]))


def _mathutils():
    import bpy  # first: importing bpy is what makes the mathutils module available
    from mathutils import geometry

    epsilon = 1e-9  # merge distance; coordinates are O(1) and Blender rounds them to float32 (spacing ~6e-8)
    empty = np.zeros((0, 2), np.int32)

    def run(work):
        # output_type 0 keeps the whole convex hull, 1 only the triangles inside the constraint edges. need_ids is
        # left at its default: in bpy 5.0.1, passing it explicitly makes the call ignore output_type.
        edges = empty if work.segments is None else work.segments
        return geometry.delaunay_2d_cdt(work.points, edges, [], 0 if work.segments is None else 1, epsilon)

    def mesh(out):
        return np.array([tuple(v) for v in out[0]], np.float64).reshape(-1, 2), np.array(out[2], np.int64)

    return Library("mathutils", bpy.app.version_string, run, mesh)


def _scipy():
    import scipy
    from scipy.spatial import Delaunay

    return Library("scipy", scipy.__version__, lambda work: Delaunay(work.points),
                   lambda tri: (tri.points, tri.simplices), constraints=False)


def _version(dist):
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "unknown"


# ---------------------------------------------------------------- timing and checking


@dataclass(frozen=True)
class Timing:
    wall: float
    cpu: float


@dataclass
class Cell:
    """One library on one workload: median seconds over ``runs`` calls, or why there is no time."""

    seconds: float | None = None
    fastest: float | None = None
    cpu_seconds: float | None = None
    runs: int = 0
    note: str = ""


@dataclass
class Results:
    sizes: tuple
    libraries: list
    cells: dict = field(default_factory=dict)  # (case, n, library name) -> Cell
    small_outline: dict = field(default_factory=dict)  # library name -> Cell

    def cell(self, case, n, name):
        return self.cells.get((case, n, name))

    def ratio(self, case, n, name, clock="seconds"):
        """Median time of ``name`` over Triangle's, by wall clock or (clock="cpu_seconds") by CPU time."""
        mine, ref = self.cell(case, n, name), self.cell(case, n, "triangle")
        if mine is None or ref is None or mine.seconds is None or ref.seconds is None:
            return None
        return getattr(mine, clock) / getattr(ref, clock)


def timed(call):
    """Wall-clock and CPU seconds of one call, and its result; the garbage collector waits (as in timeit).

    All four libraries compute on one thread, so CPU time is the part of the wall-clock time that another
    process on this shared machine cannot inflate by taking the core away.
    """
    gc.disable()
    try:
        wall, cpu = time.perf_counter(), time.process_time()
        result = call()
        return Timing(time.perf_counter() - wall, time.process_time() - cpu), result
    finally:
        gc.enable()


def check(lib, work, result):
    """Why ``result`` is not a plausible triangulation of ``work``, or "" when it is."""
    vertices, triangles = lib.mesh(result)
    vertices = np.asarray(vertices, np.float64)
    triangles = np.asarray(triangles, np.int64).reshape(-1, 3)
    count = len(triangles)
    # Blender rounds to float32, which may merge a few nearly coincident points or hull vertices; allow a sliver.
    if abs(count - work.expected_triangles) > 2 + 1e-4 * work.expected_triangles:
        return f"{count} triangles, expected {work.expected_triangles}"
    if count and (triangles.min() < 0 or triangles.max() >= len(vertices)):
        return "triangle indices out of range"
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    area = 0.5 * np.abs(np.cross(b - a, c - a)).sum()
    if abs(area - work.expected_area) > 1e-4 * work.expected_area:
        return f"covers area {area:.6g}, expected {work.expected_area:.6g}"
    return ""


def measure(libraries, work, runs):
    """Time every library on ``work``: {name: Cell}.

    Each library's first call is checked as well as timed. The further calls come in a few passes; in each pass
    every library, in a shuffled order, makes its share of consecutive calls. Consecutive calls measure the steady
    state, as timeit does: a call right after another library's pays for the caches and memory that one left
    behind (measured: several percent at N = 1,000), so it is preceded by an untimed call where calls are short.
    The passes spread a change in the machine's load (it is shared) over all libraries alike.
    """
    gc.collect()
    cells, times = {}, {}
    for lib in libraries:
        if lib.run is None:
            cells[lib.name] = Cell(note="not built")
        elif work.segments is not None and not lib.constraints:
            cells[lib.name] = Cell(note="n/a")
        else:
            timing, result = timed(lambda: lib.run(work))
            problem = check(lib, work, result)
            del result
            cells[lib.name] = Cell(note=f"BAD: {problem}" if problem else "")
            if not problem:
                times[lib.name] = [timing]
    by_name = {lib.name: lib for lib in libraries}
    order = random.Random(SEED)
    names = list(times)
    for pass_number in range(1, PASSES + 1):
        order.shuffle(names)
        for name in names:
            done, run = times[name], by_name[name].run
            due = math.ceil(runs * pass_number / PASSES)
            if len(done) < due and done[0].wall < WARM_CALL_LIMIT_S:
                run(work)
            while len(done) < due and sum(t.wall for t in done) < CELL_BUDGET_S:
                done.append(timed(lambda: run(work))[0])
    for name, done in times.items():
        walls = [t.wall for t in done]
        cell = cells[name]
        cell.seconds, cell.fastest, cell.runs = statistics.median(walls), min(walls), len(done)
        cell.cpu_seconds = statistics.median(t.cpu for t in done)
    return cells


def warm_up(libraries):
    """One small call of each library on each case, so lazy imports and first-call setup are not timed."""
    for case in CASES:
        work = make_workload(case, 200)
        for lib in libraries:
            if lib.run is not None and (work.segments is None or lib.constraints):
                lib.run(work)


def time_small_outline(libraries):
    """Time on a 1,000-vertex smooth outline over many runs (the issue's < 1 ms target): {name: Cell}."""
    return measure(libraries, make_workload("smooth", SMALL_OUTLINE_N), SMALL_OUTLINE_RUNS)


def run_all(sizes, libraries):
    results = Results(tuple(sizes), libraries)
    warm_up(libraries)
    too_slow = {}  # (case, library name) -> why it is not run at larger N
    for n in sizes:
        for case in CASES:
            running = [lib for lib in libraries if (case, lib.name) not in too_slow]
            cells = measure(running, make_workload(case, n), runs_for(n))
            for lib in libraries:
                cell = cells.get(lib.name) or Cell(note=too_slow[(case, lib.name)])
                results.cells[(case, n, lib.name)] = cell
                if cell.seconds is not None and cell.seconds > SLOW_CALL_S:
                    too_slow[(case, lib.name)] = f"skipped: {format_seconds(cell.seconds)} at N = {n:,}"
                print(f"  {case:6} N={n:>9,} {lib.name:9} {format_cell(results, case, n, lib.name)}", flush=True)
    results.small_outline = time_small_outline(libraries)
    return results


# ---------------------------------------------------------------- reporting


def format_cell(results, case, n, name, with_runs=False):
    cell = results.cell(case, n, name)
    if cell.seconds is None:
        return cell.note
    text = format_seconds(cell.seconds)
    ratio = results.ratio(case, n, name)
    if name != "triangle" and ratio is not None:
        text += f" ({ratio:.2f}×)"
    if with_runs:
        text += f" [{cell.runs}]"
    return text


def text_table(results):
    names = [lib.name for lib in results.libraries]
    header = f"{'case':7} {'N':>10}  " + "  ".join(f"{name:22}" for name in names)
    lines = [header, "-" * len(header)]
    for case in CASES:
        for n in results.sizes:
            cells = "  ".join(f"{format_cell(results, case, n, name)[:22]:22}" for name in names)
            lines.append(f"{case:7} {n:>10,}  {cells}")
    return "\n".join(lines)


def target_verdicts(results):
    """Rows of (target description, [verdict per N]) for the issue's speed targets, met by both clocks."""
    rows = []
    for case, limit in RATIO_TARGETS.items():
        verdicts = []
        for n in results.sizes:
            ratio = results.ratio(case, n, "rigger")
            note = results.cell(case, n, "rigger").note
            if note.startswith("BAD"):
                verdicts.append("FAIL (bad output)")
            elif note.startswith("skipped"):
                verdicts.append(f"FAIL ({note})")
            elif ratio is None:
                verdicts.append("—")
            else:
                cpu_ratio = results.ratio(case, n, "rigger", "cpu_seconds")
                verdict = "PASS" if max(ratio, cpu_ratio) <= limit else "FAIL"
                verdicts.append(f"{verdict} {ratio:.2f}× (CPU {cpu_ratio:.2f}×)")
        rows.append((f"{CASE_TITLES[case]}: rigger ≤ {limit:.1f}× Triangle", verdicts))
    return rows


def small_outline_verdict(results):
    cell = results.small_outline.get("rigger")
    if cell is None or cell.seconds is None:
        return f"— (rigger {cell.note if cell else 'not measured'})"
    verdict = "PASS" if max(cell.seconds, cell.cpu_seconds) < SMALL_OUTLINE_TARGET_S else "FAIL"
    text = (f"{verdict} {format_seconds(cell.seconds)} (CPU {format_seconds(cell.cpu_seconds)}; median of {cell.runs}, "
            f"fastest {format_seconds(cell.fastest)}")
    triangle = results.small_outline.get("triangle")
    if triangle is not None and triangle.seconds is not None:
        text += f"; Triangle {format_seconds(triangle.seconds)}, fastest {format_seconds(triangle.fastest)}"
    return text + ")"


def throughput(results):
    """Points per second on the largest random input, the unit the issue quotes for Triangle and CGAL."""
    n = results.sizes[-1]
    rates = [f"{lib.name} {n / cell.seconds / 1e6:.2f}" for lib in results.libraries
             if (cell := results.cell("random", n, lib.name)).seconds is not None]
    return f"Million points per second on {n:,} random points: " + ", ".join(rates) + "."


def machine_notes():
    return cpu_model(), os.cpu_count()


def markdown(results, command, started, load_before, load_after):
    model, cores = machine_notes()
    versions = ", ".join(f"{lib.name} {lib.version}" for lib in results.libraries)
    names = [lib.name for lib in results.libraries]
    size_cols = " | ".join(f"N = {n:,}" for n in results.sizes)
    out = [
        "# CDT benchmark",
        "",
        f"Generated by `{command}` on {started:%Y-%m-%d %H:%M} UTC.",
        "",
        f"- Machine: {model}, {cores} cores, shared with other jobs (load average {load_before:.2f} before, "
        f"{load_after:.2f} after).",
        f"- Python {platform.python_version()}, numpy {np.__version__}; {versions} "
        "(mathutils is the one from the bpy wheel).",
        "- Each cell is the median wall-clock time of one call, input conversion included, over the number of "
        "runs in brackets (fewer for slow calls); the ratio in parentheses is the time over Triangle's. Results "
        "are taken in each library's own output form (numpy arrays; Python lists for mathutils). The runs of a "
        "cell come in passes, the libraries in shuffled order, each pass a block of consecutive calls per library. "
        f"A library slower than {SLOW_CALL_S:.0f} s per call is not run at larger N of that case.",
        "- Targets show the ratio of wall-clock medians and, beside it, of CPU-time medians (every library here "
        "runs on one thread, so CPU time is what other processes on the shared cores cannot inflate); a cell "
        "passes only when both ratios meet the target.",
        "- Calls: rigger `triangulate(points, segments, mode='all' | 'inside')`; Triangle `triangulate(..., 'Q')` for "
        "points and `'pQ'` for outlines; mathutils `delaunay_2d_cdt(points, edges, [], output_type, 1e-9)` with "
        "output_type 0 (convex hull) for points and 1 (inside the constraints) for outlines, in float32; scipy "
        "`Delaunay(points)` (no constraints, so n/a on outlines).",
        "- Every library's first result in each cell is checked: triangle count (2N − h − 2 for random points with "
        "h hull vertices, N − 2 for an outline) and the total area its triangles cover (hull or polygon area). A "
        "result that fails shows as BAD and gets no time.",
        "",
        "## Times",
        "",
        "| case | N | " + " | ".join(names) + " |",
        "|---|---:|" + "---:|" * len(names),
    ]
    for case in CASES:
        for n in results.sizes:
            cells = " | ".join(format_cell(results, case, n, name, with_runs=True) for name in names)
            out.append(f"| {CASE_TITLES[case]} | {n:,} | {cells} |")
    out += [
        "",
        "## Targets (issue 2)",
        "",
        f"| target | {size_cols} |",
        "|---|" + "---|" * len(results.sizes),
    ]
    for title, verdicts in target_verdicts(results):
        out.append(f"| {title} | " + " | ".join(verdicts) + " |")
    out += [
        "",
        f"- 1,000-vertex smooth outline under 1 ms (rigger): {small_outline_verdict(results)}.",
        f"- {throughput(results)}",
        "",
        "![time against N, log-log, one panel per case](cdt.png)",
        "",
    ]
    missing = [lib.missing for lib in results.libraries if lib.missing]
    if missing:
        out += ["Not measured: " + "; ".join(missing) + ".", ""]
    return "\n".join(out)


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(CASES), figsize=(5 * len(CASES), 4.2), sharey=True)
    for ax, case in zip(axes, CASES):
        for lib in results.libraries:
            points = [(n, results.cell(case, n, lib.name).seconds) for n in results.sizes]
            points = [(n, s) for n, s in points if s is not None]
            if points:
                ax.plot(*zip(*points), marker="o", label=lib.name)
        if case == "smooth":
            ax.axhline(SMALL_OUTLINE_TARGET_S, color="grey", linestyle=":", linewidth=1)
            ax.annotate("1 ms target at N = 1,000", (results.sizes[-1], SMALL_OUTLINE_TARGET_S), fontsize=8,
                        color="grey", xytext=(0, -10), textcoords="offset points", ha="right")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(CASE_TITLES[case], fontsize=10)
        ax.set_xlabel("N (points or outline vertices)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("median seconds per call")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- command line


def parse_sizes(text):
    try:
        sizes = sorted({int(float(part)) for part in text.split(",") if part.strip()})
    except ValueError:
        raise argparse.ArgumentTypeError(f"--sizes wants numbers like 1e3,1e4, got {text!r}") from None
    if not sizes or sizes[0] < 10:
        raise argparse.ArgumentTypeError("--sizes must be at least 10")
    return sizes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="stop at N = 1e5")
    parser.add_argument("--sizes", type=parse_sizes, help="comma-separated N values, e.g. 1e3,1e4 (overrides --quick)")
    args = parser.parse_args(argv)
    sizes = args.sizes or (QUICK_SIZES if args.quick else FULL_SIZES)

    libraries = load_libraries()
    for lib in libraries:
        if lib.missing:
            print(f"note: {lib.missing}", file=sys.stderr)
    started = datetime.datetime.now(datetime.timezone.utc)
    load_before = os.getloadavg()[0]
    results = run_all(sizes, libraries)
    load_after = os.getloadavg()[0]

    print()
    print(text_table(results))
    for title, verdicts in target_verdicts(results):
        print(f"{title}: " + ", ".join(verdicts))
    print(f"1,000-vertex smooth outline < 1 ms: {small_outline_verdict(results)}")

    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    command = "python bench/cdt.py " + " ".join(sys.argv[1:] if argv is None else argv)
    (RESULTS_DIR / "cdt.md").write_text(markdown(results, command.strip(), started, load_before, load_after))
    plot(results, RESULTS_DIR / "cdt.png")
    print(f"wrote {RESULTS_DIR / 'cdt.md'} and {RESULTS_DIR / 'cdt.png'}; took "
          f"{(datetime.datetime.now(datetime.timezone.utc) - started).total_seconds():.0f} s")
    broken = [key for key, cell in results.cells.items() if cell.note.startswith("BAD")]
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
