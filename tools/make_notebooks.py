"""Build the notebooks (outputs stripped) from cell lists -- run once, commit the .ipynb."""

import nbformat as nbf


def nb(name, cells):
    """A notebook of markdown ("md:...") and code cells, with ids stable across rebuilds."""
    n = nbf.v4.new_notebook()
    n.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    n.cells = [
        nbf.v4.new_markdown_cell(c[3:], id=f"{name[:2]}-{i}")
        if c.startswith("md:")
        else nbf.v4.new_code_cell(c, id=f"{name[:2]}-{i}")
        for i, c in enumerate(cells)
    ]
    return n


setup = """import os
import numpy as np
import matplotlib.pyplot as plt
import granular
from granular import theory, plot
QUICK = os.environ.get("GRANULAR_QUICK") == "1"  # the test suite runs the notebooks small"""

quick = [
    (
        "md:# granular in ten cells\n"
        "A granular gas of hard spheres in the thesis' standard box, run by event-driven MD and "
        "compared with theory."
    ),
    setup,
    (
        "md:A scene: N = 1000 spheres of radius 0.025 in the periodic unit box (packing fraction "
        "0.065), speed sqrt(2) in isotropic directions."
    ),
    """n, r = (1000, 0.025) if not QUICK else (300, 0.0373)
scene = granular.Scene.random(n, r, seed=1)
scene""",
    (
        "md:Equilibrate it as a molecular gas, then make it granular (xi = 0.8) and run to t = 20, "
        "sampling on a log grid."
    ),
    """sim = granular.Simulation(scene)
sim.run(stop_when={"collisions_per_particle": 20}, store=())
gas = sim.scene.replace(restitution=0.8)
times = np.concatenate([[0], np.logspace(-2, np.log10(20 if not QUICK else 5), 30)])
traj = granular.Simulation(gas).run(t_stop=times[-1], sample_times=times)
traj""",
    "md:Haff's law: the temperature against T0 / (1 + t/tau0)^2 with tau0 from (2.45).",
    """c = theory.langevin_coefficients(
    n=n, radius=r, volume=1.0, restitution=0.8, temperature0=gas.temperature
)
plot.haff(traj.times, traj.temperature, tau0=c.tau0)""",
    (
        "md:The mean squared displacement against (2.79): ballistic, then logarithmic (ultraslow "
        "diffusion)."
    ),
    """th = theory.msd_granular(traj.times, D0=c.D0, gamma0=c.gamma0, tau0=c.tau0)
plot.msd(traj.times, traj.msd(), theory_values=th)""",
]

repro = [
    (
        "md:# The thesis' chapter 4, the story\n"
        "The same experiments as `python -m granular reproduce`, one at a time. "
        "`reproduce.figure(name, quick=..., runs=...)` runs one of them on the thesis' system, "
        "writes its figures and returns their paths and its summary rows: our value with its "
        "standard error over the runs, the thesis' value and theory's. `reproduce.FIGURES` lists "
        "the names.\n\n"
        "**Time:** by default each experiment runs the thesis' system with 4 runs (the "
        "thesis' own count for most figures): the whole notebook took 3 min 5 s on 2 cores "
        "that were busy with other jobs (load average 6), less on a quiet machine. "
        "Set `FULL = True` for the statistics of `python -m granular reproduce` (five times the "
        "thesis' runs): about 14 minutes on 2 cores."
    ),
    setup + "\nfrom granular.cli import reproduce\nfrom IPython.display import Image, display",
    """FULL = False  # True: five times the thesis' runs, as `python -m granular reproduce`
# 4 runs per experiment (the thesis' own count for most figures); None: reproduce's defaults
RUNS = None if FULL or QUICK else 4
out = "reproduction"
rows = []
list(reproduce.FIGURES)""",
    "md:## Verification: a head-on collision, energy conservation, collision counts (Figs 4.1-4.4)",
    """for name in ("4.1", "4.2-4.4"):
    paths, new_rows = reproduce.figure(name, quick=QUICK, runs=RUNS, out=out)
    rows += new_rows
    display(*[Image(p) for p in paths])""",
    "md:## Speed distributions and Table 4.1 (Figs 4.5-4.7)",
    """paths, new_rows = reproduce.figure("4.5-4.7", quick=QUICK, runs=RUNS, out=out)
rows += new_rows
display(Image(paths[1]))
new_rows""",
    "md:## Haff's law (Figs 4.8, 4.10) and 2D clustering (Fig. 4.9)",
    """for name in ("4.8+4.10", "4.9"):
    paths, new_rows = reproduce.figure(name, quick=QUICK, runs=RUNS, out=out)
    rows += new_rows
    display(*[Image(p) for p in paths])""",
    "md:## Brownian motion: MSD, diffusivity and long-time slopes (Figs 4.11-4.16, F.1-F.2)",
    """paths, new_rows = reproduce.figure("4.11-4.16+F", quick=QUICK, runs=RUNS, out=out)
rows += new_rows
display(Image(paths[2]), Image(paths[-1]))
new_rows""",
    (
        "md:## Langevin and UDSBM, ergodicity (Figs 4.17-4.23)\n"
        "Fig. 4.23: the time-averaged MSD of UDSBM for several t_stop, beside the ensemble MSD."
    ),
    """paths, new_rows = reproduce.figure("4.17-4.23", quick=QUICK, runs=RUNS, out=out)
rows += new_rows
display(Image(paths[3]), Image(paths[-1]))
new_rows""",
    (
        "md:All rows: ours against theory (`python -m granular reproduce` writes them to "
        "`summary.json` and a report)."
    ),
    """[(r["id"], r["ours"], r["ours_error"], r["theory"]) for r in rows]""",
]

lve = [
    (
        "md:# When is a Langevin model enough?\n"
        "The thesis models a molecular gas by the underdamped Langevin equation and a granular gas "
        "by underdamped scaled Brownian motion (UDSBM), with coefficients from kinetic theory. "
        "Here both models meet the event-driven gas they stand for."
    ),
    setup + "\nfrom granular import langevin",
    """n, r = (1000, 0.025) if not QUICK else (300, 0.0373)
sim = granular.Simulation(granular.Scene.random(n, r, seed=2))
sim.run(stop_when={"collisions_per_particle": 20}, store=())
eq = sim.scene
t_stop = 50.0 if not QUICK else 5.0
times = np.concatenate([[0], np.logspace(-2, np.log10(t_stop), 30)])""",
    (
        "md:The same scene three ways: EDMD, the SDE model from `langevin.from_scene` "
        "(Euler-Maruyama and exact), and theory."
    ),
    """fig, axes = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
for ax, xi in zip(axes, (1.0, 0.8)):
    gas = eq.replace(restitution=xi)
    traj = granular.Simulation(gas).run(t_stop=t_stop, sample_times=times)
    for scheme in ("em", "exact"):
        sde = langevin.from_scene(
            gas, dt=0.01, t_stop=t_stop, scheme=scheme, n=4 * n, sample_times=times, seed=3
        )
        ax.plot(sde.times[1:], sde.msd()[1:], label=f"{sde.model}, {scheme}")
    plot.msd(traj.times, traj.msd(), ax=ax, label="EDMD")
    ax.set_title(f"xi = {xi}")""",
    (
        "md:For the molecular gas the Langevin model matches: its velocity autocorrelation is the "
        "gas' (2.66). For the granular gas UDSBM tracks EDMD only up to O(1 - xi) (thesis 4.2.2): "
        "its velocity autocorrelation (2.111) differs from the granular gas' (2.77) unless gamma0 "
        "tau0 >> 1. Ergodicity is where they part for good: UDSBM's time average never catches its "
        "ensemble average."
    ),
    """lags = np.logspace(-2, np.log10(t_stop / 2), 15)
lags = np.unique(np.rint(lags / 0.01)) * 0.01  # whole steps of dt, as run() needs
c = langevin.coefficients_from_scene(eq.replace(restitution=0.8))
u = langevin.run(
    n,
    gamma0=c.gamma0,
    D0=c.D0,
    tau0=c.tau0,
    dt=0.01,
    t_stop=t_stop,
    scheme="exact",
    initial="udsbm",
    tamsd_lags=lags,
    seed=4,
)
plot.msd_vs_tamsd(u.times, u.msd(), lags=u.tamsd_lags, tamsd_values=u.tamsd(), label="UDSBM")""",
    "md:Ensembles of EDMD runs on all local cores (the default backend), a sweep over xi:",
    """import functools
runs = 4 if not QUICK else 2
sweep = {}
for xi in (1.0, 0.9, 0.8):
    make = functools.partial(granular.Scene.random, n, r, restitution=xi)
    sweep[xi] = granular.ensemble(
        make,
        runs=runs,
        seed=1,
        t_stop=times[-1],
        sample_times=times,
        quantities=("msd",),
        progress=False,
    )
ax = None
for xi, res in sweep.items():
    ax = plot.msd(times, res.mean["msd"], error=res.error["msd"], ax=ax, label=f"xi = {xi}")""",
    (
        "md:The same code on a Dask cluster: pass a `distributed.Client` as the backend. A "
        "`LocalCluster` of two worker processes stands in here for a real cluster "
        '(`Client("scheduler-address:8786")`). Run r always gets '
        "`SeedSequence(seed).spawn(runs)[r]`, so the numbers are the ones the local cores gave."
    ),
    """from distributed import Client, LocalCluster

cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0")
client = Client(cluster)
on_dask = {}
for xi in sweep:
    make = functools.partial(granular.Scene.random, n, r, restitution=xi)
    on_dask[xi] = granular.ensemble(
        make,
        runs=runs,
        seed=1,
        backend=client,
        t_stop=times[-1],
        sample_times=times,
        quantities=("msd",),
        progress=False,
    )
client.close()
cluster.close()
same = all(np.array_equal(on_dask[xi].mean["msd"], sweep[xi].mean["msd"]) for xi in sweep)
assert same, "the Dask cluster gave other numbers than the local cores"
print("same numbers as on local cores:", same)""",
]

visco = [
    (
        "md:# Viscoelastic particles and the end of homogeneous cooling\n"
        "The two topics the thesis names as further work (chapter 5). Particles whose "
        "restitution depends on the impact speed (viscoelastic spheres) cool as T ~ t^(-5/3) "
        "instead of Haff's t^(-2), diffuse as MSD ~ t^(1/6), and do not collapse; a constant-xi "
        "gas in a box wider than the critical size of the shear instability leaves Haff's law "
        "as vortices and clusters grow.\n\n"
        "Full size this notebook takes about 15 s (11-15 s measured on a loaded 2-core "
        "machine; `GRANULAR_QUICK=1`: about 4 s)."
    ),
    setup + "\nimport math\nimport warnings\nfrom granular import analysis, langevin",
    (
        "md:## A viscoelastic gas\n"
        "The thesis' gas (N = 1000 spheres of radius 0.025 in the unit box), equilibrated, then "
        "given the viscoelastic law `granular.Viscoelastic`: eps(g) = 1 - C1 delta + C2 delta^2, "
        "delta = A kappa^(2/5) g^(1/5) (Schwager & Poeschel 1998), g the normal impact speed. "
        "`from_restitution` picks the law whose eps is 0.9 at g = sqrt(4 T0/m), the rms normal "
        "speed of colliding pairs. The one number theory needs is A kappa^(2/5), the law's "
        "`scale`."
    ),
    """n, r = (1000, 0.025) if not QUICK else (300, 0.0373)
sim = granular.Simulation(granular.Scene.random(n, r, seed=1))
sim.run(stop_when={"collisions_per_particle": 20}, store=())
eq = sim.scene
T0 = eq.temperature
law = granular.Viscoelastic.from_restitution(0.9, speed=math.sqrt(4 * T0))
a_kappa = law.a_kappa  # A kappa^(2/5), the number theory takes
c = theory.viscoelastic_langevin_coefficients(
    n=n, radius=r, volume=eq.volume, a_kappa=a_kappa, temperature0=T0
)
print(f"delta(T0) = {theory.viscoelastic_delta(T0, a_kappa=a_kappa):.3f}, tau0' = {c.tau0:.3f}")
t_stop = (1000 if not QUICK else 100) * c.tau0
times = np.concatenate([[0], np.logspace(-2, np.log10(t_stop), 40)])
visco_sim = granular.Simulation(eq.replace(restitution=law))
traj = visco_sim.run(t_stop=t_stop, sample_times=times)
print("collisions per particle:", visco_sim.stats["collisions_per_particle"])
print("collisions past the series' range:", visco_sim.stats["law_clamped_collisions"])""",
    (
        "md:Cooling: the temperature against the leading-order law T0 (1 + t/tau0')^(-5/3) "
        "(`theory.viscoelastic_temperature`) and the law with the next term of the series "
        "(`theory.viscoelastic_temperature_second_order`); right, the local exponent "
        "d ln T / d ln t, which tends to -5/3 (Haff's law with constant xi: -2)."
    ),
    """fig, axes = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
t = traj.times[1:]
T = traj.temperature[1:]
axes[0].loglog(t, T, "o", ms=3, label="EDMD")
T1 = theory.viscoelastic_temperature(t, temperature0=T0, tau0=c.tau0)
axes[0].loglog(t, T1, label="leading order")
second = theory.viscoelastic_temperature_second_order(
    t, temperature0=T0, a_kappa=a_kappa, density=eq.density, radius=r
)
axes[0].loglog(t, second, "--", label="with the next term")
axes[0].set(xlabel="t", ylabel="T", title="viscoelastic cooling")
axes[0].legend()
mid = np.sqrt(t[1:] * t[:-1])
axes[1].semilogx(mid, np.diff(np.log(T)) / np.diff(np.log(t)), "o", ms=3, label="EDMD")
axes[1].semilogx(mid, np.diff(np.log(second)) / np.diff(np.log(t)), "--", label="theory")
axes[1].axhline(-5 / 3, color="0.5", ls=":", label="-5/3")
axes[1].axhline(-2, color="r", ls=":", label="-2 (constant xi)")
axes[1].set(xlabel="t", ylabel="d ln T / d ln t")
axes[1].legend();""",
    (
        "md:## Subdiffusion, and power-law UDSBM\n"
        "With D(t) ~ sqrt(T) ~ (1 + t/tau0')^(-5/6) the MSD grows as t^(1/6) "
        "(`theory.msd_viscoelastic`, Brilliantov & Poeschel 2004 ch. 14). The Langevin "
        "counterpart is underdamped scaled Brownian motion with gamma and D ~ (1 + t/tau0')^(-a), "
        "a = 5/6 (Bodrova et al. 2015): `langevin.run(..., exponent=5/6)` with the "
        "coefficients of `theory.viscoelastic_langevin_coefficients`."
    ),
    """u = langevin.run(
    4 * n,
    gamma0=c.gamma0,
    D0=c.D0,
    tau0=c.tau0,
    exponent=5 / 6,
    dt=0.02,
    t_stop=t_stop,
    sample_times=times,
    seed=3,
)
ax = plot.msd(traj.times, traj.msd(), label="EDMD")
ax.plot(u.times[1:], u.msd()[1:], label="UDSBM, a = 5/6")
ax.plot(t, theory.msd_viscoelastic(t, D0=c.D0, tau0=c.tau0), "--", label="theory, 2 d int D")
asymptote = theory.msd_viscoelastic_asymptote(t, D0=c.D0, tau0=c.tau0)
ax.plot(t, asymptote, ":", label="t^(1/6) asymptote")
ax.legend()
late = traj.times > 10 * c.tau0
tl = traj.times[late]
slope = analysis.fit_power_law(tl, traj.msd()[late])[0]
slope_u = analysis.fit_power_law(tl, np.interp(tl, u.times, u.msd()))[0]
slope_th = analysis.fit_power_law(tl, theory.msd_viscoelastic(tl, D0=c.D0, tau0=c.tau0))[0]
print(f"d ln MSD / d ln t over t in [{tl[0]:.3g}, {tl[-1]:.3g}]:")
print(f"EDMD {slope:.3f}, UDSBM {slope_u:.3f}, theory {slope_th:.3f}", "(1/6 only as t -> inf)")""",
    (
        "md:Both models sit some 10-20% off each other at late times: the MSD's prefactor comes "
        "from Enskog's D0, which the thesis' EDMD already exceeds for constant xi (its section "
        "4.2.2), and UDSBM drops the velocity correlations of a real gas. The exponent is the "
        "robust part.\n\n"
        "## Time averages and ergodicity breaking, a = 1 and a = 5/6\n"
        "The time-averaged MSD of one trajectory against the ensemble MSD, and the "
        "ergodicity-breaking parameter EB = Var(TAMSD) / <TAMSD>^2 over the particles, "
        "measured and from theory (`theory_ergodicity_breaking`: exact, from the position "
        "covariance, for Gaussian initial velocities)."
    ),
    """# the thesis' gas, xi = 0.8
c8 = theory.langevin_coefficients(
    n=1000, radius=0.025, volume=1.0, restitution=0.8, temperature0=2 / 3
)
t_sde = 100.0 if not QUICK else 10.0  # 2000 steps of dt = 0.05
lags = np.logspace(-1, np.log10(t_sde / 4), 8 if not QUICK else 3)
lags = np.unique(np.rint(lags / 0.05)) * 0.05  # whole steps of dt, as run() needs
fig, axes = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
for a in (1.0, 5 / 6):
    res = langevin.run(
        2000,
        gamma0=c8.gamma0,
        D0=c8.D0,
        tau0=c8.tau0,
        exponent=a,
        dt=0.05,
        t_stop=t_sde,
        tamsd_lags=lags,
        seed=4,
    )
    name = f"a = {a:.3g}"
    plot.msd_vs_tamsd(
        res.times, res.msd(), lags=res.tamsd_lags, tamsd_values=res.tamsd(), ax=axes[0], label=name
    )
    eb = res.ergodicity_breaking()
    (line,) = axes[1].loglog(res.tamsd_lags, eb, "o", label=f"measured, {name}")
    eb_theory = res.theory_ergodicity_breaking()
    axes[1].loglog(res.tamsd_lags, eb_theory, "-", color=line.get_color(), label=f"theory, {name}")
axes[1].set(xlabel="lag", ylabel="EB")
axes[1].legend();""",
    (
        "md:EB grows with the lag for both and is not zero at short lags as it would be for an "
        "ergodic process over a long window; the viscoelastic case (a = 5/6) ages more slowly "
        "and its EB is a little smaller.\n\n"
        "## No inelastic collapse\n"
        "1000 disks at area fraction 0.4 between walls collapse with xi = 0.8 (seed 2). The "
        "viscoelastic law with the same mean restitution -- eps(g) averaged over the initial "
        "collisions, whose normal relative speeds g have the density g/s^2 exp(-g^2 / 2 s^2), "
        "s^2 = 2T/m -- runs on: slow collisions become nearly elastic, so the sequence of ever "
        "faster collisions that makes a collapse cannot form."
    ),
    """nd, phi, xi = 1000, 0.4, 0.8
rd = math.sqrt(phi / (nd * math.pi))
disks = granular.Scene.random(
    nd, rd, dim=2, boundary="walls", restitution=xi, temperature=1.0, seed=2
)
try:
    granular.Simulation(disks).run(stop_when={"collisions_per_particle": 400}, store=())
    print(f"xi = {xi}: no collapse")
except granular.InelasticCollapseError as e:
    print(f"xi = {xi}: inelastic collapse at t = {e.time:.3f}")

s = math.sqrt(2 * disks.temperature)
g = np.linspace(0, 12 * s, 100_001)
weight = g / s**2 * np.exp(-(g**2) / (2 * s**2))


def mean_eps(damping):
    return np.trapezoid(granular.Viscoelastic(damping, 1.0)(g) * weight, g)


lo, hi = 1e-4, 1.0  # bisection: the mean restitution falls as the damping grows
for _ in range(50):
    lo, hi = ((lo + hi) / 2, hi) if mean_eps((lo + hi) / 2) > xi else (lo, (lo + hi) / 2)
vsim = granular.Simulation(disks.replace(restitution=granular.Viscoelastic(lo, 1.0)))
with warnings.catch_warnings():
    warnings.simplefilter("ignore", RuntimeWarning)  # a few hot-start collisions are clamped
    vsim.run(stop_when={"collisions_per_particle": 400}, store=())
reached = vsim.stats["collisions_per_particle"]
print(f"viscoelastic, mean eps {mean_eps(lo):.3f}: no collapse,", f"{reached:.0f} collisions each")
fig, ax = plt.subplots(figsize=(4, 4))
plot.snapshot(
    vsim.scene.positions,
    radii=vsim.scene.radii,
    lower=vsim.scene.lower,
    upper=vsim.scene.upper,
    ax=ax,
)
ax.set_title("viscoelastic disks, the end of the run");""",
    (
        "md:The viscoelastic disks still cluster (here against the walls, where the gas is "
        "densest) but never collapse.\n\n"
        "## Where homogeneous cooling ends: clustering at xi = 0.3\n"
        "At the thesis' density and xi = 0.3 the critical box size of the shear instability "
        "(`theory.critical_box_size`, Goldhirsch & Zanetti 1993) is L_c = 1.09. A box twice "
        "as wide (N = 8000) goes unstable -- `Simulation.run` says so with a "
        "`ClusteringWarning` -- while boxes of L = 0.74 (N = 400) stay homogeneous; eight of "
        "those are averaged to beat their noise."
    ),
    """xi, density = 0.3, 1000.0
lc = theory.critical_box_size(density=density, radius=0.025, restitution=xi)
big_n, small_n, small_runs = (8000, 400, 8) if not QUICK else (3000, 250, 3)


def cool(n_particles, seed):
    box = (n_particles / density) ** (1 / 3)
    start = granular.Scene.random(n_particles, 0.025, box=box, temperature=2 / 3, seed=seed)
    sim = granular.Simulation(start)
    sim.run(stop_when={"collisions_per_particle": 10}, store=())
    gas = sim.scene.replace(restitution=xi)
    tau0 = theory.haff_tau0(
        density=density, radius=0.025, restitution=xi, temperature0=gas.temperature
    )
    when = np.concatenate([[0], np.logspace(-1, 2.5, 30)]) * tau0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", granular.ClusteringWarning)
        tr = granular.Simulation(gas).run(
            t_stop=when[-1], sample_times=when, store=("positions", "velocities")
        )
    haff = theory.haff_temperature(when, temperature0=gas.temperature, tau0=tau0)
    return box, tau0, tr, tr.temperature / haff, [str(w.message) for w in caught]


box, tau0, big, big_ratio, caught = cool(big_n, 1)
print(f"big box L = {box:.2f} = {box / lc:.2f} L_c; warned:", caught[0][:120] if caught else "no")
small = [cool(small_n, 10 + k) for k in range(small_runs)]
small_box = small[0][0]
warned = any(s[4] for s in small)
print(f"small box L = {small_box:.2f} = {small_box / lc:.2f} L_c; warned:", warned)""",
    (
        "md:Left: T against Haff's law (Enskog's tau0). Middle: the energy of the flow field "
        "coarse-grained on cells about 0.4 wide, against the thermal energy (dotted: the level "
        "of pure noise). Right: the structure factor at the smallest wave vectors, 1 for a "
        "homogeneous gas and of order N for box-scale clusters."
    ),
    """fig, axes = plt.subplots(1, 3, figsize=(15, 4), layout="constrained")
s_t = big.times / tau0
axes[0].semilogx(s_t[1:], big_ratio[1:], label=f"L = {box / lc:.2f} L_c")
small_ratio = np.mean([s[3] for s in small], axis=0)
small_label = f"L = {small_box / lc:.2f} L_c, {small_runs} runs"
axes[0].semilogx(s_t[1:], small_ratio[1:], label=small_label)
axes[0].axhline(1, color="0.5", ls=":")
axes[0].set(xlabel="t / tau0", ylabel="T / T_Haff")
axes[0].legend()
plot.flow_energy(s_t, big.flow_energy(cells=4), ax=axes[1], label=f"L = {box / lc:.2f} L_c")
flows = [s[2].flow_energy(cells=2) for s in small]
mean_flow = type(flows[0])(*(np.mean(f, axis=0) for f in zip(*flows)))
plot.flow_energy(s_t, mean_flow, ax=axes[1], label=small_label)
axes[1].set_xlabel("t / tau0")
sk_big = big.structure_factor()
sk_small = np.mean([s[2].structure_factor().values[:, 0] for s in small], axis=0)
axes[2].loglog(s_t[1:], sk_big.values[1:, 0], label=f"L = {box / lc:.2f} L_c")
axes[2].loglog(s_t[1:], sk_small[1:], label=small_label)
axes[2].axhline(1, color="0.5", ls=":")
axes[2].set(xlabel="t / tau0", ylabel="S(k_min)")
axes[2].legend();""",
    (
        "md:The big box at the end: the particles of a slab a sixth of the box thick, and the "
        "flow field of that slab (mean velocity per cell, arrows): the box-scale shear flow, "
        "streams running in opposite directions, and the dense bands it gathers."
    ),
    """x = np.mod(big.positions[-1] - big.lower, box) + big.lower
v = big.velocities[-1] - big.velocities[-1].mean(axis=0)
slab = x[:, 2] < big.lower[2] + box / 6
fig, ax = plt.subplots(figsize=(6, 6))
plot.snapshot(
    x[slab, :2], radii=0.025, lower=big.lower[:2], upper=big.upper[:2], ax=ax, color="0.6"
)
bins = 10
ij = np.minimum(((x[slab, :2] - big.lower[:2]) / box * bins).astype(int), bins - 1)
flat = ij[:, 0] * bins + ij[:, 1]
count = np.bincount(flat, minlength=bins * bins)
mean_v = [np.bincount(flat, v[slab, k], bins * bins) / np.maximum(count, 1) for k in (0, 1)]
centres = big.lower[0] + (np.arange(bins) + 0.5) * box / bins
cx, cy = np.meshgrid(centres, centres, indexing="ij")
ax.quiver(cx.ravel(), cy.ravel(), mean_v[0], mean_v[1], color="C3")
ax.set_title(f"xi = 0.3, t = {s_t[-1]:.0f} tau0, L = {box / lc:.2f} L_c");""",
    (
        "md:Above L_c the flow energy climbs far beyond its noise level, clusters follow "
        "(S(k_min) grows by orders of magnitude) and the gas cools ever slower than Haff's law. "
        "Below L_c the flow stays near its noise level, S stays of order 1, and T follows "
        "Haff's law up to a constant offset: T / T_Haff levels off near 1.15, a tau0 some 8% "
        "above Enskog's, which short-range velocity correlations give in any box "
        "(`docs/clustering.md`)."
    ),
]

for name, cells in (
    ("01_quickstart", quick),
    ("02_thesis_reproduction", repro),
    ("03_langevin_vs_edmd", lve),
    ("04_viscoelastic_and_clustering", visco),
):
    nbf.write(nb(name, cells), f"notebooks/{name}.ipynb")
