"""The Langevin engine against theory.  Statistical tolerances are five standard errors
of the estimate, from the ensemble size (stated at each assertion): a false-alarm
probability of 5.7e-7 per comparison (two-sided Gaussian tail at 5 sigma), so by the union
bound even a test comparing at all its ~60 sample times fails by chance less than once in
10^4 runs."""

import json
import math
import os
import platform
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import granular
from granular import _core, langevin, theory

from helpers import sde_bits, sde_reference

G0, D0 = 9.26, 0.072  # the thesis' standard gas, xi = 0.8 (theory.langevin_coefficients)
TAU0 = 0.972
VT = G0 * D0  # T0 / m
A = G0 * TAU0  # a = gamma0 tau0 of UDSBM


def rel_se_msd(n, dim=3):
    """Relative standard error of a mean of |x|^2 over n particles when each component is
    Gaussian (true at every time here: linear SDEs from Gaussian velocities):
    sqrt(2 / (dim n))."""
    return math.sqrt(2 / (dim * n))


def diffusive_limit(t):
    """Langevin, thermal start: (2.68) tends to Einstein's (2.46) shifted by 1/gamma0."""
    return theory.msd_diffusive(t, D0=D0, gamma0=G0)


def logarithmic_limit(t):
    """UDSBM, App. C's start: (2.113) is exactly the granular gas' (2.79) with
    gamma0 -> gamma0 - 1/tau0 and D0 -> D0 a^2 / (a - 1)^2, so it tends to the
    logarithmic limit (2.80) with those coefficients -- a slope against ln t larger than
    the granular gas' 2 d D0 tau0 by a^2 / (a - 1)^2 (27% at xi = 0.8)."""
    return theory.msd_logarithmic(t, D0=D0 * A**2 / (A - 1) ** 2, tau0=TAU0, gamma0=G0 - 1 / TAU0)


@pytest.mark.parametrize(
    "model,tau0,initial,limit",
    [
        ("langevin", math.inf, "thermal", diffusive_limit),
        ("udsbm", TAU0, "udsbm", logarithmic_limit),
        ("udsbm", TAU0, "thermal", None),
    ],
)  # the thermal start's transient shifts the limit
def test_exact_scheme_msd_matches_theory(model, tau0, initial, limit):
    """Ensemble MSD vs (2.68) for Langevin and (2.113) for UDSBM with App. C's initial
    speed (and the transient term for a thermal start), from the ballistic to the
    diffusive / logarithmic regime; then the long-time samples vs the limit.  Tolerance:
    5 relative standard errors, sqrt(2 / (3 * 20000)) = 0.58% each, at every sample."""
    n = 20000
    r = langevin.run(
        n,
        gamma0=G0,
        D0=D0,
        tau0=tau0,
        dt=0.01,
        t_stop=50.0,
        scheme="exact",
        initial=initial,
        seed=1,
    )
    th = r.theory_msd()
    ok = r.times > 0
    tol = 5 * rel_se_msd(n)
    np.testing.assert_array_less(np.abs(r.msd()[ok] / th[ok] - 1), tol)
    assert r.msd()[0] == 0.0
    if limit is None:
        return
    # from t = 5 (gamma0 t = 46, t = 5 tau0) the limits equal the full MSD to 1e-6
    # relative (exp(-gamma0 t) / (gamma0 t) and (1 + t/tau0)^(1-a) / ((a - 1) ln(...))),
    # so the data, within tol of the full MSD above, are within tol + 1e-6 of the limit
    late = r.times >= 5.0
    assert late.sum() >= 10
    np.testing.assert_array_less(np.abs(limit(r.times[late]) / th[late] - 1), 1e-6)


def test_euler_maruyama_msd_matches_theory_at_small_steps():
    """EM at gamma0 dt = 0.009: its velocity bias 2/(2 - gamma0 dt) - 1 = 0.47% adds to
    the statistical tolerance."""
    n = 20000
    for tau0 in (math.inf, TAU0):
        r = langevin.run(
            n,
            gamma0=G0,
            D0=D0,
            tau0=tau0,
            dt=0.001,
            t_stop=5.0,
            scheme="em",
            initial="udsbm" if tau0 < math.inf else "thermal",
            seed=2,
        )
        ok = r.times > 0
        bias = 2 / (2 - G0 * 0.001) - 1
        np.testing.assert_array_less(
            np.abs(r.msd()[ok] / r.theory_msd()[ok] - 1), 5 * rel_se_msd(n) + bias
        )


@pytest.mark.parametrize(
    "tau0,initial,v0_sq",
    [
        (math.inf, "thermal", VT),
        (math.inf, "fixed", 1.5**2 / 3),
        (TAU0, "udsbm", theory.udsbm_v0_sq(D0=D0, gamma0=G0, tau0=TAU0)),
    ],
)
def test_ballistic_limit(tau0, initial, v0_sq):
    """Short times, t << 1/gamma0: the MSD is free flight, d <v0^2> t^2
    (theory.msd_ballistic with T/m = the initial <v_a^2>), over a decade of t.
    Tolerance: 5 relative standard errors of the mean of |x|^2, sqrt(2 / (3 n)) = 0.18%
    for n = 2e5 Gaussian velocities (conservative for a fixed speed, where |v0| has no
    spread), plus the limit's own distance from the full MSD at these times, taken from
    theory (at most 0.4%, at t = 1e-3: gamma0 t / 3 for Langevin)."""
    n = 200_000
    t = np.array([1e-4, 3e-4, 1e-3])
    r = langevin.run(
        n,
        gamma0=G0,
        D0=D0,
        tau0=tau0,
        dt=1e-4,
        t_stop=1e-3,
        scheme="exact",
        initial=initial,
        speed=1.5 if initial == "fixed" else None,
        sample_times=t,
        seed=3,
    )
    assert r.v0_sq == pytest.approx(v0_sq)
    ballistic = theory.msd_ballistic(t, temperature=v0_sq)
    off_limit = np.abs(r.theory_msd(t) / ballistic - 1)
    np.testing.assert_array_less(np.abs(r.msd() / ballistic - 1), 5 * rel_se_msd(n) + off_limit)


def test_euler_maruyama_first_step_is_exact_free_flight():
    """Fixed speed, first Euler-Maruyama step: x = v0 dt exactly (the noise enters the
    velocity only), so MSD(dt) = speed^2 dt^2 to rounding."""
    r = langevin.run(
        100,
        gamma0=G0,
        D0=D0,
        dt=1e-4,
        t_stop=1e-3,
        speed=1.5,
        initial="fixed",
        scheme="em",
        sample_times=[0, 1e-4],
        seed=3,
    )
    assert r.msd()[1] == pytest.approx(1.5**2 * 1e-8, rel=1e-13)
    assert r.v0_sq == pytest.approx(0.75)


@pytest.mark.parametrize("gdt", [0.5, 1.0, 1.5])
def test_euler_maruyama_velocity_bias(gdt):
    """Stationary <v^2> of EM is (T/m) 2 / (2 - gamma0 dt) (2.92 iterated); relative standard
    error of the mean over 3N Gaussian components, sqrt(2 / (3 N))."""
    n = 100_000
    r = langevin.run(
        n,
        gamma0=G0,
        D0=D0,
        dt=gdt / G0,
        t_stop=60 / G0,
        scheme="em",
        seed=4,
        sample_times=[60 / G0],
    )
    assert r.v2[-1] / (3 * VT) == pytest.approx(2 / (2 - gdt), rel=5 * rel_se_msd(n))
    exact = langevin.run(
        n,
        gamma0=G0,
        D0=D0,
        dt=gdt / G0,
        t_stop=60 / G0,
        scheme="exact",
        seed=4,
        sample_times=[60 / G0],
    )
    assert exact.v2[-1] / (3 * VT) == pytest.approx(1.0, rel=5 * rel_se_msd(n))


def test_exact_step_moments():
    """One exact step from x = 0, v = 0: v' ~ N(0, D g (1 - c^2)), x' Gaussian with the OU
    variance (2D/g)(h - 2(1-c) + (1-c^2)/2) and covariance D (1-c)^2, c = exp(-h), h = g dt.
    Checked with 10^6 particles in 1D: variances to 5 sqrt(2/N), the correlation coefficient
    to 5 (1 - rho^2)/sqrt(N), kurtosis 3 to 5 sqrt(24/N) (which also tests the Gaussian
    generator)."""
    n, g, D, dt = 1_000_000, 2.0, 0.5, 0.3
    r = langevin.run(
        n,
        gamma0=g,
        D0=D,
        dt=dt,
        t_stop=dt,
        scheme="exact",
        dim=1,
        initial="fixed",
        speed=1e-300,
        sample_times=[dt],
        store_positions=True,
        seed=5,
    )
    x = r.positions[0, :, 0]
    v = r.final_velocities[:, 0]
    h, c = g * dt, math.exp(-g * dt)
    var_v = D * g * (1 - c * c)
    var_x = 2 * D / g * (h - 2 * (1 - c) + (1 - c * c) / 2)
    cov = D * (1 - c) ** 2
    tol = 5 * math.sqrt(2 / n)
    assert np.var(v) == pytest.approx(var_v, rel=tol)
    assert np.var(x) == pytest.approx(var_x, rel=tol)
    rho = cov / math.sqrt(var_v * var_x)
    assert np.corrcoef(x, v)[0, 1] == pytest.approx(rho, abs=5 * (1 - rho**2) / math.sqrt(n))
    for a in (x, v):
        assert abs(np.mean(a)) < 5 * math.sqrt(np.var(a) / n)
        kurt = np.mean((a - a.mean()) ** 4) / np.var(a) ** 2
        assert abs(kurt - 3) < 5 * math.sqrt(24 / n)


def test_tamsd_equals_msd_for_langevin_but_not_for_udsbm():
    """Ergodicity (thesis 2.114-2.119, Figs 4.21-4.23): for the Langevin model the
    time-averaged MSD equals the ensemble MSD; for UDSBM it equals (2.115) evaluated with
    the UDSBM increments over the run's windows (``theory_tamsd``, itself checked in
    test_theory), far below the ensemble MSD.  Tolerance: 5 standard errors of the
    particle average of the TAMSD (particles are independent: the std of the per-particle
    TAMSD over sqrt(n)); the exact scheme's frozen UDSBM coefficients err by
    O(dt^2 / tau0^2) = 1e-4 relative, far below that."""
    n = 4000
    lags = np.array([0.05, 0.5, 5.0])
    r = langevin.run(
        n, gamma0=G0, D0=D0, dt=0.01, t_stop=100.0, scheme="exact", tamsd_lags=lags, seed=6
    )
    se = r.tamsd_per_particle.std(0, ddof=1) / math.sqrt(n)
    expected = theory.msd_langevin(lags, D0=D0, gamma0=G0)
    np.testing.assert_array_less(np.abs(r.tamsd() - expected), 5 * se)
    u = langevin.run(
        n,
        gamma0=G0,
        D0=D0,
        tau0=TAU0,
        dt=0.01,
        t_stop=100.0,
        scheme="exact",
        initial="udsbm",
        tamsd_lags=lags,
        seed=6,
    )
    se = u.tamsd_per_particle.std(0, ddof=1) / math.sqrt(n)
    np.testing.assert_array_less(np.abs(u.tamsd() - u.theory_tamsd()), 5 * se)
    # non-ergodic: the ensemble MSD lies many standard errors above the time average
    np.testing.assert_array_less(5 * se, u.theory_msd(lags) - u.tamsd())


@pytest.mark.parametrize("model,tau0", [("langevin", math.inf), ("udsbm", TAU0)])
@pytest.mark.parametrize("scheme", ["em", "exact"])
def test_same_seed_same_result_whatever_the_chunking(monkeypatch, model, tau0, scheme):
    """Bit-identical results (np.array_equal) whether the work goes to C in one call, in
    blocks of particles, or one particle at a time in segments of a few steps -- 1, 7 or 13,
    so that segment ends fall before, on and after sample steps and TAMSD window starts and
    ends (samples at every step; lags of 1, 7, 30, 100 and all 200 steps)."""
    kw = dict(
        gamma0=G0,
        D0=D0,
        tau0=tau0,
        model=model,
        scheme=scheme,
        dt=0.01,
        t_stop=2.0,
        sample_times=np.arange(201) * 0.01,
        tamsd_lags=[0.01, 0.07, 0.3, 1.0, 2.0],
        store_positions=True,
        seed=7,
    )
    names = (
        "msd_total",
        "msd_per_dimension",
        "v2",
        "tamsd_per_particle",
        "positions",
        "final_positions",
        "final_velocities",
    )
    a = langevin.run(30, **kw)  # one call: 30 x 200 particle-steps
    for chunk in (
        200 * 7,
        13,
        7,
        1,
    ):  # 7 particles a call; then one particle, 13, 7, 1 steps a call
        monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", chunk)
        b = langevin.run(30, **kw)
        for name in names:
            assert np.array_equal(getattr(a, name), getattr(b, name)), (chunk, name)
    c = langevin.run(30, **{**kw, "seed": 8})
    assert not np.array_equal(a.positions, c.positions)


@pytest.mark.parametrize("model,tau0", [("langevin", math.inf), ("udsbm", TAU0)])
@pytest.mark.parametrize("scheme", ["em", "exact"])
@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("lags", [None, [0.01, 0.05, 0.13, 0.5]])
def test_same_bits_for_any_number_of_threads(monkeypatch, model, tau0, scheme, dim, lags):
    """threads = 1, 2, 3, 7 give the same bits (np.array_equal) -- the ensemble sums too,
    whose blocks of 32 particles are added in order whatever thread summed them.  250
    particles are 8 blocks, the last one short, so 7 threads split them unevenly; then
    the same in calls of 45 x threads particles (rounded down to whole blocks per
    thread), and of 3 x threads (below a block: calls begin and end inside blocks, a
    thread's first and last blocks are partial, the carry takes them to the next call)."""
    kw = dict(
        gamma0=G0,
        D0=D0,
        tau0=tau0,
        model=model,
        scheme=scheme,
        dim=dim,
        dt=0.01,
        t_stop=0.5,
        sample_times=np.arange(0, 51, 5) * 0.01,
        tamsd_lags=lags,
        store_positions=True,
        seed=11,
    )
    names = (
        "msd_per_dimension",
        "v2",
        "tamsd_per_particle",
        "positions",
        "final_positions",
        "final_velocities",
    )
    a = langevin.run(250, threads=1, **kw)
    for per_thread in (None, 45, 3):
        if per_thread:
            monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", per_thread * 50)
        for threads in (1, 2, 3, 7):
            b = langevin.run(250, threads=threads, **kw)
            for name in names:
                assert np.array_equal(getattr(a, name), getattr(b, name)), (threads, name)
    # the sums are not all zeros or copies: a particle's noise is its own
    assert a.msd_total[-1] > 0 and not np.array_equal(a.final_positions[0], a.final_positions[1])


@pytest.mark.parametrize("threads", [0, -1, 1.5, "2", True])
def test_refuses_a_bad_thread_count(threads):
    with pytest.raises(ValueError, match="threads must be"):
        langevin.run(10, gamma0=G0, D0=D0, dt=0.01, t_stop=0.1, threads=threads)


def test_ctrl_c_stops_a_long_run_of_one_particle():
    """SIGINT reaches a run of one particle and many steps between calls into C: the work
    is chunked by particle-steps, not by particles.  The run is 2e9 Euler-Maruyama steps,
    which in one call into C (the chunking by particles alone) took 31 s (15.7 ns a step,
    measured on a 2-core machine), far past the bound.  In a child process, so that a
    failure costs a kill, not the test run.  The bound, 3 s from the signal to the exit
    with KeyboardInterrupt, is generous: a call takes ~0.2 s."""
    code = textwrap.dedent("""
        import sys
        from granular import langevin
        print("start", flush=True)
        try:
            langevin.run(1, gamma0=1.0, D0=1.0, dt=0.01, t_stop=2e7, scheme="em",
                         sample_times=[0.0], seed=1)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
        print("finished", flush=True)
        """)
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        text=True,
        cwd=os.path.dirname(__file__),
    )
    try:
        assert proc.stdout.readline() == "start\n"
        time.sleep(1.0)  # well inside the run
        proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        out, _ = proc.communicate(timeout=30)
        waited = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert out.strip() == "interrupted" and proc.returncode == 0
    assert waited < 3.0, f"the run took {waited:.1f} s to stop after SIGINT"


@pytest.mark.parametrize(
    "case,error",
    [
        # positions: T x n x dim = 4 x 2**62 x 1 wraps to 0 in int64
        (
            "dict(n=2**62, sample_steps=np.arange(4), positions=np.zeros(0))",
            "OverflowError: .*positions",
        ),
        # tamsd: n x L = 2**62 x 4 wraps to 0
        ("dict(n=2**62, lags=np.arange(1, 5), tamsd=np.zeros(0))", "OverflowError: .*tamsd"),
        # first + len(x) past int64
        ("dict(n=2**63 - 1, first=2**63 - 1)", "ValueError: first \\+ len\\(x\\) exceeds n"),
        ("dict(n_steps=2**62 + 1, step_to=2**62 + 1)", "ValueError: n_steps must lie in"),
    ],
)
def test_core_sde_run_checks_sizes_without_overflow(case, error):
    """_core.sde_run called directly with sizes whose products overflow int64 raises a
    clean exception instead of accepting a short buffer and writing past it (a child
    process, so that a crash fails the test instead of ending the test run)."""
    code = textwrap.dedent(f"""
        import numpy as np
        from granular import _core
        args = dict(dim=1, model=0, scheme=0, gamma0=1.0, D0=1.0, tau0=float("inf"), dt=0.01,
                    key=1, n=1, first=0, step_from=0, step_to=3, n_steps=3, x=np.zeros(1),
                    v=np.zeros(1), sample_steps=np.zeros(1, dtype=np.int64), x2=None, v2=None,
                    positions=None, lags=np.zeros(0, dtype=np.int64), tamsd=np.zeros(0),
                    ring=None)
        args.update({case})
        args.update(x2=np.zeros(len(args["sample_steps"])), v2=np.zeros(len(args["sample_steps"])),
                    ring=np.zeros(_core.sde_ring_size(1, args["lags"])))
        try:
            _core.sde_run(**args)
            print("no error")
        except Exception as exc:
            print(f"{{type(exc).__name__}}: {{exc}}")
        """)
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=os.path.dirname(__file__),
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert re.match(error, done.stdout), done.stdout


def test_refuses_unstable_euler_maruyama():
    with pytest.raises(granular.UnstableStepError, match=r"gamma0\*dt >= 2.*exact") as info:
        langevin.run(10, gamma0=10.0, D0=0.1, dt=0.2, t_stop=1.0, scheme="em")
    assert info.value.value == pytest.approx(2.0)
    # the exact scheme takes the same step
    r = langevin.run(
        1000,
        gamma0=10.0,
        D0=0.1,
        dt=0.2,
        t_stop=100.0,
        scheme="exact",
        seed=1,
        sample_times=[100.0],
    )
    assert r.v2[-1] / 3 == pytest.approx(1.0, rel=5 * rel_se_msd(1000))


def test_exact_scheme_is_the_default():
    s = granular.Scene.random(100, 0.025, restitution=0.8, seed=1)
    assert langevin.run(10, gamma0=G0, D0=D0, dt=0.01, t_stop=0.1, seed=1).scheme == "exact"
    assert langevin.from_scene(s, dt=0.01, t_stop=0.1, n=10, seed=1).scheme == "exact"
    assert langevin.from_scene(s, dt=0.01, t_stop=0.1, n=10, scheme="em", seed=1).scheme == "em"


def test_default_samples_end_at_t_stop_for_any_step_count(monkeypatch):
    """The default log-spaced samples end at the last step even where float rounding of
    logspace overshoots it (10^15 + 3 steps: 10^15 + 4); no stepping is needed to see it,
    so the C core is replaced by a stub (called once)."""
    seen = []
    monkeypatch.setattr(langevin._core, "sde_run", lambda **kw: seen.append(kw["sample_steps"]))
    monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", 10**16)
    r = langevin.run(1, gamma0=G0, D0=D0, dt=1.0, t_stop=1e15 + 3, seed=1)
    assert r.times[-1] == 1e15 + 3 and np.all(np.diff(r.times) > 0)
    assert len(seen) == 1 and seen[0][-1] == 10**15 + 3


def test_from_scene_uses_the_thesis_coefficients():
    s = granular.Scene.random(1000, 0.025, restitution=0.8, seed=1)
    c = langevin.coefficients_from_scene(s)
    ref = theory.langevin_coefficients(
        n=1000, radius=0.025, volume=1.0, restitution=0.8, temperature0=s.temperature
    )
    assert c == pytest.approx(ref)
    r = langevin.from_scene(s, dt=0.01, t_stop=1.0, n=200, seed=1)
    assert r.model == "udsbm" and r.tau0 == pytest.approx(ref.tau0)
    m = langevin.from_scene(s.replace(restitution=1.0), dt=0.01, t_stop=1.0, n=200, seed=1)
    assert m.model == "langevin"


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(gamma0=-1.0), "gamma0 must be positive"),
        # named with its meaning, as theory names it
        (
            dict(D0=-1.0),
            r"^D0 must be positive and finite, got -1 \(D0: diffusivity per dimension at t = 0\)",
        ),
        (dict(mass=0.0), r"mass must be positive and finite, got 0 \(mass: particle mass\)"),
        (dict(dt=0.0), "dt must be positive"),
        (dict(t_stop=float("nan")), "t_stop must be positive"),
        (dict(model="brownian"), "model must be one of"),
        (dict(scheme="rk4"), "scheme must be one of"),
        (dict(dim=4), "dim must be"),
        (dict(sample_times=[0.5, 0.2]), "increasing"),
        (dict(sample_times=[0.5, 5.0]), "past t_stop"),
        (dict(tamsd_lags=[0.0]), "tamsd_lags"),
        (dict(initial="hot"), "initial must be one of"),
        (dict(model="udsbm"), "finite tau0"),
        (dict(initial="udsbm"), "App. C"),
        # step counts past int64 (or infinite) are refused with the numbers, before any cast
        (
            dict(t_stop=1e300),
            "t_stop / dt = 1e\\+300 / 0.01 = 1e\\+302 steps; a run takes at most 2\\*\\*62",
        ),
        (dict(dt=5e-324), "t_stop / dt = 1.0 / 5e-324 = inf steps"),
        (dict(sample_times=[0.0, 1e300]), "past t_stop"),
        (dict(tamsd_lags=[1e300]), "tamsd_lags must be at least dt and at most t_stop"),
        (dict(tamsd_lags=[float("nan")]), "tamsd_lags must be at least dt and at most t_stop"),
        (dict(tamsd_estimator="some"), "tamsd_estimator must be one of"),
        (
            dict(t_stop=2.0**31 * 0.01, tamsd_lags=[2.0**31 * 0.01], tamsd_estimator="all"),
            "every-window TAMSD keeps the last lag's worth",
        ),
    ],
)
def test_bad_input(kwargs, match):
    base = dict(gamma0=G0, D0=D0, dt=0.01, t_stop=1.0)
    base.update(kwargs)
    with pytest.raises(ValueError, match=match):
        langevin.run(10, **base)


# Scales whose squares or products would leave float64 over the run (granular._scales):
# refused before it, naming the parameter, its value and the range.  A speed of 1e154 used
# to run, its squared speed summed over 8 particles an inf.
SCALE_BASE = dict(gamma0=3.2, D0=1.78, dt=0.01, t_stop=0.5, scheme="em", dim=1, seed=1)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(initial="fixed", speed=1.79e308), r"speed = 1\.79e\+308 is outside 0 \.\. 1e\+140"),
        (dict(initial="fixed", speed=1e154), r"speed = 1e\+154 is outside 0 \.\. 1e\+140"),
        (dict(initial="fixed", speed=1.01e140), r"speed = 1\.01e\+140 is outside"),
        # the ballistic displacement: speed 1e100 is fine, for 1e41 time units it is not
        (
            dict(initial="fixed", speed=1e100, t_stop=1e41, dt=1e39, gamma0=1e-41),
            r"speed \* t_stop \(the ballistic displacement\) = 1e\+141 is outside 0 \.\. "
            r"1e\+140.*speed at most 1e\+99 for t_stop = 1e\+41",
        ),
        (dict(gamma0=1e141, scheme="exact"), r"gamma0 = 1e\+141 is outside 1e-140 \.\. 1e\+140"),
        (dict(gamma0=1e-141), r"gamma0 = 1e-141 is outside 1e-140 \.\. 1e\+140"),
        (dict(dt=1e-141, t_stop=1e-139), r"dt = 1e-141 is outside"),
        (dict(dt=1e140, t_stop=1e141, gamma0=1e-141), r"t_stop = 1e\+141 is outside"),
        (dict(D0=1e281), r"D0 = 1e\+281 is outside 1e-280 \.\. 1e\+280"),
        (dict(D0=1e-281), r"D0 = 1e-281 is outside 1e-280 \.\. 1e\+280"),
        (dict(D0=1e200, gamma0=1e100, scheme="exact"), r"D0 \* gamma0 .* = 1e\+300 is outside"),
        (
            dict(D0=1e250, gamma0=1e-100, t_stop=1e40, dt=1e38),
            r"D0 \* t_stop .* = 1e\+290 is outside 0 \.\. 1e\+280.*D0 at most 1e\+240",
        ),
        (dict(mass=1e281), r"mass = 1e\+281 is outside 1e-280 \.\. 1e\+280"),
        (dict(mass=1e-281), r"mass = 1e-281 is outside"),
        # the temperature, mass v^2, would overflow
        (dict(mass=1e270, initial="fixed", speed=1e10), r"mass \* speed\^2 .* = 1e\+290"),
        (dict(model="udsbm", tau0=1e-141), r"tau0 = 1e-141 is outside"),
        # UDSBM's friction decays below float64's range: the exact step would divide 0 by 0
        (
            dict(model="udsbm", tau0=1.0, exponent=100.0, t_stop=1e4, dt=1.0, scheme="exact"),
            r"UDSBM's gamma0 at t_stop.*= 10\^-399\.5, is below 1e-140",
        ),
    ],
)
def test_scales_past_float64_are_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        langevin.run(8, **dict(SCALE_BASE, **kwargs))


@pytest.mark.parametrize(
    "kwargs",
    [
        # speed at its limit, and speed * t_stop at its limit: MSDs near 1e280
        dict(initial="fixed", speed=1e140, t_stop=1.0, dim=2, scheme="exact"),
        dict(initial="fixed", speed=1e100, t_stop=1e40, dt=1e38, gamma0=1e-40, D0=1.0),
        dict(initial="fixed", speed=1e140, mass=1e-1),
    ],
)
@pytest.mark.filterwarnings("ignore:LangevinResult.temperature is an energy now")
def test_scales_just_inside_the_limits_run_to_finite_results(kwargs):
    r = langevin.run(8, **dict(SCALE_BASE, **kwargs))
    for name in (
        "msd_total",
        "msd_per_dimension",
        "v2",
        "temperature",
        "final_positions",
        "final_velocities",
    ):
        assert np.all(np.isfinite(getattr(r, name))), name
    # the fixed speed dominates the thermal noise (~1) by 1e100 and more: the MSD is the
    # deterministic ballistic transient to rounding, s^2 ((1 - e^(-gamma t)) / gamma)^2
    # (Euler-Maruyama: its discrete sum, (1 - (1 - gamma dt)^k) / gamma)
    s, g, t = kwargs["speed"], r.gamma0, r.times
    if r.scheme == "exact":
        want = s**2 * (-np.expm1(-g * t) / g) ** 2
    else:
        want = s**2 * ((1 - (1 - g * r.dt) ** r.steps) / g) ** 2
    np.testing.assert_allclose(r.msd_total[1:], want[1:], rtol=1e-9)
    assert r.msd_total[-1] > 1e200


def test_a_lag_between_two_steps_is_refused_before_the_run(monkeypatch):
    """The engine samples the path at whole steps, so tamsd_lags=[0.15] with dt = 0.1 is
    refused, naming the two lags it could have (not rounded to 0.1 unseen, as
    Trajectory.tamsd refuses a lag off its samples), before the engine is started; so are
    the theory's lags, and two lags that are the same step."""

    def engine(*args, **kwargs):
        raise AssertionError("the engine ran")

    monkeypatch.setattr(langevin._core, "sde_run", engine)
    kw = dict(gamma0=G0, D0=D0, dt=0.1, t_stop=1.0, seed=1)
    msg = r"tamsd_lags: 0\.15 is not a whole number of steps of dt = 0\.1.* 0\.1 and 0\.2 "
    with pytest.raises(ValueError, match=msg):
        langevin.run(10, tamsd_lags=[0.1, 0.15], **kw)
    # past the last step that fits in t_stop, only the lag below is offered
    with pytest.raises(ValueError, match=r"nearest lags that are: 1 \("):
        langevin.run(10, tamsd_lags=[1.04], **kw)
    with pytest.raises(ValueError, match=r"0\.1 and 0\.1000000001 are the same number of steps"):
        langevin.run(10, tamsd_lags=[0.1, 0.1000000001], **kw)
    with pytest.raises(ValueError, match=r"lags: 0\.25 is not a whole number.* 0\.2 and 0\.3 "):
        langevin.theory_tamsd([0.25], gamma0=G0, D0=D0, **{k: kw[k] for k in ("dt", "t_stop")})


def test_a_result_without_lags_says_how_to_ask_for_them():
    """A run given no tamsd_lags accumulated no TAMSD: tamsd() and everything built on it
    raise, saying to pass tamsd_lags= to run, instead of returning an empty array."""
    r = langevin.run(5, gamma0=G0, D0=D0, dt=0.01, t_stop=0.1, seed=1)
    for method in (r.tamsd, r.ergodicity_breaking, r.theory_tamsd, r.theory_ergodicity_breaking):
        with pytest.raises(ValueError, match=r"no time-averaged MSD .*run\(\.\.\., tamsd_lags="):
            method()


def test_theory_ergodicity_breaking_refuses_a_fixed_speed_start():
    """The EB theory rests on Isserlis' theorem, so on Gaussian initial velocities: a run
    from initial="fixed" (one speed for every particle) gets a ValueError saying so, not
    a number; Gaussian starts ("thermal", "udsbm") get finite positive numbers."""
    kw = dict(gamma0=G0, D0=D0, dt=0.01, t_stop=2.0, tamsd_lags=[0.1, 0.5], seed=3)
    fixed = langevin.run(50, initial="fixed", **kw)
    assert fixed.initial == "fixed"
    with pytest.raises(ValueError, match=r"Gaussian initial velocities.*initial='fixed'"):
        fixed.theory_ergodicity_breaking()
    with pytest.raises(ValueError, match="Isserlis"):
        fixed.theory_ergodicity_breaking([0.5])
    for initial, extra in (("thermal", {}), ("udsbm", dict(model="udsbm", tau0=1.0))):
        r = langevin.run(50, initial=initial, **kw, **extra)
        assert r.initial == initial
        eb = r.theory_ergodicity_breaking()
        assert eb.shape == (2,) and np.all(np.isfinite(eb) & (eb > 0))


def test_every_window_of_a_huge_lag_is_refused_before_allocating():
    """Every window of a lag of 2**30 steps needs a ring of 2**31 positions (48 GiB in 3D)
    per thread: refused with the size and the way out, before anything is allocated."""
    with pytest.raises(MemoryError, match=r"GiB of past positions per thread.*'strided'"):
        langevin.run(
            10,
            gamma0=G0,
            D0=D0,
            dt=0.01,
            t_stop=2.0**30 * 0.01,
            tamsd_lags=[2.0**30 * 0.01],
            tamsd_estimator="all",
        )


# -- the engine against a slow NumPy reference fed the same random numbers ------------------
#
# tests/helpers/sde_reference.py redraws csrc/rng.h's stream in Python and integrates from the
# equations (its own formulas and order of operations).  Tolerance: 1e-12 of the largest
# magnitude.  The two differ by a few ulps a step (other rounding); velocities forget such
# differences (they contract by exp(-gamma dt) a step), positions add them up, so after
# n steps they differ by about n x (a few) x 2.2e-16 -- 1e-13 for the 60 steps here,
# at most 5e-15 measured (all models, schemes, d = 1..3).  One wrong random number would
# differ by O(1).


def _assert_rounding_close(got, want):
    scale = float(np.max(np.abs(want)))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize(
    "model,scheme,dim",
    [
        ("langevin", "em", 3),
        ("langevin", "exact", 3),
        ("udsbm", "em", 3),
        ("udsbm", "exact", 3),
        ("langevin", "exact", 1),
        ("udsbm", "em", 2),
    ],
)
def test_the_engine_is_the_reference_integrator_to_rounding(model, scheme, dim):
    """Every position at every step, the final velocities, the ensemble MSD sums and the
    TAMSD over the strided estimator's windows (lags 1, 13, 33 and 60 steps: strides 1, 2,
    8, 8)."""
    v0 = np.random.default_rng(1).normal(scale=0.8, size=(4, dim))
    kw = dict(model=model, scheme=scheme, gamma0=G0, D0=D0, tau0=TAU0, dt=0.05, n_steps=60)
    key, lags = 0xDEADBEEF12345678, [1, 13, 33, 60]
    pos, v, x2, tamsd = sde_reference.engine(v0, key, lags=lags, **kw)
    xs, vs = sde_reference.run(v0, key, **kw)
    _assert_rounding_close(pos, xs)
    _assert_rounding_close(v, vs[-1])
    _assert_rounding_close(x2, (xs * xs).sum(axis=1))
    for m, lag in enumerate(lags):
        stride = sde_reference.stride(lag)
        windows = len(range(0, 61 - lag, stride))
        _assert_rounding_close(
            tamsd[:, m] / windows, sde_reference.tamsd_per_particle(xs, lag, stride)
        )


# lags (in steps) of every kind the strided bookkeeping has: stride 1 (below 8), each
# power of two, lags not multiples of their stride, and past the 4096-step phase table
# (stride 8192 from lag 32768: the "slow" lags)
BOOK_LAGS = [1, 2, 3, 5, 7, 8, 9, 13, 31, 64, 100, 1001, 5000, 16383, 32768, 40000, 65537]


@pytest.mark.parametrize("estimator", ["strided", "all"])
@pytest.mark.parametrize("dim", [1, 3])
def test_tamsd_is_the_mean_over_its_windows_of_the_stored_path(monkeypatch, estimator, dim):
    """The TAMSD the engine books on the fly is, to summation rounding, the mean over the
    windows of the estimator (starting every reference `stride` steps, written from the
    definition in tamsd.h) of |x(t + lag) - x(t)|^2 computed from the positions stored at
    every step -- in one call, on 3 threads, and one particle at a time in segments of
    7919 steps (a prime: segment ends fall everywhere in the strides' cycles, and the
    stored starts carry over in the ring).  The windows are summed in time order by both,
    in different association (d terms first here): 1e-12 relative covers it."""
    n, n_steps = 3, 70_000
    kw = dict(
        gamma0=G0,
        D0=D0,
        dt=0.01,
        t_stop=n_steps * 0.01,
        scheme="em",
        dim=dim,
        sample_times=np.arange(n_steps + 1) * 0.01,
        tamsd_lags=np.array(BOOK_LAGS) * 0.01,
        store_positions=True,
        tamsd_estimator=estimator,
        seed=5,
    )
    runs = [langevin.run(n, threads=1, **kw), langevin.run(n, threads=3, **kw)]
    monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", 7919)
    runs.append(langevin.run(n, threads=2, **kw))
    xs = runs[0].positions
    want = np.array(
        [
            sde_reference.tamsd_per_particle(xs, lag, sde_reference.stride(lag, estimator))
            for lag in BOOK_LAGS
        ]
    ).T
    for r in runs:
        np.testing.assert_allclose(r.tamsd(per_particle=True), want, rtol=1e-12, atol=0)
        assert np.array_equal(r.tamsd(per_particle=True), runs[0].tamsd(per_particle=True))
    assert [
        granular._core.sde_lag_stride(k, ("strided", "all").index(estimator)) for k in BOOK_LAGS
    ] == [sde_reference.stride(k, estimator) for k in BOOK_LAGS]


def _brownian_tamsd_rel_var(lag, stride, n_steps, dim):
    """Var / mean^2 of one particle's TAMSD for Brownian motion, windows [j s, j s + lag]
    ending by n_steps: (2 / (d M^2)) sum_ij (overlap_ij / lag)^2 -- Gaussian increments
    give Cov(dx_i^2, dx_j^2) = 2 Cov(dx_i, dx_j)^2 per axis (tamsd.h)."""
    starts = np.arange(0, n_steps - lag + 1, stride)
    gap = np.abs(starts[:, None] - starts[None, :])
    overlap = np.clip(1 - gap / lag, 0, None)
    return 2 / (dim * len(starts) ** 2) * np.sum(overlap**2)


def test_strided_tamsd_costs_the_stated_variance():
    """The strided estimator's variance against every window's, on the same paths (same
    seed, only the windows differ): each one's Var / mean^2 over particles against the
    Brownian formula above, and their ratio against (2 + 1/W^2)/(2 + 1/k^2) <= 1.031.
    Brownian increments: gamma0 dt = 2 with the exact scheme, so velocities decorrelate
    within a step or two and lags of 48-160 steps see a random walk with D0 (its
    per-step correction, ~1/(gamma0 lag) = 1-2% of the MSD, cancels in Var / mean^2 to
    first order).  Tolerances: 5 standard errors from the particles (the variance's SE
    from the sample fourth moment; the ratio's from a jackknife over 40 groups, small
    because both estimators see the same paths)."""
    n, n_steps, lags = 4000, 1500, [48, 80, 160]
    kw = dict(
        gamma0=200.0,
        D0=0.01,
        dt=0.01,
        t_stop=n_steps * 0.01,
        scheme="exact",
        dim=1,
        sample_times=[0.0],
        tamsd_lags=np.array(lags) * 0.01,
        seed=13,
    )
    per = {
        e: langevin.run(n, tamsd_estimator=e, **kw).tamsd(per_particle=True)
        for e in ("strided", "all")
    }
    for e, p in per.items():
        for m, lag in enumerate(lags):
            a = p[:, m] / p[:, m].mean()
            var = a.var(ddof=1)
            se = math.sqrt(np.mean((a - 1) ** 4) - var**2) / math.sqrt(n)
            want = _brownian_tamsd_rel_var(lag, sde_reference.stride(lag, e), n_steps, 1)
            assert abs(var - want) < 5 * se, (e, lag, var, want, se)
    groups = np.array_split(np.arange(n), 40)

    def ratio(keep):
        s, a = per["strided"][keep], per["all"][keep]
        return (s / s.mean(0)).var(0, ddof=1) / (a / a.mean(0)).var(0, ddof=1)

    full = ratio(np.arange(n))
    jack = np.array([ratio(np.setdiff1d(np.arange(n), g)) for g in groups])
    se = np.sqrt((len(groups) - 1) * np.mean((jack - jack.mean(0)) ** 2, axis=0))
    for m, lag in enumerate(lags):
        s = sde_reference.stride(lag)
        want = _brownian_tamsd_rel_var(lag, s, n_steps, 1) / _brownian_tamsd_rel_var(
            lag, 1, n_steps, 1
        )
        asymptotic = (2 + (s / lag) ** 2) / (2 + 1 / lag**2)  # W = lag / s
        assert abs(want - asymptotic) < 0.02 and want < 1.032  # the formula in tamsd.h
        assert abs(full[m] - want) < 5 * se[m], (lag, full[m], want, se[m])


def test_the_reference_covers_the_ziggurat_tail_and_wedges():
    """300 particles x 10 steps x 3 axes x 2 normals: draws from the rare paths of the
    ziggurat (beyond r = 3.44 and in the layers' wedges) are among them, and match."""
    key, n, n_steps = 12345, 300, 10
    tails = 0
    for k in range(n_steps):
        for i in range(n):
            rs = sde_reference.Stream(key, k, i)
            tails += sum(abs(rs.normal()) > sde_reference.ZIG_R for _ in range(6))
    assert tails >= 3
    v0 = np.zeros((n, 3))
    kw = dict(model="udsbm", scheme="exact", gamma0=G0, D0=D0, tau0=TAU0, dt=0.05, n_steps=n_steps)
    pos, v, _, _ = sde_reference.engine(v0, key, **kw)
    xs, vs = sde_reference.run(v0, key, **kw)
    _assert_rounding_close(pos, xs)
    _assert_rounding_close(v, vs[-1])


def test_run_draws_from_its_seed_as_documented():
    """langevin.run: key and initial velocities from SeedSequence(seed).spawn(2), then the
    engine; particles numbered from 0 whatever the chunking (first > 0 here)."""
    r = langevin.run(
        5,
        gamma0=G0,
        D0=D0,
        dt=0.05,
        t_stop=1.0,
        scheme="em",
        sample_times=np.arange(21) * 0.05,
        store_positions=True,
        seed=42,
    )
    key_seq, vel_seq = np.random.SeedSequence(42).spawn(2)
    key = int(key_seq.generate_state(1, dtype=np.uint64)[0])
    v0 = np.random.default_rng(vel_seq).normal(scale=math.sqrt(VT), size=(5, 3))
    xs, vs = sde_reference.run(
        v0, key, model="langevin", scheme="em", gamma0=G0, D0=D0, tau0=math.inf, dt=0.05, n_steps=20
    )
    _assert_rounding_close(r.positions, xs)
    _assert_rounding_close(r.final_velocities, vs[-1])
    part, _, _, _ = sde_reference.engine(
        v0[2:4],
        key,
        model="langevin",
        scheme="em",
        gamma0=G0,
        D0=D0,
        tau0=math.inf,
        dt=0.05,
        n_steps=20,
        first=2,
        n=5,
    )
    np.testing.assert_array_equal(part, r.positions[:, 2:4])


# -- the same bits as before the inner loop was batched -------------------------------------
#
# tests/sde_bits.json: SHA-256 digests of every array of the runs in helpers/sde_bits.py,
# computed with the engine BEFORE its random numbers were drawn in batches (main at commit
# 402792d, unchanged build).  The batched engine must give the very same bits.


# the digests were recorded on x86-64 Linux: the ziggurat's tail calls the C library's exp,
# whose last bit another platform's library may round differently
RECORDED_HERE = pytest.mark.skipif(
    platform.machine() not in ("x86_64", "AMD64") or not sys.platform.startswith("linux"),
    reason="sde_bits.json was recorded on x86-64 Linux (glibc's exp in the ziggurat tail)",
)


@RECORDED_HERE
@pytest.mark.parametrize("name", sorted(sde_bits.cases()))
def test_the_same_bits_as_the_step_by_step_engine(monkeypatch, name):
    want = json.loads((Path(__file__).with_name("sde_bits.json")).read_text())
    got = sde_bits.digest(sde_bits.run_case(sde_bits.cases()[name], monkeypatch))
    assert got == want[name]


@RECORDED_HERE
@pytest.mark.parametrize("kernel", ["plain", "avx2", "avx512"])
def test_every_compilation_of_the_batched_normals_gives_the_same_bits(kernel):
    """rng.c compiles the batch of normals plain, for AVX2 and for AVX-512, and picks the
    widest the CPU runs; GRANULAR_RNG_KERNEL asks for a narrower one.  Each one this CPU
    runs gives every digest of tests/sde_bits.json (main's bits), in its own process (the
    choice is made at import)."""
    env = dict(os.environ, GRANULAR_RNG_KERNEL=kernel)
    tests = Path(__file__).resolve().parent
    script = textwrap.dedent(
        f"""
        import json, sys
        sys.path.insert(0, {str(tests)!r})
        import granular._core
        from helpers import sde_bits
        print(granular._core.RNG_KERNEL)
        print(json.dumps({{k: sde_bits.digest(sde_bits.run_case(c))
                          for k, c in sde_bits.cases().items()}}))
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    if out[0] != kernel:
        pytest.skip(f"this CPU does not run the {kernel} compilation (got {out[0]})")
    want = json.loads((tests / "sde_bits.json").read_text())
    assert json.loads(out[1]) == want


def test_the_engine_takes_its_arguments_by_name():
    """_core.sde_run takes every argument by name (23 numbers and arrays, many of one
    type: gamma0 and D0 swapped would run unseen): a positional call, a misspelt or a
    missing name is a TypeError naming it."""
    args = sde_reference.one_step_args(model=0, gamma0=G0, D0=D0, tau0=math.inf)
    v = args["v"]
    _core.sde_run(**args)
    assert np.all(np.isfinite(v)) and np.any(v != 0)
    with pytest.raises(TypeError, match="positional"):
        _core.sde_run(*args.values())
    with pytest.raises(TypeError, match="gamma"):
        _core.sde_run(**{("gamma" if k == "gamma0" else k): a for k, a in args.items()})
    with pytest.raises(TypeError, match="missing required keyword argument 'D0'"):
        _core.sde_run(**{k: a for k, a in args.items() if k != "D0"})
