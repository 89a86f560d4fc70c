"""A Brownian particle in an external force: the harmonic trap and uniform gravity, for the
Langevin model's forces (``langevin.run(trap_stiffness=..., gravity=...)``).

Per axis the underdamped Langevin equation with the force per mass g - w (x - c), w = k/m,

    dx = v dt,   dv = [g - w (x - c) - gamma0 v] dt + sqrt(2 D0) gamma0 dW,

is a linear (Ornstein-Uhlenbeck) process in (x, v): the harmonically bound Brownian particle
of Uhlenbeck & Ornstein, Phys. Rev. 36, 823 (1930), sec. 4 ("harmonically bound particle"),
and of Chandrasekhar, Rev. Mod. Phys. 15, 1 (1943), ch. II sec. 3 ("The Brownian motion of
a particle in a field of force. The harmonically bound particle") -- cited by section: we
did not check their equation numbers against the printed papers.  Norrelykke &
Flyvbjerg, Phys. Rev. E 83, 041103 (2011) give its stationary correlations and an exact
step of any size in the underdamped case.  Its mean propagates by
E(t) = exp(A t), A = [[0, 1], [-w, -gamma0]]:

    e11(t) = exp(-gamma0 t / 2) [C(t) + (gamma0 / 2) S(t)],   e12(t) = exp(-gamma0 t / 2) S(t),
    e22(t) = exp(-gamma0 t / 2) [C(t) - (gamma0 / 2) S(t)],   e21 = -w e12,

with q^2 = gamma0^2 / 4 - w, C = cosh(q t), S = sinh(q t) / q: overdamped for q^2 > 0,
underdamped (cos, sin of omega1 t, omega1^2 = w - gamma0^2 / 4) for q^2 < 0, critical
(C = 1, S = t) at q = 0.  C and S are entire in q^2, and are evaluated by their Taylor
series near the critical point, so no regime divides by zero.

In the stationary state (equipartition: k <(x - x_eq)^2> = m <v^2> = T, T = m D0 gamma0,
x_eq = c + g/w):

- position autocorrelation <dx(t) dx(0)> / <dx^2> = e11(t);
- velocity autocorrelation <v(t) v(0)> = (T/m) e22(t);
- MSD of a particle started in the stationary state, over d axes,
  <(x(t) - x(0))^2> summed over the axes = 2 d (T / k) [1 - e11(t)],
  which rises ballistically, d (T/m) t^2, and tends to the plateau 2 d T / k: oscillating
  about it (underdamped), approaching it as (1 + gamma0 t / 2) exp(-gamma0 t / 2)
  (critical), or as exp(-lambda t) with the slow rate lambda = w / (gamma0/2 + q)
  (overdamped, -> k / (m gamma0), the Smoluchowski limit).

Uniform gravity alone (w = 0): the mean drifts to the terminal velocity g / gamma0,
<x(t) - x(0)> = (g / gamma0^2) [gamma0 t - 1 + exp(-gamma0 t)], and the fluctuations are
those of the free Langevin model (theory.msd_langevin).  Against a reflecting wall (at
z = 0, gravity g > 0 towards it) the stationary density is barometric,
n(z) / N = (m g / T) exp(-m g z / T) (Chandrasekhar 1943, ch. III sec. 5, sedimentation).
"""

from __future__ import annotations

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _x_plus_expm1


def _cosh_sinhc(z):
    """C = cosh(sqrt(z)) and S1 = sinh(sqrt(z)) / sqrt(z) for any real z (z < 0: cos and
    sin / sqrt(-z)), as entire functions of z: their Taylor series for |z| < 0.1, where
    the closed forms would divide by a vanishing sqrt(z)."""
    z = np.asarray(z, dtype=np.float64)
    small = np.abs(z) < 0.1
    zs = np.where(small, z, 0.0)
    # terms to z^8: the remainder is below 0.1^9 / 17! ~ 3e-24
    c_ser = np.ones_like(zs)
    s_ser = np.ones_like(zs)
    tc = np.ones_like(zs)
    ts = np.ones_like(zs)
    for n in range(1, 9):
        tc = tc * zs / ((2 * n - 1) * (2 * n))
        ts = ts * zs / ((2 * n) * (2 * n + 1))
        c_ser = c_ser + tc
        s_ser = s_ser + ts
    zl = np.where(small, 1.0, z)
    r = np.sqrt(np.abs(zl))
    with np.errstate(over="ignore"):
        c_big = np.where(zl > 0, np.cosh(r), np.cos(r))
        s_big = np.where(zl > 0, np.sinh(r), np.sin(r)) / r
    return np.where(small, c_ser, c_big), np.where(small, s_ser, s_big)


def _propagator(t, gamma0, w):
    """(e11, e12, e22) of exp(A t), A = [[0, 1], [-w, -gamma0]], at times t >= 0 (inf
    allowed: all 0).  Overdamped steps far past the fast rate are written with the slow and
    fast exponentials apart, so that cosh never overflows."""
    t = np.asarray(t, dtype=np.float64)
    fin = np.isfinite(t)
    tt = np.where(fin, t, 0.0)
    q2 = gamma0 * gamma0 / 4.0 - w
    z = q2 * tt * tt
    far = z > 1.0  # overdamped, q t > 1: exponentials apart
    c, s1 = _cosh_sinhc(np.where(far, 0.0, z))
    decay = np.exp(-gamma0 * tt / 2.0)
    C, S = decay * c, decay * s1 * tt
    if q2 > 0:
        q = np.sqrt(q2)
        slow = -w / (gamma0 / 2.0 + q)  # q - gamma0/2, without cancellation
        ep, em = np.exp(slow * tt), np.exp(-(q + gamma0 / 2.0) * tt)
        C = np.where(far, (ep + em) / 2.0, C)
        S = np.where(far, (ep - em) / (2.0 * q), S)
    e11 = C + gamma0 / 2.0 * S
    e22 = C - gamma0 / 2.0 * S
    zero = np.zeros_like(t)
    return (np.where(fin, e11, zero), np.where(fin, S, zero), np.where(fin, e22, zero))


def _per_mass(stiffness, mass):
    return float(stiffness) / float(mass)


@keyword_only("t")
def trap_position_autocorrelation(
    t: FloatOrArray, *, gamma0: float, stiffness: float, mass: float = 1.0
) -> FloatOrArray:
    """Normalised stationary position autocorrelation of a Brownian particle in a
    harmonic trap, <dx(t) dx(0)> / <dx^2> = e11(t) (module docstring), per axis.

    Parameters
    ----------
    t : time lag (time)
    gamma0 : friction rate (1/time)
    stiffness : the trap's k (force per length, m / time^2)
    mass : the particle's mass (m)
    """
    return _propagator(t, gamma0, _per_mass(stiffness, mass))[0]


@keyword_only("t")
def trap_velocity_autocorrelation(
    t: FloatOrArray, *, D0: float, gamma0: float, stiffness: float, mass: float = 1.0
) -> FloatOrArray:
    """Stationary velocity autocorrelation per component of a Brownian particle in a
    harmonic trap, <v_a(t) v_a(0)> = D0 gamma0 e22(t) (T/m = D0 gamma0; module
    docstring).  It crosses zero (the trap turns the particle round) in every regime,
    once when critical or overdamped, periodically when underdamped.

    Parameters
    ----------
    t : time lag (time)
    D0 : diffusivity per dimension (L^2/time)
    gamma0 : friction rate (1/time)
    stiffness : the trap's k (m / time^2)
    mass : the particle's mass (m)
    """
    return D0 * gamma0 * _propagator(t, gamma0, _per_mass(stiffness, mass))[2]


@keyword_only("t")
def msd_trap(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    stiffness: float,
    mass: float = 1.0,
    dim: int = 3,
) -> FloatOrArray:
    """MSD, total over ``dim`` axes, of a Brownian particle in a harmonic trap started in
    its stationary state: 2 d (T / k) [1 - e11(t)], T / m = D0 gamma0 (module docstring;
    Uhlenbeck & Ornstein 1930 sec. 4, Chandrasekhar 1943 ch. II sec. 3).  A uniform force
    along a trapped axis only shifts the centre and leaves it unchanged.

    Limits: ballistic d (T/m) t^2 for t << 1/gamma0 and sqrt(m/k); the plateau 2 d T / k
    (``msd_trap_plateau``) at long times, approached as e11(t).

    Parameters
    ----------
    t : time (time)
    D0 : diffusivity per dimension (L^2/time)
    gamma0 : friction rate (1/time)
    stiffness : the trap's k, the same along every axis (m / time^2)
    mass : the particle's mass (m)
    dim : number of axes, 2 or 3
    """
    w = _per_mass(stiffness, mass)
    e11 = _propagator(t, gamma0, w)[0]
    return dim * 2.0 * D0 * gamma0 / w * (1.0 - e11)


def _msd_trap_axis(t, *, D0, gamma0, w, v0_sq, offset):
    """One axis' MSD from a fixed start at ``offset`` from the force's balance point with
    velocities of mean square ``v0_sq``: (1 - e11)^2 offset^2 + e12^2 v0_sq + Var_noise,
    Var_noise = (T/k) (1 - e11^2 - w e12^2) (the Lyapunov integral, module docstring)."""
    e11, e12, _ = _propagator(t, gamma0, w)
    noise = D0 * gamma0 / w * (1.0 - e11 * e11 - w * e12 * e12)
    return (1.0 - e11) ** 2 * offset**2 + e12 * e12 * v0_sq + noise


@keyword_only("stiffness")
def msd_trap_plateau(stiffness: float, *, temperature: float, dim: int = 3) -> float:
    """The long-time MSD in a harmonic trap, 2 d T / k (twice the stationary mean square
    distance from the balance point, d T / k: equipartition), total over ``dim`` axes.

    Parameters
    ----------
    stiffness : the trap's k (m / time^2)
    temperature : T, an energy (k_B = 1)
    dim : number of axes, 2 or 3
    """
    return 2.0 * dim * temperature / stiffness


@keyword_only("t")
def gravity_mean_displacement(t: FloatOrArray, *, gravity: float, gamma0: float) -> FloatOrArray:
    """Mean displacement along a uniform acceleration g of a free Langevin particle with
    zero-mean initial velocities: (g / gamma0^2) [gamma0 t - 1 + exp(-gamma0 t)] -- g t^2 / 2
    at first, then the terminal velocity g / gamma0.  Its square adds to the MSD of the
    free model (``msd_langevin``) along that axis.

    Parameters
    ----------
    t : time (time)
    gravity : the acceleration's component g along the axis (L / time^2)
    gamma0 : friction rate (1/time)
    """
    return gravity / gamma0**2 * _x_plus_expm1(gamma0 * np.asarray(t, dtype=np.float64))


@keyword_only("height")
def barometric_density(
    height: FloatOrArray, *, gravity: float, temperature: float, mass: float = 1.0
) -> FloatOrArray:
    """The stationary density, per particle and unit height, of non-interacting particles
    above a reflecting wall at z = 0 under gravity g towards it (the barometric formula):
    (m g / T) exp(-m g z / T) for z >= 0, 0 below -- normalised to 1.  The velocities stay
    Maxwellian at T at every height (Chandrasekhar 1943 ch. III sec. 5).

    Parameters
    ----------
    height : height z above the wall (L)
    gravity : g > 0, the acceleration towards the wall (L / time^2)
    temperature : T, an energy (k_B = 1)
    mass : the particle's mass (m)
    """
    if not (gravity > 0 and np.isfinite(gravity)):
        raise ValueError(
            f"gravity must be positive and finite (its magnitude towards the wall), got {gravity}"
        )
    z = np.asarray(height, dtype=np.float64)
    inv = mass * gravity / temperature  # 1 / (the barometric height T / (m g))
    return np.where(z >= 0, inv * np.exp(-inv * np.maximum(z, 0.0)), 0.0)
