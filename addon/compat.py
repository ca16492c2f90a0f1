"""Does this add-on's compiled code load here? Checked before the add-on registers anything.

A Rigger zip carries compiled modules for one platform and one Python version, and Blender releases embed different
Pythons (4.2 to 5.0 embed 3.11, 5.1 and later 3.13). Installing a zip built for another platform or Blender, or one
built without its compiled modules, must tell the user which zip to install instead of failing with a traceback.
Needs no bpy, so the build tool (``tools/build_addon.py``) shares these names.
"""
import importlib
import importlib.machinery
import os
import pathlib
import platform
import re
import sys
import tomllib
from typing import NamedTuple

COMPILED_MODULES = ("_rigger_cdt", "_rigger_silhouette", "_rigger_weights")  # as setup.py builds them
COMPILED_FILE_SUFFIXES = (".so", ".pyd")


class BlenderRange(NamedTuple):
    """The Blender releases that embed one Python version; ``maximum`` is the first release outside (or None)."""

    minimum: str
    maximum: str | None
    label: str


BLENDER_FOR_PYTHON = {
    (3, 11): BlenderRange("4.2.0", "5.1.0", "Blender 4.2 to 5.0"),
    (3, 13): BlenderRange("5.1.0", None, "Blender 5.1 and later"),
}

_SYSTEMS = {"linux": "linux", "darwin": "macos", "win32": "windows"}
_MACHINES = {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64", "arm64": "arm64"}
# The interpreter tag in a compiled module's file name: ".cpython-311-x86_64-linux-gnu.so", ".cp311-win_amd64.pyd".
_PYTHON_TAG = re.compile(r"\.(?:cpython-|cp)(\d)(\d+)(?:-([^.]+))?\.")

PACKAGE_DIR = pathlib.Path(__file__).resolve().parent
MANIFEST = "blender_manifest.toml"  # in every zip (either installer); its version names the zip to install


def blender_platform():
    """This machine's platform as Blender's extension platforms name it: ``linux-x64``, ``macos-arm64``, ..."""
    machine = platform.machine().lower()
    return f"{_SYSTEMS.get(sys.platform, sys.platform)}-{_MACHINES.get(machine, machine)}"


def zip_name(version, platform_name, python):
    """The file name of the add-on zip for ``platform_name`` and the ``python`` (major, minor) it was built with."""
    return f"rigger-{version}-{platform_name}-py{python[0]}{python[1]}.zip"


def compiled_problem():
    """None when every compiled module imports; otherwise one user-facing paragraph: what is wrong, what to install.

    Never raises: the add-on shows the text in its panel instead of its real UI.
    """
    for name in COMPILED_MODULES:
        try:
            importlib.import_module(f".{name}", __package__)
        except Exception as error:  # an unloadable binary raises ImportError, or whatever its init raises
            return f"{_what_is_wrong(name, error)} {_what_to_install()}"
    return None


def _what_is_wrong(name, error):
    """Why compiled module ``name`` did not import, judged from the files beside this module."""
    files = sorted(path.name for path in PACKAGE_DIR.glob(f"{name}.*") if path.suffix in COMPILED_FILE_SUFFIXES)
    loadable = [file for file in files if file[len(name):] in importlib.machinery.EXTENSION_SUFFIXES]
    if loadable:
        reason = str(error).replace(f"{PACKAGE_DIR}{os.sep}", "")  # the folder is this add-on's own: noise
        return f"Rigger's compiled module {loadable[0]} is installed but does not load ({reason})."
    if files:
        built_for = ", ".join(sorted({_built_for(file) for file in files}))
        here = f"Python {sys.version_info[0]}.{sys.version_info[1]} on {blender_platform()}"
        return f"Rigger's compiled modules were built for {built_for}, but this Blender runs {here}."
    return (f"Rigger's compiled module {name} is missing from this installation (a zip built without compiled "
            f"code?), so it cannot rig.")


def _built_for(file_name):
    """The Python version (and platform, when the name tells) a compiled module file was built for."""
    tag = _PYTHON_TAG.search(file_name)
    if tag is None:
        return f"another Python ({file_name})"
    major, minor, target = tag.groups()
    return f"Python {major}.{minor}" + (f" on {target}" if target else "")


def manifest_version():
    """The add-on's version, as its manifest gives it (the one source of the version)."""
    return tomllib.loads((PACKAGE_DIR / MANIFEST).read_text(encoding="utf-8"))["version"]


def _what_to_install():
    """Which zip to install instead, for this Blender's Python and this platform."""
    python = sys.version_info[:2]
    name = zip_name(manifest_version(), blender_platform(), python)
    blender = BLENDER_FOR_PYTHON.get(python)
    fits = blender.label if blender else f"Python {python[0]}.{python[1]}"
    return (f"Remove this add-on and install {name} instead, the zip for {fits} on {blender_platform()} "
            f"(`make addon` builds it; see the README).")
