# Set-up, main job and tests of foldcore on a fresh Debian machine.
#   make demo    fold the built-in scenes, write FOLD + PNG + JSON to out/
#   make test    run the test suite
#   make bench   run the benchmarks (results in bench/results/; the full set
#                takes long: QUICK=1 runs small sizes and few runs, results in a
#                temp folder; what each measures: docs/benchmarks.md)
# Both demo and test do all set-up first: system library for CHOLMOD (when
# root), a virtual environment in .venv, the package with its extras, and the
# default path's numba kernels compiled once (foldcore.warmup), so the first
# simulation starts warm. test also installs Debian's Chromium (when root), in
# which the tests load `foldcore view` pages.

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
OUT ?= out

.PHONY: setup demo test bench clean vendor-three

setup: $(STAMP)

$(STAMP): pyproject.toml
	@./.ci/system-deps
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	@if ./.ci/system-deps --check; then \
	    $(PY) -m pip install --quiet -e ".[cholmod,render,export,contact,study,dev]"; \
	else \
	    echo "foldcore: SuiteSparse headers missing: installing without CHOLMOD (SciPy fallback)"; \
	    $(PY) -m pip install --quiet -e ".[render,export,contact,study,dev]"; \
	fi
	$(PY) -m foldcore.warmup
	touch $(STAMP)

demo: setup
	$(PY) -m foldcore.demo --out $(OUT)

test: setup
	@./.ci/system-deps --browser
	$(PY) -m pytest -q

bench: setup
	$(PY) bench/run.py $(if $(QUICK),--quick)

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .hypothesis
	find src tests -name __pycache__ -type d -exec rm -rf {} +

# Refresh the vendored three.js of `foldcore view` from npm (not part of set-up:
# the files are committed; see src/foldcore/viewer_assets/README.md).
THREE_VERSION := 0.170.0
THREE_SHA256 := 4a608a355dcaba72e0e5383cdc814303f5b6060b43c238cdf6932dceb699238d
vendor-three:
	cd /tmp && npm pack three@$(THREE_VERSION) >/dev/null
	echo "$(THREE_SHA256)  /tmp/three-$(THREE_VERSION).tgz" | sha256sum -c -
	tar xzf /tmp/three-$(THREE_VERSION).tgz -C /tmp package/build/three.module.min.js \
	    package/examples/jsm/controls/OrbitControls.js package/LICENSE
	cp /tmp/package/build/three.module.min.js /tmp/package/examples/jsm/controls/OrbitControls.js \
	    src/foldcore/viewer_assets/
	cp /tmp/package/LICENSE src/foldcore/viewer_assets/THREE-LICENSE
