"""The hydrostatic profile of an elastic gas under gravity (theory.hydrostatic_density) and
profiles along an axis (analysis.profile): the theory's limits and its equation of state,
then an EDMD column against it, with a tolerance from the statistics."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, simpson

from granular import analysis, theory
from granular.cli import reproduce_gravity
from granular.trajectory import Trajectory


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("eta", [0.01, 0.2, 0.45, 0.6])
def test_excess_chemical_potential_is_the_integral_of_granulars_equation_of_state(dim, eta):
    """mu_ex / T = int_0^eta (Z - 1) / x dx + Z - 1 with Z = theory.compressibility_factor
    (quadrature to 1e-12): the closed forms are the equation of state granular uses."""
    z = theory.compressibility_factor

    def integrand(x):
        return (z(x, dim=dim) - 1) / x

    want = quad(integrand, 0, eta, epsabs=1e-13)[0] + z(eta, dim=dim) - 1
    assert theory.excess_chemical_potential(eta, dim=dim) == pytest.approx(want, rel=1e-12)


def test_the_dilute_profile_is_barometric_and_holds_its_count():
    """Tiny disks: exp(-z / h) to the first-order excess (~1e-7); any gas: the profile
    integrates to the count between bottom and top (Simpson on 30001 points, not the
    theory's own grid: 1e-9), and is 0 outside."""
    h, count = 0.1, 10.0
    z = np.linspace(0.0, 1.0, 11)
    kw = dict(area=1.0, bottom=0.0, top=1.0, gravity=1.0, temperature=h, dim=2)
    n = theory.hydrostatic_density(z, n=count, radius=1e-5, **kw)
    baro = count / (h * -math.expm1(-1 / h)) * np.exp(-z / h)
    np.testing.assert_allclose(n, baro, rtol=2e-7)
    fine = np.linspace(0.0, 1.0, 30001)
    for dim, radius, count in ((2, 0.01, 800.0), (3, 0.03, 500.0)):
        kw["dim"] = dim
        total = simpson(theory.hydrostatic_density(fine, n=count, radius=radius, **kw), x=fine)
        assert total == pytest.approx(count, rel=1e-9)
        assert theory.hydrostatic_density(-0.01, n=count, radius=radius, **kw) == 0.0
        # denser at the bottom than the barometric law's exp(-z/l) would keep it: the
        # excess pressure of hard cores lifts the gas (a flatter profile)
        ratio = theory.hydrostatic_density(np.array([0.0, 0.5]), n=count, radius=radius, **kw)
        assert ratio[0] / ratio[1] < math.exp(0.5 / h)


def test_bad_profile_arguments_are_refused():
    kw = dict(n=10.0, area=1.0, bottom=0.0, top=1.0, radius=0.01, gravity=1.0, temperature=1.0)
    with pytest.raises(ValueError, match="top must lie above bottom"):
        theory.hydrostatic_density(0.5, **{**kw, "top": 0.0})
    with pytest.raises(ValueError, match="more particles than fit"):
        theory.hydrostatic_density(0.5, **{**kw, "n": 1e6, "radius": 0.1})
    with pytest.raises(ValueError, match="gravity must be positive"):
        theory.hydrostatic_density(0.5, **{**kw, "gravity": 0.0})


def test_profile_counts_bins_and_blocks_exactly():
    """A hand-made trajectory: particles at known heights and velocities give known
    densities, temperatures and mean velocities per bin, and the blocks' spread."""
    x = np.array([[[0.5, 0.1], [0.5, 0.2], [0.5, 0.7], [0.5, 0.8]]] * 4)
    v = np.array([[[1.0, 0.0], [-1.0, 0.0], [0.0, 2.0], [0.0, 2.0]]] * 4)
    v[2:, 2:, 1] = 4.0  # the upper pair moves faster in the later blocks
    zeros = np.zeros(4)
    tr = Trajectory(
        np.arange(4.0), x, v, zeros, np.zeros((4, 2)), zeros.astype(np.int64),
        zeros.astype(np.int64), zeros, zeros, masses=np.ones(4), radii=np.full(4, 0.01),
        lower=np.zeros(2), upper=np.ones(2), boundary="walls", stop_reason="time",
    )  # fmt: skip
    p = analysis.profile(tr, bins=2, blocks=2)
    np.testing.assert_allclose(p.density, [4.0, 4.0])  # two centres in each half of a 1 x 1 box
    np.testing.assert_allclose(p.temperature[0], [1.0, 0.0])  # u = 0, T_x = <v_x^2>
    np.testing.assert_allclose(p.temperature[1], [0.0, 0.0])
    np.testing.assert_allclose(p.velocity[1], [0.0, 3.0])
    np.testing.assert_allclose(p.velocity_error[1], [0.0, 1.0])  # blocks 2 and 4: std/sqrt 2
    with pytest.raises(ValueError, match="blocks must be an integer from 2"):
        analysis.profile(tr, blocks=5)


# the chi^2 bound of 20 bins, each a mean over 10 blocks divided by its standard error (a
# t variable of 9 degrees of freedom): its 0.999 quantile, 82.6 (Monte Carlo, 2e5 draws;
# the mean is 25.7 = 20 * 9/7)
CHI2_20_BINS = 82.6


def test_an_elastic_column_has_the_hydrostatic_profile():
    """One column of reproduce_gravity (N = 400 disks, scale height ~40 diameters, area
    fraction ~0.13 at the floor), the profile away from the walls in 20 bins with 10
    blocks of 1 time unit (the sound crossing time of the column ~1.5, so neighbouring
    blocks are partly correlated: the bound below is for independent blocks, at 0.1 %):
    against the hydrostatic theory chi^2 <= 82.6, against the barometric law at the same
    count and temperature far beyond it (the test can fail: the hard cores' pressure is
    resolved).  The temperature per component is uniform along the column (equilibrium:
    chi^2 of T_a(z) - T over 40 values <= 130, the 0.999 quantile of the same t^2 sum for
    40 terms) and the mean velocity zero (same bound)."""
    r = reproduce_gravity.column(3, equilibrate=20.0, measure=10.0)
    p = r["profile"]
    chi2 = np.sum(((p.density - r["theory"]) / p.density_error) ** 2)
    assert chi2 <= CHI2_20_BINS
    assert np.sum(((p.density - r["barometric"]) / p.density_error) ** 2) > 10 * CHI2_20_BINS
    t = np.sum(((p.temperature - r["temperature"]) / p.temperature_error) ** 2)
    assert t <= 130
    assert np.sum((p.velocity / p.velocity_error) ** 2) <= 130
