"""Every compatibility shim says in which release it goes, and that release is still to come:
once granular's version reaches it, this test fails until the shim is removed.

The shims: the applications' old names ``granular.<app>`` (now ``granular.cli.<app>``), and
``LangevinResult.msd`` / ``.tamsd`` used as arrays (now methods).  A new shim adds its
warning here."""

import re
import warnings

import numpy as np
import pytest

import granular
from granular import _deprecation, langevin


def _release(version):
    return tuple(int(part) for part in version.split(".")[:3])


def _warnings_of_every_shim():
    result = langevin.run(
        2, gamma0=1.0, D0=1.0, dt=0.1, t_stop=0.5, dim=2, tamsd_lags=[0.2], seed=1
    )
    heavy = langevin.run(2, gamma0=1.0, D0=1.0, dt=0.1, t_stop=0.5, mass=2.0, seed=1)
    uses = [
        lambda: granular.demo,
        lambda: result.msd[0],
        lambda: np.max(result.tamsd),
        lambda: heavy.temperature,  # per unit mass before; an energy now
    ]
    caught = []
    for use in uses:
        with warnings.catch_warnings(record=True) as got:
            warnings.simplefilter("always")
            use()
        assert [w.category for w in got] == [FutureWarning], [str(w.message) for w in got]
        caught.append(str(got[0].message))
    return caught


@pytest.mark.parametrize("message", _warnings_of_every_shim())
def test_shims_name_a_removal_release_still_to_come(message):
    found = re.search(r"removed in granular (\d+\.\d+\.\d+)", message)
    assert found, f"the warning names no removal release: {message!r}"
    assert _release(found.group(1)) > _release(granular.__version__), (
        f"granular {granular.__version__} has reached the release this shim should be gone "
        f"in: {message!r}"
    )


def test_help_shows_the_removal_release_not_its_constant_name():
    # a docstring is not an f-string: help() would show the literal name
    from granular.langevin import LangevinResult

    for name in ("msd", "tamsd", "temperature"):
        doc = getattr(LangevinResult, name).__doc__
        assert "REMOVAL_VERSION" not in doc, name
        assert _deprecation.REMOVAL_VERSION in doc, name
