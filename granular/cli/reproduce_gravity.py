"""The reproduction's gravity experiment: an elastic gas of hard disks in a tall box under
gravity against its hydrostatic profile (``theory.hydrostatic_density``: dP/dz = -n m g
with granular's own equation of state, Henderson's in 2D).

Each run: N = 400 disks (r = 0.01) in a walled box 1 wide and 2 high, g = 2 down, placed
uniformly at random with speed sqrt(2) and let fall; the fall heats the gas to T ~ 1.6,
a scale height l = T / (m g) ~ 0.8 = 40 diameters, and the floor's area fraction ~0.13
(Henderson's Z ~ 1.3 there: the profile is measurably not barometric).  After
``EQUILIBRATE`` time units (several sound crossings of the column, many collisions per
particle) the profile is sampled every 0.1 for ``MEASURE`` time units.  It is measured
away from the walls (``PAD`` = 3 diameters from the floor, ceiling and side walls), where
the hard walls' layering does not reach and the local-density approximation holds, and
the theory is normalised to the mean number of centres in that window and evaluated at
the run's mean kinetic temperature (uniform in equilibrium: checked by
tests/test_gravity_profile.py).

The row ``gravity.profile.elastic`` is, per run, the mean height of the centres in the
window over the theory's (bin-averaged), against 1: a scalar that a wrong equation of
state, a wrong temperature or a wrong flight would move (the barometric, ideal-gas
profile at the same count gives 0.90 of it here).

The same runs keep the stress tensor (``Simulation(stress=True)``, docs/stress.md "Under
gravity"): the rows ``gravity.stress.pressure``, per run trace(P) / d over the mean over the
centres' column of the local pressure n T Z of the bulk's hydrostatic profile
(``bulk_mean_pressure``: the profile whose count in the window is the run's, extended to the
walls), against 1, and ``gravity.stress.anisotropy``, (P_xx - P_yy) / (trace(P) / d), against
0: the column's volume-averaged stress is the local pressure's mean, isotropic.

The figure shows the profile pooled over the runs with its error bars, the theory and the
barometric curve, and the residuals in units of their errors with their chi^2.
"""

from __future__ import annotations

import math

import numpy as np

from .. import Scene, Simulation, analysis, theory
from ..errors import InelasticCollapseError

WIDTH, HEIGHT, RADIUS, G, N = 1.0, 2.0, 0.01, 2.0, 400
PAD = 6 * RADIUS  # three diameters
BINS = 20
EQUILIBRATE, MEASURE = 20.0, 20.0


def column(seed: int, *, equilibrate: float = EQUILIBRATE, measure: float = MEASURE) -> dict:
    """One run of the column: its profile (``analysis.profile`` in the window, 10 blocks),
    the theory's bin averages at its count and temperature, and the barometric ones."""
    box = (np.zeros(2), np.array([WIDTH, HEIGHT]))
    s = Scene.random(N, RADIUS, dim=2, box=box, boundary="walls", seed=seed)
    # the stress tensor changes no event: the same runs give the profile and the tensor
    sim = Simulation(s.replace(gravity=(0.0, -G)), stress=True)
    sim.run(t_stop=equilibrate, store=())
    times = np.linspace(equilibrate, equilibrate + measure, round(measure / 0.1) + 1)
    tr = sim.run(t_stop=times[-1], sample_times=times, store=("positions", "velocities"))
    temperature = float(np.mean(tr.temperature))
    bottom, top = PAD, HEIGHT - PAD
    edges = np.linspace(bottom, top, BINS + 1)
    prof = analysis.profile(tr, bins=edges, within=([PAD, 0.0], [WIDTH - PAD, HEIGHT]), blocks=10)
    count = float(prof.count.sum())
    area = WIDTH - 2 * PAD
    fine = np.linspace(bottom, top, 20 * BINS + 1)  # 20 intervals a bin: Simpson's rule
    n_fine = np.asarray(
        theory.hydrostatic_density(
            fine, n=count, area=area, bottom=bottom, top=top, radius=RADIUS, gravity=G,
            temperature=temperature, dim=2,
        )
    )  # fmt: skip
    w = np.ones(21)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    w /= w.sum()
    bin_mean = np.array([np.sum(w * n_fine[20 * k : 20 * k + 21]) for k in range(BINS)])
    scale = temperature / G
    # the barometric profile exp(-z / l) with the same count, averaged over each bin
    share = np.exp(-(edges[:-1] - bottom) / scale) - np.exp(-(edges[1:] - bottom) / scale)
    baro = count / area * share / (np.diff(edges) * np.sum(share))
    tensor = tr.pressure_tensor()
    # the temperature of the tensor's own kinetic integral (exact, not from the samples)
    k = tr.kinetic_time_tensor
    assert k is not None  # (stress=True)
    kinetic = np.trace(k[-1] - k[0])
    exact_t = float(kinetic / (2 * N * (times[-1] - times[0])))
    return dict(
        profile=prof,
        theory=bin_mean,
        barometric=baro,
        temperature=temperature,
        count=count,
        collisions=sim.stats["pair_collisions"],
        pressure_tensor=tensor,
        bulk_pressure=bulk_mean_pressure(exact_t, count),
    )


def bulk_mean_pressure(temperature: float, count: float) -> float:
    """The mean over the centres' column [r, HEIGHT - r] of the local pressure n T Z(eta)
    (Henderson's Z) of the hydrostatic profile ``theory.hydrostatic_density`` whose count of
    centres in the window (``PAD`` from every wall) is ``count``: the bulk's profile, extended
    to the walls.  Not the profile of all N: the hard walls adsorb (their contact density is
    P / T), ~4 of the 400 disks beyond what the profile puts there, and all N in it
    overestimate the bulk density by ~1 % and the pair part of the pressure by ~3 %."""
    z = np.linspace(RADIUS, HEIGHT - RADIUS, 4001)
    bulk = (z >= PAD) & (z <= HEIGHT - PAD)

    def profile(n_total):
        return np.asarray(
            theory.hydrostatic_density(
                z, n=n_total, area=WIDTH - 2 * RADIUS, bottom=RADIUS, top=HEIGHT - RADIUS,
                radius=RADIUS, gravity=G, temperature=temperature, dim=2,
            )
        )  # fmt: skip

    def excess(n_total):
        return np.trapezoid(profile(n_total)[bulk], z[bulk]) * (WIDTH - 2 * PAD) - count

    a, b = 0.97 * N, 0.99 * N  # the secant on the total (the count grows with it)
    fa, fb = excess(a), excess(b)
    for _ in range(30):
        a, fa, b = b, fb, b - fb * (b - a) / (fb - fa)
        fb = excess(b)
        if abs(fb) <= 1e-10 * count:
            break
    n = profile(b)
    p = n * temperature * theory.compressibility_factor(n * math.pi * RADIUS**2, dim=2)
    return float(np.trapezoid(p, z) / (HEIGHT - 2 * RADIUS))


def mean_height(centres: np.ndarray, density: np.ndarray) -> float:
    """The mean height of a profile given in bins of equal width."""
    return float(np.sum(centres * density) / np.sum(density))


def _fig_gravity(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run the columns, write ``gravity_profile.png``, return (file names, rows)."""
    runs = 10 if cfg.quick else 20
    kw = dict(equilibrate=10.0, measure=10.0) if cfg.quick else {}
    results = [column(seed, **kw) for seed in range(runs)]
    c = results[0]["profile"].centres
    ratios = [mean_height(c, r["profile"].density) / mean_height(c, r["theory"]) for r in results]
    baro = float(
        np.mean([mean_height(c, r["barometric"]) / mean_height(c, r["theory"]) for r in results])
    )
    # the profile pooled over the runs: each run's mean profile, their mean and standard error
    dens = np.array([r["profile"].density for r in results])
    th = np.mean([r["theory"] for r in results], axis=0)
    bar = np.mean([r["barometric"] for r in results], axis=0)
    mean, err = dens.mean(0), dens.std(0, ddof=1) / math.sqrt(runs)
    z = (mean - th) / err
    chi2 = float(np.sum(z**2))
    temperature = float(np.mean([r["temperature"] for r in results]))
    eta0 = float(th[0]) * math.pi * RADIUS**2
    rows = [
        mean_row(
            "gravity.profile.elastic",
            f"mean height of the centres over the hydrostatic theory's (EDMD, 2D, N = {N} "
            f"disks r = {RADIUS} in a {WIDTH:g} x {HEIGHT:g} box, g = {G:g}, T = "
            f"{temperature:.3f}, scale height T/mg = {temperature / G / (2 * RADIUS):.0f} "
            f"diameters, area fraction {eta0:.3f} at the bottom of the window; the window 3 "
            f"diameters from every wall); theory: dP/dz = -n m g with Henderson's equation of "
            f"state (theory.hydrostatic_density), 1; the barometric (ideal-gas) profile gives "
            f"{baro:.4f}; the pooled profile's chi^2 against the theory is {chi2:.1f} for "
            f"{BINS} bins",
            ratios,
            None,
            1.0,
        ),
        mean_row(
            "gravity.stress.pressure",
            "trace(P) / d of the column's stress tensor (kinetic + pair collisions, "
            "Simulation(stress=True): exact integrals through the parabolic flights) over the "
            "mean over the column of the local pressure n T Z of the bulk's hydrostatic "
            "profile (Henderson's equation of state; the profile's count that of the window 3 "
            "diameters from every wall, T the tensor's kinetic temperature); theory: 1",
            [np.trace(r["pressure_tensor"]) / 2 / r["bulk_pressure"] for r in results],
            None,
            1.0,
        ),
        mean_row(
            "gravity.stress.anisotropy",
            "(P_xx - P_yy) / (trace(P) / d) of the same columns' stress tensor; theory: 0 "
            "(the local pressure is isotropic; the walls' layers add O(sigma / L) of the pair "
            "part, below the error)",
            [
                (r["pressure_tensor"][0, 0] - r["pressure_tensor"][1, 1])
                / (np.trace(r["pressure_tensor"]) / 2)
                for r in results
            ],
            None,
            0.0,
        ),
    ]
    f, (ax, ax2) = fig(2)
    ax.errorbar(c, mean, err, fmt="o", ms=3, label=f"EDMD, {runs} runs")
    ax.plot(c, th, "-", label="hydrostatic, Henderson EOS")
    ax.plot(c, bar, ":", label="barometric (ideal gas)")
    ax.set_yscale("log")
    ax.set_xlabel("height z")
    ax.set_ylabel("number density n(z)")
    ax.legend(fontsize=8)
    ax.set_title("elastic disks under gravity")
    ax2.axhline(0.0, color="0.6")
    ax2.plot(c, z, "o", ms=4, label="hydrostatic theory")
    ax2.plot(c, (mean - bar) / err, "x", ms=4, label="barometric (most off the scale)")
    ax2.set_xlabel("height z")
    ax2.set_ylabel("(ours - theory) / error")
    ax2.set_ylim(-12, 12)
    ax2.legend(fontsize=8)
    ax2.set_title(f"residuals: chi^2 = {chi2:.1f} for {BINS} bins")
    names = [save(f, out, "gravity_profile.png")]
    return names, rows


def notes(by_id):
    """Sentences for report.md's gravity section."""
    return [
        "The theory is the local-density approximation of equilibrium statistical mechanics "
        "with granular's own equation of state; it is measured away from the walls, where "
        "hard walls layer the gas, and normalised to the count there (reproduce_gravity).  "
        "The quantity text gives the barometric profile's value: the ideal gas is far off, "
        "so the row resolves the hard cores' pressure.",
        "The stress rows are the same columns' volume-averaged stress tensor (kinetic plus "
        "pair collisions, integrated exactly through the parabolic flights): its trace against "
        "the bulk's hydrostatic profile's mean pressure (the profile fixed by the count away "
        "from the walls, which adsorb), and its anisotropy, which the walls' tension moves by "
        "less than the error (docs/stress.md, 'Under gravity').",
    ]


BED_XIS = (0.9, 0.7, 0.5, 0.3)
BED_TCS = (0.0, 1e-5, 1e-4, 1e-3)


def bed_map(
    xis=BED_XIS,
    contact_durations=BED_TCS,
    t_stop=1.0,
    events_per_particle=10_000,
    n=200,
    floor=None,
):
    """Where an inelastic bed resting on its floor collapses: 2D disks (r = 0.01) dropped
    in a walled box 0.3 wide and 1 high under g = 10 (they settle within t ~ 0.5), pairs
    and floor of restitution xi, with the TC model's t_c; each run to ``t_stop`` within a
    budget of ``events_per_particle`` events a particle.  Each cell: 'collapse' (with its
    time), 'budget' (the rattling bed's events ran out first: the time reached), or 'ok';
    and the events per particle per unit time over the run's last tenth.  ``floor``: a
    ``VibratingWall`` on the lower face of axis 1 (the particles start above its sweep),
    its restitution xi too; None: a fixed floor."""
    cells = []
    box = (np.zeros(2), np.array([0.3, 1.0]))
    above = (np.array([0.0, 2 * floor.amplitude]), box[1]) if floor is not None else box
    for tc in contact_durations:
        for xi in xis:
            s = Scene.random(
                n, 0.01, dim=2, box=above, boundary="walls", restitution=xi,
                wall_restitution=xi, contact_duration=tc, seed=4,
            ).replace(gravity=(0.0, -10.0))  # fmt: skip
            if floor is not None:
                s = s.replace(box=box, vibrating_wall=floor)
            sim = Simulation(s)
            cell = dict(xi=xi, contact_duration=tc)
            budget = events_per_particle * n
            try:
                sim.run(t_stop=0.9 * t_stop, stop_when={"events": budget}, store=())
                e0, t0 = sim.stats["events"], sim.time
                tr = sim.run(t_stop=t_stop, stop_when={"events": budget - e0}, store=())
                status = "budget" if tr.stop_reason == "events" else "ok"
                rate = (sim.stats["events"] - e0) / (n * max(sim.time - t0, 1e-300))
                cell.update(status=status, time=sim.time, events_per_particle_time=rate)
            except InelasticCollapseError as exc:
                cell.update(status="collapse", time=exc.time)
            cell.update(tc_elastic=sim.stats["tc_elastic_collisions"], events=sim.stats["events"])
            cells.append(cell)
    return cells


def bed_map_figure(cells, path, title=None):
    """The map as a grid of coloured cells, xi across, t_c down, each labelled (``title``:
    the default names the fixed floor)."""
    import matplotlib.pyplot as plt

    xis = sorted({c["xi"] for c in cells}, reverse=True)
    tcs = sorted({c["contact_duration"] for c in cells})
    colour = {"collapse": "#d62728", "budget": "#ff7f0e", "ok": "#2ca02c"}
    fig, ax = plt.subplots(figsize=(6.0, 3.6), layout="constrained")
    for c in cells:
        x, y = xis.index(c["xi"]), tcs.index(c["contact_duration"])
        ax.add_patch(plt.Rectangle((x - 0.5, y - 0.5), 1, 1, color=colour[c["status"]], alpha=0.6))
        text = {
            "collapse": f"collapse\nt = {c['time']:.3f}",
            "budget": f"budget\nt = {c['time']:.2f}",
            "ok": f"ok\n{c.get('events_per_particle_time', 0):.2g} ev/(N t)",
        }[c["status"]]
        ax.text(x, y, text, ha="center", va="center", fontsize=8)
    ax.set_xlim(-0.5, len(xis) - 0.5)
    ax.set_ylim(-0.5, len(tcs) - 0.5)
    ax.set_xticks(range(len(xis)), [f"{x:g}" for x in xis])
    ax.set_yticks(range(len(tcs)), ["off" if t == 0 else f"{t:g}" for t in tcs])
    ax.set_xlabel("restitution xi (pairs and floor)")
    ax.set_ylabel("TC model t_c")
    ax.set_title(title or "a bed settling on an inelastic floor (g = 10, N = 200, to t = 1)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
