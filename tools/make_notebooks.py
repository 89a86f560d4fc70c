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
    """c = theory.langevin_coefficients(n, r, 1.0, 0.8, gas.temperature)
plot.haff(traj.times, traj.temperature, tau0=c.tau0)""",
    (
        "md:The mean squared displacement against (2.79): ballistic, then logarithmic (ultraslow "
        "diffusion)."
    ),
    """th = theory.msd_granular(traj.times, c.D0, c.gamma0, c.tau0)
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
plot.msd_vs_tamsd(u.times, u.msd(), u.tamsd_lags, u.tamsd(), label="UDSBM")""",
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

for name, cells in (
    ("01_quickstart", quick),
    ("02_thesis_reproduction", repro),
    ("03_langevin_vs_edmd", lve),
):
    nbf.write(nb(name, cells), f"notebooks/{name}.ipynb")
