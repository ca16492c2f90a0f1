"""Retargeting benchmark: the CMU walk and jump (``../shared/anim``) on game rigs of humanoids.

Each character (the generated sample humanoids, and the ``../shared`` humanoids Rigger recognises as humanoid) is
rigged with the ``game`` target, skinned, and given each clip with ``rigger.blender.animate``; then every frame but
the first (CMU's frame 1 is a reference pose, not motion: ``../shared/anim/README.md``) is posed and measured:

- feet: in the frames where the mocap's foot is planted (``core.retarget.contact_frames``: its toe joint within 5%
  of its leg's length of its contact level and slower than half a leg length a second), the lowest point of the
  character's posed foot (its vertices weighted more than half to Foot or ToeBase; for a leg without a foot bone, to
  its Leg) lies within 0.02 of the model's size of the ground (the mesh's lowest point at rest); measured: the
  largest distance and the share within;
- knees bend forward and elbows backwards in every frame: an elbow bent more than ``BENT`` degrees whose joint lies
  in front of the line from the shoulder to the wrist, seen along the character's posed facing (the Hips' rest
  forward turned with the Hips), is a wrong frame; so is a knee bent that far the other way about its hinge than a
  knee bends (the rest left turned with the thigh: its sense does not depend on where the leg points, as ahead
  does not for a heel kicked up behind);
- every vertex weighted, at most 4 influences, and seams: vertices at one place at rest (within 1e-6 of the size)
  stay together (the largest distance between them over every frame, a share of the size: 0 is no crack).

Writes ``bench/results/retarget.md`` and ``retarget.png``.

    .venv/bin/python bench/retarget.py [--models NAME,...] [--clips walk,jump]
"""
import argparse
import datetime
import pathlib
import platform
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from benchkit import RESULTS_DIR, SHARED_MODELS, cpu_model, described_commit, markdown_table, table_cell  # noqa
from rigger.blender.headless import empty_scene, temporary_user_folder  # noqa: E402  (bpy-free)

ANIM = SHARED_MODELS.parent / "anim"
CLIPS = {"walk": "cmu_07_01_walk.bvh", "jump": "cmu_141_05_jump_sideways.bvh"}
SAMPLES = ("humanoid", "humanoid_hips", "humanoid_a_pose", "humanoid_knees", "humanoid_handmade", "head_with_nose",
           "four_arms")
SHARED = (*(f"gt/{name}/{name}.obj" for name in ("BrainStem", "CesiumMan", "magicarticulate_0a59c5ff", "rignet_1347",
                                                 "rignet_15930", "rignet_17364", "rignet_8210", "rignet_8330",
                                                 "rignet_8333", "rignet_9477", "rignet_smith")),
          *(f"nogt/{name}.obj" for name in ("cheburashka", "homer", "ogre", "woody")))  # bench/bodyplan's humanoids
Z_UP = ("BrainStem", "CesiumMan", "magicarticulate_0a59c5ff")  # OBJ files written Z up (the others Y up)
FEET = 0.02  # the target: planted feet within this share of the size of the ground
BENT = 5.0  # degrees: a knee or elbow bent less is straight, whichever way
SEAM = 1e-6  # vertices this close at rest (a share of the size) are one place


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", help="comma-separated sample names or ../shared model stems")
    parser.add_argument("--clips", default=",".join(CLIPS), help="comma-separated: walk, jump")
    args = parser.parse_args()
    clips = [clip for clip in args.clips.split(",") if clip]
    missing = [CLIPS[clip] for clip in clips if not (ANIM / CLIPS[clip]).is_file()]
    if missing:
        print(f"skipped: the clips {', '.join(missing)} are not in {ANIM} (clone the project beside ../shared)")
        return 0
    temporary_user_folder()
    models = [(name, None) for name in SAMPLES] + [(pathlib.Path(path).stem, SHARED_MODELS / path) for path in SHARED
                                                   if (SHARED_MODELS / path).is_file()]
    if args.models:
        wanted = set(args.models.split(","))
        models = [model for model in models if model[0] in wanted]
    started = time.perf_counter()
    load = _load()
    rows, traces = [], {}
    for name, path in models:
        for clip in clips:
            row, trace = measure(name, path, ANIM / CLIPS[clip])
            row = {"model": name, "clip": clip, **row}
            rows.append(row)
            traces[(name, clip)] = trace
            print(_line(row), flush=True)
    write(rows, traces, time.perf_counter() - started, load)
    return 0


def measure(name, path, bvh):
    """Rig, skin and animate one character with one clip; (the row of measurements, the walk trace to plot)."""
    import bpy

    import rigger
    from rigger.blender import animate
    from rigger.blender.pipeline import rig_object, skin_meshes
    from rigger.blender.samples import build_character
    from rigger.core.retarget import RetargetError, contact_frames, retarget

    empty_scene()
    rigger.register()
    if path is None:
        obj = build_character(name)
    else:
        axes = {"up_axis": "Z", "forward_axis": "Y"} if name in Z_UP else {}
        bpy.ops.wm.obj_import(filepath=str(path), **axes)
        obj = max((o for o in bpy.context.scene.objects if o.type == 'MESH'), key=lambda o: len(o.data.vertices))
    result = rig_object(obj, "silhouette", target="game")
    plan = result.skeleton.body_plan
    if result.target.name != "game" or plan.kind != "humanoid":
        return {"skipped": f"body plan {plan.kind}: no humanoid game rig"}, None
    armature = result.armature
    outcomes, _ = skin_meshes([obj], armature)
    clip = animate.read_clip(bvh, armature)
    rig = animate.game_rig(armature)
    try:
        motion = retarget(clip, rig)
    except RetargetError as error:
        return {"skipped": str(error)}, None
    animate.bake(armature, rig, motion, "bench", 1)
    return _posed_measures(obj, armature, rig, motion, clip, outcomes[obj.name], contact_frames)


def _posed_measures(obj, armature, rig, motion, clip, outcome, contact_frames):
    import bpy

    from rigger.core.retarget import sole_bones

    scene = bpy.context.scene
    rest = _world_vertices(obj, bpy.context.evaluated_depsgraph_get(), rest=True)
    size = float(np.ptp(rest, axis=0).max())
    up = rig.up
    ground = rig.ground
    groups = {group.index: group.name for group in obj.vertex_groups}
    weights = [{groups[e.group]: e.weight for e in v.groups if e.weight > 0 and groups[e.group] in rig.names}
               for v in obj.data.vertices]
    carriers = {side: sole_bones(rig.names, side) for side in ("Left", "Right")}
    feet = {side: np.array([i for i, w in enumerate(weights) if sum(w.get(name, 0) for name in carriers[side]) > 0.5])
            for side in ("Left", "Right")}
    seams = _seam_pairs(rest, size)
    planted = {side: contact_frames(clip, motion.mapping, side) for side in ("Left", "Right")}
    frames = range(2, len(motion.rotations) + 1)
    left = rig.rest[rig.names.index("LeftUpLeg"), :3, 3] - rig.rest[rig.names.index("RightUpLeg"), :3, 3]
    forward = np.cross(left - (left @ up) * up, up)
    forward /= np.linalg.norm(forward)
    errors, lows, crack, wrong_knees, wrong_elbows = [], {"Left": [], "Right": []}, 0.0, 0, 0
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for frame in frames:
        scene.frame_set(frame)
        points = _world_vertices(obj, depsgraph)
        for side in ("Left", "Right"):
            low = float((points[feet[side]] @ up).min() - ground) if len(feet[side]) else np.nan
            lows[side].append(low)
            if planted[side][frame - 1]:
                errors.append(abs(low) / size)
        if len(seams):
            crack = max(crack, float(np.linalg.norm(points[seams[:, 0]] - points[seams[:, 1]], axis=1).max()) / size)
        pose = armature.pose.bones
        hips = np.array(pose["Hips"].matrix)[:3, :3] @ rig.rest[rig.names.index("Hips"), :3, :3].T
        facing = hips @ forward
        wrong_knees += any(_knee(pose, rig, side, left / np.linalg.norm(left)) < 0 for side in ("Left", "Right"))
        wrong_elbows += any(_bend(pose, f"{side}Arm", f"{side}ForeArm", f"{side}Hand", facing) > 0
                            for side in ("Left", "Right"))
    errors = np.array(errors)
    row = {"frames": len(frames), "planted": int(len(errors)),
           "feet_max": float(errors.max()) if len(errors) else np.nan,
           "feet_within": float((errors <= FEET).mean()) if len(errors) else np.nan,
           "wrong_knees": wrong_knees, "wrong_elbows": wrong_elbows,
           "unweighted": int(sum(not w for w in weights)), "influences": max(len(w) for w in weights),
           "seams": len(seams), "crack": crack, "scale": motion.scale}
    trace = {"lows": {side: np.array(values) / size for side, values in lows.items()},
             "planted": {side: planted[side][1:] for side in planted}}
    return row, trace


def _knee(pose, rig, side, left):
    """+1 when the knee on ``side`` bends the way a knee bends about its hinge (the rest ``left`` turned with the
    thigh), -1 the other way, 0 within ``BENT`` degrees of straight (or without a thigh, shin and foot)."""
    names = [f"{side}{word}" for word in ("UpLeg", "Leg", "Foot")]
    limb = _bent_limb(pose, names)
    if limb is None:
        return 0
    upper, lower = limb
    turn = np.array(pose[names[0]].matrix)[:3, :3] @ rig.rest[rig.names.index(names[0]), :3, :3].T
    return 1 if np.cross(upper, lower) @ (turn @ left) > 0 else -1


def _bend(pose, first, middle, last, facing):
    """+1 when the joint at ``middle`` lies in front of the line from ``first``'s head to ``last``'s head (along
    ``facing``), -1 behind, 0 when the limb is within ``BENT`` degrees of straight (or the rig lacks one of them)."""
    limb = _bent_limb(pose, (first, middle, last))
    if limb is None:
        return 0
    upper, lower = limb
    line = (upper + lower) / np.linalg.norm(upper + lower)
    offset = upper - (upper @ line) * line
    return 1 if offset @ facing > 0 else -1


def _bent_limb(pose, names):
    """(upper, lower): the vectors from the first of the three posed bones' heads ``names`` to the second and from
    the second to the third; None when the pose lacks one or they lie within ``BENT`` degrees of straight."""
    if any(name not in pose for name in names):
        return None
    a, b, c = (np.array(pose[name].head) for name in names)
    upper, lower = b - a, c - b
    angle = np.degrees(np.arccos(np.clip(upper @ lower / (np.linalg.norm(upper) * np.linalg.norm(lower)), -1, 1)))
    return None if angle < BENT else (upper, lower)


def _world_vertices(obj, depsgraph, rest=False):
    """The mesh's vertices in world space, posed (evaluated) or at rest."""
    mesh = obj.data if rest else obj.evaluated_get(depsgraph).data
    points = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", points)
    matrix = np.array(obj.matrix_world)
    return points.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]


def _seam_pairs(points, size):
    """Pairs of vertex indices at one place (within ``SEAM`` of ``size``): each vertex with the first at its place."""
    keys = np.round(points / (SEAM * size)).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    pairs = [(first[group], vertex) for vertex, group in enumerate(inverse) if first[group] != vertex]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def _line(row):
    if "skipped" in row:
        return f"{row['model']} {row['clip']}: skipped ({row['skipped']})"
    return (f"{row['model']} {row['clip']}: feet max {row['feet_max']:.4f} within {row['feet_within']:.0%} of "
            f"{row['planted']} planted foot-frames; wrong knees {row['wrong_knees']}, elbows {row['wrong_elbows']}; "
            f"unweighted {row['unweighted']}, crack {row['crack']:.2g}")


def _load():
    try:
        return open("/proc/loadavg").read().split()[0]
    except OSError:
        return "?"


def write(rows, traces, seconds, load):
    measured = [row for row in rows if "skipped" not in row]
    walk = [row for row in measured if row["clip"] == "walk"]
    feet_ok = all(row["feet_max"] <= FEET for row in walk)
    lines = [
        "# Retargeted mocap on game rigs",
        "",
        f"`python bench/retarget.py` on {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, commit "
        f"{described_commit()}, {cpu_model()} ({platform.machine()}, load {load} at the start), Python "
        f"{platform.python_version()}; {seconds:.0f} s in all. What is measured and how: the docstring of "
        f"`bench/retarget.py`. Clips: CMU 07_01 (walk, 317 frames) and 141_05 (jump sideways, 231 frames) from "
        f"`../shared/anim`, frames 2 on.",
        "",
        "## Targets",
        "",
        *markdown_table(("target", "result", "verdict"), [
            ("the walk keeps planted feet within 0.02 of the size of the ground",
             f"largest {max((r['feet_max'] for r in walk), default=np.nan):.4f} over {len(walk)} characters",
             "**met**" if walk and feet_ok else "**not met**"),
            ("knees bend forward and elbows backwards in every frame",
             f"{sum(r['wrong_knees'] for r in measured)} wrong knee frames, "
             f"{sum(r['wrong_elbows'] for r in measured)} wrong elbow frames",
             "**met**" if measured and not any(r["wrong_knees"] or r["wrong_elbows"] for r in measured)
             else "**not met**"),
            ("every vertex weighted, at most 4 influences, no seam cracks",
             f"{sum(r['unweighted'] for r in measured)} unweighted, at most "
             f"{max((r['influences'] for r in measured), default=0)} influences, largest crack "
             f"{max((r['crack'] for r in measured), default=0):.2g}",
             "**met**" if measured and not any(r["unweighted"] or r["influences"] > 4 or r["crack"] > 0
                                                for r in measured) else "**not met**"),
        ]),
        "",
        "## Runs",
        "",
        *markdown_table(("model", "clip", "planted foot-frames", "feet: largest", "feet: within 0.02",
                         "wrong knees", "wrong elbows", "unweighted", "influences", "seam vertices", "crack",
                         "scale"),
                        [(r["model"], r["clip"], r["planted"], f"{r['feet_max']:.4f}", f"{r['feet_within']:.1%}",
                          r["wrong_knees"], r["wrong_elbows"], r["unweighted"], r["influences"], r["seams"],
                          f"{r['crack']:.2g}", f"{r['scale']:.4f}") for r in measured]),
        "",
    ]
    skipped = [row for row in rows if "skipped" in row]
    if skipped:
        lines += ["Skipped:", ""] + [f"- {row['model']} ({row['clip']}): {table_cell(row['skipped'])}"
                                     for row in skipped] + [""]
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    (RESULTS_DIR / "retarget.md").write_text("\n".join(lines))
    _plot(measured, traces)
    print(f"wrote {RESULTS_DIR / 'retarget.md'} and retarget.png")


def _plot(measured, traces):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (left, right) = plt.subplots(1, 2, figsize=(13, 4.5))
    trace = traces.get(("humanoid", "walk")) or next((t for t in traces.values() if t), None)
    if trace is not None:
        for side, colour in (("Left", "tab:blue"), ("Right", "tab:orange")):
            lows = trace["lows"][side]
            frames = np.arange(2, 2 + len(lows))
            left.plot(frames, lows, color=colour, label=f"{side} foot's lowest point")
            planted = trace["planted"][side][:len(lows)]
            left.scatter(frames[planted], lows[planted], color=colour, s=6)
        left.axhspan(-FEET, FEET, color="green", alpha=0.12, label="within 0.02 of the size")
        left.set_xlabel("frame (dots: the mocap's foot planted)")
        left.set_ylabel("height above the ground / size")
        left.set_title("humanoid, CMU walk")
        left.legend(fontsize=8)
    labels = [f"{r['model']}\n{r['clip']}" for r in measured]
    right.bar(range(len(measured)), [r["feet_max"] for r in measured], color="tab:gray")
    right.axhline(FEET, color="red", label="target 0.02")
    right.set_xticks(range(len(measured)), labels, rotation=90, fontsize=6)
    right.set_ylabel("largest planted-foot distance / size")
    right.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(RESULTS_DIR / "retarget.png", dpi=110)


if __name__ == "__main__":
    sys.exit(main())
