import os
import sys

import matplotlib
import pytest

matplotlib.use("Agg")
sys.path.insert(0, os.path.dirname(__file__))  # tests import their reference helpers


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", help="run long physics validation")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--runslow"):
        return
    skip = pytest.mark.skip(reason="slow physics validation: run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
