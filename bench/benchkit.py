"""Helpers the benchmarks share: where the checkout, the shared models and the results are, the machine and commit,
markdown tables, time formatting, mesh refinement."""
import datetime
import json
import os
import pathlib
import subprocess
import sys

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[1]
# The read-only shared data beside the checkout (RIGGER_SHARED overrides, as for the tests).
SHARED_MODELS = pathlib.Path(os.environ.get("RIGGER_SHARED", REPO.parent / "shared")) / "models"
RESULTS_DIR = REPO / "bench" / "results"  # where every benchmark writes its report and plots


def cpu_model():
    """The CPU model from /proc/cpuinfo, or "unknown CPU"."""
    try:
        with open("/proc/cpuinfo") as info:
            return next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        return "unknown CPU"


def described_commit():
    """``git describe --always --dirty`` of the checkout, or "unknown"."""
    try:
        described = subprocess.run(["git", "-C", str(REPO), "describe", "--always", "--dirty"], capture_output=True,
                                   text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        described = ""
    return described or "unknown"


def run_record(script, argv):
    """What a benchmark's report says about its run: the command (``script`` with the arguments ``argv``, None: this
    process's), the start (UTC), the load average then, the CPU and the commit."""
    arguments = " ".join(argv if argv is not None else sys.argv[1:])
    return {"command": f"python bench/{script} {arguments}".rstrip(),
            "started": datetime.datetime.now(datetime.timezone.utc), "load": os.getloadavg(), "cpu": cpu_model(),
            "commit": described_commit()}


def subset_options(parser, name):
    """Add a benchmark's ``--models`` (run on a subset, for ``picked``) and ``--out`` options (``results_folder``);
    ``name`` is the benchmark's, for its out/ folder."""
    parser.add_argument("--models", nargs="+", help="names or substrings of names (commas also separate)")
    parser.add_argument("--out", type=pathlib.Path,
                        help=f"results folder (default bench/results, or out/{name} with --models)")


def settings_option(parser):
    """Add a benchmark's ``--set KEY=VALUE`` (repeatable): parameters of Rigger's method, for ``method_params``."""
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                        help="a parameter of Rigger's method, e.g. --set bone_length=0.08 (repeatable)")


def method_params(assignments):
    """``key=value`` strings to method parameters; values are read as JSON when they parse, else kept as text.
    SystemExit for a string without a key and an ``=``."""
    params = {}
    for assignment in assignments:
        key, separator, value = assignment.partition("=")
        if not separator or not key:
            raise SystemExit(f"--set expects key=value, got {assignment!r}")
        try:
            params[key] = json.loads(value)
        except json.JSONDecodeError:
            params[key] = value
    return params


def results_folder(args, name):
    """The folder a run writes to, made: ``--out``, else out/NAME for a run on some ``--models`` (a subset must not
    overwrite the committed results), else bench/results."""
    out = args.out or (REPO / "out" / name if args.models else RESULTS_DIR)
    out.mkdir(parents=True, exist_ok=True)
    return out


def picked(items, wanted, name=lambda item: item):
    """The ``items`` whose ``name`` contains any of the texts of ``wanted`` (a ``--models`` list, commas also
    separating), all of them when ``wanted`` is empty; SystemExit when none does."""
    if not wanted:
        return list(items)
    texts = [text for item in wanted for text in item.split(",") if text]
    chosen = [item for item in items if any(text in name(item) for text in texts)]
    if not chosen:
        raise SystemExit(f"No model name contains any of {texts}.")
    return chosen


def markdown_table(header, rows, numeric=False):
    """Lines of a markdown table; ``numeric`` right-aligns every column but the first."""
    rule = "|" + "|".join("---:" if numeric and i else "---" for i in range(len(header))) + "|"
    return ["| " + " | ".join(header) + " |", rule] + ["| " + " | ".join(str(cell) for cell in row) + " |"
                                                       for row in rows]


def table_cell(text, limit=160):
    """``text`` (an error message, say) on one line, shortened, safe inside a markdown table cell."""
    return " ".join(text.split())[:limit].replace("|", "\\|")


def format_seconds(seconds):
    if seconds < 1e-3:
        return f"{seconds * 1e6:.0f} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def midpoint_subdivided(vertices, triangles):
    """Each triangle split into four at its edge midpoints, corners wound as the original's.

    Neighbouring triangles share the midpoint of their common edge, so a closed mesh stays closed; the surface is
    unchanged, so only the vertex count grows (about fourfold).
    """
    count = len(vertices)
    a, b, c = (np.asarray(triangles[:, k], dtype=np.int64) for k in range(3))
    starts, ends = np.concatenate([a, b, c]), np.concatenate([b, c, a])
    keys, edge_of_side = np.unique(np.minimum(starts, ends) * count + np.maximum(starts, ends), return_inverse=True)
    midpoints = 0.5 * (vertices[keys // count] + vertices[keys % count])
    ab, bc, ca = (count + edge_of_side).reshape(3, -1)
    quarters = [np.stack(corners, axis=1) for corners in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
    return np.concatenate([vertices, midpoints]), np.concatenate(quarters).astype(np.int32)
