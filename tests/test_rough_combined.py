"""Rough particles (csrc/rule.h) combined with the other physics: a sheared box (Lees-Edwards,
csrc/edmd.c do_pair_sheared), a vibrating wall (vibwall.h) and gravity (edmd_gravity_rough.c),
and a vibrated bed under gravity.  Each: against the slow reference where it has the
physics (tests/helpers/reference_edmd.py: rough pairs through the sliding images, beside
the vibrating wall, under gravity between fixed walls), beta = -1 against the smooth loop bit
for bit, the energy books to rounding (the collisional loss summed from the rule's
formulas, translational and rotational), checkpoints that continue bit for bit.  Walls
stay smooth for rough particles: they reflect the velocity and leave the spin."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, VibratingWall, _core
from granular.checkpoint import potential_energy

from helpers import reference_edmd


def energy(scene):
    """Translational + rotational + potential energy (0 without gravity)."""
    return scene.kinetic_energy + scene.rotational_energy + potential_energy(scene)


def _spins(rng, n, dim, scale):
    return rng.standard_normal((n,) if dim == 2 else (n, 3)) * scale


def _sheared(dim, n=100, seed=3, rate=0.5, **rough):
    radius = 0.02 if dim == 2 else 0.05
    s = Scene.random(n, radius, dim=dim, seed=seed, temperature=1.0)
    w = _spins(np.random.default_rng(seed), n, dim, 10.0)
    return s.replace(angular_velocities=w, shear_rate=rate, **rough)


def _bed(n=25, seed=2, gravity=1.0, wall=True, **rough):
    """n disks in a unit box over a floor (vibrating: A = 0.05, omega = 20) under gravity."""
    k = round(math.sqrt(n))
    grid = (np.arange(k) + 0.5) / k
    pos = np.stack(np.meshgrid(grid, 0.3 + 0.6 * grid), -1).reshape(-1, 2)
    rng = np.random.default_rng(seed)
    vel = rng.normal(size=(k * k, 2))
    s = Scene(pos, vel, 0.02, boundary="walls", angular_velocities=_spins(rng, k * k, 2, 10.0))
    if gravity:
        s = s.replace(gravity=[0.0, -gravity])
    if wall:
        s = s.replace(vibrating_wall=VibratingWall(1, "lower", 0.05, 20.0))
    return s.replace(**rough)


def _beside_wall(n=12, seed=3, radius=0.06, **rough):
    """n disks beside a vibrating lower wall (A = 0.04, omega = 12), no gravity: the
    vibrating-wall tests' gas (tests/test_vibrating_wall.py) with spins."""
    a = 0.04
    s = Scene.random(n, radius, dim=2, box=((0.0, 2 * a), (1.0, 1.0)), boundary="walls", seed=seed)
    wall = VibratingWall(1, "lower", a, 12.0, phase=0.7)
    w = _spins(np.random.default_rng(seed), n, 2, 5.0)
    return s.replace(box=1.0, vibrating_wall=wall, angular_velocities=w, **rough)


def _advance(engine, collisions):
    code, _ = engine.advance(
        t_stop=math.inf,
        collisions_per_particle=float(collisions),
        stop_kinetic_energy=-1.0,
        max_events=10**7,
        sample_times=np.empty(0),
        next=0,
    )
    assert code == _core.STOP_COLLISIONS


def _bits(engine):
    pos, vel, img = engine.state()
    c = engine.counters()
    return pos.tobytes() + vel.tobytes() + img.tobytes(), c["events"], c["wall_work"]


# -- beta = -1 is the smooth scene, bit for bit, in each combination ----------------------

_SMOOTH_CASES = {
    "sheared 2d": lambda: _sheared(2, restitution=0.9),
    "sheared 3d": lambda: _sheared(3, restitution=0.9),
    "vibrating wall": lambda: _beside_wall(n=40, radius=0.03, restitution=0.9),
    "gravity": lambda: _bed(wall=False, restitution=0.9),
    "vibrated bed": lambda: _bed(restitution=0.9, wall_restitution=0.95),
}


@pytest.mark.parametrize("case", sorted(_SMOOTH_CASES))
def test_beta_minus_one_in_the_rough_loop_is_the_smooth_scene(case):
    """An engine given spins at beta = -1 runs the rough loop of its combination (sheared
    pair, vibrating-wall loop, gravity's loops); it makes the smooth loop's events bit for
    bit and leaves the spins as they were."""
    s = _SMOOTH_CASES[case]()
    kw = s._engine_keywords()
    assert kw["angular_velocities"] is None  # a smooth scene: the smooth loop
    smooth = _core.EDMD(**kw)
    rough = _core.EDMD(**{**kw, "angular_velocities": np.array(s.angular_velocities)})
    for engine in (smooth, rough):
        _advance(engine, 20)
    assert _bits(rough) == _bits(smooth)
    assert np.array_equal(rough.angular_velocities(), s.angular_velocities)


# -- against the slow reference ------------------------------------------------------------


@pytest.mark.parametrize(
    ("dim", "rough", "shell"),
    [
        (2, dict(tangential_restitution=0.4, restitution=0.9), 0.0),
        (3, dict(tangential_restitution=0.0, restitution=0.8), 0.0),
        (2, dict(tangential_restitution=0.6, friction=0.15, restitution=0.9), 0.0),
        # neighbour lists (csrc/le_nlist.h): pairs through the sliding faces found by the
        # lists reach the same rough rule
        (2, dict(tangential_restitution=0.4, restitution=0.9), 0.25),
        (2, dict(tangential_restitution=0.6, friction=0.15, restitution=0.9), 0.25),
    ],
)
def test_a_sheared_rough_gas_agrees_with_the_slow_reference(dim, rough, shell):
    """A small rough gas in a sheared box (unequal radii and masses) against the O(N^2)
    reference, whose pairs through the sliding images collide by the rigid-body impulse on
    the image's velocity (v_x + ky u) with the spins as they are: positions, velocities and
    spins at every sample to 1e-8 (chaos grows rounding by ~e a collision: the smooth
    sheared gas too parts from the reference by 1e-8 at t ~ 1.2; 1e-11 at t = 1), and
    collisions through the images among them."""
    n = 12
    small = 0.05 if dim == 2 else 0.1
    radii = np.where(np.arange(n) % 2, small, 1.6 * small)
    s = Scene.random(
        n, radii, dim=dim, box=1.0, seed=11, temperature=1.0, mass=(radii / small) ** dim
    )
    w = _spins(np.random.default_rng(1), n, dim, 5.0)
    s = s.replace(angular_velocities=w, shear_rate=1.5, **rough)
    t_stop = 1.0
    times = np.linspace(0.0, t_stop, 5)
    sim = Simulation(s, shell=shell)
    store = ("positions", "velocities", "angular_velocities")
    tr = sim.run(t_stop=t_stop, sample_times=times, store=store)
    assert sim.stats["pair_collisions"] >= 2 * n
    assert sim.stats["shear_work"] != 0.0  # pairs through the sliding images collided
    assert sim.stats["shell"] == shell and (shell == 0.0) == (sim.stats["shell_exits"] == 0)
    rx, rv, rw = reference_edmd.run_scene(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.angular_velocities, rw, rtol=0, atol=1e-8)


@pytest.mark.parametrize(
    "rough",
    [
        dict(tangential_restitution=0.3, restitution=0.9),
        dict(tangential_restitution=0.5, friction=0.2),
    ],
)
def test_rough_disks_beside_a_vibrating_wall_agree_with_the_slow_reference(rough):
    """12 rough disks and the vibrating wall they hit over and over, against the reference
    (brute-force wall, rigid-body pair impulse, smooth walls): samples to 1e-8."""
    s = _beside_wall(**rough)
    times = np.linspace(0.0, 0.6, 7)
    sim = Simulation(s)
    store = ("positions", "velocities", "angular_velocities")
    tr = sim.run(t_stop=0.6, sample_times=times, store=store)
    assert sim.stats["wall_collisions"] >= 10 and sim.stats["pair_collisions"] >= 10
    assert sim.stats["wall_work"] != 0.0
    rx, rv, rw = reference_edmd.run_scene(s, 0.6, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.angular_velocities, rw, rtol=0, atol=1e-8)


@pytest.mark.parametrize(
    "rough",
    [
        dict(restitution=0.9),  # (smooth: the reference's gravity itself)
        dict(tangential_restitution=0.3, restitution=0.9),
        dict(tangential_restitution=0.5, friction=0.2, restitution=0.95, wall_restitution=0.9),
    ],
)
def test_rough_disks_under_gravity_agree_with_the_slow_reference(rough):
    """16 disks falling between walls (g = 2), smooth and rough, against the reference with
    gravity (parabolic flights, pairs on straight relative lines, walls at the quadratic's
    root): positions, velocities and spins at every sample to 1e-8 (the smooth gas parts
    from it by 1e-8 at t ~ 1.1: chaos)."""
    s = _bed(n=16, wall=False, gravity=2.0, **rough)
    times = np.linspace(0.0, 0.8, 9)
    sim = Simulation(s)
    store = ("positions", "velocities", "angular_velocities")
    tr = sim.run(t_stop=0.8, sample_times=times, store=store)
    assert sim.stats["pair_collisions"] >= 10 and sim.stats["wall_collisions"] >= 10
    out = reference_edmd.run_scene(s, 0.8, times)
    np.testing.assert_allclose(tr.positions, out[0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, out[1], rtol=0, atol=1e-8)
    if s.tangential_restitution != -1.0:
        np.testing.assert_allclose(tr.angular_velocities, out[2], rtol=0, atol=1e-8)


# -- the energy books ----------------------------------------------------------------------


@pytest.mark.parametrize("dim", [2, 3])
def test_a_sheared_rough_gas_keeps_its_energy_books(dim):
    """Translational + rotational energy changes by the sliding images' work less the
    collisional loss, the loss summed from the rule's formulas ((1 - xi^2) m_eff g_n^2 / 2
    plus the tangential f |g_t|^2 (1 - f / 2 m_t), csrc/rule.h), not from energies: to
    rounding, a few 1e-16 of the energies in play per collision.  The Coulomb rule slides
    in some collisions and sticks in others; both lose."""
    s = _sheared(dim, tangential_restitution=0.5, friction=0.2, restitution=0.9)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 100}, store=())
    st = sim.stats
    change = st["kinetic_energy"] + st["rotational_energy"] - energy(s)
    books = st["shear_work"] - st["collision_loss"]
    scale = max(abs(st["shear_work"]), st["collision_loss"], energy(s))
    assert st["collision_loss"] > 0.5 * energy(s) and st["shear_work"] > 0.1 * energy(s)
    assert abs(change - books) <= 1e-15 * st["pair_collisions"] * scale


def test_a_perfectly_rough_elastic_sheared_gas_loses_nothing():
    """beta = 1, xi = 1 in a sheared box: the collision loss stays at rounding's scale and
    all the images' work goes into translation and rotation."""
    s = _sheared(2, tangential_restitution=1.0, restitution=1.0)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 100}, store=())
    st = sim.stats
    scale = max(abs(st["shear_work"]), energy(s))
    assert abs(st["collision_loss"]) <= 1e-15 * st["pair_collisions"] * scale
    change = st["kinetic_energy"] + st["rotational_energy"] - energy(s)
    assert abs(change - st["shear_work"]) <= 1e-15 * st["pair_collisions"] * scale


@pytest.mark.parametrize("wall", [False, True])
def test_perfectly_rough_elastic_disks_under_gravity_keep_their_energy(wall):
    """beta = 1, xi = 1 and elastic walls under gravity: translational + rotational +
    potential energy kept over ~1e4 collisions to the rounding bound (8 ulp of the total a
    collision, as tests/test_rough.py derives, and gravity's flights round the same way:
    16 K 2^-53 for K events that touch the energy); beside a vibrating floor it changes by
    the floor's work alone, the collision loss at rounding's scale."""
    s = _bed(wall=wall, tangential_restitution=1.0, restitution=1.0)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 500}, store=())
    st = sim.stats
    k = st["pair_collisions"] + st["wall_collisions"]
    assert st["pair_collisions"] > 3000
    work = st["wall_work"] if wall else 0.0
    scale = max(energy(s), abs(work))
    bound = 16 * k * 2.0**-53 * scale
    assert abs(energy(sim.scene) - energy(s) - work) <= bound
    if wall:
        assert abs(st["collision_loss"]) <= bound
        assert st["wall_work"] != 0.0
    # the spins did take part
    assert not np.allclose(sim.scene.angular_velocities, s.angular_velocities)


@pytest.mark.parametrize("gravity", [0.0, 1.0])
def test_rough_disks_beside_a_vibrating_wall_keep_their_energy_books(gravity):
    """Translational + rotational (+ potential) energy changes by the floor's work less the
    collisions' loss: pairs booked by the rough rule's formulas, walls (smooth) by the
    wall's own formula; to rounding."""
    s = _bed(gravity=gravity, tangential_restitution=0.2, friction=0.3, restitution=0.9)
    sim = Simulation(s)
    sim.run(t_stop=5.0, store=())
    st = sim.stats
    k = st["pair_collisions"] + st["wall_collisions"]
    assert st["wall_collisions"] > 100 and st["wall_work"] > 0.0
    scale = max(energy(s), abs(st["wall_work"]), st["collision_loss"])
    gain = energy(sim.scene) - energy(s)
    assert abs(gain - (st["wall_work"] - st["collision_loss"])) <= 1e-15 * k * scale


# -- steady states -------------------------------------------------------------------------


def _windows(sim, keys, count, span):
    """Per-window rates (change / time) of the stats named, and T_tr, T_rot at each end."""
    rates = {k: [] for k in keys}
    temps = []
    for _ in range(count):
        before, t0 = sim.stats, sim.time
        sim.run(t_stop=t0 + span, store=())
        after = sim.stats
        for k in keys:
            rates[k].append((after[k] - before[k]) / (sim.time - t0))
        temps.append((after["translational_temperature"], after["rotational_temperature"]))
    return {k: np.array(v) for k, v in rates.items()}, np.array(temps)


def test_a_sheared_rough_gas_reaches_a_steady_state():
    """Rough disks (xi = 0.9, beta = 0) sheared from rest in spin: after ~100 collisions per
    particle the images' mean power equals the collisional loss's (within 4 standard
    errors of their difference over 30 windows of ~5 collisions per particle, longer than
    the energy's correlation time ~1 / (1 - xi^2) collisions), and the temperatures no
    longer drift: the means of the two halves of the windows agree within 4 standard
    errors of their difference."""
    s = _sheared(2, n=100, tangential_restitution=0.0, restitution=0.9, rate=1.0)
    s = s.replace(angular_velocities=np.zeros(100))
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 100}, store=())
    per_collision = sim.time / 100
    rates, temps = _windows(sim, ("shear_work", "collision_loss"), 30, 5 * per_collision)
    diff = rates["shear_work"] - rates["collision_loss"]
    se = diff.std(ddof=1) / math.sqrt(len(diff))
    assert abs(diff.mean()) <= 4 * se
    assert rates["shear_work"].mean() > 10 * se  # a real balance, not two zeros
    for col in (0, 1):  # T_tr, T_rot
        a, b = temps[:15, col], temps[15:, col]
        se2 = math.hypot(a.std(ddof=1), b.std(ddof=1)) / math.sqrt(15)
        assert abs(a.mean() - b.mean()) <= 4 * se2
    assert temps[:, 1].mean() > 0.0  # the spins were heated by the collisions alone


def test_a_vibrated_rough_bed_under_gravity_balances_work_and_loss():
    """Rough disks (xi = 0.9, beta = 0.3) on a vibrating floor under gravity: after it
    settles, the floor's mean power equals the collisions' mean loss (translational and
    rotational) within 4 standard errors of their difference across 30 windows of one
    time unit (~20 floor periods, several collisions per particle)."""
    s = _bed(n=36, tangential_restitution=0.3, restitution=0.9)
    sim = Simulation(s)
    sim.run(t_stop=20.0, store=())
    rates, temps = _windows(sim, ("wall_work", "collision_loss"), 30, 1.0)
    diff = rates["wall_work"] - rates["collision_loss"]
    se = diff.std(ddof=1) / math.sqrt(len(diff))
    assert rates["collision_loss"].mean() > 0
    assert abs(diff.mean()) <= 4 * se
    assert rates["wall_work"].mean() > 10 * se
    assert np.all(temps[:, 1] > 0.0)


# -- checkpoints ---------------------------------------------------------------------------

_CHECKPOINT_CASES = {
    "sheared": lambda: _sheared(
        3, n=150, tangential_restitution=0.5, friction=0.3, restitution=0.9
    ),
    "vibrating wall": lambda: _beside_wall(
        n=40, radius=0.03, tangential_restitution=0.4, restitution=0.9
    ),
    "gravity": lambda: _bed(wall=False, tangential_restitution=0.4, restitution=0.9),
    "vibrated bed": lambda: _bed(tangential_restitution=0.4, friction=0.3, restitution=0.9),
}


@pytest.mark.parametrize("case", sorted(_CHECKPOINT_CASES))
def test_a_checkpoint_continues_bit_for_bit(tmp_path, case):
    """Saved mid-run and loaded, each combination goes on with the same positions,
    velocities and spins and the same books, bit for bit."""
    s = _CHECKPOINT_CASES[case]()
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 5}, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    t = sim.time + 0.5
    times = np.linspace(sim.time, t, 4)
    store = ("positions", "velocities", "angular_velocities")
    a = sim.run(t_stop=t, sample_times=times, store=store)
    b = loaded.run(t_stop=t, sample_times=times, store=store)
    for name in store:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    # (a sheared box's pressure is NaN without the stress tensor: NaN != NaN)
    assert {k: v for k, v in sim.stats.items() if v == v} == {
        k: v for k, v in loaded.stats.items() if v == v
    }


def test_the_sheared_trajectory_has_the_rotational_temperature():
    """In a sheared box T_rot / T_tr of the samples is the spins' temperature over the
    peculiar translational one (the velocities less the mean flow), as stats has it."""
    s = _sheared(2, tangential_restitution=0.3, restitution=0.9)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.5, sample_times=[0.0, 0.5], store=("positions", "velocities"))
    st = sim.stats
    assert tr.rotational_temperature[-1] == pytest.approx(st["rotational_temperature"], rel=1e-12)
    assert tr.temperature_ratio[-1] == pytest.approx(st["temperature_ratio"], rel=1e-12)


@pytest.mark.parametrize(
    "rough",
    [
        dict(tangential_restitution=1.0, restitution=1.0),
        dict(tangential_restitution=0.5, friction=0.2, restitution=0.9),
    ],
)
def test_the_sheared_stress_tensor_carries_the_tangential_impulse(rough):
    """Simulation(stress=True) of rough particles in a sheared box: the peculiar
    translational energy (half the kinetic tensor's trace) plus the rotational energy plus
    the collisions' loss rose by the viscous heating, -rate (int K_xy dt + W_yx) -- the
    collisional part W summed with each collision's whole impulse, normal and tangential:
    to rounding, a few 1e-16 of the energies in play per collision, while the heating is
    a good part of them."""
    s = _sheared(3, n=100, **rough)
    sim = Simulation(s, stress=True)
    tr = sim.run(stop_when={"collisions_per_particle": 30}, sample_times=[0.0, 1e9])
    st = sim.stats
    k = np.array(st["kinetic_tensor"])
    kt = np.array(st["kinetic_time_tensor"])
    w = np.array(st["stress_collisional"])
    k0 = tr.kinetic_tensor[0]
    gained = 0.5 * (np.trace(k) - np.trace(k0)) + st["rotational_energy"] - s.rotational_energy
    gained += st["collision_loss"]
    heated = -s.shear_rate * (kt[0, 1] + w[1, 0])
    scale = max(np.trace(k), np.trace(k0), s.rotational_energy, abs(heated))
    assert abs(gained - heated) <= 1e-15 * st["pair_collisions"] * scale
    assert abs(heated) > 0.03 * scale


@pytest.mark.parametrize("case", ["sheared", "vibrated bed"])
def test_gsd_carries_the_spins_in_each_combination(tmp_path, case):
    """A sheared rough run and a rough vibrated bed written to GSD: granular.read gives back
    the spins and rotational energies exactly, Scene.from_gsd the last frame's spins with
    the scene's rough parameters and its shear or gravity and wall."""
    pytest.importorskip("gsd.hoomd")
    from granular import read

    s = _CHECKPOINT_CASES[case]()
    sim = Simulation(s)
    store = ("positions", "velocities", "angular_velocities")
    tr = sim.run(t_stop=0.5, sample_times=[0.0, 0.25, 0.5], store=store)
    tr.write(tmp_path / "r.gsd")
    back = read(tmp_path / "r.gsd")
    assert np.array_equal(back.angular_velocities, tr.angular_velocities)
    assert np.array_equal(back.rotational_energy, tr.rotational_energy)
    scene = Scene.from_gsd(tmp_path / "r.gsd")
    assert np.array_equal(scene.angular_velocities, tr.angular_velocities[-1])
    assert scene.tangential_restitution == s.tangential_restitution
    assert scene.shear_rate == s.shear_rate
    assert (scene.gravity is None) == (s.gravity is None)
    assert (scene.vibrating_wall is None) == (s.vibrating_wall is None)


@pytest.mark.parametrize("q", [5e-324, 1e-300])
def test_the_loss_book_at_a_vanishing_inertia_factor(q):
    """q at the bottom of float64 (m_t = q m_eff / (1 + q) underflows to 0 at the smallest
    subnormal): the rule's loss stays finite and the books hold, in a sheared box with
    Walton's rule (the case the fuzz test found giving NaN)."""
    s = _sheared(3, n=60, tangential_restitution=0.5, friction=0.3, restitution=0.9)
    sim = Simulation(s.replace(inertia_factor=q))
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    st = sim.stats
    assert math.isfinite(st["collision_loss"]) and st["collision_loss"] > 0.0
    change = st["kinetic_energy"] + st["rotational_energy"] - sim._initial.rotational_energy
    change -= s.kinetic_energy
    scale = max(abs(st["shear_work"]), st["collision_loss"], s.kinetic_energy)
    assert abs(change - (st["shear_work"] - st["collision_loss"])) <= (
        1e-15 * st["pair_collisions"] * scale
    )
