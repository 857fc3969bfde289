# The two commands a new user needs (both do the whole set-up first, once):
#   make demo   the main job: the quick transfer benchmark (grid teachers -> MuJoCo students),
#               ending in a leaderboard, learning curves and a video in runs/quick
#   make test   the default test run (slow tests excluded; `make test-slow` runs them)
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.craftsuite-setup

.PHONY: setup demo test test-slow bench clean

$(STAMP): pyproject.toml constraints.txt scripts/setup.sh
	VENV=$(VENV) bash scripts/setup.sh
	touch $(STAMP)

setup: $(STAMP)

demo: $(STAMP)
	$(PY) -m craftsuite transfer --suite quick --out runs/quick

test: $(STAMP)
	$(PY) -m pytest -q --nbmake tests notebooks

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

bench: $(STAMP)
	$(PY) benchmarks/automata.py
	$(PY) benchmarks/grid_steps.py
	$(PY) benchmarks/cont_steps.py
	$(PY) benchmarks/student_throughput.py
	$(PY) benchmarks/interval_coverage.py

clean:
	rm -rf out .pytest_cache
