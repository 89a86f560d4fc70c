"""Command line: ``python -m granular demo | reproduce | bench``.

Thin on purpose: it parses the arguments, checks the optional modules the command needs and
only then imports the application from granular.cli (applications built on the library,
which the library never imports)."""

from __future__ import annotations

import argparse
import importlib.util
import sys

# Optional modules a command imports only when it draws, and the extra that installs each:
# checked before the command starts, so that a missing one never loses minutes of work.
_NEEDS = {
    "demo": ("matplotlib",),
    "reproduce": ("matplotlib",),
    "bench --speed-accuracy": ("matplotlib",),
}
_EXTRA = {"matplotlib": "plot"}


def _missing(modules):
    """The modules among ``modules`` that cannot be imported."""
    return [m for m in modules if importlib.util.find_spec(m) is None]


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m granular", description="Molecular and granular gases of hard spheres."
    )
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="a granular and a molecular gas against theory")
    demo.add_argument("--out", default="granular-demo", help="output folder for figures")
    demo.add_argument("--quick", action="store_true", help="smaller, for tests")
    rep = sub.add_parser("reproduce", help="the thesis' chapter 4, figure by figure")
    rep.add_argument("--out", default="granular-reproduce", help="output folder")
    rep.add_argument("--quick", action="store_true", help="small sizes, under a minute")
    rep.add_argument("--runs", type=int, default=None, help="runs per experiment")
    bench = sub.add_parser("bench", help="throughput benchmarks")
    bench.add_argument("--json", metavar="FILE", help="write the figures as JSON")
    bench.add_argument("--quick", action="store_true", help="tiny workloads (seconds)")
    bench.add_argument("--large", action="store_true", help="add N = 1e6")
    bench.add_argument(
        "--rounds",
        type=int,
        default=None,
        help="interleaved rounds of the Langevin runs, medians reported (default 3; 1 --quick)",
    )
    bench.add_argument(
        "--speed-accuracy",
        action="store_true",
        help="chart error against cost and map where methods fail",
    )
    bench.add_argument("--out", default="speed-accuracy", help="output folder (--speed-accuracy)")
    args = parser.parse_args(argv)

    command = "bench --speed-accuracy" if getattr(args, "speed_accuracy", False) else args.command
    missing = _missing(_NEEDS.get(command, ()))
    if missing:
        extras = ",".join(sorted({_EXTRA[m] for m in missing}))
        print(
            f"python -m granular {command} needs {', '.join(missing)}, which is not "
            f"installed: pip install 'granular[{extras}]'",
            file=sys.stderr,
        )
        return 2

    if args.command == "demo":
        from .cli import demo as demo_module

        demo_module.main(out=args.out, quick=args.quick)
    elif args.command == "reproduce":
        from .cli import reproduce

        reproduce.main(out=args.out, quick=args.quick, runs=args.runs)
    elif args.command == "bench":
        if args.speed_accuracy:
            from .cli import speed_accuracy

            speed_accuracy.main(out=args.out, quick=args.quick)
        else:
            from .cli import bench as bench_module

            bench_module.main(
                json_path=args.json, quick=args.quick, large=args.large, rounds=args.rounds
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
