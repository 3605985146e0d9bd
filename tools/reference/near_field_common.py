"""tools/reference/near_field_common.py — what the near-field reference scripts share: the
magsolve argument and its check, the markdown table of a ratio per gap × field cell, and the
axial prototypes' central differences in the balls' positions."""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
MAGSOLVE = "build/release/tools/magsolve"


def add_magsolve(parser):
    """--magsolve, the engine's solver binary (relative to the repository's root)."""
    parser.add_argument("--magsolve", default=MAGSOLVE)


def add_curve(parser):
    """--curve: the balls' curve that magsolve solves on (magsolve --curve)."""
    parser.add_argument("--curve", choices=("tanh", "iron"), default="tanh",
                        help="the balls' curve (magsolve --curve): tanh = eq. 10, iron = a sphere of the reference's iron")


def magsolve_missing(path, prog):
    """True (and one line on stderr) when path is not an executable: build it first."""
    if os.access(path, os.X_OK):
        return False
    print(f"{prog}: {path} is not an executable (build it first)", file=sys.stderr)
    return True


def pair_mark(v):
    """v to two places, bold outside the pair model's axial mark 0.85-1.15."""
    return f"**{v:.2f}**" if not 0.85 <= v <= 1.15 else f"{v:.2f}"


def gap_field_table(gaps, fields, cell):
    """Markdown lines: a row per gap g/a, a column per H0/Ms, cell(g, h) the text of a cell."""
    lines = ["| g/a | " + " | ".join(f"{h:g}" for h in fields) + " |", "|---" * (len(fields) + 1) + "|"]
    lines += [f"| {g:g} | " + " | ".join(cell(g, h) for h in fields) + " |" for g in gaps]
    return lines



def central_z(z, fn, step):
    """[d fn / d z_k for every k] by central differences of `step` (m), z a numpy array: the
    axial prototypes' forces at fixed moments (the envelope theorem)."""
    out = []
    for k in range(len(z)):
        zp, zm = z.copy(), z.copy()
        zp[k] += step
        zm[k] -= step
        out.append((fn(zp) - fn(zm)) / (2 * step))
    return out
