# Set-up, main job and tests of foldcore on a fresh Debian machine.
#   make demo    fold the built-in scenes, write FOLD + PNG + JSON to out/
#   make test    run the test suite
#   make bench   run the benchmarks (results in bench/results/)
# Both demo and test do all set-up first: system library for CHOLMOD (when
# root), a virtual environment in .venv, the package with its extras, and the
# default path's numba kernels compiled once (foldcore.warmup), so the first
# simulation starts warm.

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
OUT ?= out

.PHONY: setup demo test bench clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	@./.ci/system-deps
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	@if ./.ci/system-deps --check; then \
	    $(PY) -m pip install --quiet -e ".[cholmod,render,export,dev]"; \
	else \
	    echo "foldcore: SuiteSparse headers missing: installing without CHOLMOD (SciPy fallback)"; \
	    $(PY) -m pip install --quiet -e ".[render,export,dev]"; \
	fi
	$(PY) -m foldcore.warmup
	touch $(STAMP)

demo: setup
	$(PY) -m foldcore.demo --out $(OUT)

test: setup
	$(PY) -m pytest -q

bench: setup
	$(PY) bench/run.py

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .hypothesis
	find src tests -name __pycache__ -type d -exec rm -rf {} +
