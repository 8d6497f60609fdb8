# Two commands: `make run` and `make test`. Both create .venv if it is missing and (re)install when
# pyproject.toml or constraints.txt changed.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test scenarios lint typecheck docs docs-serve clean vamp

# constraints.txt pins every dependency's version, so a fresh install is the one the results were measured with.
$(STAMP): pyproject.toml constraints.txt
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV) || python3 -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -c constraints.txt -e '.[dev]'
	$(BIN)/python -m scone_bt.motion.warm || echo "planner kernels not compiled now: the first plan compiles them"  # ~18 s once, not in the first run
	@touch $(STAMP)

run: $(STAMP)
	@mkdir -p runs
	$(BIN)/scone-run --robot sim --headless --seed 0 --save runs/episode.rrd

# The suite and the fast scenarios (tags: [fast]), on PyBullet and on MuJoCo; .ci/run adds the rest of the library (docs/scenarios.md).
# Two pytest-xdist workers (12.5 -> 8.3 min on 2 cores); `make test JOBS=0` runs it in one process.
JOBS ?= 2
test: $(STAMP)
	$(BIN)/python -m pytest tests scenarios -m "not scenario or fast" -n $(JOBS)
	$(BIN)/python -m pytest scenarios -m fast --robot mujoco -n $(JOBS)

# The rest of the scenario library, on PyBullet and then on MuJoCo (each case's expected_on says where it differs).
scenarios: $(STAMP)
	$(BIN)/python -m pytest scenarios -m "not fast" -n 2 --junitxml=runs/scenarios-junit.xml
	$(BIN)/python -m pytest scenarios -m "not fast" --robot mujoco -n 2 --junitxml=runs/scenarios-mujoco-junit.xml

# VAMP (vamp-planner, Panda only) built from its PyPI sdist and third_party/vamp/, into .venv; not part of test or run.
vamp: $(STAMP)
	tools/build_vamp.sh

lint: $(STAMP)
	$(BIN)/ruff check scone_bt tests tools
	$(BIN)/ruff format --check scone_bt tests tools

# mypy on scone_bt/, configured in pyproject.toml ([tool.mypy]; docs/how-to/typecheck.md).
typecheck: $(STAMP)
	$(BIN)/python -m mypy

# The documentation site (MkDocs, Material theme) into site/; --strict fails on a broken link or a missing page.
# Its reference pages are generated from the code at build time (tools/docs_reference.py).
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(BIN)/python -m mkdocs build --strict

docs-serve: $(STAMP)
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(BIN)/python -m mkdocs serve

clean:
	rm -rf $(VENV) runs .pytest_cache .mypy_cache site
