"""Checkpoints: Simulation.save / Simulation.load and pickling continue a run bit for bit,
in every engine mode; files get the permissions open() gives; bad files (damaged archives,
other kinds of file, states crafted past the checksum that break a scene's rules or its
initial scene's conservation laws) are refused with CheckpointError, reading no more than
the state needs; corrupted engine states never crash the C core
(tests/helpers/checkpoint_fuzz.py, in a subprocess).

"Bit for bit" is tested as exact equality (np.array_equal, ==) of positions, velocities,
every statistic and every Trajectory array between a Simulation that ran on and one that
was saved and loaded at the same point: no tolerance is involved, a single differing
event order or rounding shows."""

import copy
import io
import json
import math
import os
import pickle
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import granular
from granular import CheckpointError, Scene, Simulation, TabulatedRestitution, Viscoelastic, _core
from granular import checkpoint as ck

HERE = Path(__file__).resolve().parent


def _assert_same_trajectory(a, b):
    assert a.stop_reason == b.stop_reason
    for name in (
        "times",
        "positions",
        "velocities",
        "momentum",
        "kinetic_energy",
        "pair_collisions",
        "wall_collisions",
        "virial",
        "wall_impulse",
        "stress_collisional",
        "kinetic_time_tensor",
        "kinetic_tensor",
    ):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and np.array_equal(x, y), name


def _assert_same_state(a, b):
    sa, sb = a.scene, b.scene
    for name in ("positions", "velocities", "radii", "masses", "lower", "upper"):
        assert np.array_equal(getattr(sa, name), getattr(sb, name)), name
    assert np.array_equal(a.unwrapped_positions, b.unwrapped_positions)
    assert a.stats == b.stats
    assert a.time == b.time


def _continue_after_load(sim, t1, t2, path, samples=9):
    """Run sim to t1, save, then run sim and the loaded copy on to t2 with samples; both
    must agree to the last bit.  Returns the stats at t1 and the loaded Simulation."""
    sim.run(t1)
    at_save = sim.stats
    sim.save(path)
    loaded = Simulation.load(path)
    _assert_same_state(sim, loaded)
    times = np.linspace(t1, t2, samples)
    _assert_same_trajectory(sim.run(t2, sample_times=times), loaded.run(t2, sample_times=times))
    _assert_same_state(sim, loaded)
    # a second leg after the first: the loaded engine's queue, lists and counters keep
    # evolving as the original's
    _assert_same_trajectory(sim.run(t2 * 1.5), loaded.run(t2 * 1.5))
    _assert_same_state(sim, loaded)
    assert sim.stats["pair_collisions"] > at_save["pair_collisions"] > 0, "the test must collide"
    return at_save, loaded


def _tracer_scene(dim, n_small, r_small, r_big, seed, **kw):
    """Small particles on a jittered grid with one big particle (r_big > 3 median radii,
    the engine's big-particle rule) in the middle of a unit box."""
    rng = np.random.default_rng(seed)
    k = math.ceil(n_small ** (1 / dim)) + 2
    axes = [(np.arange(k) + 0.5) / k] * dim
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, dim)
    grid += rng.uniform(-0.1, 0.1, grid.shape) * (1 / k - 2 * r_small)
    centre = np.full(dim, 0.5)
    grid = grid[np.linalg.norm(grid - centre, axis=1) > r_big + r_small + 1e-3][:n_small]
    pos = np.vstack([centre, grid])
    vel = rng.normal(size=pos.shape)
    radii = np.full(len(pos), r_small)
    radii[0] = r_big
    return Scene(pos, vel, radii, box=1.0, **kw)


def _symmetric_lattice():
    """A square lattice whose rows move left and right and whose columns up and down:
    events at exactly equal times everywhere (many pairs collide at one instant), where
    the order of ties in the queue and the cell lists decides which comes first."""
    k = 16  # spacing and positions binary fractions: equal distances exactly
    g = (np.arange(k) + 0.5) / k
    pos = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    vel = np.zeros_like(pos)
    vel[:, 0] = np.where((np.arange(k * k) // k) % 2 == 0, 1.0, -1.0)
    vel[:, 1] = np.where(np.arange(k * k) % 2 == 0, 0.5, -0.5)
    return Scene(pos, vel, 0.015, box=1.0, restitution=0.9)


# -- every mode continues bit for bit ---------------------------------------------------

MODES = {
    "2d-periodic-cells": lambda: (Scene.random(300, 0.01, dim=2, restitution=0.9, seed=1), {}),
    "3d-periodic-cells": lambda: (Scene.random(300, 0.03, dim=3, restitution=0.95, seed=2), {}),
    # dense 3D: shell="auto" takes neighbour lists (checked below)
    "3d-dense-lists": lambda: (Scene.random(400, 0.063, dim=3, seed=3), {}),
    "2d-lists": lambda: (Scene.random(300, 0.015, dim=2, seed=4), {"shell": 0.25}),
    "2d-walls-inelastic": lambda: (
        Scene.random(200, 0.012, dim=2, boundary="walls", wall_restitution=0.9, seed=5),
        {},
    ),
    "3d-heated-walls": lambda: (
        Scene.random(
            200, 0.03, dim=3, boundary="walls", restitution=0.8, wall_restitution=1.05, seed=6
        ),
        {},
    ),
    # TC model: xi well below 1 and a contact duration long enough that it acts
    "2d-tc-model": lambda: (
        Scene.random(300, 0.012, dim=2, restitution=0.3, contact_duration=1e-3, seed=7),
        {},
    ),
    "3d-tc-walls": lambda: (
        Scene.random(
            200,
            0.03,
            dim=3,
            boundary="walls",
            restitution=0.4,
            wall_restitution=0.7,
            contact_duration=1e-3,
            seed=8,
        ),
        {},
    ),
    "2d-big-tracer": lambda: (_tracer_scene(2, 300, 0.008, 0.08, seed=9), {}),
    "3d-big-tracer-walls": lambda: (
        _tracer_scene(3, 300, 0.02, 0.15, seed=10, boundary="walls", restitution=0.9),
        {},
    ),
    "2d-symmetric-lattice": lambda: (_symmetric_lattice(), {}),
    # restitution laws (their own compiled loop); eps = 0.8 at |v_n| = 1 puts the fastest
    # impacts past the series' range, so the clamp counter is saved and restored too
    "3d-viscoelastic": lambda: (
        Scene.random(
            300, 0.03, dim=3, restitution=Viscoelastic.from_restitution(0.8, 1.0), seed=12
        ),
        {},
    ),
    "2d-tabulated-walls": lambda: (
        Scene.random(
            200,
            0.012,
            dim=2,
            boundary="walls",
            restitution=TabulatedRestitution([0.0, 0.5, 2.0], [1.0, 0.9, 0.7]),
            wall_restitution=TabulatedRestitution([0.0, 1.0], [0.95, 0.85]),
            seed=13,
        ),
        {},
    ),
    # the stress tensor's accumulators (csrc/stress.h), with walls and with lists
    "3d-stress-walls": lambda: (
        Scene.random(200, 0.03, dim=3, boundary="walls", restitution=0.9, seed=15),
        {"stress": True},
    ),
    "2d-stress-lists": lambda: (
        Scene.random(300, 0.015, dim=2, seed=16),
        {"shell": 0.25, "stress": True},
    ),
    "3d-mixture-cell-factor": lambda: (
        Scene.random(300, np.linspace(0.02, 0.035, 300), dim=3, seed=11),
        {"cell_factor": 1.5, "big_ratio": math.inf},
    ),
}


@pytest.mark.parametrize("mode", sorted(MODES))
def test_a_loaded_simulation_continues_bit_for_bit(mode, tmp_path):
    scene, knobs = MODES[mode]()
    sim = Simulation(scene, **knobs)
    # about 15 and then 30 collisions per particle: long enough for cell crossings, shell
    # exits, queue rebuilds and (TC) elastic collisions on both sides of the save
    stop = {"collisions_per_particle": 15}
    sim.run(stop_when=stop)
    t1 = sim.time
    _, loaded = _continue_after_load(sim, t1 * 1.01, t1 * 2.0, tmp_path / "run.ckpt")
    stats = loaded.stats
    if "lists" in mode:
        assert stats["shell"] > 0
    else:
        assert stats["shell"] == 0
    if "tc" in mode:
        assert stats["tc_elastic_collisions"] > 0, "the TC model must have acted"
    if "walls" in mode:
        assert stats["wall_collisions"] > 0
    if "viscoelastic" in mode:
        assert stats["law_clamped_collisions"] > 0, "the clamp counter must be exercised"
        assert loaded.scene.restitution == scene.restitution
    if "big" in mode:
        s = loaded.scene
        big = _core.big_particles(s.radii, s.lengths, granular.scene.BIG_RATIO, 1.0)
        assert big.sum() == 1, "the tracer must be a big particle (csrc/big.c)"


def test_renumbering_large_systems_continue_bit_for_bit(tmp_path):
    """N >= 4096 renumbers particles in cell order every 16 N events (csrc/renumber.c):
    save after one renumbering and continue past the next."""
    scene = Scene.random(5000, 0.002, dim=2, restitution=0.95, seed=12)
    sim = Simulation(scene)
    sim.run(stop_when={"events": 16 * 5000 + 1234})  # one renumbering behind
    t1 = sim.time
    sim.save(tmp_path / "big.ckpt")
    loaded = Simulation.load(tmp_path / "big.ckpt")
    budget = {"events": 2 * 16 * 5000}  # two more ahead
    _assert_same_trajectory(sim.run(stop_when=budget), loaded.run(stop_when=budget))
    _assert_same_state(sim, loaded)
    assert sim.stats["events"] > 3 * 16 * 5000 and sim.time > t1


def test_a_grid_out_of_cache_continues_bit_for_bit(tmp_path):
    """A cell grid past _core.HEADS_CACHED bytes: the event loop prefetches events ahead
    and its queue keeps more keys at hand (calendar.h's depth), state a checkpoint must
    carry exactly."""
    n = 40_000
    scene = Scene.random(n, (0.05 / (n * 4 / 3 * math.pi)) ** (1 / 3), restitution=0.9, seed=14)
    sim = Simulation(scene)
    assert 4 * math.prod(sim.stats["cells"]) > _core.HEADS_CACHED
    sim.run(stop_when={"events": 100_000})
    sim.save(tmp_path / "grid.ckpt")
    loaded = Simulation.load(tmp_path / "grid.ckpt")
    budget = {"events": 200_000}
    _assert_same_trajectory(sim.run(stop_when=budget), loaded.run(stop_when=budget))
    _assert_same_state(sim, loaded)


def test_saving_changes_nothing_and_a_split_run_equals_one_run(tmp_path):
    """Saving only reads the engine; and stopping at t1 does not perturb the dynamics, so
    run(t1), save, load, run(t2) equals a single run(t2) of a Simulation that never
    stopped."""
    scene = Scene.random(300, 0.012, dim=2, restitution=0.8, contact_duration=1e-4, seed=13)
    never = Simulation(scene)
    never.run(1.0)
    t2 = 2 * never.time
    whole = Simulation(scene)
    whole.run(t2)
    split = Simulation(scene)
    split.run(0.4 * t2)
    split.save(tmp_path / "a")
    split.save(tmp_path / "b")
    assert (tmp_path / "a").read_bytes() == (tmp_path / "b").read_bytes()
    loaded = Simulation.load(tmp_path / "a")
    loaded.save(tmp_path / "c")  # a loaded Simulation saves the very same file
    assert (tmp_path / "c").read_bytes() == (tmp_path / "a").read_bytes()
    loaded.run(t2)
    _assert_same_state(whole, loaded)


def test_pickle_and_copy_give_independent_engines():
    """Pickling (Dask, multiprocessing) and copy.copy / copy.deepcopy go through a
    checkpoint: the copy continues bit for bit and runs on its own engine."""
    sim = Simulation(Scene.random(200, 0.015, dim=2, restitution=0.9, seed=14))
    sim.run(0.5)
    copies = [pickle.loads(pickle.dumps(sim)), copy.copy(sim), copy.deepcopy(sim)]
    for c in copies:
        assert c._engine is not sim._engine
    c = copies[0]
    c.run(1.0)  # one runs ahead: the others must not move
    assert c.time == 1.0 and sim.time == 0.5 and copies[1].time == 0.5
    sim.run(1.0)
    for other in copies[1:]:
        other.run(1.0)
    for other in copies:
        _assert_same_state(sim, other)


def test_save_writes_atomically_and_refuses_during_a_run(tmp_path):
    sim = Simulation(Scene.random(50, 0.02, dim=2, seed=15))
    path = tmp_path / "x.ckpt"
    sim.save(path)
    assert os.listdir(tmp_path) == ["x.ckpt"], "no temporary file left behind"
    assert sim._running.acquire(blocking=False)  # as a running thread holds it
    try:
        with pytest.raises(RuntimeError, match="between runs"):
            sim.save(path)
        with pytest.raises(RuntimeError, match="between runs"):
            pickle.dumps(sim)
    finally:
        sim._running.release()


# -- bad files are refused clearly ------------------------------------------------------


@pytest.fixture(scope="module")
def saved():
    sim = Simulation(Scene.random(100, 0.02, dim=2, restitution=0.9, seed=16))
    sim.run(0.5)
    return ck.dumps(sim)


def _rewrite_meta(data, **changes):
    with np.load(__import__("io").BytesIO(data)) as npz:
        arrays = {k: npz[k] for k in npz.files}
    meta = json.loads(str(arrays["meta"][()]))
    meta.update(changes)
    arrays["meta"] = np.array(json.dumps(meta))
    buf = __import__("io").BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def test_files_from_another_version_are_refused(saved, tmp_path):
    for field, value in (
        ("granular_version", "0.0.1"),
        ("format_version", 99),
        ("layout", "12345"),
    ):
        path = tmp_path / f"{field}.ckpt"
        path.write_bytes(_rewrite_meta(saved, **{field: value}))
        with pytest.raises(CheckpointError, match=r"written by granular .* this is granular"):
            Simulation.load(path)
    assert Simulation._loads(saved).time == 0.5  # the unaltered bytes load


def test_truncated_corrupt_and_foreign_files_are_refused(saved, tmp_path):
    path = tmp_path / "bad.ckpt"
    rng = np.random.default_rng(17)
    cuts = sorted({0, 1, 10, len(saved) // 2, len(saved) - 1, *rng.integers(0, len(saved), 20)})
    for cut in cuts:
        path.write_bytes(saved[:cut])
        with pytest.raises(CheckpointError, match=r"truncated or corrupt|not a granular"):
            Simulation.load(path)
    for _ in range(30):  # flipped bytes: the zip's CRC-32, the header or the checksum see it
        data = bytearray(saved)
        k = int(rng.integers(0, len(data)))
        data[k] ^= int(rng.integers(1, 256))
        path.write_bytes(bytes(data))
        try:
            Simulation.load(path)
        except CheckpointError:
            continue
        # a flip in bytes no reader uses (zip padding, the header's timestamps) is harmless
    path.write_text("not a checkpoint")
    with pytest.raises(CheckpointError, match="not a granular checkpoint"):
        Simulation.load(path)
    other = tmp_path / "other.npz"
    np.savez(other, meta=np.array(json.dumps({"format": "something else"})))
    with pytest.raises(CheckpointError, match="not a granular checkpoint"):
        Simulation.load(other)
    # a missing or unreadable file is the OSError open() gives, as granular.read does
    with pytest.raises(FileNotFoundError):
        Simulation.load(tmp_path / "missing.ckpt")
    with pytest.raises(FileNotFoundError):
        granular.read(tmp_path / "missing.gsd")
    with pytest.raises(CheckpointError, match="not a regular file"):
        Simulation.load(tmp_path)  # a directory
    with zipfile.ZipFile(tmp_path / "empty.npz", "w"):
        pass
    with pytest.raises(CheckpointError):
        Simulation.load(tmp_path / "empty.npz")


def test_an_engine_state_for_another_scene_is_refused(saved):
    """A state whose checksum matches but which belongs to another scene or other knobs:
    the C core compares sizes, config, radii and masses."""
    _, arrays = ck._read_npz(saved, "x")
    state = bytes(arrays["engine_state"])
    base = Scene.random(100, 0.02, dim=2, restitution=0.9, seed=16)
    engine = Simulation(base)._engine
    engine.restore_state(state)  # its own scene: fine
    for scene, knobs, why in (
        (base.replace(restitution=0.5), {}, "restitution"),
        (base.replace(masses=np.full(base.n, 2.0)), {}, "mass"),
        (base, {"shell": 0.25}, "sizes differ"),
        (base, {"cell_factor": 2.0}, "sizes differ|knobs"),
        (Scene.random(101, 0.02, dim=2, seed=16), {}, "sizes differ"),
    ):
        with pytest.raises(ValueError, match=why):
            Simulation(scene, **knobs)._engine.restore_state(state)


def _rewrite_state(data, edit):
    """The checkpoint bytes with the engine state passed through edit(bytearray) and its
    checksum made to match, as a file crafted past the checksum would be."""
    with np.load(__import__("io").BytesIO(data)) as npz:
        arrays = {k: npz[k] for k in npz.files}
    state = bytearray(arrays["engine_state"].tobytes())
    edit(state)
    arrays["engine_state"] = np.frombuffer(bytes(state), dtype=np.uint8)
    meta = json.loads(str(arrays["meta"][()]))
    meta["engine_state_sha256"] = __import__("hashlib").sha256(bytes(state)).hexdigest()
    arrays["meta"] = np.array(json.dumps(meta))
    buf = __import__("io").BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


# the neighbour-list capacity in the engine state's header (csrc/checkpoint.c, `header`):
# magic 8, version 4, byte order 4, layout 8, total 8, n 8, dim, stride, lists, nb,
# ncells 4 each, nc 3 x 4, then cap (int32)
CAP_AT = 72


def test_a_neighbour_list_capacity_the_engine_could_not_reach_is_refused(tmp_path):
    """The rows (n x cap int32) are allocated from the header's cap before the rest is
    read: only a capacity the engine itself could have grown to is accepted -- 32 (3D)
    doubled while a row of cap / 2 could overflow, which with n = 60 particles (59 others
    to list) is 32 or 64 -- not 128, not the largest list the engine allows (16384), not
    one that is no doubling (48)."""
    sim = Simulation(Scene.random(60, 0.1, dim=3, seed=3), shell=0.25)
    sim.run(stop_when={"events": 300})
    assert sim.stats["shell"] > 0
    data = ck.dumps(sim)
    _, arrays = ck._read_npz(data, "x")
    assert int(np.frombuffer(arrays["engine_state"], np.int32, 1, CAP_AT)[0]) == 32

    def with_cap(cap):
        def edit(state):
            state[CAP_AT : CAP_AT + 4] = np.int32(cap).tobytes()

        return _rewrite_state(data, edit)

    path = tmp_path / "cap.npz"
    path.write_bytes(with_cap(64))  # reachable: loads, and runs on as the original
    loaded = Simulation.load(path)
    more = {"events": 600}
    _assert_same_trajectory(sim.run(stop_when=more), loaded.run(stop_when=more))
    for cap in (128, 16384, 48, 2**31 - 1):
        path.write_bytes(with_cap(cap))
        with pytest.raises(CheckpointError, match=r"neighbour-list capacity \(header field cap\)"):
            Simulation.load(path)


def test_a_restitution_law_other_than_the_saved_one_is_refused(tmp_path):
    """The engine state holds the laws (kind, parameters, table); a file whose scene
    description names another law (the JSON edited, the engine state untouched), or an
    engine built with another law, is refused, as a different scalar restitution is."""
    law = TabulatedRestitution([0.0, 0.5, 2.0], [1.0, 0.9, 0.7])
    wall = Viscoelastic.from_restitution(0.9, 1.0)
    base = Scene.random(
        100, 0.02, dim=2, boundary="walls", restitution=law, wall_restitution=wall, seed=16
    )
    sim = Simulation(base)
    sim.run(0.3)
    data = ck.dumps(sim)
    assert Simulation._loads(data).stats == sim.stats  # the unaltered bytes load
    meta, _ = ck._read_npz(data, "x")
    others = {
        "restitution": (
            TabulatedRestitution([0.0, 0.5, 2.0], [1.0, 0.9, 0.69]),  # one value
            TabulatedRestitution([0.0, 0.5, 2.0, 3.0], [1.0, 0.9, 0.7, 0.7]),  # one more point
            Viscoelastic.from_restitution(0.9, 1.0),  # another kind
            0.9,  # a number
        ),
        "wall_restitution": (
            Viscoelastic.from_restitution(0.91, 1.0),  # another damping
            TabulatedRestitution([0.0], [0.9]),
        ),
    }
    path = tmp_path / "law.npz"
    state = bytes(ck._read_npz(data, "x")[1]["engine_state"])
    for name, laws in others.items():
        for other in laws:
            scene = dict(meta["scene"], **{name: granular.restitution.describe(other)})
            path.write_bytes(_rewrite_meta(data, scene=scene))
            with pytest.raises(CheckpointError, match="restitution law"):
                Simulation.load(path)
            with pytest.raises(ValueError, match="restitution law"):
                Simulation(base.replace(**{name: other}))._engine.restore_state(state)


# the counters the engine state holds, in order, from `events` on (csrc/checkpoint.c)
COUNTERS = ("events", "pair", "wall", "invalid", "elastic_tc", "law_clamped")


@pytest.mark.parametrize("name", COUNTERS)
def test_negative_or_overflowing_counters_are_refused(saved, name, tmp_path):
    """Counters start at 0 and grow by one: a file with one negative, or past
    INT64_MAX / 2 where the next increments could overflow, is corrupt; INT64_MAX / 2
    itself loads.  The counters are found by their values (events, pair and wall
    collisions side by side as int64)."""
    stats = Simulation._loads(saved).stats
    _, arrays = ck._read_npz(saved, "x")
    known = np.array(
        [stats["events"], stats["pair_collisions"], stats["wall_collisions"]], np.int64
    ).tobytes()
    at = bytes(arrays["engine_state"]).find(known)
    assert at > 0 and bytes(arrays["engine_state"]).count(known) == 1
    at += 8 * COUNTERS.index(name)
    path = tmp_path / "count.npz"

    def with_value(v):
        def edit(state):
            state[at : at + 8] = np.int64(v).tobytes()

        return _rewrite_state(saved, edit)

    path.write_bytes(with_value(2**62 - 1))  # INT64_MAX // 2
    Simulation.load(path)
    for v in (-1, -(2**63), 2**62, 2**63 - 1):
        path.write_bytes(with_value(v))
        with pytest.raises(CheckpointError, match=f"counter {name} is negative or past"):
            Simulation.load(path)


@pytest.mark.parametrize("field", ["count", "pcount"])
def test_negative_or_overflowing_particle_counters_are_refused(field, tmp_path):
    """Each particle's collision counter (and the copy of its partner's its prediction
    keeps) likewise.  Two disks stopped right after their one collision: each scheduling
    state holds t_last = that time then count = 1, pcount (csrc/schedstate.h)."""
    s = Scene([[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]], 0.05, boundary="walls")
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 1e-9})
    assert sim.stats["pair_collisions"] == 1
    data = ck.dumps(sim)
    state = bytes(ck._read_npz(data, "x")[1]["engine_state"])
    known = np.float64(sim.time).tobytes() + np.int64(1).tobytes()
    assert state.count(known) == 2
    at = state.find(known) + 8 + (8 if field == "pcount" else 0)
    path = tmp_path / "count.npz"
    for v in (-1, 2**62):

        def edit(state, v=v):
            state[at : at + 8] = np.int64(v).tobytes()

        path.write_bytes(_rewrite_state(data, edit))
        with pytest.raises(CheckpointError, match=r"collision counter .*negative or past"):
            Simulation.load(path)


def test_corrupted_engine_states_never_crash_the_core():
    """Thousands of corrupted engine states (truncated, bytes flipped, words overwritten
    with indices just out of range, NaN and inf), fed straight to the C restore past the
    file's checksums, in a subprocess: each is refused with ValueError or, if it passes
    the checks (a changed position or velocity is a valid state), runs a bounded number
    of events ending in a result or a GranularError.  A crash (or an ASan report) fails."""
    proc = subprocess.run(
        [sys.executable, str(HERE / "helpers" / "checkpoint_fuzz.py"), "1500"],
        capture_output=True,
        text=True,
        cwd=HERE,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    # both outcomes must occur, or the corruption is too weak or too strong to test much
    assert summary["refused"] > 300 and summary["accepted"] > 50, summary


@pytest.mark.parametrize(
    "stop",
    [{"collisions_per_particle": 7}, {"kinetic_energy": 0.3}, {"events": 4321}],
)
def test_saving_where_a_stop_criterion_ended_the_run(stop, tmp_path):
    """A run that stopped right after an event (a criterion, an event budget) rather than
    at a time in between events continues bit for bit too."""
    scene = Scene.random(200, 0.015, dim=2, restitution=0.7, temperature=1.0, seed=18)
    sim = Simulation(scene)
    sim.run(stop_when=stop)
    sim.save(tmp_path / "s")
    loaded = Simulation.load(tmp_path / "s")
    more = {"collisions_per_particle": 20}
    _assert_same_trajectory(sim.run(stop_when=more), loaded.run(stop_when=more))
    _assert_same_state(sim, loaded)


def test_a_state_that_cannot_continue_is_not_saved(tmp_path):
    """Walls that multiply speeds by 1e100 overflow them to inf within three bounces: the
    run stops with NonFiniteError, and saving that state is refused (nothing written)."""
    scene = Scene.random(5, 0.01, dim=2, boundary="walls", wall_restitution=1e100, seed=19)
    sim = Simulation(scene)
    with pytest.raises((granular.NonFiniteError, granular.HeatedWallsError)):
        sim.run(1.0)
    with pytest.raises(CheckpointError, match="cannot continue"):
        sim.save(tmp_path / "inf")
    assert not list(tmp_path.iterdir())


# -- files get the permissions a plain open() gives ---------------------------------------


@pytest.mark.parametrize("umask", [0o022, 0o027])
def test_files_get_the_permissions_a_plain_open_gives(umask, tmp_path):
    """Checkpoints and an ensemble's run files (both written by _files.write_atomic) are
    readable by whom the user's umask lets read a file: 0o666 less the umask for a new
    file, as open() makes it; a file replaced keeps its own mode, as open() keeps it."""
    from granular._files import write_atomic

    sim = Simulation(Scene.random(20, 0.02, dim=2, seed=31))
    old = os.umask(umask)
    try:
        with open(tmp_path / "plain", "wb") as f:
            f.write(b"x")
        sim.save(tmp_path / "ck.npz")
        write_atomic(tmp_path / "run.npz", b"data")
    finally:
        os.umask(old)
    want = 0o666 & ~umask
    assert os.stat(tmp_path / "plain").st_mode & 0o777 == want
    for name in ("ck.npz", "run.npz"):
        assert os.stat(tmp_path / name).st_mode & 0o777 == want, name
    os.chmod(tmp_path / "ck.npz", 0o640)
    sim.save(tmp_path / "ck.npz")
    assert os.stat(tmp_path / "ck.npz").st_mode & 0o777 == 0o640
    assert sorted(os.listdir(tmp_path)) == ["ck.npz", "plain", "run.npz"]


# -- another kind of file: say what it is and what reads it ---------------------------------


def test_a_gsd_file_given_to_load_and_a_checkpoint_given_to_read_are_named(saved, tmp_path):
    """Simulation.load of a GSD file says it is one and names granular.read (not NumPy's
    advice to load with allow_pickle); granular.read of a checkpoint names
    Simulation.load; a lone .npy names numpy.load."""
    gsd = tmp_path / "run.gsd"
    gsd.write_bytes(b"\xdf\x65\xdf\x65\xdf\x65\xdf\x65" + bytes(200))  # GSD's magic number
    with pytest.raises(
        CheckpointError, match=r"'.*run\.gsd' .* GSD trajectory file .*granular\.read"
    ) as exc:
        Simulation.load(gsd)
    assert "pickle" not in str(exc.value)
    npy = tmp_path / "a.npy"
    np.save(npy, np.arange(3))
    with pytest.raises(CheckpointError, match=r"\.npy array \(read it with numpy\.load"):
        Simulation.load(npy)
    ck_file = tmp_path / "ck.npz"
    ck_file.write_bytes(saved)
    # each reader's own error class, as the docs promise for a bad file
    with pytest.raises(granular.GSDFileError, match=r"'.*ck\.npz' is not a GSD .*Simulation\.load"):
        granular.read(ck_file)
    with pytest.raises(granular.GSDFileError, match=r"not a GSD .*Simulation\.load"):
        Scene.from_gsd(ck_file)


# -- damaged and crafted archives: CheckpointError, and no more read than the state needs --


def _zip_members(data):
    with zipfile.ZipFile(__import__("io").BytesIO(data)) as zf:
        return {i.filename: zf.read(i) for i in zf.infolist()}


def _zip(members, compress=zipfile.ZIP_STORED):
    buf = __import__("io").BytesIO()
    with zipfile.ZipFile(buf, "w", compress) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    return buf.getvalue()


def _npy(array_or_header, data=b""):
    buf = __import__("io").BytesIO()
    if isinstance(array_or_header, dict):  # a header alone, then the given data
        np.lib.format.write_array_header_1_0(buf, array_or_header)
        buf.write(data)
    else:
        np.save(buf, array_or_header)
    return buf.getvalue()


def test_damaged_archives_raise_checkpoint_error_only(saved, tmp_path):
    """A compression method zipfile does not know (NotImplementedError), an encrypted
    member (RuntimeError), JSON nested 10^5 deep (RecursionError), a .npy header claiming
    2^40 elements (MemoryError) and a device that never ends (/dev/zero) are each refused
    with CheckpointError."""
    members = _zip_members(saved)
    path = tmp_path / "bad.npz"

    def refused(data, match=None):
        path.write_bytes(data)
        with pytest.raises(CheckpointError, match=match):
            Simulation.load(path)
        with pytest.raises(CheckpointError, match=match):
            Simulation._loads(data)

    # the method and flag bits in the local and central headers of the first member
    method = bytearray(saved)
    for sig, at in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        k = method.find(sig)
        method[k + at : k + at + 2] = (99).to_bytes(2, "little")
    refused(bytes(method), "compressed or encrypted")
    encrypted = bytearray(saved)
    for sig, at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        k = encrypted.find(sig)
        encrypted[k + at] |= 1
    refused(bytes(encrypted), "compressed or encrypted")
    refused(_zip(dict(members, **{"meta.npy": _npy(np.array("[" * 100_000))})))
    for name, dtype, shape in (
        ("scene_radii.npy", "<f8", (2**40,)),
        ("scene_positions.npy", "<f8", (2**40, 2)),
        ("engine_state.npy", "|u1", (2**40,)),
    ):
        header = {"descr": dtype, "fortran_order": False, "shape": shape}
        bad = _zip(dict(members, **{name: _npy(header, bytes(800))}))
        refused(bad, r"an array of shape|800 bytes of data for an array of \d{13,} bytes")
    with pytest.raises(CheckpointError, match="not a regular file"):
        Simulation.load("/dev/zero")
    refused(_zip(dict(members, extra=b"x")), "a checkpoint holds exactly")


def test_checkpoints_and_run_files_are_read_by_one_set_of_rules(saved, tmp_path):
    """The rules of granular/_npz.py, which the run files' reader has too: a FIFO is
    refused, not waited on for a writer; an .npy member of a version np.save does not
    write for plain arrays (3.0), or in Fortran order, is refused."""
    import threading

    fifo = tmp_path / "fifo.npz"
    os.mkfifo(fifo)
    got = []

    def load():
        try:
            Simulation.load(fifo)
        except (CheckpointError, OSError) as exc:
            got.append(exc)

    reader = threading.Thread(target=load, daemon=True)
    reader.start()
    reader.join(timeout=30)
    if reader.is_alive():  # blocked in open(): give it a writer, so that it ends
        with open(fifo, "wb"):
            pass
        reader.join(timeout=30)
        pytest.fail("Simulation.load waited on a FIFO for a writer")
    assert isinstance(got[0], CheckpointError) and "not a regular file" in str(got[0]), got
    members = _zip_members(saved)
    path = tmp_path / "bad.npz"
    v2 = io.BytesIO()
    radii = np.load(io.BytesIO(members["scene_radii.npy"]))
    header = np.lib.format.header_data_from_array_1_0(radii)
    np.lib.format.write_array_header_2_0(v2, header)
    v3 = bytearray(v2.getvalue())
    v3[6] = 3  # the same header as version 3.0 (UTF-8 where 2.0 is Latin-1: the same bytes)
    path.write_bytes(_zip(dict(members, **{"scene_radii.npy": bytes(v3) + radii.tobytes()})))
    with pytest.raises(CheckpointError, match=r"scene_radii\.npy: \.npy version \(3, 0\)"):
        Simulation.load(path)
    # the same header as version 2.0 is read: only the version differs
    path.write_bytes(_zip(dict(members, **{"scene_radii.npy": v2.getvalue() + radii.tobytes()})))
    Simulation.load(path)
    fortran = dict(header, fortran_order=True)
    path.write_bytes(_zip(dict(members, **{"scene_radii.npy": _npy(fortran, radii.tobytes())})))
    with pytest.raises(CheckpointError, match="Fortran-ordered"):
        Simulation.load(path)


def test_an_extra_deflated_member_is_refused_unread(saved, tmp_path):
    """A checkpoint with one more member of 256 MiB of zeros, deflated to 256 kB: refused
    before anything of it is inflated (Python's allocations peak far below its size)."""
    import tracemalloc

    path = tmp_path / "bomb.npz"
    path.write_bytes(saved)
    with zipfile.ZipFile(path, "a", zipfile.ZIP_DEFLATED) as zf:
        with zf.open("extra.npy", "w", force_zip64=True) as member:
            chunk = bytes(1 << 20)
            for _ in range(256):
                member.write(chunk)
    assert path.stat().st_size < 2 * len(saved) + (1 << 20)
    tracemalloc.start()
    try:
        with pytest.raises(CheckpointError, match="compressed"):
            Simulation.load(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 16 * len(saved) + (4 << 20), peak


# -- a loaded state must be one its scene could reach, and can go on from -----------------


def _small(boundary="periodic", restitution=1.0, **kw):
    """Nine disks on a grid with distinct masses (found by them in the engine state)."""
    g = (np.arange(3) + 0.5) / 3
    pos = np.array([[x, y] for x in g for y in g])
    vel = np.random.default_rng(41).normal(size=pos.shape)
    masses = np.linspace(0.6, 1.0, 9)
    return Scene(pos, vel, 0.05, masses, boundary=boundary, restitution=restitution, **kw)


def _edit_records(data, scene, change):
    """The checkpoint with change(P, image) applied to the engine state's particle records
    (n x 8 doubles: x, v, clock, radius, padded to one cache line) and image counters
    (n x d int64), which lie either side of the masses; no renumbering below 4096
    particles: scene order."""

    def edit(state):
        at = bytes(state).find(scene.masses.tobytes())
        assert at > 0 and bytes(state).count(scene.masses.tobytes()) == 1
        n, d = scene.n, scene.dim
        p0, i0 = at - 8 * n * 8, at + 8 * n
        records = np.frombuffer(state[p0:at], np.float64).reshape(n, 8).copy()
        image = np.frombuffer(state[i0 : i0 + 8 * n * d], np.int64).reshape(n, d).copy()
        change(records, image)
        state[p0:at] = records.tobytes()
        state[i0 : i0 + 8 * n * d] = image.tobytes()

    return _rewrite_state(data, edit)


def _set(**columns):
    """A change of records: {"x0": (particle, value), "v0": ...} (x0 = first coordinate)."""

    def change(records, image):
        for name, (i, value) in columns.items():
            records[i, {"x": 0, "v": 2}[name[0]] + int(name[1])] = value

    return change


def test_a_state_that_breaks_the_rules_of_a_scene_is_refused(tmp_path):
    """States crafted past the checksum at t = 0 (so that positions are those at the
    clocks): two particles at one place, a particle through a wall, a speed of 1e140
    (within the scale limits in a unit box with masses <= 1, but 1e280 times the initial
    energy) are refused as a new scene would be; the unaltered file loads."""
    path = tmp_path / "state.npz"
    walls = _small("walls")
    data = ck.dumps(Simulation(walls))
    Simulation._loads(data)
    cases = (
        (_set(x0=(1, walls.positions[0, 0]), x1=(1, walls.positions[0, 1])), "overlap"),
        (_set(x0=(0, 1.1)), "crosses a wall"),
        (_set(v0=(0, 1e140)), "kinetic energy .* exceeds the initial scene's"),
    )
    for change, why in cases:
        path.write_bytes(_edit_records(data, walls, change))
        with pytest.raises(CheckpointError, match=f"is corrupt: .*{why}"):
            Simulation.load(path)


def test_a_state_its_initial_scene_cannot_reach_is_refused(tmp_path):
    """The stored initial scene bounds the state: collisions without heated walls never
    add kinetic energy, elastic ones keep it, and a periodic box keeps the momentum (to a
    relative 1e-6: rounding drifts them by ~1e-15 in 5e5 collisions)."""
    path = tmp_path / "state.npz"

    def scaled(factor, shift=0.0):
        def change(records, image):
            records[:, 2:4] = records[:, 2:4] * factor + shift

        return change

    for scene, change, why in (
        (_small(), scaled(0.5), "below the initial scene's .* elastic"),
        (_small(restitution=0.5), scaled(1.01), "exceeds the initial scene's"),
        (_small(restitution=0.5), scaled(0.5, 0.1), "momentum differs"),
        (_small("walls", wall_restitution=0.9), scaled(1.01), "exceeds"),
    ):
        data = ck.dumps(Simulation(scene))
        path.write_bytes(_edit_records(data, scene, change))
        with pytest.raises(CheckpointError, match=why):
            Simulation.load(path)
    heated = _small("walls", wall_restitution=1.5)  # heated walls may add energy
    data = ck.dumps(Simulation(heated))
    path.write_bytes(_edit_records(data, heated, scaled(1.01)))
    Simulation.load(path)


def test_an_image_counter_no_crossing_could_make_is_refused(tmp_path):
    """Each change of an image counter is a cell crossing or a shell exit through a periodic
    box's face, so none is larger than their count: INT64_MIN (whose decrement overflowed,
    and whose unwrapped position flipped sign) or one more than the crossings is refused; as
    many loads.  Between walls every counter is 0."""
    scene = _small()
    sim = Simulation(scene)
    sim.run(3.0)
    moves = sim.stats["cell_crossings"] + sim.stats["shell_exits"]
    assert np.any(sim._engine.state()[2] != 0) and moves > 0
    data = ck.dumps(sim)
    path = tmp_path / "image.npz"

    def image(value):
        def change(records, image):
            image[4, 1] = value

        return change

    path.write_bytes(_edit_records(data, scene, image(-moves)))
    assert Simulation.load(path).unwrapped_positions[4, 1] < -moves + 1
    for value in (-(2**63), 2**63 - 1, moves + 1):
        path.write_bytes(_edit_records(data, scene, image(value)))
        with pytest.raises(CheckpointError, match="image counter is larger than the cell"):
            Simulation.load(path)
    # between walls nothing wraps: every counter is 0, however many cells were crossed
    walls = _small("walls")
    sim = Simulation(walls)
    sim.run(3.0)
    assert sim.stats["cell_crossings"] > 0
    path.write_bytes(_edit_records(ck.dumps(sim), walls, image(1)))
    with pytest.raises(CheckpointError, match="image counter is larger than the cell"):
        Simulation.load(path)


def test_a_stored_scene_that_is_no_scene_is_refused(saved, tmp_path):
    """The stored initial scene is checked as Scene(...) checks one, and what that raises
    (ValueError; OverflowError for a number of 400 digits in the JSON) comes out as
    CheckpointError."""
    members = _zip_members(saved)
    path = tmp_path / "scene.npz"
    meta, _ = ck._read_npz(saved, "x")
    for name in ("contact_duration", "restitution"):
        path.write_bytes(_rewrite_meta(saved, scene=dict(meta["scene"], **{name: 10**400})))
        with pytest.raises(CheckpointError, match="is corrupt"):
            Simulation.load(path)
    for name, value in (("positions", np.nan), ("radii", -1.0), ("masses", np.inf)):
        arr = np.load(__import__("io").BytesIO(members[f"scene_{name}.npy"])).copy()
        arr.flat[0] = value
        path.write_bytes(_zip(dict(members, **{f"scene_{name}.npy": _npy(arr)})))
        with pytest.raises(CheckpointError, match="is corrupt"):
            Simulation.load(path)
