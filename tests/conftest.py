"""Shared test fixtures: where the read-only shared data lives, and skipping when it is absent."""
import os
import pathlib
import sys
import tempfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = pathlib.Path(os.environ.get("RIGGER_SHARED", ROOT.parent / "shared"))
sys.path.insert(0, str(ROOT / "bench"))  # bench/ is not a package; tests use its scorers and readers (rigdata, ...)

# bpy reads user resources at import; keep every test run away from the real home directory.
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="rigger-blender-user-"))


def shared_path(*parts):
    """Path inside ../shared, or skip the test with a clear reason when that data is not beside this checkout."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"shared test data not found at {path} (clone the project beside ../shared to run this test)")
    return path
