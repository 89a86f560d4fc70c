"""Lees-Edwards (sliding-brick) boundaries in the event-driven engine (csrc/boundary.h,
csrc/lees_edwards.h, csrc/le_nlist.h): the sheared gas, with cells and with neighbour
lists, against the slow reference with its brute-force pair search over all images, the
pairs the sliding images bring together, the energy given by the boundary, checkpoints,
and bad input."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation
from granular.errors import OverlapError
from granular.simulation import shear_offset_at

from helpers import reference_edmd


def _sheared(dim, radius, rate, xi=1.0, n=12, box=3.0, seed=7, offset=0.0):
    s = Scene.random(n, radius, dim=dim, box=box, temperature=1.0, seed=seed)
    return s.replace(shear_rate=rate, shear_offset=offset, restitution=xi)


def _reference(s, t_stop, times):
    return reference_edmd.run_sheared(
        np.array(s.positions),
        np.array(s.velocities),
        s.radii,
        s.masses,
        s.lower,
        s.upper,
        s.restitution,
        t_stop,
        times,
        s.shear_rate,
        s.shear_offset,
    )


def _min_gap(pos, radii, lower, upper, delta):
    """The smallest surface gap over all pairs through the sheared images, brute force."""
    L = upper - lower
    dr = pos[None, :, :] - pos[:, None, :]
    ky = np.where(dr[..., 1] > L[1] / 2, -1, np.where(dr[..., 1] < -L[1] / 2, 1, 0))
    dr[..., 1] += ky * L[1]
    dr[..., 0] += ky * delta
    dr[..., 0] -= L[0] * np.round(dr[..., 0] / L[0])
    for a in range(2, pos.shape[1]):
        dr[..., a] -= L[a] * np.round(dr[..., a] / L[a])
    gap = np.sqrt((dr**2).sum(-1)) - (radii[:, None] + radii[None, :])
    np.fill_diagonal(gap, np.inf)
    return gap.min()


@pytest.mark.parametrize(
    "dim,radius,rate,xi,t_stop,atol",
    [
        (2, 0.2, 3.0, 0.9, 2.0, 1e-7),
        (2, 0.2, -2.0, 1.0, 2.0, 1e-7),
        (3, 0.15, 3.0, 0.9, 3.0, 1e-8),
        (3, 0.2, -2.5, 1.0, 2.0, 1e-8),
    ],
)
def test_agrees_with_slow_reference(dim, radius, rate, xi, t_stop, atol):
    """The same events as the O(N^2) reference, which tries every pair through 5 x 3 (x 3)
    images at every step and integrates the unwrapped positions from the velocities in
    the unfolded lattice: positions (unwrapped) and velocities sample by sample.  The
    images slide by 4 to 9 box lengths and particles cross the sheared faces several
    times; chaos amplifies rounding (~x10 per 0.15 time units here once the shear has
    heated the gas), so the runs stay short of where it reaches the tolerance (measured:
    2D 4e-9, 3D 3e-10 at the end).  A wrong image offset, velocity jump or unwrapped x
    convention is off by O(1)."""
    s = _sheared(dim, radius, rate, xi, offset=0.3)
    times = np.linspace(0.0, t_stop, 13)
    sim = Simulation(s)
    tr = sim.run(t_stop=t_stop, sample_times=times)
    slid = abs(rate) * 3.0 * t_stop / 3.0  # box lengths the images slid
    assert slid >= 4
    _, _, img = sim._engine.state()
    assert np.abs(img[:, 1]).sum() >= 4  # crossings of the sheared faces
    assert sim.stats["pair_collisions"] >= s.n
    rx, rv, rk, rw = _reference(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=atol)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=atol)
    if xi == 1.0:  # the reference's own bookkeeping: energy = boundary work
        np.testing.assert_allclose(rk - rk[0], rw, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_particle_at_rest_meets_the_sliding_images(dim):
    """Two particles at rest, one near the upper face, one near the lower face far along
    x: neither has an event of its own, and only the sliding images bring them into
    contact, at the time the image's x offset closes the gap (both radii 0.5, y gap
    0.85 through the face, so the centres touch at x distance sqrt(1 - 0.85^2)).  A cell
    scan that did not follow the slide would let them pass through each other."""
    # 20 cells along x (8 particles at rest mid-box keep the grid from being capped at a
    # few cells per particle): the scan's window of 6 columns is not the whole row
    Lx, L = 20.0, 3.0
    z = [1.0] if dim == 3 else []
    still = [[x, 1.5, *z] for x in range(2, 18, 2)]
    pos = np.array([[1.0, L - 0.55, *z], [14.0, 0.3, *z], *still], dtype=float)
    u = 0.5  # image speed: shear_rate * L_y
    box = (np.zeros(dim), np.array([Lx, L, 2.2][:dim]))
    s = Scene(pos, np.zeros((len(pos), dim)), 0.5, box=box, shear_rate=u / L)
    assert Simulation(s).stats["cells"][0] == 20
    # the lower particle's image above sits at x = 14 + u t; it meets x = 1 + 20 (the
    # upper particle's next image along x) at distance sqrt(1 - 0.85^2)
    t_hit = (21.0 - math.sqrt(1 - 0.85**2) - 14.0) / u
    sim = Simulation(s)
    tr = sim.run(t_stop=t_hit + 1.0, sample_times=[t_hit + 1.0])
    assert sim.stats["pair_collisions"] >= 1
    v = tr.velocities[-1]
    assert np.abs(v).max() > 0.1 * u  # they hit: the images' motion passed on
    times = [t_hit - 1e-9, t_hit + 1.0]
    rx, rv, _, _ = _reference(s, t_hit + 1.0, times)
    np.testing.assert_allclose(rv[0], 0.0, atol=1e-12)  # not before
    np.testing.assert_allclose(v, rv[-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(tr.positions[-1], rx[-1], rtol=0, atol=1e-9)


@pytest.mark.parametrize("dim,n,box", [(2, 300, 24.0), (3, 400, 11.0)])
def test_no_pair_is_missed_over_many_box_crossings(dim, n, box):
    """A long elastic run (the images slide 25 box lengths, hundreds of crossings of the
    sheared faces, > 30 collisions per particle): at every sample no two particles overlap
    through any image (brute force; a missed pair overlaps by a good fraction of a
    diameter), and the kinetic energy has risen by exactly the work of the boundary (the
    x momentum carried across the faces times the velocity jump), up to the rounding of
    ~1e5 differences summed."""
    rate = 0.05
    s = Scene.random(n, 0.5, dim=dim, box=box, temperature=1.0, seed=2)
    s = s.replace(shear_rate=rate)
    k0 = s.kinetic_energy
    t_stop = 25.0 * box / (rate * box)
    times = np.linspace(0.0, t_stop, 26)
    sim = Simulation(s)
    tr = sim.run(t_stop=t_stop, sample_times=times, store=("positions",))
    st = sim.stats
    assert st["pair_collisions"] * 2 / n > 30
    _, _, img = sim._engine.state()
    assert np.abs(img[:, 1]).sum() > n // 2  # net crossings alone (2D ~200, 3D ~700)
    for k, t in enumerate(times):
        wrapped = tr.positions[k] - s.lower
        wrapped = s.lower + np.mod(wrapped, s.upper - s.lower)
        # x unwrapped includes img_y D(t): folding x mod L_x needs the same y image
        img_y = np.floor((tr.positions[k][:, 1] - s.lower[1]) / (s.upper[1] - s.lower[1]))
        d_total = s.shear_offset + rate * (s.upper[1] - s.lower[1]) * t
        x = tr.positions[k][:, 0] - img_y * d_total
        wrapped[:, 0] = s.lower[0] + np.mod(x - s.lower[0], s.upper[0] - s.lower[0])
        gap = _min_gap(wrapped, s.radii, s.lower, s.upper, shear_offset_at(s, t))
        assert gap > -1e-9, (t, gap)
    heat = st["kinetic_energy"] - k0
    assert heat > 0.5 * k0  # the shear heats the elastic gas
    assert abs(heat - st["shear_work"]) < 1e-9 * st["kinetic_energy"]


def test_the_work_of_the_boundary_is_counted_from_momentum():
    """The engine's shear_work is summed from momenta (m (v + v') / 2 at a crossing, the
    image's impulse at a collision), not from energies: its agreement with the energy
    is a check of the velocity jumps' signs.  A short elastic run, to rounding."""
    s = _sheared(2, 0.2, 3.0)
    sim = Simulation(s)
    sim.run(t_stop=2.0, store=())
    st = sim.stats
    assert st["shear_work"] != 0.0
    assert abs(st["kinetic_energy"] - s.kinetic_energy - st["shear_work"]) < 1e-10 * abs(
        st["shear_work"]
    )


def test_a_checkpoint_continues_bit_for_bit(tmp_path):
    """Saved mid-run (the images at some offset, slides and face crossings pending) and
    loaded, the run goes on with the same bits as the one never stopped."""
    s = _sheared(3, 0.3, 0.7, xi=0.9, n=60, box=5.0)
    a = Simulation(s)
    a.run(t_stop=1.3, store=())
    a.save(tmp_path / "c.npz")
    b = Simulation.load(tmp_path / "c.npz")
    times = np.linspace(1.3, 3.0, 5)
    ta = a.run(t_stop=3.0, sample_times=times)
    tb = b.run(t_stop=3.0, sample_times=times)
    assert np.array_equal(ta.positions, tb.positions)
    assert np.array_equal(ta.velocities, tb.velocities)
    assert a.stats["shear_work"] == b.stats["shear_work"]
    assert a.stats["events"] == b.stats["events"]


def test_the_scene_now_carries_the_offset_now():
    """Simulation.scene of a sheared run holds the image offset at that time: a new run
    from it is a valid scene (no overlap through the displaced images) and its particles
    sit where the old run's unwrapped positions say."""
    s = _sheared(2, 0.2, 1.3, n=30, box=5.0)
    sim = Simulation(s)
    sim.run(t_stop=2.7, store=())
    now = sim.scene
    assert now.shear_offset == shear_offset_at(s, 2.7)
    assert 0.0 <= now.shear_offset < 5.0
    again = Simulation(now)
    again.run(t_stop=0.5, store=())  # runs: no overlap, no error
    # x unwrapped minus img_y D(t) is the box x, up to whole box lengths
    pos, _, img = sim._engine.state()
    x = sim.unwrapped_positions[:, 0] - img[:, 1] * (s.shear_offset + 1.3 * 5.0 * 2.7)
    np.testing.assert_allclose(np.mod(x - pos[:, 0] + 2.5, 5.0) - 2.5, 0.0, atol=1e-12)


def test_an_overlap_through_the_displaced_images_is_refused():
    """At time 0 the image across the upper face is displaced by shear_offset: two
    particles that touch only through it overlap, and two that would overlap only through
    an undisplaced image do not."""
    L = 6.0
    pos = np.array([[1.0, L - 0.3], [3.0, 0.3]])  # y gap 0.6 through the face
    Scene(pos, np.zeros((2, 2)), 0.5, box=L, shear_rate=0.1, shear_offset=1.0)  # 3 apart
    with pytest.raises(OverlapError, match="sheared images"):  # the image at x = 7 = 1 + L
        Scene(pos, np.zeros((2, 2)), 0.5, box=L, shear_rate=0.1, shear_offset=4.0)
    close = np.array([[1.0, L - 0.3], [1.2, 0.3]])  # overlapping without an offset
    Scene(close, np.zeros((2, 2)), 0.5, box=L, shear_rate=0.1, shear_offset=3.0)


def _gaps_at_samples(s, tr, times, rate):
    """The smallest gap through the sheared images at each sample (positions folded into
    the box: x unwrapped includes img_y D(t), so x is folded with the same y image)."""
    gaps = []
    for k, t in enumerate(times):
        wrapped = s.lower + np.mod(tr.positions[k] - s.lower, s.upper - s.lower)
        img_y = np.floor((tr.positions[k][:, 1] - s.lower[1]) / (s.upper[1] - s.lower[1]))
        d_total = s.shear_offset + rate * (s.upper[1] - s.lower[1]) * t
        x = tr.positions[k][:, 0] - img_y * d_total
        wrapped[:, 0] = s.lower[0] + np.mod(x - s.lower[0], s.upper[0] - s.lower[0])
        gaps.append(_min_gap(wrapped, s.radii, s.lower, s.upper, shear_offset_at(s, t)))
    return np.array(gaps)


def _dense_sheared(n, eta, dim, rate, seed=1, xi=1.0):
    r = (eta / (n * (math.pi if dim == 2 else 4 / 3 * math.pi))) ** (1 / dim)
    s = Scene.random(n, r, dim=dim, temperature=1.0, seed=seed)
    return s.replace(shear_rate=rate, restitution=xi)


@pytest.mark.parametrize(
    "dim,n,radius,rate,xi,t_stop,offset,seed",
    [
        (2, 12, 0.2, 3.0, 0.9, 1.8, 0.3, 7),
        (2, 12, 0.2, -2.0, 1.0, 2.0, 0.3, 7),
        (3, 12, 0.15, 3.0, 0.9, 3.0, 0.3, 7),
        (3, 12, 0.2, -2.5, 1.0, 2.0, 0.3, 7),
        (2, 30, 0.2, 2.0, 0.9, 1.0, 0.0, 3),  # area fraction 0.42
        (3, 30, 0.33, 2.0, 0.9, 0.6, 0.0, 3),  # packing 0.17 in a box 2.2 lists wide
    ],
)
def test_lists_agree_with_slow_reference(dim, n, radius, rate, xi, t_stop, offset, seed):
    """Neighbour lists in a sheared box (csrc/le_nlist.h: entries through a sliding face
    take the nearest x image at each scan, shells move with the mean flow, pairs are listed
    over a list's life) against the reference that tries every pair through every image at
    every step: the same positions (unwrapped) and velocities sample by sample.  The images
    slide by 1.2 to 6 box lengths (offset wraps), particles cross the sheared faces, and
    each particle rebuilds its list more than five times.  Chaos amplifies rounding (the
    lists' rounding differs from the cells'): the runs stop before it reaches the tolerance
    (the largest difference at the end, velocities: dilute 2D 2e-10 and 2e-9, 3D 5e-11 and
    1e-11, dense 2D 6e-11, 3D 3e-13).  A pair missed through a sliding face, or a wrong
    image, is off by O(1)."""
    s = Scene.random(n, radius, dim=dim, box=3.0, temperature=1.0, seed=seed)
    s = s.replace(shear_rate=rate, shear_offset=offset, restitution=xi)
    times = np.linspace(0.0, t_stop, 13)
    sim = Simulation(s, shell=0.25)
    tr = sim.run(t_stop=t_stop, sample_times=times)
    st = sim.stats
    assert st["shell"] == 0.25 and st["shell_exits"] > 5 * n
    assert abs(rate) * 3.0 * t_stop / 3.0 >= 1.2  # box lengths the images slid
    assert st["pair_collisions"] >= n
    rx, rv, rk, rw = _reference(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-7)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-7)
    # the box velocities' energy, particles strayed beyond a sliding face included
    np.testing.assert_allclose(tr.kinetic_energy, rk, rtol=1e-7)
    np.testing.assert_allclose(st["kinetic_energy"], rk[-1], rtol=1e-7)
    if xi == 1.0:  # energy = boundary work, as the reference books it
        np.testing.assert_allclose(st["shear_work"], rw[-1], rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(
            st["kinetic_energy"] - s.kinetic_energy, st["shear_work"], rtol=1e-9, atol=1e-9
        )


@pytest.mark.parametrize("dim,n,radius,t_stop", [(2, 40, 0.15, 1.0), (3, 40, 0.2, 1.0)])
def test_lists_in_crowded_cells_agree_with_slow_reference(dim, n, radius, t_stop):
    """As test_lists_agree_with_slow_reference, with cells made wide (cell_factor 2: 3 x 3
    cells in 2D, 2 x 2 x 2 in 3D) so that they hold five centres each on average, often
    more than a cell's block (csrc/le_cells.h: its first seven), whose rest then comes
    from the cell's list; 20 or more rebuilds a particle.  Largest velocity difference at
    the end, measured: 9e-10 (2D, chaos growing tenfold every 0.25) and 8e-13 (3D)."""
    s = Scene.random(n, radius, dim=dim, box=3.0, temperature=1.0, seed=11)
    s = s.replace(shear_rate=2.0, restitution=0.9)
    times = np.linspace(0.0, t_stop, 7)
    sim = Simulation(s, shell=0.25, cell_factor=2.0)
    tr = sim.run(t_stop=t_stop, sample_times=times)
    st = sim.stats
    assert st["shell"] == 0.25 and st["shell_exits"] > 5 * n
    assert n / np.prod(st["cells"]) >= 4.0  # centres a cell, on average
    rx, rv, _, _ = _reference(s, t_stop, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-7)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-7)


@pytest.mark.parametrize("dim", [2, 3])
def test_lists_see_the_sliding_images_of_particles_at_rest(dim):
    """As test_a_particle_at_rest_meets_the_sliding_images, with neighbour lists (a box
    wide enough for them): two particles at rest near opposite y faces, far apart along
    x, with no event of their own.  Only their lists' rebuilds (shells carried by the flow
    leave particles at rest; lives end) bring the pair into a list before the sliding image
    reaches it."""
    Lx, L = 20.0, 5.0
    z = [2.0] if dim == 3 else []
    still = [[x, 2.5, *z] for x in range(2, 18, 2)]
    pos = np.array([[1.0, L - 0.55, *z], [14.0, 0.3, *z], *still], dtype=float)
    u = 0.5
    box = (np.zeros(dim), np.array([Lx, L, 4.5][:dim]))
    s = Scene(pos, np.zeros((len(pos), dim)), 0.5, box=box, shear_rate=u / L)
    t_hit = (21.0 - math.sqrt(1 - 0.85**2) - 14.0) / u
    sim = Simulation(s, shell=0.25)
    tr = sim.run(t_stop=t_hit + 1.0, sample_times=[t_hit + 1.0])
    assert sim.stats["shell"] == 0.25 and sim.stats["shell_exits"] > 0
    assert sim.stats["pair_collisions"] >= 1
    v = tr.velocities[-1]
    assert np.abs(v).max() > 0.1 * u
    rx, rv, _, _ = _reference(s, t_hit + 1.0, [t_hit - 1e-9, t_hit + 1.0])
    np.testing.assert_allclose(rv[0], 0.0, atol=1e-12)  # not before
    np.testing.assert_allclose(v, rv[-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(tr.positions[-1], rx[-1], rtol=0, atol=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_lists_catch_a_pair_the_mean_flow_brings_together(dim):
    """Two spheres (radius 0.5, shell 0.25: reach 1.5) whose list centres start 1.52
    apart (0.7 along y: not listed), in the quadrant where the mean flow (rate 1) closes
    the gap, each moving with the flow at its centre plus 0.5 towards the other.  They
    touch at t = 0.32, inside both shells (each has moved 0.16) and before a list's
    longest life (a strain of 0.4): no list is rebuilt before, so only the listing that
    sweeps the centres' separation over the life (csrc/le_cells.h) can have listed them.
    Without the sweep they pass through each other; the reference has them collide."""
    rate, L = 1.0, 10.0
    z = [5.0] if dim == 3 else []
    dx, dy = math.sqrt(1.52**2 - 0.7**2), 0.7
    pos = np.array([[4.0, 5.35, *z], [4.0 + dx, 5.35 - dy, *z]])
    unit = (pos[1] - pos[0]) / 1.52
    vel = np.outer([1.0, -1.0], 0.5 * unit)
    vel[:, 0] += rate * (pos[:, 1] - L / 2)
    box = (np.zeros(dim), np.full(dim, L))
    s = Scene(pos, vel, 0.5, box=box, shear_rate=rate)
    rel, dv = pos[1] - pos[0], vel[1] - vel[0]  # |rel + dv t| = 1, the first root
    a, b, c = dv @ dv, rel @ dv, rel @ rel - 1.0
    t_hit = (-b - math.sqrt(b * b - a * c)) / a
    assert 0.3 < t_hit < 0.4 * 0.999 / rate and 0.5 * t_hit < 0.25 * (1 - 1e-9)
    sim = Simulation(s, shell=0.25)
    tr = sim.run(t_stop=t_hit + 0.01, sample_times=[t_hit + 0.01])
    assert sim.stats["shell"] == 0.25 and sim.stats["shell_exits"] == 0
    assert sim.stats["pair_collisions"] == 1
    rx, rv, _, _ = _reference(s, t_hit + 0.01, [t_hit - 1e-6, t_hit + 0.01])
    np.testing.assert_allclose(rv[0], vel, atol=1e-12)  # not before
    np.testing.assert_allclose(tr.velocities[-1], rv[-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(tr.positions[-1], rx[-1], rtol=0, atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("dim,n,eta,rate", [(2, 300, 0.6, 0.1), (3, 400, 0.45, 0.2)])
def test_lists_never_let_a_pair_overlap_in_a_dense_sheared_gas(dim, n, eta, rate):
    """A long elastic dense run with lists (the images slide 4 box lengths, hundreds of
    crossings of the sheared faces, ~100 collisions per particle): at every sample no two
    particles overlap through any image (brute force: a missed pair overlaps by a good
    fraction of a diameter), the engine's own check finds every list complete (through
    the sliding faces: every pair within reach over a life from the later build),
    and the kinetic energy has risen by exactly the work of the boundary."""
    s = _dense_sheared(n, eta, dim, rate, seed=2)
    k0 = s.kinetic_energy
    L = s.upper - s.lower
    t_stop = 4.0 * L[0] / (rate * L[1])
    times = np.linspace(0.0, t_stop, 17)
    sim = Simulation(s, shell=0.25)
    tr = sim.run(t_stop=t_stop, sample_times=times, store=("positions",))
    st = sim.stats
    assert st["shell"] == 0.25
    assert st["pair_collisions"] * 2 / n > 50
    _, _, img = sim._engine.state()
    assert np.abs(img[:, 1]).sum() > n // 4
    gaps = _gaps_at_samples(s, tr, times, rate)
    assert gaps.min() > -1e-9, gaps
    sim._engine.restore_state(sim._engine.save_state())  # raises if a list is wrong
    heat = st["kinetic_energy"] - k0
    assert heat > 0.02 * k0  # the shear heats the elastic gas
    assert abs(heat - st["shear_work"]) < 1e-9 * st["kinetic_energy"]


def test_lists_and_cells_follow_the_same_sheared_gas():
    """The same dense sheared gas with lists and with cells: the same trajectory to
    rounding while chaos has not amplified it (the first collision per particle), and
    over longer runs of 6 seeds each the same pair collisions per particle, within 4
    standard errors of the difference (from the spread over the seeds)."""
    s = _dense_sheared(300, 0.4, 3, 0.5, seed=5, xi=0.9)
    times = np.linspace(0.0, 0.05, 6)
    a = Simulation(s, shell=0.25).run(t_stop=0.05, sample_times=times)
    b = Simulation(s, shell=0).run(t_stop=0.05, sample_times=times)
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.velocities, b.velocities, rtol=0, atol=1e-9)
    counts = {0.25: [], 0.0: []}
    for seed in range(6):
        g = _dense_sheared(300, 0.4, 3, 0.5, seed=10 + seed, xi=0.9)
        for shell in counts:
            sim = Simulation(g, shell=shell)
            sim.run(t_stop=2.0, store=())
            assert sim.stats["shell"] == shell
            counts[shell].append(sim.stats["pair_collisions"] * 2 / g.n)
    la, ce = np.array(counts[0.25]), np.array(counts[0.0])
    err = np.sqrt(la.var(ddof=1) / la.size + ce.var(ddof=1) / ce.size)
    assert abs(la.mean() - ce.mean()) < 4 * err, (la, ce)


def test_lists_continue_bit_for_bit_from_a_checkpoint(tmp_path):
    """Saved mid-run with lists in a sheared box (shells carried by the flow, their build
    times, laps and filing time, particles strayed beyond a sliding face) and loaded: the
    same bits as the run never stopped."""
    s = _dense_sheared(400, 0.45, 3, 0.7, seed=3, xi=0.9)
    a = Simulation(s, shell=0.25)
    a.run(t_stop=1.3, store=())
    a.save(tmp_path / "c.npz")
    b = Simulation.load(tmp_path / "c.npz")
    times = np.linspace(1.3, 2.5, 4)
    ta = a.run(t_stop=2.5, sample_times=times)
    tb = b.run(t_stop=2.5, sample_times=times)
    assert a.stats["shell"] == 0.25 and b.stats["shell"] == 0.25
    assert np.array_equal(ta.positions, tb.positions)
    assert np.array_equal(ta.velocities, tb.velocities)
    assert a.stats["shear_work"] == b.stats["shear_work"]
    assert a.stats["events"] == b.stats["events"]


def test_lists_report_the_box_velocities_energy():
    """With lists a particle may stray up to a shell beyond a sliding face before its
    shell exit brings it back (its record then in the frame of the box it left): the
    reported velocities, kinetic energy and boundary work are those of the box it is
    in, at every stop (energy = the box velocities' total, and = the initial energy plus
    the work in an elastic gas)."""
    s = _dense_sheared(400, 0.45, 3, 1.0, seed=4)
    sim = Simulation(s, shell=0.25)
    for t in np.linspace(0.1, 1.0, 10):
        sim.run(t_stop=t, store=())
        st = sim.stats
        kinetic = 0.5 * (s.masses[:, None] * sim.scene.velocities**2).sum()
        assert abs(st["kinetic_energy"] - kinetic) < 1e-12 * kinetic
        assert abs(st["kinetic_energy"] - s.kinetic_energy - st["shear_work"]) < 1e-12 * kinetic


def test_a_sheared_list_that_misses_a_pair_is_refused():
    """The engine's check of a restored state in a sheared box (csrc/checkpoint.c,
    check_sheared_lists): two spheres within reach only through the lower y face (centres
    0.12 apart, reach 0.1 + 2 x 0.025) list each other through the image of y shift -L
    and no x image (code 1 + 3 * 0 + 9 * 1 = 10, its opposite 16); listed as if in the
    box instead (13 both ways: symmetric) the pair is missing and the state is refused.
    A build time in the future is refused, and so is a centre's lap (the box lengths
    between its filed x and the flow's, csrc/le_cells.h) that no drift can reach.  The
    state ends with the rows (one entry each, j << 5 | code), the build times (two
    doubles), the laps (two bytes) and the filing time (one double)."""
    pos = [[0.5, 0.04, 0.5], [0.5, 0.92, 0.5]]
    s = Scene(pos, [[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]], 0.05, shear_rate=0.1)
    sim = Simulation(s, shell=0.25)
    state = bytearray(sim._engine.save_state())
    rows = np.frombuffer(bytes(state[-34:-26]), np.int32)
    assert sorted(rows >> 5) == [0, 1] and sorted(rows & 31) == [10, 16]
    assert list(np.frombuffer(bytes(state[-26:-10]), np.float64)) == [0.0, 0.0]
    assert list(state[-10:-8]) == [0, 0]
    sim._engine.restore_state(bytes(state))  # as saved: fine
    inside = bytearray(state)
    inside[-34:-26] = ((rows & ~31) | 13).astype(np.int32).tobytes()
    with pytest.raises(ValueError, match="misses a particle within reach"):
        sim._engine.restore_state(bytes(inside))
    future = bytearray(state)
    future[-26:-18] = np.float64(1.0).tobytes()
    with pytest.raises(ValueError, match="build time is out of range"):
        sim._engine.restore_state(bytes(future))
    lapped = bytearray(state)
    lapped[-10] = 3
    with pytest.raises(ValueError, match="filed in another cell"):
        sim._engine.restore_state(bytes(lapped))


def test_auto_uses_lists_for_a_dense_sheared_gas():
    """shell='auto' picks neighbour lists for a dense 3D gas, sheared or not."""
    n = 500
    s = Scene.random(n, (0.45 / (n * 4 / 3 * math.pi)) ** (1 / 3), dim=3, seed=1)
    s = s.replace(shear_rate=0.2)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 5}, store=())
    assert sim.stats["shell"] == 0.25 and sim.stats["shell_exits"] > 0


@pytest.mark.parametrize(
    "change,match",
    [
        ({"boundary": "walls", "shear_rate": 0.1}, "needs a periodic box"),
        ({"shear_rate": math.nan}, "shear_rate must be finite"),
        ({"shear_rate": math.inf}, "shear_rate must be finite"),
        ({"shear_offset": math.nan, "shear_rate": 0.1}, "shear_offset must be finite"),
        ({"shear_offset": 0.5}, "needs a shear rate"),
        ({"shear_rate": 0.1, "shear_offset": 3.0}, r"\[0, L_x\)"),
        ({"shear_rate": 0.1, "shear_offset": -0.1}, r"\[0, L_x\)"),
        ({"shear_rate": 1e9}, "2\\^26 times the fastest"),
        ({"shear_rate": 1e145}, r"\[1e-140, 1e140\]"),
    ],
)
def test_bad_shear_is_refused(change, match):
    s = Scene.random(10, 0.2, dim=2, box=3.0, temperature=1.0, seed=1)
    with pytest.raises(ValueError, match=match):
        s.replace(**change)


def _with_profile(s):
    """s with the mean flow shear_rate (y - y_c) added to its velocities along x."""
    v = np.array(s.velocities)
    v[:, 0] += s.shear_rate * (s.positions[:, 1] - 0.5 * (s.lower[1] + s.upper[1]))
    return s.replace(velocities=v)


def test_the_temperature_is_that_of_the_peculiar_velocities():
    """Velocities that are exactly the mean flow have no temperature, in the Trajectory
    and in stats; the plain kinetic temperature counts the flow (shear_rate^2 <(y -
    y_c)^2> = 1/12 here, box 1, rate 1)."""
    s = Scene.random(200, 0.02, dim=2, temperature=1.0, seed=1).replace(shear_rate=1.0)
    s = _with_profile(s.replace(velocities=np.zeros((200, 2))))
    sim = Simulation(s)
    assert sim.stats["temperature"] < 1e-30
    tr = sim.run(t_stop=0.0, sample_times=[0.0])
    assert tr.temperature[0] < 1e-30
    plain = 2 * tr.kinetic_energy[0] / (2 * 200)
    assert abs(plain - 1 / 24) < 0.02  # (1/2) <v_x^2> over d = 2: 1/12 / 2
    with pytest.raises(ValueError, match="positions and velocities"):
        _ = sim.run(t_stop=0.1, store=()).temperature


def test_an_inelastic_sheared_gas_reaches_a_steady_temperature():
    """Without a thermostat the sheared inelastic gas (3D, xi = 0.7, packing 0.2) heats
    or cools to the state where viscous heating balances collisional cooling: started
    7 times colder and 7 times hotter than that, both runs settle (by t = 20, ~60
    collisions per particle) to temperatures that agree, and that stay steady.  The
    error: the temperature averaged over four blocks of 5 time units in t = 20 .. 40 of
    each run (several relaxation times each: the runs reach the state within ~10), the
    block-to-block spread pooled over both runs (6 degrees of freedom); tolerances are 5
    standard errors (Student's t with 6 degrees of freedom: p = 0.0025).  The mean
    velocity profile is the imposed linear one."""
    n, eta, rate = 256, 0.2, 1.0
    r = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3)
    times = np.linspace(0.0, 40.0, 161)
    blocks = []
    starts = []
    profiles = []
    centres = (np.arange(5) + 0.5) / 5 - 0.5  # y - y_c of five bins across the box
    for t0 in (0.001, 0.05):
        s = Scene.random(n, r, dim=3, temperature=t0, seed=3)
        s = _with_profile(s.replace(restitution=0.7, shear_rate=rate))
        tr = Simulation(s).run(t_stop=40.0, sample_times=times)
        starts.append(tr.temperature[0])
        late = times > 20.0
        blocks.append(tr.temperature[late].reshape(4, -1).mean(axis=1))
        y, vx = tr.positions[late][..., 1] % 1.0, tr.velocities[late][..., 0]
        bins = np.minimum((y * 5).astype(int), 4)
        split = np.array_split(np.arange(late.sum()), 4)
        profiles.append([[vx[b][bins[b] == k].mean() for k in range(5)] for b in split])
    blocks = np.array(blocks)
    sd = np.sqrt(((blocks - blocks.mean(axis=1, keepdims=True)) ** 2).sum() / 6)
    cold, hot = blocks.mean(axis=1)
    steady = 0.5 * (cold + hot)
    assert starts[0] < steady / 5 and starts[1] > steady * 5  # far from it at the start
    assert abs(hot - cold) < 5 * sd * math.sqrt(2 / 4)
    early, late = blocks[:, :2].mean(), blocks[:, 2:].mean()
    assert abs(late - early) < 5 * sd * math.sqrt(2 / 4)
    # the mean flow: linear, rate (y - y_c) (a bin's mean is its centre's value), no
    # banding at this size; each bin's mean over the four blocks, the block spread pooled
    # over bins and runs (30 degrees of freedom), within 4 standard errors
    prof = np.array(profiles)  # run, block, bin
    spread = prof - prof.mean(axis=1, keepdims=True)
    se = np.sqrt((spread**2).sum() / 30) / 2
    assert np.all(np.abs(prof.mean(axis=1) - rate * centres) < 4 * se)


def test_gsd_carries_the_sheared_box(tmp_path):
    """A sheared run's GSD file: each frame's box has HOOMD's tilt xy = delta / L_y (the
    image across the upper face displaced by delta, in [-L_x/2, L_x/2)), its float32
    positions lie in that triclinic box and unwrap through its lattice vectors to the
    run's positions (to float32's precision); read back, the Trajectory is the one
    written and the last frame's Scene is the run's scene then, offset included."""
    gsd = pytest.importorskip("gsd.hoomd")
    import granular

    s = _sheared(2, 0.2, 1.3, n=30, box=5.0)
    sim = Simulation(s)
    times = np.linspace(0.0, 2.7, 4)
    tr = sim.run(t_stop=2.7, sample_times=times)
    tr.write(tmp_path / "run.gsd")
    with gsd.open(tmp_path / "run.gsd") as f:
        for k, frame in enumerate(f):
            lx, ly, _, xy, _, _ = frame.configuration.box
            delta = shear_offset_at(s, times[k])
            delta = delta - 5.0 if delta >= 2.5 else delta
            assert xy == pytest.approx(delta / ly, rel=1e-6, abs=1e-7)
            pos = frame.particles.position.astype(float)
            img = frame.particles.image.astype(float)
            frac_x = (pos[:, 0] - xy * pos[:, 1]) / lx
            assert np.all((frac_x >= -0.5) & (frac_x < 0.5))
            unwrapped = pos[:, 0] + img[:, 0] * lx + img[:, 1] * xy * ly + 2.5
            np.testing.assert_allclose(unwrapped, tr.positions[k][:, 0], atol=1e-4)
    back = granular.read(tmp_path / "run.gsd")
    np.testing.assert_array_equal(back.positions, tr.positions)
    assert back.scene_parameters["shear_rate"] == 1.3
    last = Scene.from_gsd(tmp_path / "run.gsd")
    now = sim.scene
    assert last.shear_offset == now.shear_offset
    np.testing.assert_allclose(last.positions, now.positions, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(last.velocities, now.velocities)


def test_the_animation_draws_particles_through_the_sliding_images():
    """plot.animate of a sheared run: each frame's disks at the positions brought into the
    box through the sliding images at its time (not by folding x alone, which is off by
    img_y D(t)), and a disk's image across a y face displaced along x by the offset."""
    pytest.importorskip("matplotlib")
    from granular import _shear, plot

    s = _sheared(2, 0.2, 1.3, n=30, box=5.0)
    tr = Simulation(s).run(t_stop=4.0, sample_times=np.linspace(0.0, 4.0, 5))
    anim = plot.animate(tr)
    folded_wrong = 0
    for k, si in enumerate(anim.samples):
        anim.draw(k)
        t = float(tr.times[si])
        want, _ = _shear.wrap(tr.positions[si], s.lower, s.upper, 1.3, 0.0, t)
        np.testing.assert_allclose(anim.disks.get_offsets(), want, rtol=0, atol=1e-12)
        folded_wrong += np.sum(np.abs(np.mod(tr.positions[si][:, 0], 5.0) - want[:, 0]) > 1e-6)
        below = np.asarray(anim.images[1].get_offsets())  # the copies across a y face
        delta = shear_offset_at(s, t)
        up = want[:, 1] > 2.5  # copied below: the image displaced by -delta
        np.testing.assert_allclose(below[up, 0], np.mod(want[up, 0] - delta, 5.0), atol=1e-12)
        np.testing.assert_allclose(below[up, 1], want[up, 1] - 5.0, atol=1e-12)
    assert folded_wrong > 0  # particles did cross the sheared faces


def test_no_clustering_warning_for_a_sheared_box():
    """The ClusteringWarning is about the homogeneous cooling state's shear instability; a
    sheared gas has no cooling state, so the box that warns unsheared does not warn."""
    import warnings

    from granular.errors import ClusteringWarning

    scene = Scene.random(200, 0.015, dim=2, restitution=0.7, temperature=1.0, seed=18)
    with pytest.warns(ClusteringWarning):
        Simulation(scene).run(stop_when={"collisions_per_particle": 30}, store=())
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClusteringWarning)
        sheared = Simulation(scene.replace(shear_rate=1.0))
        sheared.run(stop_when={"collisions_per_particle": 30}, store=())


@pytest.mark.parametrize("dim,n,radius,box", [(2, 5, 0.45, 3.0), (3, 6, 0.45, 2.5)])
def test_a_box_of_few_cells_agrees_with_slow_reference(dim, n, radius, box):
    """Two or three cells along x: the six columns of the sliding window wrap onto the
    same cells through several images along x, each its own candidate.  Against the
    reference as above (~35 collisions; measured 7e-11 at the end)."""
    s = Scene.random(n, radius, dim=dim, box=box, temperature=1.0, seed=4)
    s = s.replace(shear_rate=2.0, restitution=0.9)
    times = np.linspace(0.0, 2.0, 9)
    sim = Simulation(s)
    tr = sim.run(t_stop=2.0, sample_times=times)
    assert sim.stats["cells"][0] <= 3 and sim.stats["pair_collisions"] >= 5 * n
    rx, rv, _, _ = _reference(s, 2.0, times)
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=1e-8)
