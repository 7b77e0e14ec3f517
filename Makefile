# Each target creates the virtual environment when it is missing and installs what it needs.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test bench lint clean

# The problems here are tall and thin (e.g. 34,000 x 44): threaded BLAS only adds overhead
# on a small machine. Override with OPENBLAS_NUM_THREADS=N make ...
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e ".[test,plots]"
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/dynid demo --out out

test: $(STAMP)
	MPLBACKEND=Agg $(PY) -m pytest -q

bench: $(STAMP)
	$(PY) benchmarks/run_all.py

lint: $(STAMP)
	$(PY) -m pip install -q ruff
	$(PY) -m ruff check src tests benchmarks examples

clean:
	rm -rf $(VENV) out build src/*.egg-info
