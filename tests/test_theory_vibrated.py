"""theory.vibrated: the vibrating wall's work on a dilute gas (against the defining integral
and the engine), its leading order, and the steady temperature of the energy balance."""

import math

import numpy as np
import pytest
from scipy import integrate

from granular import Scene, Simulation, VibratingWall, theory


def _defining_integral(V, n, T, m, e, waveform):
    """(1 + e) m n <U int_{v<U} (U - v)^2 f(v) dv> over the phase, by quadrature."""
    s = math.sqrt(T / m)

    def at_phase(theta):
        U = V * (math.cos(theta) if waveform == "sine" else math.copysign(1.0, math.cos(theta)))
        f = lambda v: math.exp(-0.5 * (v / s) ** 2) / (s * math.sqrt(2 * math.pi))  # noqa: E731
        inner, _ = integrate.quad(lambda v: (U - v) ** 2 * f(v), -np.inf, U, epsabs=0, epsrel=1e-12)
        return U * inner

    mean, _ = integrate.quad(at_phase, 0, 2 * math.pi, limit=200, epsrel=1e-11)
    return (1 + e) * m * n * mean / (2 * math.pi)


@pytest.mark.parametrize("waveform", ["sine", "triangle"])
@pytest.mark.parametrize("z", [0.05, 0.7, 3.0])
def test_wall_power_is_its_defining_integral(waveform, z):
    T, m, n, e = 2.0, 1.5, 300.0, 0.8
    V = z * math.sqrt(T / m)
    got = theory.wall_power(
        V, density=n, temperature=T, mass=m, wall_restitution=e, waveform=waveform
    )
    assert got == pytest.approx(_defining_integral(V, n, T, m, e, waveform), rel=1e-8)


@pytest.mark.parametrize("waveform", ["sine", "triangle"])
def test_the_leading_order_is_the_small_speed_limit(waveform):
    """wall_power / wall_power_leading - 1 = O((V / s)^2): below (V/s)^2 for small V/s."""
    for z in (1e-3, 1e-2, 0.1):
        exact = theory.wall_power(z, density=10.0, temperature=1.0, waveform=waveform)
        lead = theory.wall_power_leading(z, density=10.0, temperature=1.0, waveform=waveform)
        assert abs(exact / lead - 1) < z * z


def test_the_balance_temperature_scales_as_v_squared_and_balances():
    """The balance is homogeneous in V and sqrt(T): T(2V) = 4 T(V) exactly (the dilute
    exponent 2), and at T the wall's input per volume equals Haff's loss d n T / tau0."""
    kw = dict(density=400.0, radius=0.01, restitution=0.9, wall_distance=0.9, dim=2)
    t1 = theory.vibrated_temperature(0.3, **kw)
    t2 = theory.vibrated_temperature(0.6, **kw)
    assert t2 / t1 == pytest.approx(4.0, rel=1e-10)
    assert math.log(t2 / t1) / math.log(2) == pytest.approx(theory.DILUTE_EXPONENT, rel=1e-10)
    gain = theory.wall_power(0.3, density=400.0, temperature=t1)
    tau0 = theory.haff_tau0(density=400.0, radius=0.01, restitution=0.9, temperature0=t1, dim=2)
    assert gain == pytest.approx(0.9 * 2 * 400.0 * t1 / tau0, rel=1e-10)
    with pytest.raises(ValueError, match="elastic"):
        theory.vibrated_temperature(0.3, **{**kw, "restitution": 1.0})


@pytest.mark.parametrize("g", [0.5, 4.0])
def test_the_bed_balance_integrates_the_barometric_column(g):
    """The bed's temperature balances, for any g, the floor's input at the barometric
    profile's floor density n0 = c m g / T against Haff's loss d n T / tau0(n) (dilute,
    eta = 0) integrated by quadrature up the column n0 exp(-z m g / T); and T(2V) = 4 T(V)."""
    n, area, r, xi, e = 150.0, 0.8, 0.01, 0.9, 0.95
    kw = dict(n=n, area=area, radius=r, restitution=xi, wall_restitution=e, dim=2)
    T = theory.vibrated_bed_temperature(0.4, **kw)
    assert theory.vibrated_bed_temperature(0.8, **kw) / T == pytest.approx(4.0, rel=1e-10)
    n0 = (n / area) * g / T
    gain = theory.wall_power(0.4, density=n0, temperature=T, wall_restitution=e)

    def loss_density(z):
        local = n0 * math.exp(-z * g / T)
        tau0 = theory.haff_tau0(
            density=local, radius=r, restitution=xi, temperature0=T, dim=2, eta=0.0
        )
        return 2 * local * T / tau0

    # to 60 scale heights: the rest is exp(-120) of the loss
    loss, _ = integrate.quad(loss_density, 0, 60 * T / g, epsrel=1e-12, limit=200)
    assert gain == pytest.approx(loss, rel=1e-9)
    with pytest.raises(ValueError, match="elastic"):
        theory.vibrated_bed_temperature(0.4, **{**kw, "restitution": 1.0})


@pytest.mark.slow
def test_the_engine_walls_work_is_the_theorys():
    """A near-ideal 2D gas (N = 4000 disks of radius 0.001, elastic) heated by a sine wall of
    A = 0.002, omega = 100 (V = 0.2, a fifth of the thermal speed: the small-amplitude limit,
    A omega / s = A / (s / omega) small): the wall's measured power in each of 40 windows,
    over wall_power at the window's normal temperature (the mean of v_y^2 at its ends),
    averages to 1 within 4 standard errors (the windows' spread, ~4 %).  The work per hit
    has the sign of U (its mean is second order in U), hence the many hits (~7e4).  At
    V / s = 0.5 the same measurement gives ~0.9: the wall's excursion then matters
    (docs/vibrated.md).  Cells 20 diameters wide: fewer crossings in this dilute gas."""
    N, r, A, omega = 4000, 0.001, 0.002, 100.0
    s = Scene.random(
        N, r, dim=2, box=((0, 2 * A), (1, 1)), boundary="walls", temperature=1.0, seed=4
    )
    wall = VibratingWall(1, "lower", A, omega)
    sim = Simulation(s.replace(box=1.0, vibrating_wall=wall), cell_factor=20)
    n = N / ((1 - 2 * r) * (1 - 2 * r))  # the centres' reach (the wall's sweep is 0.4 %)
    ratios = []
    t_before = np.mean(s.velocities[:, 1] ** 2)
    for _ in range(40):
        before, t0 = sim.stats, sim.time
        sim.run(t_stop=t0 + 0.25, store=())
        t_after = np.mean(sim.scene.velocities[:, 1] ** 2)
        power = (sim.stats["wall_work"] - before["wall_work"]) / (sim.time - t0)
        T = 0.5 * (t_before + t_after)
        ratios.append(power / theory.wall_power(wall.peak_velocity, density=n, temperature=T))
        t_before = t_after
    ratios = np.array(ratios)
    se = ratios.std(ddof=1) / math.sqrt(len(ratios))
    assert se < 0.06
    assert abs(ratios.mean() - 1) <= 4 * se
