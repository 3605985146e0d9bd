#!/usr/bin/python3
"""tools/scripts/ensemble.py — one scene, several perturbed runs: the spread of its outcome.

A single run of a strongly magnetized pile is chaotic: removing one ball of 1032 can change
how many of falling_magnet's balls are thrown off several times over (tools/findings/
falling_magnet.md). This runs the scene N times with --count BASE, BASE-1, ..., BASE-N+1 (one body fewer each time) and
reports per run and over the runs: escaped (beyond the scene's escape_radius, summary.json
"final"), held, "held_fastest_last_half" (the fastest of the held bodies over the last 0.5 s,
from summary.json's series held_max_speed: the lifted pile without the balls on the floor), the
fastest body at the end and in the last second, and the error if the
run failed. From states.csv (recorded at --fps 20 unless the flags say otherwise), as
frame-to-frame displacement over the frame time, of the pieces (bodies named ball_* or
letter_*): "fastest_last_half", the fastest over the last 0.5 s, and "heap", the fastest of
those within 0.12 m of a magnet body over the last 0.5 s; "fastest_body", "fastest_at" and
"fastest_from_magnet" name the piece that sets fastest_last_half, the time of the frame where
it was that fast (s) and its distance from the nearest magnet body then (m; empty without
one). From summary.json's series, of
E = K + U_g + U* from 0.05 s on: "energy_rise", the most E ever stood above its running
minimum (J), "energy_lost", E(0.05 s) - E(end) (J), and "rise_per_lost" their ratio.

usage: /usr/bin/python3 tools/scripts/ensemble.py SCENE [--runs N] [--seconds S] [--base-count C]
                                                  [--out DIR] [--label L] [--jobs J]
                                                  [-- MAGSIM_SCENE_FLAGS...]
  SCENE          a registry scene (balls_up, alphabets, falling_magnet, sakura_tree)
  --runs N       runs (default 6), N >= 1
  --seconds S    simulated seconds per run (default: 0.6)
  --base-count C the count of the first run (default: the scene's own count)
  --out DIR      output directory (default out/ensemble/SCENE[_L])
  --label L      a name for this configuration, in the output and DIR
  --jobs J       runs at a time (default 1), each with --threads 1 unless the flags say
  flags after -- go to every magsim-scene run (e.g. -- --force-model classic --threads 1)
The program run is build/release/tools/magsim-scene, or $MAGSIM_SCENE_BIN when set.
Writes DIR/run_<count>/ (each run's summary.json, states.csv), DIR/ensemble.csv (a row per
run) and DIR/ensemble.json (the rows and min/median/mean/max of each figure). Exit 0 when
every run finished, 1 when a run failed (its row says why), 2 on bad usage.
"""
import json
import math
import os
import statistics
import subprocess
import sys

DEFAULT_COUNT = {"balls_up": 243, "alphabets": 100, "falling_magnet": 1032, "sakura_tree": 2500}
FIGURES = ["escaped", "held", "held_fastest_last_half", "max_speed_end", "max_speed_last_second", "fastest_last_half", "heap",
           "energy_rise", "energy_lost", "rise_per_lost", "guard_retakes", "substeps_mean"]
# which piece sets fastest_last_half, when, and how far from a magnet: columns, not statistics
WHO = ["fastest_body", "fastest_at", "fastest_from_magnet"]
PIECE_PREFIXES = ("ball_", "letter_")
HEAP_RADIUS = 0.12  # (m) "the heap": pieces this close to a magnet body
LAST = 0.5          # (s) the window of fastest_last_half and heap
ENERGY_FROM = 0.05  # (s) the energy figures start here (the first steps solve from M = 0)


def usage_error(msg):
    print(f"ensemble.py: {msg} (try --help)", file=sys.stderr)
    sys.exit(2)


def parse(argv):
    if "-h" in argv[:1] or "--help" in argv[:1]:
        print(__doc__.strip())
        sys.exit(0)
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    opts = {"runs": 6, "seconds": 0.6, "base_count": None, "out": None, "label": None, "jobs": 1}
    pos = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--runs", "--seconds", "--base-count", "--out", "--label", "--jobs"):
            if i + 1 >= len(argv):
                usage_error(f"{a} needs a value")
            v = argv[i + 1]
            key = a[2:].replace("-", "_")
            try:
                if key in ("runs", "base_count", "jobs"):
                    opts[key] = int(v)
                elif key == "seconds":
                    opts[key] = float(v)
                else:
                    opts[key] = v
            except ValueError:
                usage_error(f"{a}: not a number: '{v}'")
            i += 2
        elif a.startswith("-"):
            usage_error(f"unknown option '{a}'")
        else:
            pos.append(a)
            i += 1
    if len(pos) != 1:
        usage_error("expected one scene name")
    scene = pos[0]
    if opts["base_count"] is None:
        if scene not in DEFAULT_COUNT:
            usage_error(f"no default count for '{scene}': give --base-count")
        opts["base_count"] = DEFAULT_COUNT[scene]
    if opts["runs"] < 1 or opts["base_count"] - opts["runs"] + 1 < 1:
        usage_error("--runs must be >= 1 and leave every run at least one body")
    if opts["jobs"] < 1:
        usage_error("--jobs must be >= 1")
    if not (opts["seconds"] > 0 and math.isfinite(opts["seconds"])):
        usage_error("--seconds must be positive")
    if opts["out"] is None:
        opts["out"] = os.path.join("out", "ensemble", scene + (f"_{opts['label']}" if opts["label"] else ""))
    return scene, opts, extra


def states_figures(path, magnets_hint=("magnet", "tip_magnet", "centre")):
    """fastest_last_half and heap from states.csv (see the module's doc), and a dict of WHO
    (the piece that sets fastest_last_half); None, None and WHO all None without frames."""
    frames = {}
    try:
        with open(path) as f:
            f.readline()
            for line in f:
                # frame,time,body,name,x,y,z,...; a name with a comma is quoted: split from both ends
                head = line.split(",", 3)
                tail = head[3].rsplit(",", 7)
                fr, t, name = int(head[0]), float(head[1]), tail[0].strip('"')
                p = (float(tail[1]), float(tail[2]), float(tail[3]))
                frames.setdefault(fr, (t, {}))[1][name] = p
    except (OSError, ValueError, IndexError):
        return None, None, dict.fromkeys(WHO)
    order = sorted(frames)
    if len(order) < 2:
        return None, None, dict.fromkeys(WHO)
    t_end = frames[order[-1]][0]
    fastest = heap = 0.0
    who = {k: None for k in WHO}
    for a, b in zip(order, order[1:]):
        ta, pa = frames[a]
        tb, pb = frames[b]
        if tb < t_end - LAST - 1e-9 or tb <= ta:
            continue
        magnets = [p for n, p in pb.items() if n.startswith(magnets_hint)]
        for n, q in pb.items():
            if not n.startswith(PIECE_PREFIXES) or n not in pa:
                continue
            v = math.dist(q, pa[n]) / (tb - ta)
            d = min(math.dist(q, m) for m in magnets) if magnets else None
            if v > fastest:
                fastest = v
                who = {"fastest_body": n, "fastest_at": tb, "fastest_from_magnet": d}
            if d is not None and d <= HEAP_RADIUS:
                heap = max(heap, v)
    return fastest, heap, who


def energy_figures(ser):
    """energy_rise, energy_lost, rise_per_lost from the series of E = K + U_g + U*."""
    E = [e for t, e in zip(ser.get("time", []), ser.get("energy_total", [])) if t >= ENERGY_FROM - 1e-12]
    if len(E) < 2:
        return None, None, None
    low, rise = E[0], 0.0
    for e in E:
        low = min(low, e)
        rise = max(rise, e - low)
    lost = E[0] - E[-1]
    return rise, lost, (rise / lost if lost > 0 else None)


def row_of(count, summary_path, rc, log):
    row = {"count": count, "exit": rc, "error": None}
    try:
        s = json.load(open(summary_path))
    except (OSError, ValueError) as e:
        row["error"] = f"no summary.json ({e}); {log.strip().splitlines()[-1] if log.strip() else ''}"
        for f in FIGURES + WHO:
            row[f] = None
        return row
    fin = s["final"]
    ser = s["series"]
    t_end = ser["time"][-1] if ser["time"] else 0.0
    last = [v for t, v in zip(ser["time"], ser["max_speed"]) if t >= t_end - 1.0 and v is not None]
    lifted = [v for t, v in zip(ser["time"], ser.get("held_max_speed", [])) if t >= t_end - LAST - 1e-9
              and v is not None]
    fastest, heap, who = states_figures(os.path.join(os.path.dirname(summary_path), "states.csv"))
    rise, lost, ratio = energy_figures(ser)
    sub = s.get("substeps", {})
    row.update({
        "fastest_last_half": fastest,
        "heap": heap,
        "energy_rise": rise,
        "energy_lost": lost,
        "rise_per_lost": ratio,
        "guard_retakes": s.get("energy", {}).get("guard", {}).get("retakes"),
        "substeps_mean": sub.get("mean"),
        "escaped": fin.get("escaped"),
        "held": fin.get("held"),
        "held_fastest_last_half": max(lifted) if lifted else None,
        "max_speed_end": fin.get("max_speed"),
        "max_speed_last_second": max(last) if last else None,
        "error": s.get("error"),
    })
    row.update(who)
    return row


def who_text(r):
    """' (ball_7 at 1.95 s, 0.085 m from a magnet)' for a row, '' when no piece moved."""
    if not r.get("fastest_body"):
        return ""
    d = r["fastest_from_magnet"]
    return f" ({r['fastest_body']} at {r['fastest_at']:.2f} s" + (f", {d:.3f} m from a magnet)" if d is not None else ")")


def stats(values):
    v = [x for x in values if x is not None]
    if not v:
        return None
    return {"min": min(v), "median": statistics.median(v), "mean": statistics.fmean(v), "max": max(v)}


def main():
    scene, opts, extra = parse(sys.argv[1:])
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    binary = os.environ.get("MAGSIM_SCENE_BIN") or os.path.join(root, "build", "release", "tools", "magsim-scene")
    if not os.access(binary, os.X_OK):
        print(f"ensemble.py: {binary} not built (run tools/scripts/setup.sh --no-demo)", file=sys.stderr)
        return 1
    os.makedirs(opts["out"], exist_ok=True)
    rows = []
    flags = list(extra)
    if "--fps" not in flags:
        flags += ["--fps", "20"]
    if opts["jobs"] > 1 and "--threads" not in flags:
        flags += ["--threads", "1"]
    counts = [opts["base_count"] - k for k in range(opts["runs"])]
    running = []  # (count, dir, process, log file)
    done = {}

    def finish(item):
        count, d, p, log = item
        p.wait()
        log.seek(0)
        text = log.read()
        log.close()
        if p.returncode == 1:  # bad usage or scene: every run would fail the same way
            print(f"ensemble.py: magsim-scene refused the run:\n{text.strip()}", file=sys.stderr)
            sys.exit(2)
        r = row_of(count, os.path.join(d, "summary.json"), p.returncode, text)
        done[count] = r
        print(f"run (count {count}): escaped {r['escaped']}, held {r['held']}, fastest over the last "
              f"{LAST} s {r['fastest_last_half']} m/s{who_text(r)}, heap {r['heap']} m/s, energy rise {r['energy_rise']} J "
              f"of {r['energy_lost']} J lost" + (f", error: {r['error']}" if r["error"] else ""), flush=True)

    import tempfile
    for count in counts:
        d = os.path.join(opts["out"], f"run_{count}")
        cmd = [binary, scene, "--count", str(count), "--seconds", str(opts["seconds"]),
               "--no-render", "--out", d] + flags
        log = tempfile.TemporaryFile(mode="w+")
        running.append((count, d, subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, text=True), log))
        while len(running) >= opts["jobs"]:
            finish(running.pop(0))
    while running:
        finish(running.pop(0))
    rows = [done[c] for c in counts]
    with open(os.path.join(opts["out"], "ensemble.csv"), "w") as f:
        cols = ["count", "exit"] + FIGURES + WHO + ["error"]
        f.write(",".join(cols) + "\n")
        for r in rows:
            f.write(",".join("" if r[c] is None else json.dumps(r[c]) if c in ("error", "fastest_body") else str(r[c])
                             for c in cols) + "\n")
    summary = {"scene": scene, "label": opts["label"], "seconds": opts["seconds"], "runs": rows,
               "flags": flags, "stats": {f: stats([r[f] for r in rows]) for f in FIGURES},
               "failed": sum(1 for r in rows if r["error"] or r["exit"] != 0)}
    with open(os.path.join(opts["out"], "ensemble.json"), "w") as f:
        json.dump(summary, f, indent=1)
    e = summary["stats"]["escaped"]
    if e:
        print(f"{scene}{' ' + opts['label'] if opts['label'] else ''}: escaped per run "
              f"{[r['escaped'] for r in rows]}, mean {e['mean']:.1f}, median {e['median']}, "
              f"range {e['min']}-{e['max']}; {summary['failed']} failed; {opts['out']}/ensemble.json")
    return 1 if summary["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
