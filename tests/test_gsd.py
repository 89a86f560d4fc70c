"""GSD files: Trajectory.write, granular.read and Scene.from_gsd round trip
exactly; the file is a valid HOOMD GSD file for gsd itself and for MDAnalysis."""

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
            assert box[2] == (0.0 if d == 2 else box[2])
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
