"""``rig_mesh``: the one call scripts, the CLI and the Blender layer use to turn a mesh into a skeleton."""
import time
from dataclasses import replace

import numpy as np

from .core.bodyplan import recognise
from .core.mesh import Mesh
from .core.mirror import square_turn
from .core.params import resolve
from .core.registry import RigMethod, check_method, discover
from .core.roles import Roles
from .core.rooting import pelvis, rerooted
from .core.skeleton import Skeleton
from .core.stages import Placement

_registry = None


def method_registry(*, refresh=False, folder=None):
    """The :class:`~rigger.core.registry.Registry` that ``rig_mesh`` looks method names up in.

    Discovered on first use; ``refresh=True`` discovers again (the Blender layer does so when the add-on is
    enabled) and ``folder`` discovers another methods folder instead of the shipped one, until the next refresh.
    """
    global _registry
    if _registry is None or refresh or folder is not None:
        _registry = discover(folder)
    return _registry


def rig_mesh(vertices, triangles, method="silhouette", *, axes=None, **params):
    """Rig a triangle mesh and return its :class:`~rigger.core.skeleton.Skeleton`.

    Args:
        vertices: (N, 3) array-like of finite coordinates.
        triangles: (M, 3) array-like of vertex indices.
        method: a method name from :func:`method_registry`, a :class:`~rigger.core.registry.RigMethod` subclass
            (e.g. one defined in a script) or an instance of one (e.g. with its tuning changed).
        axes: None, or a 3x3 rotation whose rows are the directions (in the mesh's coordinates) the method takes as
            its X, Y and Z: the mesh is turned into that frame for the method and the body plan (whose preferred up
            is then the frame's Z), and the skeleton, its stages and the plan's up turned back; vector parameters (a
            view direction) are directions in the mesh's coordinates and turn with it. The Blender layer passes a
            rigged object's own axes, so a character turned or tilted rigs as if it stood square to the world. A mesh
            (in that frame) that mirrors about a plane off the axes is turned on, square to that plane
            (``core.mirror.square_turn``), and its plan's reason says so.
        **params: the method's parameters by name; values may be strings as typed on a command line.

    Raises ValueError for an unknown method (naming the available ones and any that failed to load), unknown or
    out-of-range parameters, and bad meshes. The skeleton's ``params`` are the resolved values, its ``body_plan``
    and ``roles`` what ``rigger.core.bodyplan.recognise`` makes of it on this mesh (Z up preferred, as in Blender;
    the method's mirror plane when it has one; also drawn as the "roles" stage), and its ``timings["total"]`` the
    seconds for this whole call. A skeleton whose legs hang from another joint than its root's is rooted there,
    at the pelvis (``rigger.core.rooting``).
    """
    start = time.perf_counter()
    rigging = _method(method)
    values = resolve(rigging.params, params)
    mesh = Mesh(vertices, triangles)
    rotation = None if axes is None else _rotation(axes)
    if rotation is not None:  # the method, and the body plan (Z up preferred: the object's own), in the frame
        mesh = mesh.with_vertices(mesh.vertices @ rotation.T)
    square = square_turn(mesh)
    if square is not None:  # a mirror plane off the axes: rigged square to it
        mesh = mesh.with_vertices(mesh.vertices @ square.T)
        rotation = square if rotation is None else square @ rotation
    skeleton = rigging.rig(mesh, **(values if rotation is None else _turned(rigging, values, rotation)))
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"method {rigging.name!r} returned {type(skeleton).__name__}, not a Skeleton")
    recognised = time.perf_counter()
    skeleton.body_plan, skeleton.roles = recognise(skeleton, mesh, plane=skeleton.stages.get("mirror_plane"))
    root = pelvis(skeleton)
    if root is not None:
        skeleton = rerooted(skeleton, *root)
    body_plan_seconds = time.perf_counter() - recognised
    if rotation is not None:
        skeleton = _turned_back(skeleton, rotation)
    if square is not None:
        turn = np.degrees(np.arccos(np.clip(0.5 * (np.trace(square) - 1.0), -1.0, 1.0)))
        skeleton.body_plan = replace(skeleton.body_plan, reason=f"{skeleton.body_plan.reason}; rigged square to its "
                                                                f"mirror plane, {turn:.0f} degrees off the mesh's axes")
    skeleton.params = values
    skeleton.stages["roles"] = Roles.of(skeleton, skeleton.roles)
    skeleton.timings["body_plan"] = body_plan_seconds
    skeleton.timings["total"] = time.perf_counter() - start
    return skeleton


def _rotation(axes):
    """``axes`` as a (3, 3) float64 rotation; ValueError unless its rows are orthonormal and right-handed."""
    try:
        rotation = np.array(axes, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"axes must be a 3x3 rotation, got {axes!r}") from None
    if rotation.shape != (3, 3):
        raise ValueError(f"axes must be a 3x3 rotation, got shape {rotation.shape}")
    if not np.isfinite(rotation).all():
        raise ValueError("axes must be a 3x3 rotation of finite numbers")
    if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6) or np.linalg.det(rotation) < 0:
        raise ValueError("axes must be a rotation: orthonormal rows, right-handed")
    return rotation


def _turned(rigging, values, rotation):
    """The parameter ``values`` in the frame whose axes are ``rotation``'s rows: vectors (a view direction) turned."""
    kinds = {param.name: param.type for param in rigging.params}
    return {name: tuple(rotation @ np.asarray(value, dtype=np.float64)) if kinds[name] == "vector" else value
            for name, value in values.items()}


def _turned_back(inside, rotation):
    """The skeleton rigged in the frame whose axes are ``rotation``'s rows, its stages and its plan's up, in the
    mesh's own coordinates (roles and named joints ride on the bones)."""
    placement = Placement(1.0, rotation)
    front = inside.body_plan.front
    plan = replace(inside.body_plan, up=tuple(placement.vector(np.asarray(inside.body_plan.up))),
                   front=None if front is None else tuple(placement.vector(np.asarray(front))))
    skeleton = Skeleton(inside.names, placement.point(inside.heads), placement.point(inside.tails), inside.parents,
                        {name: stage.mapped(placement) for name, stage in inside.stages.items()}, roles=inside.roles,
                        body_plan=plan)
    skeleton.timings = inside.timings
    return skeleton


def _method(method):
    """An instance of the method ``method`` names or is."""
    if isinstance(method, str):
        return method_registry().lookup(method)()
    if isinstance(method, type) and issubclass(method, RigMethod):
        check_method(method)
        return method()
    if isinstance(method, RigMethod):
        check_method(type(method))
        return method
    raise ValueError(f"method must be a method name, a RigMethod subclass or an instance of one, got {method!r}")
