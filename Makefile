# Entry points: `make demo` (the main job), `make test` (every test, then the quick benchmarks
# but the stress cases and work-precision, whose quick runs are tests)
# and `make test-fast` (the inner loop: the tests not marked slow). Each creates .venv and
# installs what it needs. CI sets TORCH_SPEC=torch==2.13.0 so that pip takes the local CPU wheel
# before anything can pull the CUDA build; ordinary users leave it empty and get torch the normal
# way when they install the `rl` extra. Each first compiles the env kernels it uses into the disk
# cache (`mdi-envs compile all`; the demo only what gym.make needs, `--make-only`), so that the
# processes after it start warm. The tests run on every core
# (pytest-xdist); --dist loadfile keeps each file on one worker, so that a module's fixture (the
# kernel-cache tests compile into an empty cache) runs once, and tests/conftest.py hands out the
# files with the most slow tests first.

PYTHON ?= python3
VENV ?= .venv
TORCH_SPEC ?=
BIN := $(VENV)/bin

.PHONY: demo test test-fast docs bench lint clean

# Install the package in editable mode with the given extras, once per extras set and pyproject.
$(VENV)/.installed-%: pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	if [ -n "$(TORCH_SPEC)" ]; then $(BIN)/python -m pip install --quiet "$(TORCH_SPEC)"; fi
	$(BIN)/python -m pip install --quiet -e ".[$*]"
	touch $@

demo: $(VENV)/.installed-rl,render
	$(BIN)/mdi-envs compile all --make-only
	$(BIN)/mdi-envs demo --output results/demo

test: $(VENV)/.installed-test
	$(BIN)/mdi-envs compile all
	$(BIN)/python -m pytest -q -n auto --dist loadfile --durations=10
	$(BIN)/python -m mdi_envs bench --quick --skip stress precision

# The inner loop while editing: every test but those marked slow (training, optimisation,
# full-size solver and benchmark studies), the same as `pytest -m "not slow"`.
test-fast: $(VENV)/.installed-test
	$(BIN)/mdi-envs compile all
	$(BIN)/python -m pytest -q -m "not slow" -n auto --dist loadfile --durations=10

# The docs site (MkDocs Material + mkdocstrings) into site/; strict: a broken link or reference
# fails. Its generated pages read the committed JSON and parse the sources (nothing compiles).
docs: $(VENV)/.installed-docs
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(BIN)/mkdocs build --strict

bench: $(VENV)/.installed-bench
	$(BIN)/python -m mdi_envs bench

lint: $(VENV)/.installed-dev
	$(BIN)/ruff check mdi_envs optimal baselines tests benchmarks docs
	$(BIN)/mypy mdi_envs
	$(BIN)/lint-imports

clean:
	rm -rf $(VENV) results site .pytest_cache .hypothesis
