#!/usr/bin/env python3
"""A rake-angle study from Python: one pass of the quick loading model (examples/scenarios/loading_quick.yaml) at
each of three rake angles, then the mass per pass and the mean dig force against the angle (thesis Paper A
compares rake angles the same way).

    PYTHONPATH=build/python python3 examples/python/rake_study.py                 # 56.8, 61.8, 66.8 deg, 2 threads
    PYTHONPATH=build/python python3 examples/python/rake_study.py --angles 60 64 --out out/rake

Each variant is an ordinary run folder (report.md, probes.csv, summary.json, ParaView series); the table is
printed and the figure written to OUT/rake_study.png. About 1.5 minutes per angle on 2 cores.
"""
import argparse
import os
import sys

import dipper

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default=os.path.join(ROOT, "examples", "scenarios", "loading_quick.yaml"))
    ap.add_argument("--angles", type=float, nargs="+", default=[56.8, 61.8, 66.8], help="rake angles, deg")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default="out/rake_study")
    args = ap.parse_args()

    rows = []
    for angle in args.angles:
        scenario = dipper.load(args.scenario, set={"shovel.rake_angle_deg": angle, "shovel.passes": 1})
        folder = os.path.join(args.out, f"rake_{angle:g}")

        def progress(t, steps):
            print(f"\rrake {angle:g} deg: t = {t:5.2f} s of at most {scenario.duration_s:g} s", end="", file=sys.stderr, flush=True)

        result = dipper.run(scenario, folder, threads=args.threads, progress=progress, every=500)
        print(file=sys.stderr)
        if result.status != "completed":
            sys.exit(f"rake {angle:g} deg: the run {result.status}: {result.message}")
        passes = dipper.read_passes(folder)
        if not passes:
            sys.exit(f"rake {angle:g} deg: no pass was completed in {scenario.duration_s:g} s")
        p = passes[0]
        rows.append((angle, p["mass_kg"] / 1000.0, p["fill_factor"], p["mean_dig_force_N"] / 1e6, p["peak_dig_force_N"] / 1e6))

    print(f"{'rake deg':>8} {'mass t':>8} {'fill':>6} {'mean dig MN':>12} {'peak dig MN':>12}")
    for r in rows:
        print(f"{r[0]:8.1f} {r[1]:8.1f} {r[2]:6.2f} {r[3]:12.2f} {r[4]:12.2f}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    angles = [r[0] for r in rows]
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.plot(angles, [r[1] for r in rows], "o-")
    a.set_xlabel("rake angle (deg)")
    a.set_ylabel("mass in the dipper at the dump (t)")
    a.set_ylim(bottom=0.0)
    b.plot(angles, [r[3] for r in rows], "o-", label="mean")
    b.plot(angles, [r[4] for r in rows], "s--", label="peak")
    b.set_xlabel("rake angle (deg)")
    b.set_ylabel("dig force (MN)")
    b.set_ylim(bottom=0.0)
    b.legend()
    fig.suptitle(f"{os.path.basename(args.scenario)}: one pass per rake angle")
    fig.tight_layout()
    figure = os.path.join(args.out, "rake_study.png")
    fig.savefig(figure, dpi=110)
    print(f"figure: {figure}")


if __name__ == "__main__":
    main()
