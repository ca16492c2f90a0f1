"""Rigify benchmark: the ``rigify`` output target on every ../shared model (gt and nogt) and every sample character
(issue 29, item 4: "Rigify generate succeeds on every recognised humanoid and quadruped"; every vertex weighted and
no seam cracks).

Each model is read as Blender reads it (``bench/bodyplan.py``'s ``load``: an OBJ up Y, forward -Z; the Z-up OBJs up
Z) into a mesh object in a fresh scene, rigged with ``rigger.blender.pipeline.rig_object(target="rigify")`` and
skinned with ``skin_meshes``, as the panel and the command line do. The sample characters are built with
``rigger.blender.samples``. Per model:

- the body plan, the target built (``plain`` when the plan falls back) and the metarig;
- fit: ``core.metarig.fit_metarig`` alone, on a fresh copy of the metarig (bpy-free, milliseconds); build: the
  whole target (metarig added, fitted, generated); regenerate: Rigify's Generate Rig again from the kept metarig
  after moving one of its bones, as a user editing the metarig does (must succeed and keep the mesh bound);
- DEF bones, vertices weighted (every vertex has a DEF weight), vertex groups that are not DEF bones (must be 0),
  seam gap: the largest weight difference between vertices at one place (0: a seam cannot crack); rest: how far
  the skinned mesh, nothing posed, lies from the mesh as it was (the largest vertex distance, in mesh sizes); the
  share of Rigify's pelvis and breast deform bones inside the mesh (they deform the body from inside);
- IK: each IK limb's control moved 30% of the limb's reach towards the limb's root: the middle joint (knee, elbow)
  must move the way the metarig bends it (knees and rear knees forward, elbows and front elbows back, in the
  rig's frame): limbs right / limbs tried;
- a failure reason when the target could not be built.

    .venv/bin/python bench/rigify_target.py [--models NAME ...] [--out DIR]

Writes rigify.md, rigify.json, rigify.png (every generated rig's DEF bones on its mesh, from the front and the side) and
rigify_pose.png (the sample humanoid posed by its IK controls, a knee raised and an elbow bent, Workbench render) to
bench/results (or ``--out``; a run on ``--models`` writes to out/rigify unless told otherwise).
"""
import argparse
import json
import os
import pathlib
import platform
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from benchkit import (SHARED_MODELS, markdown_table, picked, results_folder, run_record,  # noqa: E402
                      subset_options, table_cell)
from rigger.blender.headless import temporary_user_folder  # noqa: E402  (bpy-free)

IK_REACH = 0.3  # share of a limb's reach its IK control moves towards the limb's root
REST_TOLERANCE = 1e-3  # a skinned mesh at rest within this share of its size of the mesh as it was is undeformed
HELPERS_INSIDE = 0.9  # Rigify's pelvis and breast deform the body from inside it: this share of them at least
RIGIFY_PLANS = ("humanoid", "quadruped")


def model_names():
    """The ../shared models (bench/bodyplan.py's hand-labelled list) and the sample characters."""
    from bodyplan import MODELS
    from rigger import samples

    return [("shared", name) for name in sorted(MODELS)] + [("sample", name) for name in samples.CHARACTERS]


def mesh_object(source, name):
    """A mesh object for model ``name`` in a fresh empty scene."""
    import bpy
    from rigger.blender.headless import empty_scene

    empty_scene()
    if source == "sample":
        from rigger.blender.samples import build_character

        return build_character(name)
    from bodyplan import load

    vertices, triangles, _, _ = load(name)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], triangles.tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def measure(source, name):
    """Everything measured on one model (errors become the record's ``error``)."""
    from rigger.blender import rigify
    from rigger.blender.meshdata import combined_arrays, evaluated_vertices
    from rigger.blender.pipeline import rig_object, skin_meshes

    record = {"model": name, "source": source}
    try:
        obj = mesh_object(source, name)
        record["vertices"] = len(obj.data.vertices)
        result = rig_object(obj, "silhouette", target="rigify")
        plan = result.skeleton.body_plan
        record.update(plan=plan.kind, target=result.target.name, warnings=result.warnings,
                      build_seconds=result.timings["armature"], rig_seconds=result.timings["rig"])
        if result.target.name != "rigify":
            return record
        rig = result.armature
        metarig = rig[rigify.METARIG_PROPERTY]
        record["metarig"] = metarig_name = metarig[rigify.KIND_PROPERTY]
        mesh = combined_arrays([obj])
        record["fit_seconds"] = fit_seconds(result.skeleton, mesh, metarig_name)
        record["def_bones"] = len(result.bones)
        record["helpers_inside"] = helpers_inside(result.bones, mesh)
        rest = evaluated_vertices(obj)
        outcomes, _ = skin_meshes([obj], rig)
        record["skin_seconds"] = outcomes[obj.name].seconds
        record.update(weights(obj))
        record["rest_error"] = rest_error(obj, rest)
        record["ik"] = ik_bends(rig, metarig)
        record["regenerate_seconds"], record["regenerated_bound"] = regenerate(rig, metarig, obj)
        record["drawing"] = drawing(obj, rig)
    except Exception as error:  # one model failing must not stop the benchmark
        record["error"] = f"{type(error).__name__}: {error}"
    return record


def fit_seconds(skeleton, mesh, metarig_name):
    """Seconds ``fit_metarig`` takes on a fresh copy of the metarig (median of three)."""
    import bpy
    from rigger.blender.rigify import add_metarig, read_metarig, remove_generated
    from rigger.core.metarig import fit_metarig

    fresh = add_metarig(metarig_name, "bench_metarig", bpy.context.scene.collection)
    bones = read_metarig(fresh)
    remove_generated(fresh, None)
    times = []
    for _ in range(3):
        started = time.perf_counter()
        fit_metarig(skeleton, mesh, metarig_name, bones)
        times.append(time.perf_counter() - started)
    return float(np.median(times))


def weights(obj):
    """Vertices with a DEF weight, vertex groups that are not DEF bones, and the seam gap."""
    groups = {group.index: group.name for group in obj.vertex_groups}
    table = np.zeros((len(obj.data.vertices), len(groups)))
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            table[vertex.index, element.group] = element.weight
    deform = np.array([groups[k].startswith("DEF-") for k in range(len(groups))])
    weighted = int((table[:, deform] > 0).any(axis=1).sum()) if deform.any() else 0
    places = np.unique(np.array([v.co for v in obj.data.vertices]), axis=0, return_inverse=True)[1].ravel()
    high = np.full((places.max() + 1, table.shape[1]), -np.inf)
    low = np.full_like(high, np.inf)
    np.maximum.at(high, places, table)
    np.minimum.at(low, places, table)
    return {"weighted": weighted, "non_def_groups": int((~deform).sum()), "seam_gap": float((high - low).max())}


def helpers_inside(bones, mesh):
    """The share of points along Rigify's pelvis and breast deform bones (``bones``, the rig's DEF bones in the
    mesh's frame: every tenth of their length) inside ``mesh`` (vertices, triangles: winding number above 0.5);
    None when the rig has neither."""
    from rigdata import winding_numbers

    helpers = [k for k, name in enumerate(bones.names) if name.startswith(("DEF-pelvis", "DEF-breast"))]
    if not helpers:
        return None
    steps = np.linspace(0.0, 1.0, 11)[None, :, None]
    points = (bones.heads[helpers][:, None] * (1 - steps) + bones.tails[helpers][:, None] * steps).reshape(-1, 3)
    return float((winding_numbers(points, *mesh) > 0.5).mean())


def rest_error(obj, rest):
    """How far the skinned mesh, its rig at rest, lies from the mesh as it was (``rest``, world space): the largest
    vertex distance in units of the mesh's size (0: the rig deforms nothing until posed)."""
    from rigger.blender.meshdata import evaluated_vertices

    posed = evaluated_vertices(obj)
    return float(np.linalg.norm(posed - rest, axis=1).max() / max(float(np.ptp(rest, axis=0).max()), 1e-300))


def ik_limbs(metarig):
    """(first, second, third bone name, the way the middle joint bends) of every IK limb of the metarig."""
    from rigger.blender.rigify import KIND_PROPERTY
    from rigger.core.metarig import METARIGS

    bends = {chain.names(side)[0]: (chain.names(side)[:3], chain.bend)
             for chain in METARIGS[metarig[KIND_PROPERTY]].chains if chain.bend for side in ("L", "R")}
    return [bends[bone.name] for bone in metarig.data.bones if bone.name in bends]


def ik_bends(rig, metarig):
    """Per IK limb: which way its middle joint moved (along the rig's front) when its IK control moved towards the
    limb's root, and whether that is the way the metarig bends it."""
    import bpy
    from mathutils import Matrix, Vector

    front = -np.array(rig.matrix_world)[:3, 1]
    results = []
    for (first, second, third), way in ik_limbs(metarig):
        control = rig.pose.bones.get(f"{third[:-2]}_ik{third[-2:]}")
        middle = rig.pose.bones.get(f"DEF-{second}")
        root = rig.pose.bones.get(f"ORG-{first}")
        if control is None or middle is None or root is None:
            results.append({"limb": first, "right": False, "moved": None})
            continue
        world = np.array(rig.matrix_world)
        before = world[:3, :3] @ np.array(middle.head) + world[:3, 3]
        reach = np.array(root.head) - np.array(control.head)
        saved = control.matrix.copy()
        control.matrix = Matrix.Translation(Vector(IK_REACH * reach)) @ control.matrix
        bpy.context.view_layer.update()
        after = world[:3, :3] @ np.array(middle.head) + world[:3, 3]
        control.matrix = saved
        bpy.context.view_layer.update()
        moved = float((after - before) @ front)
        results.append({"limb": first, "moved": moved, "right": bool(moved * way > 0)})
    return results


def regenerate(rig, metarig, obj):
    """Seconds Rigify takes to regenerate ``rig`` after a metarig bone moved, and whether the mesh is still
    deformed by the rig's DEF bones afterwards."""
    import bpy
    from rigger.blender.rigify import generate

    metarig.hide_set(False)
    bpy.context.view_layer.objects.active = metarig
    bpy.ops.object.mode_set(mode='EDIT')
    bone = metarig.data.edit_bones[0]
    bone.tail = bone.tail + 0.05 * (bone.tail - bone.head)
    bpy.ops.object.mode_set(mode='OBJECT')
    started = time.perf_counter()
    generate(metarig, rig)
    seconds = time.perf_counter() - started
    groups = {group.name for group in obj.vertex_groups}
    deforms = {bone.name for bone in rig.data.bones if bone.use_deform}
    modifier = next((m for m in obj.modifiers if m.type == 'ARMATURE'), None)
    return seconds, bool(modifier is not None and modifier.object == rig and groups <= deforms)


def drawing(obj, rig):
    """What the picture needs: the mesh's vertices (a sample), the DEF bones and the rig's frame, in the world."""
    world = np.array(obj.matrix_world)
    points = np.array([world[:3, :3] @ np.array(v.co) + world[:3, 3] for v in obj.data.vertices])
    sample = points[np.random.default_rng(0).choice(len(points), min(len(points), 3000), replace=False)]
    matrix = np.array(rig.matrix_world)
    bones = [(bone.name, (matrix[:3, :3] @ np.array(bone.head_local) + matrix[:3, 3]).tolist(),
              (matrix[:3, :3] @ np.array(bone.tail_local) + matrix[:3, 3]).tolist())
             for bone in rig.data.bones if bone.use_deform]
    return {"points": sample.tolist(), "bones": bones, "frame": matrix[:3, :3].tolist()}


def posed_render(path):
    """The sample humanoid rigged as rigify and skinned, its left knee raised and right elbow bent by the IK
    controls, rendered from the front-left with Workbench."""
    import bpy
    from mathutils import Matrix, Vector
    from rigger.blender.pipeline import rig_object, skin_meshes

    obj = mesh_object("sample", "humanoid")
    result = rig_object(obj, "silhouette", target="rigify")
    rig = result.armature
    skin_meshes([obj], rig)
    foot, hand = rig.pose.bones["foot_ik.L"], rig.pose.bones["hand_ik.R"]
    foot.matrix = Matrix.Translation(Vector((0.0, -0.15, 0.35))) @ foot.matrix
    hand.matrix = Matrix.Translation(Vector((0.25, -0.1, 0.2))) @ hand.matrix
    bpy.context.view_layer.update()
    scene = bpy.context.scene
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.location = (2.6, -3.2, 1.3)
    direction = Vector((0.0, 0.0, 0.95)) - camera.location
    camera.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
    scene.camera = camera
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = 640, 640
    scene.display.shading.light = 'STUDIO'
    scene.display.shading.color_type = 'SINGLE'
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    knee = np.array(rig.matrix_world) @ np.r_[np.array(rig.pose.bones["DEF-shin.L"].head), 1.0]
    rest = np.array(rig.matrix_world) @ np.r_[np.array(rig.data.bones["DEF-shin.L"].head_local), 1.0]
    return {"knee_forward": float(-(knee - rest)[1]), "knee_up": float((knee - rest)[2])}


# Report and plot.

def cell_seconds(value):
    return "—" if value is None else f"{value * 1e3:.0f} ms" if value < 1 else f"{value:.2f} s"


def ik_cell(record):
    ik = record.get("ik")
    if not ik:
        return "—"
    return f"{sum(item['right'] for item in ik)} / {len(ik)}"


def rows(records):
    table = []
    for record in records:
        note = record.get("error") or "; ".join(record.get("warnings", []))
        table.append([
            record["model"] + (" (sample)" if record["source"] == "sample" else ""), record.get("plan", "—"),
            record.get("target", "—"), record.get("metarig", "—"), cell_seconds(record.get("fit_seconds")),
            cell_seconds(record.get("build_seconds") if record.get("target") == "rigify" else None),
            cell_seconds(record.get("regenerate_seconds")), record.get("def_bones", "—"),
            f"{record['weighted']} / {record['vertices']}" if "weighted" in record else "—",
            f"{record['seam_gap']:.0e}" if "seam_gap" in record else "—",
            f"{record['rest_error']:.0e}" if "rest_error" in record else "—", ik_cell(record),
            table_cell(note, 140) if note else ""])
    return table


def summary(records):
    expected = [r for r in records if r.get("plan") in RIGIFY_PLANS]
    built = [r for r in expected if r.get("target") == "rigify" and "error" not in r and "weighted" in r]
    full = [r for r in built if r["weighted"] == r["vertices"] and r["non_def_groups"] == 0]
    cracked = [r for r in built if r["seam_gap"] > 0]
    bent = [r for r in built if r["rest_error"] > REST_TOLERANCE]
    outside = sorted((r["helpers_inside"], r["model"]) for r in built if r.get("helpers_inside") is not None
                     and r["helpers_inside"] < HELPERS_INSIDE)
    limbs = [item for r in built for item in r.get("ik", [])]
    regenerated = [r for r in built if r.get("regenerated_bound")]
    others = [r for r in records if r.get("plan") not in RIGIFY_PLANS and "plan" in r]
    return {"expected": len(expected), "built": len(built), "fully_weighted": len(full), "cracked": len(cracked),
            "rest_worst": max((r["rest_error"] for r in built), default=0.0), "bent": [r["model"] for r in bent],
            "helpers_outside": outside,
            "with_helpers": sum(r.get("helpers_inside") is not None for r in built),
            "ik_right": sum(item["right"] for item in limbs), "ik_limbs": len(limbs),
            "regenerated": len(regenerated), "others": len(others),
            "others_built": [r["model"] for r in others if r.get("target") == "rigify" and "error" not in r],
            "fell_back": {target: sum(r.get("target") == target for r in others) for target in ("game", "plain")},
            "failures": [(r["model"], r.get("error", "")) for r in expected if r not in built]}


def report(records, totals, pose, run):
    import bpy

    verdict = "met" if totals["built"] == totals["expected"] else "**not met**"
    weighted = "met" if totals["fully_weighted"] == totals["built"] and not totals["cracked"] else "**not met**"
    lines = [
        "# Rigify target", "",
        f"`{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC, commit {run['commit']}, {run['cpu']} "
        f"({os.cpu_count()} cores, load {run['load'][0]:.1f} at the start: the machine is shared), Python "
        f"{platform.python_version()}, Blender {bpy.app.version_string} (bpy); {run['seconds']:.0f} s in all. What is "
        f"measured and how: the docstring of `bench/rigify_target.py`.", "",
        "## Targets", "",
        *markdown_table(["target", "result", "verdict"], [
            ["Rigify generate succeeds on every recognised humanoid and quadruped",
             f"{totals['built']} / {totals['expected']}", verdict],
            ["every vertex weighted (DEF bones only) and no seam cracks",
             f"{totals['fully_weighted']} / {totals['built']} fully weighted, {totals['cracked']} with a seam gap",
             weighted],
        ]), "",
        f"At rest the skinned mesh lies within {totals['rest_worst']:.0e} of the size of the mesh as it was"
        + (f"; more than {REST_TOLERANCE:.0e} off on {', '.join(totals['bent'])}" if totals["bent"] else "")
        + ". "
        f"Rigify's pelvis and breast bones lie at least {HELPERS_INSIDE:.0%} inside the mesh on "
        f"{totals['with_helpers'] - len(totals['helpers_outside'])} / {totals['with_helpers']} rigs"
        + (" (less on " + ", ".join(f"{model} {share:.0%}" for share, model in totals["helpers_outside"]) + ")"
           if totals["helpers_outside"] else "") + ". "
        f"IK bends the right way (knees forward, elbows back) on {totals['ik_right']} / {totals['ik_limbs']} "
        f"limbs; regenerating from the edited metarig kept the mesh bound on {totals['regenerated']} / "
        f"{totals['built']}. Of the {totals['others']} models of other plans, "
        f"{', '.join(totals['others_built']) or 'none'} (birds with legs) got the bird metarig and "
        f"{totals['fell_back']['game']} fell back to game and {totals['fell_back']['plain']} to plain (game's own "
        f"fallback), each with a warning saying why.",
    ]
    if totals["failures"]:
        lines += ["", "Failures: " + "; ".join(f"{model}: {table_cell(error, 200)}"
                                              for model, error in totals["failures"])]
    if pose:
        lines += ["", f"`rigify_pose.png`: the sample humanoid with its left foot's IK control raised: the knee "
                      f"moved {pose['knee_forward']:.3f} m forward and {pose['knee_up']:.3f} m up."]
    lines += ["", "## Models", "",
              *markdown_table(["model", "plan", "target", "metarig", "fit", "build", "regenerate", "DEF bones",
                               "weighted", "seam gap", "rest", "IK right", "warnings / failure"], rows(records)),
              "", "Build: the metarig added, fitted and generated (Rigify's generate is most of it). A `plain` target "
                  "is the fallback of a plan the rigify target does not fill.", ""]
    return "\n".join(lines)


def plot(records, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    drawn = [record for record in records if "drawing" in record]
    columns = 5
    rows_count = max(1, -(-len(drawn) // columns))
    figure, axes = plt.subplots(rows_count, columns, figsize=(3.4 * columns, 2.8 * rows_count))
    for axis in np.atleast_1d(axes).ravel():
        axis.axis("off")
    for axis, record in zip(np.atleast_1d(axes).ravel(), drawn):
        frame = np.array(record["drawing"]["frame"])  # columns: the rig's left, back, up
        points = np.array(record["drawing"]["points"])
        views = [(frame[:, 0], frame[:, 2]), (frame[:, 1], frame[:, 2])]  # from the front (its left to the right),
        shift = 0.0  # then from its left (its front to the left)
        for across, up in views:
            low = (points @ across).min()
            axis.scatter(points @ across - low + shift, points @ up, s=0.2, c="0.8")
            for name, head, tail in record["drawing"]["bones"]:
                ends = np.array([head, tail])
                colour = "tab:red" if name.endswith(".L") or ".L." in name else \
                    "tab:blue" if name.endswith(".R") or ".R." in name else "k"
                axis.plot(ends @ across - low + shift, ends @ up, color=colour, linewidth=0.8)
            shift += np.ptp(points @ across) * 1.15
        axis.set_aspect("equal")
        axis.set_title(f"{record['model']}\n{record.get('metarig', '')}, IK {ik_cell(record)}", fontsize=7)
    figure.suptitle("Rigify rigs: the DEF bones on the mesh, from the front and from the character's left (front "
                    "to the left); red .L, blue .R", fontsize=9)
    figure.tight_layout(rect=(0, 0, 1, 1 - 0.35 / (2.8 * rows_count)))
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    subset_options(parser, "rigify")
    args = parser.parse_args(argv)
    if not SHARED_MODELS.is_dir():
        raise SystemExit(f"No models at {SHARED_MODELS}: the Rigify benchmark needs ../shared beside the checkout.")
    temporary_user_folder()
    import bpy  # noqa: F401  (after the user folder is set)
    import rigger

    rigger.register()  # the pipeline keeps its armature pointer in the add-on's properties
    names = picked(model_names(), args.models, lambda item: item[1])
    out = results_folder(args, "rigify")
    run = run_record("rigify_target.py", argv)
    started = time.perf_counter()
    records = []
    for source, name in names:
        record = measure(source, name)
        records.append(record)
        print(f"{name:30s} {record.get('plan', '—'):9s} {record.get('target', '—'):7s} "
              f"{record.get('metarig', '—'):15s} IK {ik_cell(record):7s} {record.get('error', '')}", flush=True)
    pose = None
    if any(source == "sample" and name == "humanoid" for source, name in names):
        pose = posed_render(out / "rigify_pose.png")
    run["seconds"] = time.perf_counter() - started
    totals = summary(records)
    (out / "rigify.md").write_text(report(records, totals, pose, run))
    plot(records, out / "rigify.png")
    for record in records:
        record.pop("drawing", None)
    (out / "rigify.json").write_text(json.dumps({"run": {**run, "started": run["started"].isoformat()},
                                                 "summary": totals, "pose": pose, "records": records}, indent=1))
    print(f"wrote {out / 'rigify.md'}")


if __name__ == "__main__":
    main()
