# Two commands from a fresh machine (Python >= 3.10, pip, a C compiler):
#   make demo   -- set up .venv with the plot extra only and run the main job
#   make test   -- set up .venv with the test extra and run the whole test suite (CI)
#   make test-quick -- the same without the tests marked slow, for daily work
#   make lint   -- ruff, mypy and its stubtest of the C extension (CI runs it before the tests)
#   make docs   -- the documentation site into build/docs/html, failing on any warning
# and for the C core: make test-asan (the suite against an ASan + UBSan build of it, in its own venv)
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SOURCES := pyproject.toml setup.py $(wildcard csrc/*.c csrc/*.h)

.PHONY: setup demo test test-quick lint docs test-asan test-asan-ci bench clean

$(VENV)/.created:
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	touch $@

# One venv, one marker per extra installed into it: the demo needs only matplotlib (the plot
# extra, a few packages), not the test extra's ~130 (Jupyter, MDAnalysis, Dask, Sphinx, ...)
$(VENV)/.installed-plot: $(SOURCES) | $(VENV)/.created
	$(PY) -m pip install --quiet -e '.[plot]'
	touch $@

$(VENV)/.installed-test: $(SOURCES) | $(VENV)/.created
	$(PY) -m pip install --quiet -e '.[test]'
	touch $@

setup: $(VENV)/.installed-test

demo: $(VENV)/.installed-plot
	$(PY) -m granular demo

test: setup
	$(PY) -m pytest -q

# the slowest tests (pytest.mark.slow: the CLI runs, long physics checks) left out
test-quick: setup
	$(PY) -m pytest -q -m "not slow"

# lint, formatting and the type hints; the configuration is pyproject.toml's [tool.ruff*]
# and [tool.mypy] (which names the files mypy checks: the package). stubtest checks the C
# extension's stub, granular/_core.pyi, against the built module: every name, no other.
lint: setup
	$(PY) -m ruff check . && $(PY) -m ruff format --check . && $(PY) -m mypy
	$(PY) -m mypy.stubtest granular._core --mypy-config-file pyproject.toml

# The docs extra comes with the test extra (setup). -E: a fresh environment every time, so a
# warning in a page that did not change is not hidden by the cache; -W --keep-going: every
# warning is reported, and any fails the build. API stubs are generated into docs/generated/.
docs: setup
	$(PY) -m sphinx -b html -E -W --keep-going docs build/docs/html
	@echo "open build/docs/html/index.html"

bench: setup
	$(PY) -m granular bench --json bench.json

# --- sanitizers -----------------------------------------------------------------------------
# The extension built with AddressSanitizer (setup.py's GRANULAR_ASAN=1) and UBSan (CFLAGS,
# which setuptools passes to both compiling and linking; -fno-sanitize-recover makes undefined
# behaviour abort, so a test sees it), installed non-editable into its own venv: the in-place
# granular/_core*.so of .venv stays as it is. Built from a copy of the sources, so no object
# file of an ordinary build is reused. The tests run from a copy of tests/ (and of benchmarks/,
# which tests/test_benchmarks.py runs) so that `import granular` finds the sanitized install,
# not the source tree. Under build/: git ignores it.
ASAN_VENV  := build/venv-asan
ASAN_PY    := $(ASAN_VENV)/bin/python
ASAN_CFLAGS := -fsanitize=undefined -fno-sanitize-recover=undefined
# notebooks run kernels (not the C core); packaging builds an sdist
ASAN_TESTS ?= $(filter-out test_notebooks.py test_packaging.py,$(notdir $(wildcard tests/test_*.py)))
# CI's share (.ci/run): the tests that drive the C core hardest, and the fast tests of the
# engine's newer physics (gravity, vibrating wall, driving, shear, stress, rough particles)
ASAN_CI_TESTS := test_scene.py test_simulation.py test_neighbour_lists.py test_physics_edmd.py \
                 test_langevin.py test_fuzz.py test_checkpoint.py test_restitution.py
ASAN_CI_PHYSICS := test_gravity.py test_vibrating_wall.py test_driving.py test_shear.py \
                   test_stress.py test_shear_stress.py test_rough.py test_rough_combined.py
ASAN_ENV   := LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libubsan.so)" \
              ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1 \
              UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 GRANULAR_FUZZ_TIMEOUT=30

$(ASAN_VENV)/.installed: pyproject.toml setup.py MANIFEST.in $(wildcard csrc/*.c csrc/*.h granular/*.py granular/cli/*.py granular/theory/*.py)
	$(PYTHON) -m venv $(ASAN_VENV)
	$(ASAN_PY) -m pip install --quiet --upgrade pip
	rm -rf $(ASAN_VENV)/src && mkdir -p $(ASAN_VENV)/src/granular/cli \
	    $(ASAN_VENV)/src/granular/theory
	cp setup.py pyproject.toml README.md MANIFEST.in $(ASAN_VENV)/src/
	cp -r csrc $(ASAN_VENV)/src/ && cp granular/*.py $(ASAN_VENV)/src/granular/
	cp granular/cli/*.py $(ASAN_VENV)/src/granular/cli/
	cp granular/theory/*.py $(ASAN_VENV)/src/granular/theory/
	GRANULAR_ASAN=1 CFLAGS="$(ASAN_CFLAGS)" $(ASAN_PY) -m pip install --quiet --force-reinstall \
	    "$(ASAN_VENV)/src[test]"
	touch $@

test-asan: $(ASAN_VENV)/.installed
	rm -rf $(ASAN_VENV)/tests $(ASAN_VENV)/benchmarks && cp -r tests benchmarks $(ASAN_VENV)/
	cd $(ASAN_VENV)/tests && $(ASAN_ENV) ../bin/python -c "import granular._core, sys; \
	    f = granular.__file__; sys.exit(0 if 'site-packages' in f else 'not the install: ' + f)"
	cd $(ASAN_VENV)/tests && $(ASAN_ENV) ../bin/python -m pytest -q -p no:cacheprovider $(ASAN_TESTS)

test-asan-ci:
	$(MAKE) test-asan ASAN_TESTS="$(ASAN_CI_TESTS)"
	cd $(ASAN_VENV)/tests && $(ASAN_ENV) ../bin/python -m pytest -q -p no:cacheprovider \
	    -m "not slow" $(ASAN_CI_PHYSICS)

clean:
	rm -rf build $(VENV) granular/*.so *.egg-info docs/generated
