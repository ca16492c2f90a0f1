"""Build Rigger's compiled core into the add-on package.

The add-on lives in ``addon/`` and is imported as ``rigger``. Compiled modules get names unique to this project
(``rigger._rigger_*``) because Blender shares one site-packages between add-ons.
"""
import pathlib
import sys
import tomllib

from Cython.Build import cythonize
from setuptools import Extension, find_packages, setup

# One version for the package, the extension manifest and bl_info (tools/build_addon.py and tests/test_addon_zip.py
# check that the last two agree). Read here, not through rigger.compat.manifest_version: while setup.py runs, addon/
# is not importable as rigger (it only gets that name through package_dir).
MANIFEST = pathlib.Path(__file__).parent / "addon" / "blender_manifest.toml"
VERSION = tomllib.loads(MANIFEST.read_text(encoding="utf-8"))["version"]

# Exact geometric predicates need IEEE double arithmetic without fused multiply-add contraction or fast-math.
if sys.platform == "win32":
    COMPILE_ARGS = ["/O2", "/fp:precise"]
else:
    COMPILE_ARGS = ["-O2", "-ffp-contract=off", "-fno-fast-math", "-Wall", "-Wno-unused-function"]

EXTENSIONS = [
    Extension("rigger._rigger_cdt", ["ext/cdt.pyx"], include_dirs=["ext"], extra_compile_args=COMPILE_ARGS),
    Extension("rigger._rigger_silhouette", ["ext/silhouette_binding.pyx", "ext/silhouette.c"], include_dirs=["ext"],
              extra_compile_args=COMPILE_ARGS),
    Extension("rigger._rigger_weights", ["ext/skin_weights_binding.pyx", "ext/skin_weights.c"], include_dirs=["ext"],
              extra_compile_args=COMPILE_ARGS),
]

setup(
    name="rigger",
    version=VERSION,
    description="Automatic rigging for Blender: skeleton extraction, armature building and skinning",
    license="GPL-3.0-or-later",
    python_requires=">=3.11",
    package_dir={"rigger": "addon"},
    packages=["rigger"] + [f"rigger.{package}" for package in find_packages("addon")],  # method packages too
    extras_require={"ray": ["ray==2.60.0"]},  # batch --engine ray; requirements-ray.txt pins it with its dependencies
    ext_modules=cythonize(
        EXTENSIONS,
        language_level=3,
        compiler_directives={"boundscheck": False, "wraparound": False, "cdivision": True, "initializedcheck": False},
    ),
    zip_safe=False,
)
