"""Build the offline-installable add-on zip for this platform and Python: ``make addon``.

Writes ``<output-dir>/rigger-<version>-<platform>-py<XY>.zip`` holding the package under one top folder
``rigger/``, which both installers accept: Blender's extension installer finds ``rigger/blender_manifest.toml``,
and the legacy add-on installer needs ``__init__.py`` inside a folder. (``blender_ext.py build`` writes the package
at the zip's root, which the legacy installer rejects, so the zip is written here and checked with
``blender_ext.py validate``.) The zip's manifest declares this one platform and the Blender releases that embed
this Python; the zip must hold every compiled module for them, unlike a split-platform build, which silently writes
zips without compiled code for the platforms it did not build.
"""
import argparse
import ast
import importlib.machinery
import importlib.util
import pathlib
import re
import subprocess
import sys
import tomllib
import zipfile

from rigger import compat

ROOT = pathlib.Path(__file__).resolve().parents[1]
GENERATED_KEYS = ("blender_version_min", "blender_version_max", "platforms")
LEFT_OUT_DIRS = {"__pycache__"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--source", type=pathlib.Path, default=ROOT / "addon", help="the add-on package folder")
    parser.add_argument("--output-dir", type=pathlib.Path, default=ROOT / "dist")
    args = parser.parse_args()
    try:
        print(build(args.source, args.output_dir))
    except ValueError as error:
        sys.exit(f"build_addon: {error}")


def build(source, output_dir):
    """Write, validate and check the zip for this interpreter; return its path. ValueError says what is wrong."""
    python = sys.version_info[:2]
    if python not in compat.BLENDER_FOR_PYTHON:
        raise ValueError(f"no Blender release embeds Python {python[0]}.{python[1]} (known: "
                         f"{', '.join(f'{a}.{b}' for a, b in compat.BLENDER_FOR_PYTHON)})")
    manifest_text = (source / compat.MANIFEST).read_text(encoding="utf-8")
    manifest = tomllib.loads(manifest_text)
    _check_bl_info(source / "__init__.py", manifest["version"])
    platform_name = compat.blender_platform()
    members = _package_files(source)
    output_dir.mkdir(parents=True, exist_ok=True)
    path = output_dir / compat.zip_name(manifest["version"], platform_name, python)
    partial = path.with_name(f".{path.name}")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
        for member in members:
            relative = member.relative_to(source).as_posix()
            if relative == compat.MANIFEST:
                archive.writestr(f"{manifest['id']}/{relative}",
                                 zip_manifest(manifest_text, platform_name, compat.BLENDER_FOR_PYTHON[python]))
            else:
                archive.write(member, f"{manifest['id']}/{relative}")
    partial.replace(path)
    _validate(path)
    return path


def _check_bl_info(init_file, version):
    """The legacy installer reads ``bl_info``: its version must be the manifest's."""
    tree = ast.parse(init_file.read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(target, "id", None) == "bl_info" for target in node.targets):
            bl_version = ".".join(str(part) for part in ast.literal_eval(node.value)["version"])
            if bl_version != version:
                raise ValueError(f"bl_info version {bl_version} in {init_file} differs from manifest version {version}")
            return
    raise ValueError(f"{init_file} has no bl_info (the legacy add-on installer needs it)")


def _package_files(source):
    """Every file of the package to ship: the compiled modules for this interpreter, none for others, no caches."""
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    compiled = {f"{name}{suffix}" for name in compat.COMPILED_MODULES}
    missing = sorted(name for name in compiled if not (source / name).is_file())
    if missing:
        raise ValueError(f"{', '.join(missing)} not found in {source}: run `make build` first")
    files = []
    for path in sorted(source.rglob("*")):
        parts = path.relative_to(source).parts
        if not path.is_file() or any(part.startswith(".") or part in LEFT_OUT_DIRS for part in parts):
            continue
        if path.suffix in compat.COMPILED_FILE_SUFFIXES + (".pyc",) and path.name not in compiled:
            continue
        files.append(path)
    return files


def zip_manifest(text, platform_name, blender):
    """The manifest ``text`` with the platform and Blender range of one zip written in before its first table."""
    kept = [line for line in text.splitlines() if not re.match(rf"({'|'.join(GENERATED_KEYS)})\s*=", line)]
    generated = ["# Written by tools/build_addon.py: the platform and Blender releases this zip's compiled code fits.",
                 f'blender_version_min = "{blender.minimum}"']
    if blender.maximum:
        generated.append(f'blender_version_max = "{blender.maximum}"')
    generated += [f'platforms = ["{platform_name}"]', ""]
    first_table = next((i for i, line in enumerate(kept) if line.startswith("[")), len(kept))
    result = "\n".join(kept[:first_table] + generated + kept[first_table:]) + "\n"
    parsed = tomllib.loads(result)
    if parsed["platforms"] != [platform_name] or parsed["blender_version_min"] != blender.minimum:
        raise ValueError(f"write {', '.join(GENERATED_KEYS)} in {compat.MANIFEST} on one line each, or not at all")
    return result


def _validate(path):
    """Blender's own extension checker must accept the zip."""
    bpy_dir = pathlib.Path(importlib.util.find_spec("bpy").origin).parent
    checker = next(bpy_dir.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"), None)
    if checker is None:
        raise ValueError(f"blender_ext.py not found under {bpy_dir} (is bpy installed?)")
    result = subprocess.run([sys.executable, str(checker), "validate", str(path)], capture_output=True, text=True)
    if result.returncode != 0:
        raise ValueError(f"{path.name} failed blender_ext.py validate:\n{result.stdout}{result.stderr}")


if __name__ == "__main__":
    main()
