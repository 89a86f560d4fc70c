"""Error messages print numbers as numbers: a value that reached granular as a NumPy scalar
(or a list or dict of them) must not be shown as NumPy 2 writes its repr, ``np.float64(0.5)``
or ``[np.int64(1), ...]``.  Each case passes NumPy scalars where a user's script would (an
element of an array, a result of a NumPy function) and reads the message."""

import re

import numpy as np
import pytest

import granular
from granular import _animate, analysis, clustering, langevin
from granular.errors import shown
from granular.restitution import ConstantRestitution, Viscoelastic

f64, i64 = np.float64, np.int64
SDE = dict(gamma0=1.0, D0=1.0, dt=f64(0.1), t_stop=f64(1.0), seed=1)


def _walk(times):
    """Positions and times of a random walk sampled at ``times``, as keywords."""
    x = np.random.default_rng(0).normal(size=(len(times), 3, 2)).cumsum(0)
    return dict(positions=x, times=np.asarray(times, dtype=np.float64))


def _lone_sphere(monkeypatch):
    """A sphere alone in a periodic box never collides: the stall guard gives up (after
    1000 events, not 10^7, for the test) and names the stop criteria."""
    from granular import simulation

    monkeypatch.setattr(simulation._StallGuard, "MIN_LIMIT", 0)
    lone = granular.Scene([[0.5, 0.5, 0.5]], [[1.0, 0.3, 0.2]], 0.01)
    granular.Simulation(lone).run(stop_when={"collisions_per_particle": f64(2.5)})


def _result_lags():
    r = langevin.run(3, tamsd_lags=np.array([1, 3, 7]) * 0.1, **SDE)
    return r.tamsd([f64(0.5)])


CASES = {
    # (what raises, the plain text its message must hold)
    "langevin off-step lag": (
        lambda: langevin.run(3, tamsd_lags=[f64(0.15)], **SDE),
        "0.1 and 0.2",
    ),
    "langevin lag not accumulated": (_result_lags, "0.3 and 0.7 (all: [0.1, 0.3, 0.7])"),
    "langevin lag out of range": (lambda: langevin.run(3, tamsd_lags=[f64(5.0)], **SDE), "got 5"),
    "langevin no lags": (lambda: langevin.run(3, **SDE).tamsd(), "tamsd_lags=[dt, 10 * dt"),
    "langevin threads": (lambda: langevin.run(3, threads=i64(0), **SDE), "got 0"),
    "analysis log-spaced lag": (
        lambda: analysis.tamsd(**_walk([0.0, 0.1, 0.3, 0.7, 1.5]), lags=[f64(1.0)]),
        "have are 0.8 and 1.2",
    ),
    "analysis lag off the spacing": (
        lambda: analysis.tamsd(**_walk(np.arange(11) * 0.1), lags=[f64(0.15)]),
        "0.1 and 0.2",
    ),
    "analysis lags out of range": (
        lambda: analysis.tamsd(**_walk(np.arange(11) * 0.1), lags=np.array([0.5, 9.0])),
        "got [0.5, 9]",
    ),
    "analysis lag_samples": (
        lambda: analysis.tamsd(_walk(np.arange(11))["positions"], lag_samples=[i64(0), i64(11)]),
        "got [0, 11]",
    ),
    "scene n": (lambda: granular.Scene.random(f64(10.5), 0.03), "got 10.5"),
    "restitution": (lambda: ConstantRestitution(f64(-0.5)), "got -0.5"),
    "viscoelastic damping": (lambda: Viscoelastic(f64(-2.0), 1.0), "got -2"),
    "viscoelastic poisson": (
        lambda: Viscoelastic.from_material(
            young=1.0, poisson=f64(0.7), radius=1.0, mass=1.0, damping=1.0
        ),
        "got 0.7",
    ),
    "viscoelastic restitution": (
        lambda: Viscoelastic.from_restitution(f64(0.25), 1.0),
        "got 0.25",
    ),
    "clustering box": (
        lambda: clustering.wave_vectors((f64(1.0), f64(-1.0))),
        "got (1, -1)",
    ),
    "animation trails": (lambda: _animate._trail_particles([f64(1.5)], 3), "got [1.5]"),
    "neighbour-list shell": (
        lambda: granular.Simulation(granular.Scene.random(10, 0.03, seed=1), shell=np.str_("x")),
        "got 'x'",
    ),
    "store": (
        lambda: granular.Simulation(granular.Scene.random(10, 0.03, dim=2, seed=1)).run(
            t_stop=1.0, store=np.array(["positions", "speeds"])
        ),
        "got ('positions', 'speeds')",
    ),
    "stop_when NaN": (
        lambda: granular.Simulation(granular.Scene.random(10, 0.03, dim=2, seed=1)).run(
            t_stop=1.0, stop_when={"kinetic_energy": f64("nan")}
        ),
        "got {'kinetic_energy': nan}",
    ),
    "stop_when events": (
        lambda: granular.Simulation(granular.Scene.random(10, 0.03, dim=2, seed=1)).run(
            t_stop=1.0, stop_when={"events": f64(1.5)}
        ),
        "got 1.5",
    ),
}


@pytest.mark.parametrize("name", [*CASES, "no progress"])
def test_messages_print_numbers_not_numpy_reprs(name, monkeypatch):
    if name == "no progress":
        call, plain = (lambda: _lone_sphere(monkeypatch)), "{'collisions_per_particle': 2.5}"
    else:
        call, plain = CASES[name]
    with pytest.raises((ValueError, TypeError, granular.NoProgressError)) as info:
        call()
    message = str(info.value)
    assert "np." not in message, message
    assert plain in message, message


def test_shown():
    assert shown(f64(0.5)) == "0.5"
    assert shown(0.1 * 3) == "0.3"  # float64's last bit is not news
    assert shown([i64(1), i64(2)]) == "[1, 2]"
    assert shown((f64(1.0),)) == "(1,)"
    assert shown({"a": f64("inf")}) == "{'a': inf}"
    assert shown(np.float32(0.1)) == "0.1"
    assert shown(np.array(3.0)) == "3"
    assert shown(np.str_("x")) == "'x'"
    assert shown(np.bool_(True)) == "True"
    assert re.fullmatch(r"\[0, 1, 2, 3, 4, 5, 6, 7, \.\.\. \(20 in all\)\]", shown(np.arange(20)))
