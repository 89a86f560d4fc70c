"""Scenes: construction, random placement and velocities, and every bad input."""

import itertools
import math
import re

import numpy as np
import pytest
from scipy import stats

import granular
from granular import Scene, Simulation

from helpers.scenes import three_in_line


def test_random_scene_is_uniform_isotropic_and_without_drift():
    s = Scene.random(4000, 0.01, seed=1)
    assert s.n == 4000 and s.dim == 3 and s.boundary == "periodic"
    # centre of mass at rest to rounding
    assert np.abs(s.velocities.sum(0)).max() < 1e-12
    # fixed speed sqrt(2) up to the drift removal, a shift of O(sqrt(2/N))
    speed = np.linalg.norm(s.velocities, axis=1)
    assert abs(speed.mean() - math.sqrt(2)) < 0.01
    # isotropic: each of <v_x^2>, <v_y^2>, <v_z^2> = 2/3, with relative standard error
    # sqrt(Var(v_a^2)) / (<v_a^2> sqrt N) = sqrt(4/5) / sqrt(4000) ~ 1.4% for a fixed
    # speed in random directions; 5 sigma.  The thesis' eq. 3.3 would give
    # <v_z^2> = 1 (50% too much) and fail this.
    comp = (s.velocities**2).mean(0)
    np.testing.assert_allclose(comp, 2 / 3, rtol=5 * 0.0142)
    # uniform positions: each octant holds N/8 +- sqrt(N/8 * 7/8), 5 sigma
    octant = ((s.positions > 0.5) * [1, 2, 4]).sum(1)
    counts = np.bincount(octant, minlength=8)
    assert np.all(np.abs(counts - 500) < 5 * math.sqrt(500 * 7 / 8))


def test_random_scene_temperature():
    s = Scene.random(5000, 0.005, dim=2, temperature=2.5, seed=3)
    # T estimate from 2N velocity components: relative standard error sqrt(2 / (2N)) = 1.4%
    assert s.temperature == pytest.approx(2.5, rel=5 * math.sqrt(1 / 5000))


def _fcc_order(positions, n):
    """Crystalline order seen by the structure factor at the reciprocal-lattice vectors of
    the face-centred cubic lattice that ``Scene.random`` starts dense scenes on (k^3 cubic
    cells of side a = 1/k in the unit box, k = ceil((n/4)^(1/3))).

    Returns Q = N <|rho_G|^2> averaged over the 13 independent (up to sign) vectors of the
    stars {111}, {200}, {220}, G = (2 pi / a)(h, k, l), rho_G = (1/N) sum_j exp(i G.r_j).
    Every lattice site has G.r = 2 pi * integer + a common phase, so any set of sites
    gives |rho_G| = 1 and Q = N exactly.  In a homogeneous isotropic fluid N |rho_G|^2 is
    S(|G|) times an Exp(1) variable (central limit theorem), so Q ~ S Gamma(13) / 13.
    """
    k = math.ceil((n / 4) ** (1 / 3))
    stars = [
        g
        for g in itertools.product(range(-2, 3), repeat=3)
        if sum(x * x for x in g) in (3, 4, 8) and len({x % 2 for x in g}) == 1
    ]
    half = [g for g in stars if g > tuple(-x for x in g)]  # one of each +-G pair
    G = 2 * math.pi * k * np.array(half, dtype=float)
    rho = np.exp(1j * positions @ G.T).mean(axis=0)
    return len(positions) * float(np.mean(np.abs(rho) ** 2)), len(half)


@pytest.mark.parametrize(
    "eta",
    [
        0.33,  # above the 3D random-addition limit (0.28): placed on the lattice, then melted
        0.45,  # dense, below freezing (0.494): needs hundreds of collisions per particle
    ],
)
def test_dense_random_scene_melts_a_lattice(eta):
    """A dense scene starts on an FCC lattice (placement.place_lattice) and must come out a
    fluid.  Order measure: Q of ``_fcc_order`` -- N for the unmelted lattice, S(G) times
    Gamma(13)/13 in a fluid.  Bound: the structure factor of the hard-sphere fluid stays
    below 2.85 up to freezing (Hansen-Verlet criterion, S(k_max) = 2.85 at eta = 0.494),
    so a fluid passes Q < 2.85 * q with q the 1 - 1e-6 quantile of Gamma(13)/13 (2.9):
    Q < 8.3, false alarm <= 1e-6.  The lattice (Q = 2000) fails it by a factor 240, a
    vibrating crystal keeps the Debye-Waller fraction exp(-G^2 <u^2> / 3) of that (Q ~ 700
    at eta = 0.5), residual order of a few percent in rho_G (Q ~ 10 at eta = 0.4) fails
    too; a fluid measures Q ~ 1."""
    from granular.placement import place_lattice
    from granular.scene import _RSA_LIMIT

    n = 2000
    r = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3)
    assert eta > _RSA_LIMIT[3]  # the lattice route is taken
    lattice, _ = place_lattice(
        np.random.default_rng(2), np.full(n, r), np.zeros(3), np.ones(3), True
    )
    q_lattice, m = _fcc_order(lattice, n)
    assert m == 13
    assert q_lattice == pytest.approx(n, rel=1e-9)  # the measure sees the lattice
    s = Scene.random(n, r, seed=2)
    assert s.packing_fraction == pytest.approx(eta)
    bound = 2.85 * stats.gamma.isf(1e-6, m) / m
    q_melted, _ = _fcc_order(s.positions, n)
    assert q_melted < bound, (
        f"lattice order left: Q = {q_melted:.1f} (fluid: < {bound:.1f}, lattice: {n})"
    )


def test_too_dense_random_scene_is_refused():
    n = 2000
    with pytest.raises(ValueError, match="do not fit"):
        Scene.random(n, (0.8 / (n * 4 / 3 * math.pi)) ** (1 / 3), seed=2)


@pytest.mark.parametrize(
    "dim,boundary", [(2, "periodic"), (2, "walls"), (3, "periodic"), (3, "walls")]
)
def test_random_mixtures_keep_each_particle_its_radius(dim, boundary):
    """Two and three species, size ratios up to 3, packing up to the RSA limit, many seeds:
    each particle gets the radius asked for at its index (the scene validates, so no
    overlap, inside the box), and every species is spread over the box.  Random sequential
    addition rejects some candidates in almost every round here, which used to hand a small
    particle's slot to a big one (OverlapError, OutsideBoxError)."""
    n = 150
    for seed in range(12):
        rng = np.random.default_rng(seed)
        ratio = rng.uniform(1.5, 3.0)
        sizes = [1.0, ratio] if seed % 2 else [1.0, rng.uniform(1.0, ratio), ratio]
        rel = np.array(sizes)[np.arange(n) % len(sizes)]
        rng.shuffle(rel)
        eta = rng.uniform(0.05, 0.15 if dim == 3 else 0.3)
        unit = math.pi if dim == 2 else 4 * math.pi / 3
        radii = rel * (eta / (unit * np.sum(rel**dim))) ** (1 / dim)
        s = Scene.random(n, radii, dim=dim, boundary=boundary, seed=seed)
        np.testing.assert_array_equal(s.radii, radii)
        # the biggest species (n / species particles): its centres' mean along each axis
        # is uniform on the reachable interval, standard deviation sqrt(1/12 / count)
        # <= 0.075 here; 5 of them is far wider than chance and far narrower than a
        # species crowded into one place
        big = s.positions[radii == radii.max()]
        assert np.all(np.abs(big.mean(0) - 0.5) < 5 * math.sqrt(1 / 12 / len(big)))


def test_random_mixture_from_the_report_validates():
    radii = np.where(np.arange(40) % 2 == 0, 0.02, 0.045)
    s = Scene.random(40, radii, dim=2, seed=0)
    np.testing.assert_array_equal(s.radii, radii)


def test_walls_scene_keeps_particles_inside():
    s = Scene.random(500, 0.02, dim=2, box=(-3, 3), boundary="walls", seed=4)
    assert np.all(s.positions - 0.02 >= -3) and np.all(s.positions + 0.02 <= 3)


def test_replace_and_repr():
    s = Scene.random(10, 0.05, seed=5)
    g = s.replace(restitution=0.5)
    assert g.restitution == 0.5 and np.array_equal(g.positions, s.positions)
    assert "restitution=0.5" in repr(g)
    with pytest.raises(TypeError, match="unknown Scene fields"):
        s.replace(colour="red")
    with pytest.raises(ValueError):
        s.positions[0, 0] = 1.0  # read-only


@pytest.mark.parametrize(
    "field, value, instead",
    [
        ("restitution", 7.5, "replace(restitution="),  # a value the checks would refuse
        ("positions", np.zeros((10, 3)), "replace(positions="),  # every particle overlapping
        ("lower", np.zeros(3), "replace(box="),
        ("colour", "red", "replace(...) of its fields positions, velocities"),
    ],
)
def test_a_scene_is_immutable(field, value, instead):
    """Setting a field after construction would skip its checks: refused, naming
    ``replace``, which makes a checked copy; the scene is unchanged."""
    s = Scene.random(10, 0.05, seed=5)
    before = repr(s)
    message = rf"immutable: {field} cannot be set.*{re.escape(instead)}"
    with pytest.raises(AttributeError, match=message):
        setattr(s, field, value)
    with pytest.raises(AttributeError, match="cannot be deleted"):
        delattr(s, "restitution")
    assert repr(s) == before and not hasattr(s, "colour")
    with pytest.raises(ValueError, match=r"restitution must lie in \[0, 1\]"):
        s.replace(restitution=7.5)


# -- bad input: a clear exception, never a crash --------------------------------------

GOOD = dict(positions=[[0.2, 0.2], [0.6, 0.6]], velocities=[[1, 0], [0, 1]], radii=0.1)


def make(**changes):
    kw = dict(GOOD)
    kw.update(changes)
    p, v, r = kw.pop("positions"), kw.pop("velocities"), kw.pop("radii")
    return Scene(p, v, r, **kw)


@pytest.mark.parametrize(
    "changes,error,match",
    [
        (
            dict(positions=[[0.2, 0.2], [0.3, 0.2]]),
            granular.OverlapError,
            "particles 0 and 1 overlap",
        ),
        (dict(positions=[[0.2, 0.2], [1.6, 0.6]]), granular.OutsideBoxError, "particle 1"),
        (
            dict(positions=[[0.05, 0.2], [0.6, 0.6]], boundary="walls"),
            granular.OutsideBoxError,
            "crosses a wall",
        ),
        (dict(positions=[[np.nan, 0.2], [0.6, 0.6]]), ValueError, "NaN"),
        (dict(velocities=[[np.inf, 0], [0, 1]]), ValueError, "NaN or infinity"),
        (dict(radii=[0.1, -0.1]), ValueError, r"radii must .*, got -0.1 in the array \(index 1\)"),
        (dict(radii=[0.1, 0.0]), ValueError, "radii must be positive"),
        (dict(masses=[1.0, 0.0]), ValueError, "masses must be positive"),
        (dict(restitution=1.5), ValueError, "restitution must lie in"),
        (dict(restitution=-0.1), ValueError, "restitution must lie in"),
        (dict(wall_restitution=0.0), ValueError, "wall_restitution"),
        (dict(contact_duration=-1.0), ValueError, "contact_duration"),
        (dict(velocities=[[1, 0, 0], [0, 1, 0]]), ValueError, "velocities must have shape"),
        (dict(positions=[[0.2], [0.6]]), ValueError, "shape"),
        (dict(positions=[[0.2, 0.2, 0.2, 0.2]]), ValueError, "shape"),
        (dict(positions=np.zeros((0, 2)), velocities=np.zeros((0, 2))), ValueError, "N >= 1"),
        (dict(radii=[0.1, 0.1, 0.1]), ValueError, "radii must have shape"),
        (dict(boundary="open"), ValueError, "boundary must be one of"),
        (dict(box=(1.0, 0.0)), ValueError, "lower < upper"),
        (dict(radii=0.3, positions=[[0.3, 0.3], [0.9, 0.9]]), ValueError, "two largest diameters"),
        (dict(positions="abc"), TypeError, "positions must be numbers"),
        (dict(velocities=[[1j, 0], [0, 1]]), TypeError, "velocities must be real numbers"),
    ],
)
def test_bad_scenes_raise_clear_errors(changes, error, match):
    with pytest.raises(error, match=match):
        make(**changes)


def test_overlap_error_names_the_pair_across_periodic_images():
    with pytest.raises(granular.OverlapError) as info:
        Scene([[0.02, 0.5], [0.5, 0.1], [0.97, 0.5]], np.zeros((3, 2)), 0.05)
    assert info.value.particles == (0, 2)
    assert info.value.value == pytest.approx(0.05, rel=1e-9)


def test_bad_run_arguments():
    sim = Simulation(Scene.random(20, 0.05, seed=1))
    with pytest.raises(ValueError, match="strictly increasing"):
        sim.run(t_stop=1.0, sample_times=[0.5, 0.2])
    with pytest.raises(ValueError, match="finite"):
        sim.run(t_stop=1.0, sample_times=[0.1, np.nan])
    with pytest.raises(ValueError, match="past t_stop"):
        sim.run(t_stop=1.0, sample_times=[0.5, 2.0])
    with pytest.raises(ValueError, match="unknown stop_when"):
        sim.run(stop_when={"collisions": 3})
    with pytest.raises(ValueError, match="store may contain"):
        sim.run(t_stop=1.0, store=("forces",))
    with pytest.raises(ValueError, match="NaN"):
        sim.run(t_stop=float("nan"))
    sim.run(t_stop=1.0)
    with pytest.raises(ValueError, match="before the current time"):
        sim.run(t_stop=0.5)
    with pytest.raises(ValueError, match="before the current time"):
        sim.run(t_stop=2.0, sample_times=[0.5, 1.5])
    with pytest.raises(TypeError, match=r"needs a granular\.Scene"):
        Simulation("scene")
    with pytest.raises(ValueError, match="cell_factor"):
        Simulation(Scene.random(20, 0.05, seed=1), cell_factor=0.5)


def test_heated_walls_report_non_finite_velocities():
    """Walls with restitution > 1 pump energy in exponentially; when speeds overflow the
    engine stops with NonFiniteError instead of carrying infinities on."""
    s = Scene([[0.5, 0.5]], [[1.0, 0.0]], 0.1, boundary="walls", wall_restitution=1e100)
    with pytest.raises(granular.NonFiniteError):
        Simulation(s).run(t_stop=10.0)


# -- inelastic collapse ------------------------------------------------------------------


def test_collapse_of_three_disks_is_detected():
    """Three disks in a line collapse for xi < 7 - 4 sqrt 3 = 0.0718 (thesis 2.3): the
    engine raises InelasticCollapseError naming the particles and the time, after a
    bounded number of collisions."""
    sim = Simulation(three_in_line(0.05))
    with pytest.raises(granular.InelasticCollapseError) as info:
        sim.run(t_stop=10.0)
    err = info.value
    assert set(err.particles) <= {0, 1, 2} and 1 in err.particles
    assert err.time == pytest.approx(0.1, abs=1e-6)  # the first contact is at t = 0.1
    assert sim.stats["pair_collisions"] < 100
    # the state stays consistent: the scene can still be read
    assert sim.scene.n == 3


def test_tc_model_lets_the_same_run_finish():
    sim = Simulation(three_in_line(0.05, tc=1e-3))
    tr = sim.run(t_stop=10.0)
    assert tr.stop_reason == "time"
    assert sim.stats["tc_elastic_collisions"] > 0


def test_no_collapse_above_the_threshold():
    """xi = 0.2 > 0.0718: a finite number of collisions, no error."""
    sim = Simulation(three_in_line(0.2))
    assert sim.run(t_stop=10.0).stop_reason == "time"


def test_si_units_work():
    """Argon in SI units (diameter 3.4e-10 m, mass 6.6e-26 kg, thermal speeds ~ 250 m/s at
    300 K, a box of 1e-8 m) is far inside the scales the collision arithmetic handles: it
    validates and runs elastically, conserving energy to rounding (1e-12 relative)."""
    kT, m = 1.380649e-23 * 300.0, 6.63e-26
    s = Scene.random(200, 1.7e-10, box=1e-8, mass=m, temperature=kT, seed=1)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 5})
    assert sim.stats["pair_collisions"] >= 500
    assert sim.scene.kinetic_energy == pytest.approx(s.kinetic_energy, rel=1e-12)
    assert s.temperature == pytest.approx(kT, rel=0.3)  # 200 Maxwellian particles


@pytest.mark.parametrize(
    "change,match",
    [
        (dict(masses=1e-310), "smallest mass"),
        (dict(masses=1e308), "mass = 1e\\+308"),
        (
            dict(masses=np.where(np.arange(8) % 2, 1e-279, 1.0)),
            "diameter squared times the smallest mass",
        ),
        (dict(velocities=np.full((8, 3), 1e154)), "largest speed"),
    ],
)
def test_scales_outside_float64s_reach_are_refused(change, match):
    """Masses 1e-310 or 1e308, speeds 1e154 gave NaN positions, pairs passing through each
    other or collisions without impulse; now the scene names the scale that is out of range."""
    pos = np.stack([np.arange(8) * 0.12 + 0.05, np.full(8, 0.5), np.full(8, 0.5)], 1)
    base = dict(positions=pos, velocities=np.ones((8, 3)), radii=0.05)
    base.update(change)
    with pytest.raises(ValueError, match=match):
        Scene(base.pop("positions"), base.pop("velocities"), base.pop("radii"), **base)


@pytest.mark.parametrize("offset,ok", [(1e15, False), (1e13, False), (1e3, True)])
def test_a_box_far_from_the_origin_must_still_resolve_a_diameter(offset, ok):
    """Diameter 0.1 in a box at 1e15 (coordinate steps 0.125) let particles pass through
    each other, at 1e13 (steps 0.002) 3 % of them overlapped.  Refused unless a float64
    step at the box is at most 1e-11 of the smallest diameter; at 1e3 (steps 1e-13) fine."""
    pos = offset + np.stack([np.arange(8) * 0.12 + 0.05, np.full(8, 0.5)], 1)
    make = lambda: Scene(pos, np.ones((8, 2)), 0.05, box=(offset, offset + 1.0))  # noqa: E731
    if ok:
        make()
    else:
        with pytest.raises(ValueError, match=r"resolves coordinates near .* move the box"):
            make()


def test_counts_and_boxes_beyond_float64_are_refused():
    with pytest.raises(ValueError, match="n must be a whole number, got inf"):
        Scene.random(math.inf, 0.05)
    with pytest.raises(ValueError, match="n must be a whole number"):
        Scene.random(math.nan, 0.05)
    # all lengths x 1e-150: the volume underflows to 0 (it used to divide by zero later)
    with pytest.raises(ValueError, match="volume"):
        Scene.random(10, 0.05e-150, box=1e-150)
    with pytest.raises(ValueError, match="volume"):
        Scene.random(10, 0.05e120, box=1e120)
