#!/usr/bin/env python3
"""tools/scripts/golden_check.py — one state hash per scene on every path.

Runs each registry scene for 100 rigid steps (magsim-scene SCENE --steps 100 --threads 1
--no-render) with each given magsim-scene binary, under each variant below, and compares
summary.json's state_hash with the one golden table (tests/engine/golden_hashes.txt):

  plain        the binary as it is (AVX-512 field kernels where the CPU has them)
  portable     MAGSIM_KERNEL=portable: the kernels a CPU with AVX2+FMA but no AVX-512 runs
  sse2-libm    GLIBC_TUNABLES=glibc.cpu.hwcaps=-FMA,-AVX2: glibc's libm takes the variants
               of a CPU without FMA or AVX2 (the engine must not reach libm's rounding)
  2-threads    --threads 2 instead of 1
  generic      MAGSIM_KERNEL=generic: the kernels of a CPU without FMA (the fused
               multiply-add emulated exactly, about 40x slower: only the scenes of
               SLOW_SCENES unless --scenes names others)
  no-fma       generic with the sse2-libm tunables, as on a CPU without FMA (likewise)

A binary built with -DMAGSIM_NATIVE=OFF is the portable build; one built with
-DMAGSIM_MARCH=x86-64-v3 (or -v2) is a native build for a CPU with AVX2 and FMA (or
SSE4.2) but no AVX-512: with MAGSIM_KERNEL=portable it runs that CPU's path here.

  python3 tools/scripts/golden_check.py [--bin PATH]... [--scenes a,b] [--variants a,b]

Prints a line per run and a closing line 'N passed, N failed'; exits 1 on any mismatch or
failed run, 2 on bad arguments.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TABLE = os.path.join(ROOT, "tests", "engine", "golden_hashes.txt")
VARIANTS = {
    "plain": ({}, []),
    "portable": ({"MAGSIM_KERNEL": "portable"}, []),
    "sse2-libm": ({"GLIBC_TUNABLES": "glibc.cpu.hwcaps=-FMA,-AVX2"}, []),
    "2-threads": ({}, ["--threads", "2"]),
    "generic": ({"MAGSIM_KERNEL": "generic"}, []),
    "no-fma": ({"MAGSIM_KERNEL": "generic", "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-FMA,-AVX2"}, []),
}
SLOW_SCENES = ["balls_up", "crystal_balls"]


def golden_table():
    table = {}
    with open(TABLE) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                scene, h = line.split()
                table[scene] = h
    return table


def run_hash(binary, scene, env_extra, flags):
    with tempfile.TemporaryDirectory() as out:
        env = dict(os.environ)
        env.pop("MAGSIM_KERNEL", None)
        env.pop("GLIBC_TUNABLES", None)
        env.update(env_extra)
        threads = [] if "--threads" in flags else ["--threads", "1"]
        cmd = [binary, scene, "--steps", "100", "--no-render", "--out", out] + threads + flags
        p = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           text=True, timeout=600)
        if p.returncode != 0:
            return None, f"exit {p.returncode}: {p.stderr.strip().splitlines()[-1:]}"
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f)["state_hash"], ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", action="append", default=[],
                    help="a magsim-scene binary (repeatable; default build/release/tools/magsim-scene)")
    ap.add_argument("--scenes", default="", help="comma-separated scenes (default: the table's)")
    ap.add_argument("--variants", default=",".join(VARIANTS),
                    help=f"comma-separated, of {', '.join(VARIANTS)} (default: all)")
    a = ap.parse_args()
    bins = a.bin or [os.path.join(ROOT, "build", "release", "tools", "magsim-scene")]
    for b in bins:
        if not os.access(b, os.X_OK):
            print(f"golden_check: {b}: not an executable (build it first)", file=sys.stderr)
            return 2
    variants = [v for v in a.variants.split(",") if v]
    for v in variants:
        if v not in VARIANTS:
            print(f"golden_check: unknown variant '{v}' (try --help)", file=sys.stderr)
            return 2
    table = golden_table()
    scenes = [s for s in a.scenes.split(",") if s] or list(table)
    passed = failed = 0
    for b in bins:
        for v in variants:
            env_extra, flags = VARIANTS[v]
            todo = scenes
            if v in ("generic", "no-fma") and not a.scenes:
                todo = [s for s in scenes if s in SLOW_SCENES]
            for s in todo:
                h, err = run_hash(b, s, env_extra, flags)
                ok = h is not None and h == table.get(s)
                passed += ok
                failed += not ok
                print(f"{'ok  ' if ok else 'FAIL'} {os.path.relpath(b, ROOT):40s} {v:10s} {s:15s} "
                      f"{h or err} (golden {table.get(s)})", flush=True)
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
