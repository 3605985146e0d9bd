#!/usr/bin/env python3
"""tools/scripts/house_check.py — the house rules that a script can check, in well under a second:

    python3 tools/scripts/house_check.py [ROOT] [--exclude DIR ...]
    python3 tools/scripts/house_check.py --self-test

Prints one line per finding, FILE:LINE: what is wrong, and exits 1 when there is any:

  * a .cpp, .hpp or .py file under engine/ magnetics/ render/ scenes/ tests/ tools/ longer
    than 600 lines: split it along its topics, so that a newcomer can read a file as a unit;
  * any text file that points into a sibling checkout (a relative path climbing out of the
    repository into "shared"), or refers to an issue or pull request by its number: a
    reader of this repository can open neither. Cite a file in it instead, such as
    magnetics/PHYSICS.md or tools/findings/*.md;
  * a kernel file of magnetics/ that includes, directly or through other headers, the
    header of the module that dispatches to it (LAYERS: the direct sum and Barnes-Hut below
    fields.hpp, Anderson below magnetization.hpp, ZeemanTotal below forces.hpp): a driver
    sits above its kernels, so that a kernel can be read, tested and changed on its own.

An issue reference is the word issue followed by a number (with or without a hash), or a
hash and a number standing as a word of its own (after a space, bracket or line start).
Hex colours, C preprocessor lines, shell comments, HTML entities and commit hashes do not
look like that. Skipped: .git, out/, build directories (build, build-*, build_*), every
--exclude directory and binary files (a NUL byte in the first 8 KiB). ROOT defaults to the
repository holding this script. --self-test checks the patterns on examples, and the include
rule on a small tree, and exits 0 when they all behave. Exit 2: bad usage or a failed self-test.
"""
import argparse
import fnmatch
import os
import re
import shutil
import sys
import tempfile

MAX_LINES = 600
SOURCE_DIRS = ("engine", "magnetics", "render", "scenes", "tests", "tools")
SOURCE_EXTS = (".cpp", ".hpp", ".py")
SKIP_DIR = re.compile(r"^(\.git|out|build|build[-_].*|__pycache__)$")

# (pattern, what the finding says); matched on each line of each text file
RULES = [
    (re.compile(r"\.\./shared"),
     "a path into a sibling checkout; cite a file in this repository"),
    (re.compile(r"\b(?:issue|pull request|PR)s?\s*(?:#|no\.?\s*|number\s*)?\d+\b", re.IGNORECASE),
     "an issue reference by number; cite a file in this repository"),
    (re.compile(r"(?:^|(?<=[\s(\[{,;]))#\d{1,5}\b"),
     "an issue reference by number; cite a file in this repository"),
]


# The include rule of magnetics/: (files, headers they must not reach through #include, why).
# Each header named sits above those files: the module that dispatches to them, or one that
# builds on them.
LAYERS = [
    (("magnetics/source_buffer.*", "magnetics/field_kernel.hpp", "magnetics/pair_kernel.cpp",
      "magnetics/simd*.hpp", "magnetics/dipole_field.*", "magnetics/barnes_hut*"),
     ("magnetics/fields.hpp",),
     "fields.hpp dispatches to the direct sum and to Barnes-Hut"),
    (("magnetics/source_buffer.*", "magnetics/field_kernel.hpp", "magnetics/pair_kernel.cpp",
      "magnetics/simd*.hpp"),
     ("magnetics/dipole_field.hpp",),
     "the pair kernel sits below the direct sum that calls it"),
    (("magnetics/anderson.*", "magnetics/magnetization_types.hpp"),
     ("magnetics/magnetization.hpp",),
     "magnetization.cpp dispatches to Anderson"),
    (("magnetics/magnetization_types.hpp",),
     ("magnetics/anderson.hpp",),
     "magnetization_types.hpp sits below Anderson and its dispatcher"),
    (("magnetics/forces_total.*", "magnetics/force_laws.*"),
     ("magnetics/forces.hpp",),
     "forces.cpp dispatches to ZeemanTotal"),
    (("magnetics/force_laws.*",),
     ("magnetics/forces_total.hpp",),
     "force_laws.hpp sits below both force modules"),
]
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def local_includes(root, rel):
    """(line number, path) of each quoted #include of rel that names a file under root."""
    try:
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except OSError:
        return []
    found = []
    for number, line in enumerate(lines, 1):
        m = INCLUDE.match(line)
        if m and os.path.isfile(os.path.join(root, m.group(1))):
            found.append((number, m.group(1)))
    return found


def include_chain(root, start, targets):
    """The include path from header start to one of targets (a list, start first), or None."""
    seen = {start}
    queue = [[start]]
    while queue:
        chain = queue.pop(0)
        if chain[-1] in targets:
            return chain
        for _, inc in local_includes(root, chain[-1]):
            if inc not in seen:
                seen.add(inc)
                queue.append(chain + [inc])
    return None


def check_layers(root):
    """Findings of LAYERS: a kernel file that reaches a forbidden header through #include."""
    folder = os.path.join(root, "magnetics")
    if not os.path.isdir(folder):
        return []
    findings = []
    for name in sorted(os.listdir(folder)):
        rel = "magnetics/" + name
        rules = [(bad, why) for patterns, bad, why in LAYERS
                 if any(fnmatch.fnmatchcase(rel, p) for p in patterns)]
        if not rules:
            continue
        for number, inc in local_includes(root, rel):
            for bad, why in rules:
                chain = include_chain(root, inc, bad)
                if chain:
                    via = " (through %s)" % ", ".join(chain[:-1]) if len(chain) > 1 else ""
                    findings.append("%s:%d: includes %s%s, the header above it: %s"
                                    % (rel, number, chain[-1], via, why))
    return findings


def find_on_line(line):
    """The message of the first rule that matches line, else None."""
    for pattern, message in RULES:
        m = pattern.search(line)
        if m:
            return "%s (%r)" % (message, m.group(0))
    return None


def count_lines(data):
    """Lines as `wc -l` counts them, plus an unterminated last line."""
    n = data.count(b"\n")
    return n + 1 if data and not data.endswith(b"\n") else n


def walk(root, excluded):
    """Every file under root, as a path relative to it, outside the skipped folders."""
    for top, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs
                         if not SKIP_DIR.match(d)
                         and os.path.realpath(os.path.join(top, d)) not in excluded)
        for name in sorted(files):
            yield os.path.relpath(os.path.join(top, name), root)


def check(root, excluded):
    findings = []
    for rel in walk(root, excluded):
        path = os.path.join(root, rel)
        if os.path.islink(path) or not os.path.isfile(path):
            continue
        with open(path, "rb") as f:
            data = f.read()
        if b"\0" in data[:8192]:
            continue
        parts = rel.split(os.sep)
        if parts[0] in SOURCE_DIRS and rel.endswith(SOURCE_EXTS):
            n = count_lines(data)
            if n > MAX_LINES:
                findings.append("%s:%d: %d lines, more than %d: split it by topic"
                                % (rel, MAX_LINES + 1, n, MAX_LINES))
        text = data.decode("utf-8", errors="replace")
        for number, line in enumerate(text.splitlines(), 1):
            message = find_on_line(line)
            if message:
                findings.append("%s:%d: %s" % (rel, number, message))
    return findings + check_layers(root)


def self_test():
    """The rules on lines that must and must not be flagged; True when all behave."""
    hash_ = "#"  # built up here so that this file does not flag itself
    flagged = [
        "// see issue " + hash_ + "12 for the numbers",
        "# fixed by issue " + "12",
        "the note in " + hash_ + "12's thread",
        "(a blow-up with exit 0 before " + hash_ + "13)",
        "Issue No. " + "7 says so",
        "as PR " + hash_ + "40 did",
        "[" + hash_ + "3] the first one",
        "include ../" + "shared/common.hpp",
    ]
    clean = [
        "# 1 thread per core",
        "#!/bin/sh",
        "#include <cmath>",
        "#define MAGSIM_X 1",
        "colour: " + hash_ + "ff8800, " + hash_ + "abc",
        "x" + hash_ + "12 is part of a word",
        "&" + hash_ + "8212; an HTML entity",
        "commit b5d8de6 (text only)",
        "reproduces the issue's six values",
        "issues like these are refused",
        "see tools/findings/energy.md and magnetics/PHYSICS.md",
        "a path ../scenes/examples/two_balls.json",
    ]
    ok = True
    for line in flagged:
        if not find_on_line(line):
            print("self-test: not flagged: %r" % line)
            ok = False
    for line in clean:
        message = find_on_line(line)
        if message:
            print("self-test: flagged: %r: %s" % (line, message))
            ok = False
    if not self_test_layers():
        ok = False
    counts = {b"": 0, b"a\n": 1, b"a\nb": 2, b"a\nb\n": 2}
    for data, want in counts.items():
        if count_lines(data) != want:
            print("self-test: count_lines(%r) = %d, want %d" % (data, count_lines(data), want))
            ok = False
    return ok


def self_test_layers():
    """check_layers on a small tree: the bad includes (one direct, one through a header) are
    flagged, the allowed ones not; True when it behaves."""
    tree = {
        "magnetics/fields.hpp": '#include "magnetics/dipole_field.hpp"\n',
        "magnetics/dipole_field.hpp": '#include "magnetics/source_buffer.hpp"\n',
        "magnetics/source_buffer.hpp": "",
        "magnetics/barnes_hut.cpp": '#include "magnetics/fields.hpp"\n',
        "magnetics/magnetization.hpp": '#include "magnetics/magnetization_types.hpp"\n',
        "magnetics/magnetization_types.hpp": '#include "magnetics/fields.hpp"\n',
        "magnetics/magnetization.cpp": '#include "magnetics/anderson.hpp"\n',
        "magnetics/anderson.hpp": '#include "magnetics/magnetization_types.hpp"\n',
        "magnetics/anderson.cpp": '#include "magnetics/anderson.hpp"\n'
                                  '#include "magnetics/forces.hpp"\n',
        "magnetics/forces.hpp": '#include "magnetics/magnetization.hpp"\n',
    }
    want = ["magnetics/anderson.cpp:2: includes magnetics/magnetization.hpp (through "
            "magnetics/forces.hpp)",
            "magnetics/barnes_hut.cpp:1: includes magnetics/fields.hpp,"]
    top = tempfile.mkdtemp(prefix="house_check_")
    try:
        for rel, text in tree.items():
            os.makedirs(os.path.join(top, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(top, rel), "w") as f:
                f.write(text)
        got = check_layers(top)
    finally:
        shutil.rmtree(top)
    ok = len(got) == len(want) and all(g.startswith(w) for g, w in zip(got, want))
    if not ok:
        print("self-test: layers found %r, want lines starting %r" % (got, want))
    return ok


def main():
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description="Checks the house rules (see the module docstring).")
    ap.add_argument("root", nargs="?", default=here)
    ap.add_argument("--exclude", action="append", default=[], metavar="DIR",
                    help="a folder to skip (such as an in-tree CMake build folder)")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        ok = self_test()
        print("house_check self-test: %s" % ("passed" if ok else "FAILED"))
        return 0 if ok else 2
    root = os.path.abspath(args.root)
    if not os.path.isdir(root):
        print("house_check: %s is not a folder" % root)
        return 2
    excluded = {os.path.realpath(d) for d in args.exclude}
    findings = check(root, excluded)
    for f in findings:
        print(f)
    print("house_check: %d finding%s in %s" % (len(findings), "" if len(findings) == 1 else "s", root))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
