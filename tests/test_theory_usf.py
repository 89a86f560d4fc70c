"""The Enskog kinetic theory of uniform shear flow with the anisotropic-Gaussian closure
(granular/theory/shear.py ``usf_enskog``, granular/theory/_usf_enskog.py) against results it
must reproduce exactly: the virial pressure, Enskog's elastic viscosity, Garzo & Dufty's
cooling rate and Navier-Stokes balance as xi -> 1, the energy balance, and the dilute Grad
closed form (``usf_grad_dilute``)."""

import math

import numpy as np
import pytest

from granular import theory
from granular.theory import _usf_enskog as U


def _state(phi, dim):
    """(n sigma^d, chi) at sigma = 1."""
    unit = math.pi / 6 if dim == 3 else math.pi / 4
    return phi / unit, float(theory.contact_value(phi, dim=dim))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("phi", [0.05, 0.3])
def test_elastic_equilibrium_is_the_virial_pressure(dim, phi):
    """xi = 1, no shear, isotropic: no collisional change of the second moments, and
    p / (n T) = 1 + B n chi with B = 2 pi / 3 (3D), pi / 2 (2D) -- the virial theorem."""
    n, chi = _state(phi, dim)
    lam, pc = U.moments(np.eye(dim), 0.0, n, chi, 1.0, dim)
    assert np.max(np.abs(lam)) < 1e-12 * n
    b = 2 * math.pi / 3 if dim == 3 else math.pi / 2
    for k in range(dim):
        assert n + pc[k, k] == pytest.approx(n * (1 + b * n * chi), rel=1e-12)
    assert abs(pc[0, 1]) < 1e-14 * n


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("phi", [0.05, 0.3])
def test_elastic_linear_response_is_enskogs_first_sonine_viscosity(dim, phi):
    """At xi = 1 the xy balance linearised in the anisotropy eps = C_xy and the shear rate a
    gives eta = -(n eps + Pc_xy) / a: Enskog's first-Sonine viscosity, kinetic, collisional
    transfer and bulk parts together (``theory.enskog_viscosity``, an independent code:
    Chapman & Cowling, Gass).  Finite differences of step 1e-6 in functions smooth in both
    make the derivative's error ~1e-12; the tolerance 1e-8 allows it 10^4 times over."""
    n, chi = _state(phi, dim)
    h = 1e-6

    def xy(eps, a):
        cov = np.eye(dim)
        cov[0, 1] = cov[1, 0] = eps
        lam, pc = U.moments(cov, a, n, chi, 1.0, dim)
        return lam[0, 1], pc[0, 1]

    l_e, p_e = xy(h, 0.0)
    l_a, p_a = xy(0.0, h)
    # a n C_yy = Lambda_xy, C_yy = 1: eps per unit a
    eps = (n - l_a / h) / (l_e / h)
    eta = -(n * eps + p_e / h * eps + p_a / h)
    want = theory.enskog_viscosity(phi, radius=0.5, temperature=1.0, dim=dim)
    assert eta == pytest.approx(want, rel=1e-8)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("xi", [0.9, 0.5])
def test_cooling_rate_at_zero_shear_is_garzo_dufty(dim, xi):
    """-tr(Lambda) / (d n T) of the isotropic Gaussian at a = 0 is the cooling rate zeta =
    (1 - xi^2) omega / d (= Garzo & Dufty's zeta* at a2 = 0, ``theory.cooling_rate``)."""
    n, chi = _state(0.2, dim)
    lam, _ = U.moments(np.eye(dim), 0.0, n, chi, xi, dim)
    want = theory.cooling_rate(
        density=n, radius=0.5, restitution=xi, temperature=1.0, dim=dim, eta=0.2
    )
    assert -np.trace(lam) / (dim * n) == pytest.approx(want, rel=1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_energy_identity_for_any_anisotropy_and_the_steady_balance(dim):
    """The trace of the collision moment is the collisional energy loss D plus the work of
    the collisional stress: tr(Lambda) / 2 = -D - a Pc_xy, with D = (n^2 chi / 2) Int ds
    (1 - xi^2)/4 E[w^3] computed independently here (the loss m (1 - xi^2) w^2 / 4 per
    collision of normal approach speed w).  For any covariance and shear rate, to rounding;
    at the steady state of ``usf_enskog`` the viscous heating -a P_xy equals D."""
    rng = np.random.default_rng(5)
    n, chi, xi = *_state(0.25, dim), 0.8
    s, wq = U._DIRS[dim]
    for _ in range(3):
        m = rng.normal(size=(dim, dim))
        cov = np.eye(dim) + 0.2 * (m + m.T)
        a = rng.uniform(0.2, 2.0)
        lam, pc = U.moments(cov, a, n, chi, xi, dim)
        mu = a * s[:, 0] * s[:, 1]
        v = 2 * np.einsum("ki,ij,kj->k", s, cov, s)
        loss = 0.5 * n**2 * chi * (1 - xi**2) / 4 * np.sum(wq * -U._negative_moments(mu, v)[2])
        assert np.trace(lam) / 2 == pytest.approx(-loss - a * pc[0, 1], rel=1e-12)
    st = theory.usf_enskog(0.25, restitution=xi, dim=dim)
    cov, a = U.solve(n, chi, xi, dim, st.shear_rate)
    _, pc = U.moments(cov, a, n, chi, xi, dim)
    mu = a * s[:, 0] * s[:, 1]
    v = 2 * np.einsum("ki,ij,kj->k", s, cov, s)
    loss = 0.5 * n**2 * chi * (1 - xi**2) / 4 * np.sum(wq * -U._negative_moments(mu, v)[2])
    assert -a * (n * cov[0, 1] + pc[0, 1]) == pytest.approx(loss, rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("phi", [0.05, 0.3])
def test_navier_stokes_limit_linear_in_one_minus_xi(dim, phi):
    """As xi -> 1 the steady gamma* and eta* approach the Navier-Stokes balance with Garzo &
    Dufty's coefficients (``usf_shear_rate``, ``usf_viscosity``), which differ from USF at
    first order in 1 - xi (the -zeta/2 of the cooling reference state; the anisotropy):
    the relative difference is below 2e-4 at 1 - xi = 1e-4 and ten times smaller there
    than at 1e-3 (a ratio between 8 and 12: linear convergence, not a coincidence)."""
    diffs = []
    for xi in (0.999, 0.9999):
        st = theory.usf_enskog(phi, restitution=xi, dim=dim)
        g = theory.usf_shear_rate(phi, restitution=xi, dim=dim)
        e = theory.usf_viscosity(phi, restitution=xi, dim=dim)
        diffs.append((st.shear_rate / g - 1, st.viscosity / e - 1))
    for k in range(2):
        assert abs(diffs[1][k]) < 2e-4
        assert 8 < diffs[0][k] / diffs[1][k] < 12


@pytest.mark.parametrize("dim", [2, 3])
def test_dilute_limit_approaches_grad_as_xi_goes_to_one(dim):
    """At packing 1e-7 (chi - 1 and the collisional transfer ~1e-7) the Gaussian closure's
    a / nu0 and eta / eta0 approach the linear Grad form (``usf_grad_dilute``) as xi -> 1.
    They differ at second order in the anisotropy, and P_xy / p ~ a* ~ sqrt(1 - xi), so at
    first order in 1 - xi: below 2e-3 at xi = 0.99 and ten times smaller at 0.999 (ratio
    between 8 and 12)."""
    phi = 1e-7
    n, _ = _state(phi, dim)
    eta0 = 5 / (16 * math.sqrt(math.pi)) if dim == 3 else 1 / (2 * math.sqrt(math.pi))
    nu0 = n / eta0
    diffs = []
    for xi in (0.99, 0.999):
        st = theory.usf_enskog(phi, restitution=xi, dim=dim)
        gr = theory.usf_grad_dilute(restitution=xi, dim=dim)
        diffs.append(
            (st.shear_rate / nu0 / gr.shear_rate - 1, st.viscosity / eta0 / gr.viscosity - 1)
        )
    for k in range(2):
        assert abs(diffs[0][k]) < 2e-3
        assert 8 < diffs[0][k] / diffs[1][k] < 12


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("xi", [1.0, 0.9, 0.5])
def test_grad_dilute_closed_form_balances(dim, xi):
    """The Grad form's own equations: trace P_xx + (d-1) P_yy = d p; the energy balance
    (a/nu0)^2 P_yy / (p nu*) = (d/2) zeta*; eta/eta0 = P_yy / (p nu*); xi = 1 is equilibrium."""
    gr = theory.usf_grad_dilute(restitution=xi, dim=dim)
    zeta = (dim + 2) / (4 * dim) * (1 - xi**2)
    nu = 3 / (4 * dim) * (1 + xi) * (1 - xi + 2 * dim / 3)
    assert gr.pxx + (dim - 1) * gr.pyy == pytest.approx(dim, rel=1e-14)
    assert gr.shear_rate**2 * gr.pyy / nu == pytest.approx(dim / 2 * zeta, abs=1e-14)
    assert gr.viscosity == pytest.approx(gr.pyy / nu, rel=1e-14)
    if xi == 1.0:
        assert (gr.shear_rate, gr.viscosity, gr.pxx) == (0.0, 1.0, 1.0)


def test_second_normal_stress_difference_changes_sign_with_density():
    """Saha & Alam (J. Fluid Mech. 2016, abstract): with the anisotropic Gaussian, N2 < 0
    in the dilute limit and > 0 when dense, N1 > 0 falling with density.  3D, xi = 0.8."""
    dilute = theory.usf_enskog(1e-4, restitution=0.8)
    dense = theory.usf_enskog(0.3, restitution=0.8)
    assert dilute.n2 < 0 < dense.n2
    assert dilute.n1 > dense.n1 > 0
    assert np.trace(dense.stress) == pytest.approx(3.0, rel=1e-12)
    assert np.allclose(dense.stress, dense.stress.T, atol=1e-12)


def test_arrays_elastic_and_bad_input():
    st = theory.usf_enskog(np.array([0.1, 0.2]), restitution=np.array([0.9, 1.0]), dim=2)
    assert st.shear_rate[1] == 0.0 and np.isnan(st.viscosity[1]) and st.shear_rate[0] > 0
    assert st.n2[0] == 0.0 and st.stress.shape == (2, 2, 2)
    with pytest.raises(ValueError, match="restitution"):
        theory.usf_enskog(0.2, restitution=1.5)
    with pytest.raises(ValueError, match="eta"):
        theory.usf_enskog(1.2, restitution=0.8)
    with pytest.raises(ValueError, match="dim"):
        theory.usf_enskog(0.2, restitution=0.8, dim=4)
