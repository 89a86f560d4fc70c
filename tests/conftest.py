"""Settings for the whole suite.  Shared helpers live in tests/helpers/ (``from helpers
import ...``), not here and not in test modules.

``slow`` marks the slowest tests: ``make test`` (CI) runs everything, ``make test-quick``
(``-m "not slow"``) leaves them out for daily work.  A new test may carry
``@pytest.mark.slow`` itself; the existing ones are listed in SLOW, in one place."""

import matplotlib
import pytest

matplotlib.use("Agg")  # no display: figures are only written to files

# Tests of 3 s and more in the whole suite (pytest --durations=30, 2 shared cores; the whole
# suite took 165 s, these 130 s of it), by "module" or "module::test" (every parameter).
SLOW = {
    "test_notebooks.py",  # each notebook executed in a kernel; 02 reruns the quick reproduction
    "test_cli.py::test_reproduce_quick",  # chapter 4 at quick sizes, checked row by row
    "test_cli.py::test_demo_quick",
    "test_speed_accuracy.py::test_speed_accuracy_cli_quick",
    "test_packaging.py::test_sdist_holds_sources_tests_notebooks_and_images",  # builds the sdist
    "test_langevin.py::test_tamsd_equals_msd_for_langevin_but_not_for_udsbm",
    "test_langevin.py::test_euler_maruyama_msd_matches_theory_at_small_steps",
    "test_langevin.py::test_exact_scheme_msd_matches_theory",
    "test_fuzz.py::test_fuzz_inputs_end_in_a_clear_error_or_a_valid_result",
    "test_ensemble.py::test_guarded_scripts_and_scripts_without_a_file_run",  # fresh interpreters
    "test_simulation.py::test_energy_and_momentum_conserved_over_a_million_collisions",
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in SLOW or f"{item.path.name}::{item.originalname}" in SLOW:
            item.add_marker(pytest.mark.slow)
