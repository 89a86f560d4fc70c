"""The reproduction's vibrated experiments: a gas kept hot by a vibrating wall
(``granular.VibratingWall``), against ``granular.theory.vibrated``.

Registered (``"vibrated"`` in ``reproduce.FIGURES``):

- **A granular gas between a vibrating and a fixed wall**, no gravity.  2D, N = 200 disks of
  radius 0.01 in the unit box (area fraction 0.063), xi = 0.99, elastic walls, the lower wall a
  sine of angular frequency ``OMEGA`` = 250 and amplitude A = 0.001, 0.002, 0.004 (peak
  speeds V = 0.25, 0.5, 1; A far below the mean free path, ~0.09).  Each of ``RUNS`` runs
  settles for 300 collisions per particle (quick: 150), then the time-averaged kinetic
  energy over 1500 (quick: 250) gives its temperature T = <E> / N (2D); the rows
  give T at each V (mean and standard error over runs) against ``theory.vibrated_temperature``
  (the balance of the wall's input with Haff's loss for a uniform gas: an estimate, the gas
  being hotter and thinner at the vibrating wall), and the exponent alpha of T ~ V^alpha
  (a weighted least-squares fit of ln T on ln V) against the dilute theory's 2 (Kumaran
  1998; McNamara & Luding 1998's dilute simulations).  Varying A at fixed omega is not a
  rescaling of time (which would give exactly 2: hard spheres have no time scale of their
  own), so the exponent tests the small-amplitude theory.  One more row: the wall's mean
  power over the collisions' loss in the steady state (1 by energy conservation, measured).

- **A bed on a vibrating floor under gravity** (``temperature_scaling_under_gravity``, the
  row ``vibrated.temperature_scaling``).  The same disks, xi and omega in a walled box 1
  wide and ``BED_HEIGHT`` = 40 high under g = ``BED_G`` = 1.5, the floor a sine of A = 0.002,
  0.0028, 0.004 (V = 0.5, 0.71, 1), ``RUNS`` runs each, the same lengths.  The rows: T at
  each V against ``theory.vibrated_bed_temperature`` (the dilute isothermal barometric
  balance: gravity drops out, T ~ V^2, an estimate), the exponent alpha against the dilute
  theory's 2 (Kumaran 1998; McNamara & Luding 1998 simulated it), with Warr, Huntley &
  Jacques' (1995) experimental 1.41 +- 0.11 for a dense bed in report.md's notes, and the
  floor's work over the collisions' loss (1).  The bed is dilute at its floor (area
  fraction 0.035 to 0.009, scale heights 1.8 to 7.1) and the floor elastic: nothing
  collapses, so no TC model (``contact_duration``) is needed; a dense bed on an inelastic
  floor would need it (docs/gravity.md's bed map).
"""

from __future__ import annotations

import math

import numpy as np

from .. import Scene, Simulation, VibratingWall, theory

N, RADIUS, XI = 200, 0.01, 0.99
OMEGA = 250.0
AMPLITUDES = (0.001, 0.002, 0.004)
RUNS = 10  # per amplitude (the reproduction's rows want >= 10 for Student-t error bars)
# the bed under gravity: the same disks, xi and omega on the floor of a walled box 1 wide and
# BED_HEIGHT high; V over a factor 2 (T over 4).  The scale height T / g runs from 1.8 to 7.1:
# the ceiling at 5.6 of them would hold exp(-5.6) of the column above it (T lowered by < 1 %),
# and the floor's area fraction, (N pi r^2 / width) / (T / g), runs from 0.035 to 0.009:
# dilute, the theory's limit (at g = 3 the lowest V's floor, at 0.07, is measurably hotter)
BED_G, BED_HEIGHT = 1.5, 40.0
BED_AMPLITUDES = (0.002, 0.002 * math.sqrt(2.0), 0.004)


def _lengths(quick):
    """Collisions per particle to settle, then to measure over."""
    return (150, 250) if quick else (300, 1500)


def _balance(peak_velocity):
    """theory.vibrated_temperature of the experiment's gas (the centres' reach for n)."""
    return theory.vibrated_temperature(
        peak_velocity, density=N / (1 - 2 * RADIUS) ** 2, radius=RADIUS, restitution=XI,
        wall_distance=1.0, dim=2,
    )  # fmt: skip


def _steady(amplitude, seed, quick):
    """One run: (temperature T = <E>/N, its time average, the wall's mean power over the
    collisions' mean loss) in the steady state."""
    a = amplitude
    wall = VibratingWall(1, "lower", a, OMEGA)
    # started near the balance's temperature: the gas relaxes in ~1 / (1 - xi^2) = 50
    # collisions per particle, well within the settling (quick: 150)
    start = Scene.random(
        N, RADIUS, dim=2, box=((0.0, 2 * a), (1.0, 1.0)), boundary="walls",
        temperature=_balance(a * OMEGA), seed=seed,
    )  # fmt: skip
    scene = start.replace(box=1.0, vibrating_wall=wall, restitution=XI)
    sim = Simulation(scene)
    settle, measure = _lengths(quick)
    sim.run(stop_when={"collisions_per_particle": settle}, store=())
    before, t0 = sim.stats, sim.time
    goal = before["collisions_per_particle"] + measure
    sim.run(stop_when={"collisions_per_particle": goal}, store=())
    after = sim.stats
    dt = sim.time - t0
    energy = (after["kinetic_time_integral"] - before["kinetic_time_integral"]) / dt
    work = after["wall_work"] - before["wall_work"]
    loss = after["collision_loss"] - before["collision_loss"]
    return energy / N, work / loss


def _fig_vibrated(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run the registered experiment, write ``vibrated_temperature.png``, return (file
    names, rows)."""
    runs = RUNS
    velocities = np.array([a * OMEGA for a in AMPLITUDES])
    t_list: list[float] = []
    e_list: list[float] = []
    balance: list[float] = []
    rows = []
    for k, a in enumerate(AMPLITUDES):
        results = [_steady(a, 100 * k + s, cfg.quick) for s in range(runs)]
        T = np.array([r[0] for r in results])
        t_list.append(float(T.mean()))
        e_list.append(float(T.std(ddof=1) / math.sqrt(runs)))
        balance.extend(r[1] for r in results)
        V = a * OMEGA
        predicted = _balance(V)
        rows.append(
            mean_row(
                f"vibrated.temperature.V={V:g}",
                f"steady T of 200 disks (r = 0.01, xi = 0.99) between a sine wall (A = {a:g}, "
                f"omega = {OMEGA:g}) and a fixed one, no gravity; theory: the uniform-gas "
                "energy balance (theory.vibrated_temperature, an estimate)",
                T,
                theory_value=predicted,
            )
        )
    temps, errs = np.array(t_list), np.array(e_list)
    # weighted least squares of ln T on ln V (sigma of ln T = err / T)
    x, y, w = np.log(velocities), np.log(temps), (temps / errs) ** 2
    xm = np.sum(w * x) / np.sum(w)
    slope = np.sum(w * (x - xm) * (y - np.sum(w * y) / np.sum(w))) / np.sum(w * (x - xm) ** 2)
    slope_err = 1.0 / math.sqrt(np.sum(w * (x - xm) ** 2))
    rows.append(
        row(
            "vibrated.temperature_exponent",
            "alpha of T ~ V^alpha, V = A omega varied through A at fixed omega (no gravity); "
            "theory: the dilute limit 2 (Kumaran 1998; McNamara & Luding 1998); Warr, Huntley "
            "& Jacques 1995 measured 1.41 +- 0.11 in a dense 2D bed under gravity",
            slope,
            slope_err,
            runs,
            theory_value=theory.DILUTE_EXPONENT,
        )
    )
    rows.append(
        mean_row(
            "vibrated.power_balance",
            "the vibrating wall's work over the collisions' loss in the steady state "
            "(Simulation.stats wall_work / collision_loss); 1 in a steady state",
            np.array(balance),
            theory_value=1.0,
        )
    )

    bed_v, bed_t, bed_balance, alpha, alpha_err = temperature_scaling_under_gravity(cfg.quick, runs)
    for V, T in zip(bed_v, bed_t, strict=True):
        rows.append(
            mean_row(
                f"vibrated.bed.temperature.V={V:.3g}",
                f"steady T of a bed of 200 disks (r = 0.01, xi = 0.99) on a sine floor "
                f"(V = {V:.3g}, omega = {OMEGA:g}) under g = {BED_G:g}; theory: the dilute "
                "isothermal barometric balance (theory.vibrated_bed_temperature, an estimate)",
                T,
                theory_value=_bed_estimate(V),
            )
        )
    rows.append(
        row(
            "vibrated.temperature_scaling",
            "alpha of T ~ V^alpha of the bed on a vibrating floor under gravity (V through A at "
            "fixed omega; scale height 1.8-7.1, floor area fraction 0.035-0.009); theory: the "
            "dilute limit 2 (Kumaran 1998; McNamara & Luding 1998 simulated it); Warr, "
            "Huntley & Jacques 1995 measured 1.41 +- 0.11 in a dense bed",
            alpha,
            alpha_err,
            runs,
            theory_value=theory.DILUTE_EXPONENT,
        )
    )
    rows.append(
        mean_row(
            "vibrated.bed.power_balance",
            "the floor's work over the collisions' loss of the bed under gravity in the steady "
            "state (potential energy included in the books: a steady state's is constant); 1",
            bed_balance.ravel(),
            theory_value=1.0,
        )
    )

    f, ax = fig()
    bed_mean = bed_t.mean(axis=1)
    bed_err = bed_t.std(axis=1, ddof=1) / math.sqrt(runs)
    ax.errorbar(bed_v, bed_mean, yerr=bed_err, fmt="s", color="C1", label="bed under gravity")
    ax.plot(
        bed_v, [_bed_estimate(v) for v in bed_v], "--", color="C1",
        label="dilute barometric balance (bed)",
    )  # fmt: skip
    lo, hi = bed_v[0], bed_v[-1]
    warr = theory.WARR_HUNTLEY_JACQUES_EXPONENT[0]
    ax.plot(
        [lo, hi], bed_mean[0] * np.array([1.0, (hi / lo) ** warr]), ":", color="0.4",
        label=rf"$V^{{{warr}}}$ (Warr et al. 1995, dense bed)",
    )  # fmt: skip
    ax.errorbar(velocities, temps, yerr=errs, fmt="o", color="C0", label="gas, no gravity")
    grid = np.geomspace(velocities[0] / 1.5, velocities[-1] * 1.5, 50)
    predicted = [_balance(v) for v in grid]
    ax.plot(grid, predicted, "-", color="C0", label=r"uniform-gas balance ($T \propto V^2$)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    from matplotlib.ticker import NullFormatter

    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(r"wall peak speed $V = A\omega$")
    ax.set_ylabel(r"granular temperature $T$")
    ax.set_title(
        rf"no gravity: $\alpha$ = {slope:.3f} $\pm$ {slope_err:.3f};"
        rf" bed under gravity: $\alpha$ = {alpha:.3f} $\pm$ {alpha_err:.3f}",
        fontsize=9,
    )
    ax.legend(fontsize=8)
    return [save(f, out, "vibrated_temperature.png")], rows


def notes(by_id):
    """Sentences for report.md's vibrated section, conditional on the rows."""
    text = [
        "The temperatures are compared with the energy balance of a uniform gas "
        "(theory.vibrated_temperature), an estimate: the gas is hotter and thinner at the "
        "vibrating wall, and the wall's excursion is ~0.4 of a thermal flight per period; "
        "docs/vibrated.md."
    ]
    alpha = by_id.get("vibrated.temperature_exponent")
    if alpha is not None:
        text.append(
            f"T ~ V^{alpha['ours']:.3f}: the dilute theory's 2 (Kumaran 1998); the dense bed of "
            "Warr, Huntley & Jacques (1995), under gravity, gave 1.41 +- 0.11, an experiment this "
            "gas without gravity does not repeat."
        )
    bed = by_id.get("vibrated.temperature_scaling")
    if bed is not None:
        text.append(
            f"The bed under gravity: T ~ V^{bed['ours']:.3f} +- {bed['ours_error']:.3f}, near the "
            "dilute theory's 2 (Kumaran 1998; McNamara & Luding 1998 found 2 for dilute beds in "
            "simulation, about 1.5 for dense ones).  Warr, Huntley & Jacques (1995) measured "
            "1.41 +- 0.11 in a dense 2D bed (several layers, packed near its floor), where "
            "collisions are correlated and the floor's input is not the dilute one: this "
            "dilute bed (floor area fraction 0.009-0.035) is not that experiment; docs/vibrated.md."
        )
    return text


def _bed(amplitude, seed, quick):
    """One run of the bed under gravity: (T = <E>/N over the window, the floor's work over
    the collisions' loss there)."""
    a = amplitude
    estimate = _bed_estimate(a * OMEGA)
    # placed uniformly up to twice the estimate's scale height T / g (the barometric
    # profile's mean height) at its temperature: the bed starts near its steady state
    lift = min(BED_HEIGHT, 2 * estimate / BED_G)
    start = Scene.random(
        N, RADIUS, dim=2, box=((0.0, 2 * a), (1.0, lift)), boundary="walls",
        temperature=estimate, seed=seed,
    )  # fmt: skip
    scene = start.replace(
        box=(np.zeros(2), np.array([1.0, BED_HEIGHT])),
        vibrating_wall=VibratingWall(1, "lower", a, OMEGA),
        restitution=XI,
        gravity=(0.0, -BED_G),
    )
    sim = Simulation(scene)
    settle, measure = _lengths(quick)
    sim.run(stop_when={"collisions_per_particle": settle}, store=())
    before, t0 = sim.stats, sim.time
    goal = before["collisions_per_particle"] + measure
    sim.run(stop_when={"collisions_per_particle": goal}, store=())
    after = sim.stats
    energy = (after["kinetic_time_integral"] - before["kinetic_time_integral"]) / (sim.time - t0)
    work = after["wall_work"] - before["wall_work"]
    loss = after["collision_loss"] - before["collision_loss"]
    return energy / N, work / loss


def _bed_estimate(peak_velocity):
    """theory.vibrated_bed_temperature of the bed (N disks on the unit-wide floor)."""
    return theory.vibrated_bed_temperature(
        peak_velocity, n=N, area=1.0, radius=RADIUS, restitution=XI, dim=2
    )


def _weighted_slope(x, y, err):
    """Weighted least squares of y on x with standard errors err: (slope, its error)."""
    w = err**-2.0
    xm, ym = np.sum(w * x) / np.sum(w), np.sum(w * y) / np.sum(w)
    sxx = np.sum(w * (x - xm) ** 2)
    return float(np.sum(w * (x - xm) * (y - ym)) / sxx), float(1.0 / math.sqrt(sxx))


def temperature_scaling_under_gravity(quick=False, runs=RUNS):
    """The vibrated bed under gravity (module docstring): T against V = A omega at fixed
    omega, ``runs`` runs per amplitude of ``BED_AMPLITUDES``.  Returns (velocities, the
    runs' temperatures (amplitudes x runs), their power balances (likewise), alpha of
    T ~ V^alpha and its standard error).  Compare alpha with ``theory.DILUTE_EXPONENT``
    (2) and ``theory.WARR_HUNTLEY_JACQUES_EXPONENT`` (1.41 +- 0.11, a dense bed)."""
    results = np.array(
        [[_bed(a, 1000 + 100 * k + s, quick) for s in range(runs)]
         for k, a in enumerate(BED_AMPLITUDES)]
    )  # fmt: skip
    temps, balance = results[..., 0], results[..., 1]
    velocities = np.array(BED_AMPLITUDES) * OMEGA
    mean, err = temps.mean(axis=1), temps.std(axis=1, ddof=1) / math.sqrt(runs)
    alpha, alpha_err = _weighted_slope(np.log(velocities), np.log(mean), err / mean)
    return velocities, temps, balance, alpha, alpha_err
