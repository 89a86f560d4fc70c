"""The stress tensor in a sheared (Lees-Edwards) box (csrc/stress.h): its kinetic part is
that of the peculiar velocities V = v - shear_rate (y - y_c) e_x, integrated exactly in
flight; its collisional part goes through the images.  Against the slow reference, the
exact energy balance of the peculiar motion, the virial, checkpoints."""

import numpy as np
import pytest

from granular import Scene, Simulation

from helpers import reference_edmd


def _sheared(dim, radius, rate, xi=1.0, n=12, box=3.0, seed=7, offset=0.3):
    s = Scene.random(n, radius, dim=dim, box=box, temperature=1.0, seed=seed)
    return s.replace(shear_rate=rate, shear_offset=offset, restitution=xi)


def _box_y(tr, s):
    """The y positions in the box (the unwrapped y differs from it by whole L_y)."""
    lo, ly = s.lower[1], s.upper[1] - s.lower[1]
    return lo + np.mod(tr.positions[..., 1] - lo, ly)


@pytest.mark.parametrize(
    "dim,radius,rate,xi,n",
    [
        (2, 0.2, 3.0, 0.9, 12),
        (2, 0.2, -2.0, 1.0, 12),
        (3, 0.25, 2.5, 0.8, 16),
        (3, 0.25, -2.0, 1.0, 16),
    ],
)
def test_tensor_agrees_with_slow_reference(dim, radius, rate, xi, n):
    """The cumulative collisional sum (dr through the image that touched) and the
    peculiar kinetic integral equal the O(N^2) reference's, which integrates sum m V_a V_b
    by Simpson's rule step by step (exact for its quadratic time dependence), to 1e-7 of
    their size: the same events, so only rounding amplified by chaos separates them
    (test_shear.test_agrees_with_slow_reference: ~1e-9 at this length).  A kinetic part
    in the box's velocities, a missed face crossing or the impulse taken in the wrong
    frame is off by O(1)."""
    s = _sheared(dim, radius, rate, xi, n=n)
    times = np.linspace(0.0, 2.0, 13)
    sim = Simulation(s, stress=True)
    tr = sim.run(t_stop=2.0, sample_times=times)
    assert sim.stats["pair_collisions"] >= s.n
    _, _, img = sim._engine.state()
    assert np.abs(img[:, 1]).sum() >= 4  # crossings of the sheared faces
    ref: dict = {}
    reference_edmd.run_scene(s, 2.0, times, tensors=ref)
    for ours, theirs in (
        (tr.stress_collisional, ref["collisional"]),
        (tr.kinetic_time_tensor, ref["kinetic_time"]),
    ):
        scale = np.abs(theirs).max()
        assert scale > 0
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-7 * scale)
    # the instantaneous kinetic tensor is that of the peculiar velocities
    vp = tr.velocities.copy()
    vp[..., 0] -= rate * (_box_y(tr, s) - 0.5 * (s.lower[1] + s.upper[1]))
    k = np.einsum("i,tia,tib->tab", s.masses, vp, vp)
    np.testing.assert_allclose(tr.kinetic_tensor, k, rtol=0, atol=1e-12 * np.abs(k).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_viscous_heating_is_minus_rate_volume_p_yx(dim):
    """The peculiar kinetic energy obeys d E/dt = -shear_rate V P_yx - (collisional loss):
    in flight dV/dt = -shear_rate V_y e_x, at a collision through an image E changes by
    -shear_rate dr_y dp_x.  In an elastic gas the window integral is an identity, so the
    heating equals -shear_rate (int K_xy dt + W_yx) to rounding (1e-10 of the heating,
    over some 10^3 collisions); an inelastic gas loses energy on top (the residual is a loss:
    negative).  The energies come from the instantaneous K, the heating from the
    integrals: two separate sums."""
    rate = 1.5
    for xi in (1.0, 0.8):
        s = Scene.random(
            60, 0.4 if dim == 3 else 0.2, dim=dim, box=5.0, temperature=1.0, seed=3
        ).replace(shear_rate=rate, restitution=xi)
        times = np.linspace(0.0, 4.0, 9)
        sim = Simulation(s, stress=True)
        tr = sim.run(t_stop=4.0, sample_times=times)
        assert sim.stats["pair_collisions"] > 5 * s.n
        energy = 0.5 * np.trace(tr.kinetic_tensor, axis1=1, axis2=2)
        heating = -rate * (tr.kinetic_time_tensor[:, 0, 1] + tr.stress_collisional[:, 1, 0])
        gained, heated = np.diff(energy), np.diff(heating)
        assert np.all(heated > 0)  # the shear heats: P_yx < 0
        if xi == 1.0:
            np.testing.assert_allclose(gained, heated, rtol=0, atol=1e-10 * heated.max())
        else:
            loss = heated - gained
            assert np.all(loss > 1e-3 * heated)


def test_trace_of_the_collisional_part_is_the_virial():
    """trace(W) is the virial sum dr . dp (through the images) that the scalar pressure
    uses, to rounding (the same products summed in another order)."""
    s = _sheared(3, 0.4, 2.0, xi=0.9, n=60, box=5.0, offset=0.0)
    sim = Simulation(s, stress=True)
    sim.run(t_stop=3.0, store=())
    st = sim.stats
    assert st["pair_collisions"] > 5 * s.n
    trace = np.trace(np.array(st["stress_collisional"]))
    assert trace == pytest.approx(st["virial"], rel=1e-12)


def test_a_checkpoint_continues_the_sheared_tensor_bit_for_bit(tmp_path):
    s = _sheared(3, 0.3, 0.7, xi=0.9, n=60, box=5.0)
    a = Simulation(s, stress=True)
    a.run(t_stop=1.3, store=())
    a.save(tmp_path / "c.npz")
    b = Simulation.load(tmp_path / "c.npz")
    times = np.linspace(1.3, 3.0, 5)
    ta = a.run(t_stop=3.0, sample_times=times)
    tb = b.run(t_stop=3.0, sample_times=times)
    for name in ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor"):
        assert np.array_equal(getattr(ta, name), getattr(tb, name))
    assert a.stats["pressure_tensor"] == b.stats["pressure_tensor"]


def test_gsd_carries_the_sheared_tensor(tmp_path):
    """Written and read back, the sheared run's tensor parts are the same bits."""
    import granular

    s = _sheared(3, 0.3, 0.8, xi=0.9, n=40, box=5.0, offset=0.0, seed=3)
    tr = Simulation(s, stress=True).run(2.0, sample_times=np.linspace(0.0, 2.0, 5))
    tr.write(tmp_path / "s.gsd")
    back = granular.read(tmp_path / "s.gsd")
    for name in ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor"):
        assert np.array_equal(getattr(tr, name), getattr(back, name))


def test_the_pressure_of_a_sheared_gas_is_the_peculiar_one():
    """The scalar pressure of a sheared box counts the velocities less the mean flow: with
    the stress tensor it is its trace / d (stats and Trajectory alike); without it, stats
    says NaN and Trajectory.pressure refuses, rather than count the flow's energy."""
    s = Scene.random(200, 0.03, dim=3, seed=3).replace(shear_rate=2.0)
    sim = Simulation(s, stress=True)
    tr = sim.run(1.0, sample_times=np.linspace(0.0, 1.0, 5))
    st = sim.stats
    assert st["pressure"] == pytest.approx(np.trace(np.array(st["pressure_tensor"])) / 3, rel=1e-14)
    assert tr.pressure() == pytest.approx(np.trace(tr.pressure_tensor()) / 3, rel=1e-14)
    # the lab-frame kinetic energy would overstate it: the flow's share is ~ (shear L)^2 / 12
    plain = Simulation(s)
    tr2 = plain.run(1.0, sample_times=np.linspace(0.0, 1.0, 5))
    assert np.isnan(plain.stats["pressure"])
    with pytest.raises(ValueError, match="stress=True"):
        tr2.pressure()


@pytest.mark.parametrize("kind", ["white_noise", "thermostat"])
def test_a_driven_sheared_gas_keeps_its_peculiar_kinetic_tensor(kind):
    """A random kick in a sheared box changes the kinetic tensor of the peculiar velocities
    (velocity less the flow shear_rate (y - y_c) along x), which the engine keeps by
    differences: after many kicks it is still the velocities' own to rounding (the kicks
    once went in with lab-frame velocities, off by percents in the x components)."""
    from granular import PairThermostat, WhiteNoise

    drive = WhiteNoise(0.5, 20.0, seed=1) if kind == "white_noise" else PairThermostat(1.0, 20.0, 1)
    s = Scene.random(100, 0.02, dim=2, seed=3).replace(shear_rate=2.0, driving=drive)
    sim = Simulation(s, stress=True)
    tr = sim.run(1.0, sample_times=[0.0, 1.0])
    assert sim.stats["kicks"] > 500
    pos, vel = tr.positions[-1], tr.velocities[-1]
    y = np.mod(pos[:, 1] - s.lower[1], s.upper[1] - s.lower[1]) + s.lower[1]
    v = vel.copy()
    v[:, 0] -= 2.0 * (y - 0.5 * (s.lower[1] + s.upper[1]))
    k = np.einsum("n,na,nb->ab", s.masses, v, v)
    np.testing.assert_allclose(
        np.array(sim.stats["kinetic_tensor"]), k, rtol=0, atol=1e-12 * np.abs(k).max()
    )


def test_a_pair_thermostat_keeps_the_imposed_flow():
    """The pair thermostat redraws a pair's relative velocity less the flow: it must not
    thermalise the flow difference of two particles far apart in y (it once dragged the
    profile's slope from 2 to 1.1).  The fitted slope of <v_x>(y) over 81 samples of 200
    disks: its scatter measured ~0.1; bound 0.3 of the imposed rate."""
    from granular import PairThermostat

    rate = 2.0
    s = Scene.random(200, 0.01, dim=2, seed=3).replace(
        shear_rate=rate, driving=PairThermostat(1.0, 5.0, seed=1)
    )
    tr = Simulation(s).run(6.0, sample_times=np.linspace(2.0, 6.0, 81))
    y = np.mod(tr.positions[..., 1] - s.lower[1], 1.0).ravel() - 0.5
    vx = tr.velocities[..., 0].ravel()
    slope = np.polyfit(y, vx, 1)[0]
    assert abs(slope - rate) < 0.3 * rate, slope
