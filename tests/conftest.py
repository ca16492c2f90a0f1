"""Shared test fixtures: where the read-only shared data lives, and skipping when it is absent; one reader of a
Blender mesh's vertex-group weights for the Blender tests."""
import os
import pathlib
import sys
import tempfile

import numpy as np
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


def vertex_weights(obj, names):
    """(N, len(names)) weights of mesh object ``obj``'s vertices in the vertex groups ``names``, in that order (0
    where a group is missing)."""
    column = {group.index: names.index(group.name) for group in obj.vertex_groups if group.name in names}
    table = np.zeros((len(obj.data.vertices), len(names)))
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            if element.group in column:
                table[vertex.index, column[element.group]] = element.weight
    return table
