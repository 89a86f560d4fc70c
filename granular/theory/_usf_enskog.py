"""The numerics behind ``theory.usf_enskog``: the Enskog collision moments of a sheared gas
whose peculiar velocities are Gaussian with covariance C, integrated over the contact
direction by quadrature, and the steady state found by Newton's method.

Units: sigma = m = 1 and T = tr(C) / d = 1, so the shear rate a is gamma* and the number
density n is n sigma^d.  A collision of particles 1 and 2 with unit vector s from 2 to 1:
the relative velocity at contact is g = g0 + a s_y e_x (g0 = V1 - V2 of the peculiar
velocities, the second term the mean flow's difference across sigma), the pair approaches
when w = -s.g > 0 and the impulse per mass on 1 is Delta = (1 + alpha) w s / 2.  With V1, V2
independent N(0, C): g0 ~ N(0, 2C) and u = s.g ~ N(mu, v), mu = a s_x s_y, v = 2 s.C.s;
E[g0 | s.g0] = 2 C s (s.g0) / v.  Per unit volume and time (the pair rate (1/2) n^2 chi
sigma^(d-1) w over the contact directions)::

    Lambda_ij = (n^2 chi / 2) Int ds { (1+alpha)/2 [s_i h_j + h_i s_j] E[w^2 (u - mu)] / v
                                        + (1+alpha)^2 / 2 s_i s_j E[w^3] }      (h = 2 C s)
    Pc_ij     = (n^2 chi / 4) (1 + alpha) Int ds s_i s_j E[w^2]

(the change of sum m V_i V_j a collision makes is Delta_i g0_j + g0_i Delta_j + 2 Delta_i
Delta_j; the centre-of-mass velocity drops out).  E[.] over u < 0 are moments of a truncated
Gaussian, in closed form.
"""

from __future__ import annotations

import math

import numpy as np

# quadrature over the unit sphere (Gauss-Legendre in cos(theta) x uniform phi) and circle;
# the integrands are smooth in s, so these reach ~1e-12 (tests/test_theory_usf.py checks
# the elastic virial pressure to 1e-10)
_N_THETA, _N_PHI, _N_CIRCLE = 40, 80, 160


def _directions(dim):
    """(unit vectors (K, d), weights (K,)) integrating over the unit sphere (circle)."""
    if dim == 2:
        phi = 2.0 * math.pi * (np.arange(_N_CIRCLE) + 0.5) / _N_CIRCLE
        s = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        return s, np.full(_N_CIRCLE, 2.0 * math.pi / _N_CIRCLE)
    x, wx = np.polynomial.legendre.leggauss(_N_THETA)
    phi = 2.0 * math.pi * (np.arange(_N_PHI) + 0.5) / _N_PHI
    ct, ph = np.meshgrid(x, phi, indexing="ij")
    st = np.sqrt(1.0 - ct**2)
    s = np.stack([st * np.cos(ph), st * np.sin(ph), ct], axis=-1).reshape(-1, 3)
    w = np.repeat(wx, _N_PHI) * (2.0 * math.pi / _N_PHI)
    return s, w


_DIRS = {2: _directions(2), 3: _directions(3)}


def _negative_moments(mu, v):
    """E[u^k; u < 0] for k = 1, 2, 3 of u ~ N(mu, v)."""
    from scipy.special import ndtr

    sd = np.sqrt(v)
    z = -mu / sd
    cdf = ndtr(z)
    pdf = np.exp(-0.5 * z * z) / math.sqrt(2.0 * math.pi)
    z1, z2, z3 = -pdf, cdf - z * pdf, -(z * z + 2.0) * pdf  # E[Z^k; Z < z]
    m1 = mu * cdf + sd * z1
    m2 = mu * mu * cdf + 2.0 * mu * sd * z1 + v * z2
    m3 = mu**3 * cdf + 3.0 * mu * mu * sd * z1 + 3.0 * mu * v * z2 + sd * v * z3
    return m1, m2, m3


def moments(cov, shear, density, chi, alpha, dim):
    """(Lambda, Pc): the collision moment and the collisional stress (module docstring) for
    the Gaussian of covariance ``cov`` (d x d) at reduced shear rate ``shear``."""
    s, wq = _DIRS[dim]
    h = 2.0 * s @ cov  # (K, d): 2 C s
    v = np.einsum("kd,kd->k", s, h)
    mu = shear * s[:, 0] * s[:, 1]
    _m1, m2, m3 = _negative_moments(mu, v)
    # w = -u: E[w^2 (u - mu)] = E[u^3] - mu E[u^2], E[w^3] = -E[u^3], E[w^2] = E[u^2]
    cross = (m3 - mu * m2) / v
    outer_sh = np.einsum("k,ki,kj->ij", wq * cross, s, h)
    outer_ss3 = np.einsum("k,ki,kj->ij", wq * (-m3), s, s)
    outer_ss2 = np.einsum("k,ki,kj->ij", wq * m2, s, s)
    pref = 0.5 * density**2 * chi
    lam = pref * (
        0.5 * (1.0 + alpha) * (outer_sh + outer_sh.T) + 0.5 * (1.0 + alpha) ** 2 * outer_ss3
    )
    pc = 0.25 * density**2 * chi * (1.0 + alpha) * outer_ss2
    return lam, pc


def _unpack(x, dim, scale):
    """(covariance with trace d, shear rate) from the unknowns (the last one the shear rate
    over ``scale``, so that every unknown is of order one even in a dilute gas)."""
    if dim == 3:
        cxx, cyy, cxy, t = x
        cov = np.array([[cxx, cxy, 0.0], [cxy, cyy, 0.0], [0.0, 0.0, 3.0 - cxx - cyy]])
    else:
        cxx, cxy, t = x
        cov = np.array([[cxx, cxy], [cxy, 2.0 - cxx]])
    return cov, t * scale


def residual(x, density, chi, alpha, dim, scale):
    """The steady second-moment balance a (delta_ix C_yj + delta_jx C_yi) n = Lambda_ij,
    its independent components divided by n and ``scale`` (xx, yy, xy in 2D; xx, yy, zz,
    xy in 3D)."""
    cov, a = _unpack(x, dim, scale)
    if np.any(np.linalg.eigvalsh(cov) <= 0.0):
        return np.full(dim + 1, 1e3)  # not a covariance: push the solver back
    lam, _ = moments(cov, a, density, chi, alpha, dim)
    stream = np.zeros((dim, dim))
    stream[0, :] += a * cov[1, :]
    stream[:, 0] += a * cov[1, :]
    r = (stream - lam / density) / scale
    if dim == 3:
        return np.array([r[0, 0], r[1, 1], r[2, 2], r[0, 1]])
    return np.array([r[0, 0], r[1, 1], r[0, 1]])


def solve(density, chi, alpha, dim, guess_shear):
    """The steady state: (covariance, shear rate) solving ``residual`` = 0 (d + 1 equations,
    d + 1 unknowns: the trace of C is the temperature, fixed at 1), started from the
    Navier-Stokes shear rate ``guess_shear`` and a Navier-Stokes-sized anisotropy."""
    from scipy import optimize

    # the Navier-Stokes anisotropy C_xy = -eta* a / n ~ -a / (n chi) (dilute: eta* ~ 1),
    # scaled down; strongly inelastic dense cases may need another start
    args = (density, chi, alpha, dim, guess_shear)
    for factor in (0.1, 0.3, 0.03, 1.0):
        cxy = -factor * guess_shear / (density * chi)
        x0 = [1.0, 1.0, cxy, 1.0] if dim == 3 else [1.0, cxy, 1.0]
        sol = optimize.root(residual, x0, args=args, method="hybr", tol=1e-12)
        # judged by the residual itself: hybr may stop short of its tolerance at rounding
        if sol.x[-1] > 0.0 and float(np.max(np.abs(sol.fun))) < 1e-10:
            return _unpack(sol.x, dim, guess_shear)
    raise RuntimeError(
        f"the steady uniform shear flow was not found at n sigma^d = {density}, "
        f"alpha = {alpha}, d = {dim}: {sol.message}"
    )
