"""Animations of a Trajectory: disks drawn to scale in the box, frame by frame.

``granular.plot.animate`` is the public entry (re-exported there).  matplotlib is imported
only when an animation is made, as for every figure in ``granular.plot``.

What a frame shows, and why it is drawn that way:

- every particle as a disk of its true radius in data units (an ``EllipseCollection``
  with ``units="xy"``), so that contacts look like contacts at any figure size;
- positions wrapped into a periodic box (a Trajectory keeps unwrapped positions, which an
  MSD needs), with the periodic images of disks that straddle an edge drawn too and
  clipped by the axes, which span exactly the box;
- in 3D a projection along one axis onto the plane of the other two, optionally only the
  slab ``|depth - z0| < w`` (minimum image in a periodic box);
- trails of chosen particles from their unwrapped positions at every sample (not only the
  frames shown), wrapped into the box and broken where they cross a periodic edge;
- the time in a strip above the box, never over a particle;
- with ``color_by_speed`` each frame's speeds over its own rms speed unless a ``norm`` is
  given: a cooling gas keeps its colours;
- rough particles' spins (a trajectory that stored ``angular_velocities``) as a radius line
  per disk, turned by the spin about the axis drawn face-on (z in 2D, the depth axis in
  3D): the angle is summed sample by sample, phi_k = phi_(k-1) + w_(k-1) (t_k - t_(k-1)),
  exact between collisions and an approximation across them (the samples do not record
  when a spin changed).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _shear
from ._figures import POSITION, SPEED, _matplotlib

if TYPE_CHECKING:  # matplotlib is an extra, imported only when an animation is made
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .trajectory import Trajectory

_AXES = {"x": 0, "y": 1, "z": 2}
# file endings the save method knows, and the matplotlib writer each needs
_WRITERS = {".gif": "pillow", ".mp4": "ffmpeg", ".m4v": "ffmpeg", ".mov": "ffmpeg"}
_WRITERS.update({".mkv": "ffmpeg", ".webm": "ffmpeg", ".html": "html"})


def wrap(positions: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> NDArray[np.float64]:
    """Positions folded into the periodic box [lower, upper) along every axis."""
    lo = np.asarray(lower, dtype=np.float64)
    length = np.asarray(upper, dtype=np.float64) - lo
    return lo + np.mod(np.asarray(positions, dtype=np.float64) - lo, length)


def trail_segments(
    points: ArrayLike, lower: ArrayLike, upper: ArrayLike, periodic: bool
) -> NDArray[np.float64]:
    """A path of unwrapped positions (T, 2) as drawn in the box: wrapped when periodic, with
    a row of NaN (where matplotlib lifts the pen) wherever consecutive points lie in
    different periodic images, so that no line runs across the box."""
    p = np.asarray(points, dtype=np.float64)
    if not periodic or len(p) < 2:
        return p.copy()
    lo = np.asarray(lower, dtype=np.float64)
    length = np.asarray(upper, dtype=np.float64) - lo
    image = np.floor((p - lo) / length)
    jumps = np.flatnonzero(np.any(image[1:] != image[:-1], axis=1)) + 1
    folded = p - image * length
    return np.insert(folded, jumps, np.nan, axis=0)


def _plane(plane, dim):
    """The two drawn axes and the depth axis (None in 2D) from "xy", "xz", "yz" (or a pair
    of axis numbers)."""
    if dim == 2:
        if plane not in (None, "xy", (0, 1)):
            raise ValueError(f"a 2D trajectory is drawn in the xy plane, got plane={plane!r}")
        return (0, 1), None
    if plane is None:
        plane = "xy"
    axes: tuple[int, ...]
    if isinstance(plane, str):
        if len(plane) != 2 or any(c not in _AXES for c in plane) or plane[0] == plane[1]:
            raise ValueError(f"plane must be two different axes of 'xyz', e.g. 'xz', got {plane!r}")
        axes = (_AXES[plane[0]], _AXES[plane[1]])
    else:
        axes = tuple(int(a) for a in plane)
        if len(axes) != 2 or axes[0] == axes[1] or not set(axes) <= {0, 1, 2}:
            raise ValueError(f"plane must be two different axes among 0, 1, 2, got {plane!r}")
    depth = ({0, 1, 2} - set(axes)).pop()
    return axes, depth


def _samples(n_samples, frames, stride):
    """Sample indices shown, one per frame."""
    if n_samples == 0:
        raise ValueError("the trajectory has no samples: nothing to animate")
    stride = int(stride)
    if stride < 1:
        raise ValueError(f"stride must be >= 1, got {stride}")
    if frames is None:
        idx = np.arange(n_samples)
    elif isinstance(frames, slice):
        idx = np.arange(n_samples)[frames]
    else:
        idx = np.asarray(frames)
        if idx.ndim != 1 or idx.dtype.kind not in "iu":
            raise ValueError("frames must be a slice or a 1D sequence of sample indices")
        if idx.size and (idx.min() < -n_samples or idx.max() >= n_samples):
            raise IndexError(
                f"frames index samples 0 .. {n_samples - 1} of this trajectory, got "
                f"{int(idx.min())} .. {int(idx.max())}"
            )
        idx = np.mod(idx, n_samples)
    idx = idx[::stride]
    if idx.size == 0:
        raise ValueError("frames and stride select no sample: nothing to animate")
    return idx


def _trail_particles(trails, n):
    if trails is None:
        return np.empty(0, dtype=np.intp)
    t = np.atleast_1d(np.asarray(trails))
    if t.ndim != 1 or (t.size and t.dtype.kind not in "iu"):
        from .errors import shown

        raise ValueError(f"trails must be particle indices (integers), got {shown(trails)}")
    bad = t[(t < 0) | (t >= n)]
    if bad.size:
        raise IndexError(
            f"trails: particle {int(bad[0])} does not exist (the trajectory has N = {n})"
        )
    return t.astype(np.intp)


@functools.cache
def _spin_angles(traj: Any, depth: int | None, sign: float = 1.0) -> NDArray[np.float64]:
    """(T, N) angles of each disk's radius line: the spin about the axis seen face-on (z in
    2D, the depth axis in 3D; ``sign`` -1 when the drawn axes and it are left-handed, as x,
    z and y are) summed over the samples, starting at 0."""
    w = traj.angular_velocities
    if w is None:
        raise ValueError(
            "spin=True draws rough particles' rotation: run with store including "
            "'angular_velocities'"
        )
    w = np.asarray(w, dtype=np.float64)
    face_on = w if depth is None else sign * w[:, :, depth]
    dt = np.diff(np.asarray(traj.times, dtype=np.float64))
    phi = np.zeros_like(face_on)
    phi[1:] = np.cumsum(face_on[:-1] * dt[:, None], axis=0)
    return phi


def _animation_class():
    """The FuncAnimation subclass, defined on first use so that importing granular.plot does
    not import matplotlib."""
    from matplotlib import animation

    class ParticleAnimation(animation.FuncAnimation):
        """A ``matplotlib.animation.FuncAnimation`` of particles in their box.

        Attributes
        ----------
        samples : ndarray of int
            The trajectory sample shown by each frame.
        disks : EllipseCollection
            The particles (offsets: the drawn centres of frame k after ``draw(k)``).
        images : EllipseCollection or None
            Periodic images of the disks (a periodic box only), clipped by the axes.
        trail_lines : list of Line2D
            One per particle in ``trails``.
        ax : Axes
        """

        # set by ``animate`` after construction (``_fig``, ``_interval``: by FuncAnimation)
        samples: NDArray[np.intp]
        disks: Any
        images: Any
        trail_lines: list[Any]
        ax: Axes
        _update: Callable[[int], list[Any]]
        _fig: Figure
        _interval: float

        def draw(self, k: int) -> list[Any]:
            """Draw frame ``k`` (sample ``samples[k]``) now; returns the artists changed."""
            self._draw_was_started = True  # a drawn frame is a use: no "deleted unused" warning
            return self._update(k)

        def _repr_html_(self) -> str:
            # In a notebook the animation shows itself as JavaScript frames unless the user
            # chose another rcParams["animation.html"] ("html5" needs ffmpeg).
            import matplotlib as mpl

            if mpl.rcParams["animation.html"] == "none":
                return self.to_jshtml()
            return super()._repr_html_()

        # FuncAnimation.save's parameters after writer are taken as keywords only
        def save(  # type: ignore[override]
            self, filename: str | os.PathLike[str], writer: Any = None, **kwargs: Any
        ) -> None:
            """``FuncAnimation.save`` with the writer chosen by the file's ending: .gif with
            Pillow, .mp4 (.m4v, .mov, .mkv, .webm) with ffmpeg, .html as JavaScript frames.

            Raises
            ------
            RuntimeError
                For a video ending when ffmpeg is not installed (matplotlib would fall back
                to Pillow, which cannot write it).
            ValueError
                For an ending no writer is chosen for (pass ``writer=`` then).
            """
            if writer is None:
                ext = os.path.splitext(os.fspath(filename))[1].lower()
                if ext not in _WRITERS:
                    raise ValueError(
                        f"cannot tell which writer makes {ext or 'a file without ending'!r}: "
                        f"use one of {sorted(_WRITERS)} or pass writer="
                    )
                writer = _WRITERS[ext]
                if writer == "ffmpeg" and not animation.writers.is_available("ffmpeg"):
                    import matplotlib as mpl

                    raise RuntimeError(
                        f"writing {ext} needs ffmpeg, which was not found (looked for "
                        f"{mpl.rcParams['animation.ffmpeg_path']!r}): install ffmpeg (e.g. "
                        "apt install ffmpeg, conda install ffmpeg) or save a .gif, which "
                        "Pillow writes"
                    )
            if writer == "pillow" and set(kwargs) <= {"dpi", "fps"}:
                self._save_gif(filename, **kwargs)
            else:
                super().save(os.fspath(filename), writer=writer, **kwargs)

        def _save_gif(self, filename, dpi=None, fps=None):
            """The GIF as matplotlib's Pillow writer makes it, but with the static parts
            (axes, ticks, labels, colour bar: most of the drawing time) drawn once and each
            frame drawing only the particles, trails and clock over them -- blitting, as a
            live window does.  The moving artists are drawn in the order ``draw`` returns
            them, which is their order in a full drawing."""
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from PIL import Image

            fig = self._fig
            moving = self._update(0)
            old_dpi, old_canvas = fig.dpi, fig.canvas
            animated = [a.get_animated() for a in moving]
            try:
                if dpi not in (None, "figure"):
                    fig.set_dpi(dpi)
                canvas = FigureCanvasAgg(fig)
                for a in moving:
                    a.set_animated(True)
                canvas.draw()
                background = canvas.copy_from_bbox(fig.bbox)
                frames = []
                for k in range(len(self.samples)):
                    canvas.restore_region(background)
                    for a in self._update(k):
                        a.axes.draw_artist(a)
                    size = canvas.get_width_height()
                    frames.append(Image.frombuffer("RGBA", size, canvas.buffer_rgba()).copy())
                duration = 1000.0 / fps if fps else self._interval
                frames[0].save(
                    filename,
                    save_all=True,
                    append_images=frames[1:],
                    duration=round(duration),
                    loop=0,
                )
            finally:
                for a, was in zip(moving, animated, strict=True):
                    a.set_animated(was)
                fig.set_dpi(old_dpi)
                fig.set_canvas(old_canvas)
                old_canvas.figure = fig

    return ParticleAnimation


def animate(
    traj: Trajectory,
    *,
    frames: slice | Sequence[int] | NDArray[np.integer] | None = None,
    stride: int = 1,
    trails: int | Sequence[int] | NDArray[np.integer] | None = None,
    trail_length: int | None = None,
    color_by_speed: bool = False,
    norm: Any = None,
    color: Any = "C0",
    trail_color: Any = "C3",
    plane: str | tuple[int, int] | None = None,
    slab: tuple[float, float] | None = None,
    interval: float = 50.0,
    blit: bool | None = None,
    title: str | None = None,
    ax: Axes | None = None,
    spin: bool | None = None,
) -> Any:
    """An animation of a trajectory: particles as disks at their true radii in the box.

    Parameters
    ----------
    traj : Trajectory
        With positions stored (and velocities for ``color_by_speed``).
    frames : slice or sequence of int, optional
        Which samples to show (default all), e.g. ``slice(0, 200)``.
    stride : int
        Show every ``stride``-th of them: for long trajectories.
    trails : int or sequence of int, optional
        Particles whose paths are drawn (and whose disks get ``trail_color``, half
        transparent so that the path shows across them).  A trail
        uses every sample up to the frame, not only the frames shown.
    trail_length : int, optional
        How many samples back a trail reaches (default: to the first sample).
    color_by_speed : bool
        Colour each disk by its speed at the sample (viridis, with a colour bar).
    norm : matplotlib.colors.Normalize, optional
        With ``color_by_speed``: the scale of speeds (units sqrt(epsilon / m)) onto colours,
        the same in every frame, e.g. ``Normalize(0, 3)``.  By default each frame is coloured
        by its speeds over its own root-mean-square speed (dimensionless), so that a cooling
        gas keeps its contrast instead of fading into the low end of one fixed scale.
    color, trail_color : matplotlib colours
        Of the disks, and of the trail particles' disks and paths.
    plane : "xy", "xz", "yz" or a pair of axis numbers, 3D only
        The plane a 3D trajectory is projected onto (default "xy"); the third axis is the
        depth.
    slab : (z0, w), 3D only
        Draw only the particles whose depth lies within ``|depth - z0| < w`` (minimum image
        in a periodic box): a slice instead of the whole projection.
    interval : float
        Milliseconds between frames when shown (and the frame rate a saved file gets).
    blit : bool, optional
        Redraw only what changes, where the canvas supports it (default: when it does).
    title : str, optional
        Above the box (in 3D by default what is drawn: the projection or the slice).
    ax : matplotlib Axes, optional
        Draw into these (e.g. from ``plt.subplots()`` for a live window); by default a new
        Figure outside pyplot, so a notebook shows the animation once, not also a still.
    spin : bool, optional
        Draw each disk's rotation as a radius line (rough particles: the trajectory must
        have stored ``angular_velocities``).  Default: when it did.  The angle is the spin
        about the axis seen face-on summed over the samples (module docstring).

    Returns
    -------
    ParticleAnimation
        A ``matplotlib.animation.FuncAnimation``.  In Jupyter it shows itself (JavaScript
        frames; or ``anim.to_jshtml()``); ``anim.save("run.gif")`` writes a GIF with
        Pillow, ``anim.save("run.mp4")`` an MP4 with ffmpeg; ``anim.draw(k)`` draws frame k.

    Raises
    ------
    ValueError
        No samples or no positions stored, no velocities with ``color_by_speed``, a plane
        or slab that does not fit the dimension, frames or stride that select nothing.
    IndexError
        A particle in ``trails`` or a sample in ``frames`` that does not exist.
    """
    positions = traj._need("positions")
    n, dim = traj.n, traj.dim
    samples = _samples(len(traj.times), frames, stride)
    (ax0, ax1), depth = _plane(plane, dim)
    if slab is not None:
        if depth is None:
            raise ValueError("slab selects a slice of a 3D trajectory; this one is 2D")
        z0, w = (float(s) for s in slab)
        if not w > 0:
            raise ValueError(f"slab = (z0, w) needs a half-width w > 0, got {w}")
    trail_ids = _trail_particles(trails, n)
    if trail_length is not None and int(trail_length) < 1:
        raise ValueError(f"trail_length must be >= 1 samples, got {trail_length}")
    speeds = None
    if color_by_speed:
        speeds = np.linalg.norm(traj._need("velocities"), axis=-1)
    elif norm is not None:
        raise ValueError("norm sets the colours of speeds: pass color_by_speed=True with it")

    phi = None
    if spin is None:
        spin = traj.angular_velocities is not None
    if spin:
        right_handed = depth is None or (ax0, ax1, depth) in ((0, 1, 2), (1, 2, 0), (2, 0, 1))
        phi = _spin_angles(traj, depth, 1.0 if right_handed else -1.0)

    _matplotlib("matplotlib")  # a bare install: say which extra brings it
    from matplotlib import colors as mcolors
    from matplotlib.collections import EllipseCollection, LineCollection
    from matplotlib.patches import Rectangle

    own_figure = None
    if ax is None:
        from matplotlib.figure import Figure

        own_figure = Figure(figsize=(5.0, 5.0), layout="constrained")
        ax = own_figure.add_subplot()
    fig = ax.figure
    lo, hi = np.asarray(traj.lower, dtype=np.float64), np.asarray(traj.upper, dtype=np.float64)
    periodic = traj.boundary == "periodic"
    length = hi - lo
    d = 2.0 * np.broadcast_to(np.asarray(traj.radii, dtype=np.float64), (n,))
    is_trail = np.zeros(n, dtype=bool)
    is_trail[trail_ids] = True
    if speeds is not None:
        from matplotlib import colormaps

        cmap = colormaps["viridis"]
        speed_label = SPEED
        if norm is None:
            # each sample's speeds over its rms speed: a cooling gas' speed distribution keeps
            # its shape while its scale falls, so one fixed scale would fade to dark
            rms = np.sqrt(np.mean(speeds**2, axis=-1, keepdims=True))
            speeds = speeds / np.where(rms > 0, rms, 1.0)
            norm = mcolors.Normalize(0.0, float(speeds[samples].max()) or 1.0)
            speed_label = "speed / rms speed of the frame (dimensionless)"
    # a trail particle's disk is see-through, so that its own path shows across it
    trail_rgba = mcolors.to_rgba(trail_color, alpha=0.55)
    base = np.tile(mcolors.to_rgba(color), (n, 1))
    base[is_trail] = trail_rgba

    def collection():
        c = EllipseCollection(
            d, d, np.zeros(n), units="xy", offsets=np.zeros((n, 2)), offset_transform=ax.transData
        )
        c.set_edgecolor("none")
        ax.add_collection(c)
        return c

    disks = collection()
    # a periodic box: each disk's three nearest images in the plane (shifted by one box
    # length towards the far side along each drawn axis, and along both), clipped by the
    # box (below), so only the parts that reach into it are seen
    images = [collection() for _ in range(3)] if periodic else []
    lines = [ax.plot([], [], "-", lw=1.2, color=trail_color, zorder=3)[0] for _ in trail_ids]
    radii_lines = None
    if phi is not None:
        radii_lines = LineCollection([], colors="k", linewidths=0.8, zorder=2)
        ax.add_collection(radii_lines)
    outline = ax.add_patch(
        Rectangle((lo[ax0], lo[ax1]), length[ax0], length[ax1], fill=False, lw=1.5, clip_on=False)
    )
    for c in (disks, *images):  # periodic images and wrapped disks end at the box' edges
        c.set_clip_path(outline)
    if radii_lines is not None:
        radii_lines.set_clip_path(outline)
    # the clock sits in a strip above the box, where it never covers a particle; the box'
    # outline is the frame, the axes' own spines only carry the ticks along it
    strip = 0.09 * length[ax1]
    ax.set_xlim(lo[ax0], hi[ax0])
    ax.set_ylim(lo[ax1], hi[ax1] + strip)
    ax.spines[["top", "right"]].set_visible(False)
    ax.spines["left"].set_bounds(lo[ax1], hi[ax1])
    ax.set_aspect("equal")
    ax.set_xlabel(POSITION.format("xyz"[ax0]))
    ax.set_ylabel(POSITION.format("xyz"[ax1]))
    if depth is not None:
        what = "projection" if slab is None else f"slice |{'xyz'[depth]} − {z0:g}| < {w:g}"
        title = title or f"{what} onto the {'xyz'[ax0]}{'xyz'[ax1]} plane"
    if title:
        ax.set_title(title, fontsize="medium")
    clock = ax.text(lo[ax0], hi[ax1] + strip / 2, "", va="center", fontsize="small", zorder=5)
    if speeds is not None:
        from matplotlib.cm import ScalarMappable

        fig.colorbar(ScalarMappable(norm, cmap), ax=ax, shrink=0.8, label=speed_label)

    # a sheared box (docs/shear.md): positions come into the box through the sliding
    # images, and a disk's image across a y face is displaced along x by the offset then
    rate = traj.scene_parameters.get("shear_rate", 0.0)
    sheared = rate != 0.0 and periodic
    offset0 = traj.scene_parameters.get("shear_offset", 0.0)

    def update(k):
        s = samples[k]
        x = positions[s]
        if sheared:
            x = _shear.wrap(x, lo, hi, rate, offset0, float(traj.times[s]))[0]
        elif periodic:
            x = wrap(x, lo, hi)
        xy = np.ascontiguousarray(x[:, [ax0, ax1]])
        rgba = cmap(norm(speeds[s])) if speeds is not None else base.copy()
        if speeds is not None:
            rgba[is_trail] = trail_rgba
        if slab is not None:
            dz = x[:, depth] - z0
            if periodic:
                dz -= length[depth] * np.round(dz / length[depth])
            rgba[np.abs(dz) >= w, 3] = 0.0  # outside the slab: transparent
        disks.set_offsets(xy)
        disks.set_facecolor(rgba)
        if periodic:
            centre = (lo + hi)[[ax0, ax1]] / 2
            shift = np.where(xy > centre, -1.0, 1.0) * length[[ax0, ax1]]
            # the images across the y faces: displaced by -+delta in a sheared box (drawn
            # in the x-y plane only), then their own nearest image along x
            slid, slid_shift = xy, shift
            if sheared and (ax0, ax1) == (0, 1):
                delta = _shear.offset(rate, offset0, length[0], length[1], float(traj.times[s]))
                slid = xy.copy()
                slid[:, 0] = wrap(xy[:, 0] + np.sign(shift[:, 1]) * delta, lo[0], hi[0])
                slid_shift = shift.copy()
                slid_shift[:, 0] = np.where(slid[:, 0] > centre[0], -1.0, 1.0) * length[0]
            for c, mask in zip(images, ((1, 0), (0, 1), (1, 1)), strict=True):
                if mask[1]:
                    c.set_offsets(slid + slid_shift * mask)
                else:
                    c.set_offsets(xy + shift * mask)
                c.set_facecolor(rgba)
        if radii_lines is not None and phi is not None:
            tip = xy + 0.5 * d[:, None] * np.column_stack([np.cos(phi[s]), np.sin(phi[s])])
            radii_lines.set_segments(list(np.stack([xy, tip], axis=1)))
            radii_lines.set_alpha(None)
            edge = np.zeros((n, 4))
            edge[:, 3] = np.where(rgba[:, 3] > 0, 1.0, 0.0)  # hidden with its disk
            radii_lines.set_color(cast(Any, edge))  # RGBA rows; the stubs want tuples
        first = 0 if trail_length is None else max(0, s - int(trail_length))
        for line, i in zip(lines, trail_ids, strict=True):
            path = positions[first : s + 1, i][:, [ax0, ax1]]
            path = trail_segments(path, lo[[ax0, ax1]], hi[[ax0, ax1]], periodic)
            line.set_data(path[:, 0], path[:, 1])
        clock.set_text(f"t = {traj.times[s]:.4g}")
        extra = [radii_lines] if radii_lines is not None else []
        return [disks, *images, *extra, outline, *lines, clock]  # a full drawing's order

    if own_figure is not None:
        # lay the figure out once: constrained layout would otherwise run on every frame
        # (half the time of writing a GIF), for a layout that never changes
        update(0)
        own_figure.draw_without_rendering()
        own_figure.set_layout_engine("none")
    if blit is None:
        blit = bool(getattr(fig.canvas, "supports_blit", False))
    anim = _animation_class()(
        fig,
        update,
        frames=len(samples),
        init_func=lambda: update(0),
        interval=interval,
        blit=blit,
        cache_frame_data=False,
    )
    anim.samples = samples
    anim.disks = disks
    anim.images = images or None
    anim.trail_lines = lines
    anim.ax = ax
    anim._update = update
    update(0)
    return anim
