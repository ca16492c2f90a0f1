"""``make demo``: rig the project's own sample character and write what the pipeline produced to ``out/``.

Builds the sample humanoid with Blender's Skin modifier (bpy from PyPI, headless), rigs it with the silhouette method
and writes ``out/humanoid.obj`` (the mesh), ``out/humanoid_report.json`` (bones in the OBJ's frame, per-stage timings,
distance to the known skeleton) and ``out/humanoid.png`` (silhouette, triangulation by class, chordal axis, bones).
"""
import json
import os
import pathlib
import sys
import tempfile

import numpy as np

OUT = pathlib.Path(__file__).resolve().parents[1] / "out"
CLASS_COLOURS = {2: "#e4572e", 1: "#a8c5da", 0: "#f3a712", 3: "#6c757d"}  # terminal, sleeve, junction, isolated


def sample_mesh(name):
    with tempfile.TemporaryDirectory(prefix="rigger-blender-user-") as user:
        os.environ.setdefault("BLENDER_USER_RESOURCES", user)
        import bpy
        from rigger.blender.samples import character_arrays

        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        return character_arrays(name)


def write_obj(path, vertices, triangles):
    with open(path, "w") as out:
        out.write("".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in vertices))
        out.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))


def draw(path, skeleton):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection

    stages = skeleton.stages
    sil = stages["silhouette"]
    figure, (plane, bones) = plt.subplots(1, 2, figsize=(12, 7))
    cdt = stages["cdt"]
    plane.add_collection(PolyCollection(cdt["vertices"][cdt["triangles"]], edgecolors="white", linewidths=0.3,
                                        facecolors=[CLASS_COLOURS[c] for c in cdt["classes"]]))
    for loop in sil["loops"]:
        closed = np.vstack([loop, loop[:1]])
        plane.plot(closed[:, 0], closed[:, 1], color="black", linewidth=1)
    axis = stages["axis"]
    plane.add_collection(LineCollection(axis["points"][stages["merged"]["links"]], colors="#2a9d8f", linewidths=1.5))
    plane.add_collection(LineCollection(axis["points"][stages["pruned"]["links"]], colors="#9b2226", linewidths=1.5))
    plane.set_title("silhouette, CDT (terminal / sleeve / junction), chordal axis (pruned in red)")
    plane.set_aspect("equal")
    plane.autoscale()
    # bones seen along the same view
    to_plane = np.stack([sil["u"], sil["v"]], axis=1)
    heads = (skeleton.heads - sil["origin"]) @ to_plane
    tails = (skeleton.tails - sil["origin"]) @ to_plane
    for loop in sil["loops"]:
        closed = np.vstack([loop, loop[:1]])
        bones.fill(closed[:, 0], closed[:, 1], color="0.9")
    bones.add_collection(LineCollection(np.stack([heads, tails], axis=1), colors="#264653", linewidths=2.5))
    bones.scatter(*np.vstack([heads, tails]).T, s=14, color="#e76f51", zorder=3)
    bones.set_title(f"{len(skeleton)} bones")
    bones.set_aspect("equal")
    bones.autoscale()
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)


def main(name="humanoid"):
    import rigger
    from rigger import samples

    OUT.mkdir(exist_ok=True)
    vertices, triangles = sample_mesh(name)
    skeleton = rigger.rig_mesh(vertices, triangles)
    truth = samples.ground_truth_bones(name)
    joints, true_joints = skeleton.joints(), truth.joints()
    gaps = np.linalg.norm(joints[:, None] - true_joints[None], axis=2)
    size = float(np.ptp(vertices, axis=0).max())
    report = {
        "model": name,
        "vertices": len(vertices),
        "triangles": len(triangles),
        "method": "silhouette",
        "params": skeleton.stages["params"],
        "bones": skeleton.to_dict()["bones"],
        "timings_seconds": skeleton.stages["timings"],
        "joint_chamfer_to_truth": 0.5 * float(gaps.min(axis=1).mean() + gaps.min(axis=0).mean()) / size,
    }
    write_obj(OUT / f"{name}.obj", vertices, triangles)
    (OUT / f"{name}_report.json").write_text(json.dumps(report, indent=2, default=_plain))
    draw(OUT / f"{name}.png", skeleton)
    print(f"rigged {name}: {len(skeleton)} bones in {report['timings_seconds']['total'] * 1e3:.0f} ms, "
          f"joint distance to the true skeleton {report['joint_chamfer_to_truth']:.3f} of its size")
    print(f"wrote {OUT / (name + '.obj')}, {OUT / (name + '_report.json')}, {OUT / (name + '.png')}")


def _plain(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


if __name__ == "__main__":
    main(*sys.argv[1:])
