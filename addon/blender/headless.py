"""Blender as a Python module outside Blender: bpy reads and writes a user folder (preferences, add-ons, caches) at
import, so the demo, the tests and the benchmarks give it a temporary one (unless ``BLENDER_USER_RESOURCES`` is
set already) and neither change nor depend on the user's own Blender set-up. They, and the command line's
scene files, start from one empty scene. Needs no bpy to import: it runs before the first ``import bpy``."""
import atexit
import os
import shutil
import tempfile

VARIABLE = "BLENDER_USER_RESOURCES"


def temporary_user_folder():
    """Point bpy at a new temporary user folder, removed when the process exits, unless one is set already (a parent
    process chose it; its children share it). Returns the folder."""
    if VARIABLE not in os.environ:
        folder = tempfile.mkdtemp(prefix="rigger-blender-user-")
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        os.environ[VARIABLE] = folder
    return os.environ[VARIABLE]


def empty_scene():
    """Reset Blender to its factory-default empty file (``read_factory_settings`` would unregister the add-ons)
    and return the scene."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    return bpy.context.scene


def blender_message(error):
    """A Blender operator's error (its RuntimeError) as one clause: the last line of its text (an add-on's operator
    may put its whole traceback there) without the "Error:" prefix bpy puts before it. An operator that Ctrl-C
    stopped reports that as its error: KeyboardInterrupt is raised again instead."""
    if "KeyboardInterrupt" in str(error):
        raise KeyboardInterrupt
    lines = str(error).strip().splitlines()
    return (lines[-1] if lines else "no reason given").strip().removeprefix("Error:").strip()
