"""Motion capture onto a game skeleton (bpy-free; ``rigger.blender.animate`` reads the BVH and writes the action).

Mapping: each game bone (``rigger.core.game``'s names) takes the mocap joint whose name, with any namespace
(``mixamorig:``) and separators dropped and case ignored, is one of its aliases (``aliases``: CMU's ``LowerBack``,
Mixamo's, ``LeftUpLeg`` / ``LeftThigh`` / ``lThigh`` / ``thigh_l`` and so on). The spine's joints between the hips
and the neck are shared out over Spine, Spine1 and Spine2 in order; of several neck joints, the Neck takes the one
the head sits on (CMU's Neck1, whose segment tilts as the neck does where CMU's lower Neck leans back and Neck1
leans forward again). The mapping fails, naming what is missing, when
the hips, a leg (UpLeg, Leg, Foot) or an arm (Arm, ForeArm) of the game skeleton finds no joint.

Retargeting, frame by frame (all in the game armature's space):

- A first frame the joints jump out of, by more than ``REFERENCE_JUMP`` times the clip's median step from frame to
  frame, is a reference pose, not motion (CMU's files start with one, every joint at rest): it is left out
  (:func:`captured`), so a looping clip does not flash it.
- The mocap is turned about its up so that its left (from the right hip to the left one) and up meet the
  character's (``Clip.up``: Blender's BVH importer reads files Y up, into +Z).
- Limb bones (shoulders, arms, legs, hands, fingers) take their joint's rotation since its rest, after a fixed swing
  that lays the character's bone along the mocap's bone at rest: their directions follow the mocap's whatever either
  rest pose is (a T-pose onto an A-pose). The trunk, neck and head take their joint's rotation since its rest as it
  is: both stand upright at rest. Feet and toes turn as their joint's line does from where it lies when the foot is
  flat, without the twist about that line (:func:`_level`). Bones without a joint turn with their parent.
- The hips move as the mocap's do, scaled by the ratio of the legs' lengths (hip joint to knee to ankle): across the
  ground from where the character stands, and up and down from its rest height where the mocap's hips would stand
  on straight legs with flat feet. Heights are measured from the mocap's ground (:func:`mocap_ground`, a plane
  through its planted toes); a flat foot's ankle and toe joint stand as high above it as they do, in the median, in
  the frames that foot lies flat (:func:`_flat_frames`).
- Each leg then reaches, by two-bone IK bending the knee forward (the thigh's turned rest forward), for the
  ankle height that puts the foot's lowest sole point (:func:`_lowest_sole`: the skin the foot and toes carry, else
  the bones' heel and far end) as high above its rest height as, scaled, the lower of the mocap's ankle and toe
  joint is above their heights when its foot lies flat (never below): a heel raised to push off pivots on the toes,
  and the sole neither sinks into the ground nor floats. In a frame where a leg would not reach, the hips come down
  until it does. Feet planted in the mocap are planted in the character whatever the legs' proportions.
"""
import re
from dataclasses import dataclass, field, replace

import numpy as np

from .rotations import between

REFERENCE_JUMP = 10.0  # a first frame the joints leave by this many times the clip's median step is no motion
SIDES = (("Left", ("left", "l")), ("Right", ("right", "r")))
SIDED_WORDS = {  # a game bone's word: aliases of the word, best first (sides are added around them)
    "Shoulder": ("shoulder", "collar", "clavicle"),
    "Arm": ("arm", "uparm", "upperarm", "shldr", "humerus"),
    "ForeArm": ("forearm", "lowarm", "lowerarm", "elbow"),
    "Hand": ("hand", "wrist"),
    "UpLeg": ("upleg", "thigh", "upperleg", "hip"),
    "Leg": ("leg", "lowleg", "lowerleg", "knee", "shin", "calf"),
    "Foot": ("foot", "ankle"),
    "ToeBase": ("toebase", "toe", "toes", "ball"),
}
DIGITS = {"Thumb": ("thumb",), "Index": ("index",), "Middle": ("middle",), "Ring": ("ring",),
          "Pinky": ("pinky", "little")}
MIDDLE = {"Hips": ("hips", "hip", "pelvis", "root"), "Neck": ("neck", "neck1", "neck01"), "Head": ("head",)}
SPINE = ("Spine", "Spine1", "Spine2")
SPINE_WORDS = ("lowerback", "spine", "abdomen", "chest", "torso", "back")
REQUIRED = ("Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot", "LeftArm",
            "LeftForeArm", "RightArm", "RightForeArm")
SWUNG = re.compile(r"Shoulder|Arm|ForeArm|Hand|UpLeg|Leg|Hand(Thumb|Index|Middle|Ring|Pinky)\d")  # laid along the
# mocap's bones at rest
CONTACT_HEIGHT = 0.05  # a planted foot's joint is this close to the ground (leg lengths) ...
CONTACT_SPEED = 0.5  # ... and slower than this (leg lengths a second)
MAX_SLOPE = 0.05  # the steepest capture floor taken (a rise over a run) ...
SLOPE_RUN = 2.0  # ... fitted only when the feet go this many leg lengths
SOLE_DIRECTIONS = 1024  # directions around the sphere whose extreme skin points can be a foot's lowest
SOLE_ROUNDS = 8  # a leg without a foot bone reaches at most this many times for its sole ...
SOLE_SETTLED = 0.002  # ... until the sole's height over its ankle changes less than this share of a thigh


class RetargetError(ValueError):
    """A motion that cannot drive the game skeleton; the message names the bones and joints."""


def normalised(name):
    """A joint name as aliases are written: namespace (``mixamorig:``, ``mixamorig1_``) and separators dropped,
    lower case."""
    name = name.split(":")[-1].split("|")[-1]
    name = re.sub(r"^mixamorig\d*_?", "", name, flags=re.IGNORECASE)
    return re.sub(r"[^0-9a-z]", "", name.lower())


def aliases(game_name):
    """The normalised joint names that can drive game bone ``game_name``, best first (empty when none can)."""
    if game_name in MIDDLE:
        return MIDDLE[game_name]
    for side, short in SIDES:
        if not game_name.startswith(side):
            continue
        word = game_name[len(side):]
        if word in SIDED_WORDS:
            words = SIDED_WORDS[word]
        else:
            match = re.fullmatch(r"Hand(Thumb|Index|Middle|Ring|Pinky)([123])", word)
            if match is None:
                return ()
            digit, number = match.groups()
            words = tuple(form for alias in DIGITS[digit]
                          for form in (f"hand{alias}{number}", f"{alias}{number}", f"{alias}0{number}")
                          + ((f"hand{alias}", alias) if number == "1" else ()))
        return tuple(f"{prefix}{w}" for w in words for prefix in short) + \
            tuple(f"{w}{suffix}" for w in words for suffix in short)
    return ()


@dataclass
class Mapping:
    """Which mocap joint drives each game bone (``driven``: game name -> joint index), the game bones no joint drives
    (``undriven``), the joints that drive nothing (``unused``), the toe joints by side (``toes``: "Left" -> joint
    index) and each side's hip, knee and ankle joints (``legs``: "Left" -> three joint indices), which tell where
    the feet touch the ground even when the character has no toe or foot bones."""

    driven: dict
    undriven: list
    unused: list
    toes: dict = field(default_factory=dict)
    legs: dict = field(default_factory=dict)


def map_joints(joint_names, joint_parents, game_names):
    """The :class:`Mapping` of mocap joints ``joint_names`` (parents ``joint_parents``) onto ``game_names``;
    :class:`RetargetError` naming the required game bones (``REQUIRED`` that the game skeleton has) no joint drives
    and the joints left unplaced."""
    normal = [normalised(name) for name in joint_names]
    first = {}
    for index, name in enumerate(normal):
        first.setdefault(name, index)
    driven = {}
    for game in game_names:
        joint = next((first[alias] for alias in aliases(game) if alias in first), None)
        if joint is not None and joint not in driven.values():
            driven[game] = joint
    if "Hips" in driven:  # the spine: the joints between the hips and the neck (or the arms' parent), in order
        top = driven.get("Neck", driven.get("LeftShoulder", driven.get("LeftArm")))
        path = []
        while top is not None and top >= 0 and top != driven["Hips"]:
            path.append(top)
            top = joint_parents[top]
        chain = [j for j in reversed(path[1:]) if j not in driven.values()
                 and any(word in normal[j] for word in SPINE_WORDS)] if top == driven["Hips"] else []
        spine = [name for name in SPINE if name in game_names]
        for k, name in enumerate(spine):
            if chain:
                driven[name] = chain[min(len(chain) - 1, round(k * (len(chain) - 1) / max(len(spine) - 1, 1)))]
    head = driven.get("Head")
    above = joint_parents[head] if head is not None and "Neck" in driven else -1
    if above >= 0 and "neck" in normal[above] and above not in driven.values():
        driven["Neck"] = above  # one game neck: the mocap's neck joint next to the head (CMU's Neck1, not Neck)
    undriven = [name for name in game_names if name not in driven and name != "root"]
    def joint_for(name):  # the joint driving game bone ``name``, or the one that would if the game had it
        return driven.get(name, next((first[alias] for alias in aliases(name) if alias in first), None))

    toes = {side: joint for side in ("Left", "Right") if (joint := joint_for(f"{side}ToeBase")) is not None}
    legs = {side: joints for side in ("Left", "Right")
            if None not in (joints := tuple(joint_for(f"{side}{word}") for word in ("UpLeg", "Leg", "Foot")))}
    used = set(driven.values()) | set(toes.values()) | {joint for joints in legs.values() for joint in joints}
    unused = [joint_names[j] for j in range(len(joint_names)) if j not in used]
    missing = [name for name in REQUIRED if name in game_names and name not in driven]
    if missing:
        raise RetargetError(f"the motion cannot drive the game bones {', '.join(missing)}: none of its joints has a "
                            f"name they take (the common mocap names: Hips, LeftUpLeg, LeftLeg, LeftFoot, LeftArm, "
                            f"LeftForeArm, ...); joints it could not place: {', '.join(unused) or 'none'}")
    return Mapping(driven, undriven, unused, toes, legs)


@dataclass
class Clip:
    """A motion: joint ``names`` and ``parents``, ``rest`` (J, 4, 4) and ``poses`` (F, J, 4, 4) world matrices of
    every joint (rotation: the joint's frame; translation: where it is), frames per second and the world ``up``."""

    names: tuple
    parents: np.ndarray
    rest: np.ndarray
    poses: np.ndarray
    fps: float
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))


@dataclass
class Rig:
    """The game armature at rest: bone ``names``, ``parents``, ``rest`` (B, 4, 4) matrices (Blender's
    ``bone.matrix_local``: the bone's frame, its head as translation), ``tails`` (B, 3), its ``up`` and the height
    of its ``ground`` along it, all in the armature's space; ``soles``: per foot or toe bone index, the points of the
    skin that bone carries which can touch the ground (:func:`sole_points`), when the rig has a skin."""

    names: tuple
    parents: np.ndarray
    rest: np.ndarray
    tails: np.ndarray
    up: np.ndarray
    ground: float
    soles: dict = field(default_factory=dict)


@dataclass
class Motion:
    """Baked keys: per frame and bone, the pose rotation (``rotations`` (F, B, 4) quaternions w, x, y, z, relative to
    the rest pose, as ``pose_bone.rotation_quaternion``), the Hips' pose ``location`` (F, 3) and the ``scale`` the
    mocap's lengths were taken at, with the :class:`Mapping`; ``skipped``: the clip's frames left out at its start (a
    reference pose)."""

    rotations: np.ndarray
    location: np.ndarray
    hips: int
    fps: float
    scale: float
    mapping: Mapping
    skipped: int = 0


def captured(clip):
    """``clip`` without a first frame that is a reference pose (the module docstring) and how many frames that left
    out (0 or 1)."""
    if len(clip.poses) < 3:
        return clip, 0
    steps = np.linalg.norm(np.diff(clip.poses[:, :, :3, 3], axis=0), axis=2).max(axis=1)
    if steps[0] > REFERENCE_JUMP * np.median(steps[1:]):
        return replace(clip, poses=clip.poses[1:]), 1
    return clip, 0


def retarget(clip, rig, mapping=None):
    """The :class:`Motion` of ``clip`` on ``rig`` (see the module docstring)."""
    clip, skipped = captured(clip)
    mapping = mapping or map_joints(clip.names, clip.parents, rig.names)
    index = {name: k for k, name in enumerate(rig.names)}
    legs = [f"{side}{word}" for side in ("Left", "Right") for word in ("UpLeg", "Leg")]
    if "Hips" not in mapping.driven or any(name not in mapping.driven for name in legs):
        raise RetargetError(f"a motion needs the character's hips and both legs (UpLeg, Leg) to carry it; "
                            f"this rig lacks {', '.join(n for n in ['Hips', *legs] if n not in mapping.driven)}")
    if len(mapping.legs) < 2:
        raise RetargetError("the motion needs both legs down to the ankles (UpLeg, Leg, Foot) to carry a character")
    drive = {index[name]: joint for name, joint in mapping.driven.items()}
    up = _unit(rig.up)
    turn, forward = _alignment(clip, rig, mapping.driven, index, up)
    frames = len(clip.poses)
    rest_rot = rig.rest[:, :3, :3]
    heads = rig.rest[:, :3, 3]
    directions = rig.tails - heads
    swing = {}
    for bone, joint in drive.items():
        if SWUNG.fullmatch(_word(rig.names[bone])):
            end = _segment_end(clip, joint, mapping, rig, bone)
            if end is not None:
                swing[bone] = between(directions[bone], turn @ (clip.rest[end, :3, 3] - clip.rest[joint, :3, 3]))
    ground, ankles = _planted(clip, mapping)
    level = {index[name]: _level(clip, mapping.driven[name], _flat_frames(clip, mapping, ground, side), turn, up)
             for side in ("Left", "Right") for name in (f"{side}Foot", f"{side}ToeBase")
             if name in mapping.driven and name in index}
    deltas = np.einsum("fjab,jcb->fjac", clip.poses[:, :, :3, :3], clip.rest[:, :3, :3])  # pose * rest^T
    deltas = np.einsum("ab,fjbc,dc->fjad", turn, deltas, turn)
    world = np.empty((frames, len(rig.names), 3, 3))
    for bone in range(len(rig.names)):
        parent = rig.parents[bone]
        if bone in level:
            world[:, bone] = level[bone]
        elif bone in drive:
            world[:, bone] = deltas[:, drive[bone]] @ swing.get(bone, np.eye(3))
        else:
            world[:, bone] = world[:, parent] if parent >= 0 else np.eye(3)
    scale = _leg_scale(clip, rig, mapping, index)
    hips = index["Hips"]
    hips_at = _hips_path(clip, rig, mapping, index, turn, up, scale, ground, ankles)
    _reach_ankles(clip, rig, mapping, index, world, hips_at, up, forward, scale, ground, ankles)
    rotations = np.empty((frames, len(rig.names), 4))
    for bone in range(len(rig.names)):
        parent = rig.parents[bone]
        parent_world = world[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), (frames, 3, 3))
        local = np.einsum("ba,fcb,fcd,de->fae", rest_rot[bone], parent_world, world[:, bone], rest_rot[bone])
        rotations[:, bone] = _continuous(_quaternions(local))
    location = (hips_at - heads[hips]) @ rest_rot[hips]  # into the Hips' rest frame
    return Motion(rotations, location, hips, clip.fps, scale, mapping, skipped)


def posed_points(rig, world, hips_at):
    """Heads and tails (F, B, 3) of ``rig``'s bones posed with world rotations ``world`` (F, B, 3, 3) (relative to
    rest) and the Hips' head at ``hips_at`` (F, 3): every bone's head rides on its parent."""
    heads = rig.rest[:, :3, 3]
    frames = len(world)
    posed_heads = np.empty((frames, len(rig.names), 3))
    hips = rig.names.index("Hips")
    for bone in range(len(rig.names)):
        parent = rig.parents[bone]
        if bone == hips:
            posed_heads[:, bone] = hips_at
        elif parent < 0:
            posed_heads[:, bone] = heads[bone]
        else:
            posed_heads[:, bone] = posed_heads[:, parent] + world[:, parent] @ (heads[bone] - heads[parent])
    posed_tails = posed_heads + np.einsum("fbij,bj->fbi", world, rig.tails - heads)
    return posed_heads, posed_tails


def sole_bones(names, side):
    """The names of the bones whose skin a leg on ``side`` ("Left"/"Right") stands on, of those in ``names``: its
    Foot and ToeBase, else (a leg without a foot bone) its Leg."""
    carriers = (f"{side}Foot", f"{side}ToeBase") if f"{side}Foot" in names else (f"{side}Leg",)
    return tuple(name for name in carriers if name in names)


def sole_points(points, up):
    """The points of ``points`` (N, 3), the skin one foot or toe bone carries, that can be its lowest however it
    turns up to a right angle from rest: the extremes along ``SOLE_DIRECTIONS`` directions spread over the lower
    half sphere about ``up`` (the lowest point of a turned rigid body is an extreme one)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not len(points):
        return points
    k = np.arange(SOLE_DIRECTIONS) + 0.5  # a Fibonacci sphere
    height = 1 - 2 * k / SOLE_DIRECTIONS
    angle = np.pi * (1 + 5 ** 0.5) * k
    ring = np.sqrt(1 - height ** 2)
    directions = np.column_stack([ring * np.cos(angle), ring * np.sin(angle), height])
    directions = directions[directions @ _unit(up) < 0]
    return points[np.unique(np.argmax(points @ directions.T, axis=0))]


def contact_frames(clip, mapping, side, ground=None):
    """Frames (bool (F,)) where the mocap's foot on ``side`` ("Left"/"Right") is planted: its lowest joint (toe,
    else ankle) within ``CONTACT_HEIGHT`` leg lengths of the mocap's ground (``ground``, else
    :func:`mocap_ground`) and slower than ``CONTACT_SPEED`` leg lengths a second."""
    ground = mocap_ground(clip, mapping) if ground is None else ground
    joint = _foot_joint(mapping, side)
    path = clip.poses[:, joint, :3, 3]
    speed = np.linalg.norm(np.gradient(path, axis=0), axis=1) * clip.fps
    return (ground.height(path) <= CONTACT_HEIGHT * ground.leg) & (speed <= CONTACT_SPEED * ground.leg)


@dataclass(frozen=True)
class Ground:
    """The mocap's ground: a plane through its planted toe joints (or ankles), at ``offset`` along ``up`` at the
    origin, rising by ``slope`` (a vector across ``up``) per unit across; ``leg`` is the mocap's leg length."""

    up: np.ndarray
    offset: float
    slope: np.ndarray
    leg: float

    def height(self, points):
        """Heights of ``points`` (..., 3) above the ground."""
        points = np.asarray(points, dtype=np.float64)
        return points @ self.up - self.offset - points @ self.slope


def mocap_ground(clip, mapping):
    """The :class:`Ground` the mocap's feet stand on: a plane fitted to its toe joints (else ankles) in the frames
    they move slower than ``CONTACT_SPEED`` leg lengths a second, leaving out those more than ``CONTACT_HEIGHT``
    leg lengths above it (a foot still in the air, the top of a jump). Capture floors tilt (CMU's walk climbs 0.7
    of its units over its 50); the slope is at most ``MAX_SLOPE``, and none when the feet stay within ``SLOPE_RUN``
    leg lengths of one place (feet apart on a level floor would tilt it)."""
    up = _unit(clip.up)
    leg = np.mean([length for side in ("Left", "Right")
                   if (length := _leg_length(clip.rest, mapping, side))])
    joints = [_foot_joint(mapping, side) for side in ("Left", "Right")]
    paths = clip.poses[:, joints, :3, 3]
    speed = np.linalg.norm(np.gradient(paths, axis=0), axis=2) * clip.fps
    points = paths[speed <= CONTACT_SPEED * leg]
    if len(points) < 3:
        points = paths.reshape(-1, 3)
    heights = points @ up
    across = points - np.outer(heights, up)
    axes = np.linalg.svd(np.eye(3) - np.outer(up, up))[0][:, :2]  # two directions across up
    flat = across @ axes
    kept = heights <= np.percentile(heights, 25) + CONTACT_HEIGHT * leg
    offset, slope = float(np.median(heights[kept])), np.zeros(3)
    spread = np.ptp(flat[kept], axis=0).max() if kept.any() else 0.0
    if kept.sum() >= 3 and spread > SLOPE_RUN * leg:
        for _ in range(4):
            design = np.column_stack([np.ones(kept.sum()), flat[kept]])
            solution = np.linalg.lstsq(design, heights[kept], rcond=None)[0]
            gradient = solution[1:]
            if np.linalg.norm(gradient) > MAX_SLOPE:
                gradient *= MAX_SLOPE / np.linalg.norm(gradient)
            offset, slope = float(np.median(heights[kept] - flat[kept] @ gradient)), axes @ gradient
            kept = heights - offset - points @ slope <= CONTACT_HEIGHT * leg
    return Ground(up, offset, slope, float(leg))


def _word(name):
    return name[4:] if name.startswith("Left") else name[5:] if name.startswith("Right") else name


def _unit(vector):
    vector = np.asarray(vector, dtype=np.float64)
    return vector / np.linalg.norm(vector)


def _alignment(clip, rig, driven, index, up):
    """(the rotation taking the mocap's (left, up, forward) at rest onto the character's, the character's
    forward)."""
    def left_of(points, names):
        for a, b in (("LeftUpLeg", "RightUpLeg"), ("LeftArm", "RightArm"), ("LeftShoulder", "RightShoulder")):
            if a in names and b in names:
                return points(names[a]) - points(names[b])
        raise RetargetError("the motion and the character need a left and a right leg or arm to face each other")

    source_up = _unit(clip.up)
    source_left = left_of(lambda j: clip.rest[j, :3, 3], driven)
    target_left = left_of(lambda name: rig.rest[index[name], :3, 3], {n: n for n in driven if n in index})
    frames = []
    for left, upward in ((source_left, source_up), (target_left, up)):
        left = _unit(left - (left @ upward) * upward)
        frames.append(np.column_stack([left, upward, np.cross(left, upward)]))
    return frames[1] @ frames[0].T, frames[1][:, 2]


def _level(clip, joint, flat, turn, up):
    """World rotations (F, 3, 3) of the character's foot (or toe) bone that mocap ``joint`` drives: the turn taking
    the joint's line as it lies when its foot is flat (the median slope over the frames ``flat``, its rest heading)
    onto its line in each frame, keeping the line across the bone (at right angles to it and to up) level. Capture
    solvers leave a foot's twist about its own line loose (CMU's walk rolls a planted foot by 25 degrees), so the
    twist is not taken: a flat foot's sole lies level across."""
    along = clip.poses[:, joint, :3, 1] @ turn.T  # a bone's line is its Y axis
    rest = turn @ clip.rest[joint, :3, 1]
    heading = rest - (rest @ up) * up
    if np.linalg.norm(heading) < 1e-6:  # a rest foot pointing straight down: no heading to level it by
        return np.einsum("ab,fbc,dc->fad", turn, clip.poses[:, joint, :3, :3] @ clip.rest[joint, :3, :3].T, turn)
    slope = float(np.clip(np.median(along[flat] @ up) if flat.any() else rest @ up, -1.0, 1.0))
    reference = np.sqrt(1 - slope ** 2) * _unit(heading) + slope * up
    return _level_frames(along, up, reference) @ _level_frames(reference[None], up, reference)[0].T


def _level_frames(lines, up, reference):
    """Rotation frames (N, 3, 3) whose columns are each line of ``lines`` (N, 3), the level line across it and the
    third; a line along ``up`` takes ``reference``'s across."""
    lines = lines / np.linalg.norm(lines, axis=1, keepdims=True)
    across = np.cross(lines, up)
    length = np.linalg.norm(across, axis=1, keepdims=True)
    across = np.where(length > 1e-6, across / np.maximum(length, 1e-12), _unit(np.cross(reference, up)))
    return np.stack([lines, across, np.cross(across, lines)], axis=2)


def _segment_end(clip, joint, mapping, rig, bone):
    """The joint ending the mocap bone of ``joint`` for game bone ``bone``: the joint driving the game bone's first
    child, else ``joint``'s nearest descendant away from it."""
    children = [] if rig is None else [k for k, parent in enumerate(rig.parents) if parent == bone]
    for child in children:
        end = mapping.driven.get(rig.names[child])
        if end is not None and np.linalg.norm(clip.rest[end, :3, 3] - clip.rest[joint, :3, 3]) > 0:
            return end
    todo = [k for k, parent in enumerate(clip.parents) if parent == joint]
    while todo:
        k = todo.pop(0)
        if np.linalg.norm(clip.rest[k, :3, 3] - clip.rest[joint, :3, 3]) > 0:
            return k
        todo += [c for c, parent in enumerate(clip.parents) if parent == k]
    return None


def _leg_length(points, mapping, side):
    """The mocap's hip joint to knee to ankle on ``side``, from (J, 4, 4) matrices ``points``."""
    joints = mapping.legs.get(side)
    if joints is None:
        return None
    at = points[list(joints), :3, 3]
    return float(np.linalg.norm(np.diff(at, axis=0), axis=1).sum())


def _rig_leg_length(rig, index, side):
    bones = [index.get(f"{side}{word}") for word in ("UpLeg", "Leg")]
    if None in bones:
        return None
    return float(sum(np.linalg.norm(rig.tails[bone] - rig.rest[bone, :3, 3]) for bone in bones))


def _leg_scale(clip, rig, mapping, index):
    """The character's leg length over the mocap's (the mean of both sides that both have)."""
    ratios = [target / source for side in ("Left", "Right")
              for source, target in [(_leg_length(clip.rest, mapping, side), _rig_leg_length(rig, index, side))]
              if source and target]
    if not ratios:
        raise RetargetError("the motion and the character need legs (UpLeg, Leg, Foot) to be scaled to each other")
    return float(np.mean(ratios))


def _foot_joint(mapping, side):
    """The mocap's joint that touches the ground on ``side``: its toe joint, else its ankle."""
    return mapping.toes.get(side, mapping.legs[side][2])


def _planted(clip, mapping):
    """(the mocap's :class:`Ground`; per side, how high its ankle and its toe joint stand above the ground when the
    foot lies flat on it: the medians over the frames it does (:func:`_flat_frames`), else as at rest)."""
    ground = mocap_ground(clip, mapping)
    heights = {}
    for side in ("Left", "Right"):
        ankle, toe = mapping.legs[side][2], _foot_joint(mapping, side)
        flat = _flat_frames(clip, mapping, ground, side)
        if flat.any():
            heights[side] = tuple(float(np.median(ground.height(clip.poses[flat, joint, :3, 3])))
                                  for joint in (ankle, toe))
        else:
            heights[side] = (float((clip.rest[ankle, :3, 3] - clip.rest[toe, :3, 3]) @ ground.up), 0.0)
    return ground, heights


def _flat_frames(clip, mapping, ground, side):
    """Frames where the mocap's foot on ``side`` lies flat: planted (:func:`contact_frames`) with its ankle slower
    than ``CONTACT_SPEED`` leg lengths a second too (a heel rising to push off or falling onto the ground is not)."""
    path = clip.poses[:, mapping.legs[side][2], :3, 3]
    speed = np.linalg.norm(np.gradient(path, axis=0), axis=1) * clip.fps
    return contact_frames(clip, mapping, side, ground) & (speed <= CONTACT_SPEED * ground.leg)


def _hips_path(clip, rig, mapping, index, turn, up, scale, ground, ankles):
    """Where the character's hips go (F, 3): see the module docstring."""
    source_up = _unit(clip.up)
    hips = mapping.driven["Hips"]
    path = clip.poses[:, hips, :3, 3]
    rest = clip.rest[:, :3, 3]
    standing = np.mean([(rest[hips] - rest[mapping.legs[side][0]]) @ source_up
                        + _leg_length(clip.rest, mapping, side) + ankles[side][0] for side in ("Left", "Right")])
    across = (path - path[0]) @ turn.T
    across -= np.outer(across @ up, up)
    height = ground.height(path) - standing
    return rig.rest[index["Hips"], :3, 3] + scale * (across + np.outer(height, up))


def _reach_ankles(clip, rig, mapping, index, world, hips_at, up, forward, scale, ground, ankles):
    """Turn each leg's UpLeg and Leg (in ``world``, in place) so the ankle reaches its height (module docstring),
    lowering the hips (``hips_at``, in place) in the frames a leg would not reach that far. The ankle is the Foot's
    head, else the Leg's tail; a sole the Leg carries turns as the leg reaches, so such legs reach again until their
    soles settle (within ``SOLE_SETTLED`` of a thigh's length; at most ``SOLE_ROUNDS`` times)."""
    rest = rig.rest[:, :3, 3]
    legs = []
    for side in ("Left", "Right"):
        thigh, shin, foot = (index.get(f"{side}{word}") for word in ("UpLeg", "Leg", "Foot"))
        if thigh is None or shin is None:
            continue
        source_ankle = ground.height(clip.poses[:, mapping.legs[side][2], :3, 3])
        source_toe = ground.height(clip.poses[:, _foot_joint(mapping, side), :3, 3])
        flat_ankle, flat_toe = ankles[side]
        lift = scale * np.maximum(np.minimum(source_ankle - flat_ankle, source_toe - flat_toe), 0.0)
        carriers = [index[name] for name in sole_bones(index, side)]
        rest_ankle = rig.rest[foot, :3, 3] if foot is not None else rig.tails[shin]
        legs.append((thigh, shin, foot, lift, carriers, rest_ankle))
    settled = SOLE_SETTLED * min((np.linalg.norm(rest[shin] - rest[thigh]) for thigh, shin, *_ in legs), default=0.0)
    heights = None
    for _ in range(1 if all(foot is not None for _, _, foot, *_ in legs) else SOLE_ROUNDS):
        heads, _ = posed_points(rig, world, hips_at)
        targets, previous, heights = [], heights, []
        for thigh, shin, foot, lift, carriers, rest_ankle in legs:
            ankle = _ankle(rig, world, heads, shin, foot)
            lowest, rest_lowest = _lowest_sole(rig, carriers, world, heads, ankle, rest_ankle)
            heights.append(rest_lowest - lowest)
            height = rest_ankle @ up + lift + heights[-1]
            targets.append(ankle + np.outer(height - ankle @ up, up))
        if previous is not None and max(np.abs(a - b).max() for a, b in zip(heights, previous)) <= settled:
            break
        drop = np.zeros(len(world))
        for (thigh, shin, _, _, _, rest_ankle), target in zip(legs, targets):
            reach = 0.999 * (np.linalg.norm(rest[shin] - rest[thigh]) + np.linalg.norm(rest_ankle - rest[shin]))
            offset = heads[:, thigh] - target
            rise = offset @ up
            across = np.linalg.norm(offset - np.outer(rise, up), axis=1)
            drop = np.maximum(drop, rise - np.sqrt(np.maximum(reach ** 2 - across ** 2, 0.0)))
        hips_at -= np.outer(drop, up)
        heads, _ = posed_points(rig, world, hips_at)
        for (thigh, shin, foot, _, _, rest_ankle), target in zip(legs, targets):
            ankle = _ankle(rig, world, heads, shin, foot)
            upper, lower = np.linalg.norm(rest[shin] - rest[thigh]), np.linalg.norm(rest_ankle - rest[shin])
            hip, knee = heads[:, thigh], heads[:, shin]
            for frame in range(len(world)):  # knees bend forward: towards the thigh's turned rest forward,
                pole = knee[frame] + (upper + lower) * (world[frame, thigh] @ forward)  # a leg's length ahead
                new_knee = _two_bone(hip[frame], pole, target[frame], upper, lower)
                world[frame, thigh] = between(knee[frame] - hip[frame], new_knee - hip[frame]) @ world[frame, thigh]
                world[frame, shin] = between(ankle[frame] - knee[frame], target[frame] - new_knee) @ world[frame, shin]


def _ankle(rig, world, heads, shin, foot):
    """Where the leg's ankle is in each frame: the Foot's head, else the Leg's (``shin``) tail."""
    if foot is not None:
        return heads[:, foot]
    return heads[:, shin] + world[:, shin] @ (rig.tails[shin] - rig.rest[shin, :3, 3])


def _lowest_sole(rig, carriers, world, heads, ankle, rest_ankle):
    """(per frame, at rest) the height over the ``ankle`` of the lowest sole point of the bones ``carriers`` (the
    Foot and ToeBase, else the Leg), posed with world rotations ``world`` and heads ``heads``. Sole points: the
    skin's (``Rig.soles``); without a skin, the carriers' far end and the heel below the ankle at the far end's rest
    height when that is lower."""
    up, rest = rig.up, rig.rest[:, :3, 3]
    carried = [(bone, rig.soles[bone]) for bone in carriers if len(rig.soles.get(bone, ()))]
    if not carried:
        end = carriers[-1]
        heel = rest_ankle + min((rig.tails[end] - rest_ankle) @ up, 0.0) * up
        carried = [(carriers[0], heel[None]), (end, rig.tails[end][None])]
    lowest = np.min([np.min(((heads[:, bone] - ankle)[:, None, :]
                             + np.einsum("fij,nj->fni", world[:, bone], points - rest[bone])) @ up, axis=1)
                     for bone, points in carried], axis=0)
    rest_lowest = min(float(np.min((points - rest_ankle) @ up)) for _, points in carried)
    return lowest, rest_lowest


def _two_bone(hip, pole, target, upper, lower):
    """The knee that puts a leg of bone lengths ``upper`` and ``lower`` from ``hip`` onto ``target`` (as near as
    it reaches), bending in the plane of ``hip``, ``pole`` and ``target``, towards ``pole``."""
    reach = target - hip
    distance = np.linalg.norm(reach)
    along = reach / distance if distance > 0 else _unit(pole - hip)
    distance = np.clip(distance, abs(upper - lower) + 1e-9, upper + lower - 1e-9)
    bend = (pole - hip) - ((pole - hip) @ along) * along
    if np.linalg.norm(bend) < 1e-9 * (upper + lower):
        return hip + along * upper
    bend = _unit(bend)
    share = (upper ** 2 - lower ** 2 + distance ** 2) / (2 * distance)
    return hip + share * along + np.sqrt(max(upper ** 2 - share ** 2, 0.0)) * bend


def _quaternions(matrices):
    """(..., 4) unit quaternions w, x, y, z of rotation matrices (..., 3, 3)."""
    m = matrices
    trace = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    candidates = np.stack([
        np.stack([1 + trace, m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                  m[..., 1, 0] - m[..., 0, 1]], -1),
        np.stack([m[..., 2, 1] - m[..., 1, 2], 1 + 2 * m[..., 0, 0] - trace, m[..., 0, 1] + m[..., 1, 0],
                  m[..., 0, 2] + m[..., 2, 0]], -1),
        np.stack([m[..., 0, 2] - m[..., 2, 0], m[..., 0, 1] + m[..., 1, 0], 1 + 2 * m[..., 1, 1] - trace,
                  m[..., 1, 2] + m[..., 2, 1]], -1),
        np.stack([m[..., 1, 0] - m[..., 0, 1], m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                  1 + 2 * m[..., 2, 2] - trace], -1)], -2)
    diagonal = np.stack([trace, m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]], -1)
    best = np.take_along_axis(candidates, np.argmax(diagonal, -1)[..., None, None], -2)[..., 0, :]
    return best / np.linalg.norm(best, axis=-1, keepdims=True)


def _continuous(quaternions):
    """``quaternions`` (F, 4) with signs flipped so that neighbouring frames agree (interpolation takes the short
    way)."""
    result = quaternions.copy()
    for frame in range(1, len(result)):
        if result[frame] @ result[frame - 1] < 0:
            result[frame] = -result[frame]
    return result
