"""Transport coefficients: the Enskog theory (granular.theory.transport) and the
Einstein-Helfand / MSD estimators (granular.transport), first on series whose answer is
known exactly, then on a dilute elastic gas against Chapman-Enskog."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, theory, transport

# -- theory ---------------------------------------------------------------------------


def test_enskog_viscosity_by_hand():
    """3D: Chapman & Cowling's first Sonine form written out, (1/chi + 0.8 b + 0.77115 b^2
    chi) eta0 with b = 4 phi (the coefficient (4/25)(1 + 12/pi)); 2D: Gass's 1/chi + 2 phi +
    (1 + 8/pi) phi^2 chi; and both reduce to eta0 as phi -> 0."""
    r, temp, m = 0.5, 1.3, 2.0
    for phi in (0.1, 0.3):
        chi = (1 - phi / 2) / (1 - phi) ** 3
        b = 4 * phi
        eta0 = 5 / (16 * (2 * r) ** 2) * math.sqrt(m * temp / math.pi)
        want = eta0 * (1 / chi + 0.8 * b + 4 / 25 * (1 + 12 / math.pi) * b * b * chi)
        got = theory.enskog_viscosity(phi, radius=r, temperature=temp, mass=m)
        assert got == pytest.approx(want, rel=1e-12)
        chi2 = (1 - 7 * phi / 16) / (1 - phi) ** 2
        eta02 = math.sqrt(m * temp / math.pi) / (2 * 2 * r)
        want2 = eta02 * (1 / chi2 + 2 * phi + (1 + 8 / math.pi) * phi**2 * chi2)
        got2 = theory.enskog_viscosity(phi, radius=r, temperature=temp, mass=m, dim=2)
        assert got2 == pytest.approx(want2, rel=1e-12)
    dilute = theory.enskog_viscosity(1e-9, radius=r, temperature=temp, mass=m)
    assert dilute == pytest.approx(
        5 / (16 * (2 * r) ** 2) * math.sqrt(m * temp / math.pi), rel=1e-8
    )


def test_enskog_diffusion_and_finite_size_correction_by_hand():
    r, temp, m, phi = 0.5, 1.0, 1.0, 0.2
    n = phi / (4 / 3 * math.pi * r**3)
    chi = (1 - phi / 2) / (1 - phi) ** 3
    want = 3 / (8 * n * chi) * math.sqrt(temp / (math.pi * m))  # sigma = 1
    assert theory.enskog_diffusion(phi, radius=r, temperature=temp) == pytest.approx(want)
    d_inf = theory.diffusion_infinite_system(10.0, diffusion=0.1, viscosity=0.5, temperature=2.0)
    assert d_inf == pytest.approx(0.1 + 2.837297 * 2.0 / (6 * math.pi * 0.5 * 10.0))


# -- estimators on known answers --------------------------------------------------------


def _ar1_moments(rng, steps, components, phi, sigma, dt):
    """Helfand moments G = sum P dt of AR(1) stresses P_k = phi P_(k-1) + noise with
    stationary variance sigma^2; their long-time MSD grows by dt^2 sigma^2 (1 + phi) /
    (1 - phi) per step (the sum of the autocorrelation over all lags): returned per unit
    time."""
    p = np.empty((steps, components))
    p[0] = rng.normal(0, sigma, components)
    kick = rng.normal(0, sigma * math.sqrt(1 - phi * phi), (steps, components))
    for k in range(1, steps):
        p[k] = phi * p[k - 1] + kick[k]
    g = np.vstack([np.zeros(components), np.cumsum(p * dt, axis=0)])
    return g, dt * sigma**2 * (1 + phi) / (1 - phi)


def test_speedy_diffusion_limits_and_value():
    """Speedy (1987): D0 / n at low density, which is the Boltzmann first-Sonine D (Enskog's at
    chi -> 1, to the 2.5 eta of chi - 1); zero at his singular density n sigma^3 = 1.09 and
    beyond; units through sigma = 2 r and sqrt(T / m); one value by hand at n = 0.5."""
    r, t, m = 0.3, 2.0, 3.0
    tiny = 1e-7
    assert theory.speedy_diffusion(tiny, radius=r, temperature=t, mass=m) == pytest.approx(
        theory.enskog_diffusion(tiny, radius=r, temperature=t, mass=m), rel=1e-6
    )
    eta_max = 1.09 * math.pi / 6
    assert theory.speedy_diffusion(eta_max, radius=r, temperature=t) == pytest.approx(0, abs=1e-15)
    assert theory.speedy_diffusion(0.6, radius=r, temperature=t) == 0.0
    n = 0.5
    d0 = 3 / 8 * 2 * r * math.sqrt(t / (math.pi * m))
    want = d0 / n * (1 - n / 1.09) * (1 + n**2 * (0.4 - 0.83 * n**2))
    got = theory.speedy_diffusion(n * math.pi / 6, radius=r, temperature=t, mass=m)
    assert got == pytest.approx(want, rel=1e-14)
    # above Enskog at intermediate packing (correlated collisions), as the MD it fits
    assert got > theory.enskog_diffusion(n * math.pi / 6, radius=r, temperature=t, mass=m)


def test_pieprzyk_diffusion_is_its_table_and_refuses_other_densities():
    """Pieprzyk et al. (2019) as tabulated: D* at the tabulated n sigma^3, scaled by sigma =
    2 r and sqrt(T / m), arrays element by element; an untabulated packing (0.2618 is
    n sigma^3 = 0.500001, not 0.5) is refused naming it.  The table is sane against the
    theories beside it: at n sigma^3 = 0.1 above the first-Sonine Enskog value times its
    1.019 higher-Sonine factor but by less than 5 % (the correlated collisions' share is
    small in a dilute gas: 3.4 % here), above Enskog by 35 % at 0.5 and falling
    monotonically with the density."""
    r, t, m = 0.3, 2.0, 3.0
    scale = 2 * r * math.sqrt(t / m)
    at = np.array([0.1, 0.5, 1.01]) * math.pi / 6
    got = theory.pieprzyk_diffusion(at, radius=r, temperature=t, mass=m)
    assert got == pytest.approx(np.array([1.94786, 0.265009, 0.009222]) * scale, rel=1e-15)
    one = theory.pieprzyk_diffusion(math.pi / 12, radius=r, temperature=t, mass=m)
    assert isinstance(one, float) and one == pytest.approx(0.265009 * scale, rel=1e-15)
    enskog = theory.enskog_diffusion(at[:2], radius=r, temperature=t, mass=m)
    assert 1.0 < got[0] / (1.019 * enskog[0]) < 1.05
    assert 1.3 < got[1] / enskog[1] < 1.4
    table = np.array(theory.transport.PIEPRZYK_DIFFUSION)
    assert np.all(np.diff(table[:, 0]) > 0) and np.all(np.diff(table[:, 1]) < 0)
    for bad in (0.2618, np.array([0.1, 0.52]) * math.pi / 6):
        with pytest.raises(ValueError, match="not tabulated"):
            theory.pieprzyk_diffusion(bad, radius=r, temperature=t)


def test_einstein_helfand_recovers_a_known_integral_and_its_error():
    """Correlated synthetic stresses (AR(1), correlation time ~ 4 steps) whose Green-Kubo
    integral is known exactly: over 40 independent series the estimate's z-scores
    (estimate - truth) / error have mean within 4/sqrt(40) of 0 (no bias beyond 4
    standard errors of the mean) and standard deviation in [0.6, 1.5] (the block error is
    an honest error; the sample standard deviation of 40 values is good to ~11 %)."""
    rng = np.random.default_rng(11)
    dt, volume, temp = 0.1, 8.0, 1.5
    z = []
    for _ in range(40):
        g, rate = _ar1_moments(rng, 4000, 3, phi=0.8, sigma=2.0, dt=dt)
        truth = rate / (2 * volume * temp)
        times = dt * np.arange(len(g))
        res = transport.einstein_helfand(
            times, g, volume=volume, temperature=temp, fit=(3.0, 6.0), blocks=10
        )
        z.append((res.value - truth) / res.error)
    z = np.array(z)
    assert abs(z.mean()) < 4 / math.sqrt(len(z)), z.mean()
    assert 0.6 < z.std(ddof=1) < 1.5, z.std(ddof=1)


def test_estimators_refuse_what_they_cannot_use():
    times = np.linspace(0, 1, 101)
    g = np.zeros((101, 2))
    with pytest.raises(ValueError, match="uniformly spaced"):
        transport.einstein_helfand(times**2, g, volume=1, temperature=1, fit=(0.01, 0.02))
    with pytest.raises(ValueError, match="fewer than 4 times"):
        transport.einstein_helfand(times, g, volume=1, temperature=1, fit=(0.1, 0.5))
    with pytest.raises(ValueError, match="blocks must be"):
        transport.einstein_helfand(times, g, volume=1, temperature=1, fit=(0.01, 0.02), blocks=1)
    with pytest.raises(ValueError, match="fit must be"):
        transport.einstein_helfand(times, g, volume=1, temperature=1, fit=(0.02, 0.01))
    s = Scene.random(20, 0.05, dim=2, boundary="walls", seed=1)
    tr = Simulation(s, stress=True).run(1.0, sample_times=np.linspace(0, 1, 50))
    with pytest.raises(ValueError, match="periodic"):
        transport.shear_viscosity(tr, fit=(0.1, 0.2))


# -- a dilute elastic gas against Chapman-Enskog ------------------------------------------


@pytest.mark.slow
def test_dilute_gas_viscosity_and_diffusion_against_chapman_enskog():
    """3D, packing 0.02, N = 500, 1000 mean free times (tau = t / collisions per particle)
    sampled 4 times per tau.  Viscosity: Einstein-Helfand slope over lags 3-8 tau (the
    stress correlation decays in eta / (n T) = 1.25 tau: e^-2.4 left at the window's
    start), within 4 block standard errors (~6 %) plus Enskog's first Sonine truncation
    (1.6 %, Chapman & Cowling 10.21) of Enskog.  Diffusion: MSD slope over 10-20 tau (the
    velocity correlation decays in 1.5 tau), corrected to infinite size (Yeh & Hummer,
    with Enskog's viscosity) within 4 standard errors plus the first Sonine truncation of
    D (1.9 %) and uncorrelated-collision theory's own error at this density, of Enskog."""
    eta, n = 0.02, 500
    r = (eta / n / (4 / 3 * math.pi)) ** (1 / 3)
    sim = Simulation(Scene.random(n, r, dim=3, temperature=1.0, seed=3), stress=True)
    sim.run(stop_when={"collisions_per_particle": 10}, store=())
    tau = sim.time / 10
    times = sim.time + tau * np.linspace(0, 1000, 4001)
    tr = sim.run(times[-1], sample_times=times, store=("positions",))
    temp = 2 * tr.kinetic_energy.mean() / (3 * (n - 1))
    visc = transport.shear_viscosity(tr, fit=(3 * tau, 8 * tau), blocks=10)
    enskog = theory.enskog_viscosity(eta, radius=r, temperature=temp)
    assert abs(visc.value - enskog) < 4 * visc.error + 0.016 * enskog, (
        visc.value,
        visc.error,
        enskog,
    )
    diff = transport.self_diffusion(tr, fit=(10 * tau, 20 * tau), blocks=10)
    d_inf = theory.diffusion_infinite_system(
        tr.upper[0] - tr.lower[0], diffusion=diff.value, viscosity=enskog, temperature=temp
    )
    d_e = theory.enskog_diffusion(eta, radius=r, temperature=temp)
    assert abs(d_inf - d_e) < 4 * diff.error + 0.019 * d_e, (d_inf, diff.error, d_e)
