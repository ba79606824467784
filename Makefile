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
	$(BIN)/pip install -q -e '.[dev,notebooks,vlm,ray]'  # the suite exercises every extra
	touch $@

# the kernel the notebooks name ("specrefine"), registered inside the venv for papermill and JupyterLab
KERNEL_SPEC := $(VENV)/share/jupyter/kernels/specrefine/kernel.json
$(KERNEL_SPEC): $(VENV)/.installed
	$(BIN)/python -m ipykernel install --sys-prefix --name specrefine --display-name "Python 3 (specrefine)"

venv: $(VENV)/.installed $(KERNEL_SPEC)

demo: $(VENV)/.installed
	$(BIN)/specrefine refine $(MAZE) --agent point --method ours --proposer geometric --seed 0 --out runs/demo

test: $(VENV)/.installed
	$(BIN)/ruff check specrefine tests scripts
	$(BIN)/python -m pytest -q

# Notebooks: the full-parameter tier (notebooks/full.json, minutes per notebook) and its expected values,
# regenerating expected values (a decision, not a fix: tests/test_notebooks.py), executed copies for readers,
# and JupyterLab on the notebooks with this project's kernel.
notebooks-full: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m notebooks_full

notebook-expected: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m notebooks -k values_smoke --update-notebook-expected

notebook-expected-full: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m notebooks_full --update-notebook-expected

executed: $(VENV)/.installed
	$(BIN)/python -m specrefine.runs.notebook executed --tier full --out notebooks/executed

LAB_PORT ?= 8888
# extra arguments for jupyter lab; as root (a container) it refuses to start without --allow-root
LAB_ARGS ?= $(if $(filter 0,$(shell id -u)),--allow-root)
lab: $(KERNEL_SPEC)
	$(BIN)/jupyter lab --notebook-dir=notebooks --ip=127.0.0.1 --port=$(LAB_PORT) \
		--MappingKernelManager.default_kernel_name=specrefine $(LAB_ARGS)

.PHONY: venv demo test notebooks-full notebook-expected notebook-expected-full executed lab
