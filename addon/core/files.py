"""Writing a file so that a failure part way leaves nothing behind."""
import contextlib
import glob
import os
import pathlib
import shutil
import tempfile


_LEFTOVER = ".rigger-partial."  # how the temporary folders beside the final files begin


@contextlib.contextmanager
def replaced_on_success(final):
    """A temporary path to write ``final`` to, renamed to ``final`` when the block ends without an error (and
    removed otherwise). It lies in a fresh folder ".rigger-partial.<name>.*" beside ``final``: the same file system
    for the rename, no existing file for Blender to back up as .blend1, and the usual permissions."""
    final = pathlib.Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"{_LEFTOVER}{final.name}.", dir=final.parent) as folder:
        path = pathlib.Path(folder) / final.name
        yield path
        os.replace(path, final)


def remove_leftovers(final):
    """Remove the folders ``replaced_on_success`` leaves beside ``final`` when its process is killed before the
    rename."""
    final = pathlib.Path(final)
    for leftover in final.parent.glob(glob.escape(f"{_LEFTOVER}{final.name}.") + "*"):
        if leftover.is_dir():
            shutil.rmtree(leftover)


def remove_leftover_folders(folder):
    """Remove every folder ``replaced_on_success`` left anywhere below ``folder`` (processes killed before the
    rename, say a whole batch killed at once)."""
    for parent, folders, _ in os.walk(folder):
        for name in [name for name in folders if name.startswith(_LEFTOVER)]:
            shutil.rmtree(os.path.join(parent, name), ignore_errors=True)
            folders.remove(name)
