"""The reproduction's driven-gas experiment: the velocity distribution of a granular gas,
freely cooling and heated by random kicks (``granular.WhiteNoise``), against the first
Sonine approximation (``granular.theory.sonine``).

Every part is 3D, at packing fraction ``ETA`` = 0.03 in a periodic box of N = 1000 (full)
or 300 (quick) spheres, well below the critical size of the shear instability at every xi
used (``theory.critical_box_size``: N_c = 8400 at xi = 0.5), started from a Maxwellian at
T = 1 (positions by random sequential addition; each run its own seed).

- **hcs.a2** (xi = 0.9, 0.8, 0.5): the homogeneous cooling state's a2, sampled at every
  collision per particle from 10 (after the initial Maxwellian has relaxed: a2 settles in a
  few collisions per particle) to 40, per run; the rows' error is the standard error over
  runs.  Theory: van Noije & Ernst (1998)'s first-order a2; the quantity text gives the
  nonlinear root of the same truncation beside it, the spread of the first order itself.
- **driven.temperature**, **driven.a2** (xi = 0.8, 0.5): white noise of strength xi0^2 set so
  that the theory's steady temperature is 1, kicks at ``KICK_FACTOR`` = 50 times
  m xi0^2 / T per particle (one kick's velocity variance 1/50 of T/m), run for
  ``SETTLE`` collision times to reach the steady state, then sampled every collision time
  for ``window`` of them; T over d (N - 1) degrees of freedom (the total momentum is kept
  at 0).  Theory: ``driven_temperature`` and ``sonine_a2_driven`` with the kicks' finite
  size (``kick`` = 1/50: it shifts a2 by +0.004 at xi = 0.8, half of a2 itself; the white
  noise limit is in the quantity text).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .. import Scene, Simulation, WhiteNoise, moments, theory

ETA = 0.03  # packing fraction: N = 1000 lies below the critical box size at xi >= 0.5
RADIUS = 0.5  # a unit diameter; the box follows from N and ETA
XI_HCS = (0.9, 0.8, 0.5)
XI_DRIVEN = (0.8, 0.5)
CPP_FROM, CPP_TO = 10, 40  # the cooling state's samples, in collisions per particle
KICK_FACTOR = 50.0  # kicks per particle per unit time, in units of m xi0^2 / T
SETTLE = 15.0  # collision times before the driven gas is sampled
EDGES = np.linspace(0.0, 4.5, 46)  # bins of the scaled speed c for the tails


def _speed_counts(v):
    """Counts of c = |v| / v0 in EDGES, each sample (S, N, 3) scaled by its own v0."""
    w = v - v.mean(axis=1, keepdims=True)
    s2 = np.einsum("snd,snd->sn", w, w)
    c = np.sqrt(s2 / (2.0 * s2.mean(axis=1, keepdims=True) / 3))
    return np.histogram(c, bins=EDGES)[0].astype(np.float64)


def _n(cfg):
    return 300 if cfg.quick else 1000


def _scene(n, xi, seed, driving=None):
    side = (n * 4.0 / 3.0 * math.pi * RADIUS**3 / ETA) ** (1.0 / 3.0)
    s = Scene.random(n, RADIUS, dim=3, box=side, restitution=xi, temperature=1.0, seed=seed)
    return s if driving is None else s.replace(driving=driving)


def _density(n):
    return ETA / (4.0 / 3.0 * math.pi * RADIUS**3)


def hcs_task(n, xi, *, seed):
    """a2 of one cooling run over collisions per particle CPP_FROM..CPP_TO, and its
    velocities at CPP_TO (for the tail)."""
    sim = Simulation(_scene(n, xi, seed))
    samples = []
    for cpp in range(CPP_FROM, CPP_TO + 1):
        sim.run(stop_when={"collisions_per_particle": cpp}, store=())
        samples.append(sim.scene.velocities)
    v = np.array(samples)
    # the gas cools between samples: each scaled to its own temperature
    return {"a2": np.float64(moments.sonine_a2(v, each_sample=True)), "c": _speed_counts(v)}


def driven_parameters(n, xi):
    """(strength, rate, kick): white noise whose theory steady T is 1 (white-noise a2, then
    the finite-kick one: two fixed-point steps, converged to 1e-6), and its kick size."""
    density = _density(n)
    kw = dict(density=density, radius=RADIUS, restitution=xi, dim=3)
    kick = 1.0 / KICK_FACTOR
    # T = [d m xi0^2 / (...)]^(2/3): xi0^2 for T = 1 is zeta(T=1) with the a2 factor
    a2 = theory.sonine_a2_driven(restitution=xi, dim=3, kick=kick)
    strength = theory.cooling_rate(temperature=1.0, **kw) * (1 + 3 * a2 / 16)
    return strength, KICK_FACTOR * strength, kick


def driven_task(n, xi, *, window, seed):
    """Steady temperature and a2 of one driven run, and its last velocities."""
    strength, rate, _ = driven_parameters(n, xi)
    # the kicks' own seed, an integer below 2^53, from the run's SeedSequence
    drv = WhiteNoise(strength, rate, seed=int(seed.generate_state(1, np.uint64)[0] >> 11))
    sim = Simulation(_scene(n, xi, seed, drv))
    tau = 1.0 / theory.collision_frequency(
        density=_density(n), radius=RADIUS, temperature=1.0, dim=3
    )
    t0 = SETTLE * tau
    times = t0 + tau * np.arange(0, window + 1)
    tr = sim.run(t_stop=times[-1], sample_times=times, store=("velocities",))
    temps = 2.0 * tr.kinetic_energy / (3 * (n - 1))
    return {
        "temperature": np.float64(temps.mean()),
        "a2": np.float64(moments.sonine_a2(tr.velocities)),
        "c": _speed_counts(tr.velocities),
        "power": np.float64(sim.stats["drive_energy"] / sim.time / n),
    }


def _fig_driven(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run the parts, write ``driven_a2.png``, return (file names, rows)."""
    n = _n(cfg)
    runs = cfg.runs_few if not cfg.quick else 20
    window = 200 if not cfg.quick else 60
    rows = []
    hcs, driven = {}, {}
    for xi in XI_HCS:
        res = ensemble(functools.partial(hcs_task, n, xi), runs, seed=28)
        hcs[xi] = res.runs
        a2 = [r["a2"] for r in res.runs]
        lin = theory.sonine_a2_cooling(restitution=xi)
        nonlin = theory.sonine_a2_cooling(restitution=xi, approximation="nonlinear")
        rows.append(
            mean_row(
                f"hcs.a2.xi{xi}",
                f"cooling state's a2 at xi = {xi} (3D, N = {n}, eta = {ETA}, collisions "
                f"{CPP_FROM}-{CPP_TO} per particle); theory: van Noije & Ernst's first order "
                f"(nonlinear root {nonlin:.4f})",
                a2,
                theory_value=lin,
            )
        )
    for xi in XI_DRIVEN:
        res = ensemble(functools.partial(driven_task, n, xi, window=window), runs, seed=29)
        driven[xi] = res.runs
        strength, rate, kick = driven_parameters(n, xi)
        kw = dict(density=_density(n), radius=RADIUS, restitution=xi, dim=3)
        rows.append(
            mean_row(
                f"driven.temperature.xi{xi}",
                f"steady temperature under white noise xi0^2 = {strength:.4g} at xi = {xi} "
                f"(3D, N = {n}, eta = {ETA}, {rate:.3g} kicks per particle and time); "
                "theory: heating = Enskog cooling with the a2 correction",
                [r["temperature"] for r in res.runs],
                theory_value=theory.driven_temperature(strength=strength, kick=kick, **kw),
            )
        )
        white = theory.sonine_a2_driven(restitution=xi)
        rows.append(
            mean_row(
                f"driven.a2.xi{xi}",
                f"driven steady state's a2 at xi = {xi}, kicks of variance {kick:g} T/m; "
                f"theory: first order with that kick size (white-noise limit {white:.4f})",
                [r["a2"] for r in res.runs],
                theory_value=theory.sonine_a2_driven(restitution=xi, kick=kick),
            )
        )
    return [_figure(hcs, driven, rows, save, fig, out)], rows


def _figure(hcs, driven, rows, save, fig, out):
    f, (ax1, ax2) = fig(ncols=2)
    xi = np.linspace(0.3, 1.0, 141)
    ax1.plot(xi, theory.sonine_a2_cooling(restitution=xi), "C0-", label="cooling: first order")
    ax1.plot(
        xi,
        theory.sonine_a2_cooling(restitution=xi, approximation="nonlinear"),
        "C0:",
        label="cooling: nonlinear root",
    )
    ax1.plot(xi, theory.sonine_a2_driven(restitution=xi), "C1-", label="white noise")
    kick = 1.0 / KICK_FACTOR
    ax1.plot(
        xi,
        theory.sonine_a2_driven(restitution=xi, kick=kick),
        "C1--",
        label=f"kicks of variance {kick:g} T/m",
    )
    by_id = {r["id"]: r for r in rows}
    for key, colour, label in (("hcs", "C0", "cooling (EDMD)"), ("driven", "C1", "driven (EDMD)")):
        pts = [(float(i.rsplit("xi", 1)[1]), r) for i, r in by_id.items()
               if i.startswith(f"{key}.a2.")]  # fmt: skip
        ax1.errorbar(
            [p[0] for p in pts],
            [p[1]["ours"] for p in pts],
            yerr=[p[1]["ours_error"] for p in pts],
            fmt="o",
            color=colour,
            mfc="none",
            label=label,
        )
    ax1.axhline(0.0, color="0.6", lw=0.8)
    ax1.set_xlabel(r"restitution $\xi$")
    ax1.set_ylabel(r"second Sonine coefficient $a_2$")
    ax1.set_title("3D, packing fraction 0.03")
    ax1.legend(fontsize="x-small")
    mid = 0.5 * (EDGES[1:] + EDGES[:-1])
    # the Maxwellian's share of each bin, from its distribution function in 3D
    cdf = [math.erf(x) - 2.0 / math.sqrt(math.pi) * x * math.exp(-(x**2)) for x in EDGES]
    maxwell = np.diff(cdf)
    x = mid**2
    sonine = 0.5 * x**2 - 2.5 * x + 15.0 / 8.0  # S2(c^2) in 3D
    theories = (
        theory.sonine_a2_cooling(restitution=0.5),
        theory.sonine_a2_driven(restitution=0.5, kick=1.0 / KICK_FACTOR),
    )
    for k, (states, name) in enumerate(((hcs, "cooling"), (driven, "driven"))):
        counts = np.sum([r["c"] for r in states[0.5]], axis=0)
        keep = counts >= 10  # Poisson error at most a third
        ratio = counts / counts.sum() / maxwell
        ax2.errorbar(
            mid[keep],
            ratio[keep],
            yerr=ratio[keep] / np.sqrt(counts[keep]),
            fmt="o-" if k == 0 else "s-",
            ms=3,
            color=f"C{k}",
            label=rf"{name}, $\xi$ = 0.5",
        )
        ax2.plot(mid, 1.0 + theories[k] * sonine, ":", color=f"C{k}",
                 label=rf"$1 + a_2 S_2(c^2)$, {name} (first order)")  # fmt: skip
    ax2.set_yscale("log")
    ax2.axhline(1.0, color="0.4", lw=0.8, label="Maxwellian")
    ax2.set_xlabel(r"scaled speed $c = v / v_0$, $v_0^2 = 2T/m$")
    ax2.set_ylabel("density of c over the Maxwellian's (counts >= 10)")
    ax2.set_title("overpopulated high-energy tails")
    ax2.legend(fontsize="x-small")
    return save(f, out, "driven_a2.png")


def hcs_notes(by_id):
    """Sentences for report.md's cooling-state section, conditional on the rows."""
    text = [
        "a2 is the fourth cumulant of the velocity distribution (driven_a2.png); the first "
        "Sonine order (van Noije & Ernst 1998) neglects a3 and beyond, which Brilliantov & "
        "Poeschel (2006) find as large as a2 below xi of about 0.6 (docs/driven.md)."
    ]
    row = by_id.get("hcs.a2.xi0.5")
    if row is not None and row["ours_error"]:
        z = (row["ours"] - row["theory"]) / row["ours_error"]
        text.append(
            f"At xi = 0.5 ours lies {z:+.1f} standard errors from the first order "
            f"({row['ours'] / row['theory'] - 1:+.0%})."
        )
    return text


def driven_notes(by_id):
    """Sentences for report.md's driven-gas section, conditional on the rows."""
    text = [
        "The heating is exact for kicks of any size (d m xi0^2 / 2 per particle and time), "
        "so the temperature tests the collisional cooling; kicks of finite size change a2, "
        "by an amount comparable to a2 itself at xi = 0.8 for kicks of variance T/50m, "
        "which the theory rows include (the fourth Kramers-Moyal term)."
    ]
    return text
