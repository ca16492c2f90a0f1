"""Quality benchmark: skeletons from each method scored against the artist rigs in ../shared/models/gt.

Runs the single-stick and skeletor baselines and Rigger's own method, scores them in the RigNet convention
(bench/rigdata.py) and writes bench/results/quality.md, quality.json and PNG plots.
Rigger's method is then run again with each of ``DETAIL_SETTINGS`` (the parameters that set how many bones it
makes) to show how the joint counts move against the artists'.

    .venv/bin/python bench/quality.py [--models SUBSTR,...] [--methods stick,skeletor,rigger] [--set key=value ...]
"""
import argparse
import datetime
import functools
import json
import os
import pathlib
import platform
import signal
import sys
import time
import traceback

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import rigdata  # noqa: E402  (bench/ is not a package)
import rigger  # noqa: E402
from benchkit import (RESULTS_DIR, SHARED_MODELS, cpu_model, markdown_table, method_params,  # noqa: E402
                      settings_option, table_cell)

MODELS_DIR = SHARED_MODELS / "gt"
DRAWN_MODELS = ("CesiumMan", "Quaternius_Fox", "rignet_2982")
REFERENCE_CD_J2J = {"stick": 0.147, "skeletor": 0.076}
TARGETS = {"mean_cd_j2j": 0.045, "stretch_cd_j2j": 0.040, "mean_cd_b2b": 0.028, "max_cd_j2j": 0.08,
           "joint_ratio": (0.7, 1.5), "mean_inside": 0.95}
METHOD_COLOURS = {"rigger": "tab:red", "skeletor": "tab:green", "stick": "tab:blue"}
DETAIL_SETTINGS = ({}, {"min_branch": 1.0}, {"min_branch": 1.5}, {"max_chain_bones": 4}, {"bone_length": 0.13},
                   {"prune": 1.0})  # Rigger's parameters that set how many bones it makes, changed one at a time
MUCH_LONGER = 1.5  # Rigger's bones this many times as long in total as the artist's: more of the mesh has bones


def principal_stick(vertices, triangles):
    """Baseline: one straight stick along the vertices' main principal axis through their centroid, spanning their
    extent, jointed at its middle as a rig's root would be (two collinear bones, three joints)."""
    centroid = vertices.mean(axis=0)
    centred = vertices - centroid
    axis = np.linalg.eigh(centred.T @ centred)[1][:, -1]
    along = centred @ axis
    start, end = centroid + along.min() * axis, centroid + along.max() * axis
    middle = (start + end) / 2
    return rigdata.Bones([start, middle], [middle, end], [-1, 0]), {}


def skeletor_wavefront(vertices, triangles):
    """Baseline: skeletor's wavefront skeleton with one bone per branch (between branch points and ends).

    Coincident vertices are merged first (trimesh's ``process``): exported meshes split them along UV seams, and
    skeletor would otherwise see every face as a separate fragment and drop it as debris.
    """
    import skeletor
    import trimesh

    mesh = skeletor.pre.fix_mesh(trimesh.Trimesh(vertices, triangles, process=True), remove_disconnected=5)
    swc = skeletor.skeletonize.by_wavefront(mesh, waves=1, step_size=1, progress=False).swc
    row_of_node = {int(node): row for row, node in enumerate(swc["node_id"])}
    parent_rows = np.array([row_of_node.get(int(parent), -1) for parent in swc["parent_id"]])
    child_counts = np.bincount(parent_rows[parent_rows >= 0], minlength=len(parent_rows))
    branch_nodes = (parent_rows < 0) | (child_counts != 1)
    positions = swc[["x", "y", "z"]].to_numpy(np.float64)[branch_nodes]
    return bones_from_forest(rigdata.kept_ancestors(parent_rows, branch_nodes), positions), {}


def bones_from_forest(parent_nodes, positions):
    """One bone per parent→child edge of a node forest, joined into a single tree.

    Bones leaving a root node become children of that component's first root bone; every other component's root
    bone is parented (without new geometry) to the nearest bone of the component with the most bones.
    """
    children = np.flatnonzero(parent_nodes >= 0)
    if len(children) == 0:
        raise ValueError("the skeleton has no edges")
    bone_of_node = np.full(len(parent_nodes), -1)
    bone_of_node[children] = np.arange(len(children))
    parents = bone_of_node[parent_nodes[children]]
    root_node = np.where(parent_nodes >= 0, parent_nodes, np.arange(len(parent_nodes)))
    for _ in range(len(parent_nodes).bit_length() + 1):
        root_node = root_node[root_node]
    component = root_node[parent_nodes[children]]
    heads, tails = positions[parent_nodes[children]], positions[children]

    first_root_bone = {}
    for bone in np.flatnonzero(parents < 0):
        first_root_bone.setdefault(component[bone], bone)
    for bone in np.flatnonzero(parents < 0):
        if first_root_bone[component[bone]] != bone:
            parents[bone] = first_root_bone[component[bone]]
    main = np.bincount(component).argmax()
    main_bones = np.flatnonzero(component == main)
    for root_bone in first_root_bone.values():
        if component[root_bone] != main:
            parents[root_bone] = main_bones[np.argmin(segment_distances(heads[root_bone], heads[main_bones],
                                                                        tails[main_bones]))]
    return rigdata.Bones(heads, tails, parents)


def segment_distances(point, starts, ends):
    """Distance from one point to each segment starts[i]–ends[i]."""
    direction = ends - starts
    length_squared = np.maximum((direction * direction).sum(axis=1), 1e-300)
    t = np.clip(((point - starts) * direction).sum(axis=1) / length_squared, 0.0, 1.0)
    return np.linalg.norm(starts + t[:, None] * direction - point, axis=1)


def rigger_silhouette(vertices, triangles, **params):
    """Rigger's own method; its per-step timings come from ``Skeleton.timings``."""
    skeleton = rigger.rig_mesh(vertices, triangles.astype(np.int32), method="silhouette", **params)
    return rigdata.Bones.of(skeleton), dict(skeleton.timings)


METHODS = {"stick": principal_stick, "skeletor": skeletor_wavefront, "rigger": rigger_silhouette}


class Timeout(Exception):
    """A method ran past its time limit on one model."""


def run_limited(function, seconds, *args, **kwargs):
    """Call ``function``, raising Timeout after ``seconds`` of wall time (checked whenever Python code runs)."""
    def expire(signum, frame):
        raise Timeout(f"no result after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return function(*args, **kwargs)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


class GroundTruth:
    """One model's mesh and artist rig, both in the normalised frame, with the rig's joints, bone samples and total
    bone length."""

    def __init__(self, folder):
        self.name = folder.name
        self.vertices, self.triangles, self.rig = rigdata.load_ground_truth(folder)
        self.normalisation = rigdata.Normalisation.of_mesh(self.vertices)
        self.unit_vertices = self.normalisation.points(self.vertices)
        self.bones = self.rig.bones().mapped(self.normalisation)
        if len(self.bones) == 0:
            raise ValueError("the rig has no bones")
        self.joints = self.bones.joints()  # the same joint-set rule as for predictions: RigNet's root_dup_* collapse
        self.samples = self.bones.samples()
        self.length = self.bones.total_length()

    @functools.cached_property
    def inside(self):
        """The share of the artist's bone samples inside the mesh (costly: worked out when asked)."""
        return rigdata.inside_fraction(self.samples, self.unit_vertices, self.triangles)


def scored(truth, bones):
    """(``bones`` in ``truth``'s normalised frame, their distances to the artist's: ``rigdata.skeleton_distances``)."""
    unit_bones = bones.mapped(truth.normalisation)
    return unit_bones, rigdata.skeleton_distances(unit_bones.joints(), unit_bones.samples(), truth.joints,
                                                  truth.samples)


def evaluate(truth, method, params, timeout, inside=True):
    """Run one method on one model and score it (the inside fraction only with ``inside``: it is the costly
    score); failures become a record with the error, never an exception."""
    record = {"model": truth.name, "method": method}
    try:
        started = time.perf_counter()
        bones, stage_seconds = run_limited(METHODS[method], timeout, truth.vertices, truth.triangles, **params)
        record["seconds"] = time.perf_counter() - started
        record["stages"] = {name: float(value) for name, value in stage_seconds.items()}
        record["tree_problem"] = rigdata.tree_problem(bones)
        unit_bones, distances = scored(truth, bones)
        record.update(distances)
        joints = unit_bones.joints()
        record["joints"] = len(joints)
        record["joint_ratio"] = len(joints) / len(truth.joints)
        record["length_ratio"] = unit_bones.total_length() / truth.length
        if inside:
            record["inside"] = rigdata.inside_fraction(unit_bones.samples(), truth.unit_vertices, truth.triangles)
        record["unit_bones"] = unit_bones
    except Exception as error:  # a method failing on one model must not stop the benchmark
        record["error"] = f"{type(error).__name__}: {error}".strip()
        record["traceback"] = traceback.format_exc(limit=-3)
    return record


def succeeded(record):
    return "error" not in record


def summarise(records, methods):
    """Per-method averages over the models that method scored, plus the issue's targets as PASS/FAIL."""
    summary = {}
    for method in methods:
        own = [r for r in records if r["method"] == method]
        good = [r for r in own if succeeded(r)]
        row = {"models": len(own), "failed": len(own) - len(good),
               "invalid_trees": sum(1 for r in good if r["tree_problem"])}
        row["targets"] = {"every model gives a valid tree without error": row["failed"] == 0
                          and row["invalid_trees"] == 0}
        if good:
            for key in ("cd_j2j", "cd_j2b", "cd_b2b", "joint_ratio", "inside", "seconds"):
                row[key] = float(np.mean([r[key] for r in good]))
            row["max_cd_j2j"] = max(r["cd_j2j"] for r in good)
            row["ratio_range"] = (min(r["joint_ratio"] for r in good), max(r["joint_ratio"] for r in good))
            low, high = TARGETS["joint_ratio"]
            row["targets"].update({
                f"mean CD-J2J ≤ {TARGETS['mean_cd_j2j']}": row["cd_j2j"] <= TARGETS["mean_cd_j2j"],
                f"mean CD-J2J ≤ {TARGETS['stretch_cd_j2j']} (stretch)": row["cd_j2j"] <= TARGETS["stretch_cd_j2j"],
                f"joints {low}×–{high}× the artist's on every model": low <= row["ratio_range"][0]
                and row["ratio_range"][1] <= high,
                f"mean CD-B2B ≤ {TARGETS['mean_cd_b2b']}": row["cd_b2b"] <= TARGETS["mean_cd_b2b"],
                f"no model above {TARGETS['max_cd_j2j']} CD-J2J": row["max_cd_j2j"] <= TARGETS["max_cd_j2j"],
                f"mean inside fraction ≥ {TARGETS['mean_inside']:.0%}": row["inside"] >= TARGETS["mean_inside"],
            })
        summary[method] = row
    return summary


def detail_sweep(truths, params, timeout, as_run):
    """Rigger's joint counts and mean CD-J2J with each of ``DETAIL_SETTINGS`` applied over ``params``: whether any
    one setting puts every model's joint count within the target range, and what it costs in CD-J2J. ``as_run``
    are the main run's Rigger records (one per truth, in order), reused for a setting that changes nothing."""
    low, high = TARGETS["joint_ratio"]
    rows = []
    for change in DETAIL_SETTINGS:
        setting = {**params, **change}
        records = as_run if setting == params else [evaluate(truth, "rigger", setting, timeout, inside=False)
                                                    for truth in truths]
        good = [r for r in records if succeeded(r)]
        ratios = [r["joint_ratio"] for r in good]
        label = ", ".join(f"{key}={value}" for key, value in change.items()) or ("as run" if params else "defaults")
        rows.append({
            "setting": label,
            "failed": len(records) - len(good),
            "cd_j2j": float(np.mean([r["cd_j2j"] for r in good])) if good else None,
            "ratio_range": (min(ratios), max(ratios)) if good else None,
            "over": {r["model"]: r["joint_ratio"] for r in good if r["joint_ratio"] > high},
            "under": {r["model"]: r["joint_ratio"] for r in good if r["joint_ratio"] < low},
        })
    return rows


def detail_lines(rows):
    """The markdown section for ``detail_sweep``'s rows."""
    low, high = TARGETS["joint_ratio"]
    table = [[row["setting"], "—" if row["cd_j2j"] is None else f"{row['cd_j2j']:.4f}",
              "—" if row["ratio_range"] is None else "{:.2f}–{:.2f}×".format(*row["ratio_range"]),
              str(len(row["over"]) + len(row["under"])), ratios_listed(row["over"]) or "—",
              ratios_listed(row["under"]) or "—"]
             for row in rows]
    in_range = [row["setting"] for row in rows if row["ratio_range"] and not row["over"] and not row["under"]]
    verdict = (f"Settings with every model within {low}–{high}×: {', '.join(in_range)}." if in_range else
               f"None of these settings has every model within {low}–{high}×: the artists differ in what they rig "
               f"(some leave out spikes, shields, claws, toes or a bird's legs, others give a tail eight bones or "
               f"every finger three), and a setting that brings the first kind within {high}× takes the second "
               f"below {low}×.")
    return ["", "## Joint count against the detail settings", "",
            f"Rigger's method with one parameter changed at a time (inside fractions not scored). {verdict}",
            ""] + markdown_table(
        ["setting", "mean CD-J2J", "joints vs artist", "models out of range", f"above {high}×", f"below {low}×"],
        table)


def ratios_listed(ratios):
    """``{model: ratio}`` as text, the largest ratio first."""
    return ", ".join(f"{name} {ratio:.2f}×" for name, ratio in sorted(ratios.items(), key=lambda kv: -kv[1]))


def density_lines(truths, records):
    """Two measurements behind the joint-count verdict: how many joints the artists place per unit of their own
    bone length, against the width of the target window, and on which models Rigger's bones are more than
    ``MUCH_LONGER`` times as long in total as the artist's (more of the mesh has bones)."""
    low, high = TARGETS["joint_ratio"]
    density = {t.name: len(t.joints) / t.length for t in truths}
    sparse, dense = min(density, key=density.get), max(density, key=density.get)
    longer = {r["model"]: r["length_ratio"] for r in records if succeeded(r) and r["length_ratio"] > MUCH_LONGER}
    lines = [f"The artists place {density[sparse]:.1f} ({sparse}) to {density[dense]:.1f} ({dense}) joints per "
             f"unit of their own bone length: a factor {density[dense] / density[sparse]:.2f}, where the "
             f"{low}–{high}× window is a factor {high / low:.2f} wide."]
    if longer:
        lines.append(f"Rigger's bones add up to more than {MUCH_LONGER}× the artist's length on "
                     f"{ratios_listed(longer)}: more of the mesh has bones than in the artist's rig.")
    return ["", " ".join(lines)]


def machine_description():
    cpu = cpu_model()
    return (f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}, "
            f"Python {platform.python_version()}, numpy {np.__version__}")


def model_row(record):
    if not succeeded(record):
        return [record["model"], "—", "—", "—", "—", "—", "—", f"**error**: {table_cell(record['error'])}"]
    note = f"not a tree: {record['tree_problem']}" if record["tree_problem"] else ""
    return [record["model"], f"{record['cd_j2j']:.4f}", f"{record['cd_j2b']:.4f}", f"{record['cd_b2b']:.4f}",
            f"{record['joints']} ({record['joint_ratio']:.2f}×)", f"{record['inside']:.1%}",
            f"{record['seconds'] * 1e3:.0f}", note]


def write_report(path, truths, records, summary, methods, notes, command, sweep):
    """The markdown report: averages, targets, reference checks, the detail sweep (when run), per-model tables,
    per-stage times, plots."""
    lines = [
        "# Quality benchmark", "",
        f"Generated {datetime.datetime.now().strftime('%Y-%m-%d %H:%M')} by `{command}`  ",
        f"Machine: {machine_description()}  ",
        f"Models: {len(truths)} from `../shared/models/gt`; scoring in the RigNet convention (mesh's largest "
        f"bounding-box extent = 1; bones sampled every {rigdata.BONE_SAMPLE_STEP}; helper joints matching "
        f"`{rigdata.HELPER_JOINT.pattern}` dropped). Joints = bone heads + leaf tails; inside = bone samples with "
        f"|generalised winding number| ≥ 0.5.", "",
    ]
    lines += [f"- {note}" for note in notes]
    lines += ["", "## Averages", ""]
    rows = []
    for method in methods:
        row = summary[method]
        if "cd_j2j" not in row:
            rows.append([method, "—", "—", "—", "—", "—", "—", f"{row['failed']}/{row['models']}"])
            continue
        low, high = row["ratio_range"]
        rows.append([method, f"{row['cd_j2j']:.4f}", f"{row['cd_j2b']:.4f}", f"{row['cd_b2b']:.4f}",
                     f"{row['joint_ratio']:.2f}× ({low:.2f}–{high:.2f})", f"{row['inside']:.1%}",
                     f"{row['seconds'] * 1e3:.0f}", f"{row['failed']}/{row['models']}"])
    artists_inside = np.mean([truth.inside for truth in truths])
    rows.append(["artist rigs", "—", "—", "—", "1.00×", f"{artists_inside:.1%}", "—", "—"])
    lines += markdown_table(["method", "CD-J2J", "CD-J2B", "CD-B2B", "joints vs artist (min–max)",
                             "inside", "ms / model", "failed"], rows)
    lines += ["", "Averages are over the models each method scored (failures excluded). Baselines: *stick* is one "
              "straight stick along the vertices' main principal axis through their centroid, spanning their extent, "
              "jointed at its middle (three joints); *skeletor* is skeletor's wavefront skeleton (`waves=1`, "
              "`step_size=1`, after merging coincident vertices and dropping fragments of ≤ 5 vertices) with one bone "
              "per branch, i.e. joints only at its branch points and ends, its separate pieces parented to the "
              "largest one.", "",
              "## Targets (issue 4)", ""]
    target_names = list(dict.fromkeys(name for m in methods for name in summary[m]["targets"]))
    lines += markdown_table(["target"] + methods, [
        [name] + [{True: "PASS", False: "FAIL", None: "—"}[summary[m]["targets"].get(name)] for m in methods]
        for name in target_names])
    lines += ["", "## Reference numbers", "",
              "The issue quotes CD-J2J ≈ 0.147 for a single stick and ≈ 0.076 for skeletor in this convention, and "
              f"artists' bones inside the mesh ≈ 97% of the time (measured here: {artists_inside:.1%}). The baselines "
              "above reproduce them; when this harness was written, a bare two-joint stick scored ≈ 0.250 (the true "
              "joints lie ≈ 0.35 on average from the nearer end) and skeletor with every wavefront node kept as a "
              "joint ≈ 0.052 at 4–195× the artist's joint count, so the references count a middle joint on the "
              "stick and one bone per skeletor branch.", ""]
    for method, reference in REFERENCE_CD_J2J.items():
        if "cd_j2j" in summary.get(method, {}):
            lines.append(f"- {method}: measured {summary[method]['cd_j2j']:.4f} vs reference {reference}")
    if sweep:
        lines += detail_lines(sweep) + density_lines(truths, [r for r in records if r["method"] == "rigger"])
    lines += ["", "## Per model", ""]
    lines += markdown_table(["model", "vertices", "triangles", "artist joints", "artist bones inside"],
                            [[t.name, len(t.vertices), len(t.triangles), len(t.joints), f"{t.inside:.1%}"]
                             for t in truths])
    for method in methods:
        lines += ["", f"### {method}", ""]
        lines += markdown_table(["model", "CD-J2J", "CD-J2B", "CD-B2B", "joints (vs artist)", "inside", "ms", "note"],
                                [model_row(r) for r in records if r["method"] == method])
    staged = [r for r in records if succeeded(r) and r["stages"]]
    if staged:
        stage_names = list(dict.fromkeys(name for r in staged for name in r["stages"]))
        lines += ["", "## Time per stage (ms)", ""]
        lines += markdown_table(
            ["model", "method"] + stage_names + ["wall (harness)"],
            [[r["model"], r["method"]] + [f"{r['stages'][s] * 1e3:.1f}" if s in r["stages"] else "—"
                                          for s in stage_names] + [f"{r['seconds'] * 1e3:.1f}"] for r in staged])
    lines += ["", "## Plots", "", "![CD-J2J per model](quality_cd_j2j.png)", "",
              "![Models with artist and predicted skeletons](quality_models.png)", ""]
    path.write_text("\n".join(lines))


def plot_cd_j2j(path, model_names, records, methods):
    """Grouped bars: CD-J2J per model for each method, with the target lines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(min(20, max(8, 0.6 * len(model_names))), 5.5))
    width = 0.8 / max(len(methods), 1)
    score = {(r["model"], r["method"]): r.get("cd_j2j", np.nan) for r in records}
    positions = np.arange(len(model_names))
    for i, method in enumerate(methods):
        axes.bar(positions + (i - (len(methods) - 1) / 2) * width, [score.get((m, method), np.nan)
                                                                     for m in model_names],
                 width, label=method, color=METHOD_COLOURS.get(method))
    axes.axhline(TARGETS["mean_cd_j2j"], color="black", linestyle="--", linewidth=1, label="target mean 0.045")
    axes.axhline(TARGETS["max_cd_j2j"], color="grey", linestyle=":", linewidth=1, label="per-model cap 0.08")
    axes.set_xticks(positions, model_names, rotation=70, ha="right", fontsize=8)
    axes.set_ylabel("CD-J2J (largest bbox extent = 1)")
    axes.set_title("CD-J2J per model (lower is better; failed runs have no bar)")
    axes.set_ylim(0, 1.2 * np.nanmax([0.08] + [r.get("cd_j2j", np.nan) for r in records]))
    axes.legend(fontsize=8, ncol=len(methods) + 2, loc="upper center")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def view_axes(vertices):
    """Two drawing planes as (horizontal, vertical) axis pairs, wider view first, with the up axis vertical.

    Up is the axis on which the mesh (in its own frame) stands at 0 — characters are modelled feet on the ground —,
    else the longest.
    """
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    extent = high - low
    grounded = np.flatnonzero(np.abs(low) < 0.02 * extent.max())
    up = int(grounded[np.argmax(extent[grounded])]) if len(grounded) else int(np.argmax(extent))
    across = sorted((axis for axis in range(3) if axis != up), key=lambda axis: -extent[axis])
    return [(across[0], up), (across[1], up)]


def draw_skeleton(axes, bones, joints, plane, colour, label):
    horizontal, vertical = plane
    for head, tail in zip(bones.heads, bones.tails):
        axes.plot([head[horizontal], tail[horizontal]], [head[vertical], tail[vertical]], color=colour, linewidth=1.2)
    axes.scatter(joints[:, horizontal], joints[:, vertical], s=9, color=colour, label=label, zorder=3)


def plot_models(path, truths, records, methods, drawn=DRAWN_MODELS):
    """A few models in two views, one column pair per method: mesh as a light scatter, artist rig, prediction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chosen = [t for t in truths if t.name in drawn] or truths[:3]
    by_key = {(r["model"], r["method"]): r for r in records}
    columns = [(method, view) for method in methods for view in (0, 1)]
    figure, grid = plt.subplots(len(chosen), len(columns), figsize=(3 * len(columns), 3.2 * len(chosen)),
                                squeeze=False)
    axis_names = "XYZ"
    for row, truth in enumerate(chosen):
        planes = view_axes(truth.vertices)
        outline = np.concatenate([truth.unit_vertices, truth.unit_vertices[truth.triangles].mean(axis=1)])
        for column, (method, view) in enumerate(columns):
            axes, plane = grid[row][column], planes[view]
            axes.scatter(outline[:, plane[0]], outline[:, plane[1]], s=0.3, color="0.8", rasterized=True)
            draw_skeleton(axes, truth.bones, truth.joints, plane, "black", "artist")
            record = by_key.get((truth.name, method))
            if record and succeeded(record):
                draw_skeleton(axes, record["unit_bones"], record["unit_bones"].joints(), plane,
                              METHOD_COLOURS.get(method, "tab:purple"), method)
                subtitle = f"CD-J2J {record['cd_j2j']:.3f}"
            else:
                subtitle = "failed" if record else "not run"
            axes.set_title(f"{truth.name}\n{method} ({subtitle}), {axis_names[plane[0]]}{axis_names[plane[1]]}",
                           fontsize=8)
            axes.set_aspect("equal")
            axes.set_xticks([])
            axes.set_yticks([])
    handles = [plt.Line2D([], [], color=c, marker="o", label=l) for l, c in
               [("artist", "black")] + [(m, METHOD_COLOURS.get(m, "tab:purple")) for m in methods]]
    figure.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=9)
    figure.tight_layout(rect=(0, 0.03, 1, 1))
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", help="comma-separated substrings; run the models whose name contains one")
    parser.add_argument("--methods", help=f"comma-separated, from {', '.join(METHODS)} (default: all available)")
    settings_option(parser)
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per method and model (default 300)")
    parser.add_argument("--out", type=pathlib.Path, default=RESULTS_DIR, help="results folder (default bench/results)")
    parser.add_argument("--draw", default=",".join(DRAWN_MODELS),
                        help=f"comma-separated models drawn in quality_models.png (default {','.join(DRAWN_MODELS)})")
    args = parser.parse_args(argv)

    if not MODELS_DIR.is_dir():
        raise SystemExit(f"No models at {MODELS_DIR}: the quality benchmark needs ../shared beside the checkout.")
    folders = sorted(p for p in MODELS_DIR.iterdir() if p.is_dir())
    if args.models:
        wanted = [token for token in args.models.split(",") if token]
        folders = [p for p in folders if any(token in p.name for token in wanted)]
        if not folders:
            raise SystemExit(f"No model name contains any of {wanted}.")

    notes = []
    methods = [m for m in args.methods.split(",") if m] if args.methods else list(METHODS)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise SystemExit(f"Unknown methods {unknown}; choose from {list(METHODS)}.")
    params = method_params(args.settings)
    if params:
        notes.append(f"rigger parameters: {params}.")
    if args.models:
        notes.append(f"models filtered by `--models {args.models}`.")

    truths, records = [], []
    print(f"{'model':32s} {'method':9s} {'CD-J2J':>7s} {'CD-J2B':>7s} {'CD-B2B':>7s} {'joints':>12s} "
          f"{'inside':>7s} {'ms':>8s}")
    for folder in folders:
        try:
            truth = GroundTruth(folder)
        except (OSError, ValueError) as error:
            notes.append(f"{folder.name} skipped: unreadable ground truth ({error}).")
            print(f"{folder.name:32s} skipped: {error}")
            continue
        truths.append(truth)
        for method in methods:
            record = evaluate(truth, method, params if method == "rigger" else {}, args.timeout)
            records.append(record)
            if succeeded(record):
                print(f"{truth.name:32s} {method:9s} {record['cd_j2j']:7.4f} {record['cd_j2b']:7.4f} "
                      f"{record['cd_b2b']:7.4f} {record['joints']:5d} ({record['joint_ratio']:4.2f}×) "
                      f"{record['inside']:7.1%} {record['seconds'] * 1e3:8.0f}"
                      + (f"  not a tree: {record['tree_problem']}" if record["tree_problem"] else ""))
            else:
                print(f"{truth.name:32s} {method:9s} ERROR {record['error']}")
            sys.stdout.flush()
    if not truths:
        raise SystemExit("No readable models.")

    summary = summarise(records, methods)
    print(f"\nartist rigs: {np.mean([t.inside for t in truths]):.1%} of bone samples inside")
    for method in methods:
        row = summary[method]
        if "cd_j2j" in row:
            print(f"{method:9s} mean CD-J2J {row['cd_j2j']:.4f}  CD-J2B {row['cd_j2b']:.4f}  "
                  f"CD-B2B {row['cd_b2b']:.4f}  joints {row['joint_ratio']:.2f}×  inside {row['inside']:.1%}  "
                  f"{row['seconds'] * 1e3:.0f} ms  failed {row['failed']}/{row['models']}")
        else:
            print(f"{method:9s} failed on every model")

    as_run = [r for r in records if r["method"] == "rigger"]
    sweep = detail_sweep(truths, params, args.timeout, as_run) if as_run else []
    for row in sweep:
        print(f"{row['setting']:22s} out of range: {len(row['over']) + len(row['under']):2d}  "
              + (f"mean CD-J2J {row['cd_j2j']:.4f}" if row["cd_j2j"] is not None else "failed on every model"))

    args.out.mkdir(parents=True, exist_ok=True)
    command = " ".join(["bench/quality.py"] + (argv if argv is not None else sys.argv[1:]))
    write_report(args.out / "quality.md", truths, records, summary, methods, notes, command, sweep)
    (args.out / "quality.json").write_text(json.dumps({
        "machine": machine_description(), "command": command, "notes": notes,
        "artist_inside": {t.name: t.inside for t in truths},
        "summary": summary, "detail_sweep": sweep,
        "records": [{k: v for k, v in r.items() if k != "unit_bones"} for r in records],
    }, indent=1, default=str))
    plot_cd_j2j(args.out / "quality_cd_j2j.png", [t.name for t in truths], records, methods)
    plot_models(args.out / "quality_models.png", truths, records, methods, args.draw.split(","))
    print(f"\nwrote {args.out / 'quality.md'}, quality.json, quality_cd_j2j.png, quality_models.png")


if __name__ == "__main__":
    main()
