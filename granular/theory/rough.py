"""The homogeneous cooling state of rough disks and spheres: translational and rotational
temperatures coupled by collisions with a normal restitution xi and a constant tangential
restitution beta (Huthmann & Zippelius 1997, PRE 56, R6275, in 3D; Luding, Huthmann,
McNamara & Zippelius 1998, PRE 58, 3416, in 2D and 3D; their equation numbers could not be
checked here, so the derivation is written out below).

Collisions (csrc/rule.h): equal particles of mass m, radius a, moment of inertia I = q m
a^2; the impulse is P = -eta_n m g_n - eta_t m g_t on the contact point's relative velocity
g, with eta_n = (1 + xi) / 2 and eta_t = q (1 + beta) / (2 (1 + q)).  Averaging the energy
each collision moves over a Maxwellian of the translational velocities (temperature T) and
an independent Gaussian of the spins (T_rot = <I w^2> / d_rot; d_rot = 1 in 2D, 3 in 3D) --
the weight |g . n| of a collision gives <g_n^2> = 4 T / m, <g_t^2> = 2 (d - 1) (T + T_rot /
q) / m -- gives, per collision of one particle (s: the mean collisions per particle, ds =
omega(T) dt with the Enskog collision frequency omega, granular.theory.collision_frequency):

    dT/ds     = (2 (d - 1) / d)     (-A T + B T_rot)
    dT_rot/ds = (2 (d - 1) / d_rot) ( B T - C T_rot)

    A = (1 - xi^2) / (2 (d - 1)) + eta_t (1 - eta_t),   B = eta_t^2 / q,
    C = (eta_t / q) (1 - eta_t / q).

In 3D these are Huthmann & Zippelius' eqs. (with their G = (4/3) omega / sqrt(T)); in 2D
the rotational equation carries twice the translational prefactor, as in Luding et al.
1998.  beta = -1 (eta_t = 0) is Haff's law, dT/ds = -(1 - xi^2) T / d; beta = 1 with xi =
1 keeps d T + d_rot T_rot.

In the collision count s the equations are linear with constant coefficients: their
solution is a sum of two exponentials (``rough_temperatures``), the closed form.  Time
follows from dt = ds / omega(T(s)) (``rough_cooling`` integrates the equations in t to
1e-10).  After a few collisions the slower mode dominates: T_rot / T approaches the root of
``rough_temperature_ratio`` and both decay as Haff's law with the slower rate.

Beyond the Maxwellian: in 3D spins and velocities become correlated in direction
(Brilliantov, Poeschel, Kranz & Zippelius, PRL 98, 128001 (2007); Kranz et al., arXiv
0808.1952) and the joint distribution has cumulants (Santos, Kremer & dos Santos, Phys.
Fluids 23, 030604 (2011); Megias & Santos, arXiv 2303.00057, disks and spheres with DSMC
and EDMD), which the root below leaves out (granular's 3D runs lie 1-3 % below it, its 2D
runs on it; tools/rough_spin_balance.py measures the correlation and finds it carries the
3D deficit); their corrections could not be read for this version (docs/rough.md).

Self-diffusion of rough spheres: the literature gives it for constant xi and beta
(Bodrova & Brilliantov, Granular Matter 14, 85 (2012), doi:10.1007/s10035-012-0319-2, with a
Sonine correction); its result could not be read here, so it is not implemented.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .haff import collision_frequency

# the default inertia factor q: a uniform disk (2D), a solid sphere (3D)
_Q_DEFAULT = {2: 0.5, 3: 0.4}


class RoughCoefficients(NamedTuple):
    """The coupled cooling equations' coefficients, per collision of one particle:
    ``dT/ds = k_tr (-A T + B T_rot)``, ``dT_rot/ds = k_rot (B T - C T_rot)``."""

    A: float
    B: float
    C: float
    k_tr: float
    k_rot: float


def _checked(xi, beta, q, dim):
    _check_dim(dim)
    xi, beta = float(xi), float(beta)
    q = _Q_DEFAULT[dim] if q is None else float(q)
    if not -1.0 <= beta <= 1.0:
        raise ValueError(f"tangential_restitution must lie in [-1, 1], got {beta}")
    if not 0.0 < q <= 1.0:
        raise ValueError(f"inertia_factor must lie in (0, 1], got {q}")
    return xi, beta, q


@keyword_only("restitution", "tangential_restitution", "inertia_factor", "dim")
def rough_coefficients(
    *,
    restitution: float,
    tangential_restitution: float,
    inertia_factor: float | None = None,
    dim: int = 3,
) -> RoughCoefficients:
    """The coefficients A, B, C of the coupled cooling equations of rough particles and
    their prefactors per collision, k_tr = 2 (d - 1) / d and k_rot = 2 (d - 1) / d_rot
    (module docstring; Huthmann & Zippelius 1997, Luding et al. 1998).  ``inertia_factor``
    None: 1/2 in 2D, 2/5 in 3D."""
    xi, beta, q = _checked(restitution, tangential_restitution, inertia_factor, dim)
    eta = q * (1.0 + beta) / (2.0 * (1.0 + q))
    a = (1.0 - xi**2) / (2.0 * (dim - 1)) + eta * (1.0 - eta)
    b = eta**2 / q
    c = (eta / q) * (1.0 - eta / q)
    d_rot = 1 if dim == 2 else 3
    return RoughCoefficients(a, b, c, 2.0 * (dim - 1) / dim, 2.0 * (dim - 1) / d_rot)


def _matrix(co: RoughCoefficients) -> np.ndarray:
    return np.array([[-co.k_tr * co.A, co.k_tr * co.B], [co.k_rot * co.B, -co.k_rot * co.C]])


@keyword_only("restitution", "tangential_restitution", "inertia_factor", "dim")
def rough_temperature_ratio(
    *,
    restitution: float,
    tangential_restitution: float,
    inertia_factor: float | None = None,
    dim: int = 3,
) -> float:
    """The asymptotic ratio r = T_rot / T_tr of the homogeneous cooling state: the fixed
    point of dr/ds = k_rot (B - C r) - r k_tr (-A + B r), the positive root of
    ``k_tr B r^2 + (k_rot C - k_tr A) r - k_rot B = 0`` (in 3D Huthmann & Zippelius 1997's
    ratio; 0 for smooth particles, beta = -1, where nothing couples the spins)."""
    co = rough_coefficients(
        restitution=restitution,
        tangential_restitution=tangential_restitution,
        inertia_factor=inertia_factor,
        dim=dim,
    )
    if co.B == 0.0:
        return 0.0
    a2, a1, a0 = co.k_tr * co.B, co.k_rot * co.C - co.k_tr * co.A, -co.k_rot * co.B
    # the root of a2 r^2 + a1 r + a0 with a2 > 0 > a0, in the form without cancellation
    disc = math.sqrt(a1 * a1 - 4.0 * a2 * a0)
    return -2.0 * a0 / (a1 + disc) if a1 > 0 else (-a1 + disc) / (2.0 * a2)


@keyword_only("tangential_restitution", "inertia_factor", "dim")
def rough_sheared_temperature_ratio(
    *,
    tangential_restitution: float,
    inertia_factor: float | None = None,
    dim: int = 3,
) -> float:
    """T_rot / T_tr of rough particles in a steadily sheared gas (uniform shear flow, a
    Lees-Edwards box), estimated from the rotational equation alone: the sliding images do
    work on the translation only (they shift velocities, not spins), so in the steady state
    the spins gain from the translation what they lose in collisions, dT_rot/ds = k_rot (B
    T - C T_rot) = 0 (module docstring; Huthmann & Zippelius 1997), and

        T_rot / T_tr = B / C = eta_t / (1 - eta_t / q) = q (1 + beta) / (1 + 2 q - beta),

    T_tr the temperature of the velocities less the mean flow.  Independent of xi and of
    the shear rate: 1 at beta = 1 (equipartition), 0 at beta = -1; 1/4 for disks and 2/9
    for solid spheres at beta = 0.  An estimate: the average takes the velocities
    isotropic and Maxwellian, independent of the spins, where a sheared gas' velocity
    distribution is anisotropic to order (shear_rate / omega)^2 (omega the collision
    frequency: small only where collisions lose little, xi near 1 and beta near +-1); and
    it leaves out the mean flow's velocity difference across a contact and the spins'
    mean (-shear_rate / 2 about z), of relative order shear_rate^2 sigma^2 m / T.
    Simulated (docs/rough.md) the ratio lies 3-5 % above it at xi = 0.99."""
    _, beta, q = _checked(1.0, tangential_restitution, inertia_factor, dim)
    return q * (1.0 + beta) / (1.0 + 2.0 * q - beta)


@keyword_only(
    "collisions",
    "temperature0",
    "rotational_temperature0",
    "restitution",
    "tangential_restitution",
    "inertia_factor",
    "dim",
)
def rough_temperatures(
    collisions: FloatOrArray,
    *,
    temperature0: float,
    rotational_temperature0: float,
    restitution: float,
    tangential_restitution: float,
    inertia_factor: float | None = None,
    dim: int = 3,
) -> tuple[np.ndarray, np.ndarray]:
    """(T_tr, T_rot) after ``collisions`` mean collisions per particle: the closed-form
    solution of the coupled equations in the collision count, exp(M s) (T0, T_rot0), M the
    2 x 2 matrix of ``rough_coefficients`` (its eigenvalues are real: B^2 >= 0 couples
    the two decays)."""
    co = rough_coefficients(
        restitution=restitution,
        tangential_restitution=tangential_restitution,
        inertia_factor=inertia_factor,
        dim=dim,
    )
    s = np.asarray(collisions, dtype=np.float64)
    m = _matrix(co)
    lam, vec = np.linalg.eig(m)
    lam, vec = lam.real, vec.real  # symmetrisable: real eigenvalues
    c = np.linalg.solve(vec, [temperature0, rotational_temperature0])
    modes = np.exp(np.multiply.outer(s, lam)) * c  # (..., 2)
    out = modes @ vec.T
    return out[..., 0], out[..., 1]


@keyword_only(
    "t",
    "density",
    "radius",
    "temperature0",
    "rotational_temperature0",
    "restitution",
    "tangential_restitution",
    "inertia_factor",
    "mass",
    "dim",
    "eta",
)
def rough_cooling(
    t: FloatOrArray,
    *,
    density: float,
    radius: float,
    temperature0: float,
    rotational_temperature0: float,
    restitution: float,
    tangential_restitution: float,
    inertia_factor: float | None = None,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(T_tr(t), T_rot(t)) of the homogeneous cooling state of rough particles: the coupled
    equations (module docstring) with ds = omega(T) dt, omega the Enskog collision
    frequency (granular.theory.collision_frequency), integrated in t to a relative 1e-10.
    ``t`` must be increasing or a number."""
    from scipy.integrate import solve_ivp

    co = rough_coefficients(
        restitution=restitution,
        tangential_restitution=tangential_restitution,
        inertia_factor=inertia_factor,
        dim=dim,
    )
    m = _matrix(co)
    omega1 = float(
        collision_frequency(
            density=density, radius=radius, temperature=1.0, mass=mass, dim=dim, eta=eta
        )
    )
    times = np.atleast_1d(np.asarray(t, dtype=np.float64))
    if np.any(np.diff(times) < 0):
        raise ValueError("t must be increasing")

    def rhs(_, y):
        return omega1 * math.sqrt(max(y[0], 0.0)) * (m @ y)

    y0 = np.array([temperature0, rotational_temperature0], dtype=np.float64)
    if times[-1] == 0.0:
        sol = np.repeat(y0[:, None], len(times), axis=1)
    else:
        res = solve_ivp(rhs, (0.0, times[-1]), y0, t_eval=times, rtol=1e-10, atol=1e-14 * y0.sum())
        sol = res.y
    if np.ndim(t) == 0:
        return sol[0, 0], sol[1, 0]
    return sol[0], sol[1]
