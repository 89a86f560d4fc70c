"""Gravity in the event-driven engine (csrc/flight.h, GR_FLIGHT_GRAVITY): parabolic flight
against the slow reference (walls, many cell faces, apex crossings), exact single-particle
flights, energy (kinetic + potential) kept to rounding, the TC model under a resting bed,
bad input refused, checkpoints continued bit for bit."""

import math

import numpy as np
import pytest

from granular import InelasticCollapseError, Scene, Simulation
from granular.checkpoint import potential_energy

from helpers import reference_gravity
from helpers.scenes import reference_scene


def _gravity(dim, strength=3.0, tilt=0.3):
    g = np.zeros(dim)
    g[-1] = -strength
    g[0] = tilt
    return g


def _one(x, v, box, g, radius=0.01, **kw):
    return Scene(
        np.array([x], dtype=float),
        np.array([v], dtype=float),
        radius,
        box=box,
        boundary="walls",
        gravity=np.asarray(g, dtype=float),
        **kw,
    )


# -- against the slow reference -------------------------------------------------------------


@pytest.mark.parametrize(
    "dim,boundary,xi,mixture",
    [
        (2, "walls", 1.0, False),
        (2, "walls", 0.8, True),
        (3, "walls", 1.0, False),
        (3, "walls", 0.9, True),
        (2, "periodic", 0.9, False),
        (3, "periodic", 1.0, True),
    ],
)
def test_agrees_with_slow_reference(dim, boundary, xi, mixture):
    """The same events as the O(N^2) reference with parabolic flight (its wall times from
    numpy.roots, not the engine's formulas), sample by sample, to 1e-8 (the tolerance and
    its reasoning of test_simulation's reference test: up to 12 collisions per particle;
    measured, the differences grow from 1e-14 by ~x5 per 0.1 and reach 4e-10 by t = 0.8
    in the densest case, 1e-8 by t = 1).
    g = 3 down and 0.3 sideways, speeds ~1.4: particles rise ~0.3, so flights turn over
    inside the box, and cross many cell faces on the way up and down again (the cells are
    one diameter wide, 0.16-0.2: a missed face would miss a collision, and a particle
    would pass through another, off by its spacing).  Periodic: the freely falling box."""
    s = reference_scene(dim, boundary, xi, mixture)
    s = s.replace(gravity=_gravity(dim), free_fall=boundary == "periodic")
    times = np.linspace(0.0, 0.8, 9)
    sim = Simulation(s)
    tr = sim.run(t_stop=0.8, sample_times=times)
    assert sim.stats["pair_collisions"] >= s.n
    assert sim.stats["cell_crossings"] >= 4 * s.n
    rx, rv = reference_gravity.run_scene(s, 0.8, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)


def _row(heights_v0, g, r=0.005, n=40, box=(0.5, 1.0)):
    """n balls side by side on the floor, thrown straight up at v0 together: they move in
    step (no pair ever closes in), and 8 cells a particle make a fine grid."""
    x = np.stack([np.linspace(0.0125, box[0] - 0.0125, n), np.full(n, r)], axis=1)
    v = np.zeros((n, 2))
    v[:, 1] = heights_v0
    return Scene(x, v, r, box=(np.zeros(2), np.array(box)), boundary="walls", gravity=(0.0, -g))


def test_balls_thrown_up_fall_back_through_every_face():
    """Thrown up from the floor through a grid of ~30 cells high, with the apex a hair
    (1e-9) below a cell face, the balls rise through the faces, turn, fall back through
    them and bounce elastically: the height is the parabola's at every sample (to 1e-12
    of the box) and the crossings are two per face and flight."""
    g, r = 2.0, 0.005
    cells = Simulation(_row(0.0, g)).stats["cells"]
    w = 1.0 / cells[1]
    top = w * math.floor(0.8 / w) - 1e-9  # just below a face
    v0 = math.sqrt(2 * g * (top - r))
    period = 2 * v0 / g
    s = _row(v0, g)
    times = np.linspace(0.0, 2.5 * period, 101)
    sim = Simulation(s)
    tr = sim.run(t_stop=times[-1], sample_times=times)
    tau = np.mod(times, period)
    want = r + v0 * tau - 0.5 * g * tau**2
    np.testing.assert_allclose(tr.positions[:, :, 1], want[:, None] * np.ones(s.n), atol=1e-12)
    faces = math.floor(top / w) - math.floor(r / w)  # faces crossed on the way up
    assert cells[1] >= 20 and faces >= 15
    flights = 3  # two whole flights and a half, up and down
    assert sim.stats["cell_crossings"] >= s.n * 2 * faces * 2
    assert sim.stats["cell_crossings"] <= s.n * 2 * faces * flights
    assert sim.stats["wall_collisions"] == 2 * s.n
    assert sim.stats["pair_collisions"] == 0


def test_grazing_the_apex_at_a_face_and_at_the_ceiling():
    """Apexes at (within rounding of) a cell face and of the ceiling: the flight is timed
    without cancellation and neither crossing is lost nor invented (the height is the
    parabola's, the ceiling is not hit, the energy is the start's)."""
    g, r = 1.0, 0.01
    for top in (0.5, 1.0 - r):
        v0 = math.sqrt(2 * g * (top - r))
        s = Scene(
            np.array([[0.05, r], [0.95, 0.9]]),
            np.array([[0.0, v0], [0.0, 0.0]]),
            r,
            box=1.0,
            boundary="walls",
            gravity=(0.0, -g),
        )
        period = 2 * v0 / g
        times = np.linspace(0.0, 3 * period, 61)
        sim = Simulation(s)
        tr = sim.run(t_stop=times[-1], sample_times=times)
        tau = np.mod(times, period)
        np.testing.assert_allclose(
            tr.positions[:, 0, 1], r + v0 * tau - 0.5 * g * tau**2, atol=1e-9
        )
        assert np.all(tr.positions[:, 0, 1] <= 1.0 - r + 1e-12)


def test_no_overlap_and_every_particle_in_its_box_in_a_dense_column():
    """A 2D column at packing 0.3 under strong gravity with the TC model (inelastic): no
    pair closer than contact beyond rounding and no particle outside, at every sample (a
    missed face or wall would show as an overlap or an escape)."""
    s = Scene.random(
        600,
        0.01,
        dim=2,
        box=(np.zeros(2), np.array([0.5, 1.5])),
        boundary="walls",
        restitution=0.9,
        contact_duration=1e-5,
        seed=3,
    ).replace(gravity=(0.0, -5.0))
    tr = Simulation(s).run(t_stop=0.4, sample_times=np.linspace(0, 0.4, 9))
    for x in tr.positions:
        s.replace(positions=x)  # checks the walls and every overlap (OverlapError)


# -- energy ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "collisions", [1_000_000, pytest.param(10_000_000, marks=pytest.mark.slow)]
)
def test_energy_kinetic_plus_potential_is_kept_to_rounding(collisions):
    """Elastic 3D gas between walls under gravity (tilted, so each axis carries some), 10^6
    pair collisions (1.2 s on a quiet machine) and, marked slow, 10^7 (12 s): E = K + U (U
    from the floor corner, >= 0) drifts by rounding only.  Bound: each event rounds E's
    parts by ~1e-16 of E at random signs; over the 2e7 particle events of the long run that
    random walk reaches ~1e-16 * sqrt(2e7) = 4.5e-13 (s.kinetic is also summed anew every
    16 collisions a particle), so 1e-11 of E is 20 times that walk (measured: 0 after 10^6,
    2.6e-14 after 8.8e6), while a missed collision or a wrong parabola (an error of O(g dt^2)
    a flight) would be orders larger."""
    s = Scene.random(1000, 0.025, dim=3, box=1.0, boundary="walls", seed=8)
    s = s.replace(gravity=(0.2, 0.1, -1.5))
    sim = Simulation(s)
    cpp = 2.3 * collisions / 1000
    tr = sim.run(stop_when={"collisions_per_particle": cpp}, store=("positions", "velocities"))
    assert sim.stats["pair_collisions"] >= collisions
    e0 = s.kinetic_energy + potential_energy(s)
    now = s.replace(positions=tr.positions[-1], velocities=tr.velocities[-1])
    e1 = now.kinetic_energy + potential_energy(now)
    assert abs(e1 / e0 - 1) <= 1e-11
    # the engine's own running kinetic energy agrees with the velocities' sum
    assert sim.stats["kinetic_energy"] == pytest.approx(now.kinetic_energy, rel=1e-12)


def test_the_kinetic_integral_integrates_in_flight():
    """One particle falling freely (no collision at all): the engine's time integral of the
    kinetic energy is that of K(t) = m (v0 + g t)^2 / 2 (analytic; 1e-12)."""
    g, v0, t = np.array([0.0, -1.0]), np.array([0.3, 0.5]), 0.9
    s = _one([0.5, 0.5], v0, 2.0, g)
    sim = Simulation(s)
    sim.run(t_stop=t, store=())
    want = 0.5 * (v0 @ v0 * t + (v0 @ g) * t**2 + g @ g * t**3 / 3)
    assert sim.stats["kinetic_time_integral"] == pytest.approx(want, rel=1e-12)


# -- the TC model under a resting bed -------------------------------------------------------


def test_an_inelastic_bed_on_its_floor_is_carried_by_the_tc_model():
    """A bed of inelastic disks (xi = 0.5, floor e_w = 0.5) settling under gravity: without
    the TC model its bottom layer collapses (infinitely many collisions in finite time,
    InelasticCollapseError, at t ~ 0.09); with t_c = 1e-4 (collisions within t_c of a
    particle's previous one elastic) it runs on, the TC model acting, and settles: its
    kinetic energy falls below 1 % of the energy it started with.  (It keeps rattling, at
    a cost that grows as it cools: docs/gravity.md.)"""
    s = Scene.random(
        200,
        0.01,
        dim=2,
        box=(np.zeros(2), np.array([0.3, 1.0])),
        boundary="walls",
        restitution=0.5,
        wall_restitution=0.5,
        seed=4,
    ).replace(gravity=(0.0, -10.0))
    with pytest.raises(InelasticCollapseError):
        Simulation(s).run(t_stop=0.6, store=())
    sim = Simulation(s.replace(contact_duration=1e-4))
    sim.run(t_stop=0.6, store=())
    assert sim.stats["tc_elastic_collisions"] > 0
    assert sim.stats["kinetic_energy"] < 0.01 * s.kinetic_energy


# -- bad input, checkpoints ------------------------------------------------------------------


@pytest.mark.parametrize(
    "g,error,match",
    [
        ((0.0, np.nan), ValueError, "gravity must be finite"),
        ((0.0, np.inf), ValueError, "gravity must be finite"),
        ((0.0, 0.0, -1.0), ValueError, r"shape \(2,\)"),
        ((0.0, -1e300), ValueError, r"\|g\| times the longest box edge = 1e\+300"),
        ("down", TypeError, "gravity must be numbers"),
    ],
)
def test_bad_gravity_is_refused(g, error, match):
    s = Scene.random(10, 0.03, dim=2, boundary="walls", seed=1)
    with pytest.raises(error, match=match):
        s.replace(gravity=g)


def test_gravity_in_a_periodic_box_needs_the_free_fall_frame():
    s = Scene.random(10, 0.03, dim=2, seed=1)
    with pytest.raises(ValueError, match="free_fall=True"):
        s.replace(gravity=(0.0, -1.0))
    falling = s.replace(gravity=(0.0, -1.0), free_fall=True)
    tr = Simulation(falling).run(t_stop=2.0, sample_times=[0.0, 2.0])
    # the centre of mass falls forever: its velocity gains g t (pairs keep the momentum)
    drift = (tr.momentum[-1] - tr.momentum[0]) / np.sum(s.masses)
    np.testing.assert_allclose(drift, [0.0, -2.0], atol=1e-12)
    with pytest.raises(TypeError, match="free_fall must be True or False"):
        s.replace(free_fall="yes")


def test_the_engine_refuses_what_the_scene_would():
    """The binding's own checks (csrc/validate.c) behind the Scene's."""
    from granular import _core

    s = Scene.random(10, 0.03, dim=2, seed=1)
    kw = s._engine_keywords()
    with pytest.raises(ValueError, match="free_fall=True"):
        _core.edmd_check(**{**kw, "gravity": np.array([0.0, -1.0])})
    with pytest.raises(ValueError, match="gravity must be finite"):
        _core.edmd_check(**{**kw, "gravity": np.array([0.0, np.nan]), "free_fall": True})
    with pytest.raises(ValueError, match="exceeds 1e280"):
        _core.edmd_check(**{**kw, "gravity": np.array([0.0, 1e300]), "free_fall": True})


@pytest.mark.parametrize("boundary", ["walls", "periodic"])
@pytest.mark.parametrize("shell", [0.0, 0.3])
def test_a_checkpoint_continues_bit_for_bit(tmp_path, boundary, shell):
    """Saved mid-run and loaded (the momentum and kinetic energy the flight integrates
    are engine state), the run continues with the same bits; cells and neighbour lists."""
    s = Scene.random(
        300, 0.05, dim=3, boundary=boundary, restitution=0.9, contact_duration=1e-4, seed=2
    ).replace(gravity=_gravity(3, 2.0), free_fall=boundary == "periodic")
    sim = Simulation(s, shell=shell)
    sim.run(stop_when={"collisions_per_particle": 3}, store=())
    sim.save(tmp_path / "c.npz")
    loaded = Simulation.load(tmp_path / "c.npz")
    a = sim.run(stop_when={"collisions_per_particle": 6}, store=("positions", "velocities"))
    b = loaded.run(stop_when={"collisions_per_particle": 6}, store=("positions", "velocities"))
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.velocities, b.velocities)
    assert sim.stats == loaded.stats


def test_what_gravity_is_not_offered_with_is_refused_by_name():
    """Gravity's loops have no sliding images: gravity in a sheared box is refused, naming
    why (the stress tensor under gravity: test_gravity_stress.py; rough particles under
    gravity: test_rough_combined.py)."""
    s = Scene.random(20, 0.03, dim=2, boundary="walls", seed=1)
    g = np.array([0.0, -1.0])
    Simulation(s.replace(gravity=g))  # alone it runs
    Simulation(s.replace(gravity=g), stress=True)  # and with the tensor
    Simulation(s.replace(gravity=g, tangential_restitution=0.5))  # and rough
    p = Scene.random(20, 0.03, dim=2, seed=1)
    with pytest.raises(ValueError, match="in a sheared box"):
        Simulation(p.replace(gravity=g, free_fall=True, shear_rate=0.5))


def test_a_vibrating_floor_under_gravity_keeps_its_energy_books():
    """The vibrated bed: a sine floor under gravity (vibwall.h bounds the gap's curvature by
    |g| + A omega^2).  Kinetic plus potential energy changes by exactly the floor's work
    less the collisions' loss, to rounding, and no particle ever leaves the box."""
    from granular import VibratingWall

    k = 5
    grid = (np.arange(k) + 0.5) / k
    pos = np.stack(np.meshgrid(grid, 0.3 + 0.6 * grid), -1).reshape(-1, 2)
    vel = np.random.default_rng(2).normal(size=(k * k, 2))
    s = Scene(pos, vel, 0.02, boundary="walls", restitution=0.9, gravity=[0.0, -1.0])
    s = s.replace(vibrating_wall=VibratingWall(1, "lower", 0.05, 20.0))
    sim = Simulation(s)
    tr = sim.run(t_stop=5.0, sample_times=np.linspace(0.0, 5.0, 11))
    st = sim.stats
    assert st["wall_collisions"] > 100 and st["wall_work"] > 0.0
    potential = np.einsum("n,tn->t", s.masses, tr.positions[:, :, 1] - s.lower[1])
    e = tr.kinetic_energy + 1.0 * potential
    # the samples' energies against the books at the end (the books are totals)
    gain = e[-1] - e[0]
    books = st["wall_work"] - st["collision_loss"]
    assert gain == pytest.approx(books, rel=1e-9, abs=1e-9 * abs(e[0]))
    y = tr.positions[:, :, 1]
    assert np.all(y >= s.lower[1] + 0.02 - 1e-9) and np.all(y <= s.upper[1] - 0.02 + 1e-9)
