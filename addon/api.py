"""``rig_mesh``: the one call scripts, the CLI and the Blender layer use to turn a mesh into a skeleton."""
import time

from .core.bodyplan import recognise
from .core.mesh import Mesh
from .core.params import resolve
from .core.registry import RigMethod, check_method, discover
from .core.roles import Roles
from .core.skeleton import Skeleton

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


def rig_mesh(vertices, triangles, method="silhouette", **params):
    """Rig a triangle mesh and return its :class:`~rigger.core.skeleton.Skeleton`.

    Args:
        vertices: (N, 3) array-like of finite coordinates.
        triangles: (M, 3) array-like of vertex indices.
        method: a method name from :func:`method_registry`, a :class:`~rigger.core.registry.RigMethod` subclass
            (e.g. one defined in a script) or an instance of one (e.g. with its tuning changed).
        **params: the method's parameters by name; values may be strings as typed on a command line.

    Raises ValueError for an unknown method (naming the available ones and any that failed to load), unknown or
    out-of-range parameters, and bad meshes. The skeleton's ``params`` are the resolved values, its ``body_plan``
    and ``roles`` what ``rigger.core.bodyplan.recognise`` makes of it on this mesh (Z up preferred, as in Blender;
    the method's mirror plane when it has one; also drawn as the "roles" stage), and its ``timings["total"]`` the
    seconds for this whole call.
    """
    start = time.perf_counter()
    rigging = _method(method)
    values = resolve(rigging.params, params)
    mesh = Mesh(vertices, triangles)
    skeleton = rigging.rig(mesh, **values)
    if not isinstance(skeleton, Skeleton):
        raise TypeError(f"method {rigging.name!r} returned {type(skeleton).__name__}, not a Skeleton")
    skeleton.params = values
    recognised = time.perf_counter()
    skeleton.body_plan, skeleton.roles = recognise(skeleton, mesh, plane=skeleton.stages.get("mirror_plane"))
    skeleton.stages["roles"] = Roles.of(skeleton, skeleton.roles)
    skeleton.timings["body_plan"] = time.perf_counter() - recognised
    skeleton.timings["total"] = time.perf_counter() - start
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
