"""MDAnalysis export: EinsteinMSD of an exported simulation agrees with granular's TAMSD;
written files read back."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, analysis, interop

mda = pytest.importorskip("MDAnalysis")


def walk(T=120, N=40, d=3, seed=0):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(scale=0.05, size=(T, N, d)), axis=0) + 0.5
    return np.arange(T) * 0.25, x


def test_einstein_msd_of_an_exported_simulation_agrees_with_tamsd(tmp_path):
    """An EDMD trajectory (uniform sample times, unwrapped positions) written to TRR by
    ``interop.write_trajectory`` and read back by MDAnalysis: its EinsteinMSD (windowed,
    every lag) equals granular's TAMSD of the same trajectory within float32 rounding.

    Rounding bound, u = 2^-24 (float32 unit roundoff): a coordinate x passes three
    roundings -- to float32, the writer's angstrom -> nm scaling (x 0.1, itself 1.5e-8
    off in float32), the reader's nm -> angstrom -- so it comes back within
    eps = 4 u max|x|.  A displacement Delta is then off by at most 2 eps per component,
    its square by at most 4 eps sum_a |Delta_a| + 3 (2 eps)^2 <= 4 sqrt(3) eps |Delta|
    + 12 eps^2, and the average over pairs and particles, with <|Delta|> <= sqrt(TAMSD),
    by at most 4 sqrt(3) eps sqrt(TAMSD) + 12 eps^2.  Everything after reading is float64
    (MDAnalysis' differences of float32 values are exact; granular's FFT TAMSD of
    start-relative positions rounds at ~1e-16 relative).  Lag times come from the
    file's float32 frame times: relative error <= 2 u.  Anything but the rounding -- a
    lost, reordered or wrapped frame, a wrong time -- is far outside these bounds."""
    from MDAnalysis.analysis.msd import EinsteinMSD

    s = Scene.random(100, 0.02, seed=7)
    times = np.linspace(0.0, 4.0, 81)  # ~4 collisions per particle: ballistic to collisional
    tr = Simulation(s).run(t_stop=times[-1], sample_times=times, store=("positions",))
    path = interop.write_trajectory(tmp_path / "gas.trr", tr.times, tr.positions, box=[1, 1, 1])
    u = mda.Universe.empty(s.n, trajectory=False)
    u.load_new(path)
    assert u.trajectory.n_frames == len(times)
    res = EinsteinMSD(u, select="all", msd_type="xyz", fft=False).run()

    lags = np.arange(1, len(times))
    ours = analysis.tamsd(tr.positions, lags)
    theirs = res.results.timeseries[1:]
    eps = 4 * 2.0**-24 * np.abs(tr.positions).max()
    bound = 4 * math.sqrt(3) * eps * np.sqrt(ours) + 12 * eps**2
    assert np.all(np.abs(theirs - ours) <= bound), np.max(np.abs(theirs - ours) / bound)
    np.testing.assert_allclose(res.results.delta_t_values[1:], times[lags], rtol=2 * 2.0**-24)
    assert ours[-1] > 100 * ours[0]  # not a trivial trajectory: it moved


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
    path = interop.write_trajectory(
        tmp_path / "gas.trr", tr2.times, tr2.positions, tr2.velocities, box=[1, 1, 1]
    )
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
    np.testing.assert_array_equal(u.dimensions, [1, 1, 1, 90, 90, 90])
    np.testing.assert_allclose(u.trajectory[3].positions[:, :2], x[3], rtol=1e-6)
    assert np.all(u.trajectory[3].positions[:, 2] == 0)


def _ring_counts_2d(positions, lengths, edges):
    """Ordered pairs (i != j) per distance bin in the plane, minimum image, float64."""
    counts = np.zeros(len(edges) - 1)
    for x in positions:
        d = x[:, None, :] - x[None, :, :]
        d -= lengths * np.round(d / lengths)
        r = np.sqrt((d**2).sum(-1))[~np.eye(len(x), dtype=bool)]
        counts += np.histogram(r, bins=edges)[0]
    return counts


@pytest.mark.filterwarnings("ignore:Reader has no dt")  # GSD frames have steps, not times
def test_a_2d_run_reaches_mdanalysis_with_one_box_that_its_analyses_accept(tmp_path):
    """The GSD file read by MDAnalysis and ``to_universe`` give the same box, with a volume
    (Lz = the longest edge), so InterRDF runs on both and agrees; the conversion to the 2D
    g(r) that the docs state matches a direct count of pairs in the plane."""
    from MDAnalysis.analysis.rdf import InterRDF

    lengths = np.array([2.0, 1.0])  # rectangular: Lz is the longest edge, not Lx or Ly
    s = Scene.random(300, 0.01, dim=2, box=([0.0, 0.0], lengths), seed=5)
    times = [0.0, 0.25, 0.5]
    tr = Simulation(s).run(t_stop=0.5, sample_times=times)
    tr.write(tmp_path / "run.gsd")
    from_file = mda.Universe(str(tmp_path / "run.gsd"))
    in_memory = tr.to_universe()
    trr = mda.Universe.empty(s.n, trajectory=False)
    trr.load_new(interop.write_trajectory(tmp_path / "run.trr", times, tr.positions, box=lengths))
    for u in (from_file, in_memory, trr):
        assert u.trajectory.n_frames == len(times)
        for ts in u.trajectory:
            np.testing.assert_array_equal(ts.dimensions, [2, 1, 2, 90, 90, 90])

    edges = np.linspace(0.02, 0.47, 16)
    kw = dict(nbins=len(edges) - 1, range=(edges[0], edges[-1]), exclusion_block=(1, 1))
    a = InterRDF(from_file.atoms, from_file.atoms, **kw).run().results
    b = InterRDF(in_memory.atoms, in_memory.atoms, **kw).run().results
    # the file's positions are wrapped and centred, the Universe's unwrapped: the minimum
    # image makes the distances equal up to float32 rounding (1e-7), which can move a pair
    # lying that close to a bin edge (expected ~1 of the ~3e5 ordered pairs in range); one
    # pair moved changes two ordered counts in each of two bins
    assert np.abs(a.count - b.count).max() <= 4
    np.testing.assert_allclose(a.rdf, b.rdf, rtol=0, atol=4 * b.rdf.max() / b.count.max())

    # the stated 2D g(r): InterRDF's times V_shell / (Lz A_ring) per bin
    r1, r2 = edges[:-1], edges[1:]
    shell, ring = 4 * np.pi * (r2**3 - r1**3) / 3, np.pi * (r2**2 - r1**2)
    g2d = b.rdf * shell / (2.0 * ring)
    n, area = s.n, float(np.prod(lengths))
    per_pair = len(times) * n * (n - 1) / area * ring  # expected count per bin at g = 1
    direct = _ring_counts_2d(tr.positions, lengths, edges) / per_pair
    np.testing.assert_allclose(g2d, direct, rtol=0, atol=4 / per_pair.min())


def test_a_walled_run_gets_the_same_box_in_a_universe_as_in_its_file(tmp_path):
    s = Scene.random(40, 0.03, dim=2, box=([0, 0], [1.0, 1.5]), boundary="walls", seed=2)
    tr = Simulation(s).run(t_stop=0.2, sample_times=[0.0, 0.2])
    tr.write(tmp_path / "w.gsd")
    expected = [1.0, 1.5, 1.5, 90, 90, 90]
    np.testing.assert_array_equal(mda.Universe(str(tmp_path / "w.gsd")).dimensions, expected)
    np.testing.assert_array_equal(tr.to_universe().dimensions, expected)
