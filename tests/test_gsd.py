"""GSD files: Trajectory.write, granular.read and Scene.from_gsd round trip
exactly; the file is a valid HOOMD GSD file for gsd itself and for MDAnalysis."""

import os
import stat
import sys

import gsd.hoomd
import numpy as np
import pytest

import granular
from granular import Scene, Simulation

FIELDS = (
    "times",
    "positions",
    "velocities",
    "kinetic_energy",
    "momentum",
    "pair_collisions",
    "wall_collisions",
    "virial",
    "wall_impulse",
    "masses",
    "radii",
    "lower",
    "upper",
)


def run_3d_periodic():
    # a box off the origin, run long enough that particles cross it (images non-zero)
    s = Scene.random(80, 0.04, box=(0.5, 2.0), speed=1.0, seed=1)
    sim = Simulation(s)
    tr = sim.run(t_stop=3.0, sample_times=np.linspace(0.0, 3.0, 13))
    return sim, tr


def run_2d_walled():
    s = Scene.random(
        60, 0.03, dim=2, box=([-0.5, 1.0], [1.5, 2.0]), boundary="walls", restitution=0.9, seed=2
    )
    sim = Simulation(s)
    tr = sim.run(t_stop=2.0, sample_times=[0.0, 0.1, 0.7, 2.0])
    return sim, tr


RUNS = {"3d_periodic": run_3d_periodic, "2d_walls": run_2d_walled}


@pytest.fixture(params=list(RUNS))
def written(request, tmp_path):
    sim, tr = RUNS[request.param]()
    path = tmp_path / "run.gsd"
    tr.write(path)
    return sim, tr, path


def test_round_trip_is_exact(written):
    _, tr, path = written
    back = granular.read(path)
    assert isinstance(back, granular.Trajectory)
    for name in FIELDS:
        a, b = getattr(tr, name), getattr(back, name)
        assert b.dtype == np.asarray(a).dtype, name
        np.testing.assert_array_equal(b, a, err_msg=name)
    assert back.boundary == tr.boundary
    assert back.stop_reason == tr.stop_reason
    assert len(back) == len(tr)


def test_gsd_reads_wrapped_float32_positions_and_image_flags(written):
    _, tr, path = written
    L = tr.upper - tr.lower
    centre = 0.5 * (tr.lower + tr.upper)
    with gsd.hoomd.open(str(path), "r") as f:
        assert len(f) == len(tr)
        for k, frame in enumerate(f):
            d = tr.dim
            assert frame.configuration.dimensions == d
            box = np.asarray(frame.configuration.box)
            np.testing.assert_allclose(box[:d], L, rtol=1e-7)
            if d == 2:  # as deep as the longest edge (MDAnalysis needs a volume)
                assert box[2] == np.float32(L.max())
            assert np.all(box[3:] == 0)
            assert frame.configuration.step == k
            x = frame.particles.position
            assert x.dtype == np.float32
            if d == 2:
                assert np.all(x[:, 2] == 0)
            half = (L / 2).astype(np.float32)  # HOOMD's box: [-L/2, L/2)
            assert np.all(x[:, :d] >= -half) and np.all(x[:, :d] < half)
            img = frame.particles.image[:, :d]
            if tr.boundary == "walls":
                assert np.all(img == 0)
            unwrapped = x[:, :d].astype(np.float64) + img * L + centre
            scale = np.max(np.abs(tr.positions[k])) + np.max(L)
            np.testing.assert_allclose(unwrapped, tr.positions[k], rtol=0, atol=4e-7 * scale)
            np.testing.assert_allclose(
                frame.particles.velocity[:, :d], tr.velocities[k], rtol=1e-6, atol=1e-7
            )
            np.testing.assert_allclose(frame.particles.diameter, 2 * tr.radii, rtol=1e-7)
            np.testing.assert_allclose(frame.particles.mass, tr.masses, rtol=1e-7)
            assert frame.log["granular/time"][0] == tr.times[k]
    # the periodic run crossed the box: the image flags carry information
    if tr.boundary == "periodic":
        with gsd.hoomd.open(str(path), "r") as f:
            assert np.any(f[-1].particles.image != 0)


def test_mdanalysis_reads_the_file(written):
    mda = pytest.importorskip("MDAnalysis")
    _, tr, path = written
    u = mda.Universe(str(path))
    assert len(u.trajectory) == len(tr)
    assert len(u.atoms) == tr.n
    L = tr.upper - tr.lower
    for ts in u.trajectory:
        np.testing.assert_allclose(ts.dimensions[: tr.dim], L, rtol=1e-6)


def test_scene_from_gsd_is_the_sampled_state(written):
    sim, tr, path = written
    # the runs end at their last sample time: sim.scene is the state of the last frame
    assert sim.time == tr.times[-1]
    now = sim.scene
    s = Scene.from_gsd(path)
    assert s.boundary == now.boundary
    np.testing.assert_array_equal(s.lower, now.lower)
    np.testing.assert_array_equal(s.upper, now.upper)
    np.testing.assert_array_equal(s.radii, now.radii)
    np.testing.assert_array_equal(s.masses, now.masses)
    np.testing.assert_array_equal(s.velocities, now.velocities)
    # wrapped again from the unwrapped float64 positions: equal to the engine's to rounding
    np.testing.assert_allclose(s.positions, now.positions, rtol=0, atol=1e-12)
    first = Scene.from_gsd(path, frame=0, restitution=0.5)
    np.testing.assert_array_equal(first.velocities, tr.velocities[0])
    assert first.restitution == 0.5


def test_bad_inputs_raise_clear_errors(tmp_path):
    _, tr = run_2d_walled()
    with pytest.raises(ValueError, match="to_universe"):
        tr.write(tmp_path / "run.xyz")
    with pytest.raises(ValueError, match=r"\.gsd"):
        granular.read(tmp_path / "run.dcd")
    with pytest.raises(FileNotFoundError, match="no GSD file"):
        granular.read(tmp_path / "missing.gsd")
    with pytest.raises(FileNotFoundError, match="no GSD file"):
        Scene.from_gsd(tmp_path / "missing.gsd")
    bare = Simulation(Scene.random(10, 0.05, seed=3)).run(t_stop=0.5, store=())
    with pytest.raises(ValueError, match="did not store positions"):
        bare.write(tmp_path / "bare.gsd")
    assert not (tmp_path / "bare.gsd").exists()
    tr.write(tmp_path / "ok.gsd")
    with pytest.raises(IndexError, match="out of range"):
        Scene.from_gsd(tmp_path / "ok.gsd", frame=len(tr))


def test_a_foreign_gsd_file_gives_a_scene_but_not_a_trajectory(tmp_path):
    path = tmp_path / "hoomd.gsd"
    frame = gsd.hoomd.Frame()
    frame.particles.N = 2
    frame.particles.types = ["A"]
    frame.particles.position = np.array([[-0.25, 0, 0], [0.25, 0, 0]], dtype=np.float32)
    frame.particles.diameter = np.array([0.25, 0.25], dtype=np.float32)
    frame.configuration.box = [1, 1, 1, 0, 0, 0]
    with gsd.hoomd.open(str(path), "w") as f:
        f.append(frame)
    s = Scene.from_gsd(path)
    np.testing.assert_array_equal(s.positions, [[-0.25, 0, 0], [0.25, 0, 0]])
    np.testing.assert_array_equal(s.radii, [0.125, 0.125])
    np.testing.assert_array_equal(s.lower, [-0.5] * 3)
    with pytest.raises(ValueError, match="not written by granular"):
        granular.read(path)


def test_a_centre_that_rounds_onto_the_upper_face_stays_in_the_box(tmp_path):
    # float64 just inside [0, 1), float32 of (x - 1/2) rounds to +1/2: GSD wants [-L/2, L/2)
    x = np.array([[[1.0 - 1e-12, 0.5, 0.5], [0.25, 0.25, 0.25]]])
    tr = granular.Trajectory(
        np.array([0.0]),
        x,
        np.zeros_like(x),
        np.zeros(1),
        np.zeros((1, 3)),
        np.zeros(1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.zeros(1),
        np.zeros(1),
        masses=np.ones(2),
        radii=np.full(2, 0.1),
        lower=np.zeros(3),
        upper=np.ones(3),
        boundary="periodic",
        stop_reason="time",
    )
    path = tmp_path / "edge.gsd"
    tr.write(path)
    with gsd.hoomd.open(str(path), "r") as f:
        p, img = f[0].particles.position, f[0].particles.image
    assert np.all(p >= -0.5) and np.all(p < 0.5)
    assert p[0, 0] == -0.5 and img[0, 0] == 1
    np.testing.assert_allclose(p[:, :3] + img + 0.5, x[0], atol=1e-7)
    np.testing.assert_array_equal(granular.read(path).positions, x)


def test_positions_without_velocities_round_trip(tmp_path):
    tr = Simulation(Scene.random(20, 0.05, seed=4)).run(
        t_stop=1.0, sample_times=[0.0, 0.5, 1.0], store=("positions",)
    )
    tr.write(tmp_path / "p.gsd")
    back = granular.read(tmp_path / "p.gsd")
    assert back.velocities is None
    np.testing.assert_array_equal(back.positions, tr.positions)
    np.testing.assert_array_equal(back.times, tr.times)


def test_without_gsd_the_error_names_the_extra(tmp_path, monkeypatch):
    _, tr = run_2d_walled()
    # hidden the way Python reports a missing module
    monkeypatch.setitem(sys.modules, "gsd", None)
    monkeypatch.setitem(sys.modules, "gsd.hoomd", None)
    with pytest.raises(ImportError, match=r"pip install 'granular\[gsd\]'"):
        tr.write(tmp_path / "run.gsd")


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_a_written_file_has_the_mode_a_plain_open_gives(tmp_path, umask):
    # gsd creates its files 0o660 less the umask: 0o640 under 022, where open() gives 0o644
    _, tr = run_2d_walled()
    before = os.umask(umask)
    try:
        tr.write(tmp_path / "run.gsd")
        with open(tmp_path / "plain", "w"):
            pass
        # over an existing file: its mode stays, as open(path, "w") keeps it
        (tmp_path / "old.gsd").write_bytes(b"old")
        os.chmod(tmp_path / "old.gsd", 0o604)
        tr.write(tmp_path / "old.gsd")
    finally:
        os.umask(before)
    assert _mode(tmp_path / "run.gsd") == _mode(tmp_path / "plain") == 0o666 & ~umask
    assert _mode(tmp_path / "old.gsd") == 0o604
    np.testing.assert_array_equal(granular.read(tmp_path / "old.gsd").positions, tr.positions)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.gsd", "plain", "run.gsd"]


def test_a_write_that_fails_midway_leaves_the_old_file(tmp_path, monkeypatch):
    _, tr = run_2d_walled()
    path = tmp_path / "run.gsd"
    tr.write(path)
    before = path.read_bytes()
    append = gsd.hoomd.HOOMDTrajectory.append
    calls = []

    def ctrl_c_at_the_second_frame(self, frame):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return append(self, frame)

    monkeypatch.setattr(gsd.hoomd.HOOMDTrajectory, "append", ctrl_c_at_the_second_frame)
    _, other = run_3d_periodic()
    with pytest.raises(KeyboardInterrupt):
        other.write(path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["run.gsd"]


# -- reading refuses what a sound file cannot hold ------------------------------------------

LOG = "log/granular/"


def copy_chunks(src, dst, change=lambda k, name, data: data, extra=None):
    """Copy a GSD file chunk by chunk through ``change(frame, name, data)``, which returns the
    data to write or None to leave the chunk out, adding the chunks ``extra[frame]`` (a dict
    name: data): files no writer of gsd.hoomd would make."""
    with gsd.fl.open(str(src), "r") as f:
        names = f.find_matching_chunk_names("")
        frames = [
            {n: f.read_chunk(k, n) for n in names if f.chunk_exists(k, n)} for k in range(f.nframes)
        ]
    with gsd.fl.open(str(dst), "w", application="test", schema="hoomd", schema_version=[1, 4]) as f:
        for k, chunks in enumerate(frames):
            for name, data in chunks.items():
                data = change(k, name, data.copy())
                if data is not None:
                    f.write_chunk(name, data)
            for name, data in (extra or {}).get(k, {}).items():
                f.write_chunk(name, data)
            f.end_frame()
    return dst


def _set(frame, name, value):
    def change(k, chunk, data):
        if k == frame and chunk == LOG + name:
            return value(data) if callable(value) else value
        return data

    return change


def _bytes(text):
    return np.frombuffer(text.encode(), np.uint8).copy()


def _item(index, value):
    def set_item(data):
        data[index] = value
        return data

    return set_item


BAD = {
    "nan position": (_set(2, "unwrapped_positions", _item((3, 0), np.nan)), 2, "NaN"),
    "zero radius": (_set(0, "radii", _item(1, 0.0)), 0, "radii must be positive"),
    "negative mass": (_set(0, "masses", _item(4, -1.0)), 0, "masses must be positive"),
    "nan radius": (_set(0, "radii", _item(0, np.nan)), 0, "radii contains NaN"),
    "nan mass": (_set(0, "masses", _item(0, np.nan)), 0, "masses contains NaN"),
    "repeated time": (_set(2, "time", np.array([0.1])), 2, r"time is 0.1, not after"),
    "earlier time": (_set(3, "time", np.array([0.05])), 3, "sample times must increase"),
    "nan time": (_set(1, "time", np.array([np.nan])), 1, "not a finite time"),
    "boundary": (_set(0, "boundary", np.frombuffer(b"pgriodic", np.uint8)), 0, "pgriodic"),
    "radii short": (_set(0, "radii", lambda r: r[:-1]), 0, r"radii has shape \(59,\)"),
    "masses long": (_set(0, "masses", lambda m: np.append(m, 1.0)), 0, r"masses has shape"),
    "missing field": (_set(1, "virial", None), 1, "log/granular/virial is missing"),
    "missing time": (_set(3, "time", None), 3, "log/granular/time is missing"),
    "missing radii": (_set(0, "radii", None), 0, "log/granular/radii is missing"),
    "wrong shape": (_set(1, "momentum", np.zeros(3)), 1, r"momentum has shape \(3,\)"),
    "positions shape": (_set(2, "unwrapped_positions", lambda x: x[:-1]), 2, "has shape"),
    "text field": (_set(0, "boundary", np.zeros((2, 2))), 0, "boundary is not text"),
    "not utf-8": (_set(0, "stop_reason", np.array([0xFF], np.uint8)), 0, "not UTF-8"),
    "text numbers": (_set(0, "radii", np.frombuffer(b"ab", np.uint8)), 0, "radii has shape"),
    "overlap": (
        _set(1, "unwrapped_positions", lambda x: x[[0, 0, *range(2, len(x))]]),
        1,
        "overlap",
    ),
    "outside walls": (_set(0, "unwrapped_positions", _item((5, 1), 9.0)), 0, "outside|box"),
    "velocities gone": (_set(2, "velocities", None), 2, "velocities is missing"),
    "velocities nan": (_set(1, "velocities", _item((0, 1), np.inf)), 1, "velocities contains"),
    "count down": (_set(3, "pair_collisions", np.array([0], np.int64)), 3, "never decreases"),
    "count float": (_set(1, "wall_collisions", np.array([0.5])), 1, "not integers"),
    "counter nan": (_set(2, "kinetic_energy", np.array([np.nan])), 2, "NaN or infinity"),
    "format": (_set(0, "format", np.array([7], np.int64)), None, "layout 7.*newer granular"),
    "format 0": (_set(0, "format", np.array([0], np.int64)), None, "layout 0, .* 1 to"),
    "restitution range": (_set(0, "restitution", np.array([1.5])), 0, r"restitution must lie"),
    "restitution text": (_set(0, "restitution", _bytes("0.5")), 0, "not a number or a law"),
    "restitution shape": (_set(0, "restitution", np.ones(2)), 0, r"restitution has shape"),
    "unknown law": (_set(0, "restitution", _bytes('{"law": "Magic"}')), 0, "unknown .* 'Magic'"),
    "broken law": (_set(0, "restitution", _bytes('{"law": ')), 0, "not a restitution law's"),
    "law arguments": (
        _set(0, "restitution", _bytes('{"law": "Viscoelastic", "speed": 1}')),
        0,
        "restitution is not a restitution law's description",
    ),
    "wall restitution": (_set(0, "wall_restitution", np.array([-1.0])), 0, "wall_restitution"),
    "contact nan": (_set(0, "contact_duration", np.array([np.nan])), 0, "contact_duration must"),
    "not granular": (_set(0, "format", None), None, "not written by granular"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_read_refuses_an_impossible_file_naming_frame_and_field(tmp_path, case):
    change, frame, message = BAD[case]
    _, tr = run_2d_walled()  # 60 disks, 4 frames at t = 0, 0.1, 0.7, 2
    tr.write(tmp_path / "good.gsd")
    bad = copy_chunks(tmp_path / "good.gsd", tmp_path / "bad.gsd", change)
    with pytest.raises(granular.errors.GSDFileError, match=message) as info:
        granular.read(bad)
    assert "bad.gsd" in str(info.value)
    if frame is not None:  # else an error of the whole file
        assert f"frame {frame}: " in str(info.value)


def test_copy_chunks_alone_keeps_a_readable_file(tmp_path):
    # the cases above differ from a sound file only by their change
    _, tr = run_2d_walled()
    tr.write(tmp_path / "good.gsd")
    back = granular.read(copy_chunks(tmp_path / "good.gsd", tmp_path / "copy.gsd"))
    np.testing.assert_array_equal(back.positions, tr.positions)


def test_velocities_in_later_frames_only_are_refused(tmp_path):
    tr = Simulation(Scene.random(20, 0.05, seed=4)).run(
        t_stop=1.0, sample_times=[0.0, 0.5, 1.0], store=("positions",)
    )
    tr.write(tmp_path / "p.gsd")
    extra = {1: {LOG + "velocities": np.zeros((20, 3))}}
    copy_chunks(tmp_path / "p.gsd", tmp_path / "v.gsd", extra=extra)
    with pytest.raises(granular.errors.GSDFileError, match=r"frame 1: .*velocities is there"):
        granular.read(tmp_path / "v.gsd")


def test_read_allocates_what_the_file_holds_not_what_it_claims(tmp_path):
    """A 60-disk file whose frames claim N = 5e7 particles (HOOMD's particles/N) without
    their data: gsd.hoomd's frames would allocate every standard field for 5e7 particles
    (about 7 GB); granular.read reads only its log chunks.  Peak of the allocations traced
    (NumPy's included): under 1 MB, against a file of ~30 kB."""
    import tracemalloc

    _, tr = run_2d_walled()
    tr.write(tmp_path / "good.gsd")

    def claim(k, name, data):
        if name == "particles/N":
            return np.array([50_000_000], np.uint32)
        return None if name.startswith("particles/") else data

    path = copy_chunks(tmp_path / "good.gsd", tmp_path / "claims.gsd", claim)
    assert path.stat().st_size < 100_000
    tracemalloc.start()
    try:
        back = granular.read(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    np.testing.assert_array_equal(back.positions, tr.positions)
    assert peak < 1_000_000, peak


def test_overlapping_chunks_cannot_make_read_take_more_than_the_file(tmp_path):
    # an index whose entries all point at the same bytes: each chunk lies inside the file
    # (gsd checks that), but together they claim far more than it holds
    _, tr = run_2d_walled()
    tr.write(tmp_path / "good.gsd")
    from granular import gsd_io

    with gsd_io._File(tmp_path / "good.gsd") as f:
        f._budget = 100  # as if the file were 50 bytes long
        with pytest.raises(granular.errors.GSDFileError, match="past twice the file's size"):
            f.raw(0, LOG + "unwrapped_positions")


def test_scene_from_gsd_refuses_a_foreign_file_it_cannot_represent(tmp_path):
    frame = gsd.hoomd.Frame()
    frame.particles.N = 2
    frame.particles.types = ["A"]
    frame.particles.position = np.array([[-0.25, 0, 0], [0.25, 0, 0]], dtype=np.float32)
    frame.particles.diameter = np.array([0.25, 0.25], dtype=np.float32)
    frame.configuration.box = [1, 1, 1, 0.5, 0, 0]  # tilted: a triclinic box
    with gsd.hoomd.open(str(tmp_path / "tilt.gsd"), "w") as f:
        f.append(frame)
    with pytest.raises(granular.errors.GSDFileError, match=r"frame 0: configuration/box"):
        Scene.from_gsd(tmp_path / "tilt.gsd")
    frame.configuration.box = [1, 1, 1, 0, 0, 0]
    frame.particles.diameter = np.array([0.75, 0.75], dtype=np.float32)  # overlapping
    with gsd.hoomd.open(str(tmp_path / "overlap.gsd"), "w") as f:
        f.append(frame)
    with pytest.raises(granular.errors.GSDFileError, match="frame 0: not a valid state"):
        Scene.from_gsd(tmp_path / "overlap.gsd")
    # a user's own mistake stays the Scene's error, not the file's
    _, tr = run_2d_walled()
    tr.write(tmp_path / "ok.gsd")
    with pytest.raises(ValueError, match="restitution must lie") as info:
        Scene.from_gsd(tmp_path / "ok.gsd", restitution=2.0)
    assert not isinstance(info.value, granular.errors.GSDFileError)


def test_a_damaged_file_is_a_gsd_file_error(tmp_path):
    _, tr = run_2d_walled()
    tr.write(tmp_path / "good.gsd")
    data = (tmp_path / "good.gsd").read_bytes()
    (tmp_path / "cut.gsd").write_bytes(data[: len(data) // 2])
    (tmp_path / "text.gsd").write_text("not a GSD file\n")
    (tmp_path / "empty.gsd").write_bytes(b"")
    for name in ("cut.gsd", "text.gsd", "empty.gsd"):
        with pytest.raises(granular.errors.GSDFileError, match=name):
            granular.read(tmp_path / name)


def test_the_scene_parameters_keep_the_fields_older_readers_read(tmp_path):
    """Frame 0 keeps the layout-1 fields as they were (the box's corners, radii and masses
    in float64, the boundary as UTF-8 text), so an older granular still reads the file
    (without the parameters it did not know); the restitution, a number, as float64."""
    _, tr = run_2d_walled()
    tr.write(tmp_path / "run.gsd")
    with gsd.fl.open(str(tmp_path / "run.gsd"), "r") as f:
        assert f.read_chunk(0, LOG + "format").tolist() == [1]
        for name in ("lower", "upper", "radii", "masses"):
            a = f.read_chunk(0, LOG + name)
            assert a.dtype == np.float64
            np.testing.assert_array_equal(a, getattr(tr, name))
        assert bytes(f.read_chunk(0, LOG + "boundary")) == b"walls"
        assert f.read_chunk(0, LOG + "restitution").tolist() == [0.9]
        assert f.read_chunk(0, LOG + "contact_duration").tolist() == [0.0]
        assert not f.chunk_exists(1, LOG + "restitution")  # the run's: frame 0 only


def test_a_file_without_the_newer_parameters_reads_with_their_defaults(tmp_path):
    # a file written before granular recorded the restitutions and the TC model: they take
    # their defaults, and Scene.from_gsd sets them as before
    _, tr = run_2d_walled()
    tr.write(tmp_path / "run.gsd")
    newer = ("restitution", "wall_restitution", "contact_duration")

    def drop(k, name, data):
        return None if name in [LOG + n for n in newer] else data

    old = copy_chunks(tmp_path / "run.gsd", tmp_path / "old.gsd", drop)
    assert Scene.from_gsd(old).restitution == 1.0
    assert Scene.from_gsd(old, restitution=0.9).restitution == 0.9
    back = granular.read(old)
    assert back.scene_parameters["restitution"] == 1.0
    np.testing.assert_array_equal(back.positions, tr.positions)
    assert Scene.from_gsd(tmp_path / "run.gsd").restitution == 0.9
