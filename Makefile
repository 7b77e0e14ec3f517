# Each target creates the virtual environment when it is missing and installs what it needs:
# `make demo` the runtime and the figures, the other targets the test extras too.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
RUNTIME := $(VENV)/.installed-runtime
TESTS := $(VENV)/.installed-tests
DOCS := $(VENV)/.installed-docs

.PHONY: demo test test-fast bench lint types docs clean

# The problems here are tall and thin (e.g. 34,000 x 44): threaded BLAS only adds overhead
# on a small machine. Override with OPENBLAS_NUM_THREADS=N make ...
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1

$(RUNTIME): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e ".[plots]"
	touch $(RUNTIME)

$(TESTS): $(RUNTIME)
	$(PY) -m pip install -q -e ".[test,plots]"
	touch $(TESTS)

$(DOCS): $(RUNTIME)
	$(PY) -m pip install -q -e ".[docs]"
	touch $(DOCS)

demo: $(RUNTIME)
	$(VENV)/bin/dynid demo --out out

# one worker per core (pytest-xdist); PYTEST_WORKERS=0 runs in one process. Each test file
# runs on one worker (--dist loadscope), so a module-scoped fixture is computed once, not once
# per worker; the files are handed out in collection order (--no-loadscope-reorder: the
# default order, most tests first, would leave the one-test demo file for the end), which
# tests/conftest.py begins with the files holding a test marked slow.
PYTEST_WORKERS ?= auto
PYTEST_XDIST := -n $(PYTEST_WORKERS) --dist loadscope --no-loadscope-reorder
# one BLAS thread per worker: each worker already has a core, and threaded BLAS on the small
# matrices of these tests spins against the other worker (the excitation optimisation of
# tests/test_excitation.py, then a finite-difference gradient, took 41 s single-threaded, 56 s
# alone with two threads, and about 220 s with two threads beside another worker)
# Compiled modules are written (PYTHONDONTWRITEBYTECODE emptied: set, each test worker rewrote
# the asserts of every test file, 10.5 s CPU against 4.1 s from the cache, and each command the
# tests start as a process compiled dynid again, about 0.5 s; tests/test_processes.py,
# test_cli_log_lines.py and test_examples.py took 42.3 s CPU, 35.5 s with the cache); the files
# go to __pycache__ folders, which git ignores, beside numba's.
TEST_ENV := MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 \
	PYTHONDONTWRITEBYTECODE=

# Chromium renders the HTML reports in tests/test_html_report.py (skipped without it): when
# it is missing, install Debian's package where apt-get can (root, a Debian system), saying
# so before and after; a failure is printed and the tests that need it are skipped.
CHROMIUM_INSTALL = command -v chromium >/dev/null 2>&1 || { \
	echo "make test: chromium is missing (tests/test_html_report.py renders with it);" \
	     "installing Debian's package: apt-get update && apt-get install -y chromium"; \
	if (DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium) >/dev/null 2>&1; then \
	    echo "make test: installed $$(chromium --version 2>/dev/null || echo chromium)"; \
	else echo "make test: chromium could not be installed; the tests that render HTML are skipped"; fi; }

test: $(TESTS)
	@$(CHROMIUM_INSTALL)
	$(TEST_ENV) $(PY) -m pytest -q $(PYTEST_XDIST)

# everything but the tests marked slow (over about 10 s each)
test-fast: $(TESTS)
	$(TEST_ENV) $(PY) -m pytest -q $(PYTEST_XDIST) -m "not slow"

# every benchmark, the long ones included (benchmarks/bench_memory.py: every command's peak
# memory on a 5-million-row log against the 1.5 GB target, about half an hour);
# BENCH_ARGS=--short skips the long ones
BENCH_ARGS ?=
bench: $(TESTS)
	$(PY) benchmarks/run_all.py $(BENCH_ARGS)

lint: $(TESTS)
	$(PY) -m pip install -q "ruff==0.17.6"
	$(PY) -m ruff check src tests benchmarks examples docs
	$(PY) -m ruff format --check src tests benchmarks examples docs

types: $(TESTS)
	$(PY) -m pip install -q "mypy==2.4.1"
	$(PY) -m mypy src/dynid

# the documentation site in site/, strict: every warning (a broken link, an unresolved API
# page, a module left out of the API reference) is an error
docs: $(DOCS)
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --site-dir site

clean:
	rm -rf $(VENV) out build site src/*.egg-info
