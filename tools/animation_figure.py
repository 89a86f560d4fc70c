"""docs/animation.gif: the Brownian tracer scene animated, for docs/animation.md.

Run from the repository root: ``python tools/animation_figure.py``.  The picture is kept
small (under 400 kB: 30 frames, 400 x 400 pixels) because it lives in the repository.
"""

import argparse
import os

import numpy as np

import granular


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join("docs", "animation.gif"))
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--dpi", type=float, default=80.0)
    args = parser.parse_args()

    scene = granular.Scene.seed_brownian_disks(seed=2020, tracer=True)
    t_stop = 20.0
    # 4 samples per time unit, so the trail is smooth; the GIF shows every 2nd sample: one
    # frame per half time unit, the tracer moving about a tenth of its radius between frames
    times = np.linspace(0.0, t_stop, int(4 * t_stop) + 1)
    traj = granular.Simulation(scene).run(t_stop=t_stop, sample_times=times)
    anim = granular.plot.animate(
        traj,
        frames=slice(0, 2 * args.frames),
        stride=2,
        trails=[0],
        interval=100,
        title="150 disks and a Brownian tracer (red)",
    )
    anim.save(args.out, dpi=args.dpi)
    print(f"{args.out}: {os.path.getsize(args.out) / 1e3:.0f} kB, {args.frames} frames")


if __name__ == "__main__":
    main()
