# The README's two commands are `make sweep` and `make test`; every target builds .venv first.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
WORKERS ?= 2

# Byte-code goes to the virtual environment's own folder, whatever PYTHONDONTWRITEBYTECODE says:
# with it set, every process compiled scipy, pandas and the tests anew (a fresh clone's
# `make test` took 218 s of pytest instead of 150 s), and nothing lands in the checkout.
export PYTHONDONTWRITEBYTECODE :=
export PYTHONPYCACHEPREFIX := $(if $(filter /%,$(VENV)),$(VENV),$(CURDIR)/$(VENV))/pycache

.PHONY: all venv test year learn benchmark sweep sweep-mintime whatif stress sensor reliability figures animation bench lint clean optimize sensitivity kn-check layout

all: test

# uv installs what pip would (the same releases: constraints.txt pins every library to the one
# the committed reports were made with) in half the time: 34 s against 70 s on a machine with no
# download cache. Like pip with --no-compile, it leaves byte-code to the first import.
# Where uv cannot be had or cannot reach the index, pip installs the same pins.
INSTALL := $(VENV)/bin/uv pip install -q --python $(PY) -c constraints.txt
PIP_INSTALL := $(PY) -m pip install -qq --no-compile -c constraints.txt
$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	($(PY) -m pip install -qq uv==0.13.9 && $(INSTALL) -e ".[dev,dist]") || \
		$(PIP_INSTALL) -e ".[dev,dist]"
	@touch $(STAMP)

venv: $(STAMP)

# Two pytest-xdist workers (TEST_WORKERS=0 runs in one process); the hostile suite's counts
# are summed over the workers (tests/conftest.py).
TEST_WORKERS ?= 2

test: $(STAMP)
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadgroup

# Each sweep target starts from an empty build folder: a sweep refuses to replace results
# without --resume, and a report regenerated here must come from this code, not reused tasks.
sweep: $(STAMP)
	rm -rf build/sweep
	$(PY) -m cell sweep scenarios/table_7_1.yaml --out build/sweep --workers $(WORKERS) --report reports/table_7_1

sweep-mintime: $(STAMP)
	rm -rf build/sweep_mintime
	$(PY) -m cell sweep scenarios/table_7_1_mintime.yaml --out build/sweep_mintime --workers $(WORKERS) --report reports/table_7_1_mintime

whatif: $(STAMP)
	rm -rf build/whatif
	MPLBACKEND=Agg $(PY) -m cell sweep scenarios/whatif.yaml --out build/whatif --workers $(WORKERS) --report reports/whatif

stress: $(STAMP)
	rm -rf build/stress
	$(PY) -m cell sweep scenarios/stress.yaml --out build/stress --workers $(WORKERS)
	MPLBACKEND=Agg $(PY) -m cell.reporting.maps.stress build/stress/replications.csv reports/stress

# Buffer against brains (issue 32): a buffer, the adaptive controller and a second robot.
layout: $(STAMP)
	rm -rf build/layout
	$(PY) -m cell sweep scenarios/layout_study.yaml --out build/layout --workers $(WORKERS)
	MPLBACKEND=Agg $(PY) -m cell.reporting.maps.layout_study build/layout/replications.csv reports/layout scenarios/layout_study.yaml

sensor: $(STAMP)
	rm -rf build/sensor
	$(PY) -m cell sweep scenarios/sensor.yaml --out build/sensor --workers $(WORKERS)
	MPLBACKEND=Agg $(PY) -m cell.reporting.maps.sensor_map build/sensor/replications.csv reports/sensor scenarios/sensor.yaml

# The reliability study (issue 21): both policies with motor wear, a year of two shifts a run.
reliability: $(STAMP)
	rm -rf build/reliability
	MPLBACKEND=Agg $(PY) -m cell.reporting.maps.reliability scenarios/reliability.yaml build/reliability reports/reliability

figures: $(STAMP)
	MPLBACKEND=Agg $(PY) -m cell figures --out reports/figures
	$(PY) -m cell.reporting.planner_report

animation: $(STAMP)
	$(PY) -m cell.reporting.animation reports/animation/both.gif

# KN's probability of correct selection on count measures, over 2,000 problems a row (issue 35).
kn-check: $(STAMP)
	$(PY) -m cell.reporting.kn_report reports/kn

bench: $(STAMP)
	$(PY) -m cell bench --out reports/bench.json

# The worked example of README (cell optimize) and the assumptions' sensitivity (cell sensitivity).
optimize: $(STAMP)
	rm -rf build/optimize
	MPLBACKEND=Agg $(PY) -m cell optimize scenarios/optimize.yaml --out build/optimize
	rm -rf reports/optimize && mkdir -p reports/optimize
	cp build/optimize/*.csv build/optimize/*.png build/optimize/report.md reports/optimize/

sensitivity: $(STAMP)
	MPLBACKEND=Agg $(PY) -m cell sensitivity scenarios/assumptions.yaml --out reports/sensitivity --workers $(WORKERS)

lint: $(STAMP)
	$(PY) -m ruff check cell tests
	$(PY) -m mypy
	$(VENV)/bin/lint-imports

clean:
	rm -rf $(VENV) build .pytest_cache .hypothesis

# The worked year on a shift calendar (issue 33): both policies, a repair crew on both shifts
# against the first shift only, three years each (about 14 minutes on 2 cores shared with other work).
year: $(STAMP)
	MPLBACKEND=Agg $(PY) -m cell.reporting.year scenarios/year.yaml reports/year --workers $(WORKERS)

# The learned controller's network retrained (issue 36 item 3): CMA-ES, the optional extra [rl],
# seeded, about 6 minutes on one core of this 2-core machine; writes cell/rl/weights/learned.json.
learn: $(STAMP)
	$(INSTALL) -e ".[rl]" || $(PIP_INSTALL) -e ".[rl]"
	$(PY) -m cell.rl.train

# The benchmark (issue 36 item 4): every controller's parts against the hindsight optimum.
benchmark: $(STAMP)
	MPLBACKEND=Agg $(PY) -m cell.reporting.benchmark reports/benchmark
