"""Methods dropped into the add-on's methods folder appear in Blender after the add-on is enabled again; broken
ones are reported and skipped.

Works on a copy of the add-on package (importable as ``rigger_copy``) enabled through Blender's own add-on utilities,
as a user's installed add-on would be. It runs in its own module: the copy registers the same class names as the dev
add-on, so the two must never be registered together.
"""
import shutil
import sys

import pytest

from conftest import ROOT, activate

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402  (Blender's own module, importable once bpy is)

from rigger.blender.headless import empty_scene  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402


@pytest.fixture
def addon_copy(tmp_path):
    """A copy of the add-on package, importable as ``rigger_copy``, enabled through Blender's add-on utilities."""
    folder = tmp_path / "addons"
    shutil.copytree(ROOT / "addon", folder / "rigger_copy", ignore=shutil.ignore_patterns("__pycache__"))
    sys.path.insert(0, str(folder))
    yield folder / "rigger_copy"
    addon_utils.disable("rigger_copy")
    sys.path.remove(str(folder))
    for name in [name for name in sys.modules if name == "rigger_copy" or name.startswith("rigger_copy.")]:
        del sys.modules[name]


DROPPED_METHOD = '''
import numpy as np
from ..core.params import Param
from ..core.registry import RigMethod
from ..core.skeleton import Skeleton


class Dropped(RigMethod):
    name = "dropped"
    label = "Dropped In"
    params = (Param("height", "float", 0.5, min=0.0, max=1.0),)

    def rig(self, mesh, *, height):
        low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
        return Skeleton(["spine"], [low], [low + height * (high - low)], [-1])
'''


def methods_in_dropdown():
    return [item.identifier for item in bpy.context.scene.rigger.bl_rna.properties["method"].enum_items]


def test_a_method_file_dropped_into_the_folder_appears_after_re_enabling(addon_copy):
    assert addon_utils.enable("rigger_copy", default_set=False, handle_error=None)
    assert "dropped" not in methods_in_dropdown()
    (addon_copy / "methods" / "dropped.py").write_text(DROPPED_METHOD)
    (addon_copy / "methods" / "broken.py").write_text("raise ImportError('needs a library we do not have')\n")
    addon_utils.disable("rigger_copy")
    assert addon_utils.enable("rigger_copy", default_set=False, handle_error=None)
    assert methods_in_dropdown() == ["dropped", "silhouette"]  # sorted, the broken one skipped
    assert bpy.context.scene.rigger.methods.dropped.height == pytest.approx(0.5)
    registry = sys.modules["rigger_copy.api"].method_registry()
    assert "needs a library" in registry.failures["broken.py"]

    empty_scene()
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    bpy.context.scene.rigger.method = "dropped"
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    assert [bone.name for bone in obj.rigger_armature.data.bones] == ["spine"]


PACKAGE_METHOD = """
from .._template import TemplateMethod
from .reach import REACH


class Reaching(TemplateMethod):
    name = "reaching"
    label = "Reaching"

    def rig(self, mesh, *, bones, axis):
        skeleton = super().rig(mesh, bones=bones, axis=axis)
        skeleton.timings["reach"] = REACH  # where the test can see it
        return skeleton
"""


def test_an_edit_to_any_module_of_a_method_package_is_seen_after_re_enabling(addon_copy):
    package = addon_copy / "methods" / "reaching"
    package.mkdir()
    (package / "__init__.py").write_text(PACKAGE_METHOD)
    (package / "reach.py").write_text("REACH = 1\n")
    assert addon_utils.enable("rigger_copy", default_set=False, handle_error=None)
    assert methods_in_dropdown() == ["reaching", "silhouette"]
    api = sys.modules["rigger_copy.api"]
    box = [(x, y, z) for x in (0, 1) for y in (0, 4) for z in (0, 1)], [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5)]
    assert api.rig_mesh(*box, method="reaching").timings["reach"] == 1
    (package / "reach.py").write_text("REACH = 2\n")  # same size, same second
    addon_utils.disable("rigger_copy")
    assert addon_utils.enable("rigger_copy", default_set=False, handle_error=None)
    assert sys.modules["rigger_copy.api"].rig_mesh(*box, method="reaching").timings["reach"] == 2


def test_every_method_failing_to_load_leaves_a_working_panel_and_rig_disabled(addon_copy):
    (addon_copy / "methods" / "silhouette" / "tuning.py").write_text("syntax error here\n")
    assert addon_utils.enable("rigger_copy", default_set=False, handle_error=None)
    assert methods_in_dropdown() == ["NONE"]
    failure = sys.modules["rigger_copy.api"].method_registry().failures["silhouette/"]
    assert failure.startswith("SyntaxError:") and "tuning.py" in failure
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    assert not bpy.ops.rigger.rig.poll()
