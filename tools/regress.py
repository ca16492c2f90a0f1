"""Regression fingerprints: does a change move any skeleton or stage by a single bit?

Rigs every ``../shared`` model (``models/gt`` and ``models/nogt``) and every generated sample character under
``SETTINGS`` and hashes each output array (dtype, shape and bytes): the bones, every stage field and the parameters
(not the timings: seconds differ between runs). ``--baseline`` writes the fingerprints; without it they are compared
with the baseline and every differing field is listed (exit status 1). Run it before a change that should move
nothing, then after::

    make regress-baseline     # on the commit before the change
    make regress              # after it: "identical" or the runs and fields that differ

A rig that raises is fingerprinted by its error message, so a change that makes a model fail is caught too.
"""
import argparse
import hashlib
import json
import multiprocessing
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = pathlib.Path(os.environ.get("RIGGER_SHARED", ROOT.parent / "shared"))
BASELINE = ROOT / "out" / "regress" / "baseline.json"
sys.path.insert(0, str(ROOT / "bench"))

# name -> silhouette parameters; together they take every branch the defaults skip (no split, no side views, a
# direction off the axes, finer detail and a coarser grid)
SETTINGS = {
    "default": {},
    "no_split": {"split_layers": False},
    "no_side_view": {"side_view": False},
    "direction": {"view": "DIRECTION", "view_direction": (0.3, 1.0, 0.2)},
    "detail": {"prune": 1.0, "min_branch": 1.0, "bone_length": 0.07, "max_chain_bones": 0, "resolution": 256},
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", action="store_true", help="write the baseline instead of comparing with it")
    parser.add_argument("--file", type=pathlib.Path, default=BASELINE, help=f"baseline file (default {BASELINE})")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel processes")
    parser.add_argument("--characters", type=pathlib.Path, help=argparse.SUPPRESS)  # child: generate into here
    args = parser.parse_args(argv)
    if args.characters:
        return _write_characters(args.characters)
    if not args.baseline and not args.file.exists():
        parser.error(f"no baseline at {args.file}: run with --baseline on the commit to compare against first")

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rigger-regress-") as folder:
        meshes = _shared_meshes() + _characters(pathlib.Path(folder))
        runs = [(name, path, setting) for name, path in meshes for setting in SETTINGS]
        with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
            prints = dict(pool.imap(_fingerprint_run, runs, chunksize=1))
    seconds = time.perf_counter() - start
    if args.baseline:
        args.file.parent.mkdir(parents=True, exist_ok=True)
        args.file.write_text(json.dumps(prints, indent=1, sort_keys=True) + "\n")
        print(f"baseline of {len(prints)} runs ({len(meshes)} meshes x {len(SETTINGS)} settings) written to "
              f"{args.file} in {seconds:.0f} s")
        return 0
    return _compare(json.loads(args.file.read_text()), prints, seconds)


def _compare(baseline, prints, seconds):
    """Print the runs and fields that differ from ``baseline``; 0 when none does."""
    differing = []
    for run in sorted(set(baseline) | set(prints)):
        before, after = baseline.get(run), prints.get(run)
        if before is None or after is None:
            differing.append(f"{run}: {'new run' if before is None else 'missing run'}")
            continue
        fields = sorted(key for key in set(before) | set(after) if before.get(key) != after.get(key))
        if fields:
            differing.append(f"{run}: {', '.join(fields)}")
    if differing:
        print(f"{len(differing)} of {len(baseline)} runs differ from the baseline:")
        print("\n".join(f"  {line}" for line in differing))
        return 1
    print(f"identical: {len(prints)} runs (skeletons and stages) match the baseline bit for bit ({seconds:.0f} s)")
    return 0


def _shared_meshes():
    """(name, OBJ path) of every ../shared model, or none (with a note) when ../shared is absent."""
    if not SHARED.exists():
        print(f"note: no shared models at {SHARED}; fingerprinting the generated characters only")
        return []
    paths = sorted((SHARED / "models" / "gt").glob("*/*.obj")) + sorted((SHARED / "models" / "nogt").glob("*.obj"))
    return [(path.stem, str(path)) for path in paths]


def _characters(folder):
    """(name, .npz path) of every sample character, generated with Blender in a child process (bpy stays out of
    the rigging processes)."""
    subprocess.run([sys.executable, __file__, "--characters", str(folder)], check=True)
    return [(f"sample_{path.stem}", str(path)) for path in sorted(folder.glob("*.npz"))]


def _write_characters(folder):
    from rigger import samples
    from rigger.blender.headless import empty_scene, temporary_user_folder

    temporary_user_folder()
    from rigger.blender.samples import character_arrays

    empty_scene()
    for name in samples.CHARACTERS:
        vertices, triangles = character_arrays(name)
        np.savez(folder / f"{name}.npz", vertices=vertices, triangles=triangles)
    return 0


def _fingerprint_run(run):
    """("mesh/setting", {field: hash}) of one rig."""
    import rigger
    from rigdata import load_obj

    name, path, setting = run
    if path.endswith(".npz"):
        with np.load(path) as arrays:
            vertices, triangles = arrays["vertices"], arrays["triangles"]
    else:
        vertices, triangles = load_obj(path)
    try:
        skeleton = rigger.rig_mesh(vertices, triangles, **SETTINGS[setting])
    except Exception as error:  # a failure is an outcome to compare like any other
        return f"{name}/{setting}", {"error": f"{type(error).__name__}: {error}"}
    fields = {"bones.names": _digest(np.array(skeleton.names)), "bones.heads": _digest(skeleton.heads),
              "bones.tails": _digest(skeleton.tails), "bones.parents": _digest(skeleton.parents)}
    for key, value in stage_fields(skeleton):
        fields[key] = _digest(value)
    return f"{name}/{setting}", fields


def stage_fields(skeleton):
    """(key, value) of every tracked field: each stage's ``to_dict`` and the parameters, nested dicts and lists
    flattened into dotted keys."""
    for name in sorted(skeleton.stages):
        yield from _flattened(f"stages.{name}", skeleton.stages[name].to_dict())
    yield from _flattened("params", skeleton.params)


def _flattened(prefix, value):
    if isinstance(value, dict):
        for key in sorted(value):
            yield from _flattened(f"{prefix}.{key}", value[key])
    elif isinstance(value, (list, tuple)) and any(isinstance(item, np.ndarray) for item in value):
        for index, item in enumerate(value):
            yield from _flattened(f"{prefix}.{index}", item)
    else:
        yield prefix, value


def _digest(value):
    """A hash of ``value``'s exact bits: dtype, shape and bytes of its array form (None hashes as itself)."""
    array = np.ascontiguousarray(np.asarray(value, dtype=object if value is None else None))
    if array.dtype == object:
        content = repr(value).encode()
    else:
        content = array.tobytes()
    return hashlib.sha256(f"{array.dtype.str}{array.shape}".encode() + content).hexdigest()[:20]


if __name__ == "__main__":
    sys.exit(main())
