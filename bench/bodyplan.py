"""Body-plan benchmark: recognition of every ../shared model against a hand label, and the named-joint error of the
humanoids against the artists' joints (issue 29, item 4).

Each model is read as Blender reads it (an OBJ up Y, forward -Z; the three Z-up OBJs up Z, as ``--up Z`` reads
them), rigged by ``rigger.rig_mesh`` (the plan and roles it fills in are the product's), and the artist's skeleton
(``rigdata.armature_skeleton`` of the rig, its separate IK roots hung from the body) is recognised on the same mesh
with ``rigger.core.bodyplan.recognise``: geometry only, since its bones are renamed ``bone_000``... A third run
turns Rigger's skeleton and the mesh back into the file's own frame and recognises them with Blender's +Z still
preferred: for the Y-up files, up must then come from the geometry alone.

Named joints: ``rigger.core.roles.named_joints``, where each role begins (a knee, a shoulder joint, a wrist), points
placed along Rigger's bones at recognition, not only at their ends. The artists' joints are named by hand
below (``NAMED``, role per joint name; a joint is left out when the rig has no such joint or it is not clear
which it is). Sides are compared by geometry (the side of the mirror plane a joint lies on), so no naming
convention matters. Errors are in units of the mesh's largest extent.

Heads: for the animals, whether Rigger's head (its bones of role head, else neck) lies from the middle of its bones
the way the hand label (``HEADS``) says the head points, as Blender imports the file.

    .venv/bin/python bench/bodyplan.py [--models NAME ...] [--out DIR]

Writes bodyplan.md, bodyplan.png and bodyplan.json to bench/results (or ``--out``; a run on ``--models`` writes to
out/bodyplan unless told otherwise).
"""
import argparse
import datetime
import json
import os
import pathlib
import platform
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import rigdata  # noqa: E402  (bench/ is not a package)
import rigger  # noqa: E402
from benchkit import (SHARED_MODELS, cpu_model, described_commit, markdown_table, picked, results_folder,  # noqa: E402
                      subset_options)
from rigger.axes import to_blender  # noqa: E402
from rigger.core.bodyplan import KINDS, recognise  # noqa: E402
from rigger.core.mesh import Mesh  # noqa: E402
from rigger.core.roles import named_joints  # noqa: E402
from rigger.core.stages import MirrorPlane  # noqa: E402

TARGET_RECOGNISED = 0.9
TARGET_MEAN_ERROR, TARGET_MAX_ERROR = 0.03, 0.06
BODY_JOINTS = ("hips", "spine", "chest", "neck", "head", "shoulder", "upper_arm", "forearm", "hand", "thigh", "shin",
               "foot", "toe")

# Hand labels, from renders of every model (matplotlib, shaded triangles from four directions): (plan, the file's up
# axis, what the model is).
MODELS = {
    "BrainStem": ("humanoid", "Z", "a robot standing in T-pose, a gun in one hand"),
    "CesiumMan": ("humanoid", "Z", "a man with a cylinder for a head, arms down at 30 degrees"),
    "Quaternius_Alpaca": ("quadruped", "Y", "an alpaca"),
    "Quaternius_Deer": ("quadruped", "Y", "a deer with antlers"),
    "Quaternius_Fox": ("quadruped", "Y", "a fox"),
    "Quaternius_Husky": ("quadruped", "Y", "a husky"),
    "Quaternius_ShibaInu": ("quadruped", "Y", "a shiba inu"),
    "Quaternius_Wolf": ("quadruped", "Y", "a wolf"),
    "RiggedSimple_blender_reexport": ("other", "Y", "an upright cylinder (Khronos' two-bone sample)"),
    "magicarticulate_0a59c5ff": ("humanoid", "Z", "a trooper in armour, A-pose, fingers"),
    "rignet_11814": ("fish", "Y", "a cartoon fish with two pectoral fins"),
    "rignet_1347": ("humanoid", "Y", "a hunched rock monster standing on two legs, blades for hands, a tail"),
    "rignet_15446": ("quadruped", "Y", "a crocodile with big eyes, standing on four legs"),
    "rignet_15930": ("humanoid", "Y", "a legless ghost: torso, arms in T-pose, head, a tapering tail"),
    "rignet_17364": ("humanoid", "Y", "a four-armed monster standing on two legs"),
    "rignet_17872": ("bird", "Y", "a crow standing, wings spread"),
    "rignet_2586": ("bird", "Y", "a round bat: a ball with two wings and ears, no legs"),
    "rignet_2982": ("quadruped", "Y", "a fox-like creature with large ears"),
    "rignet_3318": ("quadruped", "Y", "a cat with a long tail"),
    "rignet_8184": ("bird", "Y", "a penguin, flippers held out, no legs showing"),
    "rignet_8210": ("humanoid", "Y", "a woman in T-pose"),
    "rignet_8330": ("humanoid", "Y", "a boy in T-pose"),
    "rignet_8333": ("humanoid", "Y", "a man in a suit, T-pose"),
    "rignet_8338": ("quadruped", "Y", "a triceratops"),
    "rignet_9000": ("other", "Y", "a butterfly, upright: four wings, six legs, antennae"),
    "rignet_9477": ("humanoid", "Y", "a girl in a dress, T-pose"),
    "rignet_smith": ("humanoid", "Y", "a cartoon man with a big head, T-pose"),
    "alligator": ("quadruped", "Y", "an alligator, a flat cut-out seen from the side (two legs show)"),
    "cheburashka": ("humanoid", "Y", "Cheburashka: big round ears, short arms and legs"),
    "cow": ("quadruped", "Y", "a cow"),
    "homer": ("humanoid", "Y", "Homer Simpson, arms held forward"),
    "ogre": ("humanoid", "Y", "an ogre in A-pose"),
    "spot": ("quadruped", "Y", "Spot, a cartoon cow with stubby legs"),
    "woody": ("humanoid", "Y", "a gingerbread-man cut-out (flat), legs apart"),
}

_MIXAMO_PARTS = (("Shoulder", "shoulder"), ("Arm", "upper_arm"), ("ForeArm", "forearm"), ("Hand", "hand"),
                 ("HandThumb1", "finger:thumb"), ("HandIndex1", "finger:index"), ("HandMiddle1", "finger:middle"),
                 ("HandRing1", "finger:ring"), ("HandPinky1", "finger:pinky"), ("UpLeg", "thigh"), ("Leg", "shin"),
                 ("Foot", "foot"), ("ToeBase", "toe"))
_MIXAMO_NUMBERS = {"Left": ("08", "09", "010", "011", "012", "016", "020", "024", "028", "056", "057", "058", "059"),
                   "Right": ("032", "033", "034", "035", "036", "040", "044", "048", "052", "00", "061", "062", "063")}
MIXAMO = {"mixamorig_Hips_01": "hips", "mixamorig_Spine_02": "spine", "mixamorig_Spine2_04": "chest",
          "mixamorig_Neck_05": "neck", "mixamorig_Head_06": "head",
          **{f"mixamorig_{side}{part}_{number}": role for side, numbers in _MIXAMO_NUMBERS.items()
             for (part, role), number in zip(_MIXAMO_PARTS, numbers)}}

# The artists' joints by hand: joint name -> role of the bone that starts there (fingers: "finger:<digit>", the
# first segment). RigNet's humanoids follow one pattern: root at the pelvis, a hip, knee and ankle per leg, one or
# two spine joints up to the neck's base where the arms hang, then a shoulder, elbow and wrist per arm; the last joint
# of a chain (a wrist, an ankle) has no bone after it but marks where the next would start. Left out: joints whose
# place is unclear (the head's leaf joints, an ankle that may be a toe tip, the four-armed monster's two elbows, the
# robot's joint1 just above its hips, from which both its arms and its one bone up to the head start).
NAMED = {
    "magicarticulate_0a59c5ff": MIXAMO,
    "CesiumMan": {"Skeleton_torso_joint_1": "hips", "Skeleton_torso_joint_2": "spine", "torso_joint_3": "neck",
                  "Skeleton_arm_joint_L__4_": "upper_arm", "Skeleton_arm_joint_R": "upper_arm",
                  "Skeleton_arm_joint_L__3_": "forearm", "Skeleton_arm_joint_R__2_": "forearm",
                  "Skeleton_arm_joint_L__2_": "hand", "Skeleton_arm_joint_R__3_": "hand",
                  "leg_joint_L_1": "thigh", "leg_joint_R_1": "thigh", "leg_joint_L_2": "shin", "leg_joint_R_2": "shin",
                  "leg_joint_L_3": "foot", "leg_joint_R_3": "foot"},
    "BrainStem": {"joint0": "hips", "joint3": "upper_arm", "joint5": "upper_arm",
                  "joint4": "forearm", "joint6": "forearm", "joint10": "thigh", "joint14": "thigh", "joint11": "shin",
                  "joint15": "shin", "joint12": "foot", "joint16": "foot"},
    "rignet_1347": {"root": "hips", "joint_8": "neck", "joint_4": "upper_arm", "joint_14": "upper_arm",
                    "joint_0": "forearm", "joint_10": "forearm", "joint_1": "shin", "joint_11": "shin",
                    "joint_2": "foot", "joint_12": "foot"},
    "rignet_15930": {"root": "neck", "joint_2": "upper_arm", "joint_8": "upper_arm", "joint_1": "forearm",
                     "joint_7": "forearm", "joint_0": "hand", "joint_6": "hand"},
    "rignet_17364": {"root": "hips", "joint_12": "neck", "joint_2": "upper_arm", "joint_15": "upper_arm",
                     "joint_0": "thigh", "joint_13": "thigh", "joint_1": "shin", "joint_14": "shin",
                     "joint_7": "foot", "joint_20": "foot"},
    "rignet_8210": {"root": "hips", "joint_8": "neck", "joint_4": "upper_arm", "joint_13": "upper_arm",
                    "joint_1": "forearm", "joint_10": "forearm", "joint_5": "hand", "joint_14": "hand",
                    "joint_2": "thigh", "joint_11": "thigh", "joint_0": "shin", "joint_9": "shin", "joint_3": "foot",
                    "joint_12": "foot"},
    "rignet_8330": {"root": "hips", "joint_6": "spine", "joint_8": "neck", "joint_1": "upper_arm",
                    "joint_11": "upper_arm", "joint_5": "forearm", "joint_15": "forearm", "joint_4": "hand",
                    "joint_14": "hand", "joint_3": "thigh", "joint_13": "thigh", "joint_2": "shin", "joint_12": "shin",
                    "joint_0": "foot", "joint_10": "foot"},
    "rignet_8333": {"root": "hips", "joint_7": "neck", "joint_1": "upper_arm", "joint_10": "upper_arm",
                    "joint_2": "forearm", "joint_11": "forearm", "joint_5": "hand", "joint_14": "hand",
                    "joint_0": "thigh", "joint_9": "thigh", "joint_3": "shin", "joint_12": "shin", "joint_4": "foot",
                    "joint_13": "foot"},
    "rignet_9477": {"root": "hips", "joint_7": "neck", "joint_4": "upper_arm", "joint_13": "upper_arm",
                    "joint_2": "forearm", "joint_11": "forearm", "joint_0": "hand", "joint_9": "hand",
                    "joint_3": "thigh", "joint_12": "thigh", "joint_1": "shin", "joint_10": "shin", "joint_5": "foot",
                    "joint_14": "foot"},
    "rignet_smith": {"root": "hips", "joint_9": "spine", "joint_10": "neck", "joint_8": "head",
                     "joint_3": "upper_arm", "joint_15": "upper_arm", "joint_2": "forearm", "joint_14": "forearm",
                     "joint_0": "hand", "joint_12": "hand", "joint_4": "thigh", "joint_16": "thigh",
                     "joint_1": "foot", "joint_13": "foot"},
}

# The animals' hind legs by hand (Quaternius rigs: hip, knee, hock); scored apart from the humanoids' targets. Their
# front legs are left out: the artist marks a dog's elbow and a deer's carpus as the same joint.
ANIMAL_LEGS = {f"Quaternius_{animal}": {f"{joint}.{side}": role for side in ("L", "R") for joint, role in
                                        (("BackLeg", "thigh"), ("BackUpperLeg", "shin"), ("BackLowerLeg", "foot"))}
               for animal in ("Alpaca", "Deer", "Fox", "Husky", "ShibaInu", "Wolf")}

# Which way each animal's head points as Blender imports the file (the axis, in Blender's world, from the body's
# middle to its head), from renders and the artists' joints; the humanoids' heads are in the named joints.
HEADS = {**{f"Quaternius_{animal}": "-Y" for animal in ("Alpaca", "Deer", "Fox", "Husky", "ShibaInu", "Wolf")},
         "rignet_15446": "-Y", "rignet_2982": "-Y", "rignet_3318": "-Y", "rignet_8338": "-Y", "rignet_11814": "-Y",
         "alligator": "-X", "cow": "+X", "spot": "+Y"}
AXIS_VECTORS = {f"{sign}{axis}": (1.0 if sign == "+" else -1.0) * np.eye(3)[k]
                for k, axis in enumerate("XYZ") for sign in "+-"}


def model_path(name):
    folder = SHARED_MODELS / "gt" / name
    return folder if folder.is_dir() else SHARED_MODELS / "nogt" / f"{name}.obj"


def load(name):
    """(vertices, triangles, artist rig or None, rotation from the file's frame to Blender's) of model ``name``,
    vertices and rig in Blender's frame."""
    path = model_path(name)
    if path.is_dir():
        vertices, triangles, rig = rigdata.load_ground_truth(path)
    else:
        (vertices, triangles), rig = rigdata.load_obj(path), None
    turn = blender_turn(name)
    if rig is not None:
        rig = rigdata.Rig(rig.names, rig.positions @ turn.T, rig.parents, rig.root, rig.skin)
    return vertices @ turn.T, triangles.astype(np.int32), rig, turn


def blender_turn(name):
    """The rotation from model ``name``'s file frame to Blender's world, as its OBJ importer reads the file with the
    defaults for the file's up (``MODELS``): forward -Z for Y up, Y for Z up."""
    up = MODELS[name][1]
    return to_blender(up, "Y" if up == "Z" else "-Z")


def measure(name):
    """Everything measured on one model."""
    vertices, triangles, rig, turn = load(name)
    mesh = Mesh(vertices, triangles)
    size = mesh.scale
    label = MODELS[name][0]
    record = {"model": name, "label": label, "what": MODELS[name][2], "vertices": len(vertices)}
    started = time.perf_counter()
    skeleton = rigger.rig_mesh(vertices, triangles)
    record["rig_seconds"] = time.perf_counter() - started
    record["plan_seconds"] = skeleton.timings["body_plan"]
    record["rigger"] = plan_record(skeleton.body_plan, skeleton)
    record["file_frame"] = plan_record(file_frame_plan(skeleton, mesh, turn), None)
    if name in HEADS:
        record["head_right"] = head_right(skeleton, AXIS_VECTORS[HEADS[name]])
    if rig is not None:
        artist, head_joint = rigdata.armature_skeleton(rig.attached())
        plan, roles = recognise(artist, mesh)
        artist.body_plan, artist.roles = plan, roles
        record["artist"] = plan_record(plan, artist)
        if name in NAMED or name in ANIMAL_LEGS:
            axis = mirror_axis(mesh)
            middle = (axis, float(rig.positions[rig.names.index(rig.root), axis]))
            found = found_joints(skeleton, middle, size)
        if name in NAMED:
            truth = named_truth(rig, NAMED[name], middle, size)
            record["named"] = {"rigger": joint_errors(found, truth, size),
                               "nearest": nearest_joints(skeleton, truth, size),
                               "artist_roles": role_agreement(artist, head_joint, rig, NAMED[name], middle, size)}
        if name in ANIMAL_LEGS:
            record["animal_legs"] = joint_errors(found, named_truth(rig, ANIMAL_LEGS[name], middle, size), size)
    return record


def head_right(skeleton, towards):
    """Whether the skeleton's head (its bones of role head, else neck) lies from the middle of its bones towards
    ``towards``; None when it names neither."""
    middles = 0.5 * (skeleton.heads + skeleton.tails)
    for roles in (("head",), ("neck",)):
        bones = [bone for bone, role in enumerate(skeleton.roles) if role.role in roles]
        if bones:
            return bool((middles[bones].mean(axis=0) - middles.mean(axis=0)) @ towards > 0)
    return None


def plan_record(plan, skeleton):
    record = {"kind": plan.kind, "confidence": plan.confidence, "reason": plan.reason, "parts": plan.parts}
    if skeleton is not None:
        record["bones"] = len(skeleton)
        record["roles"] = sorted({role.role for role in skeleton.roles})
    return record


def file_frame_plan(skeleton, mesh, turn):
    """The plan of Rigger's skeleton and the mesh turned back into the file's frame, Blender's +Z preferred."""
    back = np.eye(4)
    back[:3, :3] = turn.T
    plane = skeleton.stages.get("mirror_plane")
    if plane is not None:
        normal = turn.T @ plane.normal
        plane = MirrorPlane(int(np.argmax(np.abs(normal))), plane.offset, normal)
    return recognise(skeleton.transformed(back), (mesh.vertices @ turn, mesh.triangles), plane=plane)[0]


def mirror_axis(mesh):
    """The axis (0, 1, 2) across which the mesh is mirror-symmetric (within 5% of its size; X when none is)."""
    from rigger.core.mirror import MirrorTuning, mirror_plane

    found = mirror_plane(mesh.used_vertices, mesh.bbox, 0.05 * mesh.scale, MirrorTuning())
    return 0 if found is None else found[0]


def side_of(points, middle, size):
    """+1, -1 or 0: the side of the mirror plane ``middle`` = (axis, offset: the artist's root joint) each point
    lies on, within 1% of the ``size`` of it."""
    axis, offset = middle
    offset = np.asarray(points)[..., axis] - offset
    return np.where(np.abs(offset) <= 0.01 * size, 0, np.sign(offset)).astype(int)


def role_key(role):
    return f"finger:{role.digit}" if role.role == "finger" and role.digit else role.role


def found_joints(skeleton, middle, size):
    """{(role, side): point} of ``rigger.core.roles.named_joints``: a role without a side on the plane, the others
    on their side by geometry (on the plane, where a leg or an arm leaves the body, by the role's side: ``L`` on the
    +X side, as Rigger's names and Blender have it for a character facing -Y)."""
    joints = {}
    for (role, side, digit), point in named_joints(skeleton).items():
        key = f"finger:{digit}" if role == "finger" and digit else role
        where = 0 if side is None else int(side_of(point, middle, size)) or {"L": 1, "R": -1}[side]
        joints.setdefault((key, where), point)
    return joints


def named_truth(rig, names, middle, size):
    """{(role, side): the artist joint's position} from the hand map ``names``."""
    index = {name: k for k, name in enumerate(rig.names)}
    missing = sorted(set(names) - set(index))
    if missing:
        raise ValueError(f"hand map names joints the rig does not have: {missing}")
    sides = side_of(rig.positions, middle, size)
    return {(role, int(sides[index[name]])): rig.positions[index[name]] for name, role in names.items()}


def joint_errors(found, truth, size):
    """Per named artist joint: the distance to the same role's joint on the same side, in mesh sizes (None when the
    skeleton names none)."""
    return {f"{role}{'.L' if side > 0 else '.R' if side < 0 else ''}":
            (None if (role, side) not in found else float(np.linalg.norm(found[(role, side)] - point) / size))
            for (role, side), point in sorted(truth.items())}


def nearest_joints(skeleton, truth, size):
    """Per named artist joint: the distance to the nearest joint of the skeleton, whatever its role (the floor any
    naming of these joints could reach), in mesh sizes."""
    joints = skeleton.joints()
    return {f"{role}{'.L' if side > 0 else '.R' if side < 0 else ''}":
            float(np.linalg.norm(joints - point, axis=1).min() / size) for (role, side), point in sorted(truth.items())}


def role_agreement(artist, head_joint, rig, names, middle, size):
    """Per named artist joint: whether the recogniser gave a bone starting there the hand map's role (side by
    geometry; a joint may start several bones: the hips start the spine and both legs' hips bones); joints ending a
    chain start no bone and are not scored."""
    sides = side_of(rig.positions, middle, size)
    given = {}
    for bone, joint in enumerate(head_joint):
        given.setdefault(int(joint), []).append(artist.roles[bone])
    result = {}
    for name, role in names.items():
        joint = rig.names.index(name)
        if joint in given:
            fits = [found for found in given[joint] if role_key(found) == role
                    and (found.side is None or {"L": 1, "R": -1}[found.side] == sides[joint])]
            result[name] = {"wanted": role, "given": role_key((fits or given[joint])[0]), "right": bool(fits)}
    return result


# Summaries, report and plot.

def confusion(records, source):
    """{label: {kind: count}} of one skeleton source ("rigger", "artist", "file_frame")."""
    table = {label: {kind: 0 for kind in KINDS} for label in KINDS}
    for record in records:
        if source in record:
            table[record["label"]][record[source]["kind"]] += 1
    return table


def recognised_share(records, source):
    scored = [record for record in records if source in record]
    return sum(record[source]["kind"] == record["label"] for record in scored), len(scored)


def error_rows(records):
    """(model, joint, error) of every named joint scored on Rigger's skeleton; error None when Rigger names none."""
    return [(record["model"], joint, error) for record in records for joint, error in
            record.get("named", {}).get("rigger", {}).items()]


def is_body_joint(joint):
    return joint.split(".")[0] in BODY_JOINTS


def summarise(records):
    rows = error_rows(records)
    found = [(model, joint, error) for model, joint, error in rows if error is not None]
    body = [error for _, joint, error in found if is_body_joint(joint)]
    agreement = [item["right"] for record in records
                 for item in record.get("named", {}).get("artist_roles", {}).values()]
    summary = {source: recognised_share(records, source) for source in ("rigger", "artist", "file_frame")}
    floor = [error for record in records for joint, error in record.get("named", {}).get("nearest", {}).items()
             if record["named"]["rigger"].get(joint) is not None]
    summary.update({
        "named_floor": float(np.mean(floor)) if floor else None,
        "named_scored": len(found), "named_missing": len(rows) - len(found),
        "named_mean": float(np.mean([error for *_, error in found])) if found else None,
        "named_max": max(found, key=lambda row: row[2]) if found else None,
        "body_mean": float(np.mean(body)) if body else None, "body_max": float(np.max(body)) if body else None,
        "over_max": sorted(((model, joint, error) for model, joint, error in found if error > TARGET_MAX_ERROR),
                           key=lambda row: -row[2]),
        "artist_role_agreement": (sum(agreement), len(agreement)),
        "heads": (sum(record.get("head_right") is True for record in records),
                  sum("head_right" in record for record in records),
                  [record["model"] for record in records if record.get("head_right") is False]),
        "plan_ms_median": 1000 * float(np.median([record["plan_seconds"] for record in records])),
        "plan_ms_max": 1000 * float(np.max([record["plan_seconds"] for record in records])),
    })
    return summary


def per_role(records, source="rigger"):
    """{role: [errors]} over the models (sides together; fingers as "finger") of Rigger's named joints, or with
    ``source`` "nearest" of the nearest joints to the same artist joints."""
    roles = {}
    for record in records:
        named = record.get("named", {})
        for joint, error in named.get("rigger", {}).items():
            if error is not None:
                roles.setdefault(joint.split(".")[0].split(":")[0], []).append(named[source][joint])
    return roles


def verdict(passed):
    return "met" if passed else "**not met**"


def report(records, summary, run):
    right, total = summary["rigger"]
    lines = [
        "# Body plan and named joints", "",
        f"`{run['command']}` on {run['started']:%Y-%m-%d %H:%M} UTC, commit {run['commit']}, {run['cpu']} "
        f"({os.cpu_count()} cores, load {run['load'][0]:.1f} at the start), Python {platform.python_version()}; "
        f"{run['seconds']:.0f} s in all. What is measured and how: the docstring of `bench/bodyplan.py`.", "",
        "## Targets", "",
        *markdown_table(["target", "result", "verdict"], [
            [f"body plan right on ≥ {TARGET_RECOGNISED:.0%} of the models (Rigger's skeletons)",
             f"{right} / {total} ({right / total:.0%})", verdict(right >= TARGET_RECOGNISED * total)],
            [f"named-joint error ≤ {TARGET_MEAN_ERROR} mean on the humanoids",
             f"{summary['named_mean']:.4f} (body joints {summary['body_mean']:.4f})",
             verdict(summary["named_mean"] <= TARGET_MEAN_ERROR)],
            [f"≤ {TARGET_MAX_ERROR} for every named joint", f"max {summary['named_max'][2]:.4f} "
             f"({summary['named_max'][0]} {summary['named_max'][1]}); {len(summary['over_max'])} of "
             f"{summary['named_scored']} above", verdict(not summary["over_max"])],
        ]), "",
        f"Also: the artists' skeletons get the right plan on {summary['artist'][0]} / {summary['artist'][1]} "
        f"models; Rigger's skeletons recognised in the files' own frames with Blender's +Z preferred (the Y-up "
        f"files must find up from geometry alone) on {summary['file_frame'][0]} / {summary['file_frame'][1]}. "
        f"The recogniser's roles on the artists' skeletons agree with the hand map on "
        f"{summary['artist_role_agreement'][0]} / {summary['artist_role_agreement'][1]} named joints. Rigger names "
        f"no joint for {summary['named_missing']} of the {summary['named_missing'] + summary['named_scored']} named "
        f"artist joints (not in the error). The nearest joint of Rigger's skeleton, whatever its role, lies "
        f"{summary['named_floor']:.4f} from the scored artist joints on average: the floor of naming Rigger's own "
        f"joints, which named joints placed along the bones may go below. Recognition takes "
        f"{summary['plan_ms_median']:.0f} ms (median; at most {summary['plan_ms_max']:.0f} ms) on top of the rig. "
        f"The animals' heads (bones named head, else neck) point the way the hand labels (``HEADS``) say on "
        f"{summary['heads'][0]} / {summary['heads'][1]}"
        + (f" (wrong: {', '.join(summary['heads'][2])})" if summary["heads"][2] else "") + ".", "",
    ]
    for source, title in (("rigger", "Rigger's skeletons (what `rig_mesh` reports)"),
                          ("artist", "the artists' skeletons (geometry only)"),
                          ("file_frame", "Rigger's skeletons in the files' own frames (up from geometry)")):
        table = confusion(records, source)
        lines += [f"## Confusion: {title}", "", "Rows: hand label; columns: recognised.", "",
                  *markdown_table(["label \\ recognised", *KINDS],
                                  [[label, *(table[label][kind] or "·" for kind in KINDS)] for label in KINDS
                                   if any(table[label].values())], numeric=True), ""]
    lines += ["## Models", "",
              *markdown_table(["model", "label", "Rigger", "confidence", "reason", "artist", "file frame"], [
                  [record["model"], record["label"], mark(record, "rigger"), f"{record['rigger']['confidence']:.2f}",
                   record["rigger"]["reason"], mark(record, "artist"), mark(record, "file_frame")]
                  for record in records]), ""]
    roles, nearest = per_role(records), per_role(records, "nearest")
    lines += ["## Named-joint error by role (Rigger's skeletons, in mesh sizes)", "",
              "Nearest: the distance from the same artist joints to the nearest joint of Rigger's skeleton, whatever "
              "its role.", "",
              *markdown_table(["role", "joints", "mean", "max", f"above {TARGET_MAX_ERROR}", "nearest: mean",
                               f"nearest above {TARGET_MAX_ERROR}"], [
                  [role, len(errors), f"{np.mean(errors):.4f}", f"{np.max(errors):.4f}",
                   sum(error > TARGET_MAX_ERROR for error in errors), f"{np.mean(nearest[role]):.4f}",
                   sum(error > TARGET_MAX_ERROR for error in nearest[role])]
                  for role, errors in sorted(roles.items(), key=lambda item: -np.mean(item[1]))], numeric=True), ""]
    lines += ["## Named-joint error by model", "",
              *markdown_table(["model", "named", "Rigger names", "mean", "max", "worst joint", "artist roles right"], [
                  model_row(record) for record in records if "named" in record]), ""]
    lines += ["## Where it fails and why", "", *failure_notes(records, summary), ""]
    lines += animal_leg_lines(records)
    return "\n".join(lines) + "\n"


def animal_leg_lines(records):
    """The animals' hind legs: Rigger's named hip joint, knee and hock against the artists' (``ANIMAL_LEGS``)."""
    legged = [record for record in records if record.get("animal_legs")]
    if not legged:
        return []
    joints = ("thigh", "shin", "foot")

    def mean(of, role):  # over both sides; a joint Rigger names none of counts as missing
        return float(np.nanmean([np.nan if error is None else error for record in of
                                 for key, error in record["animal_legs"].items() if key.split(".")[0] == role]))

    rows = [[record["model"], *(f"{mean([record], role):.4f}" for role in joints)] for record in legged]
    means = [mean(legged, role) for role in joints]
    return ["## The animals' hind legs", "",
            "Rigger's named joints where the hind leg's thigh, shin and foot begin (the hip joint, the knee and the "
            "hock) against the Quaternius artists' joints (``ANIMAL_LEGS``), in mesh sizes, both sides averaged; not "
            "part of the humanoid targets above.", "",
            *markdown_table(["model", "hip joint (thigh)", "knee (shin)", "hock (foot)"],
                            rows + [["**mean**", *(f"**{mean:.4f}**" for mean in means)]]), ""]


def mark(record, source):
    if source not in record:
        return "—"
    kind = record[source]["kind"]
    return kind if kind == record["label"] else f"**{kind}**"


def model_row(record):
    errors = {joint: error for joint, error in record["named"]["rigger"].items() if error is not None}
    agreement = [item["right"] for item in record["named"]["artist_roles"].values()]
    worst = max(errors, key=errors.get) if errors else "—"
    return [record["model"], len(record["named"]["rigger"]), len(errors),
            f"{np.mean(list(errors.values())):.4f}" if errors else "—",
            f"{max(errors.values()):.4f}" if errors else "—", worst, f"{sum(agreement)} / {len(agreement)}"]


def failure_notes(records, summary):
    notes = []
    for record in records:
        if record["rigger"]["kind"] != record["label"]:
            notes.append(f"- {record['model']} ({record['what']}): recognised as {record['rigger']['kind']} — "
                         f"{record['rigger']['reason']}.")
    nearest = {(record["model"], joint): error for record in records
               for joint, error in record.get("named", {}).get("nearest", {}).items()}
    far = [row for row in summary["over_max"] if nearest[row[:2]] > TARGET_MAX_ERROR]
    notes.append(f"- {len(summary['over_max'])} named joints lie more than {TARGET_MAX_ERROR} from the artist's; for "
                 f"{len(far)} of them no joint of Rigger's skeleton lies within {TARGET_MAX_ERROR} (the skeleton has "
                 f"no joint there), for the others a joint does but the named joint lies elsewhere:")
    for model, joint, error in summary["over_max"]:
        notes.append(f"  - {model} {joint}: {error:.3f} of the size from the artist's joint; Rigger's nearest joint "
                     f"{nearest[(model, joint)]:.3f}.")
    return notes


def plot(records, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, grid = plt.subplots(1, 3, figsize=(19, 6))
    for axes, source, title in ((grid[0], "rigger", "Rigger's skeletons"), (grid[1], "artist", "artists' skeletons")):
        table = confusion(records, source)
        matrix = np.array([[table[label][kind] for kind in KINDS] for label in KINDS])
        axes.imshow(matrix, cmap="Blues")
        for (row, column), count in np.ndenumerate(matrix):
            if count:
                axes.text(column, row, str(count), ha="center", va="center",
                          color="white" if count > matrix.max() / 2 else "black")
        axes.set_xticks(range(len(KINDS)), KINDS, rotation=30)
        axes.set_yticks(range(len(KINDS)), KINDS)
        axes.set_xlabel("recognised")
        axes.set_ylabel("hand label")
        right, total = recognised_share(records, source)
        axes.set_title(f"Body plan, {title}: {right} / {total} right")
    roles = per_role(records)
    order = sorted(roles, key=lambda role: np.mean(roles[role]))
    axes = grid[2]
    for k, role in enumerate(order):
        axes.scatter(roles[role], [k] * len(roles[role]), color="tab:red", s=14, alpha=0.6)
        axes.scatter([np.mean(roles[role])], [k], color="black", marker="|", s=200)
    axes.axvline(TARGET_MEAN_ERROR, color="tab:green", linestyle="--", label=f"target mean {TARGET_MEAN_ERROR}")
    axes.axvline(TARGET_MAX_ERROR, color="tab:orange", linestyle="--", label=f"target max {TARGET_MAX_ERROR}")
    axes.set_yticks(range(len(order)), order)
    axes.set_xlabel("distance to the artist's joint (mesh sizes); | mean")
    axes.set_title("Named-joint error on the humanoids, Rigger's skeletons")
    axes.legend(loc="lower right")
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    subset_options(parser, "bodyplan")
    args = parser.parse_args(argv)
    if not SHARED_MODELS.is_dir():
        raise SystemExit(f"No models at {SHARED_MODELS}: the body-plan benchmark needs ../shared beside the checkout.")
    names = sorted(MODELS)
    absent = [name for name in names if not model_path(name).exists()]
    if absent:
        raise SystemExit(f"Models missing from {SHARED_MODELS}: {', '.join(absent)}")
    names = picked(names, args.models)
    out = results_folder(args, "bodyplan")
    arguments = " ".join(argv if argv is not None else sys.argv[1:])
    run = {"command": f"python bench/bodyplan.py {arguments}".rstrip(),
           "started": datetime.datetime.now(datetime.timezone.utc), "load": os.getloadavg(), "cpu": cpu_model(),
           "commit": described_commit()}
    started = time.perf_counter()
    records = []
    for name in names:
        record = measure(name)
        records.append(record)
        print(f"{name:30s} {record['label']:9s} rigger {record['rigger']['kind']:9s} "
              f"artist {record.get('artist', {}).get('kind', '—'):9s} file {record['file_frame']['kind']:9s}",
              flush=True)
    run["seconds"] = time.perf_counter() - started
    summary = summarise(records)
    (out / "bodyplan.md").write_text(report(records, summary, run))
    plot(records, out / "bodyplan.png")
    (out / "bodyplan.json").write_text(json.dumps({"run": {**run, "started": run["started"].isoformat()},
                                                   "summary": summary, "records": records}, indent=1))
    print(f"wrote {out / 'bodyplan.md'}")


if __name__ == "__main__":
    main()
