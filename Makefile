# Two commands do all the set-up on a fresh machine (see README):
#   make demo   - whole pipeline on sample_data/ into a local SQLite database
#   make test   - the test suite
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT ?= out

.PHONY: demo test bench sample-data clean system-deps lock

# Debian's venv module is a separate package, and the C library libswtwpm (built into the
# package at install) needs a C compiler; install them only where they are missing.
system-deps:
	@$(PYTHON) -c "import ensurepip, venv" 2>/dev/null || \
	  (apt-get update -qq && apt-get install -y -qq python3-venv)
	@command -v cc >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq gcc libc6-dev)

# Exact versions (with hashes) from requirements.lock, then swtlab itself without resolving.
# The installer is uv (pinned with its hashes in requirements-uv.lock): it fetches and unpacks
# in parallel, a fresh environment in about 35 s where pip takes about 80 s.
$(STAMP): pyproject.toml setup.py requirements.lock requirements-uv.lock $(wildcard libswtwpm/*.c libswtwpm/*.h) | system-deps
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --require-hashes -r requirements-uv.lock
	$(BIN)/uv pip install -q --python $(BIN)/python --compile-bytecode --require-hashes \
	    -r requirements.lock
	$(BIN)/uv pip install -q --python $(BIN)/python --no-deps -e .
	touch $(STAMP)

# Regenerate the lock file after a dependency change in pyproject.toml (newest versions that
# satisfy it, for Python 3.11, every extra); commit the result.
lock: | system-deps
	$(PYTHON) -m pip install -q uv
	$(PYTHON) -m uv pip compile pyproject.toml --extra test --extra bench --generate-hashes \
	    --python-version 3.11 -o requirements.lock

demo: $(STAMP)
	mkdir -p $(OUT)
	$(BIN)/swtlab process sample_data/campaign --db sqlite:///$(OUT)/swtlab.sqlite
	$(BIN)/swtlab results --db sqlite:///$(OUT)/swtlab.sqlite --csv $(OUT)/results.csv
	$(BIN)/swtlab export --db sqlite:///$(OUT)/swtlab.sqlite -o $(OUT)/wpm.csv
	$(BIN)/swtlab wpm query $(OUT)/wpm.csv --load 120 --dp 25 --multipass 0
	$(BIN)/swtlab gap --measured sqlite:///$(OUT)/swtlab.sqlite \
	    --sim terramechanics/models/bb2_sand.toml --json $(OUT)/gap.json --html $(OUT)/gap.html
	$(BIN)/swtlab report --db sqlite:///$(OUT)/swtlab.sqlite -o $(OUT)/report.html
	@echo "results: report $(OUT)/report.html (open it in a browser), database $(OUT)/swtlab.sqlite,"
	@echo "         one row per run in $(OUT)/results.csv, WPM curves in $(OUT)/wpm.csv,"
	@echo "         sim-to-real gap report in $(OUT)/gap.html"

# Lint first (seconds), then one worker per core (pytest-xdist); a test file stays on one
# worker, so module fixtures run once. The 15 slowest tests are printed to keep the suite fast.
test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy
	$(BIN)/python -m pytest -q -n auto --dist loadfile --durations=15

bench: $(STAMP)
	$(BIN)/python -m bench

sample-data: $(STAMP)
	$(BIN)/python -m virtual_testbed.sample_campaign --out sample_data --seed 20260

clean:
	rm -rf $(VENV) $(OUT) *.egg-info
