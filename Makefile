# Everything creates .venv and installs the pinned dependencies itself (Linux, Python 3.11).
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: test build demo bench clean

$(STAMP): requirements.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -r requirements.txt
	touch $(STAMP)

build: $(STAMP)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps -e .

test: build
	$(PY) -m pytest -q tests

bench: build
	$(PY) bench/cdt.py

clean:
	rm -rf build dist *.egg-info addon/*.so ext/cdt.c ext/silhouette_binding.c
