"""Shared test fixtures: where the read-only shared data lives, and skipping when it is absent; for the Blender tests,
a fresh empty scene and object activation (bpy is imported only when they are used, so ``import rigger`` and the
pure-core tests stay bpy-free)."""
import os
import pathlib
import sys

import pytest
from hypothesis import settings

from rigger.blender.headless import empty_scene, temporary_user_folder

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = pathlib.Path(os.environ.get("RIGGER_SHARED", ROOT.parent / "shared"))
sys.path.insert(0, str(ROOT / "bench"))  # bench/ is not a package; tests use its scorers and readers (rigdata, ...)

temporary_user_folder()  # before any test imports bpy; the Blender child processes share the folder

# Property tests are derandomised and keep no saved-example database, so a run's verdict does not depend on the run
# (a failure found once is pinned as an example of its own); no deadline, the compiled code's first call is slow.
settings.register_profile("rigger", deadline=None, derandomize=True, database=None)
settings.load_profile("rigger")


def shared_path(*parts):
    """Path inside ../shared, or skip the test with a clear reason when that data is not beside this checkout."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"shared test data not found at {path} (clone the project beside ../shared to run this test)")
    return path


@pytest.fixture
def scene():
    """A fresh empty Blender scene for one test (only for modules that import bpy or skip without it)."""
    return empty_scene()


def activate(obj, *others):
    """Select ``obj`` and ``others`` only, and make ``obj`` the active object."""
    import bpy

    for selected in bpy.context.view_layer.objects.selected:
        selected.select_set(False)
    for each in (obj, *others):
        each.select_set(True)
    bpy.context.view_layer.objects.active = obj
