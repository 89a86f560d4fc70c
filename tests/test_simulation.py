"""The event-driven engine: exact cases, conservation laws, a slow reference, determinism."""

import copy
import math
import pickle
import subprocess
import sys
import threading

import numpy as np
import pytest

import granular
from granular import Scene, Simulation

from helpers import reference_edmd
from helpers.scenes import min_distance_ratio, reference_scene, tracer_scene


def two_disks(v1, v2, xi=1.0, dim=2, boundary="walls", m=(1.0, 1.0), y2=0.5):
    pos = np.array([[0.3, 0.5], [0.7, y2]])
    if dim == 3:
        pos = np.hstack([pos, [[0.5], [0.5]]])
    return Scene(pos, [v1, v2], 0.05, masses=list(m), box=1.0, boundary=boundary, restitution=xi)


# -- exact cases ------------------------------------------------------------------------


@pytest.mark.parametrize("xi", [1.0, 0.8, 0.0])
def test_head_on_collision(xi):
    """Thesis Fig. 4.1: two disks approach along x, touch at t = (0.4 - 0.1) / 2, and leave
    with the 1D rule (2.27): equal masses swap for xi = 1, keep (1 -+ xi)/2 otherwise."""
    s = two_disks([1.0, 0.0], [-1.0, 0.0], xi=xi)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.2, sample_times=[0.0, 0.1499, 0.1501])
    assert sim.stats["pair_collisions"] == 1
    v = tr.velocities[-1]
    # v1' = (1-xi)/2 v1 + (1+xi)/2 v2 with v1 = 1, v2 = -1  ->  -xi
    np.testing.assert_allclose(v[:, 0], [-xi, xi], atol=1e-15)
    np.testing.assert_allclose(v[:, 1], 0.0, atol=0)
    gap = tr.positions[1, 1, 0] - tr.positions[1, 0, 0]
    assert gap == pytest.approx(0.1 + 2 * 1e-4, rel=1e-12)


def test_lone_disk_returns_after_four_bounces():
    """A disk at 45 degrees in a square box is back where it started, moving the same way,
    after hitting each of the four walls once (thesis 4.1)."""
    x0 = np.array([[0.3, 0.6]])
    v0 = np.array([[0.7, 0.7]])
    s = Scene(x0, v0, 0.1, box=1.0, boundary="walls")
    period = 2 * (1.0 - 0.2) / 0.7
    sim = Simulation(s)
    tr = sim.run(t_stop=period, sample_times=[period])
    np.testing.assert_allclose(tr.positions[0], x0, atol=1e-14)
    np.testing.assert_allclose(tr.velocities[0], v0, atol=1e-15)
    assert sim.stats["wall_collisions"] == 4


def test_periodic_free_flight_unwraps_exactly():
    """A lone particle crossing a periodic box many times: unwrapped x(t) = x0 + v t."""
    x0, v0 = np.array([[0.1, 0.2, 0.3]]), np.array([[3.1, -2.3, 1.7]])
    s = Scene(x0, v0, 0.01, box=1.0)
    times = np.linspace(0, 10, 21)
    tr = Simulation(s).run(t_stop=10, sample_times=times)
    np.testing.assert_allclose(tr.positions[:, 0], x0 + v0 * times[:, None], rtol=0, atol=1e-12)
    assert np.all(np.abs(Simulation(s).scene.positions) <= 1.0)


def test_inelastic_energy_loss_per_collision():
    """Energy lost in one collision of equal masses: 1/4 m (1 - xi^2) (dv . n)^2 (App. B),
    for an oblique impact."""
    xi = 0.6
    s = two_disks([1.0, 0.2], [-0.5, -0.1], xi=xi, y2=0.55)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.5, sample_times=[0.0, 0.5])
    assert sim.stats["pair_collisions"] == 1
    # contact geometry from the pre-collision straight lines
    x, v = s.positions, s.velocities
    dx, dv = x[1] - x[0], v[1] - v[0]
    b, a, c = dx @ dv, dv @ dv, dx @ dx - 0.1**2
    tc = (-b - math.sqrt(b * b - a * c)) / a
    n = (dx + dv * tc) / 0.1
    expected = 0.25 * (1 - xi**2) * (dv @ n) ** 2
    lost = tr.kinetic_energy[0] - tr.kinetic_energy[1]
    assert lost == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("masses", [(1.0, 1.0), (1.0, 5.0)])
def test_momentum_conserved_and_restitution_holds_for_mixtures(masses):
    """(2.10)-(2.11) conserve momentum for any masses, and the normal relative velocity
    is reversed and scaled by xi (2.12)."""
    xi = 0.7
    s = two_disks([1.0, 0.3], [-0.4, 0.0], xi=xi, m=masses, y2=0.54)
    tr = Simulation(s).run(t_stop=0.4, sample_times=[0.0, 0.4])
    m = np.array(masses)[:, None]
    np.testing.assert_allclose(
        (m * tr.velocities[1]).sum(0), (m * tr.velocities[0]).sum(0), atol=1e-15
    )
    # normal direction at contact from the post-collision state traced back
    x, v0, v1 = s.positions, tr.velocities[0], tr.velocities[1]
    dx, dv = x[1] - x[0], v0[1] - v0[0]
    b, a, c = dx @ dv, dv @ dv, dx @ dx - 0.1**2
    tc = (-b - math.sqrt(b * b - a * c)) / a
    n = (dx + dv * tc) / 0.1
    assert (v1[1] - v1[0]) @ n == pytest.approx(-xi * (dv @ n), rel=1e-12)


# -- conservation over many collisions ---------------------------------------------------


@pytest.mark.parametrize(
    "dim,boundary", [(3, "periodic"), (2, "periodic"), (3, "walls"), (2, "walls")]
)
def test_energy_and_momentum_conserved_over_a_million_collisions(dim, boundary):
    """xi = 1: kinetic energy constant to 1e-13 relative over >= 1e6 pair collisions; total
    momentum (periodic) constant to 1e-13 of sum m|v|.  Rounding alone: each collision
    perturbs E by ~1e-16 relative, a random walk over 1e6 collisions gives ~1e-13 at
    worst, and it is far smaller in practice because errors cancel."""
    n = 2000
    radius = 0.012 if dim == 3 else 0.006
    s = Scene.random(n, radius, dim=dim, boundary=boundary, seed=11)
    sim = Simulation(s)
    # 2 * 1e6 pair collisions / N = 1000 per particle, plus room for wall collisions
    tr = sim.run(stop_when={"collisions_per_particle": 1300.0}, store=(), sample_times=None)
    assert sim.stats["pair_collisions"] >= 1_000_000
    e0, e1 = tr.kinetic_energy[0], tr.kinetic_energy[-1]
    assert abs(e1 / e0 - 1) <= 1e-13
    if boundary == "periodic":
        scale = np.sum(s.masses * np.linalg.norm(s.velocities, axis=1))
        assert np.max(np.abs(tr.momentum[-1] - tr.momentum[0])) <= 1e-13 * scale
    final = sim.scene  # constructing it checks for overlaps and particles outside the box
    assert min_distance_ratio(final, final.positions) >= 1 - 1e-10


# the dense granular box is above the shear-instability size: the warning is right, and beside
# the point of this test
@pytest.mark.filterwarnings("ignore::granular.ClusteringWarning")
@pytest.mark.parametrize("dim,boundary", [(3, "periodic"), (2, "walls")])
def test_no_overlaps_at_any_sample_dense(dim, boundary):
    """Dense and granular (eta = 0.4 3D / 0.6 2D, xi = 0.9, TC model on): no pair is
    closer than contact at any sample, beyond rounding (1e-10 relative)."""
    n = 1000
    eta = 0.4 if dim == 3 else 0.6
    r = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3) if dim == 3 else math.sqrt(eta / (n * math.pi))
    s = Scene.random(
        n, r, dim=dim, boundary=boundary, restitution=0.9, contact_duration=1e-6, seed=5
    )
    tr = Simulation(s).run(t_stop=0.5, sample_times=np.linspace(0, 0.5, 26), store=("positions",))
    for x in tr.positions:
        assert min_distance_ratio(s, x) >= 1 - 1e-10


@pytest.mark.parametrize("n", [500, 6000])
def test_centre_of_mass_moves_with_total_momentum(n):
    """Unwrapped positions are the integral of the velocities: the centre of mass of a
    periodic system moves at P / M exactly, through collisions and image crossings.
    N = 6000 also exercises the engine's renumbering of particles in cell order (done
    for N >= 4096), which must stay invisible: sample k is particle k of the scene."""
    r = 0.02 * (500 / n) ** (1 / 3)
    s = Scene.random(n, r, seed=3, remove_drift=False)
    masses = np.linspace(1.0, 3.0, s.n)
    s = s.replace(masses=masses)
    times = np.linspace(0.0, 20.0, 41)
    sim = Simulation(s)
    tr = sim.run(t_stop=20.0, sample_times=times)
    np.testing.assert_array_equal(tr.positions[0], s.positions)
    np.testing.assert_array_equal(tr.velocities[0], s.velocities)
    M = masses.sum()
    P = (masses[:, None] * s.velocities).sum(0)
    com = np.einsum("i,tia->ta", masses, tr.positions) / M
    expected = com[0] + np.outer(times, P / M)
    np.testing.assert_allclose(com, expected, rtol=0, atol=1e-11)
    assert tr.kinetic_energy[-1] == pytest.approx(tr.kinetic_energy[0], rel=1e-13)
    # and particles did cross the box: displacements exceed its size
    assert np.abs(tr.positions[-1] - tr.positions[0]).max() > 2.0
    assert sim.stats["events"] > 16 * n  # past at least one renumbering for the large case
    np.testing.assert_allclose(sim.unwrapped_positions, tr.positions[-1], rtol=0, atol=1e-12)


# -- against the slow reference ------------------------------------------------------------


@pytest.mark.parametrize(
    "dim,boundary,xi,mixture",
    [
        (2, "walls", 1.0, False),
        (2, "periodic", 0.7, False),
        (3, "periodic", 1.0, False),
        (3, "walls", 0.8, False),
        (2, "periodic", 0.9, True),
        (3, "walls", 1.0, True),
    ],
)
def test_agrees_with_slow_reference(dim, boundary, xi, mixture):
    """Same events as an O(N^2)-per-event NumPy EDMD, sample by sample, for a short time
    (chaos amplifies rounding differences by ~e per collision, so the comparison stays
    short: ~10 collisions per particle, agreement to 1e-8).  Mixtures: radii spread by a
    factor 2, masses proportional to volume (large particles among small ones)."""
    s = reference_scene(dim, boundary, xi, mixture)
    n = s.n
    t_stop = 1.0
    times = np.linspace(0.0, t_stop, 11)
    sim = Simulation(s)
    tr = sim.run(t_stop=t_stop, sample_times=times)
    assert sim.stats["pair_collisions"] >= n
    rx, rv = reference_edmd.run_scene(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)


def test_prefetching_events_ahead_changes_no_event():
    """Where the cell grid is out of cache (its heads past _core.HEADS_CACHED bytes) the
    event loop prefetches three events ahead and keeps more keys in its queue's near heap
    (csrc/edmd.c, calendar.h): hints only, which must change nothing.  The same gas with
    cells 2.5 times wider (a grid in cache, no lookahead, other crossings, so rounding
    differs) agrees to 1e-8 after ~2.4 collisions per particle, as the slow reference
    does; a wrong or missed collision would move particles by their spacing (~0.05)."""
    n = 40_000
    radius = (0.065 / (n * 4 / 3 * math.pi)) ** (1 / 3)
    s = Scene.random(n, radius, dim=3, seed=5)
    runs = []
    for cell_factor in (1.0, 2.5):
        sim = Simulation(s, cell_factor=cell_factor)
        runs.append(sim.run(t_stop=0.04, sample_times=[0.02, 0.04]))
        heads = 4 * math.prod(sim.stats["cells"])
        assert (heads > granular._core.HEADS_CACHED) == (cell_factor == 1.0)
        assert sim.stats["collisions_per_particle"] > 2.0
    np.testing.assert_allclose(runs[0].positions, runs[1].positions, rtol=0, atol=1e-8)
    np.testing.assert_allclose(runs[0].velocities, runs[1].velocities, rtol=0, atol=1e-8)


# -- runs: continuation, stop criteria, sampling, determinism ------------------------------


@pytest.mark.parametrize("n", [300, 5000, 40_000])
def test_continued_run_equals_one_run(n):
    """40 000: a grid out of cache, where the loop prefetches events ahead (its hints
    carry over from one call to the next)."""
    s = Scene.random(n, 0.03 * (300 / n) ** (1 / 3), restitution=0.9, seed=2)
    one = Simulation(s).run(t_stop=2.0, sample_times=[0.5, 1.0, 2.0])
    sim = Simulation(s)
    a = sim.run(t_stop=1.0, sample_times=[0.5, 1.0])
    b = sim.run(t_stop=2.0, sample_times=[2.0])
    np.testing.assert_array_equal(np.concatenate([a.positions, b.positions]), one.positions)
    np.testing.assert_array_equal(np.concatenate([a.velocities, b.velocities]), one.velocities)


def test_energy_integral_is_the_same_in_one_run_or_many():
    """The running energy total is summed anew at fixed collision counts, not at the start
    of each engine call: a run cut into pieces of 997 events (many engine calls, across
    several re-sums: 60 collisions a particle) integrates the energy, hence the pressure, to
    the same bits as one run."""
    s = Scene.random(300, 0.03, restitution=0.8, seed=4)
    one = Simulation(s)
    one.run(stop_when={"collisions_per_particle": 60}, store=())
    pieces = Simulation(s)
    while pieces.stats["events"] < one.stats["events"]:
        left = one.stats["events"] - pieces.stats["events"]
        pieces.run(stop_when={"events": min(997, left)}, store=())
    assert pieces.time == one.time
    for key in ("kinetic_time_integral", "kinetic_energy", "pressure", "virial"):
        assert pieces.stats[key] == one.stats[key], key


def test_sampling_does_not_change_the_dynamics():
    s = Scene.random(300, 0.03, restitution=0.8, seed=4)
    sparse = Simulation(s).run(t_stop=3.0, sample_times=[3.0])
    dense = Simulation(s).run(t_stop=3.0, sample_times=np.linspace(0, 3.0, 997))
    np.testing.assert_array_equal(sparse.positions[-1], dense.positions[-1])
    np.testing.assert_array_equal(sparse.velocities[-1], dense.velocities[-1])


def test_same_seed_same_result_bit_for_bit():
    a = Scene.random(400, 0.03, restitution=0.8, seed=42)
    b = Scene.random(400, 0.03, restitution=0.8, seed=42)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.velocities, b.velocities)
    ta = Simulation(a).run(t_stop=2.0)
    tb = Simulation(b).run(t_stop=2.0)
    np.testing.assert_array_equal(ta.positions, tb.positions)
    c = Scene.random(400, 0.03, restitution=0.8, seed=43)
    assert not np.array_equal(a.positions, c.positions)


def test_stop_criteria():
    s = Scene.random(500, 0.025, restitution=0.8, seed=9)
    sim = Simulation(s)
    tr = sim.run(stop_when={"collisions_per_particle": 10})
    assert tr.stop_reason == "collisions"
    assert 10 <= tr.collisions_per_particle[-1] < 10 + 2.0 / s.n + 1e-12
    e_target = 0.25 * s.kinetic_energy / s.n
    tr = sim.run(stop_when={"kinetic_energy": e_target})
    assert tr.stop_reason == "kinetic_energy"
    assert tr.kinetic_energy[-1] / s.n <= e_target
    before = sim.stats["events"]
    tr = sim.run(stop_when={"events": 1234})
    assert tr.stop_reason == "events" and sim.stats["events"] - before == 1234
    tr = sim.run(t_stop=sim.time + 0.1, stop_when={"collisions_per_particle": 1e9})
    assert tr.stop_reason == "time"
    with pytest.raises(ValueError, match="needs a finite t_stop"):
        sim.run()


def _bouncing_energy_integral(speed, mass, t_end):
    """The integral over [0, t_end] of the kinetic energy of a disk of radius 0.05 that
    starts at the centre of the unit box moving along x at `speed`, between walls of
    restitution 1/2: each bounce halves the speed (exactly, in binary)."""
    t, gap, total, v = 0.0, 0.45, 0.0, speed
    while t + gap / v < t_end:
        total += 0.5 * mass * v * v * (gap / v)
        t, gap, v = t + gap / v, 0.9, 0.5 * v
    return total + 0.5 * mass * v * v * (t_end - t)


@pytest.mark.parametrize("speed", [1e15, 7e15, 1e17, 1e20])
def test_a_fast_disk_cooled_by_walls_keeps_a_true_energy_count(speed):
    """A disk at 1e15 between walls of restitution 1/2 loses 30 orders of magnitude of
    energy by t = 1; the engine's running energy total (updated by differences) carried
    rounding of 1e-16 of the first energy, which then exceeded the energy itself: below
    the "no criterion" sentinel it stopped the run at t = 1.2e-7 with stop_reason
    'kinetic_energy' (1e15, 1e20), above it the time integral of the energy, hence the
    pressure, came out 32 % or 3x too large (7e15, 1e17).  The run must go to t_stop and
    the integral match the bounce-by-bounce sum.  The engine sums the energy anew every 16
    collisions a particle; in between, the running total carries rounding of order u =
    1.1e-16 of the energy E_k it was summed at, for 16 flights that last about 2^16 times
    the first's: an error ~ u E_k 2^16 / v_k against an integral ~ 2 E_0 / v_0, so at most
    of order 2^16 u = 7e-12 relative (seen: up to 4e-12); the bound is 2e-11."""
    s = Scene([[0.5, 0.5]], [[speed, 0.0]], 0.05, boundary="walls", wall_restitution=0.5)
    sim = Simulation(s)
    tr = sim.run(1.0)
    assert tr.stop_reason == "time" and tr.times[-1] == 1.0
    exact = _bouncing_energy_integral(speed, s.masses[0], 1.0)
    assert sim.stats["kinetic_time_integral"] == pytest.approx(exact, rel=2e-11)


def test_an_energy_target_stops_at_the_bounce_that_reaches_it():
    """The same disk asked to stop at an energy 4**-30.5 of its start: each bounce
    quarters the energy, so the 31st is the first at or below the target -- not the
    27th, where the drifting running total had fallen to the target."""
    s = Scene([[0.5, 0.5]], [[1e15, 0.0]], 0.05, boundary="walls", wall_restitution=0.5)
    sim = Simulation(s)
    tr = sim.run(stop_when={"kinetic_energy": s.kinetic_energy * 4.0**-30.5})
    assert tr.stop_reason == "kinetic_energy"
    assert sim.stats["wall_collisions"] == 31
    assert tr.kinetic_energy[-1] == pytest.approx(s.kinetic_energy * 4.0**-31, rel=1e-15)


def test_log_spaced_samples_and_counters():
    s = Scene.random(500, 0.025, seed=1)
    times = np.concatenate([[0.0], np.logspace(-3, 1, 30)])
    tr = Simulation(s).run(t_stop=10.0, sample_times=times, store=())
    assert tr.positions is None and tr.velocities is None
    np.testing.assert_array_equal(tr.times, times)
    assert np.all(np.diff(tr.pair_collisions) >= 0)
    assert np.all(np.diff(tr.virial) >= 0)
    with pytest.raises(ValueError, match="did not store positions"):
        tr.msd()


def test_idle_system_stops():
    s = Scene([[0.5, 0.5]], [[0.0, 0.0]], 0.1)
    tr = Simulation(s).run(stop_when={"collisions_per_particle": 1})
    assert tr.stop_reason == "idle"


def test_seed_scenes():
    """Seed 000: 150 elastic disks between walls at +-3, energy and the speed of each
    collision pair conserved; seed 003: elastic spheres in a walled unit box."""
    b = Scene.seed_brownian_disks(seed=1)
    assert b.n == 150 and b.dim == 2 and b.boundary == "walls"
    np.testing.assert_array_equal(b.lower, [-3, -3])
    np.testing.assert_allclose(np.linalg.norm(b.velocities, axis=1), 1.0, rtol=1e-15)
    tr = Simulation(b).run(t_stop=50.0)
    assert tr.kinetic_energy[-1] == pytest.approx(tr.kinetic_energy[0], rel=1e-13)
    g = Scene.seed_ideal_gas(seed=2)
    sim = Simulation(g)
    tr = sim.run(t_stop=5.0)
    assert sim.stats["wall_collisions"] > 0
    assert tr.kinetic_energy[-1] == pytest.approx(tr.kinetic_energy[0], rel=1e-13)


def test_tc_model_counts_elastic_collisions():
    s = Scene.random(500, 0.03, restitution=0.5, contact_duration=1e-3, seed=8)
    sim = Simulation(s)
    sim.run(t_stop=5.0)
    assert 0 < sim.stats["tc_elastic_collisions"] < sim.stats["pair_collisions"]


def test_ctrl_c_leaves_a_consistent_state():
    """SIGINT during a long run raises KeyboardInterrupt between chunks; the simulation
    can then be read and continued."""
    import os
    import signal
    import threading

    s = Scene.random(2000, 0.02, seed=12)
    sim = Simulation(s)
    timer = threading.Timer(0.3, os.kill, args=(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(t_stop=1e6, store=())
    finally:
        timer.cancel()
    t = sim.time
    assert 0 < t < 1e6
    assert sim.scene.n == 2000  # state is valid: no overlaps, inside the box
    tr = sim.run(t_stop=t + 0.1)
    assert tr.kinetic_energy[-1] == pytest.approx(s.kinetic_energy, rel=1e-13)


class _InterruptedEngine:
    """The real engine, whose second advance() is cut short by Ctrl-C."""

    def __init__(self, engine):
        self.engine, self.calls = engine, 0

    def advance(self, *args, **kwargs):
        self.calls += 1
        if self.calls == 2:
            raise KeyboardInterrupt
        return self.engine.advance(*args, **kwargs)

    def __getattr__(self, name):
        return getattr(self.engine, name)


def test_ctrl_c_says_interrupted_and_keeps_the_samples():
    """Ctrl-C between chunks: the partial trajectory says "interrupted", not "error", and
    holds every sample up to the engine's clock."""
    sim = Simulation(Scene.random(200, 0.02, seed=12))
    sim._engine = _InterruptedEngine(sim._engine)
    times = np.linspace(0.0, 1e4, 10001)
    with pytest.raises(KeyboardInterrupt) as info:
        sim.run(t_stop=1e4, sample_times=times)
    tr = info.value.trajectory
    assert tr.stop_reason == "interrupted"
    assert 0 < sim.time < 1e4
    np.testing.assert_array_equal(tr.times, times[times <= sim.time])


def test_progress_bar_and_memory_guard(capsys):
    s = Scene.random(200, 0.03, seed=13)
    Simulation(s).run(t_stop=0.5, progress=True)
    Simulation(s).run(stop_when={"collisions_per_particle": 3}, progress=True)
    with pytest.raises(MemoryError, match="store=\\(\\)"):
        Simulation(s).run(
            t_stop=1.0, sample_times=np.linspace(0, 1, 10**7)
        )  # 10^7 x 200 x 3 x 2 doubles = 96 GB


@pytest.mark.skipif(
    "libasan" in __import__("os").environ.get("LD_PRELOAD", ""),
    reason="AddressSanitizer quarantines freed memory, so RSS grows anyway",
)
def test_repeated_simulations_do_not_leak():
    """Build and run many engines: resident memory must not grow with the count (each
    engine holds ~0.5 MB, so a leak of it would add ~100 MB over 200 rounds)."""

    def rss():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096

    s = Scene.random(2000, 0.02, seed=14)
    for _ in range(20):
        Simulation(s).run(t_stop=0.01, store=())
    before = rss()
    for _ in range(200):
        Simulation(s).run(t_stop=0.01, store=())
    assert rss() - before < 20e6


def test_unreachable_stops_raise_instead_of_running_forever():
    """A run with no time limit must end: an energy target below the energy of an
    elastic gas is refused at once; a collision target that no collision will ever meet
    (a lone sphere flying through a periodic box) raises NoProgressError after a bounded
    number of events (10^7, about a second)."""
    gas = Scene.random(50, 0.02, seed=1)
    with pytest.raises(ValueError, match="can never be reached"):
        Simulation(gas).run(stop_when={"kinetic_energy": 0.01})
    lone = Scene([[0.5, 0.5, 0.5]], [[1.0, 0.3, 0.2]], 0.01)
    sim = Simulation(lone)
    with pytest.raises(granular.NoProgressError, match="no collision"):
        sim.run(stop_when={"collisions_per_particle": 1})
    assert sim.stats["pair_collisions"] == 0 and sim.stats["cell_crossings"] >= 10**7
    # with a time limit the same run is fine
    assert sim.run(t_stop=sim.time + 1.0).stop_reason == "time"


def test_bad_stop_and_sample_arguments():
    sim = Simulation(Scene.random(50, 0.02, seed=1))
    with pytest.raises(ValueError, match="must be numbers"):
        sim.run(stop_when={"collisions_per_particle": float("nan")})
    with pytest.raises(ValueError, match="whole number"):
        sim.run(stop_when={"events": 1.5})
    with pytest.raises(ValueError, match="whole number"):
        sim.run(stop_when={"events": -1})
    with pytest.raises(ValueError, match="one-dimensional"):
        sim.run(1.0, sample_times=[[0.0, 0.5], [0.6, 1.0]])


@pytest.mark.parametrize("xi", [1.0, 0.7])
def test_stats_pressure_is_the_time_average(xi):
    """stats['pressure'] uses the time integral of the kinetic energy kept by the
    engine.  Against the trajectory's trapezoid over dense samples: the kinetic energy
    is piecewise constant and (for xi < 1) falls monotonically, so the trapezoid's
    error is at most (K_0 - K_end) * dt / 2 in the integral; for xi = 1 the two agree
    to rounding."""
    s = Scene.random(400, 0.03, restitution=xi, seed=21)
    sim = Simulation(s)
    times = np.linspace(0.0, 4.0, 4001)
    tr = sim.run(t_stop=4.0, sample_times=times, store=())
    c = sim.stats
    p_traj = tr.pressure()
    k = tr.kinetic_energy
    bound = (k[0] - k[-1]) * (times[1] - times[0]) / 2  # error of the kinetic integral
    dp = 2.0 * bound / times[-1] / (s.dim * s.volume)
    assert abs(c["pressure"] - p_traj) <= dp + 1e-12 * p_traj
    if xi < 1:  # the current kinetic energy (the old formula) would be far off
        p_now = (2 * c["kinetic_energy"] + c["virial"] / c["time"]) / (s.dim * s.volume)
        assert abs(p_now - p_traj) > 100 * (dp + 1e-12 * p_traj)


def test_collapse_keeps_the_samples_taken_before_it():
    """The error carries the trajectory up to the collapse: three disks in a line with
    xi below 7 - 4 sqrt 3 collapse at t = 0.1 (tests/test_scene.py)."""
    s = Scene(
        [[0.3, 0.5], [0.5, 0.5], [0.7, 0.5]],
        [[1, 0], [0, 0], [-1, 0]],
        0.05,
        boundary="walls",
        restitution=0.05,
    )
    times = np.linspace(0.0, 10.0, 1001)
    with pytest.raises(granular.InelasticCollapseError) as info:
        Simulation(s).run(t_stop=10.0, sample_times=times)
    tr = info.value.trajectory
    assert tr.stop_reason == "error"
    assert 0 < len(tr.times) < len(times) and tr.times[-1] <= info.value.time
    np.testing.assert_array_equal(tr.positions[0], s.positions)


# -- a large tracer among small particles ---------------------------------------------------


@pytest.mark.parametrize(
    "dim,boundary", [(2, "periodic"), (2, "walls"), (3, "periodic"), (3, "walls")]
)
def test_large_tracer_agrees_with_slow_reference(dim, boundary):
    """A tracer five times wider than the rest stays out of the cell grid (cells sized by
    the small particles, as the cell count shows); its collisions must be exactly those
    of the O(N^2) reference.  Short runs (~1-2 collisions per particle), where chaos has
    amplified rounding differences to ~1e-9 at most (measured), so agreement to 1e-8."""
    n, r, big = (40, 0.02, 0.1) if dim == 2 else (60, 0.03, 0.15)
    s = tracer_scene(n, r, big, dim, boundary, 0.9, seed=3)
    times = np.linspace(0.0, 0.5, 11)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.5, sample_times=times)
    assert min(sim.stats["cells"][:dim]) > 1.0 / (2 * big)  # finer than the tracer
    assert sim.stats["pair_collisions"] >= n // 3
    rx, rv = reference_edmd.run_scene(s, 0.5, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)


@pytest.mark.parametrize("dim", [2, 3])
def test_large_tracer_long_run_conserves_and_never_overlaps(dim):
    """Many collisions of a big tracer (radius 12 times the rest) in an elastic gas:
    energy to rounding, no overlap at any sample -- the tracer's block scans and
    layer scans miss no partner.  The tracer does collide throughout: ~80 (3D) and ~470
    (2D) collisions in 20 sample intervals, so its velocity changes in nearly every one
    (an interval without a collision has probability e^-4 ~ 2% in 3D); at least 15 of 20
    are required.  big_ratio=inf puts everyone in one grid, coarse as the tracer."""
    n, r = (1500, 0.004) if dim == 2 else (1500, 0.006)
    s = tracer_scene(n, r, 12 * r, dim, "periodic", 1.0, seed=4)
    times = np.linspace(0.0, 2.0, 21)
    sim = Simulation(s)
    tr = sim.run(t_stop=2.0, sample_times=times)
    assert tr.kinetic_energy[-1] == pytest.approx(tr.kinetic_energy[0], rel=1e-12)
    tree_ok = [min_distance_ratio(s, x) >= 1 - 1e-10 for x in tr.positions]
    assert all(tree_ok)
    changed = np.any(np.diff(tr.velocities[:, 0], axis=0) != 0, axis=1)
    assert changed.sum() >= 15
    coarse = Simulation(s, big_ratio=math.inf)
    assert min(coarse.stats["cells"][:dim]) < min(sim.stats["cells"][:dim])


# -- unreachable energy targets, rounding past t_stop, heated walls, threads ---------------


def test_energy_target_without_a_dissipative_channel_is_refused():
    """A lone particle cannot collide with anyone, and elastic walls take no energy: the
    energy never falls, so the target is refused at once (this used to run forever)."""
    lone = Scene.random(1, 0.05, boundary="walls", restitution=0.9, seed=3)
    with pytest.raises(ValueError, match=r"can never be reached.*single particle"):
        Simulation(lone).run(stop_when={"kinetic_energy": 0.1})
    # absorbing walls do take energy: the same target is reached
    sim = Simulation(lone.replace(wall_restitution=0.5))
    assert sim.run(stop_when={"kinetic_energy": 0.1}).stop_reason == "kinetic_energy"


def test_stall_guard_counts_only_progress_towards_the_criterion(monkeypatch):
    """Two inelastic disks on parallel lines between elastic walls never meet: wall hits go
    on for ever but take no energy.  Under an energy target the guard counts only
    dissipative collisions and raises after its limit (lowered here to 1e5 events to keep
    the test fast); under a collision target the wall hits are progress and it ends."""
    monkeypatch.setattr(granular.simulation._StallGuard, "MIN_LIMIT", 10**5)
    s = Scene(
        [[0.3, 0.25], [0.6, 0.75]],
        [[1.0, 0.0], [-1.0, 0.0]],
        0.05,
        box=1.0,
        boundary="walls",
        restitution=0.9,
    )
    sim = Simulation(s)
    with pytest.raises(granular.NoProgressError, match="no dissipative collision"):
        sim.run(stop_when={"kinetic_energy": 0.1})
    # the wall hits the old guard took for progress did happen (1 in 4 events here)
    assert sim.stats["pair_collisions"] == 0 and sim.stats["wall_collisions"] > 10**4
    tr = sim.run(stop_when={"collisions_per_particle": sim.stats["collisions_per_particle"] + 10})
    assert tr.stop_reason == "collisions"


def test_samples_past_t_stop_by_rounding_are_all_returned():
    """Sample times past t_stop by no more than rounding (1e-12 relative) are taken at the
    times asked for, not dropped; beyond rounding they are refused."""
    sim = Simulation(Scene.random(50, 0.02, seed=1))
    asked = [1 + 5e-13, 1 + 9e-13]
    tr = sim.run(1.0, sample_times=asked)
    np.testing.assert_array_equal(tr.times, asked)
    assert sim.time == asked[-1]
    # a log-spaced grid ending at t_stop up to rounding keeps all its samples
    times = np.logspace(-3, math.log10(3.0), 30)
    tr = Simulation(Scene.random(50, 0.02, seed=1)).run(3.0, sample_times=times)
    np.testing.assert_array_equal(tr.times, times)
    with pytest.raises(ValueError, match="past t_stop"):
        Simulation(Scene.random(50, 0.02, seed=1)).run(1.0, sample_times=[0.5, 1 + 1e-9])


def test_heated_walls_blowing_up_are_not_called_a_collapse():
    """Walls with restitution 1.5 multiply a particle's normal speed by 1.5 at each hit, so
    the energy grows without bound until the event times cannot be resolved in float64:
    a HeatedWallsError, with the energy ratio, not an inelastic collapse.  A real collapse
    (three disks in a line, xi = 0.05 < 7 - 4 sqrt 3, at t = 0.1, long before any wall
    hit) in a box with heated walls stays an InelasticCollapseError."""
    s = Scene.random(4, 0.05, dim=3, boundary="walls", wall_restitution=1.5, seed=3)
    with pytest.raises(
        granular.HeatedWallsError, match=r"wall_restitution = 1.5 > 1\) pumped .* float64"
    ) as info:
        Simulation(s).run(10.0)
    assert isinstance(info.value, granular.GranularError) and isinstance(info.value, RuntimeError)
    assert not isinstance(info.value, granular.InelasticCollapseError)
    assert info.value.value > 1e6 and 0 < info.value.time < 10.0
    assert info.value.trajectory.stop_reason == "error"
    line = Scene(
        [[0.3, 0.5], [0.5, 0.5], [0.7, 0.5]],
        [[1, 0], [0, 0], [-1, 0]],
        0.05,
        boundary="walls",
        restitution=0.05,
        wall_restitution=1.01,
    )
    with pytest.raises(granular.InelasticCollapseError):
        Simulation(line).run(10.0)


class _BlockingEngine:
    """The real engine, whose advance() signals that it is running and waits for a go."""

    def __init__(self, engine):
        self.engine, self.inside, self.go = engine, threading.Event(), threading.Event()

    def advance(self, *args, **kwargs):
        self.inside.set()
        assert self.go.wait(10)
        return self.engine.advance(*args, **kwargs)

    def __getattr__(self, name):
        return getattr(self.engine, name)


def test_a_second_concurrent_run_raises_at_once():
    """While one thread is inside run (held inside the engine until released), a second
    run of the same Simulation from another thread raises at once; after the first run
    ends, runs work again.  The first run's samples are untouched."""
    sim = Simulation(Scene.random(50, 0.02, seed=1))
    blocking = sim._engine = _BlockingEngine(sim._engine)
    result = {}
    first = threading.Thread(target=lambda: result.setdefault("tr", sim.run(1.0)))
    first.start()
    try:
        assert blocking.inside.wait(10)
        with pytest.raises(RuntimeError, match="another thread is running this Simulation"):
            sim.run(2.0)
    finally:
        blocking.go.set()
        first.join(10)
    assert result["tr"].times[-1] == 1.0 and sim.time == 1.0
    assert sim.run(2.0).times[-1] == 2.0


def test_copying_or_pickling_a_simulation_gives_an_independent_engine():
    """Copies go through a checkpoint (granular/checkpoint.py): never a shared C engine.
    Bit-for-bit continuation is tested in test_checkpoint.py."""
    sim = Simulation(Scene.random(50, 0.02, seed=1))
    for copier in (copy.copy, copy.deepcopy, lambda s: pickle.loads(pickle.dumps(s))):
        other = copier(sim)
        assert other._engine is not sim._engine
        other.run(0.1)
        assert other.time == 0.1 and sim.time == 0.0


def test_plot_and_interop_are_attributes_imported_lazily():
    """The README writes granular.plot.msd after `import granular`; importing granular
    alone must not pull in matplotlib or MDAnalysis (fresh interpreter)."""
    code = (
        "import sys, granular\n"
        "assert 'matplotlib' not in sys.modules and 'MDAnalysis' not in sys.modules\n"
        "assert callable(granular.plot.msd)\n"
        "assert callable(granular.interop.to_universe)\n"
        "assert 'plot' in dir(granular)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    with pytest.raises(AttributeError, match="no attribute 'nonesuch'"):
        _ = granular.nonesuch


def test_trajectory_msd_and_tamsd_select_particles_and_take_lags_in_samples():
    """A tracer's MSD is the full per-particle data restricted to it; lag_samples k is the
    lag k * dt in time."""
    s = Scene.random(60, 0.02, seed=5)
    tr = Simulation(s).run(2.0, sample_times=np.linspace(0.0, 2.0, 21))
    d = tr.positions - tr.positions[0]
    np.testing.assert_allclose(tr.msd(particles=[7]), (d[:, 7] ** 2).sum(axis=1), rtol=1e-14)
    mask = np.arange(60) < 10
    np.testing.assert_allclose(
        tr.msd(particles=mask), (d[:, :10] ** 2).sum(axis=2).mean(axis=1), rtol=1e-14
    )
    lags = np.array([0.1, 0.5, 1.0])
    np.testing.assert_allclose(
        tr.tamsd(lag_samples=[1, 5, 10], particles=[7]), tr.tamsd(lags, particles=[7]), rtol=1e-12
    )
    per = tr.tamsd(lags, per_particle=True)
    np.testing.assert_allclose(tr.tamsd(lags, particles=[7]), per[7], rtol=1e-12)


def test_a_gas_too_slow_for_float64_is_not_advanced():
    """Below speeds x diameter ~ 1e-140 the contact-time quadratic underflows and pairs
    would pass through each other: a scene that slow, or one that absorbing walls cool that
    far (wall restitution 1e-30: each hit takes 30 decades off a speed), raises
    FrozenGasError instead of returning overlapping particles.  A gas at rest runs."""
    pos = np.array([[0.2, 0.5], [0.5, 0.5], [0.8, 0.5]])
    slow = Scene(pos, np.full((3, 2), 1e-150), 0.05, boundary="walls")
    with pytest.raises(granular.FrozenGasError, match=r"below .* float64 can no longer"):
        Simulation(slow).run(t_stop=1e200)
    rest = Scene(pos, np.zeros((3, 2)), 0.05, boundary="walls")
    assert Simulation(rest).run(t_stop=1e200).stop_reason == "time"
    s = Scene.random(3, 0.05, dim=2, boundary="walls", wall_restitution=1e-30, seed=1)
    with pytest.raises(granular.FrozenGasError) as caught:
        Simulation(s).run(t_stop=1e250)
    assert caught.value.value < 1e-270  # underflowed to 0, possibly


@pytest.mark.parametrize("target", [0.0, -1.0, 1e-300])
def test_an_energy_target_float64_cannot_reach_is_refused(target):
    """A cooling gas only approaches zero energy: a target of 0 used to run forever."""
    s = Scene.random(20, 0.05, dim=3, restitution=0.9, seed=2)
    with pytest.raises(ValueError, match=r"kinetic_energy .* is not above"):
        Simulation(s).run(stop_when={"kinetic_energy": target})


def test_moving_lattice_many_equal_event_times():
    """A lattice moving as one never collides, and its particles cross cell walls in
    groups at identical instants: up to a thousand equal keys at once in the event
    queue's current bucket (its near heap), which runs empty between groups.  Every
    particle must end exactly at x0 + v t (only rounding: 1e-12 over a box of size 1)."""
    k = 10
    g = (np.arange(k) + 0.5 + 0.013) / k
    pos = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    v = np.array([1.0, 0.5, 0.25])
    sim = Simulation(Scene(pos, np.tile(v, (k**3, 1)), 0.02))
    t = 2.37
    sim.run(t_stop=t, store=())
    assert sim.stats["pair_collisions"] == 0
    assert sim.stats["cell_crossings"] > 10 * k**3  # many groups went through the queue
    np.testing.assert_allclose(sim.unwrapped_positions, pos + v * t, rtol=0, atol=1e-12)


def test_a_lattice_on_the_cell_faces_agrees_with_slow_reference():
    """A lattice whose sites lie on the cell faces, to within 1e-13: every particle's first
    event is a face crossing at t ~ 1e-13, so the event queue takes its first bucket width
    from keys bunched at one instant, and all later keys land far beyond its calendar
    (csrc/calendar.c: it then rebuilds from them rather than walk them at every event).
    Its events must be those of the O(N^2) reference, to 1e-8 as in
    test_agrees_with_slow_reference, over ~2 collisions per particle."""
    k = 5  # 125 spheres; the engine makes 2k cells a side, so faces at the sites
    n = k**3
    radius = (0.065 * 3 / (4 * math.pi * n)) ** (1 / 3)
    g = (2 * np.arange(k) + 1) / (2 * k)
    pos = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    pos = (pos + np.random.default_rng(5).uniform(-1e-13, 1e-13, size=pos.shape)) % 1.0
    vel = np.random.default_rng(1).normal(size=(n, 3))
    s = Scene(pos, vel, radius)
    times = np.linspace(0.0, 0.3, 6)
    sim = Simulation(s)
    tr = sim.run(t_stop=times[-1], sample_times=times)
    assert sim.stats["cells"] == (2 * k,) * 3
    assert sim.stats["pair_collisions"] >= n
    rx, rv = reference_edmd.run_scene(s, times[-1], times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)
