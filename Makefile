# physcam: two entry points for a fresh machine.
#   make demo   create .venv if missing, install physcam, run the main job
#   make test   create .venv if missing, install physcam with test tools, run every test
#   make schema regenerate the USD schema plugin; make bench runs the benchmarks
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.physcam-installed

.PHONY: demo test venv bench clean schema

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): $(PY) pyproject.toml
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/physcam demo --out demo-output --force

test: $(STAMP)
	$(PY) -m pytest -n 2 -q

bench: $(STAMP)
	$(PY) benchmarks/startup.py
	$(PY) benchmarks/trace.py

# Regenerate the USD schema plugin (plugInfo.json, generatedSchema.usda) from
# src/physcam/usd/schema/schema.usda with usd-core's own usdGenSchema.
schema: $(STAMP)
	$(PY) scripts/gen_usd_schema.py

clean:
	rm -rf $(VENV) demo-output build *.egg-info src/*.egg-info
