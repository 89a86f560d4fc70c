"""Uniform shear flow at Navier-Stokes order (granular/theory/shear.py) against the
dilute limit worked by hand from Garzo & Dufty's coefficients, and its limits."""

import math

import numpy as np
import pytest

from granular import theory


@pytest.mark.parametrize("xi", [0.95, 0.8, 0.5])
def test_dilute_limit_by_hand(xi):
    """At packing -> 0 (chi -> 1, no collisional transfer), 3D, sigma = m = T = 1:
    eta* = (5 / (16 sqrt(pi))) / (nu* - zeta*/2) with nu* = (1/4)(1 - xi + 2)(1 + xi),
    zeta*/2 = (5/24)(1 - xi^2) (Garzo & Dufty 1999 in units of n T / eta0), and
    zeta = (1 - xi^2) omega / 3 with omega = 4 sqrt(pi) n (the Enskog collision
    frequency), so gamma*^2 = (3/2) n zeta / eta* in which n cancels... except in zeta's
    own n: gamma*^2 = (3/2) n* (1 - xi^2) (4 sqrt(pi) n* / 3) / eta*.  Checked at packing
    1e-6, where chi - 1 and the collisional terms are ~1e-6."""
    phi = 1e-6
    n = 6 * phi / math.pi
    nu = 0.25 * (3 - xi) * (1 + xi)
    eta_star = 5 / (16 * math.sqrt(math.pi)) / (nu - 5 / 24 * (1 - xi**2))
    zeta = (1 - xi**2) * 4 * math.sqrt(math.pi) * n / 3
    want = math.sqrt(1.5 * n * zeta / eta_star)
    assert theory.usf_shear_rate(phi, restitution=xi) == pytest.approx(want, rel=1e-4)
    assert theory.usf_viscosity(phi, restitution=xi) == pytest.approx(eta_star, rel=1e-4)


def test_temperature_scales_with_the_shear_rate_squared_and_the_balance_holds():
    """T = m (gamma sigma / gamma*)^2, and at that T the Navier-Stokes heating
    gamma^2 eta equals the cooling (d/2) n T zeta computed by the package's own
    coefficients (the balance, to rounding)."""
    eta, r, xi, m = 0.2, 0.03, 0.8, 2.0
    t1 = theory.usf_temperature(1.5, eta=eta, radius=r, restitution=xi, mass=m)
    t2 = theory.usf_temperature(3.0, eta=eta, radius=r, restitution=xi, mass=m)
    assert t2 == pytest.approx(4 * t1, rel=1e-12)
    n = eta / (4 / 3 * math.pi * r**3)
    kw = dict(density=n, radius=r, restitution=xi, temperature=t1, mass=m, eta=eta)
    heating = 1.5**2 * theory.shear_viscosity(**kw)
    cooling = 1.5 * n * t1 * theory.cooling_rate(**kw)
    assert heating == pytest.approx(cooling, rel=1e-12)


def test_elastic_has_no_steady_state_and_2d_works():
    assert theory.usf_shear_rate(0.2, restitution=1.0) == 0.0
    assert np.isinf(theory.usf_temperature(1.0, eta=0.2, radius=0.5, restitution=1.0))
    g2 = theory.usf_shear_rate(np.array([0.1, 0.3]), restitution=0.8, dim=2)
    assert np.all(np.isfinite(g2)) and np.all(g2 > 0)
    with pytest.raises(ValueError, match="restitution"):
        theory.usf_shear_rate(0.2, restitution=1.5)
    with pytest.raises(ValueError, match="shear_rate"):
        theory.usf_temperature(-1.0, eta=0.2, radius=0.5, restitution=0.8)
