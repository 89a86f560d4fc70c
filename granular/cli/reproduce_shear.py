"""The reproduction's shear experiment: the uniform shear flow (USF) of an inelastic
hard-sphere gas, where viscous heating balances collisional cooling without a thermostat.

3D periodic cube with Lees-Edwards images (flow x, gradient y), packing 0.2, N = 500 full
(256 quick), restitution 0.9 and 0.7.  Each run starts at the Navier-Stokes steady state
(T = 1, the linear flow profile in place, ``transport.with_shear_profile``) and runs for
``SPAN`` time units sigma / sqrt(T / m) (~900 collisions per particle full); the first
``TRANSIENT`` of it is left out (the temperature relaxes within a few 1 / zeta, ~20 time
units at 0.7).  From the stress tensor's exact window integrals (``shear_windows``):

- ``shear.temperature``: the steady reduced shear rate gamma* = gamma sigma / sqrt(T / m)
  (the steady temperature in the units kinetic theory gives it);
- ``shear.viscosity.granular``: eta* = -P_xy / gamma sigma^2 / sqrt(m T);
- ``shear.normal_stress``: the first normal-stress difference (P_xx - P_yy) / p (and the
  second, (P_yy - P_zz) / p, in the text).

Theory: the Enskog kinetic theory of USF, its second-moment balance closed with the
anisotropic Gaussian and solved without further approximation (``theory.usf_enskog``:
gamma*, eta*, N1, N2).  The published closed forms (Santos, Garzo & Dufty, Phys. Rev. E 69,
061303 (2004), Grad's method; Montanero, Garzo, Alam & Luding, Granular Matter 8, 103
(2006), with MD) could not be read for this version; the closure's own uncertainty is
second order in the anisotropy (``theory.usf_grad_dilute`` vs the dilute ``usf_enskog``:
1.3 % in gamma* at xi = 0.9, 4 % at 0.7).  The rows' text gives the Navier-Stokes balance
gamma^2 eta = (d / 2) n T zeta with Garzo & Dufty's coefficients (``theory.usf_shear_rate``,
``theory.usf_viscosity``) beside it, which misses the anisotropy altogether.

Errors: the steady part cut into 10 consecutive blocks, std / sqrt(10).
"""

from __future__ import annotations

import math

import numpy as np

from .. import Scene, Simulation, theory, transport

PACKING = 0.2
RESTITUTIONS = (0.9, 0.7)
SPAN = 200.0  # time units sigma / sqrt(T / m) at T = 1
TRANSIENT = 0.25  # the fraction of the run left out
SAMPLES = 200
BLOCKS = 10


def _sizes(cfg):
    return (256, 0.5) if cfg.quick else (500, 1.0)


def usf_run(xi, n, span, seed=31):
    """One sheared run at restitution ``xi`` (module docstring): (trajectory, sigma, the
    shear rate, the sample times)."""
    r = (PACKING / n / (4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sigma = 2.0 * r
    rate = float(theory.usf_shear_rate(PACKING, restitution=xi)) / sigma  # NS: T = 1
    scene = Scene.random(n, r, dim=3, temperature=1.0, seed=seed).replace(restitution=xi)
    scene = transport.with_shear_profile(scene, rate)
    times = np.linspace(0.0, span * sigma, SAMPLES + 1)
    sim = Simulation(scene, stress=True)
    tr = sim.run(float(times[-1]), sample_times=times)
    return tr, sigma, rate, times


def _blocks(x):
    b = np.array([c.mean() for c in np.array_split(np.asarray(x), BLOCKS)])
    return float(b.mean()), float(b.std(ddof=1) / math.sqrt(BLOCKS))


def usf_measure(tr):
    """The steady part's (gamma*, eta*, N1 / p, N2 / p) as (mean, error) pairs, and the
    windows' pressure tensors (W, 3, 3)."""
    w = transport.shear_windows(tr)
    volume = float(np.prod(tr.upper - tr.lower))
    kin, coll = tr.kinetic_time_tensor, tr.stress_collisional
    assert kin is not None and coll is not None
    p_win = (np.diff(kin, axis=0) + np.diff(coll, axis=0)) / (volume * np.diff(tr.times))[
        :, None, None
    ]
    steady = slice(int(TRANSIENT * len(w.times)), None)
    p = np.trace(p_win, axis1=1, axis2=2) / 3.0
    n1 = (p_win[:, 0, 0] - p_win[:, 1, 1]) / p
    n2 = (p_win[:, 1, 1] - p_win[:, 2, 2]) / p
    out = tuple(_blocks(x[steady]) for x in (w.shear_rate, w.viscosity, n1, n2))
    return out, w, p_win


def velocity_profile(tr, rate, bins=10):
    """Mean v_x (box velocities) in ``bins`` slabs along y over the steady samples, with
    the standard error of each slab's mean over samples: (centres, means, errors,
    the line rate (y - y_c))."""
    lo, hi = float(tr.lower[1]), float(tr.upper[1])
    start = int(TRANSIENT * len(tr.times))
    y = lo + np.mod(tr.positions[start:, :, 1] - lo, hi - lo)
    vx = tr.velocities[start:, :, 0]
    edges = np.linspace(lo, hi, bins + 1)
    k = np.clip(np.digitize(y, edges) - 1, 0, bins - 1)
    per_sample = np.array([[vx[s][k[s] == b].mean() for b in range(bins)] for s in range(len(y))])
    centres = 0.5 * (edges[1:] + edges[:-1])
    means = per_sample.mean(axis=0)
    errors = per_sample.std(axis=0, ddof=1) / math.sqrt(len(per_sample))
    return centres, means, errors, rate * (centres - 0.5 * (lo + hi))


def _fig_shear(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run both restitutions, write ``shear_profile.png`` and ``shear_stress.png``,
    return (file names, rows)."""
    n, scale = _sizes(cfg)
    rows = []
    f_prof, ax_prof = fig(1)
    f_st, (ax_p, ax_t) = fig(2)
    for k, xi in enumerate(RESTITUTIONS):
        tr, sigma, rate, _ = usf_run(xi, n, SPAN * scale)
        values, w, p_win = usf_measure(tr)
        (g, g_err), (e, e_err), (n1, n1_err), (n2, n2_err) = values
        g_ns = float(theory.usf_shear_rate(PACKING, restitution=xi))
        e_ns = float(theory.usf_viscosity(PACKING, restitution=xi))
        usf = theory.usf_enskog(PACKING, restitution=xi)
        t_ratio = (g_ns / g) ** 2  # T_sim / T_NS at the same gamma
        what = (
            f"3D, packing {PACKING}, xi = {xi}, N = {n}, Lees-Edwards, no thermostat, "
            f"{SPAN * scale:g} sigma / sqrt(T/m) after starting at the Navier-Stokes state, "
            f"first {TRANSIENT:g} left out, 10 blocks"
        )
        theory_is = (
            "theory: Enskog kinetic theory of USF with the anisotropic-Gaussian closure "
            "(theory.usf_enskog)"
        )
        suffix = f".xi{xi:g}"
        rows.append(
            row(
                "shear.temperature" + suffix,
                f"steady reduced shear rate gamma* = gamma sigma / sqrt(T/m) of uniform shear "
                f"flow ({what}); {theory_is}; the Navier-Stokes balance gamma^2 eta = (3/2) "
                f"n T zeta (Garzo & Dufty 1999) gives {g_ns:.4f}, a steady T {1 / t_ratio:.3f} "
                f"times the simulated one",
                g,
                g_err,
                None,
                None,
                float(usf.shear_rate),
            )
        )
        rows.append(
            row(
                "shear.viscosity.granular" + suffix,
                f"reduced shear viscosity eta* = -P_xy sigma^2 / (gamma sqrt(m T)) in steady "
                f"uniform shear flow ({what}); {theory_is}; Garzo & Dufty's Navier-Stokes "
                f"viscosity is {e_ns:.4f}",
                e,
                e_err,
                None,
                None,
                float(usf.viscosity),
            )
        )
        rows.append(
            row(
                "shear.normal_stress" + suffix,
                f"first normal-stress difference (P_xx - P_yy) / p in steady uniform shear "
                f"flow ({what}); second (P_yy - P_zz) / p = {n2:.4f} +- {n2_err:.4f} "
                f"(theory {float(usf.n2):.4f}); {theory_is}; zero at Navier-Stokes order",
                n1,
                n1_err,
                None,
                None,
                float(usf.n1),
            )
        )
        colour = f"C{k}"
        c, m, err, line = velocity_profile(tr, rate)
        ax_prof.errorbar(c / sigma, m * sigma, yerr=err * sigma, fmt="o", color=colour,
                         capsize=2, label=rf"$\xi$ = {xi}: mean $v_x$ in slabs")  # fmt: skip
        ax_prof.plot(c / sigma, line * sigma, color=colour, lw=0.8,
                     label=rf"$\xi$ = {xi}: $\dot\gamma\,(y - y_c)$")  # fmt: skip
        t_mid = w.times / sigma
        ax_p.plot(t_mid, -p_win[:, 0, 1] * sigma**3, color=colour, lw=0.8,
                  label=rf"$\xi$ = {xi}: $-P_{{xy}}$")  # fmt: skip
        ax_p.plot(t_mid, (p_win[:, 0, 0] - p_win[:, 1, 1]) * sigma**3, color=colour, lw=0.8,
                  ls="--", label=rf"$\xi$ = {xi}: $P_{{xx}} - P_{{yy}}$")  # fmt: skip
        ax_t.plot(t_mid, w.temperature, color=colour, lw=0.8, label=rf"$\xi$ = {xi}: simulated")
        ax_t.axhline(1.0, color="k", lw=0.6, ls=":")
        ax_t.axhline(t_ratio, color=colour, lw=0.6, ls="--", label=rf"$\xi$ = {xi}: steady mean")
        ax_t.axhline((g_ns / float(usf.shear_rate)) ** 2, color=colour, lw=0.8, ls="-.",
                     label=rf"$\xi$ = {xi}: Enskog USF")  # fmt: skip
    ax_prof.set_xlabel(r"$y / \sigma$")
    ax_prof.set_ylabel(r"$\langle v_x \rangle / \sqrt{T_{NS}/m}$")
    ax_prof.set_title(f"velocity profile, packing {PACKING}, N = {n}")
    ax_prof.legend(fontsize=7)
    for ax in (ax_p, ax_t):
        ax.axvline(TRANSIENT * SPAN * scale, color="0.7", lw=0.8)
        ax.set_xlabel(r"time / ($\sigma / \sqrt{T_{NS}/m}$)")
        ax.legend(fontsize=7)
    ax_p.set_ylabel(r"stress $\times \sigma^3 / T_{NS}$")
    ax_p.set_title("stress against time")
    ax_t.set_ylabel(r"$T / T_{NS}$ (dotted: Navier-Stokes)")
    ax_t.set_title("temperature against time")
    return [save(f_prof, out, "shear_profile.png"), save(f_st, out, "shear_stress.png")], rows
