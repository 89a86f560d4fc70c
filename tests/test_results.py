"""One result idiom: a Trajectory (EDMD), a LangevinResult and an EnsembleResult offer the
same quantities under the same names and units (``times``, ``temperature`` as an energy,
``msd()``, ``tamsd()``, ``tamsd_lags``, ``ergodicity_breaking()``), with the same
signatures, defaults and errors; they agree with each other where they measure the same
thing; and they are read-only."""

import dataclasses
import functools
import inspect
import warnings

import numpy as np
import pytest

import granular
from granular import analysis, langevin
from granular.ensemble import RunFailure

N, DIM, T = 20, 3, 41  # particles, dimensions, samples (uniform: every step)
DT = 0.01
LAG_STEPS = [1, 3, 10]  # the engine's TAMSD over every window (tamsd_estimator="all")
LAGS = [k * DT for k in LAG_STEPS]


@pytest.fixture(scope="module")
def traj():
    scene = granular.Scene.random(N, 0.03, dim=DIM, restitution=0.9, seed=1)
    return granular.Simulation(scene).run(
        t_stop=0.4, sample_times=np.linspace(0, 0.4, T), store=("positions",)
    )


def _langevin(seed=None, store_positions=True):
    return langevin.run(
        N,
        gamma0=9.26,
        D0=0.072,
        dt=DT,
        t_stop=(T - 1) * DT,
        dim=DIM,
        sample_times=np.arange(T) * DT,
        tamsd_lags=LAGS,
        tamsd_estimator="all",
        store_positions=store_positions,
        seed=seed,
    )


@pytest.fixture(scope="module")
def sde():
    return _langevin(seed=2)


@pytest.fixture(scope="module")
def ens():
    return granular.ensemble(_langevin, 3, seed=3, backend="serial", progress=False)


@pytest.fixture(scope="module")
def edmd_ens():
    scene = granular.Scene.random(N, 0.03, dim=DIM, seed=4)
    return granular.ensemble(
        scene,
        2,
        seed=5,
        backend="serial",
        progress=False,
        t_stop=0.4,
        sample_times=np.linspace(0, 0.4, T),
        quantities=("msd", "msd_per_dimension", "positions", "temperature"),
    )


@pytest.fixture(scope="module")
def lean():
    """An EDMD ensemble that collected the MSD only: no positions, no temperature."""
    return granular.ensemble(
        granular.Scene.random(N, 0.03, seed=4),
        1,
        seed=5,
        backend="serial",
        progress=False,
        t_stop=0.1,
        quantities=("msd",),
    )


def test_msd_has_the_same_shapes_on_all_three(traj, sde, ens, edmd_ens):
    for result in (traj, sde, ens, edmd_ens):
        assert result.msd().shape == (T,)
        assert result.msd(per_dimension=True).shape == (T, DIM)
        np.testing.assert_allclose(result.msd(per_dimension=True).sum(1), result.msd(), rtol=1e-12)
    for result in (traj, sde, ens, edmd_ens):
        assert result.msd(particles=[0, 4]).shape == (T,)
        assert result.msd(per_dimension=True, particles=[0, 4]).shape == (T, DIM)


def test_tamsd_has_the_same_shapes_on_all_three(traj, sde, ens, edmd_ens):
    L = len(LAGS)
    for result in (traj, sde, ens, edmd_ens):
        assert result.tamsd(LAGS).shape == (L,)
        assert result.tamsd(lag_samples=LAG_STEPS[1:]).shape == (L - 1,)
        np.testing.assert_allclose(
            result.tamsd(lag_samples=LAG_STEPS), result.tamsd(LAGS), rtol=1e-12
        )
        assert result.tamsd(LAGS, particles=[1, 2]).shape == (L,)
        # by default at every lag the result has: tamsd_lags
        np.testing.assert_allclose(result.tamsd(), result.tamsd(result.tamsd_lags), rtol=1e-12)
        assert result.ergodicity_breaking(LAGS).shape == (L,)
    for result in (traj, sde):
        assert result.tamsd(LAGS, per_particle=True).shape == (N, L)
        assert result.tamsd(LAGS, particles=[1, 2], per_particle=True).shape == (2, L)
    for result, runs in ((ens, 3), (edmd_ens, 2)):  # a row per particle of every run
        assert result.tamsd(LAGS, per_particle=True).shape == (runs * N, L)
        assert result.tamsd(LAGS, particles=[1, 2], per_particle=True).shape == (runs * 2, L)
    # the engine's results default to the lags they accumulated, a trajectory to all of its
    assert sde.tamsd().shape == ens.tamsd().shape == (L,)
    assert traj.tamsd().shape == edmd_ens.tamsd().shape == (T - 1,)
    np.testing.assert_allclose(traj.tamsd_lags, np.linspace(0, 0.4, T)[1:], rtol=1e-12)


def test_the_engine_tamsd_is_the_trajectory_tamsd_of_its_positions(sde):
    """With tamsd_estimator="all" the engine averages over a window at every step: exactly
    what ``analysis.tamsd`` does with the positions at every step (to rounding: other
    sums)."""
    direct = analysis.tamsd(
        sde.positions, lag_samples=LAG_STEPS, method="direct", per_particle=True
    )
    np.testing.assert_allclose(sde.tamsd(per_particle=True), direct, rtol=1e-12)
    np.testing.assert_allclose(sde.tamsd(LAGS, particles=[3]), direct[3], rtol=1e-12)


def test_particle_choices_agree(traj, sde):
    mask = np.zeros(N, dtype=bool)
    mask[[2, 5]] = True
    for result in (traj, sde):
        np.testing.assert_array_equal(result.msd(particles=mask), result.msd(particles=[2, 5]))
    # all particles from the stored positions: the accumulated MSD, to rounding
    np.testing.assert_allclose(sde.msd(particles=np.arange(N)), sde.msd(), rtol=1e-12)
    np.testing.assert_allclose(
        sde.msd(particles=[7]), (sde.positions[:, 7] ** 2).sum(1), rtol=1e-15
    )
    np.testing.assert_allclose(
        traj.msd(particles=[7]),
        ((traj.positions[:, 7] - traj.positions[0, 7]) ** 2).sum(1),
        rtol=1e-12,
    )


def test_the_ensemble_verbs_are_the_means_of_the_runs(ens, edmd_ens):
    stacked = np.array([r["msd"] for r in ens.runs])
    np.testing.assert_allclose(ens.msd(), stacked.mean(0), rtol=1e-13)
    tamsd = np.array([r["tamsd"] for r in ens.runs])
    np.testing.assert_allclose(ens.tamsd(), tamsd.mean(0), rtol=1e-13)
    np.testing.assert_array_equal(ens.tamsd([LAGS[2]]), ens.tamsd()[[2]])
    np.testing.assert_array_equal(ens.tamsd_lags, LAGS)
    temperature = np.array([r["temperature"] for r in ens.runs])
    np.testing.assert_allclose(ens.temperature, temperature.mean(0), rtol=1e-13)
    # a choice of particles: the mean over the runs of each run's, from its positions
    # (a Langevin run's from the common start at the origin)
    tracer = np.mean([(r["positions"][:, 3] ** 2).sum(1) for r in ens.runs], axis=0)
    np.testing.assert_allclose(ens.msd(particles=[3]), tracer, rtol=1e-13)
    rows = np.concatenate([r["tamsd_per_particle"][:, [0, 2]] for r in ens.runs])
    np.testing.assert_array_equal(ens.tamsd(lag_samples=[1, 10], per_particle=True), rows)
    np.testing.assert_allclose(
        ens.tamsd(particles=[4, 5]),
        np.mean([r["tamsd_per_particle"][[4, 5]].mean(0) for r in ens.runs], axis=0),
        rtol=1e-13,
    )
    # all particles: the accumulated means, to rounding (other sums)
    np.testing.assert_allclose(ens.msd(particles=np.arange(N)), ens.msd(), rtol=1e-12)
    np.testing.assert_allclose(ens.tamsd(particles=np.arange(N)), ens.tamsd(), rtol=1e-12)
    np.testing.assert_allclose(edmd_ens.msd(particles=np.arange(N)), edmd_ens.msd(), rtol=1e-12)
    # an EDMD ensemble's TAMSD: the mean over runs of analysis.tamsd of each
    each = [analysis.tamsd(r["positions"], LAGS, times=r["times"]) for r in edmd_ens.runs]
    np.testing.assert_allclose(edmd_ens.tamsd(LAGS), np.mean(each, axis=0), rtol=1e-13)


def test_ergodicity_breaking_is_analysis_of_the_tamsd_rows_on_every_result(
    traj, sde, ens, edmd_ens
):
    """EB over the particles (of every run, for an ensemble), from the rows
    ``tamsd(per_particle=True)`` gives: ``analysis.ergodicity_breaking``, one computation."""
    for result in (traj, sde, ens, edmd_ens):
        rows = result.tamsd(LAGS, per_particle=True)
        want = rows.var(axis=0) / rows.mean(axis=0) ** 2
        np.testing.assert_allclose(result.ergodicity_breaking(LAGS), want, rtol=1e-12)
        np.testing.assert_array_equal(
            result.ergodicity_breaking(LAGS), analysis.ergodicity_breaking(rows)
        )
        picked = result.tamsd(LAGS, particles=[0, 1, 2], per_particle=True)
        np.testing.assert_array_equal(
            result.ergodicity_breaking(LAGS, particles=[0, 1, 2]),
            analysis.ergodicity_breaking(picked),
        )
    with pytest.raises(ValueError, match="at least 2"):
        traj.ergodicity_breaking(particles=[0])
    with pytest.raises(ValueError, match=r"shape \(N, L\)"):
        analysis.ergodicity_breaking(np.ones(3))


def test_what_cannot_apply_is_refused_by_name(sde, ens, edmd_ens, lean, traj):
    with pytest.raises(ValueError, match="not accumulated"):
        sde.tamsd([0.05])  # a whole number of steps, but not one of tamsd_lags
    with pytest.raises(ValueError, match="not accumulated"):
        ens.tamsd(lag_samples=[2])
    with pytest.raises(ValueError, match="not accumulated"):
        sde.tamsd([0.0105])  # not a whole number of steps
    # the lags on either side of the one asked for, in its unit
    with pytest.raises(ValueError, match=r"nearest of those: 0\.03 and 0\.1 \(all: \[0\.01, "):
        sde.tamsd([0.05])
    with pytest.raises(ValueError, match=r"nearest of those: 3 and 10 steps"):
        ens.tamsd(lag_samples=[4])
    # the same errors on every result
    for result in (traj, sde, ens, edmd_ens):
        with pytest.raises(TypeError, match="at most one"):
            result.tamsd(LAGS, lag_samples=LAG_STEPS)
        with pytest.raises(ValueError, match="nearest"):
            result.tamsd([0.0105])  # no sample pair, no step of the engine, is that far apart
    with pytest.raises(ValueError, match="store_positions=True"):
        _langevin(seed=1, store_positions=False).msd(particles=[0])
    lean_sde = granular.ensemble(
        functools.partial(_langevin, store_positions=False),
        2,
        seed=3,
        backend="serial",
        progress=False,
        keep_runs=False,
    )
    with pytest.raises(ValueError, match="kept no runs"):
        lean_sde.msd(particles=[0])
    with pytest.raises(ValueError, match="kept no runs"):
        lean_sde.tamsd(per_particle=True)
    with pytest.raises(ValueError, match=r"'positions'.*store_positions=True"):
        granular.ensemble(
            functools.partial(_langevin, store_positions=False),
            1,
            seed=3,
            backend="serial",
            progress=False,
        ).msd(particles=[0])
    with pytest.raises(ValueError, match='"positions"'):
        lean.tamsd(LAGS)
    with pytest.raises(ValueError, match="msd_per_dimension"):
        lean.msd(per_dimension=True)
    with pytest.raises(ValueError, match="collected no 'temperature'"):
        _ = lean.temperature


def test_the_old_array_attributes_still_work_with_a_future_warning(sde):
    """``result.msd`` / ``result.tamsd`` as arrays: a FutureWarning naming the call and the
    release that removes them."""
    with pytest.warns(FutureWarning, match=r"removed in granular 0\.3\.0; call result\.msd\(\)"):
        last = sde.msd[-1]
    assert last == sde.msd()[-1]
    with pytest.warns(FutureWarning, match=r"result\.tamsd\(\)"):
        doubled = sde.tamsd * 2
    assert type(doubled) is np.ndarray
    np.testing.assert_array_equal(doubled, 2 * sde.tamsd())
    with pytest.warns(FutureWarning):
        assert np.max(sde.msd) == np.max(sde.msd())
    # the shim goes in 0.3.0: this fails in that release, until it is gone
    assert tuple(int(v) for v in granular.__version__.split(".")[:2]) < (0, 3)
    # an ensemble of Langevin runs collects them under their old names
    assert set(langevin.LangevinResult.arrays(sde)) >= {
        "msd",
        "tamsd",
        "tamsd_lags",
        "v2",
        "temperature",
    }


RESULTS = (granular.Trajectory, langevin.LangevinResult, granular.EnsembleResult)
# a trajectory computes its TAMSD from positions, the others hold one the engine accumulated:
# how to compute it is the trajectory's own keyword, and the only parameter not shared
OWN = {(granular.Trajectory, "tamsd"): {"method"}}


@pytest.mark.parametrize("verb", ["msd", "tamsd", "ergodicity_breaking"])
def test_every_result_type_has_the_same_signatures(verb):
    """The same parameters (names, kinds, defaults, order) on every result type, read from
    the classes themselves (``inspect.signature(LangevinResult.msd)`` included)."""
    shared = []
    for cls in RESULTS:
        params = inspect.signature(getattr(cls, verb)).parameters.values()
        own = OWN.get((cls, verb), set())
        shared.append([(p.name, p.kind, p.default) for p in params if p.name not in own])
    assert shared[0] == shared[1] == shared[2], f"{verb}: {shared}"
    assert shared[0][0][0] == "self" and len(shared[0]) > 1


def test_every_result_offers_the_same_quantities(traj, sde, ens, edmd_ens):
    for result in (traj, sde, ens, edmd_ens):
        for name in ("times", "temperature", "tamsd_lags"):
            assert isinstance(getattr(result, name), np.ndarray), (type(result), name)
        for name in ("msd", "tamsd", "ergodicity_breaking"):
            assert callable(getattr(result, name)), (type(result), name)
        assert result.temperature.shape == result.times.shape == (T,)
    # the signature of a result's bound method too, through the array shim
    assert str(inspect.signature(sde.msd)) == str(inspect.signature(traj.msd))


def test_temperature_is_an_energy_on_every_result():
    """One gas of mass-2 particles at t = 0: its EDMD trajectory, the Langevin model that
    stands for it (``from_scene``, every particle at the thermal speed: ``initial="fixed"``,
    so <v^2> is exact, not a sample), and ensembles of both agree on T = m <v^2> / d, the
    scene's, to rounding.  Per unit mass (the old LangevinResult.temperature) is half."""
    scene = granular.Scene.random(50, 0.02, dim=2, restitution=0.9, mass=2.0, seed=6)
    run = dict(t_stop=0.2, sample_times=[0.0, 0.1, 0.2])
    model = functools.partial(
        langevin.from_scene,
        scene,
        dt=0.01,
        t_stop=0.2,
        initial="fixed",
        threads=1,
        sample_times=[0.0, 0.1, 0.2],
    )
    sde = model(seed=1)
    with pytest.warns(
        FutureWarning, match=r"an energy now.*removed in .*0\.3\.0; .*result\.v2 / result\.dim"
    ):
        sde_t = sde.temperature
    edmd = granular.Simulation(scene).run(**run)
    ensembles = [
        granular.ensemble(
            scene, 2, seed=7, backend="serial", progress=False, **run, quantities=("temperature",)
        ),
        granular.ensemble(model, 2, seed=7, backend="serial", progress=False),
    ]
    starts = [edmd.temperature[0], sde_t[0], *(e.temperature[0] for e in ensembles)]
    np.testing.assert_allclose(starts, scene.temperature, rtol=1e-12)
    assert sde.mass == 2.0
    assert sde.v2[0] / sde.dim == pytest.approx(scene.temperature / 2, rel=1e-12)
    # a run of unit mass, the default: the same numbers as before, and no notice
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        unit = _langevin(seed=1)
        np.testing.assert_array_equal(unit.temperature, unit.v2 / DIM)
    with pytest.raises(ValueError, match="mass must be positive"):
        langevin.run(2, gamma0=1.0, D0=1.0, dt=0.1, t_stop=1.0, mass=0.0)


def test_results_are_read_only(traj, sde, ens, edmd_ens):
    """No attribute can be set, and writing into an array a result hands out either
    raises (a read-only view of what it holds) or changes a new array computed for the
    caller: the result stays as it was."""
    for result in (traj, sde, ens, edmd_ens):
        with pytest.raises(AttributeError):
            result.times = np.zeros(T)
        handed = {
            "times": lambda r: r.times,
            "temperature": lambda r: r.temperature,
            "msd()": lambda r: r.msd(),
            "msd(per_dimension=True)": lambda r: r.msd(per_dimension=True),
            "tamsd()": lambda r: r.tamsd(),
            "tamsd_lags": lambda r: r.tamsd_lags,
        }
        for name, get in handed.items():
            before = get(result).copy()
            try:
                get(result)[...] = -1.0
            except ValueError as exc:  # a read-only view of what the result holds
                assert "read-only" in str(exc)
            np.testing.assert_array_equal(get(result), before, err_msg=name)
    for array in (traj.positions, sde.tamsd_per_particle, sde.positions, ens.runs[0]["msd"]):
        assert not array.flags.writeable
    for result in (sde, ens):
        assert dataclasses.is_dataclass(result)
        with pytest.raises(dataclasses.FrozenInstanceError):
            result.count = 0
    with pytest.raises(AttributeError, match="read-only"):
        del traj.positions
    # a copy, and an unpickled one, are read-only too (NumPy does not keep the flag)
    import copy
    import pickle

    for result in (traj, sde):
        for again in (copy.deepcopy(result), pickle.loads(pickle.dumps(result))):
            assert not again.times.flags.writeable
    failure = RunFailure(
        1, {"entropy": 5, "spawn_key": (1,)}, "ValueError('x')", "tb", "ValueError"
    )
    assert failure.error_type == "ValueError" and "run 1" in repr(failure)


def test_a_failed_run_names_its_error_type():
    # a sweep whose other point succeeds: a call whose every run fails raises instead
    good = functools.partial(langevin.run, 1, gamma0=1.0, D0=1.0, dt=0.5, t_stop=1.0)
    with pytest.warns(RuntimeWarning, match="point 1: every one of its 1 runs failed"):
        _, res = granular.ensemble(
            [good, functools.partial(good, dt=-1.0)], 1, backend="serial", progress=False
        )
    (failure,) = res.failures
    assert failure.error_type == "ValueError" and "dt must be positive" in failure.error
