# `make test` and `make run` set everything up from a fresh clone: a virtual
# environment in .venv with dcsim installed (editable) and its test dependencies.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: lint test test-slow run docs clean

$(STAMP): pyproject.toml setup.cfg
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# `make lint` (ruff and mypy) runs first. One pytest-xdist worker per core; tests marked with one xdist_group share a worker
# (and the set-up they share). `.venv/bin/pytest` alone runs the suite in one process.
# dcsim's and the plugins' bytecode is compiled first: where PYTHONDONTWRITEBYTECODE is
# set, every process the suite starts (`dcsim` commands, Dask workers) would otherwise
# compile them again, about 1.3 s each. The tests marked `slow` (every shipped scenario
# with every planner and controller that can fly it, the FMU examples' exits in 40 fresh
# processes) are left out: `make test-slow`.
test: lint
	$(BIN)/python -m compileall -q dcsim plugins
	$(BIN)/python -m pytest -n auto --dist loadgroup -m "not slow"

test-slow: $(STAMP)
	$(BIN)/python -m compileall -q dcsim plugins
	$(BIN)/python -m pytest -n auto --dist loadgroup -m slow

run: $(STAMP)
	$(BIN)/dcsim run

# Types and style of dcsim/ and plugins/ (settings in pyproject.toml); tests/ is linted too.
# `make test` runs it first.
lint: $(STAMP)
	$(BIN)/ruff check dcsim plugins tests
	$(BIN)/ruff format --check dcsim plugins tests
	$(BIN)/mypy

# Regenerate the generated parts of docs/ (a test fails while they are stale).
docs: $(STAMP)
	$(BIN)/python -m dcsim.scenario.reference docs/scenarios.md
	$(BIN)/python -m dcsim.testing.reference docs/plugins.md
	$(BIN)/python -m dcsim.fmu.reference docs/fmu.md

clean:
	rm -rf $(VENV) build *.egg-info
