"""``python -m rigger``: rig model files from the command line (``rig``), or whole folders in parallel (``batch``).

``rig`` imports an OBJ, glTF/GLB, FBX or .blend file into an empty headless Blender (the ``bpy`` module), rigs its
mesh, skins it and saves .blend, .glb or .fbx, plus an optional JSON report. Outputs are written to temporary
files and renamed into place only when everything succeeded (``rigger.core.files``), so a failure leaves nothing
behind.
"""
import argparse
import collections
import concurrent.futures
import json
import os
import pathlib
import subprocess
import sys
import time

from .axes import AXES, AXIS_SUFFIXES, file_axes
from .core.files import remove_leftovers, replaced_on_success
from .core.targets import TARGETS

INPUTS = (".obj", ".glb", ".gltf", ".fbx", ".blend")
OUTPUTS = (".blend", ".glb", ".fbx")
SUMMARY = "summary.json"  # batch: the summary table as JSON, beside the results
EXIT_FAILED = 1


class CliError(Exception):
    """A failure to tell the user in one line (missing file, no mesh, rigging failed); exits non-zero."""


def main(argv=None):
    parser = _parser()
    args = parser.parse_args(_axis_values_joined(sys.argv[1:] if argv is None else list(argv)))
    try:
        return args.run(args)
    except CliError as error:
        print(f"rigger: error: {error}", file=sys.stderr)
        return EXIT_FAILED


def _parser():
    parser = argparse.ArgumentParser(prog="python -m rigger", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)

    rig = commands.add_parser("rig", help="rig one model file")
    rig.add_argument("input", type=pathlib.Path, help=f"model file ({', '.join(INPUTS)})")
    rig.add_argument("-o", "--output", type=pathlib.Path,
                     help=f"where to save ({', '.join(OUTPUTS)}); default INPUT_rigged.blend beside the input")
    rig.add_argument("--report", type=pathlib.Path, help="write a JSON report here")
    _method_options(rig)
    _axis_options(rig)
    rig.set_defaults(run=_run_rig)

    batch = commands.add_parser("batch", help="rig every model file of a folder in parallel processes")
    batch.add_argument("folder", type=pathlib.Path, help="folder of model files (not searched recursively)")
    batch.add_argument("-o", "--output", type=pathlib.Path, required=True, help="folder for the results")
    batch.add_argument("--format", choices=[suffix[1:] for suffix in OUTPUTS], default="blend",
                       help="output format (default blend)")
    batch.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel processes (default: CPUs)")
    batch.add_argument("--timeout", type=float, metavar="SECONDS",
                       help="give up on a file after this many seconds (default: no limit)")
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
    parser.add_argument("--target", choices=list(TARGETS), default="plain",
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
        from .core.metarig import MetarigTuning

        print("the rigify target's metarig fitting:")
        _print_tuning(MetarigTuning)
    for where, error in registry.failures.items():
        print(f"failed to load {where}: {error}", file=sys.stderr)
    return 0


def _print_tuning(table):
    print(f"  tuning ({table.__module__}.{table.__name__}):")
    for field, value, why, owner in table.rows():
        print(f"    {field} = {value!r}  {why}  [{owner.__module__}.{owner.__name__}]")


def _run_rig(args):
    from .api import method_registry
    from .core.params import resolve

    source = args.input
    if not source.is_file():
        raise CliError(f"{source}: no such file")
    if source.suffix.lower() not in INPUTS:
        raise CliError(f"{source}: cannot read {source.suffix or 'files without a suffix'}; use {', '.join(INPUTS)}")
    output = args.output or source.with_name(f"{source.stem}_rigged.blend")
    if output.suffix.lower() not in OUTPUTS:
        raise CliError(f"{output}: cannot write {output.suffix or 'files without a suffix'}; use {', '.join(OUTPUTS)}")
    _check_destinations(source, output, args.report)
    try:  # check the method, parameters and axes before the slow import
        method = method_registry().lookup(args.method)
        params = resolve(method.params, _settings(args.settings))
        file_axes(source.suffix, args.up, args.forward)
    except ValueError as error:
        raise CliError(str(error)) from None

    from . import register
    from .blender import scenefiles

    register()  # the properties the Blender layer keeps on scenes and objects
    try:
        report = scenefiles.rig_file(source, output, method.name, params, target=args.target, skin=not args.no_skin,
                                     up=args.up, forward=args.forward)
        if args.report is not None:
            with replaced_on_success(args.report) as path:
                path.write_text(json.dumps(report, indent=2))
    except ValueError as error:
        raise CliError(str(error)) from None
    except RuntimeError as error:  # a Blender operator failed (an exporter, say)
        raise CliError(f"{source}: {scenefiles.blender_message(error)}") from None
    except OSError as error:  # a folder that cannot be written, a full disk
        raise CliError(f"{error.filename or output}: {error.strerror or error}") from None
    print(f"rigged {source} → {output}: {len(report['bones'])} bones, {report['skinning']['summary']}")
    for warning in report["warnings"]:
        print(f"warning: {warning}", file=sys.stderr)
    return 0


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


def _run_batch(args):
    if not args.folder.is_dir():
        raise CliError(f"{args.folder}: no such folder")
    if args.jobs < 1:
        raise CliError(f"--jobs must be at least 1, got {args.jobs}")
    if args.timeout is not None and args.timeout <= 0:
        raise CliError(f"--timeout must be a positive number of seconds, got {args.timeout}")
    sources = sorted(path for path in args.folder.iterdir() if path.suffix.lower() in INPUTS and path.is_file())
    if not sources:
        raise CliError(f"{args.folder}: no model files ({', '.join(INPUTS)})")
    axes = _batch_axes(args, sources)
    _check_folder(args.output, "the results")
    args.output.mkdir(parents=True, exist_ok=True)
    extra = [f"--method={args.method}", f"--target={args.target}", *(f"--set={pair}" for pair in args.settings)]
    extra += ["--no-skin"] if args.no_skin else []
    stems = output_stems(sources, args.format, args.folder.resolve() == args.output.resolve())
    rows = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(rig_in_child, source, args.output / f"{stem}.{args.format}",
                               args.output / f"{stem}.json", extra + axes.get(source.suffix.lower(), []),
                               args.timeout)
                   for source, stem in zip(sources, stems)]
        for done, future in enumerate(concurrent.futures.as_completed(futures), start=1):
            rows.append(future.result())
            _progress(done, len(sources))
    rows.sort(key=lambda row: row["file"])
    print(_summary_table(rows))
    (args.output / SUMMARY).write_text(json.dumps(rows, indent=2))
    failed = sum(row["status"] != "ok" for row in rows)
    return EXIT_FAILED if failed else 0


def _batch_axes(args, sources):
    """The ``--up``/``--forward`` arguments of a batch's children by file suffix: given only to the OBJ and FBX files
    (checked here, once); a warning when other files are read in their own frames."""
    if args.up is None and args.forward is None:
        return {}
    try:
        axes = {suffix: file_axes(suffix, args.up, args.forward) for suffix in AXIS_SUFFIXES}
    except ValueError as error:
        raise CliError(str(error)) from None
    fixed = sum(source.suffix.lower() not in AXIS_SUFFIXES for source in sources)
    if fixed:
        print(f"warning: --up and --forward apply to OBJ and FBX files only; {fixed} glTF or .blend file(s) keep "
              f"their own frames", file=sys.stderr)
    return {suffix: [f"--up={up}", f"--forward={forward}"] for suffix, (up, forward) in axes.items()}


def output_stems(sources, suffix, in_place):
    """The name (without suffix) of each source's output and report: its stem, or stem_suffix where that would
    overwrite another source's results, the summary, or (``in_place``: results written into the input folder) the
    source itself."""
    counts = collections.Counter(source.stem for source in sources)

    def clashes(source):
        return (counts[source.stem] > 1 or source.stem == pathlib.Path(SUMMARY).stem
                or in_place and source.suffix.lower() == f".{suffix}")

    return [f"{source.stem}_{source.suffix[1:]}" if clashes(source) else source.stem for source in sources]


def child_command(source, output, report, extra):
    """The command that rigs one file of a batch: this CLI's ``rig`` in a fresh Python (each needs its own Blender)."""
    return [sys.executable, "-m", __package__, "rig", str(source), "-o", str(output), "--report", str(report), *extra]


def rig_in_child(source, output, report, extra, timeout=None):
    """Rig ``source`` in a child process; its row of the summary table. A child that fails, crashes or runs past
    ``timeout`` seconds (killed then) gives a failed row saying so; it never stops the batch."""
    start = time.perf_counter()
    try:
        child = subprocess.run(child_command(source, output, report, extra), capture_output=True, text=True,
                               timeout=timeout)
    except subprocess.TimeoutExpired:
        child = None
    row = {"file": source.name, "seconds": round(time.perf_counter() - start, 2), "status": "failed", "bones": 0,
           "skinning": ""}
    if child is None or child.returncode:
        for final in (output, report):  # what a killed child left half written
            remove_leftovers(final)
        return {**row, "message": f"timed out after {timeout:g} s" if child is None else _child_failure(child)}
    try:
        data = json.loads(report.read_text())
    except (OSError, ValueError) as error:
        return {**row, "message": f"finished without a readable report: {error}"}
    return {**row, "status": "ok", "bones": len(data["bones"]), "skinning": data["skinning"]["summary"],
            "message": "; ".join(data["warnings"]), "output": output.name}


def _child_failure(child):
    """What went wrong in a failed child: its ``rigger: error:`` line, else how it ended and its last output."""
    lines = [line for line in child.stderr.splitlines() if line.startswith("rigger: error:")]
    if lines:
        return lines[-1].removeprefix("rigger: error: ")
    how = f"killed by signal {-child.returncode}" if child.returncode < 0 else f"exit status {child.returncode}"
    tail = child.stderr.strip()[-300:]
    return f"crashed ({how})" + (f": {tail}" if tail else "")


def _progress(done, total, width=30):
    filled = round(width * done / total)
    end = "\n" if done == total else ""
    print(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total}", end=end, file=sys.stderr, flush=True)


def _summary_table(rows):
    header = ("file", "status", "bones", "seconds", "skinning / message")
    lines = [" | ".join(header), " | ".join("---" for _ in header)]
    for row in rows:
        note = row["message"] if row["status"] != "ok" else row["skinning"]
        lines.append(" | ".join(str(value) for value in (row["file"], row["status"], row["bones"], row["seconds"],
                                                           note)))
    ok = sum(row["status"] == "ok" for row in rows)
    return "\n".join(lines) + f"\n{ok} of {len(rows)} rigged"
