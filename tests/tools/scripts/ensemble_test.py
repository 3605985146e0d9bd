#!/usr/bin/python3
"""tests/tools/scripts/ensemble_test.py — tools/scripts/ensemble.py's figures from a states.csv
made by hand: the fastest piece over the last 0.5 s, the heap (pieces within 0.12 m of a magnet
body), and which piece sets the fastest figure, when, and how far from a magnet. Run by CTest
(label tools)."""
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tools", "scripts"))
import ensemble  # noqa: E402

HEADER = "frame,time,body,name,x,y,z,qw,qx,qy,qz\n"


def write_states(rows):
    """rows: (frame, time, name, (x, y, z)); returns the path of a states.csv."""
    d = tempfile.mkdtemp(prefix="ensemble_test_")
    path = os.path.join(d, "states.csv")
    with open(path, "w") as f:
        f.write(HEADER)
        for k, (fr, t, name, p) in enumerate(rows):
            n = f'"{name}"' if "," in name else name
            f.write(f"{fr},{t},{k},{n},{p[0]},{p[1]},{p[2]},1,0,0,0\n")
    return path


class Figures(unittest.TestCase):
    def scene(self, with_magnet=True):
        # 1 s at 20 fps: a magnet at the origin; ball_0 8 cm from it, stepping 2 mm per frame
        # from 0.6 s on (0.04 m/s); ball_1 1 m out, still until it moves 30 mm in the frame
        # that ends at 0.8 s (0.6 m/s); "ball_2, odd" (a name with a comma) 5 cm out, still.
        rows = []
        for fr in range(21):
            t = fr * 0.05
            if with_magnet:
                rows.append((fr, t, "magnet", (0, 0, 0)))
            x0 = 0.08 + (0.002 * (fr - 12) if fr > 12 else 0)
            rows.append((fr, t, "ball_0", (x0, 0, 0)))
            rows.append((fr, t, "ball_1", (1.0 + (0.03 if fr >= 16 else 0), 0, 0)))
            rows.append((fr, t, "ball_2, odd", (0, 0.05, 0)))
        return write_states(rows)

    def test_fastest_heap_and_who(self):
        fastest, heap, who = ensemble.states_figures(self.scene())
        self.assertAlmostEqual(fastest, 0.03 / 0.05, places=9)
        self.assertAlmostEqual(heap, 0.002 / 0.05, places=9)
        self.assertEqual(who["fastest_body"], "ball_1")
        self.assertAlmostEqual(who["fastest_at"], 0.8, places=9)
        self.assertAlmostEqual(who["fastest_from_magnet"], 1.03, places=9)

    def test_without_a_magnet_body(self):
        fastest, heap, who = ensemble.states_figures(self.scene(with_magnet=False))
        self.assertAlmostEqual(fastest, 0.6, places=9)
        self.assertEqual(heap, 0.0)
        self.assertEqual(who["fastest_body"], "ball_1")
        self.assertIsNone(who["fastest_from_magnet"])

    def test_one_frame_has_no_figures(self):
        path = write_states([(0, 0.0, "magnet", (0, 0, 0)), (0, 0.0, "ball_0", (0.1, 0, 0))])
        # the row's WHO columns are filled (empty) all the same
        self.assertEqual(ensemble.states_figures(path),
                         (None, None, {"fastest_body": None, "fastest_at": None, "fastest_from_magnet": None}))

    def test_still_pieces_name_no_one(self):
        rows = [(fr, fr * 0.05, n, p) for fr in range(5)
                for n, p in (("magnet", (0, 0, 0)), ("ball_0", (0.05, 0, 0)))]
        fastest, heap, who = ensemble.states_figures(write_states(rows))
        self.assertEqual((fastest, heap), (0.0, 0.0))
        self.assertIsNone(who["fastest_body"])
        self.assertEqual(ensemble.who_text({"fastest_body": None}), "")


if __name__ == "__main__":
    unittest.main()
