"""Which way is up in a model file: the axis names Blender's importers take, and the turn into Blender's world.

Blender's world is Z up. Its importers name two of the file's axes: *up* becomes Blender's +Z and *forward* becomes
Blender's +Y (the direction a character's front view looks along). An OBJ file carries no axes, so Blender reads it
as up Y, forward -Z unless told otherwise; glTF is up Y, forward -Z by its specification; FBX files say their own
axes; a .blend is in Blender's world already. No bpy: the command line checks the options before it starts Blender.
"""
import numpy as np

AXES = ("X", "Y", "Z", "-X", "-Y", "-Z")
DEFAULT_UP = "Y"
DEFAULT_FORWARD = "-Z"  # ... or Y when up is Z or -Z (the default forward would lie on the up axis)
AXIS_SUFFIXES = (".obj", ".fbx")  # the file types whose importer takes axes
GLTF_AXES = ("Y", "-Z")  # (up, forward) of every glTF file
_UNIT = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def file_axes(suffix, up=None, forward=None):
    """The (up, forward) axes a file of type ``suffix`` ('.obj', ...) is read with, given the ``--up`` and
    ``--forward`` options (None: not given), or None where Blender's importer decides (FBX without options, .blend).

    Option values are ``AXES`` names, in any case. An OBJ file gets the defaults for what is not given; an FBX file
    given one option gets the defaults for the other. ValueError for a name that is not an axis, up and forward on
    one axis, or options for glTF or .blend files, whose frame is fixed.
    """
    up, forward = (None if value is None else _axis(value, option)
                   for value, option in ((up, "--up"), (forward, "--forward")))
    suffix = suffix.lower()
    if suffix not in AXIS_SUFFIXES:
        if up is not None or forward is not None:
            fixed = "glTF is Y-up by its specification" if suffix in (".glb", ".gltf") else \
                "a .blend file is in Blender's Z-up world already"
            raise ValueError(f"--up and --forward apply to OBJ and FBX files only; {fixed}")
        return GLTF_AXES if suffix in (".glb", ".gltf") else None
    if suffix == ".fbx" and up is None and forward is None:
        return None
    up = up or DEFAULT_UP
    forward = forward or ("Y" if up[-1] == "Z" else DEFAULT_FORWARD)
    if up[-1] == forward[-1]:
        raise ValueError(f"--up {up} and --forward {forward} lie on one axis; choose two different axes")
    return up, forward


def axes_field(axes):
    """``file_axes``' answer as reports give it: {"up": "Y", "forward": "-Z"}, or None."""
    return None if axes is None else dict(zip(("up", "forward"), axes))


def to_blender(up, forward):
    """The 3x3 rotation taking a file's coordinates, read with axes ``up`` and ``forward``, to Blender's world:
    ``forward`` to +Y, ``up`` to +Z, and so their cross product to +X."""
    up_vector, forward_vector = _vector(up), _vector(forward)
    return np.array([np.cross(forward_vector, up_vector), forward_vector, up_vector])


def _axis(value, option):
    name = str(value).strip().upper()
    if name not in AXES:
        raise ValueError(f"{option} must be one of {', '.join(AXES)}, got {value!r}")
    return name


def _vector(axis):
    return np.array(_UNIT[axis[-1]]) * (-1.0 if axis.startswith("-") else 1.0)
