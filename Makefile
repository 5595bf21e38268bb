# physcam: two entry points for a fresh machine.
#   make demo   create .venv if missing, install physcam, run the main job
#   make shell  open your shell with .venv/bin first on PATH, so `physcam` runs (exit to leave)
#   make test   create .venv if missing, install physcam with test tools, run every test
#   make schema regenerate the USD schema plugin; make bench runs the benchmarks
#   make test-latest  the suite's core against the newest versions pyproject.toml's ranges allow
#   make usd-min      the USD tests against the oldest usd-core pyproject.toml allows (make test runs it)
#   make wheel  build the wheel and sdist into dist/ (what `pip install physcam` installs)
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.physcam-installed
# Blender as a Python module (bpy) pins numpy < 2, while the test tools (OpenCV) need numpy 2:
# Blender gets its own environment, with physcam installed in it; tests drive it in subprocesses.
BLENDER_VENV  ?= .venv-blender
BLENDER_PY    := $(BLENDER_VENV)/bin/python
BLENDER_STAMP := $(BLENDER_VENV)/.physcam-installed
BPY_VERSION   ?= 5.0.1

.PHONY: bytecode test-bytecode jit editables demo test venv blender blender-extension bench clean schema chromium shell test-latest latest-venv latest-editable latest-run wheel usd-min lint

# Installs go through uv (https://docs.astral.sh/uv/, installed into .venv by pip first): it resolves
# the same versions as pip (constraints.txt) and installs them 2-3x faster, which the 15-minute CI
# budget needs (docs/performance.md, "make test"). A user's own `pip install physcam` is unaffected.
# --compile-bytecode, as pip does: under PYTHONDONTWRITEBYTECODE (CI sets it) every test's subprocess
# would otherwise compile numpy, matplotlib and physcam's dependencies from source again (+185 s).
# The environment is made without ensurepip's own pip install (7 s of the installs' critical path): the base
# Python's pip puts uv in (pip >= 22.3's --python), and uv adds pip with the dependencies (DEPS), so .venv
# still has its pip; where the base Python has no pip, ensurepip does as before.
UV := $(VENV)/bin/uv
$(PY):
	$(PYTHON) -m venv --without-pip $(VENV)
	$(PYTHON) -m pip --python $(PY) install --quiet --disable-pip-version-check -c constraints.txt uv 2>/dev/null \
	  || { $(PY) -m ensurepip >/dev/null && $(PY) -m pip install --quiet --disable-pip-version-check -c constraints.txt uv; }

# What scripts/compile_jit.py needs (numpy, numba; constraints.txt's versions) goes into .venv first, so the
# JIT compile (the installs' longest step, ~52 s of one core) starts while the rest of .venv installs.
JIT_DEPS := $(VENV)/.jit-deps
$(JIT_DEPS): $(PY) constraints.txt
	$(UV) pip install --quiet --compile-bytecode --python $(PY) -c constraints.txt numpy numba
	touch $(JIT_DEPS)

# The test environment gets the exact versions of constraints.txt (reproducible CI); the library's own
# dependencies are ranges (pyproject.toml), so a studio can install physcam into its environment.
# An environment's dependencies go in first, read from pyproject.toml (uv: no build of the source tree, so
# they install beside the other environments'), then physcam itself, editable and --no-deps (a few seconds):
# two editable builds of one source tree must not run at once, and only these short steps take turns.
DEPS := $(VENV)/.deps-installed
$(DEPS): $(JIT_DEPS) pyproject.toml constraints.txt
	$(UV) pip install --quiet --compile-bytecode --python $(PY) -c constraints.txt -r pyproject.toml --extra test pip
	touch $(DEPS)

# the editable install builds the C tracing kernel into src/ (setup.py): a change to its source rebuilds it
$(STAMP): $(DEPS) setup.py src/physcam/trace/kernels/_ckernel.c src/physcam/trace/kernels/_rimpass.c
	$(UV) pip install --quiet --compile-bytecode --python $(PY) --no-deps -e .
	touch $(STAMP)

venv: $(STAMP)

# demo-output is make demo's own folder: one written by a physcam from before folders carried a
# manifest (physcam-manifest.json) is removed first, since --force replaces only a folder physcam wrote whole
demo: $(STAMP)
	@if [ -d demo-output ] && [ ! -f demo-output/physcam-manifest.json ]; then rm -rf demo-output; fi
	$(VENV)/bin/physcam demo --out demo-output --force
	@echo "physcam is installed in $(VENV): run it as $(VENV)/bin/physcam, or type 'make shell' for a shell where 'physcam' works"

# A shell where `physcam` is on PATH (the virtual environment's bin first), for trying the README's
# examples; `exit` returns. The same as `. .venv/bin/activate` in your own shell.
shell: $(STAMP)
	@echo "physcam $(abspath $(VENV)): type 'physcam --help'; 'exit' to leave"
	@VIRTUAL_ENV="$(abspath $(VENV))" PATH="$(abspath $(VENV))/bin:$$PATH" $${SHELL:-/bin/sh}

# Where bpy cannot be installed (another Python, another platform) the Blender tests skip and
# pytest's summary says why; the rest of the suite runs. bpy (a 300 MB download) is fetched on its
# own (BLENDER_BPY), so `make test` can fetch it while .venv installs; then physcam's dependencies (the
# `fast` extra; bpy's numpy stays) beside .venv's, and physcam's editable install after .venv's. uv
# installs into it: it is made without pip.
BLENDER_BPY := $(BLENDER_VENV)/.bpy-installed
BLENDER_DEPS := $(BLENDER_VENV)/.deps-installed
$(BLENDER_BPY): | $(PY)
	@( $(PYTHON) -m venv --without-pip $(BLENDER_VENV) \
	  && $(UV) pip install --quiet --compile-bytecode --python $(BLENDER_PY) "bpy==$(BPY_VERSION)" \
	  && touch $(BLENDER_BPY) ) \
	|| ( echo "physcam: Blender (bpy==$(BPY_VERSION)) could not be installed here; the Blender tests will be skipped" >&2; \
	     rm -rf $(BLENDER_VENV) )

$(BLENDER_DEPS): pyproject.toml | $(BLENDER_BPY) $(PY)
	@if [ -f $(BLENDER_BPY) ]; then \
	  $(UV) pip install --quiet --compile-bytecode --python $(BLENDER_PY) -r pyproject.toml --extra fast && touch $(BLENDER_DEPS) \
	  || { echo "physcam: physcam's dependencies could not be installed beside Blender; the Blender tests will be skipped" >&2; \
	       rm -rf $(BLENDER_VENV); }; fi

$(BLENDER_STAMP): pyproject.toml $(STAMP) | $(BLENDER_DEPS)
	@if [ -f $(BLENDER_DEPS) ]; then \
	  $(UV) pip install --quiet --compile-bytecode --python $(BLENDER_PY) --no-deps -e . && touch $(BLENDER_STAMP) \
	  || { echo "physcam: physcam could not be installed beside Blender; the Blender tests will be skipped" >&2; \
	       rm -rf $(BLENDER_VENV); }; fi

# the physcam Blender extension zip (docs/blender.md)
blender-extension: $(STAMP)
	$(VENV)/bin/physcam export blender-extension -o dist --force

blender: $(BLENDER_STAMP)

# The `physcam serve` page tests drive Debian's chromium (tests/serve/test_serve_browser.py). CI runs
# as root on a fresh Debian machine: install it there when missing, at the version tested, or at the
# current one when Debian's security archive has moved on. Not root or no apt-get: nothing is
# installed and the browser tests skip, saying why.
CHROMIUM_VERSION ?= 156.0.8078.79-1~deb12u1
chromium:
	@if ! command -v chromium >/dev/null 2>&1 && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  ( apt-get update -qq \
	    && { DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium=$(CHROMIUM_VERSION) \
	         || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } ) >/dev/null \
	  || echo "physcam: chromium could not be installed; the browser tests will be skipped" >&2; \
	fi

# The installs are mostly downloads and unpacking: they run side by side (the three environments'
# dependencies, bpy, chromium, the JIT compile), then the suite.
# (Three xdist workers on the two cores were slower: 792 s against 742 s, the Blender tests queued last.)
# The oldest USD's and the newest versions' tests run beside the suite, niced, their output after the
# suite's: no 45 s tail after it. The suite is CPU-bound most of the time, so they mostly take their CPU
# from it (its servers, browsers and subprocesses leave a core idle about a tenth of its time);
# docs/performance.md, round 14.
SIDE_LOG := .test-side.log
test:
	$(MAKE) --no-print-directory -j6 $(STAMP) $(BLENDER_BPY) $(BLENDER_DEPS) latest-venv chromium editables jit test-bytecode lint bytecode
	@rm -f $(SIDE_LOG); ( nice -n 10 $(MAKE) --no-print-directory -j2 usd-min latest-run > $(SIDE_LOG) 2>&1; \
	  echo "side-rc=$$?" >> $(SIDE_LOG) ) & \
	PHYSCAM_BLENDER_PYTHON=$(abspath $(BLENDER_PY)) $(PY) -m pytest -n 2 --dist worksteal -q; rc=$$?; \
	wait; cat $(SIDE_LOG); grep -q '^side-rc=0$$' $(SIDE_LOG) && exit $$rc; exit 1

# the editable installs one after the other (two builds of one source tree must not run at once): the
# newest versions' environment, then physcam beside Blender; a few seconds each (--no-deps)
editables: | $(STAMP) $(BLENDER_DEPS) latest-venv
	$(MAKE) --no-print-directory latest-editable
	$(MAKE) --no-print-directory $(BLENDER_STAMP)

# The oldest usd-core physcam supports, the `usd` extra's lower bound in pyproject.toml (the two must
# agree: tests/usd/test_usd_minimum.py). Older ones fail: 24.8 to 25.2 lack UsdGeomCamera's exposure
# attributes (CreateExposureTimeAttr), and 25.5 and 25.5.1 cannot load usd-core's validators (the
# usdShade/usdGeom/usdUtils validator libraries are missing from those wheels). Only that wheel is installed, into its own folder put first on
# PYTHONPATH (the test environment is otherwise unchanged), and tests/usd runs against it: about 10 s
# plus the first download. The schema-regeneration test is left out: usd-core 25.8's wheel cannot
# run its own usdGenSchema (the checked-in plugin is regenerated with the pinned usd-core, make schema).
USD_MIN     ?= 25.8
USD_MIN_DIR ?= $(VENV)/usd-min-$(USD_MIN)
usd-min: $(STAMP)
	@test -f $(USD_MIN_DIR)/.installed || ( rm -rf $(USD_MIN_DIR) \
	  && $(UV) pip install --quiet --compile-bytecode --python $(PY) --no-deps --target $(USD_MIN_DIR) "usd-core==$(USD_MIN)" \
	  && touch $(USD_MIN_DIR)/.installed )
	PYTHONPATH="$(abspath $(USD_MIN_DIR)):$(abspath src)" PHYSCAM_USD_MIN=$(USD_MIN) \
	  PHYSCAM_USD_MIN_DIR="$(abspath $(USD_MIN_DIR))" $(PY) -m pytest -q -p no:cacheprovider tests/usd \
	  --deselect tests/usd/test_schema.py::test_generated_plugin_is_current

# The newest versions the ranges allow, not constraints.txt: a fresh environment each run (uv's
# cache makes it quick), the tests of what leans on the dependencies (optics and tracing on numpy and
# numba, USD, OpenTrackIO's schema and CBOR, finufft, OpenJD) that need no Blender, browser or renderer.
# The on-set report and the lens readers (no numpy on their paths but lens comparison's and the pupil
# plot's) are left to `make test`: the CI's 15-minute budget.
# `make test` makes it (latest-venv, then latest-editable) beside its other installs and runs it
# (latest-run) beside the suite.
LATEST_VENV ?= .venv-latest
LATEST_PY   := $(LATEST_VENV)/bin/python
test-latest:
	$(MAKE) --no-print-directory latest-venv
	$(MAKE) --no-print-directory latest-editable
	$(MAKE) --no-print-directory latest-run

# The dependencies, newest versions, read from pyproject.toml: nothing is built from the source tree, so
# this runs beside the other installs, after numba is in .venv, so that the JIT compile (the installs'
# longest step) starts first (not niced: the suite waits for its editable step). uv installs into it, so
# it is made without pip (ensurepip's own install of pip: 3-4 s of CPU).
latest-venv: | $(JIT_DEPS)
	rm -rf $(LATEST_VENV)
	$(PYTHON) -m venv --without-pip $(LATEST_VENV)
	$(UV) pip install --quiet --compile-bytecode --python $(LATEST_PY) --upgrade -r pyproject.toml --extra all \
	  pytest pytest-xdist hypothesis opencv-python-headless

# physcam itself into it, after .venv's (two editable builds of one source tree must not run at once)
latest-editable: | $(STAMP)
	$(UV) pip install --quiet --compile-bytecode --python $(LATEST_PY) --no-deps -e .

# The tree's JIT cache (trace/kernels/__pycache__) is shared with .venv's suite, which runs beside this:
# under another numba version each would find the other's cache index stale and rewrite it, recompiling
# the kernels by turns, so a numba other than .venv's gets a cache folder of its own.
NUMBA_VERSION := import importlib.metadata as m; print(m.version("numba"))
latest-run:
	@$(LATEST_PY) scripts/compile_tests.py tests
	@$(UV) pip list --python $(LATEST_PY) --format=freeze 2>/dev/null \
	  | grep -i -E '^(numpy|numba|matplotlib|usd-core|openexr|jsonschema|cbor2|dask|pyarrow|starlette|uvicorn|openjd-model|opencue.pyoutline)=' \
	  | tr '\n' ' ' | sed 's/^/physcam: newest versions tested: /'; echo
	@cache=; if [ "$$($(LATEST_PY) -c '$(NUMBA_VERSION)')" != "$$($(PY) -c '$(NUMBA_VERSION)')" ]; then \
	  cache="$(abspath $(LATEST_VENV))/numba-cache"; echo "physcam: the newest numba is not .venv's: its JIT cache is $$cache"; fi; \
	  env $${cache:+NUMBA_CACHE_DIR=$$cache} \
	$(LATEST_PY) -m pytest -n 2 -q -m "not slow" -p no:cacheprovider tests/optics \
	  tests/usd tests/live tests/trace/test_tracer.py tests/analysis/image_quality/test_image_quality_closed_forms.py \
	  tests/farm/test_farm_jobs.py $(LATEST_LEFT_OUT)

# Left to `make test` (the constraints' versions), for the CI's budget: they grew to half of this run's
# CPU (2026-11-29: 260 of 480 s) while leaning on the dependencies less than the rest: the formulas'
# NaN and inf properties (pure Python and numpy's ufuncs), the catalogue glasses (stored fits, no
# fitting), the live parser's hostile input (physcam's own limits), the usd commands' CLI (the same
# USD calls as tests/usd's authoring and kit tests).
LATEST_LEFT_OUT := --ignore=tests/optics/test_no_nan_formulas.py --ignore=tests/optics/test_glass.py \
	  --ignore=tests/live/test_attacks.py --ignore=tests/usd/test_cli_usd.py

# physcam's own bytecode, written once before the suite: the editable install leaves src/ uncompiled and
# CI sets PYTHONDONTWRITEBYTECODE, so every subprocess of the suite (the CLI, Blender, the fork servers)
# compiled the physcam modules it imports again (tests/trace/test_cold_start.py, test_zoom_analyses.py
# and test_lens_zoom.py: 23.2 -> 21.7 s CPU). 1 s; Python still checks each file's time stamp.
bytecode: $(STAMP)
	$(PY) -m compileall -q -j0 src >/dev/null

# the tests' bytecode, with pytest's assertion rewriting, written once before the suite: under
# PYTHONDONTWRITEBYTECODE each xdist worker rewrote and compiled every test module again (14 s CPU of a
# worker's 24 s collection), and every pytest process its plugins' modules (3 s; scripts/compile_tests.py)
test-bytecode: $(STAMP)
	$(PY) scripts/compile_tests.py tests

# physcam's JIT ray-tracing kernels compiled into numba's disk cache before the suite, beside the other
# installs (scripts/compile_jit.py says why: a fresh clone's processes each compiled them side by side),
# from the source tree as soon as numba is in .venv (JIT_DEPS), while the rest of .venv installs
jit: $(JIT_DEPS)
	PYTHONPATH="$(abspath src)" $(PY) scripts/compile_jit.py

# ruff (pyproject.toml [tool.ruff]): unused imports and variables, undefined names, pycodestyle errors
lint: $(STAMP)
	$(VENV)/bin/ruff check src tests scripts benchmarks

wheel: $(STAMP)
	$(PY) -m build --outdir dist .

bench: $(STAMP)
	$(PY) benchmarks/startup.py
	$(PY) benchmarks/trace.py
	$(PY) benchmarks/serve.py

# Regenerate the USD schema plugin (plugInfo.json, generatedSchema.usda) from
# src/physcam/usd/schema/schema.usda with usd-core's own usdGenSchema.
schema: $(STAMP)
	$(PY) scripts/gen_usd_schema.py

clean:
	rm -rf $(VENV) $(BLENDER_VENV) $(LATEST_VENV) demo-output build dist *.egg-info src/*.egg-info $(SIDE_LOG)
