"""Frame benchmark: how much Rigger's skeleton of one mesh depends on the frame the mesh is read in.

The silhouette method traces axis-aligned views, so a quarter turn of the mesh turns or mirrors the traced outline,
and a decision near its threshold (a branch's reach against ``prune``) may go the other way. Every
../shared/models/gt model is rigged by ``rigger.rig_mesh`` (``axes=``: the mesh turned for the method, the skeleton
turned back) in its file's own frame, in four frames turned from it (a quarter turn about X, about Y and about Z,
a half turn about Z), and as Blender's OBJ importer reads it (``bodyplan.MODELS``' up: a Y-up file turned so that
Z is up); and with its vertices turned 7° and 30° about its up axis (``bodyplan.MODELS``' up), no axes given, as a
mesh saved turned reaches Rigger (``rig_mesh`` rigs it square to its mirror plane), the skeleton turned back; and
scaled a hundredfold, moved by a third of its size (``MOVES``) and with its vertices and triangles renumbered,
which should change nothing at all. Each skeleton is scored in the file's frame as the quality benchmark scores it
(CD-J2J against the artist's joints, in its normalised units) and with the posing benchmark's limb recall, and its
body plan and bones compared with the file frame's: the same bones are the same names in the same order, each
within ``SAME_PLACE`` of the size of its place.

    .venv/bin/python bench/frames.py [--models NAME ...] [--out DIR]

Writes frames.md, frames.png and frames.json to bench/results (or ``--out``; out/frames with ``--models``).
"""
import argparse
import json
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import posing_math  # noqa: E402  (bench/ is not a package)
import quality  # noqa: E402
import rigdata  # noqa: E402
import rigger  # noqa: E402
from benchkit import SHARED_MODELS, markdown_table, picked, results_folder, run_record, subset_options  # noqa: E402
from bodyplan import MODELS, blender_turn  # noqa: E402

# name -> the rotation whose rows are the directions (in the file's coordinates) the method takes as X, Y and Z
TURNS = {"file": np.eye(3),
         "X 90°": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
         "Y 90°": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),
         "Z 90°": np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]),
         "Z 180°": np.array([[-1.0, 0, 0], [0, -1, 0], [0, 0, 1]])}
BLENDER = "Blender"  # the frame Blender's OBJ importer reads the file in
BAKED = {"up 7° baked": 7.0, "up 30° baked": 30.0}  # vertices turned about the model's up by so many degrees
MOVES = {"×100": (100.0, (0.0, 0.0, 0.0)), "moved": (1.0, (0.37, -0.21, 0.11))}  # scale; shift in sizes
RENUMBERED = "renumbered"  # the vertices and the triangles in another order (seeded)
SAME_PLACE = 1e-3  # bone ends this close (a share of the size) are in the same place


def frames_of(name):
    """{frame name: rotation} for model ``name``: ``TURNS`` and Blender's import."""
    return {**TURNS, BLENDER: blender_turn(name)}


def baked_turn(name, degrees):
    """The rotation turning model ``name``'s vertices ``degrees`` about its up axis (``bodyplan.MODELS``)."""
    up = "XYZ".index(MODELS[name][1])
    a, b = [axis for axis in range(3) if axis != up]
    angle = np.radians(degrees)
    turn = np.eye(3)
    turn[[a, a, b, b], [a, b, a, b]] = np.cos(angle), -np.sin(angle), np.sin(angle), np.cos(angle)
    return turn


def measure(folder):
    """{frame: (CD-J2J, limb recall, bones, body plan, whether the bones are the file frame's)} of one model."""
    truth = quality.GroundTruth(folder)
    rig = truth.rig.attached()
    size = float(np.ptp(truth.vertices, axis=0).max())
    triangles = truth.triangles.astype(np.int32)
    result = {}
    rigs = [(frame, rigger.rig_mesh(truth.vertices, triangles, axes=turn), lambda points: points)
            for frame, turn in frames_of(folder.name).items()]
    for frame, degrees in BAKED.items():
        turn = baked_turn(folder.name, degrees)
        rigs.append((frame, rigger.rig_mesh(truth.vertices @ turn.T, triangles),
                     lambda points, turn=turn: points @ turn))
    for frame, (scale, shift) in MOVES.items():
        shift = np.asarray(shift) * size
        rigs.append((frame, rigger.rig_mesh(truth.vertices * scale + shift, triangles),
                     lambda points, scale=scale, shift=shift: (points - shift) / scale))
    rng = np.random.default_rng(0)
    order = rng.permutation(len(truth.vertices))
    renumbered = np.argsort(order)[triangles][rng.permutation(len(triangles))].astype(np.int32)
    rigs.append((RENUMBERED, rigger.rig_mesh(truth.vertices[order], renumbered), lambda points: points))
    file_bones = None
    for frame, skeleton, back in rigs:
        heads, tails = back(skeleton.heads), back(skeleton.tails)  # in the file's frame
        file_bones = file_bones or (skeleton.names, heads, tails)
        same = bool(skeleton.names == file_bones[0] and np.abs(heads - file_bones[1]).max() <= SAME_PLACE * size
                    and np.abs(tails - file_bones[2]).max() <= SAME_PLACE * size)
        _, scores = quality.scored(truth, rigdata.Bones(heads, tails, np.asarray(skeleton.parents)))
        recall, _ = posing_math.limb_recall(rig.positions, rig.parents, heads, tails, skeleton.parents, size)
        result[frame] = (float(scores["cd_j2j"]), float(recall), len(skeleton), skeleton.body_plan.kind, same)
    return result


def report(records, run):
    frames = list(next(iter(records.values())))
    means = {frame: (np.mean([r[frame][0] for r in records.values()]), np.mean([r[frame][1] for r in records.values()]))
             for frame in frames}
    moved = {frame: sum(r[frame][2] != r["file"][2] for r in records.values()) for frame in frames}
    replanned = {frame: sum(r[frame][3] != r["file"][3] for r in records.values()) for frame in frames}
    other = {frame: sum(not r[frame][4] for r in records.values()) for frame in frames}
    spread = {name: max(v[0] for v in r.values()) - min(v[0] for v in r.values()) for name, r in records.items()}
    load = ", ".join(f"{value:.2f}" for value in run["load"])
    lines = ["# Frames: one mesh read in different frames", "",
             f"`{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC in {run['seconds']:.0f} s, commit "
             f"`{run['commit']}`, {run['cpu']} (load average {load} at the start). What is measured and how: the "
             "docstring of `bench/frames.py`.", "",
             f"{len(records)} models. CD-J2J in the quality benchmark's units; limb recall as the posing benchmark's. "
             f"`{BLENDER}`: as Blender's OBJ importer reads the file (Y-up files turned, Z-up ones read with "
             "`--up Z`).", "", "## Means by frame", ""]
    lines += markdown_table(["frame", "mean CD-J2J", "mean limb recall", "models whose bone count differs from the "
                             "file frame's", "models whose body plan differs", "models whose bones (names, order, "
                             "places) differ"],
                            [[frame, f"{means[frame][0]:.4f}", f"{means[frame][1]:.3f}", moved[frame],
                              replanned[frame], other[frame]] for frame in frames])
    turned = [means[frame][0] for frame in TURNS if frame != "file"]
    lines += ["", f"Turned frames: mean CD-J2J {min(turned):.4f} to {max(turned):.4f} against {means['file'][0]:.4f} "
              "in the files' own frames. Per model, the largest CD-J2J minus the smallest over the frames: median "
              f"{np.median(list(spread.values())):.4f}, largest {max(spread.values()):.4f} "
              f"({max(spread, key=spread.get)}). Turns in the vertices: "
              + ", ".join(f"{frame} {means[frame][0]:.4f}, recall {means[frame][1]:.3f}, {replanned[frame]} plans "
                          "changed" for frame in BAKED) + ". The same bones as in the file frame, "
              + ", ".join(f"{frame} on {len(records) - other[frame]} of {len(records)}"
                          + (f" (not {', '.join(n for n, r in records.items() if not r[frame][4])})"
                             if other[frame] else "") for frame in [*MOVES, RENUMBERED]) + ".", "",
              "![CD-J2J per model and frame](frames.png)", "",
              "## Per model", "", "CD-J2J / limb recall / bones per frame.", ""]
    lines += markdown_table(["model", *frames, "CD-J2J spread"],
                            [[name, *(f"{r[frame][0]:.4f} / {r[frame][1]:.2f} / {r[frame][2]}" for frame in frames),
                              f"{spread[name]:.4f}"] for name, r in records.items()])
    return "\n".join(lines) + "\n"


def plot(records, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(records)
    frames = list(records[names[0]])
    figure, axes = plt.subplots(figsize=(14, 5))
    for k, frame in enumerate(frames):
        axes.scatter(np.arange(len(names)) + (k - len(frames) / 2) * 0.1, [records[n][frame][0] for n in names],
                     s=16, label=frame, marker="D" if frame in ("file", BLENDER) else "o")
    axes.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=8)
    axes.set_ylabel("CD-J2J")
    axes.set_title(f"Rigger's skeleton of each model read in {len(frames)} frames")
    axes.legend(ncol=len(frames), fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    subset_options(parser, "frames")
    args = parser.parse_args(argv)
    folder = SHARED_MODELS / "gt"
    if not folder.is_dir():
        raise SystemExit(f"No models at {folder}: the frame benchmark needs ../shared beside the checkout.")
    folders = picked(sorted(f for f in folder.iterdir() if f.is_dir() and f.name in MODELS), args.models,
                     name=lambda f: f.name)
    out = results_folder(args, "frames")
    run = run_record("frames.py", argv)
    started = time.perf_counter()
    records = {}
    for model in folders:
        records[model.name] = measure(model)
        print(f"{model.name:30s} " + "  ".join(f"{frame} {cd:.4f}/{recall:.2f}/{bones}/{plan}{'' if same else '*'}"
                                               for frame, (cd, recall, bones, plan, same)
                                               in records[model.name].items()),
              flush=True)
    run["seconds"] = time.perf_counter() - started
    (out / "frames.md").write_text(report(records, run))
    plot(records, out / "frames.png")
    (out / "frames.json").write_text(json.dumps({"run": {**run, "started": run["started"].isoformat()},
                                                 "records": records}, indent=1))
    print(f"wrote {out / 'frames.md'}")


if __name__ == "__main__":
    main()
