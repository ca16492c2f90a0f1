"""One headless Blender session for tests/test_addon_zip.py: install the add-on zip, use it, remove it.

Run as ``python -s -S addon_child.py SCENARIO ZIP INSTALLER`` with only a venv's site-packages on PYTHONPATH, so no
``.pth`` file runs and the editable dev install of ``rigger`` is not importable, and with the Blender user
directories in a temporary folder (``BLENDER_USER_RESOURCES``). SCENARIO is ``use`` (rig and skin a character
through the operators, then disable, re-enable and uninstall) or ``problem`` (a zip whose compiled code cannot
load); INSTALLER is ``extension`` or ``legacy``. Prints one JSON line of findings for the test to judge.
"""
import importlib
import importlib.util
import json
import os
import pathlib
import sys
from types import SimpleNamespace

import bpy
import mathutils
import numpy as np

import addon_utils  # Blender's own module, importable once bpy is

PACKAGE_ID = "rigger"
SAMPLE = "humanoid"
UNINSTALL_MARK = "--- uninstalling"  # on stderr: headless, Blender's legacy uninstaller prints a traceback after it
LIFT = np.array([0.0, 0.0, 1.0])  # metres the root bones are moved by in pose mode


def main(scenario, zip_path, installer):
    findings = {"blender": bpy.app.version_string,
                "dev_rigger_importable": importlib.util.find_spec(PACKAGE_ID) is not None}
    module = install(zip_path, installer)
    findings.update(module=module, installed_at=str(pathlib.Path(sys.modules[module].__file__).parent),
                    enabled=is_enabled(module))
    if scenario == "use":
        findings["operator_file"] = sys.modules[bpy.types.RIGGER_OT_rig.__module__].__file__
        findings["first"] = rig_and_skin(module)
        disable(module)
        findings["after_disable"] = {"enabled": is_enabled(module), "operators": operators_registered()}
        enable(module)
        findings["after_enable"] = {"enabled": is_enabled(module), "operators": operators_registered()}
        findings["second"] = rig_and_skin(module)
        disable(module)
    else:
        findings["operators"] = operators_registered()
        findings["panel_lines"] = problem_panel_lines()
        findings["problem"] = importlib.import_module(f"{module}.compat").compiled_problem()
        disable(module)
        findings["panel_after_disable"] = hasattr(bpy.types, "RIGGER_PT_problem")
    installed_at = pathlib.Path(findings["installed_at"])
    print(UNINSTALL_MARK, file=sys.stderr, flush=True)
    uninstall(module, installer)
    findings["files_left"] = installed_at.exists()
    findings["listed_after_uninstall"] = module in {mod.__name__ for mod in addon_utils.modules(refresh=True)}
    print(json.dumps(findings))


def install(zip_path, installer):
    """Install and enable the zip; the add-on's module name."""
    if installer == "extension":
        finished(bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                                            enable_on_install=True))
        return f"bl_ext.user_default.{PACKAGE_ID}"
    finished(bpy.ops.preferences.addon_install(filepath=zip_path))
    enable(PACKAGE_ID)
    return PACKAGE_ID


def uninstall(module, installer):
    if installer == "extension":
        repos = list(bpy.context.preferences.extensions.repos)
        index = next(i for i, repo in enumerate(repos) if repo.module == "user_default")
        finished(bpy.ops.extensions.package_uninstall(repo_index=index, pkg_id=PACKAGE_ID))
        return
    try:
        finished(bpy.ops.preferences.addon_remove(module=module))
    except RuntimeError as error:
        # Headless there is no area to redraw: the operator fails on its last line, after removing the add-on.
        if "tag_redraw" not in str(error):
            raise


def enable(module):
    finished(bpy.ops.preferences.addon_enable(module=module))


def disable(module):
    finished(bpy.ops.preferences.addon_disable(module=module))


def finished(result):
    if result != {'FINISHED'}:
        raise RuntimeError(f"operator returned {result}")


def is_enabled(module):
    return addon_utils.check(module)[1]


def operators_registered():
    """Every Rigger operator class registered, whatever the add-on defines: none left over once it is disabled."""
    return sorted(name for name in dir(bpy.types) if name.startswith("RIGGER_OT_"))


def rig_and_skin(module):
    """Rig & Skin a new sample character through the operator; what came out, and how the skin follows the bones."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    samples = importlib.import_module(f"{module}.blender.samples")
    character = samples.build_character(SAMPLE)
    bpy.context.view_layer.objects.active = character
    character.select_set(True)
    result = bpy.ops.rigger.rig_skin()
    armatures = [obj for obj in bpy.data.objects if obj.type == 'ARMATURE']
    outcome = {"result": sorted(result), "armatures": len(armatures), "vertices": len(character.data.vertices),
               "samples_file": samples.__file__}
    if len(armatures) != 1:
        return outcome
    armature = armatures[0]
    bones = armature.data.bones
    bone_groups = {group.index for group in character.vertex_groups if group.name in bones}
    weighted = sum(any(item.group in bone_groups and item.weight > 0 for item in vertex.groups)
                   for vertex in character.data.vertices)
    outcome.update(bones=len(bones), weighted=weighted, worst_follow=worst_follow(character, armature))
    return outcome


def worst_follow(character, armature):
    """Lift every root bone in pose mode; the largest distance by which a vertex misses following by the same lift.

    The armature modifier normalises each vertex's weights, so every vertex that is weighted at all follows exactly.
    """
    before = evaluated_vertices(character)
    for pose_bone in armature.pose.bones:
        if pose_bone.parent is None:
            pose_bone.matrix = mathutils.Matrix.Translation(LIFT) @ pose_bone.matrix
    moved = evaluated_vertices(character)
    return float(np.abs(moved - before - LIFT).max())


def evaluated_vertices(obj):
    bpy.context.view_layer.update()
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    coordinates = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", coordinates)
    evaluated.to_mesh_clear()
    matrix = np.array(obj.matrix_world)
    return coordinates.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]


def problem_panel_lines():
    """The text the problem panel draws, if it is registered (drawn into a stand-in layout: no window here)."""
    panel = getattr(bpy.types, "RIGGER_PT_problem", None)
    if panel is None:
        return None
    lines = []
    layout = SimpleNamespace(label=lambda text="", icon='NONE': lines.append(text))
    layout.column = lambda align=False: layout
    context = SimpleNamespace(region=SimpleNamespace(width=300), preferences=bpy.context.preferences)
    panel.draw(SimpleNamespace(layout=layout, message=panel.message), context)
    return lines


if __name__ == "__main__":
    main(*sys.argv[1:])
    # bpy 4.2 as a Python module (4.2.0 and 4.2.23 alike; not 5.0) segfaults at process exit, in C++ destructors
    # that run after Python has finalised, once an add-on with property update callbacks has been removed. Every
    # check is done and printed by now, so leave without that teardown.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
