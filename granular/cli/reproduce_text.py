"""The words of the reproduction (``python -m granular reproduce``): ``report.md``, generated
from the rows of ``summary.json`` -- the table, a sentence per row saying whether ours agrees
with theory and with the thesis within ``SIGMA`` standard errors, and the physics beside the
numbers, section by section, each claim conditional on the rows -- and the numbers the
thesis printed that the runner (``reproduce``) and the report both use.

A section's notes are written only when its rows are there (``reproduce --only``).
"""

from __future__ import annotations

import math

from .. import theory

SIGMA = 3.0  # the report calls a value "in agreement" within this many standard errors
THESIS_T0 = 2.0 / 3.0  # the thesis' temperature: speed sqrt(2) in 3D
# App. F: the thesis' long-time MSD slopes (N = 1000), measured and as it computed theory
THESIS_SLOPES = {1.0: (0.364, 0.350), 0.8: (0.420, 0.451)}


def _thesis_coefficients(xi):
    """gamma0, D0, tau0 of the thesis' system (N = 1000, r = 0.025, T0 = 2/3), (2.45-2.55)."""
    return theory.langevin_coefficients(
        n=1000, radius=0.025, volume=1.0, restitution=xi, temperature0=THESIS_T0
    )


def _num(x):
    return "--" if x is None else f"{x:.4g}"


def _fmt(x, e=None):
    return _num(x) + (f" ± {e:.2g}" if x is not None and e is not None else "")


def _z(row, key="theory"):
    """(ours - reference) / standard error, or None when there is no error to judge by."""
    ref, err = row[key], row["ours_error"]
    if ref is None or err is None or not err > 0:
        return None
    return (row["ours"] - ref) / err


def _compare(row, key):
    """'theory 1.3: agrees within 2 sigma (+0.4%)' or 'theory 1.3: differs by +5.0% (6.1 sigma)'."""
    ref = row[key]
    if ref is None:
        return None
    z = _z(row, key)
    if z is None:
        return f"{key} {_num(ref)}"
    if ref == 0:  # a reference of 0 (e.g. a correlation that should vanish): no relative gap
        gap = f"{row['ours'] - ref:+.3g}"
        if abs(z) <= SIGMA:
            return f"{key} {_num(ref)}: agrees within {max(1, math.ceil(abs(z)))} sigma"
        return f"{key} {_num(ref)}: differs by {gap} ({z:+.1f} sigma)"
    rel = row["ours"] / ref - 1
    if abs(z) <= SIGMA:
        return f"{key} {_num(ref)}: agrees within {max(1, math.ceil(abs(z)))} sigma ({rel:+.1%})"
    return f"{key} {_num(ref)}: differs by {rel:+.1%} ({z:+.1f} sigma)"


def _sentence(row):
    runs = f" ({row['runs']} runs)" if row["runs"] else ""
    parts = [p for p in (_compare(row, "theory"), _compare(row, "thesis")) if p]
    return (
        f"- `{row['id']}`, {row['quantity']}: ours {_fmt(row['ours'], row['ours_error'])}{runs}"
        + "".join("; " + p for p in parts)
        + "."
    )


def _xi(row):
    return row["id"].rsplit("xi", 1)[1]


def _significant(by_id, prefix, sign):
    """The rows under ``prefix`` more than SIGMA standard errors above (sign 1) or below
    (sign -1) theory."""
    return [r for i, r in by_id.items() if i.startswith(prefix) and (_z(r) or 0) * sign > SIGMA]


def _energy_notes(cfg, by_id):
    drift = by_id["energy.drift.xi1"]["ours"]
    energy = [
        f"The largest relative change of the molecular gas' energy, {drift:.1e}, is "
        + ("rounding (below 1e-12)." if drift < 1e-12 else "more than rounding (above 1e-12).")
    ]
    return energy


def _speed_notes(cfg, by_id):
    return [
        "<v^2> agrees by construction: T is measured from the kinetic energy of the same runs, as "
        "in the thesis.  The thesis' own Table 4.1 numbers did not survive the text conversion, so "
        "that column is empty."
    ]


def _haff_notes(cfg, by_id):
    haff = [
        "(2.45) is Enskog's tau0 for a homogeneous cooling state with a Maxwellian velocity "
        "distribution.  The real cooling state is not quite Maxwellian (Sonine coefficient a2), "
        "and inelastic collisions build up velocity correlations and, at late times, "
        "inhomogeneities: corrections of a few percent that grow with 1 - xi."
    ]
    above, below = _significant(by_id, "haff.", 1), _significant(by_id, "haff.", -1)
    if above:
        haff.append(
            f"Where the fit lies above (2.45) (xi = {', '.join(map(_xi, above))}) the gas cools "
            "more slowly than that theory says; the thesis too found 'computed values somewhat "
            "higher than theory' at low xi."
        )
    if below:
        haff.append(
            f"Where the fit lies below (2.45) (xi = {', '.join(map(_xi, below))}) the gas cools "
            "faster than that theory says."
        )
    if not above and not below:
        haff.append(f"Every fitted tau0 agrees with (2.45) within {SIGMA:g} standard errors.")
    return haff


def _slope_notes(cfg, by_id):
    (m1, t1), (m8, t8) = THESIS_SLOPES[1.0], THESIS_SLOPES[0.8]
    c1, c8 = _thesis_coefficients(1.0), _thesis_coefficients(0.8)
    ours8 = 6 * c8.D0 * c8.tau0
    slopes = [
        "Theory's slope is its MSD curve fitted over the same window with the same fit, so the "
        "columns compare like with like; the asymptotic slopes the thesis quoted are in the "
        "quantity text."
    ]
    if cfg.quick:
        slopes.append(
            "Quick mode runs a smaller system over shorter times, so the thesis' App. F values "
            "(N = 1000) are quoted, not compared."
        )
    slopes.append(
        f"The thesis measured its molecular slope {m1:.3f} against 6 D0 = {t1:.3f} "
        f"({m1 / t1 - 1:+.0%}); (2.52) for its system gives 6 D0 = {6 * c1.D0:.3f}.  For xi = 0.8 "
        f"it measured {m8:.3f} and quoted {t8:.3f} as theory, while (2.45) and (2.52) for its "
        f"system give 6 D0 tau0 = {ours8:.3f}"
        + (
            ": its theory value does not follow from its own equations."
            if abs(ours8 / t8 - 1) > 0.02
            else "."
        )
    )
    above = _significant(by_id, "msd.slope.", 1)
    if above:
        slopes.append(
            f"Where our slope lies above theory ({', '.join(r['id'] for r in above)}): Enskog's D0 "
            "(2.52) neglects velocity correlations and underestimates hard-sphere self-diffusion "
            "by a few percent at eta = 0.065, and for xi < 1 a tau0 above (2.45) (see Haff's law) "
            "raises the slope against ln t further."
        )
    return slopes


def _sde_notes(cfg, by_id):
    c8 = _thesis_coefficients(0.8)
    cq = {
        xi: theory.langevin_coefficients(
            n=cfg.n3, radius=cfg.r3, volume=1.0, restitution=xi, temperature0=THESIS_T0
        )
        for xi in (1.0, 0.8)
    }
    g_max = max(c.gamma0 for c in cq.values()) * 0.01
    g_dt1, g_thesis = cq[0.8].gamma0, c8.gamma0
    sde = [
        f"Euler-Maruyama at dt = 0.01 (gamma0 dt up to {g_max:.3f} here) biases the stationary "
        f"<v^2> by up to 2 / (2 - gamma0 dt) - 1 = {2 / (2 - g_max) - 1:.1%}; the theory includes "
        "the transient of the thesis' fixed initial speed sqrt(2).",
        f"At dt = 1 (Fig. 4.20) gamma0 dt = {g_dt1:.1f} for xi = 0.8 here"
        + (
            ", past Euler-Maruyama's stability limit 2, so the figure shows the exact scheme there."
            if g_dt1 >= 2
            else ", within Euler-Maruyama's stability limit 2."
        )
        + (
            f"  With the thesis' coefficients gamma0 dt = {g_thesis:.1f}: its dt = 1 curve cannot "
            "have been Euler-Maruyama as printed."
            if g_thesis >= 2
            else ""
        ),
        "UDSBM is a model of the granular gas, not the gas: it tracks the EDMD MSD only up to "
        "O(1 - xi), because its velocity autocorrelation (2.111) differs from the gas' (2.77) "
        "unless gamma0 tau0 >> 1 (thesis 4.2.2); here gamma0 tau0 = "
        f"{cq[0.8].gamma0 * cq[0.8].tau0:.1f} at xi = 0.8.",
    ]
    return sde


def _ergodicity_notes(cfg, by_id):
    ud = by_id["ergodicity.udsbm"]
    ergodicity = [
        "Theory: for the Langevin model the ratio is 1 (the thermal initial <v^2> makes its "
        "increments stationary); for UDSBM it is the expected time average over the same windows, "
        "from the velocity correlations of the linear SDE, over its ensemble MSD."
    ]
    if ud["ours"] + SIGMA * ud["ours_error"] < 1:
        ergodicity.append(
            "UDSBM's time average stays below its ensemble MSD: it is not ergodic, as in the "
            "thesis and ref. [15]."
        )
    ergodicity.append(
        "Fig. 4.23 sets its time averages for t_stop = "
        + ", ".join(f"{t:g}" for t in cfg.tamsd_t_stops)
        + " beside their theory."
    )
    return ergodicity


def _clustering_notes(cfg, by_id):
    from . import reproduce_clustering

    return reproduce_clustering.notes(by_id)


def _visco_notes(cfg, by_id):
    from . import reproduce_visco

    return reproduce_visco.notes(by_id)


def _hcs_notes(cfg, by_id):
    from . import reproduce_driven

    return reproduce_driven.hcs_notes(by_id)


def _driven_notes(cfg, by_id):
    from . import reproduce_driven

    return reproduce_driven.driven_notes(by_id)


def _vibrated_notes(cfg, by_id):
    from . import reproduce_vibrated

    return reproduce_vibrated.notes(by_id)


def _gravity_notes(cfg, by_id):
    from . import reproduce_gravity

    return reproduce_gravity.notes(by_id)


def _rough_notes(cfg, by_id):
    return [
        "Theory: the two-temperature cooling of rough spheres and disks (Huthmann & "
        "Zippelius 1997; Luding, Huthmann, McNamara & Zippelius 1998) with Maxwellian "
        "velocities and spins. The 3D ratios T_rot/T_tr have come out 2-3% below it where the "
        "disks agree, which the velocity-spin correlations it leaves out may explain; Walton's "
        "row is against the rule's own Maxwellian mean field, not a published simulation."
    ]


def _trap_notes(cfg, by_id):
    return [
        "The exact scheme has no step error and each run starts in the trap's stationary "
        "state, so the MSD's plateau is 2 d T / k in every damping regime (Uhlenbeck & "
        "Ornstein 1930); docs/langevin_forces.md also shows where Euler-Maruyama fails."
    ]


def _transport_notes(cfg, by_id):
    return [
        "One long run per packing, errors from blocks of it. Enskog's first Sonine value is "
        "the answer only at low packing (the higher Sonine orders add 1.6% to the "
        "viscosity); at packing 0.30 correlated collisions change it (Alder, Gass & "
        "Wainwright 1970). The Green-Kubo and NEMD viscosities are two routes to one number "
        "and must agree within their errors."
    ]


def _diffusion_notes(cfg, by_id):
    from . import reproduce_transport

    n = reproduce_transport._diffusion_sizes(cfg)[0]
    eta = math.pi / 12.0  # n sigma^3 = 0.5
    box = (n / 0.5) ** (1.0 / 3.0)
    visc = float(theory.enskog_viscosity(eta, radius=0.5, temperature=1.0))
    d = float(theory.pieprzyk_diffusion(eta, radius=0.5, temperature=1.0))
    term = theory.diffusion_infinite_system(box, diffusion=d, viscosity=visc, temperature=1.0)
    share = float(term) / d - 1.0
    return [
        "Against Pieprzyk, Bannerman, Branka, Chudak & Heyes' 2019 MD values for the infinite "
        "system (theory.pieprzyk_diffusion, as transcribed in a public script), errors from "
        "independent runs. The MSD's slope is taken past the decay of the box's slowest "
        "shear mode, where the velocity correlation's t^-3/2 tail is cut off: over 10-20 "
        "mean free times it is still 6% short at n sigma^3 = 0.5. The Yeh-Hummer "
        f"correction to infinite N, with Enskog's viscosity, is {share:.0%} of D at N = {n} "
        "and n sigma^3 = 0.5; our own N-dependence is 11 +- 8% weaker than it there and 34 "
        "+- 16% at n sigma^3 = 0.1, where the correction is smaller "
        "(docs/stress.md). Enskog neglects correlated collisions, which raise D by 35% at "
        "n sigma^3 = 0.5."
    ]


def _eos_notes(cfg, by_id):
    return [
        "Against Pieprzyk, Bannerman, Branka, Chudak & Heyes' 2019 fit of the equation of "
        "state to molecular dynamics (theory.pieprzyk_compressibility), good to ~1e-4; finite "
        "N shifts the fluid's structure by O(1/N). The mean free time follows exactly from "
        "the contact value g(sigma) = (Z - 1) / (4 eta). Carnahan-Starling lies 0.2% below "
        "the fit at packing 0.45."
    ]


def _shear_notes(cfg, by_id):
    return [
        "Against the Enskog kinetic theory of uniform shear flow, its second-moment balance "
        "closed with the anisotropic Gaussian (theory.usf_enskog), whose own uncertainty is "
        "that of the closure: 1.3% at restitution 0.9 and 4% at 0.7 in the dilute gas "
        "(Grad's linear closure against it). The rows' text gives the Navier-Stokes balance "
        "(Garzo & Dufty 1999), which uniform shear flow lies beyond by more as the "
        "restitution falls; the published Grad solutions (Santos, Garzo & Dufty 2004; "
        "Montanero, Garzo, Alam & Luding 2006) could not be read for this version."
    ]


# The sections of the report: (title, row id prefix, notes(cfg, by_id) -> sentences)
SECTIONS = (
    ("Energy (Fig. 4.2)", "energy.", _energy_notes),
    ("Speed distributions (Table 4.1, Figs 4.5-4.7)", "table4.1.", _speed_notes),
    ("Haff's law (Fig. 4.10)", "haff.", _haff_notes),
    ("Long-time MSD slopes (App. F)", "msd.slope.", _slope_notes),
    ("Langevin and UDSBM (Figs 4.17-4.20)", "sde.", _sde_notes),
    ("Ergodicity (Figs 4.21-4.23)", "ergodicity.", _ergodicity_notes),
    ("Where homogeneous cooling ends (clustering)", "cluster.", _clustering_notes),
    ("Viscoelastic gases", "visco.", _visco_notes),
    ("The cooling state's velocity distribution (a2)", "hcs.", _hcs_notes),
    ("Gases driven by white noise", "driven.", _driven_notes),
    ("A gas kept hot by a vibrating wall", "vibrated.", _vibrated_notes),
    ("Gravity: the hydrostatic profile", "gravity.", _gravity_notes),
    ("Rough particles", "rough.", _rough_notes),
    ("Forces in the Langevin model", "langevin.trap.", _trap_notes),
    ("The elastic fluid's viscosity", "viscosity.", _transport_notes),
    ("The elastic fluid's self-diffusion", "diffusion.", _diffusion_notes),
    ("The elastic fluid's equation of state and collision rate", "eos.", _eos_notes),
    ("Uniform shear flow", "shear.", _shear_notes),
)


def report(rows, cfg, names, seconds):
    """The text of ``report.md``: the table, a sentence per row generated from it, the
    physics of each section and the figures."""
    lines = [
        "# Thesis chapter 4, reproduced by granular",
        "",
        f"System: N = {cfg.n3}, r = {cfg.r3:.4g} (3D), N = {cfg.n2}, r = {cfg.r2:.4g} (2D); "
        f"{cfg.runs_few} runs where the thesis used 4, {cfg.runs_many} where it used 20"
        + (" (quick mode: small sizes, short times)" if cfg.quick else "")
        + f". Took {seconds:.0f} s.",
        "Errors are standard errors of the mean over the runs (central limit theorem); 'agrees' "
        f"means within {SIGMA:g} of them.",
        "",
        "| id | quantity | ours | runs | thesis | theory | ours/theory - 1 |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        rel = f"{r['ours'] / r['theory'] - 1:+.2%}" if r["theory"] else "--"
        quantity = r["quantity"].replace("|", "\\|")
        lines.append(
            f"| {r['id']} | {quantity} | {_fmt(r['ours'], r['ours_error'])} | {r['runs'] or '--'} "
            f"| {_num(r['thesis'])} | {_num(r['theory'])} | {rel} |"
        )
    lines += ["", "## Where we agree, and where not"]
    by_id = {r["id"]: r for r in rows}
    for title, prefix, notes in SECTIONS:
        mine = [r for r in rows if r["id"].startswith(prefix)]
        if not mine:  # an experiment left out (--only)
            continue
        lines += ["", f"### {title}", ""]
        lines += [_sentence(r) for r in mine]
        lines += ["", " ".join(notes(cfg, by_id))]
    lines += [
        "",
        "### Slips of the thesis, corrected",
        "",
        "Isotropic initial directions instead of eq. 3.3 (a uniform polar angle puts too much "
        "speed along z), the mean collision time of (2.42) instead of (2.70)-(2.71) (which make "
        "it proportional to sqrt(T)), and the Euler-Maruyama noise term sqrt(2D) gamma dW.",
        "",
        "## Figures",
        "",
    ]
    lines += [f"![{n}]({n})" for n in names]
    return "\n".join(lines) + "\n"
