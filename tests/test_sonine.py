"""granular.theory.sonine: a2 of the cooling and the white-noise driven state and the driven
temperature.  The collision moments the formulas rest on are integrated here by Monte Carlo
(independently of any formula), the closed forms are checked to solve the moment equations
they come from, and the driven temperature to balance heating and cooling."""

import math

import numpy as np
import pytest

from granular import theory
from granular.theory.sonine import _coefficients


def _collision_moment_residuals(alpha, d, n, seed):
    """z-scores of mu2 and mu4's coefficients against _coefficients: pairs (c1, c2) drawn
    from the Maxwellian phi(c) ~ exp(-c^2), a random unit vector e, the collision taken
    where g.e > 0 with weight g.e (the Boltzmann kernel); X = (the integrand of one moment)
    - (predicted ratio) * (the integrand of mu2's Maxwellian part) has mean 0 if and only if
    the ratio is right."""
    rng = np.random.default_rng(seed)
    c1, c2 = (rng.normal(scale=math.sqrt(0.5), size=(n, d)) for _ in range(2))
    e = rng.normal(size=(n, d))
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    ge = np.einsum("nd,nd->n", c1 - c2, e)
    w = np.where(ge > 0, ge, 0.0)
    k = (1 + alpha) / 2 * ge
    p1, p2 = c1 - k[:, None] * e, c2 + k[:, None] * e
    x1, x2, y1, y2 = ((u**2).sum(1) for u in (c1, c2, p1, p2))

    def s2(x):
        return x * x / 2 - (d + 2) * x / 2 + d * (d + 2) / 8

    s = s2(x1) + s2(x2)  # the first-order part of F(c1) F(c2) / (phi phi)
    m2 = -w * (y1 + y2 - x1 - x2)
    m4 = -w * (y1**2 + y2**2 - x1**2 - x2**2)
    a0, a1, b0, b1 = _coefficients(alpha, d)
    checks = (m2 * s - a1 / a0 * m2, m4 - b0 / a0 * m2, m4 * s - b1 / a0 * m2)
    return [x.mean() / (x.std() / math.sqrt(n)) for x in checks]


@pytest.mark.parametrize(("alpha", "d"), [(0.5, 2), (0.8, 3)])
def test_collision_moments_by_monte_carlo(alpha, d):
    """mu2 = K (1 - a^2)(1 + 3 a2/16) and mu4 = K[(1 - a^2)(d + 3/2 + a^2) + a2 b1]: each
    coefficient within 5 standard errors of a Monte Carlo integral of 4e5 collisions
    (which resolves b1 to about 0.15 (5 sigma) and the others better)."""
    for z in _collision_moment_residuals(alpha, d, 400_000, seed=int(10 * alpha) + d):
        assert abs(z) < 5


@pytest.mark.parametrize("d", [2, 3])
def test_closed_forms_solve_their_moment_equations(d):
    """The cooling state's linear a2 is the linearised root of mu4 = (d+2)(1+a2) mu2, the
    driven state's the root of mu4 = (d+2) mu2, and the nonlinear form solves the first
    exactly (all from _coefficients)."""
    alpha = np.linspace(0.0, 0.99, 12)
    a0, a1, b0, b1 = _coefficients(alpha, d)
    cooling = theory.sonine_a2_cooling(restitution=alpha, dim=d)
    driven = theory.sonine_a2_driven(restitution=alpha, dim=d)
    nonlinear = theory.sonine_a2_cooling(restitution=alpha, dim=d, approximation="nonlinear")
    np.testing.assert_allclose(
        cooling, (b0 - (d + 2) * a0) / ((d + 2) * (a0 + a1) - b1), rtol=1e-12
    )
    np.testing.assert_allclose(driven, (b0 - (d + 2) * a0) / ((d + 2) * a1 - b1), rtol=1e-12)
    residual = (d + 2) * (1 + nonlinear) * (a0 + a1 * nonlinear) - b0 - b1 * nonlinear
    np.testing.assert_allclose(residual, 0.0, atol=1e-14)
    assert np.all(np.abs(nonlinear - cooling) < 0.25 * np.abs(cooling) + 1e-15)


def test_known_values_and_signs():
    """van Noije & Ernst's 3D numbers at xi = 0.8 and 0.5 (-0.0126 and 0.0525: the formula
    in 3D, 16(1-a)(1-2a^2)/(81 - 17 a + 30 a^2 (1-a))), 0 for elastic gases, the sign change
    at 1/sqrt(2), and the Maxwellian option."""
    assert theory.sonine_a2_cooling(restitution=0.8) == pytest.approx(-0.896 / 71.24)
    assert theory.sonine_a2_cooling(restitution=0.5) == pytest.approx(4.0 / 76.25)
    assert theory.sonine_a2_driven(restitution=0.5) == pytest.approx(4.0 / 156.25)
    for f in (theory.sonine_a2_cooling, theory.sonine_a2_driven):
        assert f(restitution=1.0, dim=2) == 0.0
        assert abs(f(restitution=1 / math.sqrt(2), dim=3)) < 1e-15
        assert f(restitution=0.8, approximation="maxwell") == 0.0
    with pytest.raises(ValueError, match="approximation must be one of"):
        theory.sonine_a2_driven(restitution=0.8, approximation="nonlinear")


@pytest.mark.parametrize("d", [2, 3])
def test_driven_temperature_balances_heating(d):
    """At the steady temperature the heating m xi0^2 equals zeta T, zeta =
    (1 - xi^2)(1 + 3 a2/16) omega(T) / d (theory.cooling_rate is the a2 = 0 part)."""
    kw = dict(density=800.0, radius=0.01, restitution=0.7, dim=d)
    t = theory.driven_temperature(strength=0.3, **kw)
    a2 = theory.sonine_a2_driven(restitution=0.7, dim=d)
    zeta = theory.cooling_rate(temperature=t, **kw) * (1 + 3 * a2 / 16)
    assert zeta * t == pytest.approx(0.3, rel=1e-12)
    assert theory.driven_temperature(strength=0.3, **{**kw, "restitution": 1.0}) == math.inf


@pytest.mark.parametrize("d", [2, 3])
def test_finite_kicks_solve_their_moment_equation(d):
    """With kicks of variance kick T/m the steady state needs mu4 = (d+2)(1 + kick/2) mu2;
    kick = 0 is the white-noise formula."""
    alpha = np.linspace(0.0, 0.99, 7)
    a0, a1, b0, b1 = _coefficients(alpha, d)
    for kick in (1e-9, 0.02, 0.5):
        a2 = theory.sonine_a2_driven(restitution=alpha, dim=d, kick=kick)
        g = (d + 2) * (1 + kick / 2)
        np.testing.assert_allclose(g * (a0 + a1 * a2) - b0 - b1 * a2, 0.0, atol=1e-13)
    np.testing.assert_allclose(
        theory.sonine_a2_driven(restitution=alpha, dim=d, kick=1e-12),
        theory.sonine_a2_driven(restitution=alpha, dim=d),
        atol=1e-12,
    )
