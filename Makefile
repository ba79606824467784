# Two commands on a fresh machine: `make demo` runs the main job, `make test` runs the suite.
# Both create/refresh the virtual environment in .venv first.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
MAZE ?= data/mazes/split_doorway.maze

$(VENV)/.installed: pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q torch==2.13.0  # the local CPU wheel; an unpinned torch would pull CUDA
	$(BIN)/pip install -q -e '.[dev]'
	touch $@

venv: $(VENV)/.installed

demo: $(VENV)/.installed
	$(BIN)/specrefine refine $(MAZE) --agent point --method ours --proposer geometric --seed 0 --out runs/demo

test: $(VENV)/.installed
	$(BIN)/ruff check specrefine tests benchmarks
	$(BIN)/python -m pytest -q

.PHONY: venv demo test
