# Everything creates .venv and installs the pinned dependencies itself (Linux, Python 3.11).
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: test build demo bench bench-quality bench-silhouette clean

$(STAMP): requirements.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet pip==26.3  # older pips cannot install a package_dir-mapped project editable
	$(PY) -m pip install --quiet -r requirements.txt
	touch $(STAMP)

build: $(STAMP)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps -e .

test: build
	$(PY) -m pytest -q tests

demo: build
	$(PY) tools/demo.py

bench: build
	$(PY) bench/cdt.py

bench-quality: build
	$(PY) -m pip install --quiet -r bench/requirements.txt
	$(PY) bench/quality.py

bench-silhouette: build
	$(PY) bench/silhouette.py

clean:
	rm -rf build dist out *.egg-info addon/*.so ext/cdt.c ext/silhouette_binding.c
