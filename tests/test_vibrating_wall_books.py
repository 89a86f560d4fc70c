"""A vibrating wall's energy books per sample (Trajectory.wall_work, .collision_loss and
.wall_power, csrc/sample.c): cumulative as the counters, equal to stats at the ends,
balancing the energy window by window, in checkpoints and GSD files, and the steady state's
power balance."""

import math

import numpy as np
import pytest

import granular
from granular import Scene, Simulation, VibratingWall

# The gas of reproduce_vibrated (docs/vibrated.md): 200 disks, r = 0.01, xi = 0.99, in the unit
# box over a sine floor of A = 0.002, omega = 250 (peak speed 0.5), started near the balance's
# temperature (T ~ 1.3)
N, RADIUS, XI, AMPLITUDE, OMEGA = 200, 0.01, 0.99, 0.002, 250.0


def _gas(seed=1, **kw):
    start = Scene.random(
        N, RADIUS, dim=2, box=((0.0, 2 * AMPLITUDE), (1.0, 1.0)), boundary="walls",
        temperature=1.3, seed=seed,
    )  # fmt: skip
    wall = VibratingWall(1, "lower", AMPLITUDE, OMEGA)
    return start.replace(box=1.0, vibrating_wall=wall, restitution=XI, **kw)


def test_the_samples_carry_the_books_and_they_end_at_the_stats():
    """The series are cumulative since the simulation began, like wall_impulse: the first
    sample (at the start of the run) holds the stats before it, the last (at t_stop) the
    stats after it, bit for bit; and in every window between samples the kinetic energy
    changed by the work less the loss, to rounding (the books are kept at every hit and
    collision: a series sampled late or early by one event would miss by a collision's
    loss, ~1e-3 of a window's)."""
    sim = Simulation(_gas())
    sim.run(t_stop=1.0, store=())
    before = sim.stats
    times = np.linspace(1.0, 3.0, 41)
    tr = sim.run(t_stop=3.0, sample_times=times, store=())
    after = sim.stats
    for name in ("wall_work", "collision_loss"):
        series = getattr(tr, name)
        assert series.shape == (41,)
        assert series[0] == before[name] and series[-1] == after[name]
    # collisions only lose (xi < 1); the wall's work in a window may be negative (a hit while
    # the wall retreats takes energy), but it heats on the whole
    assert np.all(np.diff(tr.collision_loss) > 0)
    assert tr.wall_work[-1] > tr.wall_work[0]
    work, loss = np.diff(tr.wall_work), np.diff(tr.collision_loss)
    gain = np.diff(tr.kinetic_energy)
    np.testing.assert_allclose(gain, work - loss, rtol=0, atol=1e-10 * loss.max())
    assert np.min(loss) > 1e-2 * loss.max()  # every window holds many collisions
    # wall_power: the same books per unit time, per window and over the run
    p_in, p_out = tr.wall_power(per_window=True)
    np.testing.assert_allclose(p_in, work / np.diff(times), rtol=1e-15)
    np.testing.assert_allclose(p_out, loss / np.diff(times), rtol=1e-15)
    total = tr.wall_power()
    assert total[0] == pytest.approx((after["wall_work"] - before["wall_work"]) / 2.0, rel=1e-14)
    assert total[1] == pytest.approx(
        (after["collision_loss"] - before["collision_loss"]) / 2.0, rel=1e-14
    )


def test_the_books_balance_the_energy_under_gravity_per_window():
    """A vibrating floor under gravity: per window, kinetic plus potential energy changed by
    the floor's work less the collisions' loss, to rounding."""
    g = 1.5
    s = _gas(seed=2, gravity=(0.0, -g))
    sim = Simulation(s)
    times = np.linspace(0.0, 2.0, 21)
    tr = sim.run(t_stop=2.0, sample_times=times, store=("positions",))
    energy = tr.kinetic_energy + g * np.einsum("n,tn->t", s.masses, tr.positions[:, :, 1])
    books = np.diff(tr.wall_work) - np.diff(tr.collision_loss)
    scale = np.max(np.abs(energy))
    np.testing.assert_allclose(np.diff(energy), books, rtol=0, atol=1e-10 * scale)
    assert np.max(np.abs(books)) > 1e-4 * scale  # the windows are not in balance by chance


def test_the_mean_power_balances_the_mean_loss_in_the_steady_state():
    """Settled for 5 time units (~100 collisions a particle: the gas relaxes in
    1 / (1 - xi^2) = 50), then 40 time units in 10 blocks of 4 (each ~80 collisions a
    particle: the energy's correlation time is ~1 / (1 - xi^2) collisions, so the blocks are
    nearly independent).  The blocks' mean of input - loss is zero within 3 standard
    errors of their mean (it is the energy's change over the run, over its length: it
    vanishes only in a steady state; measured 1.1 +- 1.3 on an input of 51.6, the error
    the energy's fluctuation), and the mean input is the mean loss within the same error,
    which resolves the balance to better than 30 % of the input."""
    sim = Simulation(_gas(seed=3))
    sim.run(t_stop=5.0, store=())
    blocks = 10
    times = np.linspace(5.0, 45.0, blocks * 10 + 1)
    tr = sim.run(t_stop=45.0, sample_times=times, store=())
    span = (times[-1] - times[0]) / blocks
    work = (tr.wall_work[10::10] - tr.wall_work[:-10:10]) / span
    loss = (tr.collision_loss[10::10] - tr.collision_loss[:-10:10]) / span
    net = work - loss
    error = np.std(net, ddof=1) / math.sqrt(blocks)
    assert abs(np.mean(net)) <= 3 * error
    p_in, p_out = tr.wall_power()
    assert p_in == pytest.approx(np.mean(work), rel=1e-12)
    assert abs(p_in - p_out) <= 3 * error
    assert 3 * error < 0.3 * p_in


def test_without_a_vibrating_wall_there_are_no_books():
    s = Scene.random(20, 0.03, dim=2, boundary="walls", seed=1)
    tr = Simulation(s).run(1.0, sample_times=[0.0, 1.0])
    assert tr.wall_work is None and tr.collision_loss is None
    with pytest.raises(ValueError, match="no vibrating wall"):
        tr.wall_power()


def test_a_checkpoint_continues_the_books_bit_for_bit(tmp_path):
    """Saved mid-run and loaded, the books (engine state) continue with the same bits."""
    sim = Simulation(_gas(seed=4))
    sim.run(t_stop=0.7, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    times = np.linspace(0.7, 1.5, 9)
    a = sim.run(1.5, sample_times=times, store=())
    b = loaded.run(1.5, sample_times=times, store=())
    assert np.array_equal(a.wall_work, b.wall_work)
    assert np.array_equal(a.collision_loss, b.collision_loss)


def test_gsd_carries_the_books(tmp_path):
    """Written to the GSD log (granular/wall_work, granular/collision_loss) and read back to
    the bit; a run without a vibrating wall writes neither."""
    pytest.importorskip("gsd")
    sim = Simulation(_gas(seed=5))
    tr = sim.run(0.5, sample_times=np.linspace(0.0, 0.5, 6))
    tr.write(tmp_path / "v.gsd")
    back = granular.read(tmp_path / "v.gsd")
    assert np.array_equal(back.wall_work, tr.wall_work)
    assert np.array_equal(back.collision_loss, tr.collision_loss)
    s = Scene.random(20, 0.03, dim=2, boundary="walls", seed=1)
    Simulation(s).run(0.5, sample_times=[0.0, 0.5]).write(tmp_path / "p.gsd")
    assert granular.read(tmp_path / "p.gsd").wall_work is None
