"""Settings for the whole suite.  Shared helpers live in tests/helpers/ (``from helpers
import ...``), not here and not in test modules.  ``@pytest.mark.slow`` marks the slowest
tests: ``make test`` (CI) runs them, ``make test-quick`` (``-m "not slow"``) leaves them out."""
import matplotlib

matplotlib.use("Agg")  # no display: figures are only written to files
