# The two commands a new user needs (both do the whole set-up first, once):
#   make demo   the main job: the quick transfer benchmark (grid teachers -> MuJoCo students),
#               ending in a leaderboard, learning curves and a video in runs/quick
#   make test   the linter (ruff), then the default test run over TEST_WORKERS processes (slow tests excluded;
#               `make test-slow` runs them)
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.craftsuite-setup
# the default test run's processes (pytest-xdist): one per core of the 2-core machines it is sized for
TEST_WORKERS ?= 2

.PHONY: setup demo test test-slow bench docs clean

$(STAMP): pyproject.toml constraints.txt scripts/setup.sh
	VENV=$(VENV) bash scripts/setup.sh
	touch $(STAMP)

setup: $(STAMP)

demo: $(STAMP)
	$(PY) -m craftsuite transfer --suite quick --out runs/quick

test: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m pytest -q -n $(TEST_WORKERS) --nbmake tests notebooks

# the slow tests alone (spawned transfers, Ray, kills, the wheel, the transfer notebook);
# this -m replaces the default run's -m 'not slow' (pyproject.toml's addopts)
test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow --nbmake tests notebooks

# The pages generated from data: the tasks page from the specs and the results archive (its
# scripted and random references cached, played again only when the package, a spec or a
# simulating library changed: craftsuite.references),
# the record format's page from its table (craftsuite.record_format),
# the results and reproduction pages from the archive (results/)
docs: $(STAMP)
	$(PY) -m craftsuite tasks --markdown docs/tasks.md
	$(PY) -m craftsuite records --markdown docs/records.md
	$(PY) -m craftsuite leaderboard results/standard results/hard --page docs/results.md
	$(PY) -m craftsuite leaderboard results/paper --reproduction docs/reproduction.md

# Each benchmark prints its figures beside their targets and rewrites its own section of
# docs/performance.md (about 30 minutes on 2 cores; run it on an idle machine)
bench: $(STAMP)
	$(PY) benchmarks/automata.py --flloat-timeout 30
	$(PY) benchmarks/grid_steps.py --steps 100000
	$(PY) benchmarks/cont_steps.py --steps 20000
	$(PY) benchmarks/vector_envs.py
	$(PY) benchmarks/student_throughput.py
	$(PY) benchmarks/crm_memory.py
	$(PY) benchmarks/checkpoint_memory.py
	$(PY) benchmarks/engine_equivalence.py
	$(PY) benchmarks/teachers.py --quick
	$(PY) benchmarks/interval_coverage.py
	$(PY) benchmarks/verdict_error.py
	$(PY) benchmarks/results_page.py
	$(PY) benchmarks/code_size.py

clean:
	rm -rf out .pytest_cache
