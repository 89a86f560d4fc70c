"""Command line: ``python -m granular demo | bench``."""
from __future__ import annotations

import argparse
import sys


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m granular",
                                     description="Molecular and granular gases of hard spheres.")
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
    bench.add_argument("--speed-accuracy", action="store_true",
                       help="chart error against cost and map where methods fail")
    bench.add_argument("--out", default="speed-accuracy", help="output folder (--speed-accuracy)")
    args = parser.parse_args(argv)

    if args.command == "demo":
        from . import demo as demo_module

        demo_module.main(out=args.out, quick=args.quick)
    elif args.command == "reproduce":
        from . import reproduce

        reproduce.main(out=args.out, quick=args.quick, runs=args.runs)
    elif args.command == "bench":
        if args.speed_accuracy:
            from . import speed_accuracy

            speed_accuracy.main(out=args.out, quick=args.quick)
        else:
            from . import bench as bench_module

            bench_module.main(json_path=args.json, quick=args.quick, large=args.large)
    return 0


if __name__ == "__main__":
    sys.exit(main())
