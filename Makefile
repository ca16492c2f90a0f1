# Everything creates .venv and installs the pinned dependencies itself (Linux, Python 3.11).
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
# Blender 4.2 LTS as a module in its own venv (inside .venv, which git ignores), for the add-on install test;
# pip takes the wheel from its cache when it has it.
BPY42_VENV := $(VENV)/bpy42
BPY42_STAMP := $(BPY42_VENV)/.installed
# Ray, the optional engine of `batch --engine ray`, into .venv for its tests and benchmark (not the default install).
RAY_STAMP := $(VENV)/.ray-installed

.PHONY: test build demo addon bpy42 ray bench bench-quality bench-silhouette bench-skinning bench-posing \
	bench-bodyplan bench-frames bench-robustness bench-retarget bench-rigify bench-rig-time bench-batch regress \
	regress-baseline defects clean

$(STAMP): requirements.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet pip==26.3  # older pips cannot install a package_dir-mapped project editable
	$(PY) -m pip install --quiet -r requirements.txt
	touch $(STAMP)

$(BPY42_STAMP): requirements-bpy42.txt
	$(PYTHON) -m venv $(BPY42_VENV)
	$(BPY42_VENV)/bin/python -m pip install --quiet -r requirements-bpy42.txt
	touch $(BPY42_STAMP)

$(RAY_STAMP): $(STAMP) requirements-ray.txt
	$(PY) -m pip install --quiet -r requirements-ray.txt
	touch $(RAY_STAMP)

build: $(STAMP)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps -e .

bpy42: $(BPY42_STAMP)

ray: $(RAY_STAMP)

test: build bpy42 ray
	$(PY) -m pytest -q tests

demo: build
	$(PY) tools/demo.py

# The offline-installable add-on zip for this platform and Python: dist/rigger-<version>-<platform>-py<XY>.zip.
addon: build
	$(PY) tools/build_addon.py --output-dir dist

bench: build
	$(PY) bench/cdt.py

bench-quality: build
	$(PY) -m pip install --quiet -r bench/requirements.txt
	$(PY) bench/quality.py

bench-silhouette: build
	$(PY) bench/silhouette.py

# Skinning over ../shared/models/gt with the artists' skeletons and Rigger's: bench/results/skinning.md and .png.
bench-skinning: build
	$(PY) bench/skinning.py

# Posing over ../shared/models/gt: random artist poses reproduced by each rig; bench/results/posing.{md,png,json}.
bench-posing: build
	$(PY) bench/posing.py

# Body plan of every ../shared model against a hand label, named-joint error of the humanoids: bodyplan.{md,png,json}.
bench-bodyplan: build
	$(PY) bench/bodyplan.py

# Every ../shared/models/gt model rigged read in six frames (its own, four turned, Blender's import): frames.{md,png,json}.
bench-frames: build
	$(PY) bench/frames.py

# Every ../shared model rigged clean and with noise too small to see: robustness.{md,png,json}.
bench-robustness: build
	$(PY) bench/robustness.py

# The CMU walk and jump (../shared/anim) on game rigs of the humanoids: feet, knees, elbows, weights, seams.
bench-retarget: build
	$(PY) bench/retarget.py

# The rigify target on every ../shared model and sample character: generated, skinned, IK bends, regenerated:
# bench/results/rigify.{md,png,json} and rigify_pose.png.
bench-rigify: build
	$(PY) bench/rigify_target.py

bench-rig-time: build
	$(PY) bench/rig_time.py

# Skeletons and stages of every ../shared model and sample character under several settings, bit for bit:
# regress-baseline fingerprints them (on the commit to compare against), regress compares with that baseline.
regress: build
	$(PY) tools/regress.py

regress-baseline: build
	$(PY) tools/regress.py --baseline

# Issue 28's defect characters rigged, measured against their true skeletons and drawn: out/defects/.
defects: build
	$(PY) tools/defects.py

# Batch throughput, local engine against Ray, on generated characters: bench/results/batch.md and .png.
bench-batch: build ray
	$(PY) bench/batch.py

clean:
	rm -rf build dist out *.egg-info addon/*.so ext/cdt.c ext/silhouette_binding.c ext/skin_weights_binding.c
