#!/usr/bin/python3
"""tools/reference/near_field_fem_table.py — the nonlinear finite-element table of touching iron
balls (axisym_fem.py): pairs at every gap and field, chains of 3 and 5, each at two mesh
levels, with the Richardson error estimate.

    /usr/bin/python3 tools/reference/near_field_fem_table.py [--out tools/reference/data] [--quick]

Writes near_field_fem.csv (or, with --extra-chains, near_field_fem_chains.csv: held-out chains
of 4 and 7 at g = 0.003a and of 3 and 5 at wider gaps, in the same columns): one row per (N, g/a, H0/Ms, ball). Balls are numbered from the
bottom, 0..N-1; only the upper half is listed (ball N-1-i carries the force -F_z of ball i:
mirror symmetry). Forces are the z force on the ball; moments the whole chain's, along z.

Error estimate: the forces converge as O(h^2) under refinement (`refine` 1, 2 and 4 halve
every element size each time), so F_4 - F_2 is 3/4 of the level-2 error and |F_4 - F_2|/3
estimates the fine level's; the table gives the fine value F_4, that estimate relative to
it, the two coarser values, and the observed order log2(|F_2 - F_1|/|F_4 - F_2|).
The units are SI for a = 5 mm and Ms = 1.6e6 A/m (the registry's iron), mu_r = 1000, and the
module units (mu0 Ms^2 a^2, Ms a^3) beside them."""
import argparse
import csv
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import axisym_fem as af  # noqa: E402

A, MS, MU0 = 5e-3, 1.6e6, 4e-7 * math.pi
F_UNIT = MU0 * MS * MS * A * A  # N per mu0 Ms^2 a^2
M_UNIT = MS * A ** 3  # A m^2 per Ms a^3
GAPS = (1.0, 0.3, 0.1, 0.03, 0.01, 0.003)
FIELDS = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0)
CHAINS = (3, 5)
CHAIN_GAP = 0.003
LEVELS = (1.0, 2.0, 4.0)

COLUMNS = ["N", "gap_over_a", "H0_over_Ms", "ball", "z_over_a", "Fz_N", "Fz_mu0Ms2a2",
           "Fz_rel_error_est", "Fz_level1_mu0Ms2a2", "Fz_level2_mu0Ms2a2", "Fz_observed_order", "chain_moment_Am2", "chain_moment_Msa3",
           "moment_rel_error_est", "nodes_fine", "newton_fine", "seconds"]


# Held-out chains (near_field_fem_chains.csv): a 4-chain at the table's gap gives the chain
# correction a second contact count to fit on, and chains at wider gaps check it off that gap.
EXTRA_CHAINS = ((4, 0.003), (7, 0.003), (3, 0.03), (3, 0.01), (5, 0.03))


def cases(quick, extra=False):
    if quick:
        return [(2, 0.1, (0.01, 0.1))]
    if extra:
        return [(n, g, FIELDS) for n, g in EXTRA_CHAINS]
    return [(2, g, FIELDS) for g in GAPS] + [(n, CHAIN_GAP, FIELDS) for n in CHAINS]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--out", default=os.path.join(here, "data"))
    ap.add_argument("--quick", action="store_true", help="one small case (a smoke test)")
    ap.add_argument("--extra-chains", action="store_true",
                    help="the held-out chains (EXTRA_CHAINS) into near_field_fem_chains.csv instead")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "near_field_fem_chains.csv" if args.extra_chains else "near_field_fem.csv")
    t_all = time.time()
    with open(path, "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(COLUMNS)
        for n, gap, fields in cases(args.quick, args.extra_chains):
            t0 = time.time()
            res = []
            for lev in LEVELS:
                mesh, rows = af.run_case(n, gap, fields, refine=lev)
                res.append((mesh, rows))
            (m1, r1), (m2, r2), (m4, r4) = res
            chain = m4.chain
            nb = len(chain.centres)
            for a_, b_, c_ in zip(r1, r2, r4):
                mom = c_["moment"]
                merr = abs(c_["moment"] - b_["moment"]) / 3.0 / abs(mom)
                for k in range(nb):
                    z = chain.centres[k]
                    ball = n - nb + k
                    f1, f2, f4 = a_["forces"][k], b_["forces"][k], c_["forces"][k]
                    ferr = abs(f4 - f2) / 3.0 / abs(f4)
                    order = math.log2(abs(f2 - f1) / abs(f4 - f2)) if f4 != f2 and f2 != f1 else float("nan")
                    if abs(z) < 1e-12:
                        f1 = f2 = f4 = 0.0  # the central ball of an odd chain: zero by symmetry
                        ferr, order = 0.0, float("nan")
                    wr.writerow([n, gap, c_["H0"], ball, f"{z:.6g}", f"{f4 * F_UNIT:.8g}", f"{f4:.8g}",
                                 f"{ferr:.3g}", f"{f1:.8g}", f"{f2:.8g}", f"{order:.3g}",
                                 f"{mom * M_UNIT:.8g}", f"{mom:.8g}", f"{merr:.3g}", m4.nodes,
                                 c_["newton"], f"{c_['seconds']:.1f}"])
                fh.flush()
            print(f"N {n} g {gap}: {time.time() - t0:.0f} s (nodes {m1.nodes}, {m2.nodes}, {m4.nodes})",
                  flush=True)
    print(f"wrote {path} ({time.time() - t_all:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
