"""granular.theory.rough: the coupled cooling of rough particles, its limits and its
closed form against the equations integrated in time, and against a simulated gas."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, theory


@pytest.mark.parametrize("dim", [2, 3])
def test_smooth_particles_cool_by_haff_and_keep_their_spins(dim):
    """beta = -1 couples nothing: T falls as exp(-(1 - xi^2) s / d) per collision (Haff's
    law in the collision count), T_rot stays."""
    s = np.array([0.0, 1.0, 10.0, 100.0])
    T, R = theory.rough_temperatures(
        s, temperature0=2.0, rotational_temperature0=0.3, restitution=0.8,
        tangential_restitution=-1.0, dim=dim,
    )  # fmt: skip
    np.testing.assert_allclose(T, 2.0 * np.exp(-(1 - 0.64) * s / dim), rtol=1e-12)
    np.testing.assert_allclose(R, 0.3, rtol=1e-12)
    assert theory.rough_temperature_ratio(restitution=0.8, tangential_restitution=-1.0) == 0.0


@pytest.mark.parametrize("dim", [2, 3])
def test_perfectly_rough_elastic_particles_keep_the_energy_and_share_it_equally(dim):
    """beta = 1, xi = 1: d T + d_rot T_rot is kept at every s and the ratio tends to 1
    (equipartition), for any q."""
    d_rot = 1 if dim == 2 else 3
    s = np.linspace(0, 50, 11)
    for q in (0.2, 0.4, 1.0):
        T, R = theory.rough_temperatures(
            s, temperature0=1.0, rotational_temperature0=0.0, restitution=1.0,
            tangential_restitution=1.0, inertia_factor=q, dim=dim,
        )  # fmt: skip
        np.testing.assert_allclose(dim * T + d_rot * R, dim, rtol=1e-12)
        T, R = theory.rough_temperatures(
            [2000.0], temperature0=1.0, rotational_temperature0=0.0, restitution=1.0,
            tangential_restitution=1.0, inertia_factor=q, dim=dim,
        )  # fmt: skip
        assert R[-1] / T[-1] == pytest.approx(1.0, rel=1e-9)
        assert theory.rough_temperature_ratio(
            restitution=1.0, tangential_restitution=1.0, inertia_factor=q, dim=dim
        ) == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize(("dim", "beta", "xi"), [(2, 0.0, 0.9), (3, 0.5, 0.8), (3, -0.5, 0.95)])
def test_the_ratio_is_the_closed_forms_limit(dim, beta, xi):
    """The asymptotic T_rot / T_tr (the quadratic's root) is where the closed form goes,
    from either side (spins at rest or hot)."""
    r = theory.rough_temperature_ratio(restitution=xi, tangential_restitution=beta, dim=dim)
    for rot0 in (0.0, 5.0):
        T, R = theory.rough_temperatures(
            [400.0], temperature0=1.0, rotational_temperature0=rot0, restitution=xi,
            tangential_restitution=beta, dim=dim,
        )  # fmt: skip
        assert R[0] / T[0] == pytest.approx(r, rel=1e-8)


def test_known_ratio_values():
    """Numbers: in 3D for solid spheres (q = 2/5) at xi = 1 and beta = 0 the coefficients
    are eta = 1/7, A = 6/49, B = 5/98, C = 45/196 (k_tr = k_rot = 4/3), so r solves
    10 r^2 + 21 r - 10 = 0: r = (-21 + sqrt(841)) / 20 = 2/5.  In 2D (disks, q = 1/2) eta =
    1/6, A = 5/36, B = 1/18, C = 2/9, k_tr = 1, k_rot = 2: 2 r^2 + 11 r - 4 = 0."""
    co = theory.rough_coefficients(restitution=1.0, tangential_restitution=0.0, dim=3)
    assert (co.A, co.B, co.C) == pytest.approx((6 / 49, 5 / 98, 45 / 196), rel=1e-14)
    r = theory.rough_temperature_ratio(restitution=1.0, tangential_restitution=0.0, dim=3)
    assert r == pytest.approx(0.4, rel=1e-13)
    co = theory.rough_coefficients(restitution=1.0, tangential_restitution=0.0, dim=2)
    assert co == pytest.approx((5 / 36, 1 / 18, 2 / 9, 1.0, 2.0), rel=1e-14)
    r = theory.rough_temperature_ratio(restitution=1.0, tangential_restitution=0.0, dim=2)
    assert r == pytest.approx((-11 + math.sqrt(153)) / 4, rel=1e-13)


def test_cooling_in_time_is_the_closed_form_along_the_collisions():
    """rough_cooling (the equations integrated in t with the Enskog frequency) follows the
    closed form in the collision count s(t) = int omega(T) dt: computed here by the
    trapezoid rule on a fine grid (error ~1e-8)."""
    kw = dict(restitution=0.85, tangential_restitution=0.2, dim=3)
    gas = dict(density=2000.0, radius=0.01)
    t = np.linspace(0.0, 12.0, 40001)
    T, R = theory.rough_cooling(t, temperature0=1.0, rotational_temperature0=0.5, **gas, **kw)
    omega = theory.collision_frequency(temperature=T, **gas)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (omega[1:] + omega[:-1]) * np.diff(t))])
    T2, R2 = theory.rough_temperatures(s, temperature0=1.0, rotational_temperature0=0.5, **kw)
    np.testing.assert_allclose(T, T2, rtol=1e-6)
    np.testing.assert_allclose(R, R2, rtol=1e-6)
    assert s[-1] > 15  # into the asymptotic state (about 8 collisions per particle suffice)


def test_smooth_cooling_in_time_is_haffs_law():
    gas = dict(density=2000.0, radius=0.01)
    t = np.array([0.0, 1.0, 10.0])
    T, _ = theory.rough_cooling(
        t, temperature0=1.0, rotational_temperature0=0.0, restitution=0.8,
        tangential_restitution=-1.0, **gas,
    )  # fmt: skip
    tau0 = theory.haff_tau0(restitution=0.8, temperature0=1.0, **gas)
    np.testing.assert_allclose(
        T, theory.haff_temperature(t, temperature0=1.0, tau0=tau0), rtol=1e-8
    )


def test_a_rough_gas_cools_as_the_coupled_equations():
    """A 3D gas of N = 4000 rough spheres (xi = 0.9, beta = 0, spins at rest, packing 0.13)
    against the closed form in its own collision count, over 3 collisions per particle, where
    the gas is still homogeneous and nearly Maxwellian.  Four seeds: their mean T_rot and
    T_tr over theory.  The noise of one seed's T_rot, measured over 8 seeds at s = 0.5, is
    5 % (the energy passes through ~N s / 2 collisions, each moving a random amount), T_tr's
    0.5 %: the means of four lie within 4 sigma / 2, 10 % and 1 %."""
    ratios = []
    for seed in range(4):
        s0 = Scene.random(4000, 0.02, dim=3, seed=seed, temperature=1.0)
        s0 = s0.replace(restitution=0.9, tangential_restitution=0.0)
        sim = Simulation(s0)
        sim.run(stop_when={"collisions_per_particle": 3.0}, store=())
        st = sim.stats
        T, R = theory.rough_temperatures(
            st["collisions_per_particle"], temperature0=s0.temperature,
            rotational_temperature0=0.0, restitution=0.9, tangential_restitution=0.0, dim=3,
        )  # fmt: skip
        ratios.append((st["translational_temperature"] / T, st["rotational_temperature"] / R))
    tr, rot = np.mean(ratios, axis=0)
    assert tr == pytest.approx(1.0, abs=0.01)
    assert rot == pytest.approx(1.0, abs=0.10)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_sheared_ratio_is_the_rotational_balance(dim):
    """rough_sheared_temperature_ratio is B / C of the coupled equations (the rotational
    equation's fixed point at a given T): q (1 + beta) / (1 + 2 q - beta), 1 at beta = 1,
    0 at beta = -1, 1/4 for disks and 2/9 for solid spheres at beta = 0, whatever xi."""
    for beta in (-1.0, -0.3, 0.0, 0.5, 1.0):
        for q in (None, 0.25, 1.0):
            co = theory.rough_coefficients(
                restitution=0.7, tangential_restitution=beta, inertia_factor=q, dim=dim
            )
            r = theory.rough_sheared_temperature_ratio(
                tangential_restitution=beta, inertia_factor=q, dim=dim
            )
            if beta == -1.0:
                assert r == 0.0
            else:
                assert r == pytest.approx(co.B / co.C, rel=1e-13)
    assert theory.rough_sheared_temperature_ratio(tangential_restitution=1.0, dim=dim) == 1.0
    expected = 0.25 if dim == 2 else 2 / 9
    r = theory.rough_sheared_temperature_ratio(tangential_restitution=0.0, dim=dim)
    assert r == pytest.approx(expected, rel=1e-15)
    with pytest.raises(ValueError, match="tangential_restitution"):
        theory.rough_sheared_temperature_ratio(tangential_restitution=1.5, dim=dim)
