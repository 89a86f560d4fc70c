"""The engine's neighbour-list mode (Simulation(shell=...)): the same dynamics as the
cell-crossing mode and as the slow reference, conservation and no overlaps where lists
matter (dense 3D), lists that grow, periodic wrapping at rebuilds, and the automatic
choice."""

import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import granular
from granular import Scene, Simulation

from helpers import reference_edmd
from helpers.scenes import min_distance_ratio, reference_scene, three_in_line, tracer_scene


def _dense(n, eta, dim=3, boundary="periodic", seed=1, **kw):
    r = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3) if dim == 3 else math.sqrt(eta / (n * math.pi))
    return Scene.random(n, r, dim=dim, boundary=boundary, seed=seed, **kw)


def _lists(scene, shell=0.25, **kw):
    sim = Simulation(scene, shell=shell, **kw)
    assert sim.stats["shell"] == shell  # lists are on, not declined for a small box
    return sim


@pytest.mark.parametrize(
    "dim,boundary,xi,mixture",
    [
        (2, "walls", 1.0, False),
        (2, "periodic", 0.7, False),
        (3, "periodic", 1.0, False),
        (3, "walls", 0.8, False),
        (2, "periodic", 0.9, True),
        (3, "periodic", 1.0, True),
    ],
)
@pytest.mark.parametrize("shell", [0.02, 0.25])
def test_agrees_with_slow_reference(dim, boundary, xi, mixture, shell):
    """As test_simulation's reference test (same tolerance, same reasoning: ~10
    collisions per particle, chaos keeps rounding differences below 1e-8), with lists:
    a thin shell rebuilds often (every 0.02 diameters travelled), a thick one rarely.
    Each rebuild adds rounding of its own: in the 2D mixture the thin shell is 5e-14 off
    the reference at t = 0.2 where plain cells are 3e-15 off, and chaos multiplies both by
    ~10 every 0.1 time units (40 collisions among 12 particles), so the thin shell gets
    1e-7 there instead of 1e-8 (measured: 2e-8 at t = 1)."""
    s = reference_scene(dim, boundary, xi, mixture)
    n = s.n
    times = np.linspace(0.0, 1.0, 11)
    sim = _lists(s, shell)
    tr = sim.run(t_stop=1.0, sample_times=times)
    assert sim.stats["pair_collisions"] >= n
    assert sim.stats["shell_exits"] >= n and sim.stats["cell_crossings"] == 0  # lists rebuilt
    rx, rv = reference_edmd.run_scene(s, 1.0, times)
    atol = 1e-7 if (shell, dim, mixture) == (0.02, 2, True) else 1e-8
    np.testing.assert_allclose(tr.positions, rx, rtol=0, atol=atol)
    np.testing.assert_allclose(tr.velocities, rv, rtol=0, atol=atol)


@pytest.mark.parametrize("n,boundary,eta", [(1500, "periodic", 0.45), (1500, "walls", 0.4)])
def test_lists_and_cells_give_the_same_trajectory(n, boundary, eta):
    """Dense 3D, where lists are used: the two modes find the same collisions, so
    positions agree until chaos has amplified the rounding differences of their
    arithmetic (they differ in how a periodic image is added).  About 2 collisions per
    particle: differences stay below 1e-8."""
    s = _dense(n, eta, boundary=boundary, restitution=0.95, seed=2)
    t_stop = Simulation(s).run(stop_when={"collisions_per_particle": 2}).times[-1]
    times = np.linspace(0.0, t_stop, 5)
    cells = Simulation(s, shell=0.0)
    lists = _lists(s)
    a = cells.run(t_stop=t_stop, sample_times=times)
    b = lists.run(t_stop=t_stop, sample_times=times)
    assert lists.stats["pair_collisions"] == cells.stats["pair_collisions"]
    np.testing.assert_allclose(b.positions, a.positions, rtol=0, atol=1e-8)
    np.testing.assert_allclose(b.velocities, a.velocities, rtol=0, atol=1e-8)


def test_energy_and_momentum_conserved_over_a_million_collisions():
    """As in test_simulation (same bounds, same reasoning), with lists at packing 0.45."""
    s = _dense(2000, 0.45, seed=11)
    sim = _lists(s)
    tr = sim.run(stop_when={"collisions_per_particle": 1000.0}, store=())
    assert sim.stats["pair_collisions"] >= 1_000_000
    assert tr.kinetic_energy[-1] / tr.kinetic_energy[0] - 1 == pytest.approx(0, abs=1e-13)
    scale = np.sum(s.masses * np.linalg.norm(s.velocities, axis=1))
    assert np.max(np.abs(tr.momentum[-1] - tr.momentum[0])) <= 1e-13 * scale
    final = sim.scene  # constructing it checks overlaps and that everyone is in the box
    assert min_distance_ratio(final, final.positions) >= 1 - 1e-10


@pytest.mark.parametrize("boundary", ["periodic", "walls"])
def test_no_overlaps_at_any_sample_dense_granular(boundary):
    """Packing 0.5 (walls: 0.4), xi = 0.9 with the TC model: no pair closer than contact beyond
    rounding (1e-10 relative) at any of 26 samples."""
    eta = 0.5 if boundary == "periodic" else 0.4  # walls take room: 0.5 does not fit
    s = _dense(1000, eta, boundary=boundary, restitution=0.9, contact_duration=1e-6, seed=5)
    tr = _lists(s).run(t_stop=0.2, sample_times=np.linspace(0, 0.2, 26), store=("positions",))
    for x in tr.positions:
        assert min_distance_ratio(s, x) >= 1 - 1e-10


def test_unwrapped_positions_through_rebuilds():
    """Between rebuilds a particle may stray up to a shell beyond a periodic box; it is
    wrapped back when its list is rebuilt.  Unwrapped positions must still be the
    integral of the velocities (centre of mass moves at P / M to 1e-11), and the current
    scene lies in the box.  N = 5000 also renumbers the particles (N >= 4096, every 16 N
    events), which remaps every list entry and must stay invisible."""
    s = _dense(5000, 0.45, seed=3, remove_drift=False)
    masses = np.linspace(1.0, 3.0, s.n)
    s = s.replace(masses=masses)
    times = np.linspace(0.0, 0.3, 7)
    sim = _lists(s)
    tr = sim.run(t_stop=0.3, sample_times=times)
    assert sim.stats["events"] > 2 * 16 * s.n
    np.testing.assert_array_equal(tr.positions[0], s.positions)
    M = masses.sum()
    P = (masses[:, None] * s.velocities).sum(0)
    com = np.einsum("i,tia->ta", masses, tr.positions) / M
    np.testing.assert_allclose(com, com[0] + np.outer(times, P / M), rtol=0, atol=1e-11)
    np.testing.assert_allclose(sim.unwrapped_positions, tr.positions[-1], rtol=0, atol=1e-12)
    now = sim.scene
    assert np.all((now.positions >= s.lower) & (now.positions < s.upper))
    crossed = np.any(np.abs(sim.unwrapped_positions - now.positions) > 0.5, axis=1)
    assert crossed.sum() >= 10  # some particles did cross the periodic boundary


@pytest.mark.parametrize("boundary", ["periodic", "walls", "sheared"])
def test_lists_mended_at_shell_exits_stay_complete(boundary):
    """A shell exit rebuilds one list and changes only the rows of the neighbours that
    leave or join it (unless the particle was wrapped back into the box, when its image
    codes change and it is linked anew).  After thousands of such exits, in a dense gas
    whose particles also get renumbered (N = 5000), the engine's own check on loading a
    state (csrc/checkpoint.c, check_lists) must find every listed pair listed back the
    other way and every pair of centres within r_i + r_j + 2 delta listed (in a sheared
    box: every centre filed where the flow carries it, every pair whose centres come within
    reach over a list's life from the later of the two builds, through a sliding face too;
    the build times and laps renumbered with the particles)."""
    walls = boundary == "walls"
    s = _dense(5000, 0.4 if walls else 0.45, boundary="walls" if walls else "periodic", seed=8)
    if boundary == "sheared":  # reduced shear rate ~0.5 in a box ~24 diameters high
        s = s.replace(shear_rate=0.5 * math.sqrt(s.temperature) / (2 * s.radii[0]))
    sim = _lists(s)
    sim.run(stop_when={"collisions_per_particle": 30.0}, store=())
    assert sim.stats["shell_exits"] > 2 * s.n
    sim._engine.restore_state(sim._engine.save_state())  # raises if a list is wrong


def test_a_list_that_misses_a_pair_is_refused():
    """The check itself: two spheres within reach (centres 0.12 apart, reach 0.1 + 2 x 0.025)
    list each other through the image code of no shift (13 in 3D); the same pair listed
    through another image, both ways, is symmetric but misses the pair that can collide,
    and is refused; codes that are not each other's opposite are not listed back.  The
    rows are the engine state's last bytes (csrc/checkpoint.c: one entry each here,
    j << 5 | code)."""
    s = Scene([[0.44, 0.5, 0.5], [0.56, 0.5, 0.5]], [[1.0, 0, 0], [-1.0, 0, 0]], 0.05)
    sim = _lists(s)
    state = bytearray(sim._engine.save_state())
    rows = np.frombuffer(bytes(state[-8:]), np.int32)
    assert sorted(rows >> 5) == [0, 1] and list(rows & 31) == [13, 13]
    sim._engine.restore_state(bytes(state))  # as saved: fine
    elsewhere = (rows & ~31) | np.array([14, 12], np.int32)  # shifted by +-L along x
    state[-8:] = elsewhere.astype(np.int32).tobytes()
    with pytest.raises(ValueError, match="misses a particle within reach"):
        sim._engine.restore_state(bytes(state))
    state[-8:] = ((rows & ~31) | 14).astype(np.int32).tobytes()  # not the opposite codes
    with pytest.raises(ValueError, match="not listed back the other way"):
        sim._engine.restore_state(bytes(state))


def test_lists_grow_around_a_large_particle():
    """A particle 8 times wider than the rest with lists: its list must hold every
    particle whose centre is within R + r + 2 delta (delta = 0.25 * 2R) of its own --
    over a hundred here (counted below), far beyond the starting 32 per row, so rows are
    doubled during setup and as the gas moves.  The trajectory must still be the cell
    mode's (which keeps the big particle out of the grid: independent code; short run,
    1e-8 as above) and the big particle must collide."""
    r, big = 0.012, 0.096
    s = tracer_scene(4000, r, big, 3, "periodic", 1.0, seed=6)
    d = s.positions[1:] - s.positions[0]
    d -= np.round(d / s.lengths) * s.lengths
    reach = big + r + 2 * 0.25 * 2 * big
    assert np.sum(np.linalg.norm(d, axis=1) < reach) > 2 * 32  # 128: rows doubled twice
    times = np.linspace(0.0, 0.05, 5)
    lists = _lists(s, shell=0.25, big_ratio=math.inf)
    b = lists.run(t_stop=0.05, sample_times=times)
    a = Simulation(s, shell=0.0).run(t_stop=0.05, sample_times=times)
    np.testing.assert_allclose(b.positions, a.positions, rtol=0, atol=1e-8)
    np.testing.assert_allclose(b.velocities, a.velocities, rtol=0, atol=1e-8)
    assert np.any(b.velocities[-1, 0] != b.velocities[0, 0])


def test_same_result_bit_for_bit_and_continued_runs():
    s = _dense(800, 0.45, restitution=0.9, seed=8)
    one = _lists(s).run(t_stop=0.2, sample_times=[0.1, 0.2])
    sim = _lists(s)
    a = sim.run(t_stop=0.1, sample_times=[0.1])
    b = sim.run(t_stop=0.2, sample_times=[0.2])
    np.testing.assert_array_equal(np.concatenate([a.positions, b.positions]), one.positions)
    np.testing.assert_array_equal(np.concatenate([a.velocities, b.velocities]), one.velocities)


# Dense 3D list-mode runs whose bits must not depend on how the list scan is compiled:
# periodic and walled, elastic and inelastic, a mixture (contact distances differ per
# pair; rows grow), a sheared box (entries through the sliding faces), lists of every
# length mod 4 (the AVX2 scan takes four at a time).
_KERNEL_SCENES = textwrap.dedent(
    """
    import hashlib, math
    import numpy as np
    from granular import Scene, Simulation

    def dense(n, eta, seed, **kw):
        r = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3)
        return Scene.random(n, r, seed=seed, **kw)

    def mixture():
        s = dense(600, 0.4, seed=4, restitution=0.9)
        radii = s.radii * np.where(np.arange(600) % 3 == 0, 1.0, 0.8)
        return Scene(s.positions, s.velocities, radii, restitution=0.9)

    def digests():
        out = {}
        for name, scene in (
            ("periodic", dense(800, 0.45, seed=1)),
            ("walls-inelastic", dense(800, 0.42, seed=2, boundary="walls", restitution=0.8)),
            ("mixture", mixture()),
            ("sheared", dense(800, 0.45, seed=5, restitution=0.9).replace(shear_rate=3.0)),
        ):
            sim = Simulation(scene, shell=0.25)
            assert sim.stats["shell"] == 0.25  # lists, not declined for a small box
            tr = sim.run(stop_when={"collisions_per_particle": 20}, sample_times=[0.01])
            h = hashlib.sha256()
            for a in (tr.positions, tr.velocities, sim.scene.positions, sim.scene.velocities):
                h.update(np.ascontiguousarray(a).tobytes())
            out[name] = (h.hexdigest(), sim.stats["pair_collisions"], sim.stats["stale_events"])
        return out
    """
)


def test_every_compilation_of_the_list_scan_gives_the_same_bits():
    """The 3D list scan runs four candidates at a time in AVX2's lanes where the CPU has
    them (search.h, scan_avx2.h); GRANULAR_SCAN_KERNEL=plain asks for the scalar loop (the
    choice is made at import, so in its own process).  Both give the same bits over 20
    collisions per particle in each scene, where chaos would make any difference in one
    rounding visible."""
    if granular._core.SCAN_KERNEL == "plain":
        pytest.skip("this CPU runs the plain list scan only")
    env = dict(os.environ, GRANULAR_SCAN_KERNEL="plain")
    script = _KERNEL_SCENES + (
        "import json, granular._core\n"
        "print(granular._core.SCAN_KERNEL)\n"
        "print(json.dumps(digests()))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    assert out[0] == "plain"
    here = {}
    exec(_KERNEL_SCENES, here)
    wide = here["digests"]()
    plain = {k: tuple(v) for k, v in json.loads(out[1]).items()}
    assert wide == plain
    assert all(stale > 0 for _, _, stale in wide.values())


def test_collapse_is_detected_and_the_tc_model_finishes():
    """As in test_scene: three disks in a line with xi = 0.05 < 7 - 4 sqrt 3 collapse at
    t = 0.1, raised after a bounded number of collisions; with t_c the run finishes."""
    sim = _lists(three_in_line(0.05))
    with pytest.raises(granular.InelasticCollapseError) as info:
        sim.run(t_stop=10.0)
    assert info.value.time == pytest.approx(0.1, abs=1e-6)
    assert sim.stats["pair_collisions"] < 100
    assert _lists(three_in_line(0.05, tc=1e-3)).run(t_stop=10.0).stop_reason == "time"


def test_automatic_choice():
    """Lists for dense 3D scenes without a big particle; cells otherwise."""
    assert Simulation(_dense(500, 0.45)).stats["shell"] == 0.25
    assert Simulation(_dense(500, 0.3)).stats["shell"] == 0.0
    assert Simulation(_dense(500, 0.6, dim=2)).stats["shell"] == 0.0
    # radii spread by 5 %: one is "big" when big_ratio is below that spread
    s = _dense(500, 0.5)
    s = s.replace(radii=s.radii * np.random.default_rng(1).uniform(0.95, 1.0, s.n))
    assert s.packing_fraction > 0.4
    assert Simulation(s).stats["shell"] == 0.25
    assert Simulation(s, big_ratio=1.01).stats["shell"] == 0.0
    # a box too small for the shell asked for: cells, and stats say so
    tiny = Scene.random(4, 0.1, seed=1)
    assert Simulation(tiny, shell=1.0).stats["shell"] == 0.0


def test_bad_shell():
    s = _dense(100, 0.2)
    for bad in (-0.1, 1e-5, math.nan, math.inf):
        with pytest.raises(ValueError, match="shell"):
            Simulation(s, shell=bad)
    # lists with a particle far wider than the rest: refused unless insisted on
    tracer = tracer_scene(500, 0.01, 0.08, 3, "periodic", 1.0, seed=1)
    with pytest.raises(ValueError, match="big_ratio"):
        Simulation(tracer, shell=0.25)
    assert Simulation(tracer, shell=0.25, big_ratio=math.inf).stats["shell"] == 0.25
    for bad in ("big", True, None):
        with pytest.raises(TypeError, match="shell"):
            Simulation(s, shell=bad)
