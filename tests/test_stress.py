"""The stress (pressure) tensor of the event-driven engine (csrc/stress.h): against the
slow reference, its trace against the scalar pressure, symmetry and isotropy in
equilibrium, and what it refuses."""

import numpy as np
import pytest

from granular import Scene, Simulation

from helpers import reference_edmd
from helpers.scenes import reference_scene


@pytest.mark.parametrize(
    "dim, boundary, xi, mixture",
    [
        (2, "periodic", 1.0, False),
        (3, "periodic", 0.8, True),
        (2, "walls", 0.9, True),
        (3, "walls", 1.0, False),
    ],
)
def test_tensor_agrees_with_slow_reference(dim, boundary, xi, mixture):
    """The cumulative collisional sum r_a dp_b and kinetic integral at every sample equal
    the O(N^2) reference's (which sums the kinetic tensor step by step) to 1e-8 of their
    size: the same events, so only rounding (amplified by chaos, see
    test_simulation.test_agrees_with_slow_reference) separates them."""
    s = reference_scene(dim, boundary, xi, mixture)
    times = np.linspace(0.0, 1.0, 11)
    sim = Simulation(s, stress=True)
    tr = sim.run(t_stop=1.0, sample_times=times)
    assert sim.stats["pair_collisions"] >= s.n
    ref: dict = {}
    reference_edmd.run_scene(s, 1.0, times, tensors=ref)
    for ours, theirs in (
        (tr.stress_collisional, ref["collisional"]),
        (tr.kinetic_time_tensor, ref["kinetic_time"]),
    ):
        scale = np.abs(theirs).max()
        assert scale > 0
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-8 * scale)
    # the instantaneous kinetic tensor is the velocities' own
    k = np.einsum("i,tia,tib->tab", s.masses, tr.velocities, tr.velocities)
    np.testing.assert_allclose(tr.kinetic_tensor, k, rtol=1e-13, atol=0)


@pytest.mark.parametrize(
    "dim, boundary, shell",
    [(2, "periodic", 0.0), (3, "periodic", 0.25), (3, "walls", 0.0), (2, "walls", 0.0)],
)
def test_trace_over_d_is_the_scalar_pressure(dim, boundary, shell):
    """trace(P) / d equals stats["pressure"] and Trajectory.pressure to rounding, not bit
    for bit: the tensor sums r_a dp_a and m v_a v_a in another order than the virial and
    the kinetic-energy integral do.  Between walls too (neither counts wall impulses).
    stats from an inelastic gas (the kinetic part changes throughout: its integral is
    exact in both); Trajectory.pressure, whose kinetic mean is a trapezoid over the
    samples (exact only for constant energy), from an elastic one."""
    n = 200
    r = 0.03 if dim == 3 else 0.015
    for xi in (0.9, 1.0):
        s = Scene.random(n, r, dim=dim, boundary=boundary, restitution=xi, temperature=1.0, seed=4)
        sim = Simulation(s, stress=True, shell=shell)
        sim.run(stop_when={"collisions_per_particle": 20}, store=())
        st = sim.stats
        trace = np.trace(np.array(st["pressure_tensor"])) / dim
        assert trace == pytest.approx(st["pressure"], rel=1e-13)
    tr = sim.run(sim.time + 0.2, sample_times=np.linspace(sim.time, sim.time + 0.2, 5))
    p = tr.pressure_tensor()
    assert np.trace(p) / dim == pytest.approx(tr.pressure(), rel=1e-13)
    windows = tr.pressure_tensor(per_window=True)
    assert windows.shape == (4, dim, dim)
    # the whole run's average is the windows' time-weighted mean
    np.testing.assert_allclose(
        np.average(windows, axis=0, weights=np.diff(tr.times)), p, rtol=1e-12
    )
    assert tr.kinetic_pressure_tensor().shape == (5, dim, dim)


def test_symmetric_and_isotropic_in_equilibrium():
    """Smooth spheres: the impulse is along r, so the tensor is symmetric to rounding
    (1e-12 of the pressure).  In equilibrium it is also isotropic: over 40 independent
    windows of ~5 collisions per particle (the stress autocorrelation decays within ~1
    collision time), the mean of each off-diagonal element and of each difference of
    diagonal elements lies within 4.5 standard errors of 0 (each of the 6 tests fails by
    chance with probability < 1e-4 for Gaussian means; the window count keeps
    Student's tail close to it)."""
    s = Scene.random(500, 0.05, dim=3, temperature=1.0, seed=5)  # packing ~0.26
    sim = Simulation(s, stress=True)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    t0 = sim.time
    tau = t0 / 20.0  # ~ one collision time per particle
    times = t0 + 5 * tau * np.arange(41)
    tr = sim.run(times[-1], sample_times=times, store=())
    w = tr.pressure_tensor(per_window=True)
    p = np.trace(tr.pressure_tensor()) / 3
    assert np.abs(w - np.swapaxes(w, 1, 2)).max() < 1e-12 * p
    m = len(w)
    for x in (
        w[:, 0, 1],
        w[:, 0, 2],
        w[:, 1, 2],
        w[:, 0, 0] - w[:, 1, 1],
        w[:, 1, 1] - w[:, 2, 2],
        w[:, 0, 0] - w[:, 2, 2],
    ):
        se = x.std(ddof=1) / np.sqrt(m)
        assert abs(x.mean()) < 4.5 * se, (x.mean(), se)


def test_stress_must_be_asked_for_and_a_bool():
    s = Scene.random(20, 0.05, dim=2, seed=1)
    tr = Simulation(s).run(0.1)
    assert tr.stress_collisional is None
    assert "pressure_tensor" not in Simulation(s).stats
    with pytest.raises(ValueError, match="stress=True"):
        tr.pressure_tensor()
    with pytest.raises(TypeError, match="stress must be True or False"):
        Simulation(s, stress="yes")  # type: ignore[arg-type]
    st = Simulation(s, stress=True).stats
    assert np.isnan(np.array(st["pressure_tensor"])).all()  # no time yet


@pytest.mark.parametrize("dim", [2, 3])
def test_gsd_carries_the_tensor_and_hoomds_pressure_tensor(dim, tmp_path):
    """granular.read gives the tensor's parts back to the bit; HOOMD's log field
    md/compute/ThermodynamicQuantities/pressure_tensor holds (xx, xy, xz, yy, yz, zz) of the
    window average since the previous frame (zeros for z in 2D), frame 0 the kinetic part."""
    gsd_hoomd = pytest.importorskip("gsd.hoomd")
    import granular

    s = Scene.random(50, 0.05 if dim == 2 else 0.08, dim=dim, seed=1)
    tr = Simulation(s, stress=True).run(1.0, sample_times=np.linspace(0, 1, 6))
    tr.write(tmp_path / "a.gsd")
    back = granular.read(tmp_path / "a.gsd")
    for name in ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor"):
        assert np.array_equal(getattr(back, name), getattr(tr, name)), name
    full = np.zeros((6, 3, 3))
    full[1:, :dim, :dim] = tr.pressure_tensor(per_window=True)
    full[0, :dim, :dim] = tr.kinetic_pressure_tensor()[0]
    with gsd_hoomd.open(tmp_path / "a.gsd") as f:
        for k, frame in enumerate(f):
            got = frame.log["md/compute/ThermodynamicQuantities/pressure_tensor"]
            p = full[k]
            assert np.array_equal(got, [p[0, 0], p[0, 1], p[0, 2], p[1, 1], p[1, 2], p[2, 2]])
    Simulation(s).run(1.0, sample_times=[0.0, 1.0]).write(tmp_path / "b.gsd")
    assert granular.read(tmp_path / "b.gsd").stress_collisional is None


def test_a_driven_gas_keeps_its_kinetic_tensor_through_the_kicks():
    """A random kick is an outside force: it changes the kinetic tensor (sum m v_a v_b, kept
    by differences) and nothing collisional.  After many kicks the kept tensor is still the
    velocities' own, and trace / d still the scalar pressure, to rounding."""
    from granular import WhiteNoise

    s = Scene.random(100, 0.03, dim=3, restitution=0.8, temperature=1.0, seed=2)
    s = s.replace(driving=WhiteNoise(0.5, 20.0, 7))
    sim = Simulation(s, stress=True)
    tr = sim.run(2.0, sample_times=np.linspace(0.0, 2.0, 5))
    assert sim.stats["kicks"] > 1000
    k = np.einsum("i,tia,tib->tab", s.masses, tr.velocities, tr.velocities)
    np.testing.assert_allclose(tr.kinetic_tensor, k, rtol=1e-12, atol=1e-12 * np.abs(k).max())
    st = sim.stats
    trace = np.trace(np.array(st["pressure_tensor"])) / 3
    assert trace == pytest.approx(st["pressure"], rel=1e-12)
