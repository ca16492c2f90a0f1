"""A BVH motion file's structure, read without Blender: whether Blender's importer can take it, said in one line
before any slow work (Blender's importer fails on a bad file with a traceback, after the rigging)."""
import math
import pathlib
from dataclasses import dataclass


class BvhError(ValueError):
    """A file that is no readable BVH motion; the message says why in one line."""


@dataclass(frozen=True)
class BvhSummary:
    """What a BVH file holds: its joints' names (root first), channels per frame, frames and seconds per frame."""

    joints: tuple
    channels: int
    frames: int
    frame_time: float


def check(path):
    """The :class:`BvhSummary` of the BVH file at ``path``; :class:`BvhError` when it cannot be read, is no BVH (a
    HIERARCHY of joints with OFFSET and CHANNELS, then MOTION with ``Frames:`` and ``Frame Time:``), holds fewer than
    two frames (a pose, no motion), or holds fewer frame lines (or fewer numbers on one) than it announces."""
    path = pathlib.Path(path)
    try:
        lines = path.read_text(encoding="utf-8-sig", errors="replace").splitlines()  # a BOM is no keyword
    except OSError as error:
        raise BvhError(f"{path}: cannot read it: {error.strerror or error}") from None
    try:
        motion = next(k for k, line in enumerate(lines) if line.strip().upper() == "MOTION")
    except StopIteration:
        raise BvhError(f"{path}: not a BVH file (no MOTION section)") from None
    joints, channels = _hierarchy(path, " ".join(lines[:motion]).split())
    after = [line.split() for line in lines[motion + 1:] if line.strip()]
    header = [[word.lower() for word in words] for words in after[:2]]
    if len(header) < 2 or header[0][:1] != ["frames:"] or header[1][:2] != ["frame", "time:"]:
        raise BvhError(f"{path}: MOTION is not followed by 'Frames:' and 'Frame Time:' lines")
    frames, frame_time = _number(path, header[0][1:], int, "Frames:"), _number(path, header[1][2:], float,
                                                                             "Frame Time:")
    if frames < 2:
        raise BvhError(f"{path}: the BVH file holds {'no frames' if frames < 1 else 'one frame'}: a motion needs two "
                       f"or more")
    if not frame_time > 0:
        raise BvhError(f"{path}: 'Frame Time:' must be a positive number of seconds, not {frame_time:g}")
    rows = after[2:]
    if len(rows) < frames:
        raise BvhError(f"{path}: holds {len(rows)} frame lines of the {frames} it announces (cut short?)")
    for number, values in enumerate(rows[:frames], start=1):
        if len(values) < channels:
            raise BvhError(f"{path}: frame {number} has {len(values)} values, not the {channels} the HIERARCHY's "
                           f"channels need")
        wrong = next((value for value in values[:channels] if not math.isfinite(_float(value))), None)
        if wrong is not None:
            raise BvhError(f"{path}: frame {number} holds {wrong!r}, not a finite number")
    return BvhSummary(tuple(joints), channels, frames, frame_time)


def _hierarchy(path, tokens):
    """(joint names, channel count) of the HIERARCHY tokens; BvhError when they are no BVH hierarchy."""
    keywords = [token.upper() for token in tokens]  # joint names keep their case, keywords may have any
    if keywords[:2] != ["HIERARCHY", "ROOT"]:
        raise BvhError(f"{path}: not a BVH file (it does not begin with HIERARCHY and a ROOT joint)")
    joints, channels, depth, k = [], 0, 0, 1
    while k < len(tokens):
        word = keywords[k]
        if word in ("ROOT", "JOINT") and k + 1 < len(tokens):
            joints.append(tokens[k + 1])
            k += 2
        elif word == "END" and keywords[k + 1:k + 2] == ["SITE"]:
            k += 2
        elif word == "{":
            depth, k = depth + 1, k + 1
        elif word == "}":
            depth, k = depth - 1, k + 1
            if depth < 0:
                break
        elif word == "OFFSET":
            k += 4
        elif word == "CHANNELS" and k + 1 < len(tokens) and tokens[k + 1].isdigit():
            count = int(tokens[k + 1])
            channels, k = channels + count, k + 2 + count
        else:
            raise BvhError(f"{path}: unexpected {tokens[k]!r} in the HIERARCHY")
    if depth != 0 or not joints:
        raise BvhError(f"{path}: the HIERARCHY's braces do not balance")
    return joints, channels


def _number(path, words, kind, label):
    try:
        return kind(words[0])
    except (IndexError, ValueError):
        raise BvhError(f"{path}: '{label}' is not followed by a number") from None


def _float(text):
    try:
        return float(text)
    except ValueError:
        return math.nan
