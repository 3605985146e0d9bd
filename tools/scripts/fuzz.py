#!/usr/bin/env python3
"""tools/scripts/fuzz.py — mutates the example scene files and magsolve cases and runs the tools on
them, bounded in count and time, with the hostile-input families.

    python3 tools/scripts/fuzz.py [--seconds 60] [--count 100000] [--seed 1] [--out out/fuzz]
                          [--bin build/release/tools]

A case fails on: a signal death (crash, abort), a hang (over --timeout s), an exit code
outside the contract (0, 1, 2, 3; 128 + the signal for a stop signal sent mid-run), exit 2
without "error" in summary.json, or exit 0 with output that is not complete and finite:
magsim-scene's summary.json missing, invalid or holding an error or a non-finite number;
magsolve's stdout not valid JSON or holding a non-finite number (JSON null). After every
case, every *.csv in its output folder must hold whole rows: each row the header's field
count, the file ending with a line break.

One case in four (from the fifth on) is one of the hostile-input families, in turn: a stop
signal mid-run (SIGINT, SIGTERM, SIGHUP: exit 128 + signal, summary.json "interrupted");
a closed pipe (magsolve: exit 3; magsim-scene: not killed); deep nesting (refused beyond 64
levels); large --count (refused up front under a 1 GiB address-space limit); non-regular
files (FIFO, device, directory: exit 1 at once); two concurrent runs into one folder (one
refused, exit 1, or both done; never mixed); flag/file round trips (a flag's value and the
same value in a scene file accepted or refused alike; a summary's options rerun to the same
state hash). Failing inputs are kept in OUT/fail_*; the exit code is 1 when any case failed,
else 0. Prints a closing line 'N passed, M failed'.
"""
import argparse, csv, io, json, math, os, random, re, resource, shutil, signal, stat, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "build/release/tools/magsim-scene")  # --bin sets both
SOLVE = os.path.join(ROOT, "build/release/tools/magsolve")
TWO_BALLS = os.path.join(ROOT, "scenes/examples/two_balls.json")
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


def whole_rows(folder):
    """None when every *.csv in folder holds whole rows (the header's field count, RFC 4180
    quoting, a final line break), else what is wrong."""
    if not os.path.isdir(folder):
        return None
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".csv"):
            continue
        path = os.path.join(folder, name)
        if not os.path.isfile(path):
            continue
        with open(path, "rb") as f:
            data = f.read()
        if not data:
            continue  # created, nothing written yet (a run refused or stopped at once)
        if not data.endswith(b"\n"):
            return f"{name} does not end with a line break (a row cut in half)"
        rows = list(csv.reader(io.StringIO(data.decode("utf-8", "replace"), newline="")))
        width = len(rows[0])
        for i, row in enumerate(rows[1:], 2):
            if len(row) != width:
                return f"{name} row {i} has {len(row)} fields, the header {width}"
    return None


def summary_of(folder):
    try:
        with open(os.path.join(folder, "summary.json")) as f:
            return json.load(f)
    except Exception:
        return None


def contract(code, folder=None, allowed=(0, 1, 2, 3)):
    """None when an exit code keeps the contract (and exit 2 left its error in summary.json)."""
    if code < 0:
        return f"killed by signal {-code}"
    if code not in allowed:
        return f"exit {code}, not one of {sorted(allowed)}"
    if code == 2 and folder is not None:
        s = summary_of(folder)
        if s is None or not s.get("error"):
            return "exit 2 without \"error\" in summary.json"
    return None


def run(cmd, timeout, which):
    """(process, None) when cmd exited 0; (None, reason) on a hang or a signal; (None, None)
    on a clean non-zero exit (a refusal, which is what bad input should get)."""
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "hang"
    if p.returncode < 0:
        return None, f"signal {-p.returncode}"
    if p.returncode not in (0, 1, 2, 3):
        return None, f"exit {p.returncode}, outside the contract"
    EXIT0[which] += p.returncode == 0
    return (p, None) if p.returncode == 0 else (None, p.returncode)


def check_scene(path, out, timeout):
    shutil.rmtree(out, ignore_errors=True)
    p, why = run([SCENE, path, "--steps", "30", "--no-render", "--threads", "1", "--out", out],
                 timeout, 0)
    if p is None:
        if why == 2:
            return contract(2, out)
        return None if isinstance(why, int) else why
    try:
        s = json.load(open(os.path.join(out, "summary.json")))
    except Exception as e:
        return f"exit 0 with an unreadable summary.json ({e})"
    if s.get("error") is not None:
        return "exit 0 with an error in summary.json"
    # null: none (error, signal) or no --gltf file (gltf)
    if not finite_json({k: v for k, v in s.items() if k not in ("error", "signal", "gltf")}):
        return "exit 0 with a non-finite value in summary.json"
    with open(os.path.join(out, "states.csv"), "rb") as f:
        data = f.read()
    if not data.endswith(b"\n"):
        return "exit 0 with states.csv cut mid-row"
    return None


def check_solve(path, timeout):
    p, why = run([SOLVE, path], timeout, 1)
    if p is None:
        return None if isinstance(why, int) else why
    try:
        v = json.loads(p.stdout)
    except Exception as e:
        return f"exit 0 with stdout that is not JSON ({e})"
    if not finite_json(v):
        return "exit 0 with a non-finite value (null) in the output"
    return None


# ---- the hostile-input families -------------------------------------------------------------

STOP_SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]
AS_LIMIT = 1 << 30  # bytes of address space for the cases that must stay small


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (AS_LIMIT, AS_LIMIT))


def finish(p, timeout):
    """p's exit code, or None after killing it on a hang."""
    try:
        return p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
        return None


def default_stop_signals():
    """In the child: the stop signals at their default action. magsim-scene keeps a signal
    that its caller ignores ignored (nohup), so without this the family would test how the
    fuzz itself was started."""
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_DFL)


def fam_signal(rng, out, timeout):
    """A stop signal mid-run: exit 128 + signal, summary.json interrupted, whole CSV rows."""
    sig = rng.choice(STOP_SIGNALS)
    states = os.path.join(out, "states.csv")
    p = subprocess.Popen([SCENE, "balls_up", "--count", str(rng.randint(3, 60)), "--steps", "100000",
                          "--fps", "1000", "--no-render", "--threads", "1", "--out", out],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         preexec_fn=default_stop_signals)
    want, t0, started = rng.randint(1, 300000), time.monotonic(), False
    while time.monotonic() - t0 < 10 and p.poll() is None:
        try:
            started = os.path.getsize(states) > 0
            if os.path.getsize(states) >= want:
                break
        except OSError:
            pass
        time.sleep(0.002)
    p.send_signal(sig)
    code = finish(p, timeout)
    if code is None:
        return f"hang after {sig.name}"
    if code == -sig and not started:
        return None  # before the output folder was set up: the default action (PROGRAMS.md)
    if code != 128 + sig:
        return contract(code, out) or f"{sig.name} mid-run: exit {code}, not {128 + sig}"
    s = summary_of(out)
    if s is None or s.get("interrupted") is not True or s.get("signal") != sig.name:
        return f"{sig.name} mid-run: summary.json missing or not marked interrupted"
    return None


def fam_closed_pipe(rng, out, timeout):
    """stdout (magsolve) or stderr (magsim-scene) on a pipe whose reader is gone."""
    r, w = os.pipe()
    os.close(r)
    if rng.random() < 0.5:
        p = subprocess.Popen([SOLVE, rng.choice(CASES)], stdout=w, stderr=subprocess.DEVNULL)
        os.close(w)
        code = finish(p, timeout)
        if code is None:
            return "hang on a closed pipe"
        return contract(code) or (None if code == 3 else f"magsolve into a closed pipe: exit {code}, not 3")
    p = subprocess.Popen([SCENE, "balls_up", "--count", str(rng.randint(1, 30)), "--steps", str(rng.randint(1, 200)),
                          "--no-render", "--threads", "1", "--out", out], stdout=w, stderr=w)
    os.close(w)
    code = finish(p, timeout)
    if code is None:
        return "hang on a closed pipe"
    return contract(code, out)


def fam_deep(rng, out, timeout):
    """Nesting around the limit of 64 levels, or far beyond it."""
    depth = rng.choice([62, 63, 64, 65, rng.randint(66, 300000)])
    if rng.random() < 0.5:
        nested = "[" * depth + "]" * depth
    else:
        nested = '{"a": ' * depth + "1" + "}" * depth
    solver = rng.random() < 0.5
    text = ('{"moments": ' if solver else '{"bodies": [], "comment": ') + nested + "}"
    case = os.path.join(os.path.dirname(out), "deep.json")
    with open(case, "w") as f:
        f.write(text)
    cmd = [SOLVE, case] if solver else [SCENE, case, "--steps", "1", "--no-render", "--out", out]
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout, preexec_fn=limit_memory)
    except subprocess.TimeoutExpired:
        return f"hang at depth {depth}"
    why = contract(p.returncode, None if solver else out)
    if why:
        return f"depth {depth}: {why}"
    if depth + 1 > 64 and (p.returncode != 1 or b"nested deeper than 64 levels" not in p.stderr):
        return f"depth {depth + 1}: exit {p.returncode}, not refused as too deep"
    return None


def fam_large_count(rng, out, timeout):
    """--count from 1e5 to 1e9 under a 1 GiB address-space limit: refused up front."""
    count = int(10 ** rng.uniform(5, 9))
    name = rng.choice(["balls_up", "alphabets", "falling_magnet", "sakura_tree", "crystal_balls"])
    extra = ["--write-scene", os.path.join(os.path.dirname(out), "large.json")] if rng.random() < 0.3 else \
        ["--steps", "1", "--no-render", "--out", out]
    try:
        p = subprocess.run([SCENE, name, "--count", str(count)] + extra, capture_output=True, timeout=timeout,
                           preexec_fn=limit_memory)
    except subprocess.TimeoutExpired:
        return f"{name} --count {count}: hang"
    why = contract(p.returncode, out)
    if why:
        return f"{name} --count {count}: {why}"
    if p.returncode != 1 or b"GB of memory" not in p.stderr or p.stderr.count(b"\n") != 1:
        return f"{name} --count {count}: exit {p.returncode}, not refused up front in one line"
    return None


def fam_non_regular(rng, out, timeout):
    """A FIFO, a device, a directory or a link to one as the input: exit 1 at once."""
    base = os.path.join(os.path.dirname(out), "nonregular.json")
    if os.path.islink(base) or os.path.isfile(base):
        os.remove(base)
    elif os.path.isdir(base):
        shutil.rmtree(base)
    elif os.path.exists(base):
        os.remove(base)
    kind = rng.choice(["fifo", "zero", "null", "dir", "dangling"])
    if kind == "fifo":
        os.mkfifo(base)
    elif kind == "dir":
        os.mkdir(base)
    elif kind == "dangling":
        os.symlink(base + ".nowhere", base)
    else:
        os.symlink("/dev/" + kind, base)
    solver = rng.random() < 0.5
    cmd = [SOLVE, base] if solver else [SCENE, base, "--steps", "1", "--no-render", "--out", out]
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout, preexec_fn=limit_memory)
    except subprocess.TimeoutExpired:
        return f"{kind}: hang"
    return contract(p.returncode) or (None if p.returncode == 1 else f"{kind}: exit {p.returncode}, not 1")


def fam_concurrent(rng, out, timeout):
    """Two runs into one folder: one refused (exit 1) while the other holds it, or both done
    one after the other; the folder holds one run's files, never a mix."""
    counts = [rng.randint(3, 20), rng.randint(3, 20)]
    steps = [rng.randint(50, 400), rng.randint(50, 400)]
    ps = [subprocess.Popen([SCENE, "balls_up", "--count", str(counts[i]), "--steps", str(steps[i]), "--no-render",
                            "--threads", "1", "--out", out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
          for i in range(2)]
    codes = [finish(p, timeout) for p in ps]
    errs = [p.stderr.read() for p in ps]
    if None in codes:
        return "hang with two runs in one folder"
    for c in codes:
        why = contract(c, out)
        if why:
            return why
    if 0 not in codes and 2 not in codes:
        return f"two runs into one folder: exits {codes}, neither ran"
    for c, e in zip(codes, errs):
        if c == 1 and b"another run is writing into this folder" not in e:
            return "the refused run does not say why"
    s = summary_of(out)
    if s is None:
        return "no summary.json after two runs"
    with open(os.path.join(out, "states.csv")) as f:
        rows = sum(1 for _ in f) - 1
    if rows != s["frames"] * s["bodies"]:
        return f"mixed outputs: states.csv has {rows} rows, summary.json {s['frames']} frames of {s['bodies']} bodies"
    return None


def option_table():
    """The number options that have a flag: (key, flag, integer, lo, hi, lo_open, hi_open), from
    the table of options as magsim-scene --options-json prints it (engine/options_table.cpp)."""
    p = subprocess.run([SCENE, "--options-json"], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        sys.exit(f"fuzz.py: {SCENE} --options-json: exit {p.returncode}: {p.stderr.strip()}")
    rows = []
    for o in json.loads(p.stdout):
        if o["kind"] in ("number", "integer") and o["flag"]:
            r = o["range"]
            rows.append((o["key"], o["flag"], r["integer"], float(r["lo"]), float(r["hi"]), r["lo_open"], r["hi_open"]))
    return rows


OPTIONS = []


def fam_round_trip(rng, out, timeout):
    """A flag's value and the same value in a scene file: accepted or refused alike; what
    the flag accepts, --write-scene writes and the file takes back; a summary's options rerun
    as a scene file give the same state hash."""
    key, flag, integer, lo, hi, lo_open, hi_open = rng.choice(OPTIONS)
    big = sys.float_info.max
    if integer:
        v = rng.choice([lo, hi, lo - 1, hi + 1, rng.randint(int(lo), int(min(hi, 1e6)))])
    else:
        v = rng.choice([lo, math.nextafter(lo, -big), math.nextafter(lo, big), 10 ** rng.uniform(-12, 3)] +
                       ([hi, math.nextafter(hi, -big), math.nextafter(hi, big)] if hi < big else []))
    text = str(int(v)) if integer else repr(float(v))
    d = os.path.dirname(out)
    base, written, infile, back = (os.path.join(d, n) for n in ("rt_base.json", "rt_flag.json", "rt_file.json",
                                                               "rt_back.json"))
    def scene(args):
        try:
            return subprocess.run([SCENE] + args, capture_output=True, timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            return None
    if scene([TWO_BALLS, "--write-scene", base]) != 0:
        return "two_balls --write-scene failed"
    by_flag = scene([TWO_BALLS, flag, text, "--write-scene", written])
    j = json.load(open(base))
    at = j["options"]
    *heads, key_leaf = key.split(".")  # "magnetics.field.bh_theta": down the objects
    for head in heads:
        at = at.setdefault(head, {})
    at[key_leaf] = int(v) if integer else float(v)
    with open(infile, "w") as f:
        json.dump(j, f)
    by_file = scene([infile, "--write-scene", back])
    if by_flag is None or by_file is None:
        return f"{flag} {text}: hang"
    if by_flag not in (0, 1) or by_file != by_flag:
        return f"{flag} {text}: the flag gives exit {by_flag}, options.{key} in a scene file exit {by_file}"
    if by_flag == 0 and scene([written, "--write-scene", back]) != 0:
        return f"{flag} {text}: the scene file --write-scene wrote is refused"
    # a short run with it, its summary's options pasted into a scene file, run again
    if by_flag != 0 or (integer and v > 1000 and key != "magnetics.field.auto_threshold") or rng.random() < 0.5:
        return None
    runs = [os.path.join(d, "rt_run1"), os.path.join(d, "rt_run2")]
    for r in runs:
        shutil.rmtree(r, ignore_errors=True)
    c1 = scene([TWO_BALLS, flag, text, "--steps", "20", "--no-render", "--threads", "1", "--out", runs[0]])
    if c1 is None or contract(c1, runs[0]):
        return f"{flag} {text}: run: {'hang' if c1 is None else contract(c1, runs[0])}"
    s1 = summary_of(runs[0])
    if c1 not in (0, 2) or s1 is None:
        return None if c1 in (1, 3) else f"{flag} {text}: run exit {c1}"
    j = json.load(open(base))
    j["options"] = s1["options"]
    with open(infile, "w") as f:
        json.dump(j, f)
    c2 = scene([infile, "--steps", "20", "--no-render", "--threads", "1", "--out", runs[1]])
    s2 = summary_of(runs[1])
    if c2 != c1 or s2 is None or s2.get("state_hash") != s1.get("state_hash"):
        return f"{flag} {text}: summary.json's options rerun as a scene file: exit {c2} (first {c1}), state hash " \
               f"{s2 and s2.get('state_hash')} (first {s1.get('state_hash')})"
    for r in runs:
        why = whole_rows(r)
        if why:
            return why
    return None


FAMILIES = [fam_signal, fam_closed_pipe, fam_deep, fam_large_count, fam_non_regular, fam_concurrent, fam_round_trip]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="time budget (s)")
    ap.add_argument("--count", type=int, default=100000, help="most cases")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=30.0, help="a case hangs after this (s)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out/fuzz"))
    ap.add_argument("--bin", default=os.path.join(ROOT, "build/release/tools"),
                    help="the folder of magsim-scene and magsolve")
    a = ap.parse_args()
    global SCENE, SOLVE
    SCENE, SOLVE = os.path.join(a.bin, "magsim-scene"), os.path.join(a.bin, "magsolve")
    if not (a.seconds > 0 and a.count > 0 and a.timeout > 0):
        ap.error("--seconds, --count and --timeout must be > 0")
    for b in (SCENE, SOLVE):
        if not os.access(b, os.X_OK):
            sys.exit(f"fuzz.py: {b} not built (run tools/scripts/setup.sh --no-demo)")
    OPTIONS.extend(option_table())
    if not OPTIONS:
        sys.exit("fuzz.py: no number options with a flag in magsim-scene --options-json")
    os.makedirs(a.out, exist_ok=True)
    rng = random.Random(a.seed)
    t0 = time.monotonic()
    passed = failed = 0
    per_family = {f.__name__[4:]: 0 for f in FAMILIES}
    k = 0
    run_dir = os.path.join(a.out, "run")
    while k < a.count and time.monotonic() - t0 < a.seconds:
        shutil.rmtree(run_dir, ignore_errors=True)
        case = os.path.join(a.out, "case.json")
        if k >= 4 and k % 4 == 3:  # a hostile-input family, in turn
            family = FAMILIES[(k // 4) % len(FAMILIES)]
            name = family.__name__[4:]
            per_family[name] += 1
            with open(case, "w") as f:
                f.write(f"{name} (seed {a.seed}, case {k})\n")
            why = family(rng, run_dir, a.timeout)
        else:
            scene = k % 2 == 0
            name = "scene" if scene else "magsolve"
            src = rng.choice(SCENES if scene else CASES)
            data = mutate(open(src).read(), rng)
            with open(case, "wb") as f:
                f.write(data)
            why = check_scene(case, run_dir, a.timeout) if scene else check_solve(case, a.timeout)
        why = why or whole_rows(run_dir)  # never a CSV row cut in half, whatever the case
        if why:
            failed += 1
            keep = os.path.join(a.out, f"fail_{k}_{name}.json")
            shutil.copy(case, keep)
            print(f"FAIL {keep}: {why}", flush=True)
        else:
            passed += 1
        k += 1
    print(f"fuzz: {k} cases in {time.monotonic() - t0:.0f} s (seed {a.seed}); exit 0 and checked: "
          f"{EXIT0[0]} scene runs, {EXIT0[1]} magsolve runs; families: " +
          ", ".join(f"{n} {c}" for n, c in per_family.items()))
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
