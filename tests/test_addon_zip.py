"""The add-on zip (``make addon``): what it holds, and installing it offline into fresh headless Blenders.

Each install runs ``tests/addon_child.py`` in its own process with a clean ``sys.path`` (the venv's site-packages
without its ``.pth`` files, so the editable dev ``rigger`` is not importable) and a temporary Blender user
directory, for bpy 5.0 (``.venv``) and bpy 4.2 LTS (``.venv/bpy42``, made by ``make bpy42``), through the extension
installer and the legacy add-on installer. Also the compiled-module check ``rigger.compat`` on broken packages.
"""
import ast
import importlib
import importlib.machinery
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tomllib
import zipfile

import pytest
from conftest import ROOT

import rigger
from rigger import compat

CHILD = pathlib.Path(__file__).with_name("addon_child.py")
BLENDER_VENVS = {"5.0": ROOT / ".venv", "4.2": ROOT / ".venv" / "bpy42"}
PYTHON = sys.version_info[:2]
SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]  # this interpreter's compiled-module file ending
ALL_OPERATORS = ["RIGGER_OT_clear_overlays", "RIGGER_OT_direction_from_view", "RIGGER_OT_rig", "RIGGER_OT_rig_skin",
                 "RIGGER_OT_skin"]
CHILD_SECONDS = 300


@pytest.fixture(scope="session")
def addon_zip(tmp_path_factory):
    """The zip ``make addon`` builds, built once into a temporary folder."""
    result = build_zip(ROOT / "addon", tmp_path_factory.mktemp("dist"))
    assert result.returncode == 0, result.stderr
    return pathlib.Path(result.stdout.strip())


def build_zip(source, output_dir):
    return subprocess.run([sys.executable, str(ROOT / "tools" / "build_addon.py"), "--source", str(source),
                           "--output-dir", str(output_dir)], capture_output=True, text=True, timeout=120)


# --- what the zip holds ---------------------------------------------------------------------------------------------

def test_zip_is_named_for_version_platform_and_python(addon_zip):
    version, platform_name = compat.manifest_version(), compat.blender_platform()
    assert addon_zip.name == f"rigger-{version}-{platform_name}-py{PYTHON[0]}{PYTHON[1]}.zip"


def test_zip_holds_the_package_in_one_folder_with_its_compiled_modules(addon_zip):
    names = zipfile.ZipFile(addon_zip).namelist()
    assert all(name.startswith("rigger/") for name in names)  # the legacy installer rejects a top-level __init__.py
    compiled = sorted(name for name in names if name.endswith(compat.COMPILED_FILE_SUFFIXES))
    assert compiled == sorted(f"rigger/{module}{SUFFIX}" for module in compat.COMPILED_MODULES)
    source = ROOT / "addon"
    expected = {f"rigger/{path.relative_to(source).as_posix()}" for path in source.rglob("*.py")
                if "__pycache__" not in path.parts}
    assert {name for name in names if name.endswith(".py")} == expected
    assert "rigger/blender_manifest.toml" in names
    assert not [name for name in names if "__pycache__" in name or name.endswith((".pyc", ".pyx", ".c", ".h"))]


def test_zip_manifest_declares_its_platform_and_blender_range(addon_zip):
    manifest = tomllib.loads(zipfile.ZipFile(addon_zip).read("rigger/blender_manifest.toml").decode())
    blender = compat.BLENDER_FOR_PYTHON[PYTHON]
    assert manifest["id"] == "rigger"
    assert manifest["platforms"] == [compat.blender_platform()]
    assert manifest["blender_version_min"] == blender.minimum
    assert manifest.get("blender_version_max") == blender.maximum
    assert manifest["version"] == ".".join(map(str, rigger.bl_info["version"]))


def test_package_imports_itself_only_relatively(addon_zip):
    """Inside Blender the extension's package is ``bl_ext.user_default.rigger``: ``import rigger`` would fail."""
    archive = zipfile.ZipFile(addon_zip)
    absolute = []
    for name in archive.namelist():
        if not name.endswith(".py"):
            continue
        for node in ast.walk(ast.parse(archive.read(name), name)):
            modules = ([alias.name for alias in node.names] if isinstance(node, ast.Import) else
                       [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 else [])
            absolute += [f"{name}:{node.lineno}" for module in modules if module.split(".")[0] == "rigger"]
    assert absolute == []


def test_compiled_module_list_matches_setup_py():
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    built = {node.args[0].value.removeprefix("rigger.") for node in ast.walk(tree)
             if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Extension"}
    assert built == set(compat.COMPILED_MODULES)


def test_build_refuses_a_package_without_its_compiled_modules(tmp_path):
    source = tmp_path / "addon"
    shutil.copytree(ROOT / "addon", source, ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__"))
    result = build_zip(source, tmp_path / "dist")
    assert result.returncode != 0
    assert f"_rigger_cdt{SUFFIX}" in result.stderr and "make build" in result.stderr
    assert not (tmp_path / "dist").exists() or not list((tmp_path / "dist").iterdir())


# --- the compiled-module check, in this process -----------------------------------------------------------------------

def test_dev_package_has_no_compiled_problem():
    assert compat.compiled_problem() is None


def package_copy(tmp_path, change):
    """``compat`` of a copy of the add-on package (under another name) whose compiled modules ``change`` altered."""
    name = f"rigger_copy_{tmp_path.name.replace('-', '_')}"
    shutil.copytree(ROOT / "addon", tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    change(tmp_path / name)
    sys.path.insert(0, str(tmp_path))
    try:
        return importlib.import_module(f"{name}.compat")
    finally:
        sys.path.remove(str(tmp_path))


def zip_to_install():
    return compat.zip_name(compat.manifest_version(), compat.blender_platform(), PYTHON)


def test_problem_names_a_missing_compiled_module(tmp_path):
    copy = package_copy(tmp_path, lambda package: (package / f"_rigger_silhouette{SUFFIX}").unlink())
    problem = copy.compiled_problem()
    assert "_rigger_silhouette is missing" in problem and zip_to_install() in problem


def test_problem_names_the_python_a_module_was_built_for(tmp_path):
    def built_for_python_3_13(package):
        for module in compat.COMPILED_MODULES:
            (package / f"{module}{SUFFIX}").rename(package / f"{module}.cpython-313-x86_64-linux-gnu.so")

    problem = package_copy(tmp_path, built_for_python_3_13).compiled_problem()
    here = f"Python {PYTHON[0]}.{PYTHON[1]} on {compat.blender_platform()}"
    assert "built for Python 3.13 on x86_64-linux-gnu" in problem and here in problem
    assert zip_to_install() in problem and compat.BLENDER_FOR_PYTHON[PYTHON].label in problem


def test_problem_names_a_broken_compiled_module(tmp_path):
    copy = package_copy(tmp_path, lambda package: (package / f"_rigger_cdt{SUFFIX}").write_bytes(b"not a library"))
    problem = copy.compiled_problem()
    assert f"_rigger_cdt{SUFFIX} is installed but does not load" in problem and zip_to_install() in problem
    assert str(tmp_path) not in problem  # the add-on's own folder is left out of the reason


# --- installing into headless Blender ---------------------------------------------------------------------------------

def run_blender(version, scenario, zip_path, installer, tmp_path):
    """Run tests/addon_child.py in a fresh process of Blender ``version``; its findings and its stderr before the
    uninstall step (headless, Blender's legacy uninstaller prints a traceback of its own after removing)."""
    venv = BLENDER_VENVS[version]
    if not (venv / "bin" / "python").exists():
        pytest.skip(f"bpy {version} venv not found at {venv} (`make bpy42` makes it; `make test` does so first)")
    user_dir = tmp_path / "user"
    env = {"PATH": os.environ["PATH"], "HOME": str(user_dir), "LANG": "C.UTF-8",
           "BLENDER_USER_RESOURCES": str(user_dir / "blender"),
           "PYTHONPATH": str(venv / "lib" / f"python{PYTHON[0]}.{PYTHON[1]}" / "site-packages")}
    result = subprocess.run([str(venv / "bin" / "python"), "-s", "-S", str(CHILD), scenario, str(zip_path),
                             installer], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=CHILD_SECONDS)
    assert result.returncode == 0, f"{result.stdout}\n{result.stderr}"
    findings = json.loads(result.stdout.strip().splitlines()[-1])
    assert findings["blender"].startswith(version)
    assert not findings["dev_rigger_importable"]
    assert pathlib.Path(findings["installed_at"]).is_relative_to(user_dir)
    assert findings["enabled"]
    assert not findings["files_left"] and not findings["listed_after_uninstall"]
    return findings, result.stderr.split("--- uninstalling")[0]


@pytest.mark.parametrize("installer", ["extension", "legacy"])
@pytest.mark.parametrize("version", ["5.0", "4.2"])
def test_installed_zip_rigs_and_skins_a_character(addon_zip, version, installer, tmp_path):
    findings, stderr = run_blender(version, "use", addon_zip, installer, tmp_path)
    installed_at = pathlib.Path(findings["installed_at"])
    assert findings["module"] == ("rigger" if installer == "legacy" else "bl_ext.user_default.rigger")
    assert pathlib.Path(findings["operator_file"]).is_relative_to(installed_at)
    for run in ("first", "second"):  # before and after disabling and re-enabling
        outcome = findings[run]
        assert outcome["result"] == ["FINISHED"] and outcome["armatures"] == 1
        assert pathlib.Path(outcome["samples_file"]).is_relative_to(installed_at)
        assert outcome["bones"] >= 10
        assert outcome["weighted"] == outcome["vertices"]
        assert outcome["worst_follow"] < 1e-4
    assert findings["after_disable"] == {"enabled": False, "operators": []}
    assert findings["after_enable"] == {"enabled": True, "operators": ALL_OPERATORS}
    assert "Traceback" not in stderr


def zip_variant(addon_zip, path, change):
    """A copy of ``addon_zip`` at ``path`` whose members ``change(name, data)`` rewrites (None drops a member)."""
    with zipfile.ZipFile(addon_zip) as source, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as target:
        for info in source.infolist():
            data = change(info.filename, source.read(info))
            if data is not None:
                target.writestr(info, data)
    return path


@pytest.mark.parametrize("version, installer, fault", [("5.0", "extension", "broken"), ("4.2", "legacy", "missing")])
def test_zip_without_working_compiled_code_shows_the_problem_panel(addon_zip, version, installer, fault, tmp_path):
    module_file = f"rigger/_rigger_silhouette{SUFFIX}"
    if fault == "broken":
        variant = zip_variant(addon_zip, tmp_path / addon_zip.name,
                              lambda name, data: b"not a library" if name == module_file else data)
    else:
        variant = zip_variant(addon_zip, tmp_path / addon_zip.name,
                              lambda name, data: None if name == module_file else data)
    findings, stderr = run_blender(version, "problem", variant, installer, tmp_path)
    assert findings["operators"] == []
    problem = findings["problem"]
    assert ("does not load" if fault == "broken" else "is missing") in problem and zip_to_install() in problem
    lines = findings["panel_lines"]
    assert lines[0] == "Rigger cannot run" and "".join(lines[1:]).replace(" ", "") == problem.replace(" ", "")
    assert not findings["panel_after_disable"]
    assert "Traceback" not in stderr
