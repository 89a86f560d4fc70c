# Two commands from a fresh machine (Python >= 3.10, pip, a C compiler):
#   make demo   -- set up .venv and run the main job
#   make test   -- set up .venv and run the whole test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

.PHONY: setup demo test bench clean

$(VENV)/.installed: pyproject.toml setup.py $(wildcard csrc/*.c csrc/*.h)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $@

setup: $(VENV)/.installed

demo: setup
	$(PY) -m granular demo

test: setup
	$(PY) -m pytest -q

bench: setup
	$(PY) -m granular bench --json bench.json

clean:
	rm -rf build $(VENV) granular/*.so *.egg-info
