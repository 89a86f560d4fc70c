"""MDAnalysis export: its EinsteinMSD agrees with granular's TAMSD; written files read back."""
import numpy as np
import pytest

from granular import Scene, Simulation, analysis, interop

mda = pytest.importorskip("MDAnalysis")


def walk(T=120, N=40, d=3, seed=0):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(scale=0.05, size=(T, N, d)), axis=0) + 0.5
    return np.arange(T) * 0.25, x


def test_einstein_msd_agrees_with_tamsd():
    """MDAnalysis' EinsteinMSD (windowed, all lags) is the TAMSD.  Its coordinates are
    float32: relative rounding 6e-8 per coordinate, so squared displacements of O(1)
    positions differ by ~1e-7 absolute; tolerance 1e-5 relative for MSDs of O(0.01-1)."""
    from MDAnalysis.analysis.msd import EinsteinMSD

    t, x = walk()
    u = interop.to_universe(t, x)
    res = EinsteinMSD(u, select="all", msd_type="xyz", fft=False).run()
    lags = np.arange(1, len(t))
    ours = analysis.tamsd(x, lags)
    np.testing.assert_allclose(res.results.timeseries[1:], ours, rtol=1e-5)


def test_universe_of_a_simulation_and_a_written_trr(tmp_path):
    s = Scene.random(50, 0.03, seed=1)
    times = np.linspace(0, 2, 9)
    tr = Simulation(s).run(t_stop=2.0, sample_times=times)
    u = tr.to_universe()
    assert u.atoms.n_atoms == 50 and u.trajectory.n_frames == 9
    np.testing.assert_allclose(u.dimensions[:3], [1, 1, 1])
    np.testing.assert_allclose(u.trajectory[4].positions, tr.positions[4], rtol=1e-6, atol=1e-6)
    # log-spaced times survive in the file
    logt = np.concatenate([[0.0], np.logspace(-2, 0, 6)])
    tr2 = Simulation(s).run(t_stop=1.0, sample_times=logt)
    path = interop.write_trajectory(tmp_path / "gas.trr", tr2.times, tr2.positions, tr2.velocities,
                                    box=[1, 1, 1])
    back = mda.Universe.empty(50, trajectory=False)
    back.load_new(path)
    assert back.trajectory.n_frames == 7
    np.testing.assert_allclose([ts.time for ts in back.trajectory], logt, rtol=1e-6, atol=1e-9)
    back.trajectory[-1]
    np.testing.assert_allclose(back.atoms.positions, tr2.positions[-1], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(back.atoms.velocities, tr2.velocities[-1], rtol=1e-6, atol=1e-6)


def test_two_dimensional_export():
    t, x = walk(T=10, N=5, d=2)
    u = interop.to_universe(t, x, box=[1.0, 1.0])
    assert u.trajectory.n_frames == 10
    np.testing.assert_allclose(u.trajectory[3].positions[:, :2], x[3], rtol=1e-6)
    assert np.all(u.trajectory[3].positions[:, 2] == 0)
