"""The vibrating wall (granular/walls.py, csrc/vibwall.h): hits found at the right time all
around the cycle (against a brute-force search, helpers/vibwall_reference.py, and the slow
EDMD reference), grazing hits, the energy bookkeeping, the steady state's energy balance,
bad input, and checkpoints that continue bit for bit mid-cycle."""

import math

import numpy as np
import pytest

import granular
from granular import Scene, Simulation, VibratingWall

from helpers import reference_edmd, vibwall_reference

R = 0.01
A = 0.05
OMEGA = 10.0
PERIOD = 2 * math.pi / OMEGA


def _lone(wall, y, vy, box=1.0):
    """One disk at height y (along axis 1), moving along it only, in a unit box."""
    return Scene([[0.5, y]], [[0.0, vy]], R, box=box, boundary="walls", vibrating_wall=wall)


def _first_wall_time(scene):
    sim = Simulation(scene)
    sim.run(stop_when={"collisions_per_particle": 1}, store=())
    assert sim.stats["wall_collisions"] == 1
    return sim.time, sim.scene.velocities[0, 1]


def _cases(wall):
    """(y, vy): from far away, at rest in the band, moving away slower than the wall, and
    moving towards it slower than the wall (hit on the wall's way back, or chased on its
    way down), for the wall's side (mirrored for the upper one).  With the wall within 5 %
    of A of its innermost point there is no room in its reach: the far case only."""
    X0 = vibwall_reference.position(wall, 0.0, 0.0, 1.0)
    peak = A * OMEGA
    room = 2 * A - X0 if wall.side == "lower" else X0 - (1 - 2 * A)
    out = []
    cases = ((0.3, -20 * peak), (0.5, 0.0), (0.5, 0.1 * peak), (0.2, -0.3 * peak))
    for depth, speed in cases if room > 0.05 * A else cases[:1]:
        if wall.side == "lower":
            y = X0 + R + depth * (2 * A - X0) + (0.2 if speed < -peak else 0.0)
            out.append((y, speed))
        else:
            y = X0 - R - depth * (X0 - (1 - 2 * A)) - (0.2 if speed < -peak else 0.0)
            out.append((y, -speed))
    return out


@pytest.mark.parametrize("waveform", ["sine", "triangle"])
@pytest.mark.parametrize("side", ["lower", "upper"])
def test_hits_all_around_the_cycle_match_a_brute_force_search(side, waveform):
    """16 phases around the cycle, four kinds of approach each: the engine's first wall
    collision is the brute-force search's first contact (a grid of 5000 points a period,
    bisected; its grid misses only touches shallower than A omega^2 step^2 / 8 = 1e-8 A,
    which these are not), or the fixed wall's where the particle gets there first.  The search's
    times are good to ~1e-14 of a period; the engine's to full precision: 1e-9 leaves room
    for the wave's rounding at the hit (gap error 1e-16 over a closing speed >= 1e-6)."""
    for phase in np.linspace(0.0, 2 * np.pi, 16, endpoint=False):
        wall = VibratingWall(1, side, A, OMEGA, phase=phase, waveform=waveform)
        for y, vy in _cases(wall):
            if side == "lower":
                fixed = (1.0 - R - y) / vy if vy > 0 else np.inf
            else:
                fixed = (R - y) / vy if vy < 0 else np.inf
            horizon = min(fixed, 10 * PERIOD)
            expected = min(
                vibwall_reference.first_hit(wall, 0.0, 1.0, 0.0, y, vy, R, horizon, 5000), fixed
            )
            assert expected < np.inf
            t, _ = _first_wall_time(_lone(wall, y, vy))
            assert t == pytest.approx(expected, abs=1e-9), (phase, y, vy)


def test_a_grazing_hit_at_the_peak_is_found_and_a_near_miss_is_not():
    """A disk at rest a depth delta = 1e-9 A inside the sine wall's reach is touched at
    sin(omega t) = 1 - delta / A, 4.5e-5 rad before the peak; one delta beyond it never."""
    wall = VibratingWall(1, "lower", A, OMEGA)
    delta = 1e-9 * A
    t, vy = _first_wall_time(_lone(wall, 2 * A + R - delta, 0.0))
    assert t == pytest.approx(math.asin(1 - delta / A) / OMEGA, abs=1e-9)
    assert vy > 0
    sim = Simulation(_lone(wall, 2 * A + R + delta, 0.0))
    sim.run(t_stop=20 * PERIOD, store=())
    assert sim.stats["wall_collisions"] == 0


def test_a_wall_that_catches_up_with_a_receding_particle():
    """The wall moving up faster than the disk: the disk, just off the wall, is hit again
    while the wall still climbs (the hit on the wall's way up after a hit), and leaves with
    2U - v (elastic, in the wall's frame)."""
    wall = VibratingWall(1, "lower", A, OMEGA, phase=-math.pi / 2)  # at rest at the bottom
    scene = _lone(wall, R + 1e-3, 0.01)  # t = 0: the wall at 0
    t, vy = _first_wall_time(scene)
    expected = vibwall_reference.first_hit(wall, 0.0, 1.0, 0.0, R + 1e-3, 0.01, R, PERIOD)
    assert t == pytest.approx(expected, abs=1e-9)
    U = vibwall_reference.velocity(wall, t)
    assert vy == pytest.approx(2 * U - 0.01, rel=1e-12)


GAS_CASES = [
    ("lower", "sine", 1.0, 1.0),
    ("upper", "triangle", 0.9, 0.8),
]


def _gas(side, waveform, xi, ew, n=12, seed=3, radius=0.06):
    """n disks in the part of a unit box the wall's sweep leaves free, and the wall."""
    a = 0.04
    box = ((0.0, 2 * a), (1.0, 1.0)) if side == "lower" else ((0.0, 0.0), (1.0, 1 - 2 * a))
    s = Scene.random(n, radius, dim=2, box=box, boundary="walls", seed=seed)
    wall = VibratingWall(1, side, a, 12.0, phase=0.7, waveform=waveform)
    return s.replace(
        box=1.0,
        vibrating_wall=wall,
        restitution=xi,
        wall_restitution=ew,
        contact_duration=1e-6 if xi < 1 else 0.0,
    )


@pytest.mark.parametrize(("side", "waveform", "xi", "ew"), GAS_CASES)
def test_a_small_gas_agrees_with_the_slow_reference(side, waveform, xi, ew):
    """12 disks, the wall one of them hits over and over: the same events as the O(N^2)
    reference with its brute-force wall (helpers/reference_edmd.py), sample by sample, to
    1e-8 (the comparison stays short: chaos amplifies rounding ~e-fold per collision)."""
    s = _gas(side, waveform, xi, ew)
    times = np.linspace(0.0, 0.6, 7)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.6, sample_times=times)
    assert sim.stats["wall_collisions"] >= 10
    moving = sim.stats["wall_work"] != 0.0
    assert moving
    rx, rv = reference_edmd.run_scene(s, 0.6, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)


@pytest.mark.parametrize(("side", "waveform", "xi", "ew"), GAS_CASES)
def test_the_kinetic_energy_changes_by_the_walls_work_less_the_loss(side, waveform, xi, ew):
    """Over ~2e4 collisions, E(t) - E(0) (summed from the velocities) = wall_work -
    collision_loss, the loss summed from its own formula at the wall: to rounding, a few
    1e-16 of the energies in play per collision."""
    s = _gas(side, waveform, xi, ew, n=40, seed=5, radius=0.03)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 500}, store=())
    st = sim.stats
    change = sim.scene.kinetic_energy - s.kinetic_energy
    collisions = st["pair_collisions"] + st["wall_collisions"]
    scale = max(abs(st["wall_work"]), abs(st["collision_loss"]), s.kinetic_energy)
    assert st["wall_work"] > 0.1 * s.kinetic_energy
    if xi < 1:
        assert st["collision_loss"] > 0.1 * s.kinetic_energy
    else:
        assert abs(st["collision_loss"]) <= 1e-15 * collisions * scale
    assert abs(change - (st["wall_work"] - st["collision_loss"])) <= 1e-15 * collisions * scale


def test_in_the_steady_state_the_power_in_is_the_power_lost():
    """A granular gas (xi = 0.9) between the vibrating wall and a fixed one, no gravity:
    after it settles, the wall's mean power (work per time in windows) equals the
    collisions' mean loss within 4 standard errors of their difference across 40 windows
    (each ~10 collisions per particle, longer than the energy's correlation time)."""
    s = _gas("lower", "sine", 0.9, 1.0, n=60, seed=11, radius=0.02)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 300}, store=())
    work, loss = [], []
    for _ in range(40):
        before = sim.stats
        t0 = sim.time
        sim.run(t_stop=t0 + 2.0, store=())
        after = sim.stats
        dt = sim.time - t0
        work.append((after["wall_work"] - before["wall_work"]) / dt)
        loss.append((after["collision_loss"] - before["collision_loss"]) / dt)
    work, loss = np.array(work), np.array(loss)
    diff = work - loss
    se = diff.std(ddof=1) / math.sqrt(len(diff))
    assert loss.mean() > 0
    assert abs(diff.mean()) <= 4 * se
    # a real balance, not two zeros: the power is many standard errors from 0
    assert work.mean() > 10 * se


def test_a_checkpoint_mid_cycle_continues_bit_for_bit(tmp_path):
    s = _gas("lower", "sine", 0.9, 0.95, n=40, seed=2, radius=0.03)
    sim = Simulation(s)
    sim.run(t_stop=0.37 * PERIOD, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    times = np.linspace(0.4 * PERIOD, 3 * PERIOD, 5)
    a = sim.run(t_stop=3 * PERIOD, sample_times=times)
    b = loaded.run(t_stop=3 * PERIOD, sample_times=times)
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.velocities, b.velocities)
    for key in ("wall_work", "collision_loss", "events", "wall_collisions"):
        assert sim.stats[key] == loaded.stats[key]


def test_the_scene_of_a_running_simulation_carries_the_walls_phase():
    """Simulation.scene moves the wall's phase on to the current time: a new engine of it
    sees the wall where the running one does (and accepts particles close to it)."""
    s = _gas("lower", "triangle", 1.0, 1.0, n=20)
    sim = Simulation(s)
    sim.run(t_stop=1.234, store=())
    now = sim.scene
    wall = now.vibrating_wall
    assert wall.phase != s.vibrating_wall.phase
    x_then = vibwall_reference.position(s.vibrating_wall, 1.234, 0.0, 1.0)
    x_now = vibwall_reference.position(wall, 0.0, 0.0, 1.0)
    assert x_now == pytest.approx(x_then, abs=1e-12)
    Simulation(now).run(t_stop=0.5, store=())


def _walled(**kw):
    return Scene([[0.5, 0.5]], [[0.0, 1.0]], R, boundary="walls", **kw)


@pytest.mark.parametrize(
    ("make", "error", "match"),
    [
        (lambda: VibratingWall(1, "lower", -0.1, 1.0), ValueError, "amplitude.*-0.1"),
        (lambda: VibratingWall(1, "lower", float("nan"), 1.0), ValueError, "amplitude"),
        (lambda: VibratingWall(1, "lower", 0.1, 0.0), ValueError, "angular_frequency.*0"),
        (lambda: VibratingWall(1, "lower", 0.1, -2.0), ValueError, "angular_frequency"),
        (lambda: VibratingWall(1, "lower", 0.1, float("inf")), ValueError, "angular_frequency"),
        (lambda: VibratingWall(1, "lower", 0.1, 1.0, phase=float("nan")), ValueError, "phase"),
        (lambda: VibratingWall(1, "middle", 0.1, 1.0), ValueError, "side"),
        (lambda: VibratingWall(1, "lower", 0.1, 1.0, waveform="square"), ValueError, "waveform"),
        (lambda: VibratingWall(-1, "lower", 0.1, 1.0), ValueError, "axis"),
        (lambda: VibratingWall(1.0, "lower", 0.1, 1.0), TypeError, "axis"),
        (lambda: VibratingWall(1, "lower", 1e200, 1e200), ValueError, "finite"),
        (
            lambda: _walled(vibrating_wall=VibratingWall(2, "lower", 0.1, 1.0)),
            ValueError,
            "< the dimension 2",
        ),
        (
            lambda: Scene(
                [[0.5, 0.5]], [[0, 1]], R, vibrating_wall=VibratingWall(1, "lower", 0.1, 1.0)
            ),
            ValueError,
            "needs walls",
        ),
        (
            lambda: _walled(vibrating_wall=VibratingWall(1, "lower", 0.495, 1.0)),
            ValueError,
            "sweep",
        ),
        (
            lambda: _walled(vibrating_wall=VibratingWall(1, "lower", 0.3, 1.0, phase=1.0)),
            granular.OutsideBoxError,
            "crosses the vibrating wall",
        ),
        (lambda: _walled(vibrating_wall=0.1), TypeError, "VibratingWall"),
    ],
)
def test_bad_input_is_refused_naming_it(make, error, match):
    with pytest.raises(error, match=match):
        make()


def test_a_frequency_float64_cannot_time_is_refused():
    """omega ulp(t) past 2^-26 rad at the run's end: the wall's phase (and so its position
    to A 2^-26) is not resolved; the run is refused before any event, naming why."""
    wall = VibratingWall(1, "lower", 0.01, 1e12)
    sim = Simulation(_walled(vibrating_wall=wall))
    with pytest.raises(ValueError, match="float64 cannot time the vibrating wall"):
        sim.run(t_stop=1.0, store=())
    assert sim.stats["events"] == 0
    assert wall.max_time == pytest.approx(2**26 / 1e12)
    sim.run(t_stop=0.5 * wall.max_time, store=())  # within reach: runs


def test_a_large_phase_is_kept_modulo_two_pi_and_the_engine_refuses_one():
    """The wall is timed by omega t + phase: a phase of 1e16 (ulp 2 rad) would swamp it.
    VibratingWall keeps it modulo 2 pi; the binding, given one directly, refuses it."""
    wall = VibratingWall(1, "lower", 0.1, 1.0, phase=1e16)
    assert abs(wall.phase) <= 2 * math.pi
    assert wall.phase == math.fmod(1e16, 2 * math.pi)
    keywords = _walled(vibrating_wall=wall)._engine_keywords()
    keywords["vibrating_wall"] = dict(keywords["vibrating_wall"], phase=1e16)
    with pytest.raises(ValueError, match=r"phase must lie in \[-2 pi, 2 pi\]"):
        granular._core.edmd_check(**keywords)


def test_a_gas_the_wall_heated_saves_and_loads(tmp_path):
    """The wall adds energy: a checkpoint's energy check is its bookkeeping (the initial
    energy plus the work less the loss), not the bound that holds without heating; a state
    whose energy does not match it is refused."""
    s = _gas("lower", "sine", 1.0, 1.0, n=20, seed=6, radius=0.03)
    s = s.replace(velocities=0.3 * s.velocities)  # slower than the wall: it heats the gas
    sim = Simulation(s)
    sim.run(t_stop=5.0, store=())
    assert sim.scene.kinetic_energy > 1.5 * s.kinetic_energy
    sim.save(tmp_path / "hot.npz")
    loaded = Simulation.load(tmp_path / "hot.npz")
    a = sim.run(t_stop=6.0, sample_times=[6.0])
    b = loaded.run(t_stop=6.0, sample_times=[6.0])
    assert np.array_equal(a.positions, b.positions)
    from granular import checkpoint

    assert checkpoint._fault(loaded) is None
    sneaky = Simulation(s.replace(velocities=2.0 * s.velocities))  # same scene, other energy
    sneaky._initial = s
    assert "wall's work" in checkpoint._fault(sneaky)


def test_a_vibrating_floor_keeps_a_bed_from_collapsing_where_a_fixed_one_does_not():
    """docs/gravity.md's bed map: 200 disks dropped under g = 10, pairs and floor at
    xi = 0.9, no TC model: the bed on the fixed floor collapses as it settles (t ~ 0.5);
    on a floor vibrating at A = 0.002, omega = 250 (Gamma = 12.5) it stays fluidised to
    t = 1 within the map's event budget."""
    from granular.cli import reproduce_gravity

    kw = dict(xis=(0.9,), contact_durations=(0.0,))
    fixed = reproduce_gravity.bed_map(**kw)[0]
    shaken = reproduce_gravity.bed_map(**kw, floor=VibratingWall(1, "lower", 0.002, 250.0))[0]
    assert fixed["status"] == "collapse" and fixed["time"] < 1.0
    assert shaken["status"] == "ok" and shaken["time"] == 1.0
