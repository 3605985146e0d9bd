#!/usr/bin/env python3
"""tools/scripts/matrix_table.py DIR — a Markdown table of every DIR/<scene>_<method>/summary.json:
per-step medians of T_i, T_f, T_r (ms), magnetization iterations (median, cap hits), and the
final kinetic energy, maximum speed, bounding radius and attached count."""
import json
import pathlib
import sys

SCENES = ["balls_up", "alphabets", "falling_magnet", "sakura_tree", "crystal_balls"]
METHODS = ["ours-realigned", "ours", "kim2018", "damping-llg", "anderson"]


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) == 2 else 2
    root = pathlib.Path(sys.argv[1])
    rows = []
    for f in sorted(root.glob("*/summary.json")):
        s = json.loads(f.read_text())
        rows.append(s)
    key = lambda s: (SCENES.index(s["scene"]) if s["scene"] in SCENES else 99,
                     METHODS.index(s["method"]) if s["method"] in METHODS else 99)
    rows.sort(key=key)
    print("| scene | method | steps | T_i | T_f | T_r | iter. median | cap hits | final KE (J) | max speed (m/s) | bounding radius (m) | attached | render ms/frame | error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for s in rows:
        t, it, fin = s["timing_ms"], s["iterations"], s["final"]
        print(f"| {s['scene']} | {s['method']} | {s['steps']} | {t['T_i']['median']:.2f} | {t['T_f']['median']:.2f} | "
              f"{t['T_r']['median']:.2f} | {it['median']:.0f} | {it['cap_hits']} | {fin['kinetic_energy']:.3g} | "
              f"{fin['max_speed']:.3g} | {fin['bounding_radius']:.3g} | {fin['attached']} | "
              f"{s.get('render_ms_median', 0):.0f} | {s.get('error') or ''} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
