"""python/plot_trajectory.py on made-up APE errors files (run by ctest with Debian's python3,
which has matplotlib)."""

import math
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import plot_trajectory  # noqa: E402

TOOL = os.path.join(ROOT, "python", "plot_trajectory.py")
HEADER = "# index trans_part ref_x ref_y ref_z est_x est_y est_z\n"


def write_loop(path, poses=200, header=HEADER):
    """A KITTI-like drive around a circle in x-z (y is height), the estimate 0.1-0.3 m off."""
    with open(path, "w") as f:
        f.write(header)
        for i in range(poses):
            a = 2.0 * math.pi * i / poses
            ref = (50.0 * math.cos(a), 0.2 * math.sin(5 * a), 50.0 * math.sin(a))
            off = 0.1 + 0.2 * i / poses
            est = (ref[0] + off, ref[1], ref[2])
            f.write(f"{i} {off} {' '.join(map(str, ref))} {' '.join(map(str, est))}\n")


def png_size(path):
    with open(path, "rb") as f:
        data = f.read(24)
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)


class PlotTrajectory(unittest.TestCase):
    def test_reads_the_positions_and_draws_the_widest_plane(self):
        with tempfile.TemporaryDirectory() as tmp:
            errors = os.path.join(tmp, "errors.txt")
            write_loop(errors)
            stamp, relation, rows = plot_trajectory.read_errors(errors)
            self.assertEqual((stamp, relation, len(rows)), ("index", "trans_part", 200))
            self.assertAlmostEqual(rows[100][5] - rows[100][2], rows[100][1])
            self.assertEqual(plot_trajectory.widest_plane(rows), "xz")
            out = os.path.join(tmp, "ape.png")
            result = run(errors, "--out", out, "--title", "loop")
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("plane xz", result.stdout)
            self.assertEqual(png_size(out), (1200, 500))
            result = run(errors, "--out", out, "--plane", "xy")
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("plane xy", result.stdout)

    def test_bad_input_gives_one_line_naming_the_file_and_exit_1(self):
        with tempfile.TemporaryDirectory() as tmp:
            rpe = os.path.join(tmp, "rpe.txt")
            with open(rpe, "w") as f:
                f.write("# first_index second_index trans_part\n0 1 0.5\n1 2 0.4\n")
            nan = os.path.join(tmp, "nan.txt")
            write_loop(nan, poses=5)
            with open(nan, "a") as f:
                f.write("5 nan 0 0 0 0 0 0\n")
            short = os.path.join(tmp, "short.txt")
            write_loop(short, poses=1)
            cases = [
                (os.path.join(tmp, "missing.txt"), "file not found"),
                (rpe, "--save-errors"),
                (nan, "nan.txt:7: non-finite"),
                (short, "a plot needs at least 2"),
            ]
            for path, needle in cases:
                with self.subTest(path=path):
                    result = run(path, "--out", os.path.join(tmp, "x.png"))
                    self.assertEqual(result.returncode, 1)
                    self.assertIn(path, result.stderr)
                    self.assertIn(needle, result.stderr)
                    self.assertEqual(result.stderr.count("\n"), 1, result.stderr)
            good = os.path.join(tmp, "good.txt")
            write_loop(good)
            result = run(good, "--out", os.path.join(tmp, "no", "x.png"))
            self.assertEqual(result.returncode, 1)
            self.assertIn("not found", result.stderr)


if __name__ == "__main__":
    unittest.main()
