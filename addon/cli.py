"""``python -m rigger``: rig model files from the command line (``rig``), or whole libraries in parallel (``batch``,
see :mod:`rigger.batch`).

``rig`` imports an OBJ, glTF/GLB, FBX or .blend file into an empty headless Blender (the ``bpy`` module), rigs its
mesh, skins it and saves .blend, .glb or .fbx, plus an optional JSON report. Outputs are written to temporary
files and renamed into place only when everything succeeded (``rigger.core.files``), so a failure leaves nothing
behind.
"""
import argparse
import contextlib
import os
import pathlib
import sys
import tempfile

from .axes import AXES, AXIS_SUFFIXES, file_axes
from .core import bvh
from .core.targets import TARGETS

INPUTS = (".obj", ".glb", ".gltf", ".fbx", ".blend")
OUTPUTS = (".blend", ".glb", ".fbx")
EXIT_FAILED = 1
EXIT_INTERRUPTED = 130  # as a shell reports a command ended by Ctrl-C


class CliError(Exception):
    """A failure to tell the user in one line (missing file, no mesh, rigging failed); exits non-zero."""


def main(argv=None):
    parser = _parser()
    try:
        args = parser.parse_args(_axis_values_joined(sys.argv[1:] if argv is None else list(argv)))
        return args.run(args)
    except CliError as error:
        print(f"rigger: error: {error}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:  # outputs are written through temporary files: none is left half-written
        print("rigger: interrupted; nothing was written", file=sys.stderr)
        return EXIT_INTERRUPTED


class _Parser(argparse.ArgumentParser):
    """Usage mistakes are one ``rigger: error:`` line and status 1, as every other bad input is."""

    def error(self, message):
        raise CliError(f"{message} (see `{self.prog} --help`)")


def _parser():
    parser = _Parser(prog="python -m rigger", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    rig = commands.add_parser("rig", help="rig one model file")
    rig.add_argument("input", type=pathlib.Path, help=f"model file ({', '.join(INPUTS)})")
    rig.add_argument("-o", "--output", type=pathlib.Path,
                     help=f"where to save ({', '.join(OUTPUTS)}); default INPUT_rigged.blend beside the input")
    rig.add_argument("--report", type=pathlib.Path, help="write a JSON report here")
    rig.add_argument("--animate", type=pathlib.Path, metavar="BVH",
                     help="retarget this motion-capture file onto the rig and bake it as its action (needs the game "
                          "target, which it makes the default, and a humanoid)")
    _method_options(rig)
    _axis_options(rig)
    rig.set_defaults(run=_run_rig)

    batch = commands.add_parser("batch", help="rig a library of model files in parallel, here or on a Ray cluster")
    batch.add_argument("inputs", nargs="+", metavar="INPUTS",
                       help="folders (searched recursively), model files, text files listing model files one per "
                            "line, or quoted glob patterns (** for any depth)")
    batch.add_argument("-o", "--output", type=pathlib.Path, required=True, help="folder for the results")
    batch.add_argument("--format", choices=[suffix[1:] for suffix in OUTPUTS], default="blend",
                       help="output format (default blend)")
    batch.add_argument("--engine", choices=("local", "ray"), default="local",
                       help="local: a child process per file on this machine (default); ray: long-lived Blender "
                            "workers on a Ray cluster (pip install -r requirements-ray.txt)")
    batch.add_argument("--address", help="the Ray cluster to join (default RAY_ADDRESS; without either, a Ray "
                                         "instance of this machine is started and stopped again)")
    batch.add_argument("--jobs", type=int, help="files at once (default: one per CPU of this machine, or of the "
                                                "Ray cluster)")
    batch.add_argument("--timeout", type=float, metavar="SECONDS",
                       help="give up on a file after this many seconds (default: no limit)")
    batch.add_argument("--resume", action="store_true",
                       help="skip files whose results an earlier run with the same settings completed")
    _method_options(batch)
    _axis_options(batch)
    batch.set_defaults(run=_run_batch)

    methods = commands.add_parser("methods", help="list the rigging methods and their parameters")
    methods.add_argument("--tuning", action="store_true",
                         help="also list each method's tuned numbers: value, reason, and where they are declared")
    methods.set_defaults(run=_run_methods)
    return parser


def _method_options(parser):
    parser.add_argument("--method", default="silhouette", help="rigging method (see `python -m rigger methods`)")
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                        help="a method parameter, e.g. --set bone_length=0.08 (repeatable)")
    parser.add_argument("--target", choices=list(TARGETS), default=None,
                        help="what the armature becomes: " + "; ".join(f"{name}: {target.description}"
                                                                      for name, target in TARGETS.items())
                        + " (default plain; a body plan that cannot fill a target falls back, with a warning)")
    parser.add_argument("--no-skin", action="store_true", help="make the armature only, do not skin the mesh")


def _axis_options(parser):
    names = ", ".join(AXES)
    parser.add_argument("--up", help=f"the file's up axis ({names}; OBJ and FBX only; default Y for OBJ, the FBX "
                                     f"file's own)")
    parser.add_argument("--forward", help=f"the file's forward axis, which becomes Blender's +Y ({names}; OBJ and "
                                          f"FBX only; default -Z, or Y when --up is Z or -Z)")


def _axis_values_joined(argv):
    """``argv`` with ``--up -Z`` written ``--up=-Z``: argparse takes a value that starts with a dash for an option."""
    joined = []
    for arg in argv:
        if joined and joined[-1] in ("--up", "--forward") and str(arg).upper() in ("-X", "-Y", "-Z"):
            joined[-1] = f"{joined[-1]}={arg}"
        else:
            joined.append(arg)
    return joined


def _settings(pairs):
    values = {}
    for pair in pairs:
        key, separator, value = pair.partition("=")
        if not separator or not key.strip():
            raise CliError(f"--set expects KEY=VALUE, got {pair!r}")
        values[key.strip()] = value
    return values


def _run_methods(args):
    from .api import method_registry

    registry = method_registry()
    for name, method in registry.methods.items():
        print(f"{name}: {method.description}")
        for param in method.params:
            choices = f" {{{', '.join(param.items)}}}" if param.items else ""
            print(f"  --set {param.name}=VALUE  ({param.type}{choices}, default {param.default}) {param.description}")
        if args.tuning and method.tuning_type is not None:
            _print_tuning(method.tuning_type)
    if args.tuning:
        from .core.bodyplan import BodyPlanTuning

        print("body plan and bone roles (after every method):")
        _print_tuning(BodyPlanTuning)
        from .core.facing import FootTuning
        from .core.metarig import MetarigTuning

        print("the rigify target's metarig fitting:")
        _print_tuning(MetarigTuning)
        print("feet the skeleton lacks (the rigify and game targets):")
        _print_tuning(FootTuning)
    for where, error in registry.failures.items():
        print(f"failed to load {where}: {error}", file=sys.stderr)
    return 0


def _print_tuning(table):
    print(f"  tuning ({table.__module__}.{table.__name__}):")
    for field, value, why, owner in table.rows():
        print(f"    {field} = {value!r}  {why}  [{owner.__module__}.{owner.__name__}]")


def _run_rig(args):
    source = args.input
    if source.is_dir():
        raise CliError(f"{source}: is a folder, not a model file (`batch` rigs every model in a folder)")
    if not source.is_file():
        raise CliError(f"{source}: no such file")
    if source.suffix.lower() not in INPUTS:
        raise CliError(f"{source}: cannot read {source.suffix or 'files without a suffix'}; use {', '.join(INPUTS)}")
    output = args.output or source.with_name(f"{source.stem}_rigged.blend")
    if output.suffix.lower() not in OUTPUTS:
        raise CliError(f"{output}: cannot write {output.suffix or 'files without a suffix'}; use {', '.join(OUTPUTS)}")
    _check_destinations(source, output, args.report)
    settings = _file_settings(args)  # before the slow import
    if args.animate is not None:
        if settings.target != "game":
            raise CliError(f"--animate needs the game target (its Mixamo names are what a motion drives), not "
                           f"--target {settings.target}")
        if not args.animate.is_file():
            raise CliError(f"{args.animate}: no such BVH file")
        try:
            bvh.check(args.animate)  # before the slow rigging
        except bvh.BvhError as error:
            raise CliError(str(error)) from None
    try:
        file_axes(source.suffix, args.up, args.forward)
    except ValueError as error:
        raise CliError(str(error)) from None

    from .batch.work import FileFailed, prepare, rig_to_files

    try:
        prepare()
        report = rig_to_files(source, output, args.report, settings)
    except FileFailed as error:
        raise CliError(str(error)) from None
    print(f"rigged {source} → {output}: {len(report['bones'])} bones, {report['skinning']['summary']}")
    if report.get("animation"):
        animation = report["animation"]
        skipped = " (its first frame, a reference pose, left out)" if animation.get("skipped_frames") else ""
        print(f"animated with {animation['bvh']}: {animation['frames']} frames at {animation['fps']:g} fps{skipped}")
    for warning in report["warnings"]:
        print(f"warning: {warning}", file=sys.stderr)
    return 0


def _file_settings(args):
    """How each file is rigged (``batch.work.Settings``) from the options: the method's name, its parameters
    resolved from ``--set``, the target (default plain, or game with ``--animate``), skinning, axes and the motion
    to retarget; CliError for an unknown method or bad values."""
    from .api import method_registry
    from .batch.work import Settings
    from .core.params import resolve

    try:
        method = method_registry().lookup(args.method)
        params = resolve(method.params, _settings(args.settings))
    except ValueError as error:
        raise CliError(str(error)) from None
    animate = getattr(args, "animate", None)  # rig only
    return Settings(method.name, params, target=args.target or ("game" if animate else "plain"),
                    skin=not args.no_skin, up=args.up, forward=args.forward, pairs=tuple(args.settings),
                    animate=animate)


def _check_destinations(source, output, report):
    """Refuse outputs that would overwrite the input or each other, that are folders, or whose folder cannot be
    made or written in, before any slow work."""
    named = {"the input": source, "the output": output, "the report": report}
    seen = {}
    for role, path in named.items():
        if path is None:
            continue
        if role != "the input":
            _check_folder(path.parent, role)  # first: it may be searched then (is_dir raises where it may not)
            if path.is_dir():
                raise CliError(f"{path}: is a folder; {role} needs a file name")
        key = os.path.normcase(path.resolve())
        if key in seen:
            raise CliError(f"{path}: {role} would overwrite {seen[key]}; choose another file name")
        seen[key] = role


def _check_folder(folder, role):
    """CliError unless ``folder`` is, or can be made as, a folder to write ``role`` in."""
    existing = folder.absolute()
    try:
        while not existing.exists() and existing != existing.parent:
            existing = existing.parent
        is_folder = existing.is_dir()
    except OSError as error:  # a folder on the way that may not be searched
        raise CliError(f"{folder}: {error.strerror or error}, so {role} cannot go there") from None
    if not is_folder:
        raise CliError(f"{existing}: is not a folder, so {role} cannot go in {folder}")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise CliError(f"{existing}: cannot write there, so {role} cannot go in {folder}")
    if existing == folder.absolute():  # try it: access() says yes to root, and to file systems that refuse files
        try:
            tempfile.TemporaryFile(dir=existing).close()
        except OSError as error:
            raise CliError(f"{existing}: cannot write there ({error.strerror or error}), so {role} cannot go "
                           f"in it") from None


def _run_batch(args):
    from .batch import BatchError, driver, inputs

    if args.jobs is not None and args.jobs < 1:
        raise CliError(f"--jobs must be at least 1, got {args.jobs}")
    if args.timeout is not None and args.timeout <= 0:
        raise CliError(f"--timeout must be a positive number of seconds, got {args.timeout}")
    if args.address and args.engine != "ray":
        raise CliError("--address needs --engine ray")
    settings = _file_settings(args)
    _check_batch_axes(args)
    _check_folder(args.output, "the results")

    def found():
        return inputs.sources(args.inputs, args.output, args.format, INPUTS)

    running = False  # whether the driver runs, and so writes a summary when interrupted
    try:
        total = fixed = 0  # counted first for the progress bar (and the files whose frame is fixed); found again
        for source in found():  # as they go
            total += 1
            fixed += source.path.suffix.lower() not in AXIS_SUFFIXES
        if not total:
            raise CliError(f"no model files ({', '.join(INPUTS)}) in {' '.join(args.inputs)}")
        if fixed and (args.up or args.forward):
            print(f"warning: --up and --forward apply to OBJ and FBX files only; {fixed} glTF or .blend file(s) keep "
                  f"their own frames", file=sys.stderr)
        # stdout carries the summary table alone: what an engine prints meanwhile (Ray's notes on dead workers,
        # which the rows give too) goes to stderr with the progress bar
        with contextlib.redirect_stdout(sys.stderr), _engine(args, settings) as engine:
            args.output.mkdir(parents=True, exist_ok=True)
            running = True
            rows = driver.run(found(), total, engine, args.output, args.format, settings, resume=args.resume)
    except BatchError as error:
        raise CliError(str(error)) from None
    except KeyboardInterrupt:
        done = f"{args.output / driver.SUMMARY} lists the files done so far, and " if running else ""
        print(f"rigger: interrupted; {done}the same command with --resume goes on from there", file=sys.stderr)
        return EXIT_INTERRUPTED
    print(driver.summary_table(rows))
    return EXIT_FAILED if any(row["status"] != "ok" for row in rows) else 0


def _check_batch_axes(args):
    """CliError for ``--up``/``--forward`` values no OBJ or FBX file could be read with, before any file is."""
    try:
        for suffix in AXIS_SUFFIXES:
            file_axes(suffix, args.up, args.forward)
    except ValueError as error:
        raise CliError(str(error)) from None


def _engine(args, settings):
    if args.engine == "ray":
        from .batch.ray_engine import RayEngine

        return RayEngine(args.jobs, args.timeout, settings, args.address)
    from .batch.local import LocalEngine

    return LocalEngine(args.jobs or os.cpu_count() or 1, args.timeout, settings)
