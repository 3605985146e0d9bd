#!/usr/bin/env python3
"""Writes scenes/SCENE_FILE.md's option list from the table of options.

    /usr/bin/python3 tools/scripts/options_md.py [--bin DIR] [--check]

Reads `magsim-scene --options-json` (engine/options_table.cpp) and rewrites the table under
"| key | default | values | flag | meaning |" and the one under "| older key | key |": one row
per option in the table's order, its key, default, values and flag from the table. The
meaning column keeps the hand-written text of a row that exists; a new option gets its doc
and unit from the table. --check changes nothing and exits 1 when the file is not what it
would write (CTest runs it so, label tools). --bin names the folder of magsim-scene
(default build/release/tools).
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "../.."))
HEADER = "| key | default | values | flag | meaning |"
OLD_HEADER = "| older key | key |"


def cells(row):
    """The raw cells of a Markdown row ('\\|' is a cell's own bar)."""
    out, cell, i = [], "", 1
    while i < len(row):
        if row[i] == "\\" and row[i + 1:i + 2] == "|":
            cell += "\\|"
            i += 2
            continue
        if row[i] == "|":
            out.append(cell.strip())
            cell = ""
        else:
            cell += row[i]
        i += 1
    return out


def block(lines, header):
    """(first, end) line indices of the rows under `header` (after its |---| line)."""
    start = lines.index(header) + 2
    end = start
    while end < len(lines) and lines[end].startswith("|"):
        end += 1
    return start, end


def values_md(o):
    if o["kind"] == "name":
        return ", ".join(f"`{v}`" for v in o["values"].split(", "))
    return o["values"]


def render(text, table):
    lines = text.split("\n")
    start, end = block(lines, HEADER)
    meaning = {}
    for row in lines[start:end]:
        c = cells(row)
        meaning[c[0].strip("`")] = c[4]
    rows = []
    for o in table:
        doc = meaning.get(o["key"]) or (o["doc"] + (f" ({o['unit']})" if o["unit"] else "")).replace("|", "\\|")
        flag = f"`{o['flag']}`" if o["flag"] else ""
        rows.append(f"| `{o['key']}` | `{o['default_text']}` | {values_md(o)} | {flag} | {doc} |")
    lines[start:end] = rows
    start, end = block(lines, OLD_HEADER)
    lines[start:end] = [f"| `{o['old_key']}` | `{o['key']}` |" for o in table if o["old_key"]]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build/release/tools"))
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    p = subprocess.run([os.path.join(a.bin, "magsim-scene"), "--options-json"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"options_md.py: magsim-scene --options-json: exit {p.returncode}: {p.stderr.strip()}")
    path = os.path.join(ROOT, "scenes/SCENE_FILE.md")
    text = open(path, encoding="utf-8").read()
    new = render(text, json.loads(p.stdout))
    if a.check:
        if new != text:
            old, now = text.split("\n"), new.split("\n")
            diff = [f"- {x}\n+ {y}" for x, y in zip(old, now) if x != y][:5]
            print("scenes/SCENE_FILE.md's options are not the table's; run tools/scripts/options_md.py:\n" +
                  "\n".join(diff), file=sys.stderr)
            return 1
        return 0
    if new != text:
        with open(path, "w", encoding="utf-8") as f:
            f.write(new)
        print("options_md.py: scenes/SCENE_FILE.md rewritten", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
