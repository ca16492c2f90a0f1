"""Rigging methods: the base class a method subclasses, and discovery of the methods folder.

A method is a module (``name.py``) or a package (``name/__init__.py`` with its own modules) in the methods folder.
Discovery never raises for a broken method: a module that fails to import, or a class that is not a valid method,
is recorded in ``Registry.failures`` with its error and skipped, so one bad file cannot break the add-on.
"""
import hashlib
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import pathlib
import sys
import traceback
import dataclasses
from dataclasses import dataclass
from types import MappingProxyType

from .params import Param
from .tuning import TuningTable

# The package whose folder holds the shipped methods: "rigger.methods", or its name inside Blender's extension
# namespace (e.g. "bl_ext.user_default.rigger.methods").
METHODS_PACKAGE = __name__.rsplit(".", 2)[0] + ".methods"

# Keyword arguments of rigger.rig_mesh that a parameter name would shadow.
RESERVED_PARAM_NAMES = frozenset({"vertices", "triangles", "method", "axes", "mesh", "self"})


class RigMethod:
    """Base class of a rigging method; subclass it in a module of ``methods/`` (see ``methods/_template.py``).

    Class attributes:
        name: unique identifier (a Python identifier), used by ``rig_mesh(method=...)``, ``--method`` and the UI.
        label: shown in the method dropdown; empty means the name.
        description: one sentence for tooltips and ``--help``.
        params: tuple of :class:`~rigger.core.params.Param`, the method's options.
        tuning_type: the method's :class:`~rigger.core.tuning.TuningTable` subclass, or None.

    A method is instantiated for each run, without arguments (its default tuning) or with ``tuning``: a table of
    its ``tuning_type``, or a dict of values to change in the default one (tests and benchmarks). It must not
    need bpy.
    """

    name = ""
    label = ""
    description = ""
    params = ()
    tuning_type = None

    def __init__(self, tuning=None):
        table = type(self).tuning_type
        if tuning is None:
            self.tuning = None if table is None else table()
        elif table is None:
            raise ValueError(f"method {self.name!r} has no tuning to change")
        elif isinstance(tuning, dict):
            self.tuning = table().changed(**tuning)
        elif isinstance(tuning, table):
            self.tuning = tuning
        elif _same_class(type(tuning), table):  # made before discovery loaded the method afresh
            self.tuning = table(**{field.name: getattr(tuning, field.name) for field in dataclasses.fields(table)})
        else:
            raise ValueError(f"tuning of method {self.name!r} must be a {table.__name__} or a dict of its values, "
                             f"got {type(tuning).__name__}")

    def rig(self, mesh, **params):
        """Return a :class:`~rigger.core.skeleton.Skeleton` for the validated :class:`~rigger.core.mesh.Mesh`.

        ``params`` holds every declared parameter, already coerced and range-checked. Put intermediate results into
        the skeleton's ``stages`` (``rigger.core.stages`` types, in world coordinates) and seconds per step into its
        ``timings``.
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
    """Import every module and package of ``folder`` (default: the shipped ``methods`` package) whose name does not
    start with ``_`` and collect the valid :class:`RigMethod` subclasses each defines.

    Every call re-reads the sources, a package's modules too, so methods added, edited or removed since the last
    call are seen. Methods load in sorted order; when two methods share a name the first is kept and the second
    recorded as a failure. Methods of another folder load as top-level modules, so they import the add-on
    absolutely (``from rigger.core ...``).
    """
    if folder is None:
        folder = pathlib.Path(importlib.import_module(METHODS_PACKAGE).__file__).parent
        prefix = METHODS_PACKAGE + "."
    else:
        folder = pathlib.Path(folder).resolve()
        prefix = f"_rigger_methods_{hashlib.sha1(str(folder).encode()).hexdigest()[:12]}_"
    importlib.invalidate_caches()
    methods, origins, failures = {}, {}, {}
    for path in sorted(folder.iterdir()):
        is_package = path.is_dir() and (path / "__init__.py").is_file()
        if path.name.startswith("_") or not (is_package or path.suffix == ".py"):
            continue
        where_file = path.name + ("/" if is_package else "")
        try:
            module = _load(prefix + path.stem, path, is_package)
        except (Exception, SystemExit) as error:
            failures[where_file] = _describe(error, path)
            continue
        for method in _defined_methods(module):
            where = f"{where_file}:{method.__name__}"
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
    table = method.tuning_type
    if table is not None and not (isinstance(table, type) and issubclass(table, TuningTable)):
        raise ValueError(f"method {method.name!r}: tuning_type must be a TuningTable subclass, got {table!r}")


class _FreshSource(importlib.machinery.SourceFileLoader):
    """Compiles from source every time: a cached .pyc, keyed on a one-second modification time, could hide an edit
    made just after the previous load."""

    def get_code(self, fullname):
        return compile(self.get_data(self.path), self.path, "exec", dont_inherit=True)


class _PackageFinder(importlib.abc.MetaPathFinder):
    """Finds the modules of the package ``name`` (in ``folder``) from source, while a method package loads."""

    def __init__(self, name, folder):
        self.name, self.folder = name, folder

    def find_spec(self, fullname, path=None, target=None):
        if not fullname.startswith(self.name + "."):
            return None
        place = self.folder.joinpath(*fullname[len(self.name) + 1:].split("."))
        if (place / "__init__.py").is_file():
            return _spec(fullname, place / "__init__.py", package=True)
        if place.with_suffix(".py").is_file():
            return _spec(fullname, place.with_suffix(".py"))
        return None


def _spec(name, path, package=False):
    return importlib.util.spec_from_file_location(name, path, loader=_FreshSource(name, str(path)),
                                                  submodule_search_locations=[str(path.parent)] if package else None)


def _load(name, path, is_package):
    """Execute the module file or package folder ``path`` afresh as module ``name`` (a package with every module
    of it it imports, all from source)."""
    for loaded in [key for key in sys.modules if key == name or key.startswith(name + ".")]:
        del sys.modules[loaded]
    finder = _PackageFinder(name, path) if is_package else None
    spec = _spec(name, path / "__init__.py" if is_package else path, package=is_package)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    if finder is not None:
        sys.meta_path.insert(0, finder)
    try:
        spec.loader.exec_module(module)
    except BaseException:
        for loaded in [key for key in sys.modules if key == name or key.startswith(name + ".")]:
            del sys.modules[loaded]
        raise
    finally:
        if finder is not None:
            sys.meta_path.remove(finder)
    parent, _, child = name.rpartition(".")
    if parent in sys.modules:  # ``from rigger.methods import silhouette`` gives the fresh package too
        setattr(sys.modules[parent], child, module)
    return module


def _defined_methods(module):
    """RigMethod subclasses defined in ``module`` itself or, for a package, in its modules (not imported from
    elsewhere), in the order the module names them."""
    return [value for value in vars(module).values()
            if isinstance(value, type) and issubclass(value, RigMethod) and value is not RigMethod
            and (value.__module__ == module.__name__ or value.__module__.startswith(module.__name__ + "."))]


def _same_class(one, other):
    """Whether two classes are one class loaded twice (same module and name)."""
    return (one.__module__, one.__qualname__) == (other.__module__, other.__qualname__)


def _describe(error, path):
    """The error as one line, with the line of the method's own file (or, for a package, of the file under it)
    where it was raised."""
    if isinstance(error, SyntaxError):
        where = pathlib.Path(error.filename or "")
        name = f"{where.relative_to(path)}, " if path.is_dir() and where.is_relative_to(path) else ""
        return f"SyntaxError: {error.msg} ({name}line {error.lineno})"
    frames = [frame for frame in traceback.extract_tb(error.__traceback__)
              if pathlib.Path(frame.filename) == path or pathlib.Path(frame.filename).is_relative_to(path)]
    if not frames:
        return f"{type(error).__name__}: {error}"
    name = f"{pathlib.Path(frames[-1].filename).relative_to(path)}, " if path.is_dir() else ""
    return f"{type(error).__name__}: {error} ({name}line {frames[-1].lineno})"
