#!/usr/bin/env python3
"""Sweeps balls_up's magnet strength and charts how many balls the magnet holds.

    PYTHONPATH=build/release/python /usr/bin/python3 tools/examples/sweep.py [--out DIR]
        [--count N] [--seconds S] [--strengths 0.25,0.5,...]

For each strength (a factor on every permanent moment, magsim-scene's --strength) it runs
balls_up with N balls for S seconds and reads metrics()["held"]: balls attached to the magnet
without a path through a ball on the ground. Writes DIR/sweep.csv and DIR/sweep.png
(default out/sweep). About 30 s with the defaults.
"""
import argparse
import csv
import os
import time

import matplotlib

matplotlib.use("Agg")  # headless: no display needed
import matplotlib.pyplot as plt  # noqa: E402

import magsim  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/sweep")
    ap.add_argument("--count", type=int, default=40, help="balls (default 40)")
    ap.add_argument("--seconds", type=float, default=1.2, help="simulated time per run (default 1.2)")
    ap.add_argument("--strengths", default="0.5,0.8,1,1.2,1.25,1.3,1.4,1.5,2",
                    help="comma-separated factors on the magnet's moment")
    ap.add_argument("--threads", type=int, default=0, help="OpenMP threads (0: the free cores)")
    a = ap.parse_args()
    strengths = [float(s) for s in a.strengths.split(",")]
    os.makedirs(a.out, exist_ok=True)

    rows = []
    t0 = time.monotonic()
    for k in strengths:
        scene = magsim.Scene.from_registry("balls_up", count=a.count, strength=k)
        scene.set_option("threads", a.threads)
        sim = magsim.Simulation(scene)
        sim.run(a.seconds)
        m = sim.metrics()
        rows.append({"strength": k, "held": m["held"], "attached": m["attached"], "escaped": m["escaped"],
                     "kinetic_energy": m["kinetic_energy"]})
        print(f"strength {k:5g}: held {m['held']:3d} of {a.count}, attached {m['attached']:3d}, "
              f"KE {m['kinetic_energy']:.3g} J")

    with open(os.path.join(a.out, "sweep.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r["strength"] for r in rows], [r["held"] for r in rows], "o-", label="held")
    ax.plot([r["strength"] for r in rows], [r["attached"] for r in rows], "s--", alpha=0.6, label="attached")
    ax.set_xscale("log")
    ax.set_xlabel("magnet strength (x balls_up's moment)")
    ax.set_ylabel(f"balls (of {a.count})")
    ax.set_title(f"balls_up after {a.seconds:g} s")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    png = os.path.join(a.out, "sweep.png")
    fig.savefig(png, dpi=120)
    print(f"{len(rows)} runs in {time.monotonic() - t0:.1f} s; wrote {png} and sweep.csv")


if __name__ == "__main__":
    main()
