"""Physics of the event-driven engine against equilibrium statistical mechanics.

Tolerances: statistical ones come from the sample sizes (stated at each assert); where an
approximate theory is the reference (Carnahan-Starling, Henderson, Enskog), its own
accuracy at that density is the tolerance."""
import math

import numpy as np
import pytest
from scipy import stats

from granular import Scene, Simulation


def radius_for(n, eta, dim):
    return (eta / (n * 4 / 3 * math.pi)) ** (1 / 3) if dim == 3 else math.sqrt(eta / (n * math.pi))


@pytest.mark.parametrize("dim", [2, 3])
def test_fixed_speeds_relax_to_maxwell_boltzmann(dim):
    """All particles start with one speed; after ~30 collisions each the speeds follow the
    Maxwell-Boltzmann distribution (thesis 2.4, Figs 4.5-4.6).  Kolmogorov-Smirnov test of
    speed / sqrt(T/m) against the chi distribution with d degrees of freedom at
    significance 1e-4 (one snapshot: velocities in a dilute gas are nearly independent);
    the velocity-component kurtosis is 3 within 5 standard errors sqrt(24 / M)."""
    n = 4000
    s = Scene.random(n, radius_for(n, 0.1, dim), dim=dim, seed=21)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 30})
    v = sim.scene.velocities
    T = s.temperature
    speed = np.linalg.norm(v, axis=1) / math.sqrt(T)
    assert stats.kstest(speed, stats.chi(dim).cdf).pvalue > 1e-4
    comp = v.ravel()
    kurt = np.mean(comp**4) / np.mean(comp**2) ** 2
    assert abs(kurt - 3.0) < 5 * math.sqrt(24 / comp.size)
    # and the start was far from it: a fixed speed has component kurtosis 9/5 (3D), 3/2 (2D)
    k0 = np.mean(s.velocities.ravel() ** 4) / np.mean(s.velocities.ravel() ** 2) ** 2
    assert abs(k0 - 3.0) > 1.0


@pytest.mark.parametrize("dim,eta,accuracy", [
    # Carnahan-Starling Z = (1 + eta + eta^2 - eta^3) / (1 - eta)^3: within 0.3% of
    # simulation data up to eta = 0.45
    (3, 0.065, 0.01),
    (3, 0.30, 0.01),
    (3, 0.45, 0.015),
    # Henderson Z = (1 + eta^2 / 8) / (1 - eta)^2: within 0.5% up to eta = 0.5
    (2, 0.30, 0.01),
])
def test_pressure_from_collision_virial_follows_the_equation_of_state(dim, eta, accuracy):
    """Compressibility factor Z = P / (n T) from the collision virial against the hard-sphere
    (hard-disk) equation of state.  Statistical error of the virial over ~1e5 collisions is
    ~0.3%; the approximate equations of state are good to ~0.3-0.5%; tolerance 1%
    (1.5% at eta = 0.45 where CS starts to drift)."""
    n = 2000
    s = Scene.random(n, radius_for(n, eta, dim), dim=dim, seed=22)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    t0 = sim.time
    span = 100 * t0 / 20  # about 100 collisions per particle
    tr = sim.run(t_stop=t0 + span, sample_times=[t0, t0 + span], store=())
    if dim == 3:
        theory = (1 + eta + eta**2 - eta**3) / (1 - eta) ** 3
    else:
        theory = (1 + eta**2 / 8) / (1 - eta) ** 2
    assert tr.pressure() / (s.density * s.temperature) == pytest.approx(theory, rel=accuracy)


def test_trajectory_pressure_and_enskog_collision_rate():
    """Trajectory.pressure() gives the same Z, and the collision rate per particle matches
    Enskog's 4 n sigma^2 g2 sqrt(pi T / m) in 3D with the Carnahan-Starling contact value
    g2 = (1 - eta/2) / (1 - eta)^3 -- exact for hard spheres given the true g2, and CS is
    within 1% of it at eta = 0.2; statistical error of ~1e5 collisions is 0.3%."""
    n, eta = 2000, 0.2
    r = radius_for(n, eta, 3)
    s = Scene.random(n, r, seed=23)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 10}, store=())
    t0 = sim.time
    tr = sim.run(t_stop=t0 + 4.0, sample_times=np.linspace(t0, t0 + 4.0, 9), store=())
    g2 = (1 - eta / 2) / (1 - eta) ** 3
    z_cs = (1 + eta + eta**2 - eta**3) / (1 - eta) ** 3
    assert tr.pressure() / (s.density * s.temperature) == pytest.approx(z_cs, rel=0.01)
    rate = 2 * (tr.pair_collisions[-1] - tr.pair_collisions[0]) / (n * 4.0)
    sigma = 2 * r
    enskog = 4 * s.density * sigma**2 * g2 * math.sqrt(math.pi * s.temperature)
    assert rate == pytest.approx(enskog, rel=0.015)


def test_wall_pressure_equals_the_bulk_pressure_in_a_dilute_box():
    """In a walled box the momentum given to the walls per unit time and per unit of the
    area the centres reach is the bulk pressure n_c T Z, with n_c = N / (L - 2r)^3 and
    Z = 1 + 4 eta g2 (dilute, eta = 0.01: Z - 1 is only 4%, so the approximation in the
    contact value hardly matters).  Statistical error of ~1e5 wall hits ~0.3%; tolerance
    1%."""
    n, eta = 1000, 0.01
    r = radius_for(n, eta, 3)
    s = Scene.random(n, r, boundary="walls", seed=24)
    tr = Simulation(s).run(t_stop=40.0, sample_times=[5.0, 40.0], store=())
    n_c = n / (1 - 2 * r) ** 3
    g2 = (1 - eta / 2) / (1 - eta) ** 3
    assert tr.wall_pressure() / (n_c * s.temperature) == pytest.approx(1 + 4 * eta * g2, rel=0.01)
