"""A vibrating wall's energy input to a gas, and the temperature it sustains.

The wall (``granular.VibratingWall``) moves along its normal with velocity U(t).  In the
limit where its amplitude is small against the mean free path (the wall's position fixed,
its velocity that of the phase at which a particle happens to arrive) the gas next to it
has number density n and, along the normal, a Maxwellian of temperature T (``<v_n^2> =
T/m``).  A particle with normal velocity v (towards the wall: v < U for the lower wall)
hits it at the rate n (U - v) f(v) per unit area, and the wall does the work
J U = m (1 + e) (U - v) U on it (e the wall's restitution, the reflection in the wall's
frame).  The mean work per unit area and time (2D: per unit length) is then

    P = (1 + e) m n < U I(U) >_phase,   I(U) = int_{v < U} (U - v)^2 f(v) dv
      = s^2 [(1 + z^2) Phi(z) + z phi(z)],   z = U / s,  s = sqrt(T/m),

with Phi and phi the standard normal distribution and density.  Expanded in U/s
(<U> = 0 over a period):

    P = (1 + e) n m <U^2> sqrt(2 T / (pi m)) [1 + O(U^2 / s^2)],

the dilute small-amplitude input of McNamara & Luding (1998, Phys. Rev. E 58, 813, sec. III:
"the rate of energy input is ... an average vibration velocity times a function of the ratio
of particle to vibration velocity") and of Kumaran (1998, J. Fluid Mech. 364, 163, the
leading order in the ratio of the wall's to the particles' speed).  ``<U^2>`` is (A omega)^2
/ 2 for a sine wall and ((2/pi) A omega)^2 for the triangle wave.  The derivation is written
out in docs/vibrated.md; we have not checked the papers' own equation numbers, so none are
quoted.

What the formula leaves out: the wall's excursion (A against the mean free path), the
anisotropy of the gas at the wall (particles arriving there are colder than those leaving:
the arriving half-Maxwellian's temperature is the one that counts), and velocity
correlations (a particle just reflected may be hit again).

Energy balance.  A uniform dilute gas of N particles between the vibrating wall and a fixed
elastic one, a distance ``wall_distance`` apart, loses energy in pair collisions at the rate
(Haff, [G20] 2.40-2.41) d n T / tau0(T) per unit volume; in the steady state that equals
P / wall_distance.  Both sides at leading order: P ~ V^2 sqrt(T), loss ~ (1 - xi^2) n^2 sigma^(d-1)
T^(3/2), so T ~ V^2 -- the dilute exponent ``DILUTE_EXPONENT`` = 2 (Kumaran 1998; McNamara &
Luding 1998 find delta = 2 for dilute beds in simulation, about 1.5 for dense ones).  The
experiment of Warr, Huntley & Jacques (1995, Phys. Rev. E 52, 5583) on a vibrated 2D bed
under gravity found T ~ V^(1.41 +- 0.11) (``WARR_HUNTLEY_JACQUES_EXPONENT``): a dense bed,
where collisions are correlated and the wall's input is not the dilute one.
"""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .haff import haff_tau0

DILUTE_EXPONENT = 2.0  # T ~ V^2 in the dilute limit (Kumaran 1998)
WARR_HUNTLEY_JACQUES_EXPONENT = (1.41, 0.11)  # experiment, 2D bed under gravity (1995)

_WAVEFORMS = ("sine", "triangle")
_PHASES = 256  # quadrature points over a period (the trapezoid rule: spectral for the sine)


def _wall_velocities(peak_velocity, waveform):
    """The wall's velocity at _PHASES equally spaced phases: U = V cos(theta) (sine),
    +-V half the time each (triangle); V the peak speed."""
    if waveform not in _WAVEFORMS:
        raise ValueError(f"waveform must be one of {_WAVEFORMS}, got {waveform!r}")
    theta = 2.0 * np.pi * (np.arange(_PHASES) + 0.5) / _PHASES
    shape = np.cos(theta) if waveform == "sine" else np.sign(np.cos(theta))
    return np.multiply.outer(np.asarray(peak_velocity, dtype=np.float64), shape)


def _incoming_moment(U, s):
    """I(U) = int_{v < U} (U - v)^2 f(v) dv for f the Maxwellian of standard deviation s."""
    from scipy import special  # at call time: `import granular` does not load SciPy

    z = U / s
    return (
        s
        * s
        * ((1.0 + z * z) * special.ndtr(z) + z * np.exp(-0.5 * z * z) / math.sqrt(2 * math.pi))
    )


@keyword_only("peak_velocity")
def wall_power(
    peak_velocity: FloatOrArray,
    *,
    density: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    wall_restitution: FloatOrArray = 1.0,
    waveform: str = "sine",
) -> FloatOrArray:
    """The mean work per unit wall area and time (2D: per unit length) a vibrating wall of
    peak speed V does on a dilute gas at its face, in the small-amplitude limit (module
    docstring): ``(1 + e) m n < U I(U) >`` over the wall's phase, exact for a Maxwellian
    normal velocity at any V / sqrt(T/m).

    Parameters
    ----------
    peak_velocity : float or array
        V: A omega for a sine wall, (2/pi) A omega for the triangle wave
        (``VibratingWall.peak_velocity``) [sqrt(eps/m)].
    density : float
        n, the number density at the wall [L^-d].
    temperature : float
        T of the normal velocity component at the wall (``<v_n^2> = T/m``) [eps].
    mass : float
        m [m].
    wall_restitution : float
        e of the vibrating wall (the reflection in its frame).
    waveform : {"sine", "triangle"}
        The wall's motion.
    """
    U = _wall_velocities(peak_velocity, waveform)
    s = np.sqrt(temperature / mass)
    work = (1.0 + wall_restitution) * mass * density * U * _incoming_moment(U, s)
    return work.mean(axis=-1)[()]


@keyword_only("peak_velocity")
def wall_power_leading(
    peak_velocity: FloatOrArray,
    *,
    density: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    wall_restitution: FloatOrArray = 1.0,
    waveform: str = "sine",
) -> FloatOrArray:
    """``wall_power`` at leading order in V / sqrt(T/m):
    ``(1 + e) n m <U^2> sqrt(2 T / (pi m))`` with <U^2> = V^2 / 2 (sine), V^2 (triangle)
    (McNamara & Luding 1998; Kumaran 1998).  Parameters as ``wall_power``."""
    if waveform not in _WAVEFORMS:
        raise ValueError(f"waveform must be one of {_WAVEFORMS}, got {waveform!r}")
    v = np.asarray(peak_velocity, dtype=np.float64)
    u2 = 0.5 * v * v if waveform == "sine" else v * v
    return (
        (1.0 + wall_restitution) * density * mass * u2 * np.sqrt(2.0 * temperature / (np.pi * mass))
    )[()]


@keyword_only("peak_velocity")
def vibrated_temperature(
    peak_velocity: float,
    *,
    density: float,
    radius: float,
    restitution: float,
    wall_distance: float,
    mass: float = 1.0,
    wall_restitution: float = 1.0,
    waveform: str = "sine",
    dim: int = 2,
) -> float:
    """The steady temperature of a uniform dilute gas between a vibrating wall and a fixed
    elastic one, a distance ``wall_distance`` apart, no gravity: the T at which the wall's input
    ``wall_power`` equals the pair collisions' loss d n T / tau0(T) times ``wall_distance``
    (module docstring; Haff's tau0, ``haff_tau0``, [G20] 2.41).  Uniform density and
    temperature are assumed: in a real cell the gas is hotter and thinner at the vibrating
    wall, so this is the balance's estimate, good where the gas is nearly uniform (small
    1 - xi, few mean free paths between the walls).  At leading order T ~ V^2.

    Parameters
    ----------
    peak_velocity : float
        V [sqrt(eps/m)].
    density : float
        n = N / V, the gas's mean number density [L^-d].
    radius : float
        r [L].
    restitution : float
        xi of pair collisions, < 1.
    wall_distance : float
        The distance between the walls (the gas's volume per unit wall area) [L].
    mass, wall_restitution, waveform
        As ``wall_power``.
    dim : int
        2 or 3.
    """
    _check_dim(dim)
    if not restitution < 1.0:
        raise ValueError(f"an elastic gas (restitution {restitution}) has no steady temperature")

    def excess(log_t: float) -> float:
        t = math.exp(log_t)
        gain = wall_power(
            peak_velocity,
            density=density,
            temperature=t,
            mass=mass,
            wall_restitution=wall_restitution,
            waveform=waveform,
        )
        tau0 = haff_tau0(
            density=density,
            radius=radius,
            restitution=restitution,
            temperature0=t,
            mass=mass,
            dim=dim,
        )
        return math.log(gain) - math.log(wall_distance * dim * density * t / tau0)

    from scipy import optimize

    # the loss grows as T^(3/2), the gain as T^(1/2) (then slower): one crossing
    t_guess = mass * peak_velocity**2
    lo, hi = math.log(t_guess) - 30.0, math.log(t_guess) + 30.0
    return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-14, rtol=1e-13))


@keyword_only("peak_velocity")
def vibrated_bed_temperature(
    peak_velocity: float,
    *,
    n: float,
    area: float,
    radius: float,
    restitution: float,
    mass: float = 1.0,
    wall_restitution: float = 1.0,
    waveform: str = "sine",
    dim: int = 2,
) -> float:
    """The steady temperature of a dilute bed of ``n`` particles on a vibrating floor under
    gravity, isothermal and barometric: the T at which the floor's input ``wall_power`` at
    the floor's density n0 equals the pair collisions' loss integrated up the column.

    With the scale height l = T / (m g), n(z) = n0 exp(-z / l) and n0 l = n / area = c (the
    column's particles per unit floor area).  The loss per unit volume is d n T / tau0(n, T)
    (Haff, [G20] 2.40-2.41) with 1 / tau0 proportional to n, so up the column it sums to
    d T n0 c / (2 tau0(n0, T)): the input and the loss are both proportional to n0, and
    gravity drops out -- at leading order T = k V^2 / c, the dilute exponent
    ``DILUTE_EXPONENT`` of Kumaran (1998), twice the uniform gas's T at the same c
    (``vibrated_temperature`` with n H = c: the barometric profile's mean of n^2 is half its
    n0 c).  Dilute: Haff's rate without the contact value (eta = 0).  What it leaves out:
    the bed's temperature gradient (it cools upwards), its anisotropy, the floor's excursion,
    and the dense bottom of a deep bed (there Warr, Huntley & Jacques 1995 measured
    T ~ V^1.41, ``WARR_HUNTLEY_JACQUES_EXPONENT``).

    Parameters
    ----------
    peak_velocity : float
        V, the floor's peak speed [sqrt(eps/m)].
    n : float
        The number of particles in the bed.
    area : float
        The floor's area (a length in 2D) [L^(d-1)].
    radius : float
        r [L].
    restitution : float
        xi of pair collisions, < 1.
    mass, wall_restitution, waveform
        As ``wall_power`` (the floor's restitution and motion).
    dim : int
        2 or 3.
    """
    _check_dim(dim)
    if not restitution < 1.0:
        raise ValueError(f"an elastic bed (restitution {restitution}) has no steady temperature")
    column = n / area

    def excess(log_t: float) -> float:
        t = math.exp(log_t)
        gain = wall_power(
            peak_velocity,
            density=1.0,
            temperature=t,
            mass=mass,
            wall_restitution=wall_restitution,
            waveform=waveform,
        )
        rate = 1.0 / haff_tau0(
            density=1.0,
            radius=radius,
            restitution=restitution,
            temperature0=t,
            mass=mass,
            dim=dim,
            eta=0.0,
        )
        return math.log(gain) - math.log(dim * t * rate * column / 2.0)

    from scipy import optimize

    t_guess = mass * peak_velocity**2
    lo, hi = math.log(t_guess) - 30.0, math.log(t_guess) + 30.0
    return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-14, rtol=1e-13))
