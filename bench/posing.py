"""Posing benchmark: how well rigs reproduce the artists' motion on the models in ../shared/models/gt.

Random poses of each artist rig deform the mesh with the artist's weights (the targets). Each rig under test is
fitted to every target (its bones rotate about their heads, parents first) and deforms the mesh with its own weights;
the leftover vertex error, in units of the mesh's largest bounding-box extent, says how well the rig can pose that
character. Rigs: the artist's own (a check: ≈ 0), the artist's skeleton skinned by Rigger, Rigger's skeleton skinned
by Rigger (the product), a 3-joint stick with nearest-bone weights (the floor), and the ``game`` output target as the
add-on builds and skins it, where the body plan fills it. Also measured: seam cracks, limb recall, mirror twins and
unsided bones of Rigger's skeleton. Writes posing.md, posing.png and posing.json.

    .venv/bin/python bench/posing.py [--models NAME ...] [--seed S] [--one-seed] [--jobs N] [--compare OLD.json]
                                     [--blender-frame]

A full run writes to bench/results; a run on ``--models`` writes to out/posing, and one with ``--blender-frame``
(Rigger rigs each file as Blender's OBJ importer reads it, turned, and its skeleton is turned back to be measured:
what a user gets) to out/posing-blender, unless ``--out`` says otherwise, so the committed results stay whole.
``--compare bench/results/posing.json`` prints each model's change against a run.
"""
import os

# One BLAS thread per process: the workers already fill the cores, and the fit's many small solves slow down
# tenfold when BLAS threads wait for each other on a busy machine (set before numpy loads; workers inherit it).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import argparse  # noqa: E402
import concurrent.futures  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import multiprocessing  # noqa: E402
import pathlib  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402

import numpy as np  # noqa: E402
from scipy.stats import spearmanr  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import posing_math as pm  # noqa: E402  (bench/ is not a package)
import rigdata  # noqa: E402
from benchkit import (REPO, SHARED_MODELS, cpu_model, described_commit, markdown_table, method_params,  # noqa: E402
                      picked, results_folder, settings_option, subset_options, table_cell)
from bodyplan import blender_turn  # noqa: E402
from quality import principal_stick  # noqa: E402
from rigger.blender.headless import temporary_user_folder  # noqa: E402  (bpy-free)
from rigger.core.targets import TARGETS  # noqa: E402

MODELS_DIR = SHARED_MODELS / "gt"
RIGS = {"artist": "artist rig", "artist_skin": "artist skeleton + Rigger skinning",
        "rigger": "Rigger's rig (skeleton + skinning)", "stick": "3-joint stick, nearest-bone weights"}
RIG_COLOURS = {"artist": "black", "artist_skin": "tab:blue", "rigger": "tab:red", "stick": "tab:gray"}
POSES, MAX_DEGREES = 12, 35.0
FLOOR = 1e-6  # zero drawn on a log axis
# The issue's targets and the figures it measured "now" (issue 28).
TARGET_EXCESS_MEAN, TARGET_EXCESS_MAX, TARGET_CRACK, TARGET_RECALL, TARGET_TWIN = 0.0012, 0.004, 0.002, 0.9, 0.005
ISSUE_NOW = {"artist": 0.0, "artist_skin": 0.0053, "rigger": 0.0081, "stick": 0.0495}


def measure(folder, seeds, poses=POSES, max_degrees=MAX_DEGREES, params=None, blender_frame=False):
    """Every measurement of one model (Rigger rigging it with the method parameters ``params``, default none, in
    Blender's frame when ``blender_frame``); failures of one rig or one step become text in the record."""
    started = time.perf_counter()
    vertices, triangles, rig = rigdata.load_ground_truth(folder)
    rig = rig.attached()  # posed as one tree: feet the artist drives by IK follow the leg
    size = float(np.ptp(vertices, axis=0).max())
    record = {"model": folder.name, "vertices": len(vertices), "artist_joints": len(rig.names), "errors": {},
              "skinning": {}, "seeds": {}}
    rigs = {"artist": pm.artist_rig(rig)}
    artist_skeleton = rigdata.armature_skeleton(rig)[0]
    skeletons = {"artist_skin": artist_skeleton}
    try:
        import rigger

        rig_started = time.perf_counter()
        axes = blender_turn(folder.name) if blender_frame else None
        skeletons["rigger"] = rigger.rig_mesh(vertices, triangles.astype(np.int32), axes=axes, **(params or {}))
        record["rig_seconds"] = time.perf_counter() - rig_started
    except Exception as error:  # the product failing on one model is a result, not a crash
        record["errors"]["rigger"] = f"rig_mesh: {type(error).__name__}: {error}"
    for kind, skeleton in skeletons.items():
        try:
            obj, report, _ = rigdata.skinned_mesh(folder.name, vertices, triangles, skeleton)
            rigs[kind] = pm.skinned_rig(obj, skeleton)
            record["skinning"][kind] = report.summary()
        except Exception as error:
            record["errors"][kind] = f"skinning: {type(error).__name__}: {error}"
    if "rigger" in skeletons and TARGETS["game"].unfit(skeletons["rigger"].body_plan) is None:
        try:  # the game target, as the add-on builds and skins it (a failure here is its own, not the product's)
            obj, report, bones = rigdata.skinned_mesh(folder.name, vertices, triangles, skeletons["rigger"], "game")
            rigs["game"] = pm.skinned_rig(obj, bones)
            record["game_bones"] = len(bones)
        except Exception as error:
            record["game_error"] = f"{type(error).__name__}: {error}"
    stick = principal_stick(vertices, triangles)[0]
    rigs["stick"] = pm.nearest_bone_rig(stick.heads, stick.tails, stick.parents, vertices)
    record["bones"] = {kind: len(skeleton) for kind, skeleton in skeletons.items()}
    record["setup_seconds"] = time.perf_counter() - started

    joint_names = np.array(rig.names + ("(unweighted)",))
    region = rigdata.dominant_joints(rig)  # the artist joint each vertex follows most: where an error is
    pairs = pm.coincident_pairs(vertices, size)
    faces = pm.proper_faces(vertices, triangles)
    record["seam_pairs"] = len(pairs)
    fitters = {kind: pm.Fitter(each, vertices) for kind, each in rigs.items()}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        targets = [pm.deformed(rigs["artist"], pose, vertices)
                   for pose in pm.random_poses(rigs["artist"], poses, max_degrees, rng)]
        results, vertex_errors = {}, {}
        for kind, fitter in fitters.items():
            errors, angles, gaps, steps = [], [], [], []
            for target in targets:
                pose, taken = fitter.fit(target)
                fitted = pm.deformed(fitter.rig, pose, vertices)
                errors.append(np.linalg.norm(fitted - target, axis=1) / size)
                angles.append(pm.normal_angles(fitted, target, triangles, faces))
                gaps.append(pm.crack(fitted, pairs))
                steps.append(taken)
            errors = np.array(errors)
            vertex_errors[kind] = errors.mean(axis=0)
            gap, pair = max(gaps)
            results[kind] = {
                "mean": float(errors.mean()), "p95": float(np.percentile(errors, 95)),
                "normal_degrees": float(np.mean(angles)), "crack": gap / size,
                "crack_at": str(joint_names[region[pairs[pair, 0]]]) if gap > 0 else "",
                "per_pose": errors.mean(axis=1).tolist(), "steps": float(np.mean(steps))}
        seed_record = {"rigs": results}
        if {"game", "artist_skin"} <= results.keys():
            seed_record["game_excess"] = results["game"]["mean"] - results["artist_skin"]["mean"]
        if {"rigger", "artist_skin"} <= results.keys():
            seed_record["excess"] = results["rigger"]["mean"] - results["artist_skin"]["mean"]
            seed_record["excess_normal_degrees"] = (results["rigger"]["normal_degrees"]
                                                    - results["artist_skin"]["normal_degrees"])
            excess = vertex_errors["rigger"] - vertex_errors["artist_skin"]
            totals = np.bincount(region, weights=excess, minlength=len(joint_names))
            counts = np.bincount(region, minlength=len(joint_names))
            worst = int(totals.argmax())  # the most excess in all: small regions with a large mean are noise
            seed_record["excess_at"] = {
                "joint": str(joint_names[worst]), "excess": float(totals[worst] / counts[worst]),
                "vertices": int(counts[worst]),
                "share": float(totals[worst] / max(np.maximum(excess, 0).sum(), 1e-300))}
        record["seeds"][str(seed)] = seed_record
    if "rigger" in skeletons:
        record["skeleton"] = skeleton_measures(rig, artist_skeleton, skeletons["rigger"], vertices, triangles, size)
    record["seconds"] = time.perf_counter() - started
    return record


def skeleton_measures(rig, artist_skeleton, skeleton, vertices, triangles, size):
    """Limb recall (and the artist skeleton's against itself, a check), twin mismatch and unsided bones."""
    names = np.array(rig.names)
    recall, outcome = pm.limb_recall(rig.positions, rig.parents, skeleton.heads, skeleton.tails, skeleton.parents,
                                     size)
    own_recall = pm.limb_recall(rig.positions, rig.parents, artist_skeleton.heads, artist_skeleton.tails,
                                artist_skeleton.parents, size)[0]
    surface = pm.mirror_surface(vertices, triangles)
    plane = pm.mirror_plane(vertices, triangles, size, surface)
    twins = pm.twin_mismatches(skeleton.names, skeleton.heads, skeleton.tails, plane, size)
    unsided = pm.unsided_off_plane(skeleton.names, skeleton.heads, skeleton.tails, plane, size)
    bone = {name: k for k, name in enumerate(skeleton.names)}
    measured = [bone[f"{base}.L"] for base in twins] + [bone[name] for name in unsided]
    local = pm.local_asymmetry(vertices, surface, plane, skeleton.heads, skeleton.tails, measured, size)
    return {"limb_recall": recall, "chains": len(outcome), "own_recall": own_recall,
            "missed": [str(names[chain[-1]]) for chain, followed in outcome if not followed],
            "plane": {"axis": "XYZ"[plane.axis], "asymmetry": plane.asymmetry, "two_sided": plane.two_sided()},
            "twins": twins, "unsided": unsided if plane.two_sided() else None,
            "mesh_asymmetry": {skeleton.names[k]: value for k, value in local.items()}}


def measured(folder, seeds, poses, max_degrees, params, blender_frame):
    """``measure`` for a worker process: never raises, so one model cannot stop the run."""
    temporary_user_folder()
    try:
        return measure(folder, seeds, poses, max_degrees, params, blender_frame)
    except Exception as error:
        return {"model": folder.name, "failed": f"{type(error).__name__}: {error}",
                "traceback": traceback.format_exc(limit=-4)}


# --- summaries -----------------------------------------------------------------------------------------------------

def complete(records):
    """The records with every rig measured (the only ones averaged)."""
    return [r for r in records if "failed" not in r and not r["errors"]]


def seed_figures(records, seed):
    return [r["seeds"][str(seed)] for r in records]


def worst(pairs, count=3, digits=3):
    """``[(model, value)]`` as text, largest first."""
    ordered = sorted(pairs, key=lambda pair: -pair[1])[:count]
    return ", ".join(f"{model} {value:.{digits}f}" for model, value in ordered)


def summarise(records, seeds):
    """Averages, target figures and seed agreement over the complete records."""
    good = complete(records)
    first = str(seeds[0])
    summary = {"models": len(good), "incomplete": [r["model"] for r in records if r not in good]}
    if not good:
        return summary
    for seed in seeds:
        figures = seed_figures(good, seed)
        summary[f"seed {seed}"] = {kind: {key: float(np.mean([f["rigs"][kind][key] for f in figures]))
                                          for key in ("mean", "p95", "normal_degrees")} for kind in RIGS}
        summary[f"seed {seed}"]["excess"] = float(np.mean([f["excess"] for f in figures]))
        summary[f"seed {seed}"]["excess_normal_degrees"] = float(np.mean([f["excess_normal_degrees"]
                                                                          for f in figures]))
    excess = [(r["model"], r["seeds"][first]["excess"]) for r in good]
    cracks = [(r["model"], r["seeds"][first]["rigs"]["rigger"]["crack"]) for r in good]
    recall = [(r["model"], r["skeleton"]["limb_recall"]) for r in good]
    twins = [(r["model"], name, value) for r in good for name, value in r["skeleton"]["twins"].items()]
    unsided = [(r["model"], name) for r in good for name in (r["skeleton"]["unsided"] or [])]
    asymmetry = {(r["model"], name): value for r in good for name, value in r["skeleton"]["mesh_asymmetry"].items()}
    summary.update({
        "excess_mean": float(np.mean([value for _, value in excess])),
        "excess_over": [(m, v) for m, v in excess if v > TARGET_EXCESS_MAX],
        "cracks_over": [(m, v) for m, v in cracks if v > TARGET_CRACK],
        "recall_mean": float(np.mean([value for _, value in recall])),
        "recall_low": sorted(recall, key=lambda pair: pair[1])[:3],
        "twins_over": [(m, n, v) for m, n, v in twins if v > TARGET_TWIN], "twin_pairs": len(twins),
        "twins_over_mirrored": [(m, n, v) for m, n, v in twins if v > TARGET_TWIN
                                and asymmetry[(m, f"{n}.L")] <= TARGET_TWIN],
        "unsided": unsided, "two_sided": sum(r["skeleton"]["plane"]["two_sided"] for r in good),
        "unsided_mirrored": [(m, n) for m, n in unsided if asymmetry[(m, n)] <= TARGET_TWIN],
        "asymmetry": {f"{m} {n}": v for (m, n), v in asymmetry.items()},
        "rigger_bones": sum(r["bones"]["rigger"] for r in good),
        "excess_vs_recall": float(spearmanr([v for _, v in excess], [v for _, v in recall])[0]),
    })
    games = [r for r in good if "game_excess" in r["seeds"][first]]
    failed = [r["model"] for r in good if "game_error" in r]
    if games or failed:
        game = [(r["model"], r["seeds"][first]["game_excess"]) for r in games]
        summary["game"] = {"models": len(games), "failed": failed,
                           "excess_mean": float(np.mean([v for _, v in game])) if game else float("nan"),
                           "rigger_excess_mean": float(np.mean([r["seeds"][first]["excess"] for r in games]))
                           if games else float("nan"), "worst": sorted(game, key=lambda pair: -pair[1])[:3]}
    per_pose = [np.subtract(r["seeds"][first]["rigs"]["rigger"]["per_pose"],
                            r["seeds"][first]["rigs"]["artist_skin"]["per_pose"]) for r in good]
    summary["excess_standard_error"] = float(np.mean([np.std(each, ddof=1) / np.sqrt(len(each)) if len(each) > 1
                                                      else np.nan for each in per_pose]))
    if len(seeds) > 1:
        other = str(seeds[1])
        a = np.array([r["seeds"][first]["excess"] for r in good])
        b = np.array([r["seeds"][other]["excess"] for r in good])
        product_a = np.array([r["seeds"][first]["rigs"]["rigger"]["mean"] for r in good])
        product_b = np.array([r["seeds"][other]["rigs"]["rigger"]["mean"] for r in good])
        summary["seed_agreement"] = {
            "excess_spearman": float(spearmanr(a, b)[0]), "excess_mean_abs_difference": float(np.abs(a - b).mean()),
            "excess_largest_difference": float(np.abs(a - b).max()),
            "product_spearman": float(spearmanr(product_a, product_b)[0]),
            "product_mean_abs_difference": float(np.abs(product_a - product_b).mean())}
    return summary


# --- report --------------------------------------------------------------------------------------------------------

def verdict(passed):
    return "PASS" if passed else "FAIL"


def target_rows(summary):
    over_excess = summary["excess_over"]
    over_cracks = summary["cracks_over"]
    twins_over = summary["twins_over"]
    unsided = summary["unsided"]
    asymmetry = summary["asymmetry"]
    twin_text = (f"{len(twins_over)} of {summary['twin_pairs']} pairs above; worst "
                 + ", ".join(f"{m} {n} {v:.3f}" for m, n, v in sorted(twins_over, key=lambda t: -t[2])[:3])
                 + _where_mirrored(len(summary["twins_over_mirrored"]), len(twins_over),
                                   [asymmetry[f"{m} {n}.L"] for m, n, _ in twins_over])
                 if twins_over else f"all {summary['twin_pairs']} pairs within")
    unsided_models = sorted({model for model, _ in unsided})
    return [
        [f"excess posing error ≤ {TARGET_EXCESS_MEAN} on average", "0.0028", f"{summary['excess_mean']:.4f}",
         verdict(summary["excess_mean"] <= TARGET_EXCESS_MEAN)],
        [f"excess posing error ≤ {TARGET_EXCESS_MAX} on every model",
         "7 above; worst rignet_8338 0.010, rignet_11814 0.0067, rignet_2586 0.0064",
         f"{len(over_excess)} above; worst {worst(over_excess, digits=4)}" if over_excess else "none above",
         verdict(not over_excess)],
        [f"seam cracks ≤ {TARGET_CRACK} of size on every model",
         "8 models above; worst Husky 0.107, magicarticulate 0.098, rignet_smith 0.089",
         f"{len(over_cracks)} models above; worst {worst(over_cracks)}" if over_cracks else "none above",
         verdict(not over_cracks)],
        [f"limb recall ≥ {TARGET_RECALL} on average", "0.81; Deer 0.29, rignet_2586 0.17",
         f"{summary['recall_mean']:.2f}; " + ", ".join(f"{m} {v:.2f}" for m, v in summary["recall_low"]),
         verdict(summary["recall_mean"] >= TARGET_RECALL)],
        [f"twin mismatch ≤ {TARGET_TWIN} of size for every `.L`/`.R` pair", "—", twin_text,
         verdict(not twins_over)],
        ["no unsided off-plane bones on two-sided bodies", "—",
         f"{len(unsided)} of {summary['rigger_bones']} bones on {len(unsided_models)} of {summary['two_sided']} "
         f"two-sided models" + _where_mirrored(len(summary["unsided_mirrored"]), len(unsided),
                                               [asymmetry[f"{m} {n}"] for m, n in unsided])
         if unsided else "none", verdict(not unsided)],
    ]


def game_section(records, summary, seeds):
    """The game target's lines: its excess beside Rigger's own rig's, on the models whose plan it fills."""
    game = summary.get("game")
    if game is None:
        return []
    first = str(seeds[0])
    lines = ["", "## The game target", "",
             "The `game` output target as the add-on makes it (`rigger.core.game`: one bone per role, Mixamo's names, "
             f"a root that deforms nothing; bone heat on its own bones, at most 4 weights per vertex), on the "
             f"{game['models']} models whose body plan it fills, fitted to the same poses (seed {seeds[0]}). Its "
             f"excess over the artist skeleton with Rigger's skinning is **{game['excess_mean']:.4f}** on average "
             f"(Rigger's own rig on these models: {game['rigger_excess_mean']:.4f}); worst "
             f"{worst(game['worst'], digits=4)}. It has fewer bones than Rigger's skeleton (a humanoid's limbs are "
             f"one bone per role, as engines expect), so it follows the artist's poses less closely."
             + (f" Failed: {', '.join(game['failed'])}." if game["failed"] else ""), ""]
    rows = [[r["model"], f"{r['bones']['rigger']} / {r['game_bones']}", f"{r['seeds'][first]['excess']:+.4f}",
             f"{r['seeds'][first]['game_excess']:+.4f}"]
            for r in complete(records) if "game_excess" in r["seeds"][first]]
    return lines + markdown_table(["model", "bones Rigger / game", "excess Rigger", "excess game"], rows)


def _where_mirrored(mirrored, count, asymmetries):
    """How many of ``count`` bones measured against a target lie where the mesh itself mirrors within
    ``TARGET_TWIN`` (``posing_math.local_asymmetry``; the others' part of the mesh does not mirror)."""
    if mirrored == count:
        return ""
    if not mirrored:
        low, high = f"{min(asymmetries):.3f}", f"{max(asymmetries):.3f}"
        spread = low if low == high else f"{low}–{high}"
        return f"; all on parts the mesh itself does not mirror (its asymmetry there {spread})"
    return f"; {count - mirrored} of them on parts the mesh itself does not mirror"


def model_rows(records, seeds):
    first = str(seeds[0])
    rows = []
    for r in records:
        if "failed" in r:
            rows.append([r["model"]] + [""] * 13 + [f"**failed**: {table_cell(r['failed'])}"])
            continue
        figures = r["seeds"][first]["rigs"]
        cells = [r["model"], f"{r['vertices']:,}", f"{r['artist_joints']} / {r['bones'].get('rigger', '—')}"]
        cells += [f"{figures[kind]['mean']:.4f}" if kind in figures else "—" for kind in RIGS]
        if "excess" in r["seeds"][first]:
            cells += [f"{r['seeds'][str(seed)]['excess']:+.4f}" for seed in seeds]
            cells += [f"{figures['rigger']['p95']:.4f}",
                      f"{figures['artist_skin']['normal_degrees']:.1f} / {figures['rigger']['normal_degrees']:.1f}",
                      f"{figures['artist_skin']['crack']:.4f} / {figures['rigger']['crack']:.4f}"]
        else:
            cells += ["—"] * (len(seeds) + 3)
        skeleton = r.get("skeleton")
        if skeleton:
            twins = skeleton["twins"]
            cells += [f"{skeleton['limb_recall']:.2f} ({skeleton['chains']})",
                      f"{max(twins.values()):.4f} ({len(twins)})" if twins else "no pairs",
                      "not two-sided" if skeleton["unsided"] is None else str(len(skeleton["unsided"]))]
        else:
            cells += ["—"] * 3
        cells.append(table_cell("; ".join(r["errors"].values())))
        rows.append(cells)
    return rows


def crack_cell(figures, seam_pairs):
    if not seam_pairs:
        return "no shared positions"
    return f"{figures['crack_at']} ({figures['crack']:.4f})" if figures["crack_at"] else "none"


def where_rows(records, seeds):
    """Per model, where each problem is: the artist joint whose vertices carry the most excess error, the joint at
    the widest crack, the artist chains Rigger missed (by leaf joint), the worst twin pair, the unsided bones."""
    first = str(seeds[0])
    rows = []
    for r in complete(records):
        figures = r["seeds"][first]
        at = figures["excess_at"]
        skeleton = r["skeleton"]
        twins = skeleton["twins"]
        twin = max(twins, key=twins.get) if twins else ""
        rows.append([r["model"], f"{at['joint']} ({at['share']:.0%}; {at['excess']:+.4f} on {at['vertices']} vertices)",
                     crack_cell(figures["rigs"]["rigger"], r["seam_pairs"]),
                     table_cell(", ".join(skeleton["missed"]) or "—", 200),
                     f"{twin} ({twins[twin]:.4f})" if twin else "—",
                     table_cell(", ".join(skeleton["unsided"] or []) or "—", 200),
                     f"{skeleton['plane']['axis']} ({skeleton['plane']['asymmetry']:.4f})"])
    return rows


def report(records, summary, run):
    import bpy

    seeds = run["seeds"]
    first = f"seed {seeds[0]}"
    lines = [
        "# Posing benchmark (issue 28)", "",
        f"Generated by `{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC in {run['seconds']:.0f} s "
        f"({run['jobs']} processes); rigger at `{described_commit()}`.", "",
        f"- Machine: {cpu_model()}, {os.cpu_count()} cores shared with other agents (load average "
        f"{', '.join(f'{v:.2f}' for v in run['load'])} before, {', '.join(f'{v:.2f}' for v in run['load_after'])} "
        f"after); Blender {bpy.app.version_string} as the `bpy` module, Python {platform.python_version()}, numpy "
        f"{np.__version__}.",
        f"- Models: {len(records)} from `../shared/models/gt` (helper joints dropped; a part the artist keeps as a "
        "root of its own, such as the IK-driven feet of the Quaternius rigs, hangs from the nearest joint under the "
        "root, for the poses and for the artist skeleton alike: `rigdata.Rig.attached`)"
        + ("; filtered by `--models`" if run["filtered"] else "") + ". Sizes are fractions of the mesh's largest "
        "bounding-box extent.",
        f"- Poses: {run['poses']} per seed; every artist joint turns about its own position by an angle uniform in "
        f"[0°, {run['max_degrees']:g}°] about a uniformly random axis, applied down the hierarchy; the mesh is "
        "deformed with the artist's weights (linear blend skinning; a leaf joint's weight moves with its parent). "
        f"Seeds {', '.join(map(str, seeds))}: the first gives the figures below, the second their variability.",
        "- Fit: each bone of the rig under test turns about its own head and carries its children; a root bone may "
        "also move (as in Blender). A first pass fits each bone, parents first, by weighted Procrustes to the "
        "vertices it dominates; Levenberg-Marquardt steps then minimise the rig's own linear-blend-skinning error "
        "over all bones at once (`posing_math.Fitter`). The artist rig fitted to its own poses lands at 0, which "
        "checks the fit.",
        "- Rigs: " + "; ".join(f"**{kind}** = {label}" for kind, label in RIGS.items()) + ". Rigger's skinning is "
        "`rigger.blender.skinning.skin` on the mesh as the OBJ has it (UV-seam duplicates kept); Rigger's skeleton "
        "is `rigger.rig_mesh` with the defaults" + (", on each file as Blender's OBJ importer reads it (the mesh "
        "turned for the method, the skeleton turned back: `--blender-frame`)" if run["blender_frame"] else "")
        + ". The stick is the quality benchmark's (principal axis, jointed at "
        "its middle).",
        "- Error: distance from each fitted vertex to its target; mean and 95th percentile over all vertices and "
        "poses. Normal angle: angle between fitted and target face normals, mean over faces (non-degenerate at "
        "rest) and poses. **Excess** = Rigger's rig minus the artist skeleton with Rigger's skinning, on the same "
        "poses (the skeleton's own cost).",
        f"- Seam cracks: the largest distance over poses between two vertices that share a rest position (closer "
        f"than {pm.COINCIDENT:g} of size), after the fit. Limb recall: share of the artist's chains from a branch "
        f"joint or the root to a leaf that some path of Rigger's bones from a leaf bone to the root follows within "
        f"{pm.FOLLOWS} on average (points every {pm.CHAIN_STEP} along the chain). Mirror plane: of the axis planes, "
        f"each at the offset within {pm.PLANE_SEARCH} of the bounding box's centre the mesh is most symmetric about, "
        f"the one it is most symmetric about relative to its extent across the plane (asymmetry: the median "
        f"distance from a mirrored vertex to the surface's vertices, edge midpoints and face centres); two-sided "
        f"when that asymmetry is ≤ {pm.MIRROR_SYMMETRIC}. Twin mismatch: per `.L`/`.R` pair, the larger distance "
        f"between a head (tail) and the mirror image of its twin's. Unsided: bones without `.L`/`.R` whose midpoint "
        f"is more than {pm.OFF_PLANE} off the plane of a two-sided body. Both targets are judged on every bone; "
        f"beside them, how many lie on parts the mesh itself does not mirror within {TARGET_TWIN} (the median "
        f"distance from the mirror images of the vertices nearest the bone to the surface): a figure posed with one "
        f"arm raised, a tail curled to one side, where no rig can mirror.",
        "", "## Rigs", "",
    ]
    if not summary["models"]:
        return "\n".join(lines + ["No model was measured completely."]) + "\n"
    rig_rows = []
    for kind, label in RIGS.items():
        rig_rows.append([label, f"{ISSUE_NOW[kind]:.4f}"]
                        + [f"{summary[f'seed {seed}'][kind]['mean']:.4f}" for seed in seeds]
                        + [f"{summary[first][kind]['p95']:.4f}", f"{summary[first][kind]['normal_degrees']:.2f}°"])
    rig_rows.append(["**excess** (Rigger's rig − artist skeleton + Rigger skinning)", "0.0028"]
                    + [f"**{summary[f'seed {seed}']['excess']:.4f}**" for seed in seeds]
                    + ["", f"{summary[first]['excess_normal_degrees']:+.2f}°"])
    lines += markdown_table(["rig", "issue's \"now\""] + [f"mean error, seed {seed}" for seed in seeds]
                            + ["95th percentile", "normal angle"], rig_rows)
    lines += ["", f"Means over the {summary['models']} models measured with every rig"
              + (f" (incomplete: {', '.join(summary['incomplete'])})" if summary["incomplete"] else "") + "."]
    variability = (f"Variability: the fit is deterministic, so it is the poses'. Within seed {seeds[0]}, a model's "
                   f"excess has a standard error over its {run['poses']} poses of "
                   f"{summary['excess_standard_error']:.4f} on average.")
    if "seed_agreement" in summary:
        agreement = summary["seed_agreement"]
        variability += (f" Between seeds {seeds[0]} and {seeds[1]} (other poses, same rigs): per-model excess rank "
                        f"correlation (Spearman) {agreement['excess_spearman']:.2f}, mean absolute difference "
                        f"{agreement['excess_mean_abs_difference']:.4f} (largest "
                        f"{agreement['excess_largest_difference']:.4f}); Rigger's own error rank correlation "
                        f"{agreement['product_spearman']:.2f}, mean absolute difference "
                        f"{agreement['product_mean_abs_difference']:.4f}.")
    lines += ["", variability]
    lines += ["", f"Excess against limb recall, rank correlation over models: {summary['excess_vs_recall']:.2f}. "
              f"The artist skeleton's limb recall against itself: "
              f"{min(r['skeleton']['own_recall'] for r in complete(records)):.2f} at worst (a check)."]
    lines += ["", "## Targets (issue 28)", ""]
    lines += markdown_table(["target", "issue's \"now\"", "measured", ""], target_rows(summary))
    lines += game_section(records, summary, seeds)
    lines += ["", "![excess error, cracks, limb recall, twins per model](posing.png)", "", "## Per model", "",
              f"Errors in units of size, seed {seeds[0]} (excess also seed {seeds[1]})." if len(seeds) > 1 else
              f"Errors in units of size, seed {seeds[0]}.", ""]
    lines += markdown_table(
        ["model", "vertices", "joints artist / Rigger bones"] + [f"{kind} mean" for kind in RIGS]
        + [f"excess (seed {seed})" for seed in seeds]
        + ["Rigger p95", "normal ° artist_skin / rigger", "crack artist_skin / rigger", "limb recall (chains)",
           "twin mismatch, worst (pairs)", "unsided off-plane", "notes"], model_rows(records, seeds))
    lines += ["", "## Where", "",
              "Excess at: the artist joint whose vertices (by their largest artist weight) carry the most excess error "
              "in all; its share of the excess summed over the vertices where that is positive; the mean excess on "
              "its vertices. Crack at: the artist joint of the widest crack's vertices. Missed chains: by their leaf "
              "joint. Plane: the mirror axis and the mesh's asymmetry about it.", ""]
    lines += markdown_table(["model", "excess at", "crack at (rigger)", "missed chains", "worst twin pair",
                             "unsided off-plane bones", "plane"], where_rows(records, seeds))
    return "\n".join(lines) + "\n"


def plot(records, seeds, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    good = complete(records)
    names = [r["model"] for r in good]
    first = str(seeds[0])
    positions = np.arange(len(good))
    figure, grid = plt.subplots(3, 2, figsize=(17, 15))
    axes = grid.ravel()

    width = 0.8 / 3
    for offset, kind in zip((-width, 0.0, width), ("artist_skin", "rigger", "stick")):
        axes[0].bar(positions + offset, [r["seeds"][first]["rigs"][kind]["mean"] for r in good], width,
                    color=RIG_COLOURS[kind], label=RIGS[kind])
    axes[0].set_yscale("log")
    axes[0].set_title("Mean vertex error after the fit (the artist rig's own is ≈ 0, not drawn)", pad=40)

    axes[1].bar(positions, [r["seeds"][first]["excess"] for r in good], 0.6, color="tab:red",
                label=f"excess, seed {seeds[0]}")
    if len(seeds) > 1:
        axes[1].scatter(positions, [r["seeds"][str(seeds[1])]["excess"] for r in good], color="black", s=12,
                        zorder=3, label=f"seed {seeds[1]}")
    axes[1].axhline(TARGET_EXCESS_MAX, color="black", linestyle="--", linewidth=1, label="per-model target")
    axes[1].axhline(TARGET_EXCESS_MEAN, color="grey", linestyle=":", linewidth=1, label="mean target")
    axes[1].axhline(0.0, color="black", linewidth=0.5)
    axes[1].set_title("Excess error: Rigger's rig − artist skeleton with Rigger's skinning", pad=40)

    width = 0.4
    for offset, kind in zip((-width / 2, width / 2), ("artist_skin", "rigger")):
        axes[2].bar(positions + offset, [max(r["seeds"][first]["rigs"][kind]["crack"], FLOOR) if r["seam_pairs"]
                                         else np.nan for r in good], width, color=RIG_COLOURS[kind], label=RIGS[kind])
    axes[2].axhline(TARGET_CRACK, color="black", linestyle="--", linewidth=1, label="target")
    axes[2].set_yscale("log")
    axes[2].set_title(f"Seam cracks: widest gap between vertices sharing a rest position (0 drawn at {FLOOR:g}; "
                      "no bar: no such vertices)", fontsize=10, pad=40)

    axes[3].bar(positions, [r["skeleton"]["limb_recall"] for r in good], 0.6, color="tab:green")
    axes[3].axhline(TARGET_RECALL, color="black", linestyle="--", linewidth=1, label="mean target")
    axes[3].set_ylim(0, 1.05)
    axes[3].set_title("Limb recall: share of the artist's leaf chains a Rigger path follows", pad=40)

    twins = [max(max(r["skeleton"]["twins"].values()), FLOOR) if r["skeleton"]["twins"] else np.nan for r in good]
    axes[4].bar(positions, twins, 0.6, color="tab:purple", label="worst .L/.R pair")
    axes[4].axhline(TARGET_TWIN, color="black", linestyle="--", linewidth=1, label="target")
    axes[4].set_yscale("log")
    axes[4].set_title(f"Twin mismatch (0 drawn at {FLOOR:g}; no bar: no .L/.R pairs)", pad=40)

    for offset, kind in zip((-width / 2, width / 2), ("artist_skin", "rigger")):
        axes[5].bar(positions + offset, [r["seeds"][first]["rigs"][kind]["normal_degrees"] for r in good], width,
                    color=RIG_COLOURS[kind], label=RIGS[kind])
    axes[5].set_title("Face-normal angle error (degrees)", pad=40)
    for each in axes:
        each.set_xticks(positions, names, rotation=70, ha="right", fontsize=7)
        each.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.01), ncol=4)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)


def comparison_lines(records, seeds, previous_path):
    """Each model's excess, crack, limb recall and worst twin against a previous run's JSON."""
    previous = {r["model"]: r for r in json.loads(pathlib.Path(previous_path).read_text())["records"]}

    def figures(record):
        if not record or "failed" in record or record.get("errors"):
            return None
        seed = str(seeds[0]) if str(seeds[0]) in record["seeds"] else next(iter(record["seeds"]))
        twins = record["skeleton"]["twins"]
        return (record["seeds"][seed]["excess"], record["seeds"][seed]["rigs"]["rigger"]["crack"],
                record["skeleton"]["limb_recall"], max(twins.values()) if twins else float("nan"))

    lines = [f"{'model':32s} {'excess':>17s} {'crack':>17s} {'limb recall':>13s} {'twin':>17s}  (then → now)"]
    for record in records:
        now, then = figures(record), figures(previous.get(record["model"]))
        if now is None or then is None:
            lines.append(f"{record['model']:32s} not comparable")
            continue
        lines.append(f"{record['model']:32s} {then[0]:+.4f} → {now[0]:+.4f} {then[1]:.4f} → {now[1]:.4f} "
                     f"{then[2]:.2f} → {now[2]:.2f} {then[3]:.4f} → {now[3]:.4f}")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    subset_options(parser, "posing")
    parser.add_argument("--seed", type=int, default=0, help="first seed (default 0); the second is seed + 1")
    parser.add_argument("--one-seed", action="store_true", help="only the first seed (no variability figures)")
    parser.add_argument("--poses", type=int, default=POSES, help=f"poses per seed (default {POSES})")
    parser.add_argument("--max-angle", type=float, default=MAX_DEGREES,
                        help=f"largest turn of a joint, degrees (default {MAX_DEGREES:g})")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    parser.add_argument("--compare", type=pathlib.Path, help="a previous run's posing.json to compare against")
    settings_option(parser)
    parser.add_argument("--blender-frame", action="store_true",
                        help="Rigger rigs each file as Blender's OBJ importer reads it (default out/posing-blender)")
    args = parser.parse_args(argv)
    if args.blender_frame and not args.out:
        args.out = REPO / "out" / "posing-blender"
    params = method_params(args.settings)
    if not MODELS_DIR.is_dir():
        raise SystemExit(f"No models at {MODELS_DIR}: the posing benchmark needs ../shared beside the checkout.")
    if args.poses < 1 or args.jobs < 1:
        raise SystemExit("--poses and --jobs must be at least 1.")
    folders = picked(sorted(path for path in MODELS_DIR.iterdir() if path.is_dir()), args.models,
                     lambda path: path.name)
    out = results_folder(args, "posing")
    seeds = [args.seed] if args.one_seed else [args.seed, args.seed + 1]
    temporary_user_folder()
    run = {"command": "python bench/posing.py" + (" " + " ".join(argv if argv is not None else sys.argv[1:])).rstrip(),
           "started": datetime.datetime.now(datetime.timezone.utc), "load": os.getloadavg(), "seeds": seeds,
           "poses": args.poses, "max_degrees": args.max_angle, "jobs": args.jobs, "filtered": bool(args.models),
           "blender_frame": args.blender_frame}
    started = time.perf_counter()
    records = []
    context = multiprocessing.get_context("spawn")  # bpy in each worker of its own, never forked
    with concurrent.futures.ProcessPoolExecutor(args.jobs, mp_context=context) as pool:
        largest_first = sorted(folders, key=obj_size, reverse=True)  # the long pole starts first
        futures = [pool.submit(measured, folder, seeds, args.poses, args.max_angle, params, args.blender_frame)
                   for folder in largest_first]
        for future in concurrent.futures.as_completed(futures):
            record = future.result()
            records.append(record)
            print(progress_line(record, seeds), flush=True)
    records.sort(key=lambda r: r["model"])
    run["seconds"] = time.perf_counter() - started
    run["load_after"] = os.getloadavg()
    summary = summarise(records, seeds)
    (out / "posing.md").write_text(report(records, summary, run), encoding="utf-8")
    (out / "posing.json").write_text(json.dumps(
        {"run": {**run, "started": run["started"].isoformat(), "machine": cpu_model(), "commit": described_commit()},
         "summary": summary, "records": records}, indent=1), encoding="utf-8")
    if summary["models"]:
        plot(records, seeds, out / "posing.png")
        print(f"excess {summary['excess_mean']:.4f} (target {TARGET_EXCESS_MEAN}); "
              + ", ".join(f"{kind} {summary[f'seed {seeds[0]}'][kind]['mean']:.4f}" for kind in RIGS))
    if args.compare:
        print("\n".join(comparison_lines(records, seeds, args.compare)))
    print(f"wrote {out / 'posing.md'}, posing.json, posing.png in {run['seconds']:.0f} s")
    return 1 if any("failed" in r for r in records) else 0


def obj_size(folder):
    path = folder / f"{folder.name}.obj"
    return path.stat().st_size if path.is_file() else 0


def progress_line(record, seeds):
    if "failed" in record:
        return f"{record['model']:32s} FAILED {record['failed']}"
    figures = record["seeds"][str(seeds[0])]
    text = " ".join(f"{kind} {figures['rigs'][kind]['mean']:.4f}" for kind in RIGS if kind in figures["rigs"])
    if "excess" in figures:
        text += f"  excess {figures['excess']:+.4f}  crack {figures['rigs']['rigger']['crack']:.4f}"
    if "skeleton" in record:
        text += f"  recall {record['skeleton']['limb_recall']:.2f}"
    errors = "; ".join(record["errors"].values())
    return f"{record['model']:32s} {text}  {record['seconds']:.0f} s" + (f"  ERRORS {errors}" if errors else "")


if __name__ == "__main__":
    sys.exit(main())
