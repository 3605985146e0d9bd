#!/usr/bin/python3
"""tools/reference/near_field_compare.py — the engine's near-field models (magsolve
--near-field dipole and pair) against the finite-element table (near_field_fem_table.py):
force and moment ratios model / FEM for every pair cell and every chain.

    /usr/bin/python3 tools/reference/near_field_compare.py [--fem tools/reference/data/near_field_fem.csv]
        [--magsolve build/release/tools/magsolve] [--out tools/reference/data/near_field_compare.csv]
    # the held-out chains (near_field_fem_table.py --extra-chains):
    /usr/bin/python3 tools/reference/near_field_compare.py --fem tools/reference/data/near_field_fem_chains.csv \
        --out tools/reference/data/near_field_compare_chains.csv

Each case is the FEM's arrangement in SI (a = 5 mm, Ms = 1.6e6 A/m, balls centred at
(i - (N-1)/2)(2 + g) a on the z axis, H0 along z), solved by magsolve --method exact
--force-model classic --mu-r 1000 (the Newton solution of the engine's tanh curve, the
classic force -grad U*; --curve iron: the Newton solution of a sphere of the reference's own
bulk iron, magnetics/types.hpp). Ratios of 1 are exact; the pair model's mark is 0.85-1.15 for pairs
and 25 % for chains (end ball's force, chain moment). Prints markdown tables; a chain's
"middle ball" is the innermost one of its upper half with a non-zero force."""
import argparse
import collections
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import near_field_common as nfcommon

A, MS = 5e-3, 1.6e6
V = 4.0 / 3.0 * math.pi * A ** 3
MODELS = ("dipole", "pair")


def magsolve(exe, n, gap, h0, model, tmp, curve="tanh"):
    """(z forces on every ball, N; total moment along z, A m^2) from magsolve."""
    d = (2.0 + gap) * A
    case = {"external_field": [0, 0, h0 * MS],
            "moments": [{"kind": "induced", "position": [0, 0, (i - 0.5 * (n - 1)) * d], "volume": V, "Ms": MS}
                        for i in range(n)]}
    path = os.path.join(tmp, "case.json")
    with open(path, "w") as fh:
        json.dump(case, fh)
    out = subprocess.run([exe, path, "--method", "exact", "--force-model", "classic", "--near-field", model,
                          "--mu-r", "1000", "--curve", curve], check=True, capture_output=True, text=True).stdout
    js = json.loads(out)
    F = [m["F_model"][2] for m in js["moments"]]
    mom = sum(V * m["M"][2] for m in js["moments"])
    return F, mom


def compare(fem, exe, curve="tanh"):
    """One row per FEM ball with a non-zero force: the FEM force and moment, and each model's
    force, force / FEM and moment / FEM (magsolve per arrangement and model)."""
    rows = list(csv.DictReader(open(fem)))
    groups = collections.OrderedDict()
    for r in rows:
        groups.setdefault((int(r["N"]), float(r["gap_over_a"]), float(r["H0_over_Ms"])), []).append(r)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for (n, gap, h0), balls in groups.items():
            res = {m: magsolve(exe, n, gap, h0, m, tmp, curve) for m in MODELS}
            mom_fem = float(balls[0]["chain_moment_Am2"])
            for b in balls:
                k = int(b["ball"])
                f_fem = float(b["Fz_N"])
                if f_fem == 0.0:
                    continue
                row = {"N": n, "gap_over_a": gap, "H0_over_Ms": h0, "ball": k, "Fz_fem_N": f_fem,
                       "Fz_rel_error_est": float(b["Fz_rel_error_est"]), "moment_fem_Am2": mom_fem}
                for m in MODELS:
                    row[f"Fz_{m}_N"] = res[m][0][k]
                    row[f"F_{m}_over_fem"] = res[m][0][k] / f_fem
                    row[f"moment_{m}_over_fem"] = res[m][1] / mom_fem
                out.append(row)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--fem", default=os.path.join(here, "data", "near_field_fem.csv"))
    nfcommon.add_magsolve(ap)
    ap.add_argument("--out", default=os.path.join(here, "data", "near_field_compare.csv"))
    nfcommon.add_curve(ap)
    args = ap.parse_args(argv)
    if nfcommon.magsolve_missing(args.magsolve, "near_field_compare.py"):
        return 2
    out = compare(args.fem, args.magsolve, args.curve)
    with open(args.out, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=list(out[0].keys()))
        wr.writeheader()
        for r in out:
            wr.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    # markdown: pair cells (upper ball), then chains
    fields = sorted({r["H0_over_Ms"] for r in out})
    gaps = sorted({r["gap_over_a"] for r in out if r["N"] == 2}, reverse=True)
    for m in MODELS if gaps else ():
        print(f"\n{m} / FEM, two balls, force on the upper ball (rows g/a, columns H0/Ms):\n")
        def cell(g, h, m=m):
            r = next(r for r in out if r["N"] == 2 and r["gap_over_a"] == g and r["H0_over_Ms"] == h)
            return nfcommon.pair_mark(r[f"F_{m}_over_fem"])
        print("\n".join(nfcommon.gap_field_table(gaps, fields, cell)))
    for n, gap in sorted({(r["N"], r["gap_over_a"]) for r in out if r["N"] > 2}, key=lambda k: (-k[1], k[0])):
        print(f"\nchain of {n} (g = {gap:g}a), model / FEM:\n")
        print("| H0/Ms | " + " | ".join(f"{q} {m}" for q in ("end ball", "middle ball", "moment") for m in MODELS) + " |")
        print("|---" * 7 + "|")
        for h in fields:
            rs = [r for r in out if r["N"] == n and r["gap_over_a"] == gap and r["H0_over_Ms"] == h]
            end = max(rs, key=lambda r: r["ball"])
            mid = min(rs, key=lambda r: r["ball"])
            cells = []
            for label, q, r_ in (("end", "F", end), ("mid", "F", mid), ("moment", "moment", end)):
                for m in MODELS:
                    if label == "mid" and mid is end:
                        cells.append("—")  # N = 3: the middle ball is the central one (0 by symmetry)
                        continue
                    v = r_[f"{q}_{m}_over_fem"]
                    cells.append(f"**{v:.2f}**" if abs(v - 1) > 0.25 else f"{v:.2f}")
            print(f"| {h:g} | " + " | ".join(cells) + " |")
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
