#!/usr/bin/env python3
"""tools/fuzz.py — mutates the example scene files and magsolve cases and runs the tools on
them, bounded in count and time (issue #13).

    python3 tools/fuzz.py [--seconds 60] [--count 100000] [--seed 1] [--out out/fuzz]

A case fails on: a signal (crash, abort), a hang (over --timeout s), or exit 0 with output
that is not complete and finite: magsim-scene's summary.json missing, invalid or holding an
error or a non-finite number, its states.csv cut mid-row; magsolve's stdout not valid JSON or
holding a non-finite number (JSON null). Failing inputs are kept in OUT/fail_*; the exit code
is 1 when any case failed, else 0. Prints a closing line 'N passed, M failed'.
"""
import argparse, json, math, os, random, re, shutil, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "build/release/tools/magsim-scene")
SOLVE = os.path.join(ROOT, "build/release/tools/magsolve")
SCENES = [os.path.join(ROOT, "scenes/examples/two_balls.json")]
CASES = [os.path.join(ROOT, "tools/examples", f) for f in
         ("cluster_weak.json", "touching_spheres.json")]

NUMBERS = ["0", "-1", "1e308", "-1e308", "1e-308", "1e-12", "3", "0.5", "-0.0", "1e30",
           "-7", "2147483648", "1e9", "NaN", "Infinity", "\"x\"", "null", "[]", "{}", "true"]


EXIT0 = [0, 0]  # cases that ran to exit 0: scenes, magsolve (the checks that bite)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"(?m)^\s*//.*$|(?<=[,\[{\s])//.*$", "", text)


def mutate_tree(node, rng):
    """One structural change somewhere in the parsed JSON (in place)."""
    paths = []

    def walk(n):
        if isinstance(n, dict):
            for k in list(n):
                paths.append((n, k))
                walk(n[k])
        elif isinstance(n, list):
            for i in range(len(n)):
                paths.append((n, i))
                walk(n[i])
    walk(node)
    if not paths:
        return
    parent, key = rng.choice(paths)
    op = rng.random()
    v = parent[key]
    if isinstance(v, (int, float)) and not isinstance(v, bool) and rng.random() < 0.6:
        # a plausible-looking value: scaled by a power of ten, or negated
        parent[key] = -v if rng.random() < 0.2 else v * 10.0 ** rng.randint(-4, 4)
        return
    if op < 0.15 and isinstance(parent, dict):
        del parent[key]
    elif op < 0.25 and isinstance(parent, list) and len(parent) > 0:
        parent.append(json.loads(json.dumps(parent[key])))
    elif op < 0.35 and isinstance(parent, list):
        del parent[key]
    else:
        parent[key] = ("@@" + rng.choice(NUMBERS) + "@@") if rng.random() < 0.8 else \
            rng.choice([[], {}, "", [1, 2], -1e-3])


def mutate(text, rng):
    if rng.random() < 0.2:  # byte-level: truncate, or splice random bytes
        b = bytearray(text.encode())
        if rng.random() < 0.5:
            return bytes(b[: rng.randrange(len(b))])
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    tree = json.loads(strip_comments(text))
    for _ in range(rng.randint(1, 3)):
        mutate_tree(tree, rng)
    out = json.dumps(tree)
    return re.sub(r"\"@@(.*?)@@\"", lambda m: m.group(1).replace('\\"', '"'), out).encode()


def finite_json(v):
    if v is None:
        return False
    if isinstance(v, float):
        return math.isfinite(v)
    if isinstance(v, dict):
        return all(finite_json(x) for k, x in v.items() if k != "error")
    if isinstance(v, list):
        return all(finite_json(x) for x in v)
    return True


def run(cmd, timeout, which):
    """(process, None) when cmd exited 0; (None, reason) on a hang or a signal; (None, None)
    on a clean non-zero exit (a refusal, which is what bad input should get)."""
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "hang"
    if p.returncode < 0:
        return None, f"signal {-p.returncode}"
    EXIT0[which] += p.returncode == 0
    return (p, None) if p.returncode == 0 else (None, None)


def check_scene(path, out, timeout):
    shutil.rmtree(out, ignore_errors=True)
    p, why = run([SCENE, path, "--steps", "30", "--no-render", "--threads", "1", "--out", out],
                 timeout, 0)
    if p is None:
        return why
    try:
        s = json.load(open(os.path.join(out, "summary.json")))
    except Exception as e:
        return f"exit 0 with an unreadable summary.json ({e})"
    if s.get("error") is not None:
        return "exit 0 with an error in summary.json"
    if not finite_json({k: v for k, v in s.items() if k not in ("error", "signal")}):  # null: none
        return "exit 0 with a non-finite value in summary.json"
    with open(os.path.join(out, "states.csv"), "rb") as f:
        data = f.read()
    if not data.endswith(b"\n"):
        return "exit 0 with states.csv cut mid-row"
    return None


def check_solve(path, timeout):
    p, why = run([SOLVE, path], timeout, 1)
    if p is None:
        return why
    try:
        v = json.loads(p.stdout)
    except Exception as e:
        return f"exit 0 with stdout that is not JSON ({e})"
    if not finite_json(v):
        return "exit 0 with a non-finite value (null) in the output"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="time budget (s)")
    ap.add_argument("--count", type=int, default=100000, help="most cases")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=30.0, help="a case hangs after this (s)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out/fuzz"))
    a = ap.parse_args()
    if not (a.seconds > 0 and a.count > 0 and a.timeout > 0):
        ap.error("--seconds, --count and --timeout must be > 0")
    for b in (SCENE, SOLVE):
        if not os.access(b, os.X_OK):
            sys.exit(f"fuzz.py: {b} not built (run tools/setup.sh --no-demo)")
    os.makedirs(a.out, exist_ok=True)
    rng = random.Random(a.seed)
    t0 = time.monotonic()
    passed = failed = 0
    k = 0
    while k < a.count and time.monotonic() - t0 < a.seconds:
        scene = k % 2 == 0
        src = rng.choice(SCENES if scene else CASES)
        data = mutate(open(src).read(), rng)
        case = os.path.join(a.out, "case.json")
        with open(case, "wb") as f:
            f.write(data)
        why = check_scene(case, os.path.join(a.out, "run"), a.timeout) if scene else \
            check_solve(case, a.timeout)
        if why:
            failed += 1
            keep = os.path.join(a.out, f"fail_{k}_{'scene' if scene else 'magsolve'}.json")
            shutil.copy(case, keep)
            print(f"FAIL {keep}: {why}", flush=True)
        else:
            passed += 1
        k += 1
    print(f"fuzz: {k} cases in {time.monotonic() - t0:.0f} s (seed {a.seed}); exit 0 and checked: "
          f"{EXIT0[0]} scene runs, {EXIT0[1]} magsolve runs")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
