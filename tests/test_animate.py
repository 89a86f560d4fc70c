"""granular.plot.animate: each frame draws the trajectory's sample wrapped into the box, at
the particles' true radii; trails break at periodic edges; 3D projects or slices; the GIF
has one frame per sample shown; bad input is refused by name."""

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import granular
from granular import Trajectory, plot


def synthetic(
    positions, lower, upper, boundary="periodic", radii=0.05, velocities=None, stored=True
):
    """A Trajectory holding exactly the given (T, N, d) unwrapped positions (or, with
    ``stored=False``, of their shape without them)."""
    x = np.asarray(positions, dtype=np.float64)
    t, n, d = x.shape
    zeros = np.zeros(t)
    return Trajectory(
        np.arange(t, dtype=np.float64),
        x if stored else None,
        velocities,
        zeros,
        np.zeros((t, d)),
        zeros.astype(np.int64),
        zeros.astype(np.int64),
        zeros,
        zeros,
        masses=np.ones(n),
        radii=np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,)).copy(),
        lower=np.asarray(lower, dtype=np.float64),
        upper=np.asarray(upper, dtype=np.float64),
        boundary=boundary,
        stop_reason="time",
    )


@pytest.fixture(scope="module")
def periodic_2d():
    """A 2D periodic gas run long enough that many particles leave the box unwrapped."""
    scene = granular.Scene.random(60, 0.03, dim=2, box=(-0.5, 0.5), seed=3)
    return granular.Simulation(scene).run(3.0, sample_times=np.linspace(0.0, 3.0, 31))


def assert_drawn_in_box(drawn, unwrapped, lower, upper):
    """The drawn centres lie in [lower, upper) and differ from the unwrapped ones by whole
    box lengths (the same particle, folded into the box)."""
    lo, hi = np.asarray(lower), np.asarray(upper)
    assert np.all(drawn >= lo) and np.all(drawn < hi)
    images = (unwrapped - drawn) / (hi - lo)
    np.testing.assert_allclose(images, np.round(images), atol=1e-9)


def test_frames_match_wrapped_positions(periodic_2d):
    traj = periodic_2d
    anim = plot.animate(traj, stride=3)
    np.testing.assert_array_equal(anim.samples, np.arange(0, len(traj), 3))
    left = 0
    for k, s in enumerate(anim.samples):
        anim.draw(k)
        drawn = np.asarray(anim.disks.get_offsets())
        assert drawn.shape == (traj.n, 2)
        assert_drawn_in_box(drawn, traj.positions[s], traj.lower, traj.upper)
        left += np.sum(np.any(np.abs(traj.positions[s]) > 0.5, axis=1))
    assert left > 10  # the run did take particles out of the box: wrapping was exercised
    # true radii in data units
    if hasattr(anim.disks, "get_widths"):
        np.testing.assert_allclose(anim.disks.get_widths(), 2 * traj.radii)
    assert anim.disks.get_offset_transform() is anim.ax.transData
    # the axes span the box across, and the box with the clock's strip above it upwards;
    # the disks and their periodic images are clipped by the box
    assert anim.ax.get_xlim() == (-0.5, 0.5) and anim.ax.get_ylim()[0] == -0.5
    box = anim.ax.transData.transform([traj.lower, traj.upper])
    for c in (anim.disks, *anim.images):
        np.testing.assert_allclose(c.get_clip_box().get_points(), box, atol=1e-9)


def test_frames_option_and_stride(periodic_2d):
    anim = plot.animate(periodic_2d, frames=slice(10, 30), stride=4)
    np.testing.assert_array_equal(anim.samples, [10, 14, 18, 22, 26])
    anim.draw(0)
    anim = plot.animate(periodic_2d, frames=[0, 5, -1])
    np.testing.assert_array_equal(anim.samples, [0, 5, len(periodic_2d) - 1])
    anim.draw(2)
    assert anim.ax.texts[0].get_text() == f"t = {periodic_2d.times[-1]:.4g}"


def test_gif_has_one_frame_per_sample(periodic_2d, tmp_path):
    from PIL import Image

    anim = plot.animate(periodic_2d, frames=slice(0, 7), trails=[0])
    anim.ax.figure.set_size_inches(2.0, 2.0)
    anim.save(tmp_path / "run.gif", dpi=40)
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames == 7


def test_gif_frames_are_full_drawings(periodic_2d, tmp_path):
    """The GIF draws the static parts once and only the moving ones per frame (blitting);
    each frame must look as a full drawing of that frame does (up to the GIF palette:
    fewer than 0.5% of pixels differ by more than 40 of 255 in some channel)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    anim = plot.animate(periodic_2d, trails=[0], color_by_speed=True, frames=slice(0, 7))
    anim.save(tmp_path / "fast.gif", dpi=50)
    with Image.open(tmp_path / "fast.gif") as gif:
        for k in (0, 3, 6):
            gif.seek(k)
            fast = np.asarray(gif.convert("RGB"), dtype=float)
            anim.draw(k)
            fig = anim.ax.figure
            fig.set_dpi(50)
            canvas = FigureCanvasAgg(fig)
            canvas.draw()
            full = Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba())
            full = np.asarray(full.convert("RGB").quantize().convert("RGB"), dtype=float)
            assert fast.shape == full.shape
            assert (np.abs(fast - full).max(axis=2) > 40).mean() < 0.005


def test_trails_break_at_the_periodic_boundary():
    # particle 0 moves +0.3 per sample in a box [0, 1): it crosses x = 1 between samples
    # 3 -> 4 (0.9 + 0.3 = 1.2) and 6 -> 7 (1.8 -> 2.1); particle 1 stays put
    t = np.arange(9)
    x = np.zeros((9, 2, 2))
    x[:, 0, 0] = 0.0 + 0.3 * t
    x[:, 0, 1] = 0.5
    x[:, 1] = [0.25, 0.25]
    traj = synthetic(x, [0, 0], [1, 1])
    anim = plot.animate(traj, trails=[0])
    anim.draw(8)
    xs, ys = (np.asarray(a, dtype=float) for a in anim.trail_lines[0].get_data())
    gaps = np.flatnonzero(np.isnan(xs))
    np.testing.assert_array_equal(np.isnan(ys), np.isnan(xs))
    assert np.all(ys[~np.isnan(ys)] == 0.5)
    assert list(gaps) == [4, 8]  # after samples 0-3, and after samples 4-6 (plus one NaN)
    finite = xs[~np.isnan(xs)]
    np.testing.assert_allclose(finite, np.mod(0.3 * t, 1.0), atol=1e-12)
    # no drawn segment runs across the box: every piece moves +0.3 per sample
    for piece in np.split(xs, gaps):
        piece = piece[~np.isnan(piece)]
        np.testing.assert_allclose(np.diff(piece), 0.3, atol=1e-12)
    # trail_length keeps only the last samples
    anim = plot.animate(traj, trails=[0], trail_length=2)
    anim.draw(8)
    xs = np.asarray(anim.trail_lines[0].get_data()[0], dtype=float)
    assert np.count_nonzero(~np.isnan(xs)) == 3
    # in a walled box nothing is wrapped or broken
    walled = synthetic(x * 0.1, [-1, -1], [1, 1], boundary="walls")
    anim = plot.animate(walled, trails=[0])
    anim.draw(8)
    xs = np.asarray(anim.trail_lines[0].get_data()[0], dtype=float)
    np.testing.assert_allclose(xs, 0.03 * t)


def test_3d_projection_and_slab():
    scene = granular.Scene.random(80, 0.04, dim=3, seed=5)
    traj = granular.Simulation(scene).run(1.0, sample_times=[0.0, 0.5, 1.0])
    anim = plot.animate(traj, plane="xz")
    anim.draw(2)
    assert_drawn_in_box(
        np.asarray(anim.disks.get_offsets()),
        traj.positions[2][:, [0, 2]],
        traj.lower[[0, 2]],
        traj.upper[[0, 2]],
    )
    assert anim.ax.get_xlabel().startswith("$x$") and anim.ax.get_ylabel().startswith("$z$")
    # a slab through y = 0.9 of half-width 0.2 reaches across the periodic face y = 1
    anim = plot.animate(traj, plane="xz", slab=(0.9, 0.2))
    anim.draw(1)
    dy = np.mod(traj.positions[1][:, 1], 1.0) - 0.9
    dy -= np.round(dy)  # minimum image
    inside = np.abs(dy) < 0.2
    assert 0 < inside.sum() < traj.n
    alpha = anim.disks.get_facecolor()[:, 3]
    np.testing.assert_array_equal(alpha > 0, inside)
    assert "slice" in anim.ax.get_title()


def test_colour_by_speed_on_a_given_scale(periodic_2d):
    import matplotlib as mpl

    top = np.linalg.norm(periodic_2d.velocities[[4, 9]], axis=2).max()
    anim = plot.animate(
        periodic_2d, color_by_speed=True, frames=[4, 9], norm=mpl.colors.Normalize(0, top)
    )
    anim.draw(1)
    speeds = np.linalg.norm(periodic_2d.velocities[9], axis=1)
    expected = mpl.colormaps["viridis"](speeds / top)
    np.testing.assert_allclose(anim.disks.get_facecolor(), expected, atol=1e-12)
    with pytest.raises(ValueError, match="color_by_speed=True"):
        plot.animate(periodic_2d, norm=mpl.colors.Normalize(0, top))


def test_colour_by_speed_keeps_a_cooling_gas_coloured():
    """By default each frame is coloured by its speeds over its own rms speed: a gas whose
    speeds fall a hundredfold (velocities scaled, positions fixed) shows the same colours
    at the end as at the start, spread over the colour map, where one fixed scale would
    paint the last frame uniformly dark."""
    import matplotlib as mpl

    rng = np.random.default_rng(1)
    v = rng.normal(size=(40, 2))
    velocities = np.stack([v, v / 10, v / 100])
    traj = synthetic(np.zeros((3, 40, 2)) + 0.5, [0, 0], [1, 1], velocities=velocities)
    anim = plot.animate(traj, color_by_speed=True)
    anim.draw(0)
    first = anim.disks.get_facecolor().copy()
    anim.draw(2)
    last = anim.disks.get_facecolor()
    np.testing.assert_allclose(last, first, atol=1e-12)
    reduced = np.linalg.norm(v, axis=1) / np.sqrt(np.mean(np.sum(v**2, axis=1)))
    expected = mpl.colormaps["viridis"](reduced / reduced.max())
    np.testing.assert_allclose(last, expected, atol=1e-12)
    assert anim.disks.figure.axes[-1].get_ylabel().startswith("speed / rms speed")


def test_the_clock_never_covers_a_particle(periodic_2d):
    """The time is written in a strip above the box, not over the particles (it used to
    cover the top-left corner of the box in a white box)."""
    anim = plot.animate(periodic_2d, title="a title")
    anim.draw(3)
    fig = anim.ax.figure
    renderer = fig.canvas.get_renderer() if hasattr(fig.canvas, "get_renderer") else None
    if renderer is None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        renderer = FigureCanvasAgg(fig).get_renderer()
    clock = anim.ax.texts[0]
    assert clock.get_text() == f"t = {periodic_2d.times[3]:.4g}"
    box_top = anim.ax.transData.transform((0.0, periodic_2d.upper[1]))[1]
    assert clock.get_window_extent(renderer).y0 >= box_top


def test_notebook_and_writers(periodic_2d, tmp_path, monkeypatch):
    from matplotlib import animation

    anim = plot.animate(periodic_2d, frames=slice(0, 2))
    assert "<script" in anim._repr_html_()  # shows itself in Jupyter as JavaScript frames
    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    with pytest.raises(RuntimeError, match="needs ffmpeg"):
        anim.save(tmp_path / "run.mp4")
    with pytest.raises(ValueError, match="which writer"):
        anim.save(tmp_path / "run.xyz")


def test_bad_input_is_refused(periodic_2d):
    traj = periodic_2d
    with pytest.raises(IndexError, match=f"particle {traj.n} does not exist"):
        plot.animate(traj, trails=[0, traj.n])
    with pytest.raises(IndexError, match="particle -1"):
        plot.animate(traj, trails=-1)
    with pytest.raises(ValueError, match="integers"):
        plot.animate(traj, trails=[0.5])
    empty = synthetic(np.zeros((0, 3, 2)), [0, 0], [1, 1])
    with pytest.raises(ValueError, match="no samples"):
        plot.animate(empty)
    with pytest.raises(ValueError, match="stride"):
        plot.animate(traj, stride=0)
    with pytest.raises(ValueError, match="select no sample"):
        plot.animate(traj, frames=slice(5, 5))
    with pytest.raises(IndexError, match="frames"):
        plot.animate(traj, frames=[0, len(traj)])
    with pytest.raises(ValueError, match="xy plane"):
        plot.animate(traj, plane="xz")
    with pytest.raises(ValueError, match="3D"):
        plot.animate(traj, slab=(0.0, 0.1))
    with pytest.raises(ValueError, match="trail_length"):
        plot.animate(traj, trails=[0], trail_length=0)
    no_positions = synthetic(np.zeros((2, 3, 2)), [0, 0], [1, 1], stored=False)
    with pytest.raises(ValueError, match="did not store positions"):
        plot.animate(no_positions)
    with pytest.raises(ValueError, match="did not store velocities"):
        plot.animate(synthetic(np.zeros((2, 3, 2)), [0, 0], [1, 1]), color_by_speed=True)
    three_d = synthetic(np.zeros((2, 3, 3)), [0, 0, 0], [1, 1, 1])
    with pytest.raises(ValueError, match="plane must be"):
        plot.animate(three_d, plane="xx")
    with pytest.raises(ValueError, match="half-width"):
        plot.animate(three_d, slab=(0.5, 0.0))
