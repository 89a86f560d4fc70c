"""External forces in the Langevin model (a uniform acceleration and a harmonic trap):
the exact step's coefficients against slower independent methods in every damping regime,
the engine against the slow reference to rounding, the statistics against theory.trap, the
stability limit of Euler-Maruyama in a trap, and bad input.

Statistical tolerances are five standard errors of the estimate (stated at each assertion):
a false alarm probability of 5.7e-7 per comparison."""

import math
import pickle

import numpy as np
import pytest

from granular import _core, langevin, theory
from granular.errors import UnstableStepError
from granular.theory import trap

from helpers import sde_reference as R

G, D = 2.0, 0.7  # gamma0^2 / 4 = 1: the critical stiffness per mass
REGIMES = {"over": 0.3, "critical": 1.0, "under": 4.0}  # w = k/m


def coefficients(g, d, w, dt):
    """The C core's (e12, e22, j1, kx, sx, sv) as a dict."""
    return dict(
        zip(("e12", "e22", "j1", "kx", "sx", "sv"), _core.sde_force_step(g, d, w, dt), strict=True)
    )


def analytic_mean(g, w, t):
    """e11, e12, e22 written out per regime (complex square root: one formula for over- and
    underdamped, away from the critical point), or the critical forms at w = g^2/4."""
    if w == g * g / 4:
        return (
            (1 + g * t / 2) * math.exp(-g * t / 2),
            t * math.exp(-g * t / 2),
            (1 - g * t / 2) * math.exp(-g * t / 2),
        )
    q = complex(g * g / 4 - w) ** 0.5
    c, s = np.cosh(q * t), np.sinh(q * t) / q
    k = math.exp(-g * t / 2)
    return (k * (c + g / 2 * s)).real, (k * s).real, (k * (c - g / 2 * s)).real


@pytest.mark.parametrize("w", [0.0, 1e-9, *REGIMES.values(), 1e4])
@pytest.mark.parametrize("dt", [0.05, 0.3])
def test_force_step_matches_van_loan(w, dt):
    """The C core's Taylor series and doubling against Van Loan's block matrix exponentials
    (scipy's Pade approximant) at steps of the order of the rates, where the latter is
    accurate: every coefficient to 1e-11 relative (both sides ~1e-14 here; the margin is
    for the stiff w = 1e4, sqrt(w) dt = 30)."""
    c = coefficients(G, D, w, dt)
    e12, e22, j1, L = R.force_coefficients(G, D, w, dt)
    ref = dict(e12=e12, e22=e22, j1=j1, kx=L[1, 0], sx=L[1, 1], sv=L[0, 0])
    for name, value in ref.items():
        assert c[name] == pytest.approx(value, rel=1e-11, abs=1e-300), name


@pytest.mark.parametrize("regime", list(REGIMES))
@pytest.mark.parametrize("dt", [1e-6, 1e-3, 0.1, 1.0, 4.0])
def test_force_step_closed_forms_in_every_regime(regime, dt):
    """Over-, critically and underdamped, steps from 1e-6 to 8 / gamma0: the mean's e12,
    e22 against their closed forms (the critical one exactly at w = gamma0^2/4), j1 against
    (1 - e11)/w, and the covariance against the identities the Lyapunov integral obeys,
    S_xv = D gamma^2 e12^2 and S_vv = D gamma [1 - exp(-gamma t)] + D gamma^2 e12 e22 --
    no cancellation in either -- each to 1e-12 relative (an entry crossing zero, e22 at
    t = 2/gamma0 when critical, to 1e-14 of the entry's scale)."""
    w = REGIMES[regime]
    c = coefficients(G, D, w, dt)
    e11, e12, e22 = analytic_mean(G, w, dt)
    assert c["e12"] == pytest.approx(e12, rel=1e-12)
    assert c["e22"] == pytest.approx(e22, rel=1e-12, abs=1e-14)
    if w * dt * dt > 1e-3:  # else (1 - e11)/w cancels: j1 is checked at short steps below
        assert c["j1"] == pytest.approx((1 - e11) / w, rel=1e-11)
    svv = D * G * -math.expm1(-G * dt) + D * G * G * c["e12"] * c["e22"]
    sxv = D * G * G * c["e12"] ** 2
    assert c["sv"] ** 2 == pytest.approx(svv, rel=1e-12)
    assert c["kx"] * c["sv"] == pytest.approx(sxv, rel=1e-12)


@pytest.mark.parametrize("w", [0.0, *REGIMES.values()])
def test_force_step_keeps_its_precision_at_tiny_steps(w):
    """At dt = 1e-6 (gamma0 dt = 2e-6) the step is the force-free ballistic one to first
    order: j1 = dt^2/2, and the x noise left after the velocity's, sx^2 = S_xx - S_xv^2 /
    S_vv, is sigma^2 dt^3 / 12, sigma^2 = 2 D gamma^2 -- a number 1e-18 of the others, which
    a closed form Sinf - E Sinf E^T would lose to cancellation entirely.  To 1e-5 relative
    (the next order is gamma0 dt)."""
    dt = 1e-6
    c = coefficients(G, D, w, dt)
    assert c["j1"] == pytest.approx(dt * dt / 2, rel=1e-5)
    assert c["sx"] ** 2 == pytest.approx(2 * D * G * G * dt**3 / 12, rel=1e-5)


@pytest.mark.parametrize("w", list(REGIMES.values()))
def test_a_long_exact_step_lands_in_the_stationary_state(w):
    """Over a step of 20 / lambda, lambda the slowest decay rate (gamma0/2, or
    w / (gamma0/2 + q) when overdamped), the propagator has decayed to e^-20 and the step's
    covariance is the stationary one, diag(D gamma / w, D gamma), to ~e^-40: to 1e-10
    relative (the doubling's rounding over its ~8 squarings), and so is Van Loan's
    S_inf - E S_inf E^T."""
    q2 = G * G / 4 - w
    lam = w / (G / 2 + math.sqrt(q2)) if q2 > 0 else G / 2
    dt = 20.0 / lam
    c = coefficients(G, D, w, dt)
    assert c["sv"] ** 2 == pytest.approx(D * G, rel=1e-10)
    assert c["sx"] ** 2 + c["kx"] ** 2 == pytest.approx(D * G / w, rel=1e-10)
    S = R.force_step_stationary(G, D, w, dt)
    assert c["sx"] ** 2 + c["kx"] ** 2 == pytest.approx(S[0, 0], rel=1e-10)


def test_no_division_by_zero_across_the_critical_point():
    """w = gamma0^2/4 (1 + eps) for eps from -1e-6 to 1e-6 and exactly 0: every coefficient
    within 10 |eps| of the critical values (they are smooth in w), finite, none NaN."""
    dt = 0.8
    crit = coefficients(G, D, G * G / 4, dt)
    for eps in (-1e-6, -1e-12, 0.0, 1e-12, 1e-6):
        c = coefficients(G, D, G * G / 4 * (1 + eps), dt)
        for name, value in c.items():
            assert math.isfinite(value)
            assert value == pytest.approx(crit[name], rel=10 * abs(eps) + 1e-14), (eps, name)


@pytest.mark.parametrize("scheme", ["em", "exact"])
@pytest.mark.parametrize("dim", [1, 3])
def test_the_engine_is_the_reference_integrator_to_rounding(scheme, dim):
    """The C engine and the slow reference (the same random numbers, the force at the start
    of the step for EM, Van Loan's coefficients for the exact step) over 40 steps, with a
    trap in each regime along different axes, gravity, and starts off the centre: positions
    and velocities to 1e-11 relative to the motion's scale (rounding, and the reference's
    coefficients, ~1e-14)."""
    rng = np.random.default_rng(3)
    n = 3
    v0 = rng.normal(size=(n, dim))
    origin = rng.normal(size=(n, dim))
    w = [REGIMES["under"], REGIMES["critical"], 0.0][:dim]
    accel = [0.5, -1.5, 2.0][:dim]
    kw = dict(model="langevin", scheme=scheme, gamma0=G, D0=D, tau0=math.inf, dt=0.05)
    kw |= dict(n_steps=40, accel=accel, stiffness=w, origin=origin)
    xs, vs = R.run(v0, 11, **kw)
    pos, v, _, _ = R.engine(v0, 11, **kw)
    scale = np.abs(xs).max()
    assert np.abs(pos - xs).max() <= 1e-11 * scale
    assert np.abs(v - vs[-1]).max() <= 1e-11 * np.abs(vs).max()


@pytest.mark.parametrize("scheme", ["em", "exact"])
def test_same_bits_whatever_the_chunking_and_threads(monkeypatch, scheme):
    """With forces each particle's start (its offset from the trap's centre) goes to C with
    its chunk: bit-identical results in one call, in blocks, and one particle at a time in
    segments of 7 steps, on 1 or 3 threads."""
    kw = dict(gamma0=G, D0=D, dt=0.01, t_stop=0.5, scheme=scheme, dim=2, seed=5)
    kw |= dict(trap_stiffness=[3.0, 0.0], gravity=[0.0, -1.0], trap_centre=[0.5, 0.0])
    kw |= dict(sample_times=np.arange(51) * 0.01, store_positions=True)
    a = langevin.run(70, threads=1, **kw)
    for chunk, threads in ((50 * 7, 3), (7, 1)):
        monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", chunk)
        b = langevin.run(70, threads=threads, **kw)
        for name in ("msd_per_dimension", "v2", "positions", "final_velocities"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (chunk, name)


@pytest.mark.parametrize("regime", list(REGIMES))
def test_trap_msd_matches_theory_in_every_regime(regime):
    """20000 particles in a 3D trap with gravity along z (which only moves the centre),
    started in the stationary state: the MSD at every sample against theory.msd_trap, from
    the ballistic rise to the plateau 2 d T / k.  The displacement is Gaussian with equal
    variance per axis, so the relative standard error of the mean of |dx|^2 is
    sqrt(2 / (3 n)) = 0.58 %; tolerance 5 of them.  The plateau itself (the last sample, far
    past the slowest relaxation) within 5 standard errors of msd_trap_plateau."""
    n, k = 20000, REGIMES[regime]  # mass 1
    r = langevin.run(
        n,
        gamma0=G,
        D0=D,
        dt=0.05,
        t_stop=30.0,
        trap_stiffness=k,
        gravity=[0.0, 0.0, -2.0],
        sample_times=[0.05, 0.2, 0.5, 1.0, 2.0, 4.0, 30.0],
        seed=2,
    )
    tol = 5 * math.sqrt(2 / (3 * n))
    th = theory.msd_trap(r.times, D0=D, gamma0=G, stiffness=k)
    assert np.all(np.abs(r.msd() / th - 1) < tol), (r.msd() / th - 1) / tol
    plateau = theory.msd_trap_plateau(k, temperature=D * G, dim=3)
    assert abs(r.msd()[-1] / plateau - 1) < tol


def test_the_exact_scheme_keeps_the_stationary_state_at_any_step():
    """Steps of 2 / gamma0 (underdamped, sqrt(w) dt = 2), far beyond any Euler-Maruyama
    limit: after 50 steps the positions about the balance point keep the variance T / k and
    the velocities T / m (exactness; EM is refused here).  Relative standard error of a
    variance of n Gaussian samples: sqrt(2 / n) (plus the balance point's; the mean is
    known); tolerance 5 of them, over 2 axes."""
    n, k, g = 20000, 4.0, -1.5
    r = langevin.run(n, gamma0=G, D0=D, dt=1.0, t_stop=50.0, dim=2, trap_stiffness=k,
                     gravity=[0.0, g], seed=4)  # fmt: skip
    x = r.initial_positions + r.final_positions - np.array([0.0, g / k])
    tol = 5 * math.sqrt(2 / (2 * n))
    assert np.mean(x * x) / (D * G / k) == pytest.approx(1, abs=tol)
    assert np.mean(r.final_velocities**2) / (D * G) == pytest.approx(1, abs=tol)
    with pytest.raises(UnstableStepError):
        langevin.run(10, gamma0=G, D0=D, dt=1.0, t_stop=5.0, trap_stiffness=k, scheme="em")


def test_euler_maruyama_is_biased_as_its_own_stationary_state_says():
    """EM's stationary covariance in a trap is the solution of its discrete Lyapunov
    equation (helpers.sde_reference.em_trap_stationary), not T/k: at gamma0 dt = 0.3,
    w dt / gamma0 = 0.6 it is 12 % off for x.  The simulated variance of x (n = 20000 from
    the exact stationary start, 60 relaxation times of EM) is within 5 standard errors
    (sqrt(2 / n) relative) of EM's prediction, and more than 5 away from the exact T/k."""
    n, dt = 20000, 0.15
    w = 0.6 * G / dt
    r = langevin.run(n, gamma0=G, D0=D, dt=dt, t_stop=60.0, dim=1, trap_stiffness=w,
                     scheme="em", seed=6)  # fmt: skip
    x = r.initial_positions + r.final_positions
    var = float(np.mean(x * x))
    em = R.em_trap_stationary(G, D, w, dt)[0, 0]
    tol = 5 * math.sqrt(2 / n)
    assert var / em == pytest.approx(1, abs=tol)
    assert abs(var / (D * G / w) - 1) > tol


def test_gravity_drifts_a_free_particle_to_its_terminal_velocity():
    """Gravity alone along y: the mean displacement against
    theory.gravity_mean_displacement at t = 3 / gamma0 .. 20 / gamma0 (standard error of a
    mean: the free model's per-axis spread sqrt(msd_langevin / 2) over sqrt(n); 5 of them),
    and the MSD along y is the free one plus the drift squared (theory_msd, 5 relative
    standard errors of a non-central chi-square, bounded by sqrt(2 / n) (1 + 2 drift^2 /
    var)^(1/2))."""
    n, g = 20000, -3.0
    r = langevin.run(n, gamma0=G, D0=D, dt=0.05, t_stop=10.0, dim=2, gravity=[0.0, g],
                     seed=8, sample_times=[1.5, 10.0])  # fmt: skip
    drift = theory.gravity_mean_displacement(10.0, gravity=g, gamma0=G)
    spread = math.sqrt(theory.msd_langevin(10.0, D0=D, gamma0=G, dim=2) / 2)
    assert np.mean(r.final_positions[:, 1]) == pytest.approx(drift, abs=5 * spread / math.sqrt(n))
    assert abs(np.mean(r.final_positions[:, 0])) < 5 * spread / math.sqrt(n)
    th = r.theory_msd()
    rel = math.sqrt(2 / n) * math.sqrt(1 + 2 * drift**2 / spread**2)
    assert np.all(np.abs(r.msd() / th - 1) < 5 * rel)


def test_euler_maruyama_stability_limit_in_a_trap():
    """EM's map on the mean in a trap has spectral radius < 1 iff (k/m) dt < gamma0 (for
    gamma0 dt < 2): the reference's eigenvalues cross 1 there, the run is accepted just
    below the bound (and stays finite) and refused just above it with UnstableStepError --
    and past it the map does diverge (the reference iterated, the variance growing)."""
    dt = 0.1
    w_edge = G / dt
    assert R.em_trap_spectral_radius(G, w_edge * (1 - 1e-6), dt) < 1
    assert R.em_trap_spectral_radius(G, w_edge * (1 + 1e-6), dt) > 1
    r = langevin.run(200, gamma0=G, D0=D, dt=dt, t_stop=20.0, dim=1, scheme="em",
                     trap_stiffness=w_edge * (1 - 1e-6), seed=1)  # fmt: skip
    assert np.all(np.isfinite(r.msd()))
    with pytest.raises(UnstableStepError, match=r"\(k/m\) dt >= gamma0"):
        langevin.run(10, gamma0=G, D0=D, dt=dt, t_stop=1.0, dim=1, scheme="em",
                     trap_stiffness=w_edge * (1 + 1e-6))  # fmt: skip
    # where it fails: past the bound EM's covariance map has no fixed point it tends to
    M = np.array([[1.0, dt], [-1.2 * w_edge * dt, 1.0 - G * dt]])
    S = np.zeros((2, 2))
    for _ in range(400):
        S = M @ S @ M.T + np.diag([0.0, 2 * D * G * G * dt])
    assert S[0, 0] > 1e6 * D * G / (1.2 * w_edge)
    # the C core refuses it as well, by its own check
    with pytest.raises(UnstableStepError):
        R.engine(np.zeros((1, 1)), 1, model="langevin", scheme="em", gamma0=G, D0=D,
                 tau0=math.inf, dt=dt, n_steps=2, stiffness=[1.2 * w_edge])  # fmt: skip


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(gravity=[0.0, 0.0, math.nan]), "gravity .* must be finite"),
        (dict(gravity=[0.0, 1.0]), "gravity .* must have dim = 3 components"),
        (dict(gravity="down"), "gravity .* must be numbers"),
        (dict(trap_stiffness=-1.0), "trap_stiffness must be >= 0"),
        (dict(trap_stiffness="stiff"), "trap_stiffness .* must be a number or dim numbers"),
        (dict(trap_stiffness=[1.0, 2.0]), "trap_stiffness .* dim = 3"),
        (dict(trap_stiffness=math.inf), "trap_stiffness .* must be finite"),
        (dict(trap_stiffness=1.0, trap_centre=[0.0, math.nan, 0.0]), "trap_centre .* finite"),
        (dict(trap_centre=[0.0, 0.0, 1.0]), "give trap_stiffness too"),
        (dict(trap_stiffness=1.0, tau0=1.0), "Langevin model only"),
        (dict(trap_stiffness=1e300), "trap_stiffness / mass along axis 0"),
    ],
)
def test_bad_force_input_is_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        langevin.run(4, **{"gamma0": G, "D0": D, "dt": 0.01, "t_stop": 0.1, **kwargs})


def test_the_core_refuses_a_bad_force_itself():
    """_core.sde_run's own checks (the Python layer is bypassed): NaN accel, negative
    stiffness, a force with UDSBM, a wrong length."""
    base = dict(model="langevin", scheme="exact", gamma0=G, D0=D, tau0=math.inf, dt=0.1,
                n_steps=2)  # fmt: skip
    for extra in (dict(accel=[math.nan]), dict(stiffness=[-1.0])):
        with pytest.raises(ValueError, match="external forces need"):
            R.engine(np.zeros((1, 1)), 1, **base, **extra)
    with pytest.raises(ValueError, match="external forces need"):
        R.engine(np.zeros((1, 1)), 1, **{**base, "model": "udsbm", "tau0": 1.0},
                 stiffness=[1.0])  # fmt: skip
    with pytest.raises(ValueError, match=r"stiffness must be .* of 1 elements"):
        R.engine(np.zeros((1, 1)), 1, **base, stiffness=[1.0, 2.0])


def test_results_carry_the_forces():
    """repr names the forces, arrays() holds them (as ensembles save a result), a pickle
    keeps them; a run without force has zeros and an unchanged repr."""
    r = langevin.run(8, gamma0=G, D0=D, dt=0.01, t_stop=0.1, dim=2, trap_stiffness=[1.0, 0.0],
                     trap_centre=[0.5, 0.0], gravity=[0.0, -9.8], seed=1)  # fmt: skip
    assert "gravity=(0, -9.8), trap_stiffness=(1, 0), trap_centre=(0.5, 0)" in repr(r)
    arrays = r.arrays()
    assert np.array_equal(arrays["gravity"], [0.0, -9.8])
    assert np.array_equal(arrays["trap_stiffness"], [1.0, 0.0])
    assert np.array_equal(arrays["trap_centre"], [0.5, 0.0])
    assert arrays["initial_positions"].shape == (8, 2)
    assert np.all(arrays["initial_positions"][:, 1] == 0)  # untrapped: from the origin
    back = pickle.loads(pickle.dumps(r))
    assert np.array_equal(back.gravity, r.gravity) and back.has_force
    free = langevin.run(8, gamma0=G, D0=D, dt=0.01, t_stop=0.1, dim=2, seed=1)
    assert not free.has_force and "gravity" not in repr(free)
    # the velocities are drawn as without force: the positions' draws come after
    assert np.array_equal(
        free.final_velocities,
        langevin.run(8, gamma0=G, D0=D, dt=0.01, t_stop=0.1, dim=2, seed=1).final_velocities,
    )


def test_trap_theory_limits_and_regimes():
    """msd_trap: ballistic d (T/m) t^2 at short times (to 1e-3 at gamma0 t = 2e-4), the
    plateau at t = 1e3 (e^-49 away), continuous across the critical point (to 1e-8 at w = g^2/4
    (1 +- 1e-9)); the theory's e11 against the C core's 1 - w j1 (two independent
    implementations) in every regime to 1e-10; the VACF's value at 0; the barometric
    density normalised with mean height T / (m g)."""
    T = D * G
    t = 1e-4
    for k in REGIMES.values():
        assert theory.msd_trap(t, D0=D, gamma0=G, stiffness=k) == pytest.approx(
            3 * T * t * t, rel=1e-3
        )
        assert theory.msd_trap(1e3, D0=D, gamma0=G, stiffness=k) == pytest.approx(
            theory.msd_trap_plateau(k, temperature=T, dim=3)
        )
        assert theory.trap_velocity_autocorrelation(0.0, D0=D, gamma0=G, stiffness=k) == T
        for dt in (0.1, 1.0, 3.0):
            e11 = theory.trap_position_autocorrelation(dt, gamma0=G, stiffness=k)
            assert e11 == pytest.approx(1 - k * coefficients(G, D, k, dt)["j1"], abs=1e-10)
    ts = np.linspace(0.01, 10, 50)
    crit = theory.msd_trap(ts, D0=D, gamma0=G, stiffness=1.0)
    for eps in (-1e-9, 1e-9):
        near = theory.msd_trap(ts, D0=D, gamma0=G, stiffness=1.0 + eps)
        assert np.allclose(near, crit, rtol=1e-8)
    z = np.linspace(0, 40, 400001)
    rho = theory.barometric_density(z, gravity=2.0, temperature=T, mass=1.5)
    assert np.trapezoid(rho, z) == pytest.approx(1, rel=1e-6)
    assert np.trapezoid(z * rho, z) == pytest.approx(T / (1.5 * 2.0), rel=1e-6)
    assert theory.barometric_density(-1.0, gravity=2.0, temperature=T) == 0
    with pytest.raises(ValueError, match="gravity must be positive"):
        theory.barometric_density(1.0, gravity=-2.0, temperature=T)
    # the overdamped slow rate: 1 - MSD/plateau decays as exp(-lambda t)
    w = REGIMES["over"]
    lam = w / (G / 2 + math.sqrt(G * G / 4 - w))
    e11 = trap._propagator(np.array([20.0, 21.0]), G, w)[0]
    assert math.log(e11[0] / e11[1]) == pytest.approx(lam, rel=1e-9)


def test_an_ensemble_saves_and_resumes_the_forces(tmp_path):
    """ensemble(save_to=...) writes each run's arrays(): the force's g, k, c and the starts
    are in the run files, and a resumed ensemble reads them back unchanged."""
    import functools

    from granular import ensemble

    model = functools.partial(
        langevin.run, 6, gamma0=G, D0=D, dt=0.01, t_stop=0.1, dim=2,
        trap_stiffness=[2.0, 0.0], gravity=[0.0, -1.0], threads=1,
    )  # fmt: skip
    first = ensemble(model, 2, seed=3, backend="serial", save_to=tmp_path)
    files = sorted(tmp_path.glob("*.npz"))
    assert len(files) == 2
    with np.load(files[0]) as saved:
        assert np.array_equal(saved["trap_stiffness"], [2.0, 0.0])
        assert np.array_equal(saved["gravity"], [0.0, -1.0])
        assert saved["initial_positions"].shape == (6, 2)
    again = ensemble(model, 2, seed=3, backend="serial", save_to=tmp_path)
    for a, b in zip(first.runs, again.runs, strict=True):
        assert np.array_equal(a["initial_positions"], b["initial_positions"])
        assert np.array_equal(a["trap_centre"], b["trap_centre"])


def test_the_tamsd_of_a_stationary_trapped_run_is_its_msd():
    """A stationary trapped run has stationary increments, so its expected TAMSD at a lag
    is the MSD there: theory_tamsd gives msd_trap, and the measured TAMSD (n = 4000
    particles x ~t_stop/lag windows each; its relative standard error is at most the
    ensemble's, sqrt(2 / (3 n)) = 1.3 %, the windows only lowering it) lies within 5 of
    them.  A run that is not stationary (a fixed start; a free fall) is refused, and so is
    the free model's ergodicity-breaking theory."""
    n, k = 4000, 4.0
    lags = [0.05, 0.5, 2.0]
    r = langevin.run(n, gamma0=G, D0=D, dt=0.05, t_stop=10.0, trap_stiffness=k, tamsd_lags=lags,
                     seed=9)  # fmt: skip
    th = r.theory_tamsd()
    assert np.allclose(th, theory.msd_trap(np.array(lags), D0=D, gamma0=G, stiffness=k))
    assert np.all(np.abs(r.tamsd() / th - 1) < 5 * math.sqrt(2 / (3 * n)))
    with pytest.raises(ValueError, match="free Langevin/UDSBM model's"):
        r.theory_ergodicity_breaking()
    fixed = langevin.run(8, gamma0=G, D0=D, dt=0.05, t_stop=1.0, trap_stiffness=k,
                         tamsd_lags=[0.05], initial="fixed", seed=9)  # fmt: skip
    with pytest.raises(ValueError, match="stationary run only"):
        fixed.theory_tamsd()
    falling = langevin.run(8, gamma0=G, D0=D, dt=0.05, t_stop=1.0, dim=2, tamsd_lags=[0.05],
                           trap_stiffness=[k, 0.0], gravity=[0.0, -1.0], seed=9)  # fmt: skip
    with pytest.raises(ValueError, match="falls freely"):
        falling.theory_tamsd()


@pytest.mark.parametrize("scheme", ["exact", "em"])
def test_a_start_off_the_balance_point_relaxes_as_theory_says(scheme):
    """Every particle from the origin at one speed, the trap's centre at (1, -0.5) and
    gravity along y: the MSD includes the mean's relaxation towards the balance point,
    (1 - e11)^2 offset^2, and the theory (theory_msd, axis by axis) holds at every sample
    within 5 standard errors of the mean, measured from the particles' own squared
    displacements.  EM at gamma0 dt = 0.01 adds a bias of order gamma0 dt = 1 %, so it is
    held to 5 standard errors plus 2 %."""
    n, k = 4000, 3.0
    r = langevin.run(n, gamma0=G, D0=D, dt=0.005, t_stop=6.0, dim=2, trap_stiffness=k,
                     trap_centre=[1.0, -0.5], gravity=[0.0, -1.0], initial="fixed",
                     sample_times=[0.1, 0.5, 1.0, 2.0, 6.0], store_positions=True, scheme=scheme,
                     seed=12)  # fmt: skip
    per = (r.positions**2).sum(axis=2)  # (T, N): each particle's squared displacement
    se = per.std(axis=1, ddof=1) / math.sqrt(n)
    th = r.theory_msd()
    slack = 0.0 if scheme == "exact" else 0.02 * th
    assert np.all(np.abs(per.mean(axis=1) - th) < 5 * se + slack), (per.mean(axis=1) - th) / se
    assert np.all(r.initial_positions == 0)
