"""Rigging methods: the base class a method subclasses, and discovery of the methods folder.

Discovery never raises for a broken method: a module that fails to import, or a class that is not a valid method,
is recorded in ``Registry.failures`` with its error and skipped, so one bad file cannot break the add-on.
"""
import hashlib
import importlib
import importlib.util
import pathlib
import sys
import traceback
from dataclasses import dataclass
from types import MappingProxyType

from .params import Param

# The package whose folder holds the shipped methods: "rigger.methods", or its name inside Blender's extension
# namespace (e.g. "bl_ext.user_default.rigger.methods").
METHODS_PACKAGE = __name__.rsplit(".", 2)[0] + ".methods"

# Keyword arguments of rigger.rig_mesh that a parameter name would shadow.
RESERVED_PARAM_NAMES = frozenset({"vertices", "triangles", "method", "mesh", "self"})


class RigMethod:
    """Base class of a rigging method; subclass it in a module of ``methods/`` (see ``methods/_template.py``).

    Class attributes:
        name: unique identifier (a Python identifier), used by ``rig_mesh(method=...)``, ``--method`` and the UI.
        label: shown in the method dropdown; empty means the name.
        description: one sentence for tooltips and ``--help``.
        params: tuple of :class:`~rigger.core.params.Param`, the method's options.

    A method is instantiated without arguments for each run and must not need bpy.
    """

    name = ""
    label = ""
    description = ""
    params = ()

    def rig(self, mesh, **params):
        """Return a :class:`~rigger.core.skeleton.Skeleton` for the validated :class:`~rigger.core.mesh.Mesh`.

        ``params`` holds every declared parameter, already coerced and range-checked. Put intermediate results into
        the skeleton's ``stages`` dict and per-stage seconds into ``stages["timings"]``.
        """
        raise NotImplementedError(f"{type(self).__name__} must define rig(mesh, **params)")

    def draw(self, layout, props):
        """Custom UI drawn in the Blender panel below the generated parameter widgets; none by default.

        ``layout`` is a ``bpy.types.UILayout``; ``props`` the method's generated PropertyGroup, holding one
        property per declared parameter under the same name. Only the Blender layer calls this.
        """


@dataclass(frozen=True)
class Registry:
    """The result of :func:`discover`.

    Attributes:
        methods: read-only mapping from method name to its class, in sorted name order.
        failures: read-only mapping from what failed (``"file.py"`` for a module, ``"file.py:Class"`` for a
            class) to the error text.
    """

    methods: MappingProxyType
    failures: MappingProxyType

    def lookup(self, name):
        """The method class called ``name``; ValueError naming the available methods and any failures."""
        if name in self.methods:
            return self.methods[name]
        available = ", ".join(self.methods) or "none"
        message = f"unknown method {name!r}; available: {available}"
        if self.failures:
            failed = "; ".join(f"{where}: {error}" for where, error in self.failures.items())
            message += f"; failed to load: {failed}"
        raise ValueError(message)


def discover(folder=None):
    """Import every module of ``folder`` (default: the shipped ``methods`` package) whose name does not start with
    ``_`` and collect the valid :class:`RigMethod` subclasses each defines.

    Every call re-reads the files, so methods added, edited or removed since the last call are seen. Files load
    in sorted order; when two methods share a name the first is kept and the second recorded as a failure. Modules
    of another folder load as top-level modules, so they import the add-on absolutely (``from rigger.core ...``).
    """
    if folder is None:
        folder = pathlib.Path(importlib.import_module(METHODS_PACKAGE).__file__).parent
        prefix = METHODS_PACKAGE + "."
    else:
        folder = pathlib.Path(folder).resolve()
        prefix = f"_rigger_methods_{hashlib.sha1(str(folder).encode()).hexdigest()[:12]}_"
    importlib.invalidate_caches()
    methods, origins, failures = {}, {}, {}
    for path in sorted(folder.glob("*.py")):
        if path.name.startswith("_"):
            continue
        try:
            module = _load_module(prefix + path.stem, path)
        except (Exception, SystemExit) as error:
            failures[path.name] = _describe(error, path)
            continue
        for method in _defined_methods(module):
            where = f"{path.name}:{method.__name__}"
            try:
                check_method(method)
            except ValueError as error:
                failures[where] = str(error)
                continue
            if method.name in methods:
                failures[where] = f"duplicate method name {method.name!r}, already defined in {origins[method.name]}"
                continue
            methods[method.name] = method
            origins[method.name] = where
    return Registry(MappingProxyType(dict(sorted(methods.items()))), MappingProxyType(failures))


def check_method(method):
    """Raise ValueError saying why the class ``method`` is not a usable method."""
    if not (isinstance(method, type) and issubclass(method, RigMethod)) or method is RigMethod:
        raise ValueError(f"{method!r} is not a subclass of RigMethod")
    if not isinstance(method.name, str) or not method.name.isidentifier():
        raise ValueError(f"method name must be a Python identifier, got {method.name!r}")
    if not isinstance(method.label, str) or not isinstance(method.description, str):
        raise ValueError(f"method {method.name!r}: label and description must be strings")
    if method.rig is RigMethod.rig:
        raise ValueError(f"method {method.name!r} does not define rig(mesh, **params)")
    if not isinstance(method.params, (tuple, list)) or not all(isinstance(p, Param) for p in method.params):
        raise ValueError(f"method {method.name!r}: params must be a tuple of Param")
    names = [param.name for param in method.params]
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if duplicates:
        raise ValueError(f"method {method.name!r}: parameter {duplicates[0]!r} is declared twice")
    reserved = sorted(RESERVED_PARAM_NAMES.intersection(names))
    if reserved:
        raise ValueError(f"method {method.name!r}: parameter name {reserved[0]!r} is reserved")


def _load_module(name, path):
    """Execute ``path`` as a fresh module ``name``. It is compiled from source every time: a cached .pyc, keyed on
    a one-second modification time, could hide an edit made just after the previous load."""
    sys.modules.pop(name, None)
    module = importlib.util.module_from_spec(importlib.util.spec_from_file_location(name, path))
    sys.modules[name] = module
    try:
        exec(compile(path.read_bytes(), str(path), "exec"), module.__dict__)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    return module


def _defined_methods(module):
    """RigMethod subclasses defined in ``module`` itself (not imported into it), in definition order."""
    return [value for value in vars(module).values()
            if isinstance(value, type) and issubclass(value, RigMethod) and value is not RigMethod
            and value.__module__ == module.__name__]


def _describe(error, path):
    if isinstance(error, SyntaxError):
        return f"SyntaxError: {error.msg} (line {error.lineno})"
    lines = [frame.lineno for frame in traceback.extract_tb(error.__traceback__) if frame.filename == str(path)]
    where = f" (line {lines[-1]})" if lines else ""
    return f"{type(error).__name__}: {error}{where}"
