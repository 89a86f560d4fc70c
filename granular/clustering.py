"""Where homogeneous cooling ends: diagnostics of velocity vortices and density clusters.

A freely cooling granular gas in a periodic box large enough stays homogeneous only for a
while: the shear (transverse velocity) modes of the longest wavelengths grow first
(vortices), density clusters follow (Goldhirsch & Zanetti 1993, Phys. Rev. Lett. 70, 1619;
McNamara 1993, Phys. Fluids A 5, 3056; Brilliantov & Poeschel 2004, *Kinetic Theory of
Granular Gases*, ch. 21).  The functions here measure both from samples of positions and
velocities, normalised so that an uncorrelated gas (positions uniform, velocities
independent of each other and of the positions) gives a known value:

``structure_factor``
    ``S(k) = |sum_j exp(i k.r_j)|^2 / N`` at the box's smallest wave vectors: 1 for an ideal
    gas, grows where density clusters form.
``current_correlations``
    The same for the momentum current j(k) = sum_j m_j v_j exp(i k.r_j), split into its
    transverse part (shear modes, vortices) and longitudinal part (sound, heat), each
    normalised to 1 for an uncorrelated gas.
``flow_energy``
    The kinetic energy of the coarse-grained flow field (the momentum per cell of an m^d
    grid) against the thermal energy, with the level that pure noise gives subtracted.

Which theory says where the instability sets in: ``granular.theory.critical_box_size``;
for a viscoelastic gas at the restitution ``effective_restitution`` gives it at its
temperature.  ``unstable_box`` is the text of ``Simulation.run``'s ClusteringWarning.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import shown

if TYPE_CHECKING:
    from .restitution import RestitutionLaw
    from .scene import Scene

# samples per chunk in the Fourier sums: bounds the (chunk, N, K) complex temporaries
_CHUNK_ELEMENTS = 4_000_000


def wave_vectors(
    box_lengths: ArrayLike, n_max: float = 2.0
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The box's wave vectors ``k = 2 pi n / L`` with integer n, ``0 < |n| <= n_max``, one of each
    pair +-n (S(k) = S(-k) for real positions).

    Returns
    -------
    kvecs : (K, d) the wave vectors
    shells : (S,) the distinct ``|k|`` (rounded to 1e-9 relative), increasing
    shell_index : (K,) which shell each wave vector belongs to
    """
    lengths = np.asarray(box_lengths, dtype=np.float64)
    if lengths.ndim != 1 or lengths.size not in (2, 3) or np.any(~(lengths > 0)):
        from .errors import shown

        raise ValueError(f"box_lengths must be 2 or 3 positive lengths, got {shown(box_lengths)}")
    if not n_max >= 1:
        raise ValueError(f"n_max must be at least 1, got {n_max}")
    d = lengths.size
    m = int(np.floor(n_max))
    grid = np.stack(np.meshgrid(*([np.arange(-m, m + 1)] * d), indexing="ij"), -1).reshape(-1, d)
    norm2 = (grid**2).sum(1)
    grid = grid[(norm2 > 0) & (norm2 <= n_max**2 + 1e-9)]
    # keep one of +-n: the first non-zero component positive
    first = grid[np.arange(len(grid)), np.argmax(grid != 0, axis=1)]
    grid = grid[first > 0]
    kvecs = 2.0 * np.pi * grid / lengths
    kabs = np.round(np.linalg.norm(kvecs, axis=1), 9)
    shells, shell_index = np.unique(kabs, return_inverse=True)
    return kvecs, shells, shell_index


def _as_samples(positions):
    x = np.asarray(positions, dtype=np.float64)
    if x.ndim == 2:
        x = x[None]
    if x.ndim != 3 or x.shape[2] not in (2, 3):
        raise ValueError(f"positions must be (T, N, d) or (N, d) with d = 2 or 3, got {x.shape}")
    return x


def _fourier(x, kvecs, weights=None):
    """sum_j w_j exp(i k.r_j) for each sample and wave vector: (T, K) or, with weights of
    shape (T, N, c), (T, K, c).  Chunked over samples to bound memory."""
    t_count, n = x.shape[:2]
    out_shape = (
        (t_count, len(kvecs)) if weights is None else (t_count, len(kvecs), weights.shape[2])
    )
    out = np.empty(out_shape, dtype=np.complex128)
    step = max(1, _CHUNK_ELEMENTS // max(1, n * len(kvecs)))
    for a in range(0, t_count, step):
        phase = np.exp(1j * (x[a : a + step] @ kvecs.T))  # (t, N, K)
        if weights is None:
            out[a : a + step] = phase.sum(axis=1)
        else:
            out[a : a + step] = np.einsum("tnk,tnc->tkc", phase, weights[a : a + step])
    return out


def _shell_mean(values, shell_index, n_shells):
    """Average (T, K) values over the wave vectors of each shell: (T, S)."""
    counts = np.bincount(shell_index, minlength=n_shells)
    sums = np.zeros((values.shape[0], n_shells))
    for s in range(n_shells):
        sums[:, s] = values[:, shell_index == s].sum(axis=1)
    return sums / counts


class StructureFactor(NamedTuple):
    """S(k, t) averaged over the wave vectors of each ``|k|`` shell.

    Attributes
    ----------
    k : (S,) array
        The shells' ``|k|``.
    n : (S,) array
        ``|k| L_max / (2 pi)``: ``|n|`` in a cubic box.
    values : (T, S) array
        S(k) at each sample.
    vectors : (S,) array
        How many wave vectors (one of each +-k) each shell averages.
    """

    k: NDArray[np.float64]
    n: NDArray[np.float64]
    values: NDArray[np.float64]
    vectors: NDArray[np.int64]


def structure_factor(
    positions: ArrayLike, box_lengths: ArrayLike, n_max: float = 2.0
) -> StructureFactor:
    """Density structure factor ``S(k) = |sum_j exp(i k.r_j)|^2 / N`` at the smallest wave
    vectors of a periodic box, ``k = 2 pi n / L`` with integer n, ``0 < |n| <= n_max``, averaged
    over the vectors of equal ``|k|`` (the equivalent directions).

    For an ideal gas (independent uniform positions) each S(k) has mean exactly 1 (the
    N (N - 1) cross terms average to zero at these k) and variance 1 - 1/N: a sum of N
    random unit phasors, ``|.|^2 / N`` close to exponentially distributed; a shell average
    over m wave vectors has spread about 1/sqrt(m).  A simple cubic (square) lattice of
    n^d particles filling the box gives 0 at every ``|n| < n`` and N where n divides every
    component of the integer vector.  Density clusters at the box
    scale make S(k_min) grow to order N.

    Parameters
    ----------
    positions : array_like, (T, N, d) or (N, d)
        Positions (wrapped or unwrapped: a periodic image changes no phase).
    box_lengths : array_like, (d,)
        The box's side lengths.
    n_max : float
        Largest ``|n|`` included.

    Returns
    -------
    StructureFactor
        ``k``, ``n = |k| L_max / (2 pi)``, ``values`` (T, S) and ``vectors`` per shell.
    """
    x = _as_samples(positions)
    kvecs, shells, idx = wave_vectors(box_lengths, n_max)
    if kvecs.shape[1] != x.shape[2]:
        raise ValueError("box_lengths and positions disagree on the dimension")
    rho = _fourier(x, kvecs)
    per_vector = np.abs(rho) ** 2 / x.shape[1]
    values = _shell_mean(per_vector, idx, len(shells))
    lmax = float(np.max(box_lengths))
    return StructureFactor(shells, shells * lmax / (2 * np.pi), values, np.bincount(idx))


class CurrentCorrelations(NamedTuple):
    """Transverse and longitudinal momentum-current correlations per ``|k|`` shell, each 1 for an
    uncorrelated gas.

    Attributes
    ----------
    k : (S,) array
        The shells' ``|k|``.
    transverse : (T, S) array
        ``|j_perp(k)|^2 / ((d-1)/d sum_j m_j^2 |v_j|^2)``.
    longitudinal : (T, S) array
        ``|j_par(k)|^2 / ((1/d) sum_j m_j^2 |v_j|^2)``.
    vectors : (S,) array
        Wave vectors per shell.
    """

    k: NDArray[np.float64]
    transverse: NDArray[np.float64]
    longitudinal: NDArray[np.float64]
    vectors: NDArray[np.int64]


def _peculiar(velocities, masses):
    """Velocities relative to each sample's centre of mass."""
    m = masses[None, :, None]
    v_cm = (m * velocities).sum(axis=1, keepdims=True) / masses.sum()
    return velocities - v_cm


def _check_pv(positions, velocities, masses):
    x = _as_samples(positions)
    v = _as_samples(velocities)
    if v.shape != x.shape:
        raise ValueError(f"positions {x.shape} and velocities {v.shape} differ in shape")
    m = np.broadcast_to(np.asarray(masses, dtype=np.float64), (x.shape[1],))
    if np.any(~(m > 0)):
        raise ValueError("masses must be positive")
    return x, v, m


def current_correlations(
    positions: ArrayLike,
    velocities: ArrayLike,
    masses: ArrayLike,
    box_lengths: ArrayLike,
    n_max: float = 2.0,
) -> CurrentCorrelations:
    """Correlations of the momentum current ``j(k) = sum_j m_j v_j exp(i k.r_j)`` at the box's
    smallest wave vectors, split into the part transverse to k (shear modes: vortices) and
    the part along k (sound and heat modes), velocities taken relative to the centre of
    mass.

    Each is normalised by its expectation for an uncorrelated gas, where the cross terms
    vanish and ``<|j(k)|^2> = sum_j m_j^2 |v_j|^2``, shared isotropically: (d-1)/d of it
    transverse, 1/d longitudinal.  So both are 1 in the homogeneous state (to within
    fluctuations of relative size 1/sqrt(number of components averaged)); a shear
    instability makes the transverse one grow at the smallest k before the density
    (``structure_factor``) does (Goldhirsch & Zanetti 1993; van Noije, Ernst, Brito &
    Orza 1997, Phys. Rev. Lett. 79, 411).

    Parameters
    ----------
    positions, velocities : array_like, (T, N, d) or (N, d)
    masses : array_like, (N,) or scalar
    box_lengths : array_like, (d,)
    n_max : float
        Largest ``|n|`` included, as in ``structure_factor``.

    Returns
    -------
    CurrentCorrelations
    """
    x, v, m = _check_pv(positions, velocities, masses)
    kvecs, shells, idx = wave_vectors(box_lengths, n_max)
    if kvecs.shape[1] != x.shape[2]:
        raise ValueError("box_lengths and positions disagree on the dimension")
    d = x.shape[2]
    p = m[None, :, None] * _peculiar(v, m)
    j = _fourier(x, kvecs, p)  # (T, K, d)
    khat = kvecs / np.linalg.norm(kvecs, axis=1, keepdims=True)
    j_par = np.einsum("tkc,kc->tk", j, khat)
    total = (np.abs(j) ** 2).sum(axis=2)
    par = np.abs(j_par) ** 2
    noise = (p**2).sum(axis=(1, 2))[:, None]
    trans = (total - par) / ((d - 1) / d * noise)
    lon = par / (noise / d)
    n_sh = len(shells)
    return CurrentCorrelations(
        shells, _shell_mean(trans, idx, n_sh), _shell_mean(lon, idx, n_sh), np.bincount(idx)
    )


class FlowEnergy(NamedTuple):
    """Kinetic energy of the coarse-grained flow field and of the motion about it.

    Attributes
    ----------
    flow : (T,) array
        ``E_flow = sum_c |P_c|^2 / (2 M_c)`` over the cells, relative to the centre of mass.
    thermal : (T,) array
        E_kin - E_flow, E_kin relative to the centre of mass.
    ratio : (T,) array
        flow / thermal.
    noise : (T,) array
        The ratio an uncorrelated gas gives on average: (C - 1) / (N - C) with C the occupied
        cells (see ``flow_energy``).
    noise_std : (T,) array
        Its standard deviation, noise * sqrt(2 / (d (C - 1))) (chi-squared).
    excess : (T,) array
        ratio - noise: the flow that is not finite-sample noise.
    cells : (T,) array
        Occupied cells C.
    """

    flow: NDArray[np.float64]
    thermal: NDArray[np.float64]
    ratio: NDArray[np.float64]
    noise: NDArray[np.float64]
    noise_std: NDArray[np.float64]
    excess: NDArray[np.float64]
    cells: NDArray[np.int64]


def flow_energy(
    positions: ArrayLike,
    velocities: ArrayLike,
    masses: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    cells: int = 4,
) -> FlowEnergy:
    """Kinetic energy of the coarse-grained flow field against the thermal energy.

    The box is cut into ``cells`` per side (cells^d in all; positions are wrapped into the
    box first).  A cell's flow velocity is its momentum-weighted mean velocity
    ``u_c = P_c / M_c``; ``E_flow = sum_c M_c |u_c|^2 / 2`` and ``E_thermal = E_kin -
    E_flow``, all relative to the centre of mass.

    A gas with no flow at all still has ``E_flow > 0``: a cell's mean velocity carries the
    noise of its few particles.  For velocities independent of each other and of the
    positions (Maxwellian or not, any masses) ``<|P_c|^2> = d T M_c``, so every occupied cell
    contributes ``d T / 2`` on average, whatever its particle count; with the centre of mass
    removed (d constraints) ``<E_flow> = (C - 1) d T / 2`` and ``<E_thermal> = (N - C) d T /
    2``, C the occupied cells.  Hence ``noise = (C - 1) / (N - C)`` (about cells / N), with
    the chi-squared spread of d (C - 1) squared Gaussians, ``noise * sqrt(2 / (d (C - 1)))``.
    ``excess = ratio - noise`` is what a threshold such as "a few percent" should be applied
    to.  Choose cells a few mean free paths wide: smaller ones raise the noise, wider ones
    miss vortices smaller than the box.

    Parameters
    ----------
    positions, velocities : array_like, (T, N, d) or (N, d)
    masses : array_like, (N,) or scalar
    lower, upper : array_like, (d,)
        The box.
    cells : int
        Cells per side, at least 2.

    Returns
    -------
    FlowEnergy
    """
    x, v, m = _check_pv(positions, velocities, masses)
    lo = np.asarray(lower, dtype=np.float64)
    lengths = np.asarray(upper, dtype=np.float64) - lo
    t_count, n, d = x.shape
    if lengths.shape != (d,) or np.any(~(lengths > 0)):
        raise ValueError("lower and upper must give d positive box lengths")
    if int(cells) != cells or cells < 2:
        raise ValueError(f"cells must be an integer >= 2, got {cells}")
    cells = int(cells)
    u = _peculiar(v, m)
    frac = np.mod(x - lo, lengths) / lengths
    ijk = np.minimum((frac * cells).astype(np.int64), cells - 1)
    cell = np.ravel_multi_index(tuple(np.moveaxis(ijk, -1, 0)), (cells,) * d)  # (T, N)
    n_cells = cells**d
    flat = (cell + n_cells * np.arange(t_count)[:, None]).ravel()
    size = n_cells * t_count
    mass_c = np.bincount(flat, np.broadcast_to(m, (t_count, n)).ravel(), size).reshape(
        t_count, n_cells
    )
    mom2 = np.zeros((t_count, n_cells))
    for a in range(d):
        pa = np.bincount(flat, (m[None, :] * u[..., a]).ravel(), size).reshape(t_count, n_cells)
        mom2 += pa**2
    occupied = mass_c > 0
    flow_cells = 0.5 * (mom2[occupied] / mass_c[occupied])
    # float64 (bincount's weighted sum; its annotation says integers, the unweighted count)
    flow = np.asarray(np.bincount(np.nonzero(occupied)[0], flow_cells, t_count), np.float64)
    e_kin = 0.5 * (m[None, :, None] * u**2).sum(axis=(1, 2))
    thermal = e_kin - flow
    c = occupied.sum(axis=1)
    noise = (c - 1) / (n - c)
    noise_std = noise * np.sqrt(2.0 / (d * np.maximum(c - 1, 1)))
    ratio = flow / thermal
    return FlowEnergy(flow, thermal, ratio, noise, noise_std, ratio - noise, c)


def onset(times: ArrayLike, excess: ArrayLike, threshold: float) -> float:
    """First time at which ``excess`` reaches ``threshold``.

    Parameters
    ----------
    times : array_like, (T,)
    excess : array_like, (T,)
        E.g. ``FlowEnergy.excess``.
    threshold : float

    Returns
    -------
    float
        The crossing time, linearly interpolated between the samples around it; the first
        time if it starts above; nan if it never reaches the threshold.
    """
    t = np.asarray(times, dtype=np.float64)
    e = np.asarray(excess, dtype=np.float64)
    above = np.nonzero(e >= threshold)[0]
    if len(above) == 0:
        return float("nan")
    i = above[0]
    if i == 0:
        return float(t[0])
    w = (threshold - e[i - 1]) / (e[i] - e[i - 1])
    return float(t[i - 1] + w * (t[i] - t[i - 1]))


# -- the warning on Simulation.run ------------------------------------------------------------

# the share of the thermal energy at which the warning's t* counts homogeneous cooling as over
_ONSET_SHARE = 0.05

# Gauss-Legendre nodes on [0, 1] for effective_restitution's thermal mean, taken in y =
# x^(1/10), x = m g^2 / 4T, over [0, 60^(1/10)] (e^-60 ends the Maxwellian): a viscoelastic
# eps is a polynomial in g^(1/5), hence in y, so the integrand is smooth there except where
# the law is clamped at max_speed, where the range is split
_Y_END = 60.0**0.1
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(64)
_NODES, _WEIGHTS = 0.5 * (_NODES + 1.0), 0.5 * _WEIGHTS


def effective_restitution(
    restitution: float | RestitutionLaw, temperature: ArrayLike, mass: float = 1.0
) -> float | NDArray[np.float64]:
    """The constant restitution xi_eff that cools a gas at temperature T as fast as a
    restitution law does: the thermal mean over the collisions of a Maxwellian gas,
    weighted by the energy each loses,

        1 - xi_eff^2 = <(1 - eps(g)^2) g^2> / <g^2>,

    g the normal impact speed (its density over collisions is (g/s^2) exp(-g^2 / 2 s^2),
    s^2 = 2T/m, as in ``theory``'s viscoelastic cooling).  With xi_eff, Haff's cooling rate
    (1 - xi^2) omega(T) / d is the law's at T; for ``Viscoelastic`` it is 1 - xi_eff^2 =
    2 C1 Gamma(21/10) delta(T) + O(delta^2), ``theory.viscoelastic_cooling_rate``.  The law
    is evaluated as the engine applies it (past ``max_speed``, eps(max_speed)), by
    quadrature exact to about 1e-12 for ``Viscoelastic`` (a tabulated law's kinks cost
    digits).

    Parameters
    ----------
    restitution : float or granular.RestitutionLaw
        A number is returned as it is.
    temperature : float or array_like
        T (k_B = 1), > 0.
    mass : float
        The particle mass (equal masses: the relative velocity's variance is 2T/m).

    Returns
    -------
    float or ndarray
        xi_eff at each temperature.
    """
    from .restitution import RestitutionLaw

    if not isinstance(restitution, RestitutionLaw):
        return float(restitution)
    T = np.asarray(temperature, dtype=np.float64)
    if not (np.all(T > 0) and np.all(np.isfinite(T)) and mass > 0 and math.isfinite(mass)):
        raise ValueError(
            f"effective_restitution needs temperatures > 0 and a mass > 0, got T = "
            f"{shown(T)} and mass = {shown(mass)}"
        )
    scale = 4.0 * T[..., None] / mass  # g^2 = scale x = scale y^10
    kink = getattr(restitution, "max_speed", math.inf)
    y_kink = np.minimum((kink**2 / scale) ** 0.1, _Y_END)
    loss = 0.0
    for lo, hi in ((0.0, y_kink), (y_kink, _Y_END)):
        y = lo + (hi - lo) * _NODES
        eps = np.asarray(restitution(np.sqrt(scale * y**10)), dtype=np.float64)
        density = 10.0 * y**19 * np.exp(-(y**10))  # x e^-x dx in y
        loss = loss + np.sum((1.0 - eps**2) * density * (hi - lo) * _WEIGHTS, axis=-1)
    xi = np.sqrt(np.clip(1.0 - loss, 0.0, None))
    return float(xi) if xi.ndim == 0 else xi


def _law_outlook(restitution, scene, big, radius, density, growth):
    """Linear theory for a restitution law, whose gas grows more elastic as it cools: the
    slowest shear mode's energy relative to the thermal one grows at the rate zeta(T) (1 -
    (L_c(T)/L)^2), L_c(T) at xi_eff(T) (``effective_restitution``).  In u = ln(T0/T):
    d ln(growth) = (1 - (L_c/L)^2) du, dt = du / zeta, d(collisions) = omega dt, zeta =
    (1 - xi_eff^2) omega / d.  Returns (u, t, collisions, log growth) at the onset (the
    growth reached) if it comes, else at the peak, where L_c(T) overtakes L."""
    from . import theory

    d, eta = scene.dim, scene.packing_fraction
    T0, mass = float(scene.temperature), float(np.mean(scene.masses))
    u = np.linspace(0.0, 60.0, 1501)  # the trapezoids' relative error ~1e-4
    T = T0 * np.exp(-u)
    xi = effective_restitution(restitution, T, mass)
    lc = np.asarray(
        theory.critical_box_size(density=density, radius=radius, restitution=xi, dim=d, eta=eta)
    )
    omega = np.asarray(
        theory.collision_frequency(
            density=density, radius=radius, temperature=T, mass=mass, dim=d, eta=eta
        )
    )

    def integral(f):
        return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(u))])

    log_growth = integral(1.0 - (lc / big) ** 2)
    with np.errstate(divide="ignore"):
        dt_du = d / ((1.0 - xi**2) * omega)  # inf once xi_eff rounds to 1: never reached
    t, collisions = integral(dt_du), integral(omega * dt_du)
    past = np.nonzero(log_growth >= math.log(growth))[0]
    if past.size:
        k = int(past[0])
        u_at = float(np.interp(math.log(growth), log_growth[k - 1 : k + 1], u[k - 1 : k + 1]))
    else:
        u_at = float(u[np.argmax(log_growth)])
    at = [float(np.interp(u_at, u, f)) for f in (t, collisions, log_growth)]
    return u_at, at[0], at[1], at[2]


def unstable_box_message(scene: Scene) -> str | None:
    """Why a scene's homogeneous cooling will end, or None when theory expects it to last:
    the text of ``unstable_box(scene)``."""
    found = unstable_box(scene)
    return None if found is None else found[0]


def unstable_box(scene: Scene) -> tuple[str, float, float] | None:
    """Why a scene's homogeneous cooling will end, and when: ``(message, t_star,
    collisions_per_particle)`` with t* and its collisions per particle from the scene's
    state (inf where linear theory gives no finite onset), or None when theory expects the
    homogeneous cooling to last.

    None unless the box is periodic, the restitution a plain number xi < 1 or a
    ``Viscoelastic`` law (another law object is left alone) and the longest side above
    ``theory.critical_box_size``.  The message gives L, L_c, xi and the packing fraction,
    and t*: the time at which, in linear theory, the slowest shear modes (k = 2 pi / L) grow
    from their equipartition share of the kinetic energy, M / (d N) with M = 2 d (d - 1)
    real components, to 5% of it (``theory.shear_mode_growth``), in time and in collisions
    per particle, ``omega0 tau0 ln(1 + t*/tau0)``.  For mixtures the median radius (the
    bulk, which a big tracer does not move) stands in for the radius (the theory is for
    equal spheres).

    A viscoelastic gas is judged at its effective restitution at the present temperature
    (``effective_restitution``: the constant xi that cools as fast).  It grows more elastic
    as it cools, and L_c with it: the message gives linear theory's outlook with xi_eff(T)
    along the cooling (when the slowest shear modes reach 5%, or else when L_c outgrows
    the box and how far they have grown by then), and t* and the collisions returned are
    0, so that every run is warned: linear theory's onset is no bound here (a gas whose
    slowest modes peak short of 5% in linear theory still runs measurably warmer than
    the cooling law: docs/clustering.md).

    Parameters
    ----------
    scene : granular.Scene

    Returns
    -------
    tuple of (str, float, float) or None
        The warning's text, t* and the collisions per particle until t* (0 and 0 for a
        viscoelastic gas); or None.

    References
    ----------
    Goldhirsch & Zanetti 1993, Phys. Rev. Lett. 70, 1619; Garzo 2005, Phys. Rev. E 72,
    021106 (see ``theory.critical_box_size``).
    """
    from . import theory
    from .restitution import Viscoelastic

    law = scene.restitution if isinstance(scene.restitution, Viscoelastic) else None
    # a constant restitution (a Scene keeps it as a float), NaN for a law
    xi = scene.restitution if isinstance(scene.restitution, float) else math.nan
    if scene.boundary != "periodic" or not (law is not None or xi < 1):
        return None
    lengths = scene.upper - scene.lower
    big = float(np.max(lengths))
    radius = float(np.median(scene.radii))
    density = scene.n / scene.volume
    eta = scene.packing_fraction
    temperature = float(scene.temperature)
    mass = float(np.mean(scene.masses))
    if not 0 < eta < 1 or (law is not None and not 0 < temperature < math.inf):
        return None
    if law is not None:
        xi = float(effective_restitution(law, temperature, mass))
        at = (
            f"the effective restitution xi = {xi:.4g} of the viscoelastic law at the present "
            f"temperature T = {temperature:.4g} (the constant xi that cools as fast: "
            "granular.clustering.effective_restitution)"
        )
    else:
        at = f"restitution xi = {float(xi):g}"
    lc = float(
        theory.critical_box_size(
            density=density, radius=radius, restitution=float(xi), dim=scene.dim, eta=eta
        )
    )
    if not big > lc:
        return None
    d, n = scene.dim, scene.n
    text = (
        f"the periodic box (longest side L = {big:.4g}) exceeds the critical size "
        f"L_c = {lc:.4g} of the shear instability at {at} and "
        f"packing fraction {eta:.4g} (granular.theory.critical_box_size: Enskog, Navier-Stokes "
        "order).  Its homogeneous cooling state is unstable: vortices, then density clusters, "
        "grow from the longest wavelengths, and "
    )
    growth = _ONSET_SHARE * d * n / (2 * d * (d - 1))
    if law is not None:
        text += (
            "the viscoelastic cooling law stops describing the cooling.  The gas grows more "
            "elastic as it cools, and L_c with it"
        )
        u, t, cpp, log_growth = _law_outlook(law, scene, big, radius, density, growth)
        tau0 = theory.viscoelastic_tau0(
            a_kappa=law,
            density=density,
            radius=radius,
            temperature0=temperature,
            mass=mass,
            dim=d,
            eta=eta,
        )
        when = f"t = {t:.3g} (t/tau0' = {t / tau0:.3g}, {cpp:.3g} collisions per particle)"
        if log_growth >= math.log(growth) * (1 - 1e-9):
            text += (
                f"; in linear theory the slowest shear modes reach {_ONSET_SHARE:.0%} of the "
                f"kinetic energy at about {when}"
            )
        else:
            share = _ONSET_SHARE * math.exp(log_growth) / growth
            text += (
                f"; in linear theory L_c outgrows the box at about {when}, T = "
                f"{temperature * math.exp(-u):.3g}, when the slowest shear modes peak at "
                f"{100 * share:.2g}% of the kinetic energy"
            )
        # every run is warned: linear theory's onset is no bound for a law's gas (above)
        return text + _ADVICE, 0.0, 0.0
    text += "Haff's law stops describing the cooling"
    t_star = cpp = math.inf
    if xi > 0 and temperature > 0:
        tau0 = float(
            theory.haff_tau0(
                density=density,
                radius=radius,
                restitution=float(xi),
                temperature0=temperature,
                mass=mass,
                dim=d,
                eta=eta,
            )
        )
        omega0 = float(
            theory.collision_frequency(
                density=density, radius=radius, temperature=temperature, mass=mass, dim=d, eta=eta
            )
        )
        exponent = 2 * (1 - (lc / big) ** 2)
        if growth > 1:
            t_star = tau0 * (growth ** (1 / exponent) - 1)
            cpp = omega0 * tau0 * math.log1p(t_star / tau0)
            text += (
                f" after about t* = {t_star:.3g} (t*/tau0 = {t_star / tau0:.3g}, "
                f"{cpp:.3g} collisions per particle; linear theory: the slowest shear modes "
                f"reach {_ONSET_SHARE:.0%} of the kinetic energy)"
            )
    return text + _ADVICE, t_star, cpp


_ADVICE = (
    ".  Use a box below L_c (fewer particles at the same density) for homogeneous "
    "cooling, or measure the flow with granular.clustering.flow_energy."
)
