"""Skinning benchmark: ``rigger.blender.skinning.skin`` on the real models in ../shared/models/gt.

Every model is skinned twice in headless Blender: to an armature of its artist's skeleton (from ``rig_info``) and to
one of Rigger's own skeleton (``rigger.rig_mesh``, silhouette method). Measured: vertices left unweighted (must be 0
everywhere), what bone heat printed, how often each repair stage ran and how many vertices it weighted, time, and the
agreement of the dominant bone with the artist's weights. The compiled nearest-bones weighting alone is scored too,
and timed on synthetic bone sets up to a million points and thousands of bones. Seams: vertices at one position (split
for UVs or normals) must carry the same weights, or the posed mesh cracks open there; the largest weight difference
between them is measured and must be 0. Writes
``bench/results/skinning.md`` and ``bench/results/skinning.png``.

    .venv/bin/python bench/skinning.py [--models SUBSTR,...] [--skip-speed]
"""
import argparse
import datetime
import os
import pathlib
import platform
import statistics
import sys
import time
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import rigdata  # noqa: E402  (bench/ is not a package)
from benchkit import (RESULTS_DIR, SHARED_MODELS, cpu_model, described_commit, format_seconds,  # noqa: E402
                      markdown_table, table_cell)
from rigger.blender.headless import temporary_user_folder  # noqa: E402  (bpy-free)
from rigger.core.polyline import segment_distances  # noqa: E402  (bpy-free)

MODELS_DIR = SHARED_MODELS / "gt"
REPAIR_STAGES = ("island bone heat", "nearest bones")
SKELETONS = ("artist", "rigger")
SAMPLES_PER_BONE = 9  # points along each of Rigger's bones when finding the nearest true bone
SPEED_POINTS = (10_000, 100_000, 1_000_000)
SPEED_BONES = (20, 200, 2_000, 5_000)


@dataclass
class Model:
    """One ground-truth model: mesh arrays, the artist skeleton and its weights in the benchmark's terms."""

    name: str
    vertices: np.ndarray
    triangles: np.ndarray
    skeleton: object  # rigger Skeleton of the artist's bones
    head_joint: np.ndarray  # (B,) joint where each artist bone starts
    artist_joint: np.ndarray  # (V,) the owner joint of each vertex's largest artist weight, -1 for none
    place: np.ndarray  # (V,) index of each vertex's exact position: vertices sharing one are a seam's copies


def load_model(folder):
    vertices, triangles, rig = rigdata.load_ground_truth(folder)
    skeleton, head_joint = rigdata.armature_skeleton(rig)
    place = np.unique(vertices, axis=0, return_inverse=True)[1].ravel()
    return Model(folder.name, vertices, triangles, skeleton, head_joint, rigdata.dominant_joints(rig), place)


def nearest_true_bones(ours, truth):
    """For each of our bones, the true bone nearest on average over points along it."""
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_BONE)
    samples = ours.heads[:, None] + fractions[None, :, None] * (ours.tails - ours.heads)[:, None]
    points = samples.reshape(-1, 3)
    distances = segment_distances(points, truth.heads, truth.tails)
    return distances.reshape(len(ours), SAMPLES_PER_BONE, len(truth)).mean(axis=1).argmin(axis=1)


def agreement(joint_of_bone, dominant_bone, artist_joint):
    """Share of the artist-weighted vertices whose dominant bone starts at the artist's dominant joint."""
    weighted = artist_joint >= 0
    if not weighted.any():
        return float("nan")
    return float((joint_of_bone[dominant_bone[weighted]] == artist_joint[weighted]).mean())


def seam_gap(table, place):
    """The largest difference of one bone's weight between two vertices at one position (``table``: (V, B)
    weights, ``place``: (V,) position index); 0 when every seam's copies are weighted alike."""
    high = np.full((place.max() + 1, table.shape[1]), -np.inf)
    low = np.full_like(high, np.inf)
    np.maximum.at(high, place, table)
    np.minimum.at(low, place, table)
    return float((high - low).max())


def dominant_bones(obj, names):
    """(V,) index into ``names`` of each vertex's largest weight (-1 where it has none; of equal weights, the first
    in Blender's order)."""
    best = np.full(len(obj.data.vertices), -1)
    best_weight = np.zeros(len(obj.data.vertices))
    for vertex, column, weight in rigdata.vertex_group_weights(obj, names):
        if weight > best_weight[vertex]:
            best[vertex], best_weight[vertex] = column, weight
    return best


def skin_model(model, kind):
    """Skin one model to one kind of skeleton in a fresh scene; a record of what happened (errors included)."""
    import rigger
    from rigger.blender.skinning import FAILURE_MESSAGE, SURFACE_STAGE

    record = {"model": model.name, "skeleton": kind, "vertices": len(model.vertices),
              "seam_vertices": int((np.bincount(model.place)[model.place] > 1).sum())}
    try:
        if kind == "artist":
            skeleton, joint_of_bone = model.skeleton, model.head_joint
        else:
            started = time.perf_counter()
            skeleton = rigger.rig_mesh(model.vertices, model.triangles.astype(np.int32))
            record["rig_seconds"] = time.perf_counter() - started
            joint_of_bone = model.head_joint[nearest_true_bones(skeleton, model.skeleton)]
        obj, report, _ = rigdata.skinned_mesh(model.name, model.vertices, model.triangles, skeleton)
        record["seconds"] = report.seconds
        names = list(skeleton.names)
        dominant = dominant_bones(obj, names)
        record["seam_gap"] = seam_gap(rigdata.vertex_weights(obj, names), model.place)
        record.update(
            bones=len(names), welded=report.welded, unweighted=report.unweighted,
            recounted_unweighted=int((dominant < 0).sum()),
            failed=any(FAILURE_MESSAGE in message for message in report.stages[0].messages),
            left_by_bone_heat=report.vertices - report.stages[0].weighted,  # accessories are in bone heat too
            accessories=sum(stage.weighted for stage in report.stages if stage.name == SURFACE_STAGE),
            stages={stage.name: stage.weighted for stage in report.stages[1:]},
            notes={stage.name: stage.note for stage in report.stages[1:] if stage.note},
            agreement=agreement(joint_of_bone, dominant, model.artist_joint), summary=report.summary())
    except Exception as error:  # one model failing must not stop the benchmark
        record["error"] = f"{type(error).__name__}: {error}"
    return record


def fallback_alone(model):
    """Top-1 agreement of the nearest-bones weighting on every vertex, with the artist skeleton (no bone heat)."""
    from rigger.weights import bone_weights, vertex_normals

    places = np.zeros((model.place.max() + 1, 3))
    places[model.place] = model.vertices
    normals = vertex_normals(places, model.place[model.triangles])[model.place]  # of the mesh with its seams welded
    result = bone_weights(model.vertices, model.skeleton.heads, model.skeleton.tails, normals)
    return agreement(model.head_joint, result.bones[:, 0], model.artist_joint)


def speed_rows():
    """Median time of ``rigger.weights.bone_weights`` on random bones and points in a unit cube, with normals."""
    from rigger.weights import bone_weights

    rng = np.random.default_rng(5)
    rows = []
    for count in SPEED_POINTS:
        points = rng.uniform(0.0, 1.0, (count, 3))
        normals = rng.normal(size=(count, 3))
        for bones in SPEED_BONES:
            heads = rng.uniform(0.0, 1.0, (bones, 3))
            tails = heads + rng.normal(scale=0.5 / bones ** (1 / 3), size=(bones, 3))
            times = []
            for _ in range(3 if count <= 100_000 else 1):
                started = time.perf_counter()
                bone_weights(points, heads, tails, normals)
                times.append(time.perf_counter() - started)
            rows.append({"points": count, "bones": bones, "seconds": statistics.median(times)})
            print(f"  nearest bones: {count:>9,} points x {bones:>5,} bones  {format_seconds(rows[-1]['seconds'])}")
    return rows


def stage_cell(record, stage):
    fixed = record["stages"].get(stage)
    return "" if fixed is None else str(fixed)


def bone_heat_cell(record):
    if record["failed"]:
        return "**failed** (printed)"
    return "ok" if not record["left_by_bone_heat"] else f"{record['left_by_bone_heat']} left silently"


def percent(value):
    return "–" if value is None or np.isnan(value) else f"{100 * value:.1f}%"


def unweighted_count(record):
    """Vertices of one run left unweighted: the report's count plus the independent recount (0 for an error)."""
    return record.get("unweighted", 0) + record.get("recounted_unweighted", 0)


def totals(records):
    """(unweighted vertices, errors) over all runs."""
    return sum(unweighted_count(r) for r in records), sum("error" in r for r in records)


def verdict(records):
    """The issue's target: no vertex left unweighted on any model, with either skeleton."""
    unweighted, errors = totals(records)
    passed = not unweighted and not errors
    return (f"Target, every vertex weighted everywhere: **{'PASS' if passed else 'FAIL'}**: {unweighted} unweighted "
            f"vertices and {errors} errors over {len(records)} runs (the count is the report's and, independently, "
            f"the vertices without a weight > 0 in any deforming bone's group).")


def seam_verdict(records):
    """The seam target: vertices at one position weighted alike (gap 0) in every run."""
    good = [r for r in records if "error" not in r]
    cracked = [r for r in good if r["seam_gap"] > 0]
    worst = max(good, key=lambda r: r["seam_gap"], default=None)
    passed = not cracked and len(good) == len(records)
    text = (f"Target, vertices at one position weighted alike: **{'PASS' if passed else 'FAIL'}**: "
            f"{len(cracked)} of {len(good)} runs have a seam whose copies differ")
    if cracked:
        text += f"; the largest weight difference is {worst['seam_gap']:.3f} ({worst['model']}, {worst['skeleton']} " \
                f"skeleton)"
    return text + "."


def idle_count(record):
    """How many bones bone heat left carrying no vertex's largest weight (the skinning's idle-bones stage)."""
    from rigger.blender.skinning import IDLE_STAGE
    note = record["notes"].get(IDLE_STAGE)
    return len(note.split(", ")) if note else 0


def summary_rows(records, alone):
    rows = []
    for kind in SKELETONS:
        own = [r for r in records if r["skeleton"] == kind]
        good = [r for r in own if "error" not in r]
        cells = [kind, str(len(own)), str(len(own) - len(good)),
                 str(sum(unweighted_count(r) for r in good)),
                 str(sum(r["failed"] for r in good)), str(sum(r["left_by_bone_heat"] > 0 and not r["failed"]
                                                             for r in good))]
        for stage in REPAIR_STAGES:
            ran = [r for r in good if stage in r["stages"]]
            cells.append(f"{len(ran)} / {sum(r['stages'][stage] > 0 for r in ran)} / "
                         f"{sum(r['stages'][stage] for r in ran)}")
        cells.append(f"{sum(r['accessories'] > 0 for r in good)} / {sum(r['accessories'] for r in good)}")
        cells.append(f"{sum(idle_count(r) > 0 for r in good)} / {sum(idle_count(r) for r in good)}")
        seconds = [r["seconds"] for r in good]
        cells.append(f"{sum(r['seam_gap'] > 0 for r in good)} / {max((r['seam_gap'] for r in good), default=0):.3f}")
        cells += [format_seconds(statistics.median(seconds)) if seconds else "–",
                  format_seconds(max(seconds)) if seconds else "–",
                  percent(np.nanmean([r["agreement"] for r in good]) if good else None)]
        rows.append(cells)
    rows.append(["artist, nearest bones alone", str(len(alone)), "", "0", "", "", "", "", "", "", "", "", "",
                 percent(np.nanmean(list(alone.values())) if alone else None)])
    return rows


def markdown(records, alone, speed, run):
    import bpy
    from rigger.blender.skinning import IDLE_STAGE

    commit = described_commit()
    out = [
        "# Skinning (issue 5, item 4)",
        "",
        f"Generated by `{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC in {run['seconds']:.0f} s; "
        f"rigger at `{commit}`.",
        "",
        f"- Machine: {cpu_model()}, {os.cpu_count()} cores shared with other agents (load average before "
        f"{', '.join(f'{v:.2f}' for v in run['load'])}); Blender {bpy.app.version_string} as the `bpy` module, "
        f"Python {platform.python_version()}, numpy {np.__version__}.",
        "- Meshes: each model's OBJ (`v`/`f` lines, polygons fan-triangulated, UV-seam duplicates kept as the file "
        "has them) becomes one Blender mesh object, skinned with `rigger.blender.skinning.skin` in a fresh scene. "
        "Skinning welds the seams first (*welded*: vertices merged into another at the same place) and runs bone "
        "heat on the welded copy.",
        "- Skeletons: **artist** = the rig_info joints, one bone per parent→child pair, helper joints and zero-length "
        "bones dropped (`rigdata.armature_skeleton`); **rigger** = `rigger.rig_mesh` with the silhouette method's "
        "defaults.",
        "- Agreement (top-1): over the vertices with artist weights, the share whose largest Rigger weight is on a "
        "bone starting at the joint carrying the artist's largest weight (a leaf joint's weight counts for the bone "
        "ending there). With Rigger's skeleton, each of our bones is first mapped to the nearest true bone (mean "
        f"distance from {SAMPLES_PER_BONE} points along our bone to the true bone segment), so the score asks "
        "whether a vertex follows the right body part, and is limited by how well our bones match the artist's.",
        "- *Nearest bones alone*: `rigger.weights.bone_weights` (the last repair stage) on every vertex with the "
        "artist skeleton and the area-weighted vertex normals of the mesh with its seams welded (vertices at one "
        "position merged), no bone heat: what the fallback is worth on its own.",
        "- Repair columns: models where the stage ran / where it weighted vertices / vertices it weighted. "
        "*Accessories*: the loose parts no bone runs through, weighted by bone heat with the rest, then moved as "
        "one piece with the surface nearest to them (`rigger.core.accessories`): models that have any / their "
        "vertices. *Idle bones*: bones bone heat left carrying no vertex's largest weight, given a share of the "
        "vertices of the bones they join: models that had any / such bones (per model: their names).",
        "- Seams: *seam vertices* share their exact position with another vertex (the file split them for UVs or "
        "normals); the *seam gap* is the largest difference of one bone's weight between two such copies (0: the "
        "posed mesh cannot crack there). *Seams cracked* counts the models whose gap is above 0.",
        "",
        "## Summary",
        "",
        verdict(records),
        "",
        seam_verdict(records),
        "",
    ]
    out += markdown_table(["skeleton", "models", "errors", "unweighted vertices", "bone heat failed (message)",
                  "bone heat left vertices silently", "island bone heat", "nearest bones",
                  "accessories (models / vertices)", "idle bones (models / bones)", "seams cracked / largest gap",
                  "time (median)", "time (max)", "top-1 agreement (mean)"],
                         summary_rows(records, alone))
    out += ["", "![agreement per model, skinning time, fallback speed](skinning.png)", "", "## Per model", ""]
    rows = []
    for record in sorted(records, key=lambda r: (r["model"], SKELETONS.index(r["skeleton"]))):
        if "error" in record:
            rows.append([record["model"], record["skeleton"], f"{record['vertices']:,}"] + [""] * 11
                        + [f"error: {table_cell(record['error'])}"])
            continue
        rows.append([record["model"], record["skeleton"], f"{record['vertices']:,}", str(record["bones"]),
                     f"{record['seam_vertices']:,}", f"{record['welded']:,}", bone_heat_cell(record),
                     *(stage_cell(record, stage) for stage in REPAIR_STAGES),
                     str(record["accessories"]) if record["accessories"] else "",
                     record["notes"].get(IDLE_STAGE, ""), str(unweighted_count(record)),
                     f"{record['seam_gap']:.3f}",
                     format_seconds(record["seconds"]),
                     percent(record["agreement"]),
                     percent(alone.get(record["model"])) if record["skeleton"] == "artist" else ""])
    out += markdown_table(["model", "skeleton", "vertices", "bones", "seam vertices", "welded", "bone heat",
                  "islands", "nearest", "accessories", "idle bones", "unweighted", "seam gap", "skin time",
                  "top-1 agreement",
                  "nearest bones alone"], rows)
    if speed:
        out += ["", "## The compiled nearest-bones weighting alone", "",
                "`rigger.weights.bone_weights(points, heads, tails, normals)` (4 bones per point), random bone "
                "segments and points in a unit cube: points far from every bone are the hard case for the search.",
                ""]
        out += markdown_table(["points", "bones", "time (median)"],
                     [[f"{row['points']:,}", f"{row['bones']:,}", format_seconds(row["seconds"])] for row in speed])
    return "\n".join(out) + "\n"


def plot(records, alone, speed, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    good = [r for r in records if "error" not in r]
    models = sorted({r["model"] for r in good})
    figure, (bars, times, speeds) = plt.subplots(1, 3, figsize=(17, 5.5), gridspec_kw={"width_ratios": [2.2, 1, 1]})
    width = 0.27
    positions = np.arange(len(models))
    series = [("artist skeleton, Rigger skinning", "tab:blue",
               {r["model"]: r["agreement"] for r in good if r["skeleton"] == "artist"}),
              ("artist skeleton, nearest bones alone", "tab:gray", alone),
              ("Rigger skeleton (bones mapped to nearest true bone)", "tab:red",
               {r["model"]: r["agreement"] for r in good if r["skeleton"] == "rigger"})]
    for offset, (label, colour, values) in zip((-width, 0.0, width), series):
        bars.bar(positions + offset, [100 * values.get(m, np.nan) for m in models], width, label=label,
                 color=colour)
    bars.set_xticks(positions, models, rotation=70, ha="right", fontsize=7)
    bars.set_ylabel("top-1 agreement with the artist's weights (%)")
    bars.set_ylim(0, 118)
    bars.set_yticks(range(0, 101, 20))
    bars.legend(fontsize=7, loc="upper center", ncol=3)
    bars.set_title("Dominant bone vs the artist's")
    for kind, colour in zip(SKELETONS, ("tab:blue", "tab:red")):
        for repaired, marker in ((False, "o"), (True, "x")):
            own = [r for r in good if r["skeleton"] == kind
                   and any(stage in r["stages"] for stage in REPAIR_STAGES) == repaired]
            times.scatter([r["vertices"] for r in own], [r["seconds"] for r in own], marker=marker, color=colour,
                          label=f"{kind} skeleton" + (", repaired" if repaired else ""))
    times.set_xscale("log")
    times.set_yscale("log")
    times.set_xlabel("vertices")
    times.set_ylabel("skin() seconds")
    times.set_title("Skinning time")
    times.legend(fontsize=7)
    speeds.set_title("Nearest-bones weighting (compiled)")
    if speed:
        for bones in SPEED_BONES:
            rows = [row for row in speed if row["bones"] == bones]
            speeds.plot([row["points"] for row in rows], [row["seconds"] for row in rows], marker="o",
                        label=f"{bones:,} bones")
        speeds.set_xscale("log")
        speeds.set_yscale("log")
        speeds.set_xlabel("points")
        speeds.set_ylabel("seconds")
        speeds.legend(fontsize=7)
    else:
        speeds.text(0.5, 0.5, "not measured (--skip-speed)", ha="center", transform=speeds.transAxes)
        speeds.set_axis_off()
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", help="comma-separated substrings of the model names to run")
    parser.add_argument("--skip-speed", action="store_true", help="leave out the synthetic speed table")
    args = parser.parse_args(argv)
    if not MODELS_DIR.is_dir():
        raise SystemExit(f"No models at {MODELS_DIR}: the skinning benchmark needs ../shared beside the checkout.")
    folders = sorted(path for path in MODELS_DIR.iterdir() if path.is_dir())
    if args.models:
        wanted = [text.strip() for text in args.models.split(",") if text.strip()]
        folders = [path for path in folders if any(text in path.name for text in wanted)]
        if not folders:
            raise SystemExit(f"No model name contains any of {wanted}.")
    temporary_user_folder()
    run = {"command": "python bench/skinning.py" + (" " + " ".join(argv or sys.argv[1:])).rstrip(),
           "started": datetime.datetime.now(datetime.timezone.utc), "load": os.getloadavg()}
    started = time.perf_counter()
    records, alone = [], {}
    for folder in folders:
        model = load_model(folder)
        alone[model.name] = fallback_alone(model)
        for kind in SKELETONS:
            record = skin_model(model, kind)
            records.append(record)
            print(f"{model.name:32s} {kind:7s} " + (record.get("error") or record["summary"]), flush=True)
    speed = [] if args.skip_speed else speed_rows()
    run["seconds"] = time.perf_counter() - started
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    (RESULTS_DIR / "skinning.md").write_text(markdown(records, alone, speed, run), encoding="utf-8")
    plot(records, alone, speed, RESULTS_DIR / "skinning.png")
    unweighted, errors = totals(records)
    print(f"wrote {RESULTS_DIR / 'skinning.md'}: {len(records)} runs, {unweighted} unweighted vertices, "
          f"{errors} errors")
    return 1 if unweighted or errors else 0


if __name__ == "__main__":
    sys.exit(main())
