"""Issue 28's posing defects on the generated characters: each one rigged with the defaults, measured against its
true skeleton, posed, and drawn.

    .venv/bin/python tools/defects.py [NAME ...]      # default: the characters of CHARACTERS

Per character it prints, and writes to ``out/defects/report.md``: the bones named for a side and the unsided ones off
the mirror plane, the worst mirror-twin mismatch, each true limb (branch or root to leaf) and how far Rigger's nearest
path of bones lies from it, the chains running through the head, the distance from each true elbow, wrist, knee and
ankle to Rigger's nearest joint, Rigger's joints far from every true joint (and the true bone they lie on), every
chain with the bone it hangs from (and the true bones nearest both), and the posing error: random poses of the true
skeleton skinned by Rigger, reproduced by Rigger's rig (the excess over the true skeleton's own fit, as in
``bench/posing.py``). It draws ``out/defects/NAME.png``: the character from the front and from its left,
see-through, its true skeleton in thin green bones and Rigger's in red (``.L``), blue (``.R``) and black (no side),
and ``NAME_zoom.png``: the same around the part the defect is in (``ZOOMS``). Distances are fractions of the mesh's
largest extent. The measures are ``tests/rig_checks.py``'s.
"""
import math
import pathlib
import re
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "out" / "defects"
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "bench"), str(ROOT / "tools")]

import rig_checks as rc  # noqa: E402  (tests/ and bench/ are no packages)
import rigger  # noqa: E402
from rigger import samples  # noqa: E402
from rigger.blender.headless import empty_scene, temporary_user_folder  # noqa: E402  (bpy-free)

CHARACTERS = ("humanoid_a_pose", "humanoid_handmade", "head_with_nose", "bear", "humanoid_knees", "four_arms")
BENDS = {"upper_arm": "elbow", "forearm": "wrist", "thigh": "knee", "shin": "ankle", "leg": "ankle"}  # by joint stem
POSES, MAX_DEGREES, SEED = 12, 35.0, 0  # the posing benchmark's
# (low corner, high corner) of the box each zoomed picture shows, in metres
ZOOMS = {"humanoid_a_pose": ((0.15, -0.15, 0.85), (0.75, 0.15, 1.5)), "head_with_nose": ((-0.2, -0.2, 1.45),
                                                                                        (0.2, 0.2, 1.85)),
         "humanoid_knees": ((0.0, -0.2, 0.0), (0.75, 0.2, 1.5)), "four_arms": ((-0.85, -0.3, 1.15), (0.85, 0.3, 1.75)),
         "bear": ((-0.35, -1.0, 0.45), (0.35, -0.3, 1.1)), "humanoid_handmade": ((-0.9, -0.25, 0.0), (0.9, 0.25, 1.8))}
RENDER_SIZE = (1600, 900)
GAP = 0.15  # between the front and the side view, in the character's size
COLOURS = {"L": (0.85, 0.1, 0.1, 1.0), "R": (0.1, 0.2, 0.9, 1.0), None: (0.05, 0.05, 0.05, 1.0)}
TRUTH_COLOUR, SKIN_COLOUR = (0.1, 0.7, 0.1, 1.0), (0.8, 0.8, 0.8, 0.25)
TRUTH_WIDTH = 0.03  # bone lengths: the true bones are drawn thinner than Rigger's


def main(names):
    temporary_user_folder()
    import bpy

    import demo
    from rigger.blender.meshdata import mesh_arrays
    from rigger.blender.samples import build_character

    OUT.mkdir(parents=True, exist_ok=True)
    report = ["# Issue 28's defects on the generated characters", "",
              "Written by `tools/defects.py`; distances are fractions of the mesh's largest extent.", ""]
    for name in names:
        empty_scene()
        obj = build_character(name)
        vertices, triangles = mesh_arrays(obj.data)
        skeleton = rigger.rig_mesh(vertices, triangles)
        truth = samples.ground_truth_bones(name)
        lines = measured(name, vertices, triangles, skeleton, truth)
        print("\n".join(lines), flush=True)
        report += lines + [f"![{name}]({name}.png)", ""] + ([f"![{name}, zoomed]({name}_zoom.png)", ""]
                                                             if name in ZOOMS else [])
        render(bpy, demo, vertices, triangles, truth, skeleton, OUT / f"{name}.png")
        if name in ZOOMS:
            render(bpy, demo, vertices, triangles, truth, skeleton, OUT / f"{name}_zoom.png", ZOOMS[name])
    (OUT / "report.md").write_text("\n".join(report))
    print(f"wrote {OUT / 'report.md'} and the pictures beside it")


def measured(name, vertices, triangles, skeleton, truth):
    """Markdown lines: every measure of Rigger's ``skeleton`` of character ``name``, against its ``truth`` skeleton
    (see the module's docstring)."""
    size = rc.mesh_size(vertices)
    left, right = rc.side_counts(skeleton)
    twins = rc.twin_mismatches(skeleton, size)
    worst = max(twins, key=twins.get) if twins else None
    limbs = rc.limbs(truth, skeleton, size)
    lines = [f"## {name}", "",
             f"- {name}: {len(skeleton)} bones ({left} .L, {right} .R; true skeleton {len(truth)}), mirror plane "
             f"{'found' if 'mirror_plane' in skeleton.stages else 'none'}; unsided off the plane: "
             f"{', '.join(rc.unsided_off_plane(skeleton, size)) or 'none'}",
             "- twin mismatch: " + (f"worst {worst} {twins[worst]:.4f} over {len(twins)} pairs" if twins
                                    else "no pairs"),
             f"- limbs followed {sum(limb.followed() for limb in limbs.values())}/{len(limbs)}: " + ", ".join(
                 f"{leaf} {limb.distance:.3f}{'' if limb.followed() else ' MISSED'}" for leaf, limb in limbs.items())]
    joints = {joint.name: joint for joint in samples.character_joints(name)}
    if "head" in joints:
        head = joints["head"]
        found = rc.chains_in_ball(skeleton, head.position, head.radius)
        lines.append(f"- chains through the head: {len(found)} "
                     f"({', '.join(f'{skeleton.names[chain[0]]} of {len(chain)}' for chain in found)})")
    bends = []
    for bone, joint in zip(truth.names, truth.tails):
        stem = re.sub(r"\d+$", "", bone.split(".")[0])
        if stem in BENDS:
            bends.append(f"{BENDS[stem]} ({bone}) {rc.nearest_joint(skeleton, joint)[0] / size:.4f}")
    if bends:
        lines.append(f"- nearest joint to: {', '.join(bends)}")
    stray = rc.stray_joints(skeleton, truth, size)
    lines.append(f"- joints farther than {rc.FOLLOWS} from every true joint: {len(stray)} of {len(skeleton.joints())}"
                 + "".join(f"; on {truth.names[rc.nearest_bone(truth, joint)[0]]}, "
                           f"{rc.nearest_joint(truth, joint)[0] / size:.3f} off" for joint in stray))
    lines.append("- chains (first bone, bones, near the true bone; hangs from, near the true bone):")
    for chain in rc.chains(skeleton):
        parent = rc.chain_parent(skeleton, chain)
        hangs = "the root" if parent < 0 else f"{skeleton.names[parent]} ({_near(truth, skeleton, [parent])})"
        lines.append(f"  - {skeleton.names[chain[0]]} of {len(chain)} ({_near(truth, skeleton, chain)}) from {hangs}")
    lines.append(f"- posing ({POSES} poses up to {MAX_DEGREES:.0f} degrees, seed {SEED}): " + posing_summary(
        name, vertices, triangles, truth, skeleton, size))
    return lines + [""]


def _near(truth, skeleton, bones):
    """The name of the true bone nearest the middle of ``bones`` (a chain's, by its middle bone)."""
    bone = bones[len(bones) // 2]
    return truth.names[rc.nearest_bone(truth, (skeleton.heads[bone] + skeleton.tails[bone]) / 2)[0]]


def posing_summary(name, vertices, triangles, truth, skeleton, size):
    """The true skeleton skinned by Rigger posed at random; the mean error of its own fit and of Rigger's rig, the
    excess of Rigger's over it, and the true bone whose vertices Rigger's rig misses most."""
    import posing_math as pm
    import rigdata

    rigs = {}
    for kind, bones in (("truth", truth), ("rigger", skeleton)):
        obj, _, _ = rigdata.skinned_mesh(name, vertices, triangles, bones)
        rigs[kind] = pm.skinned_rig(obj, bones)
    poses = pm.random_poses(rigs["truth"], POSES, MAX_DEGREES, np.random.default_rng(SEED))
    targets = [pm.deformed(rigs["truth"], pose, vertices) for pose in poses]
    errors = {}
    for kind, rig in rigs.items():
        fitter = pm.Fitter(rig, vertices)
        errors[kind] = np.mean([np.linalg.norm(pm.deformed(rig, fitter.fit(target)[0], vertices) - target, axis=1)
                                for target in targets], axis=0) / size
    owner = rigs["truth"].dominant()[0]
    excess = np.bincount(owner, weights=errors["rigger"] - errors["truth"], minlength=len(truth))
    counts = np.maximum(np.bincount(owner, minlength=len(truth)), 1)
    worst = int(np.argmax(excess / counts))
    return (f"true skeleton {errors['truth'].mean():.4f}, Rigger's {errors['rigger'].mean():.4f}, excess "
            f"{errors['rigger'].mean() - errors['truth'].mean():.4f}; worst on the vertices of {truth.names[worst]} "
            f"(excess {excess[worst] / counts[worst]:.4f})")


def render(bpy, demo, vertices, triangles, truth, skeleton, path, box=None):
    """A Workbench picture of the mesh from the front (left) and from its left side (right), see-through, with the
    ``truth`` and Rigger's ``skeleton``; of what lies in ``box`` (low and high corner) when given."""
    scene = empty_scene()
    low, high = (vertices.min(axis=0), vertices.max(axis=0)) if box is None else np.array(box, dtype=np.float64)
    centre, extent = (low + high) / 2, high - low
    offset, width = 0.0, 0.0
    for view, angle, across in (("front", 0.0, extent[0]), ("side", -math.pi / 2, extent[1])):
        turn = np.array([[math.cos(angle), -math.sin(angle), 0.0], [math.sin(angle), math.cos(angle), 0.0],
                         [0.0, 0.0, 1.0]])
        shift = np.array([offset + across / 2, 0.0, 0.0])

        def placed(points):
            return (np.asarray(points) - centre) @ turn.T + shift

        _add(bpy, f"{view}_skin", placed(vertices), triangles, SKIN_COLOUR)
        bones = demo.bone_mesh(bpy, placed(truth.heads), placed(truth.tails), TRUTH_WIDTH)
        _link(bpy, f"{view}_truth", bones, TRUTH_COLOUR)
        sides = np.array([rc.side_of(bone) for bone in skeleton.names], dtype=object)
        for side, colour in COLOURS.items():
            picked = np.flatnonzero(sides == side)
            if len(picked):
                bones = demo.bone_mesh(bpy, placed(skeleton.heads[picked]), placed(skeleton.tails[picked]))
                _link(bpy, f"{view}_rig_{side}", bones, colour)
        width = offset + across
        offset += across + GAP * extent.max()
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = 'ORTHO'
    camera.data.ortho_scale = 1.08 * max(width, extent[2] * RENDER_SIZE[0] / RENDER_SIZE[1])
    camera.location = (width / 2, -10.0, 0.0)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = RENDER_SIZE
    scene.display.shading.light = 'FLAT'
    scene.display.shading.color_type = 'MATERIAL'
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def _add(bpy, name, vertices, triangles, colour):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], np.asarray(triangles).tolist())
    _link(bpy, name, mesh, colour, in_front=False)


def _link(bpy, name, mesh, colour, in_front=True):
    """A new object of ``mesh`` in one colour (its alpha see-through), drawn in front of the skin or not."""
    material = bpy.data.materials.new(name)
    material.diffuse_color = colour
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.show_in_front = in_front
    bpy.context.scene.collection.objects.link(obj)


if __name__ == "__main__":
    main(sys.argv[1:] or CHARACTERS)
