"""Command line: ``python -m granular demo | reproduce | bench``.

Thin on purpose: it parses the arguments, checks the optional modules the command needs and
only then imports the application from granular.cli (applications built on the library,
which the library never imports); only the reproduction's list of experiments is read
before, for its help page and to refuse an unknown ``--only`` name."""

from __future__ import annotations

import argparse
import importlib.util
import sys
import textwrap

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


def _parser():
    """The command line: a page per subcommand (``python -m granular CMD --help``) that says
    what it does, every option with its default."""
    from .cli.reproduce import ABOUT

    def page(sub, name, summary, description, epilog=None):
        return sub.add_parser(
            name,
            help=summary,
            description=textwrap.fill(description, 88),
            epilog=epilog,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )

    parser = argparse.ArgumentParser(
        prog="python -m granular",
        description="Molecular and granular gases of hard disks and spheres: the demo, the "
        "thesis' chapter 4 reproduced, benchmarks. Each command has its own page: "
        "python -m granular COMMAND --help.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    demo = page(
        sub,
        "demo",
        "a granular and a molecular gas against theory",
        "A granular (xi = 0.8) and a molecular gas in the thesis' standard box, eight runs "
        "each, their temperature and MSD beside theory with standard errors, then a Brownian "
        "tracer: figures, summary.json and brownian.json in the output folder (about 40 s on "
        "2 cores; needs the plot extra).",
    )
    demo.add_argument("--out", default="granular-demo", help="output folder (default: %(default)s)")
    demo.add_argument(
        "--quick",
        action="store_true",
        help="a smaller box for a tenth of the time, 20 runs (seconds; for tests) (default: off)",
    )
    listing = "\n".join(f"  {name:<13} {what}" for name, (what, *_) in ABOUT.items())
    rep = page(
        sub,
        "reproduce",
        "the thesis' chapter 4, figure by figure",
        "[G20] chapter 4 experiment by experiment with five times its runs: PNG figures, "
        "summary.json (ours, its standard error, the thesis' value, theory's) and report.md. "
        "A line per experiment on stderr says what runs and its expected time. "
        "Needs the plot extra.",
        epilog="experiments (--only NAME), in the order they run:\n" + listing,
    )
    rep.add_argument(
        "--out", default="granular-reproduce", help="output folder (default: %(default)s)"
    )
    rep.add_argument(
        "--quick",
        action="store_true",
        help="smaller systems over shorter times, 20 runs each: a minute or two (default: off)",
    )
    rep.add_argument(
        "--runs",
        type=int,
        default=None,
        help="runs per experiment (default: five times the thesis' count; 20 with --quick)",
    )
    rep.add_argument(
        "--only",
        action="append",
        choices=list(ABOUT),
        metavar="NAME",
        help="run only this experiment (repeat for several; names below) (default: all)",
    )
    bench = page(
        sub,
        "bench",
        "throughput benchmarks, or speed against accuracy",
        "Throughput of the EDMD and Langevin engines (pair collisions and particle-steps per "
        "second), or with --speed-accuracy the error of every method against its cost and "
        "where each fails (figures; about 3.5 minutes; needs the plot extra).",
    )
    bench.add_argument(
        "--json", metavar="FILE", help="write the figures as JSON to FILE (default: print only)"
    )
    bench.add_argument(
        "--quick", action="store_true", help="tiny workloads, seconds (default: off)"
    )
    bench.add_argument("--large", action="store_true", help="add N = 1e6 (default: off)")
    bench.add_argument(
        "--rounds",
        type=int,
        default=None,
        help="interleaved rounds of the Langevin runs, medians reported (default: 3; 1 with "
        "--quick)",
    )
    bench.add_argument(
        "--speed-accuracy",
        action="store_true",
        help="chart error against cost and map where methods fail (default: off)",
    )
    bench.add_argument(
        "--out",
        default="speed-accuracy",
        help="output folder of --speed-accuracy (default: %(default)s)",
    )
    return parser


def main(argv=None):
    parser = _parser()
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

        reproduce.main(out=args.out, quick=args.quick, runs=args.runs, only=args.only)
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
