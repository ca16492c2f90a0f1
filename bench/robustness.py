"""Robustness benchmark: how much Rigger's skeleton changes when the mesh is perturbed by amounts nobody would see.

Every ``../shared`` model (the body-plan benchmark's list, each read as Blender imports it) is rigged as it is and
with its vertex positions moved by Gaussian noise (per position, so vertices split at UV seams move together and
the surface stays closed) of a few standard deviations, each a share of the mesh's largest extent, several seeds
each. Per noisy rig: whether the body plan is the same, the change in bone count, how far the skeleton moved (the
Chamfer distance between the clean and the noisy skeletons' bone samples, CD-B2B, in units of size) and, on the
artist-rigged models, how much farther the joints lie from the artist's (CD-J2J). The RigNet models are also
rigged as RigNet remeshed them (``NAME_remesh.obj``, the same shape in other triangles): the same measures between
the two rigs. Also per rig: how many bones bridge twin parts, lying across the mirror plane with both ends well off
it (one hip's bone to the other hip, one ear's tip to the other's), a defect whatever the noise. Writes
robustness.md, robustness.png and robustness.json to bench/results (out/robustness with --models).

No target yet: this measures a weakness found by hand, for the work that fixes it.
"""
import argparse
import json
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import rigdata  # noqa: E402  (bench/ is not a package)
import rigger  # noqa: E402
from benchkit import (SHARED_MODELS, markdown_table, method_params, picked, results_folder, run_record,  # noqa: E402
                      settings_option, subset_options)
from bodyplan import MODELS, load, model_path  # noqa: E402

SIGMAS = (0.0005, 0.001, 0.0025)  # noise standard deviations, shares of the size: 0.1% of a 2 m figure is 2 mm
SEEDS = (0, 1, 2, 3)  # 136 noisy rigs per noise level over the 34 models
MOVED = 0.01  # a noisy skeleton whose CD-B2B to the clean one is above this (share of size) has visibly moved
BRIDGE = 0.03  # a bone across the mirror plane with both ends farther than this off it (share of size) bridges twins


def noisy(vertices, sigma, seed):
    """``vertices`` each moved by Gaussian noise of standard deviation ``sigma`` (mesh units) per axis; vertices at
    one position move together, so seams stay closed."""
    _, position = np.unique(vertices, axis=0, return_inverse=True)
    offsets = np.random.default_rng(seed).normal(0.0, sigma, (position.max() + 1, 3))
    return vertices + offsets[position.ravel()]


def rigged(vertices, triangles, normalisation, truth, params):
    """(plan kind, bones, unit bones' joints and samples, CD-J2J to the artist's or None, bridges) of Rigger on a
    mesh, with the method parameters ``params``."""
    skeleton = rigger.rig_mesh(vertices, triangles, **params)
    bones = rigdata.Bones.of(skeleton).mapped(normalisation)
    joints, samples = bones.joints(), bones.samples()
    to_artist = None if truth is None else rigdata.skeleton_distances(joints, samples, *truth)["cd_j2j"]
    return (skeleton.body_plan.kind, len(bones), joints, samples, to_artist,
            bridges(skeleton, BRIDGE / normalisation.scale))


def bridges(skeleton, distance):
    """How many of ``skeleton``'s bones lie across its mirror plane with head and tail both farther than
    ``distance`` (mesh units) off it (0 without a plane)."""
    plane = skeleton.stages.get("mirror_plane")
    if plane is None:
        return 0
    head, tail = skeleton.heads @ plane.normal - plane.offset, skeleton.tails @ plane.normal - plane.offset
    return int(np.sum((head * tail < 0) & (np.minimum(abs(head), abs(tail)) > distance)))


def measure(name, sigmas=SIGMAS, seeds=SEEDS, params=None):
    """One model's clean rig and every noisy one (Rigger with the method parameters ``params``), compared."""
    params = params or {}
    vertices, triangles, rig, turn = load(name)
    normalisation = rigdata.Normalisation.of_mesh(vertices)
    truth = None
    if rig is not None:
        artist = rig.bones().mapped(normalisation)
        truth = (artist.joints(), artist.samples())
    size = 1.0 / normalisation.scale
    kind, count, joints, samples, to_artist, bridged = rigged(vertices, triangles, normalisation, truth, params)
    record = {"model": name, "label": MODELS[name][0], "plan": kind, "bones": count, "cd_j2j": to_artist,
              "bridges": bridged, "noisy": []}
    remeshed = model_path(name) / f"{name}_remesh.obj"
    if remeshed.is_file():
        other, other_triangles = rigdata.load_obj(remeshed)
        r_kind, r_count, r_joints, r_samples, r_to_artist, _ = rigged(other @ turn.T, other_triangles.astype(np.int32),
                                                                   normalisation, truth, params)
        record["remeshed"] = {"vertices": [len(vertices), len(other)], "plan": r_kind, "bones": r_count,
                              "moved": rigdata.chamfer_distance(samples, r_samples), "cd_j2j": r_to_artist}
    for sigma in sigmas:
        for seed in seeds:
            n_kind, n_count, n_joints, n_samples, n_to_artist, n_bridged = rigged(
                noisy(vertices, sigma * size, seed), triangles, normalisation, truth, params)
            record["noisy"].append({
                "sigma": sigma, "seed": seed, "plan": n_kind, "bones": n_count, "bridges": n_bridged,
                "moved": rigdata.chamfer_distance(samples, n_samples),
                "joints_moved": rigdata.chamfer_distance(joints, n_joints),
                "cd_j2j": n_to_artist})
    return record


def summarised(records, sigmas):
    """Per noise level: the share of noisy rigs keeping the plan, the median and largest CD-B2B to the clean
    skeleton, the share that moved visibly, the mean relative change in bone count and, on the artist-rigged
    models, the mean CD-J2J to the artist's joints clean and noisy, and the share of rigs with a bone bridging twins
    (``bridges``)."""
    summary = []
    for sigma in sigmas:
        runs = [(record, run) for record in records for run in record["noisy"] if run["sigma"] == sigma]
        moved = np.array([run["moved"] for _, run in runs])
        scored = [(record["cd_j2j"], run["cd_j2j"]) for record, run in runs if run["cd_j2j"] is not None]
        summary.append({
            "sigma": sigma, "rigs": len(runs),
            "plan_kept": float(np.mean([run["plan"] == record["plan"] for record, run in runs])),
            "moved_median": float(np.median(moved)), "moved_max": float(moved.max()),
            "moved_share": float(np.mean(moved > MOVED)),
            "bridged": float(np.mean([run["bridges"] > 0 for _, run in runs])),
            "bone_change": float(np.mean([abs(run["bones"] - record["bones"]) / record["bones"]
                                          for record, run in runs])),
            "cd_j2j_clean": float(np.mean([clean for clean, _ in scored])) if scored else None,
            "cd_j2j_noisy": float(np.mean([dirty for _, dirty in scored])) if scored else None})
    return summary


def report(records, summary, run, sigmas):
    lines = ["# Robustness to imperceptible noise", "",
             f"Generated by `{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC in {run['seconds']:.0f} s; "
             f"rigger at `{run['commit']}`.", "",
             f"- Machine: {run['cpu']}.",
             f"- Models: {len(records)} from `../shared` (the body-plan benchmark's list), each read as Blender "
             "imports it. Sizes are shares of the mesh's largest extent.",
             f"- Noise: Gaussian, per vertex position (seams stay closed), standard deviations "
             f"{', '.join(f'{100 * s:g}%' for s in sigmas)} of the size, seeds {', '.join(map(str, SEEDS))}.",
             "- Moved: the Chamfer distance between the clean and the noisy skeleton's bone samples (CD-B2B); "
             f"visibly moved above {MOVED}. CD-J2J: the artist-rigged models' joints against the artist's.",
             f"- Bridged: rigs with a bone across the mirror plane whose ends both lie more than {BRIDGE} off it "
             "(a bone from one twin part to the other through the air).",
             "- No target yet: the benchmark measures a weakness, for the work that fixes it.", "",
             "## Summary", ""]
    lines += markdown_table(
        ["noise σ", "rigs", "body plan kept", "moved, median", "moved, largest", f"moved > {MOVED}",
         "bone count change", "bridged", "CD-J2J clean → noisy"],
        [[f"{100 * row['sigma']:g}%", row["rigs"], f"{100 * row['plan_kept']:.0f}%", f"{row['moved_median']:.4f}",
          f"{row['moved_max']:.4f}", f"{100 * row['moved_share']:.0f}%", f"{100 * row['bone_change']:.0f}%",
          f"{100 * row['bridged']:.0f}%",
          "—" if row["cd_j2j_clean"] is None else f"{row['cd_j2j_clean']:.4f} → {row['cd_j2j_noisy']:.4f}"]
         for row in summary])
    lines += ["", "![CD-B2B from the clean skeleton per model and noise level](robustness.png)", "",
              "## Per model", "",
              "Each cell: the body plans of the noisy rigs where they differ from the clean one, bone counts, the "
              "largest CD-B2B to the clean skeleton over the seeds and how many rigs have bones bridging twins.", ""]
    rows = []
    for record in records:
        bridged = f"; {record['bridges']} bridging" if record["bridges"] else ""
        cells = [record["model"], f"{record['plan']} ({record['bones']}{bridged})"]
        for sigma in sigmas:
            runs = [run for run in record["noisy"] if run["sigma"] == sigma]
            plans = sorted({run["plan"] for run in runs if run["plan"] != record["plan"]})
            counts = "/".join(str(run["bones"]) for run in runs)
            moved = max(run["moved"] for run in runs)
            bridged = sum(run["bridges"] > 0 for run in runs)
            cells.append(f"{', '.join(plans) + '; ' if plans else ''}{counts}; {moved:.4f}"
                         + (f"; {bridged} bridged" if bridged else ""))
        rows.append(cells)
    lines += markdown_table(["model", "clean plan (bones)"] + [f"σ {100 * s:g}%" for s in sigmas], rows)
    remeshed = [record for record in records if "remeshed" in record]
    if remeshed:
        same = sum(record["remeshed"]["plan"] == record["plan"] for record in remeshed)
        moved = np.array([record["remeshed"]["moved"] for record in remeshed])
        lines += ["", "## Remeshed", "",
                  f"The RigNet models rigged as RigNet remeshed them (the same shape, other triangles) against the "
                  f"models as they are: the body plan the same on {same} / {len(remeshed)}, CD-B2B between the two "
                  f"skeletons {np.median(moved):.4f} median, {moved.max():.4f} at most; CD-J2J to the artist's "
                  f"joints {np.mean([r['cd_j2j'] for r in remeshed]):.4f} as they are, "
                  f"{np.mean([r['remeshed']['cd_j2j'] for r in remeshed]):.4f} remeshed.", ""]
        lines += markdown_table(
            ["model", "vertices (as is, remeshed)", "plan", "bones", "CD-B2B between", "CD-J2J as is → remeshed"],
            [[r["model"], "{:,} → {:,}".format(*r["remeshed"]["vertices"]),
              r["plan"] if r["remeshed"]["plan"] == r["plan"] else f"{r['plan']} → {r['remeshed']['plan']}",
              f"{r['bones']} → {r['remeshed']['bones']}", f"{r['remeshed']['moved']:.4f}",
              f"{r['cd_j2j']:.4f} → {r['remeshed']['cd_j2j']:.4f}"] for r in remeshed])
    return "\n".join(lines) + "\n"


def plot(records, sigmas, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [record["model"] for record in records]
    fig, ax = plt.subplots(figsize=(max(8, 0.35 * len(names)), 5))
    for k, sigma in enumerate(sigmas):
        for i, record in enumerate(records):
            moved = [run["moved"] for run in record["noisy"] if run["sigma"] == sigma]
            flipped = any(run["plan"] != record["plan"] for run in record["noisy"] if run["sigma"] == sigma)
            ax.scatter([i + (k - 1) * 0.25] * len(moved), moved, s=18, color=f"C{k}",
                       marker="x" if flipped else "o", label=f"σ {100 * sigma:g}%" if i == 0 else None)
    ax.axhline(MOVED, color="0.5", lw=0.8, ls="--")
    ax.set_yscale("log")
    ax.set_xticks(range(len(names)), names, rotation=70, ha="right", fontsize=7)
    ax.set_ylabel("CD-B2B to the clean skeleton (share of size)")
    ax.set_title("Skeleton moved by noise (x: body plan changed)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    subset_options(parser, "robustness")
    settings_option(parser)
    args = parser.parse_args(argv)
    params = method_params(args.settings)
    if not SHARED_MODELS.is_dir():
        raise SystemExit(f"No models at {SHARED_MODELS}: the robustness benchmark needs ../shared beside the checkout.")
    names = picked([name for name in sorted(MODELS) if model_path(name).exists()], args.models)
    out = results_folder(args, "robustness")
    run = run_record("robustness.py", argv)
    started = time.perf_counter()
    records = []
    for name in names:
        record = measure(name, params=params)
        records.append(record)
        print(f"{name:30s} {record['plan']:10s} {record['bones']:3d} bones; moved "
              + " ".join(f"{run['moved']:.3f}" for run in record["noisy"])
              + (f"; remeshed {record['remeshed']['moved']:.3f}" if "remeshed" in record else ""), flush=True)
    run["seconds"] = time.perf_counter() - started
    summary = summarised(records, SIGMAS)
    (out / "robustness.md").write_text(report(records, summary, run, SIGMAS), encoding="utf-8")
    plot(records, SIGMAS, out / "robustness.png")
    (out / "robustness.json").write_text(json.dumps(
        {"run": {**run, "started": run["started"].isoformat()}, "summary": summary, "records": records}, indent=1),
        encoding="utf-8")
    print(f"wrote {out / 'robustness.md'}")


if __name__ == "__main__":
    main()
