"""python/black_out_frames.py on a small made-up sequence (run by ctest)."""

import os
import subprocess
import sys
import tempfile
import unittest
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import black_out_frames  # noqa: E402

TOOL = os.path.join(ROOT, "python", "black_out_frames.py")
WIDTH, HEIGHT = 12, 8


def write_gray_png(path, value):
    png = black_out_frames.black_png(WIDTH, HEIGHT, 8, 0)
    # the same layout with every sample `value`: rebuild the IDAT from rows of it
    row = b"\x00" + bytes([value]) * WIDTH
    idat = black_out_frames.chunk(b"IDAT", zlib.compress(row * HEIGHT))
    head = png[:8 + 25]  # signature and IHDR chunk
    with open(path, "wb") as f:
        f.write(head + idat + black_out_frames.chunk(b"IEND", b""))


def samples(path):
    """The pixel values of one of these 8-bit gray PNGs."""
    with open(path, "rb") as f:
        data = f.read()
    start = data.index(b"IDAT") + 4
    length = int.from_bytes(data[start - 8:start - 4], "big")
    raw = zlib.decompress(data[start:start + length])
    rows = [raw[r * (WIDTH + 1) + 1:(r + 1) * (WIDTH + 1)] for r in range(HEIGHT)]
    return b"".join(rows)


def make_sequence(root, frames=6):
    for folder in ("image_0", "image_1"):
        os.makedirs(os.path.join(root, folder))
        for i in range(frames):
            write_gray_png(os.path.join(root, folder, f"{i:06d}.png"), 10 + i)
    with open(os.path.join(root, "times.txt"), "w") as f:
        f.write("".join(f"{0.1 * i:.1f}\n" for i in range(frames)))


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)


class BlackOut(unittest.TestCase):
    def test_only_the_chosen_frames_are_black_and_the_rest_link_to_the_original(self):
        with tempfile.TemporaryDirectory() as tmp:
            src, dst = os.path.join(tmp, "seq"), os.path.join(tmp, "out")
            make_sequence(src)
            result = run(src, dst, "--first", "2", "--count", "3")
            self.assertEqual(result.returncode, 0, result.stderr)
            for folder in ("image_0", "image_1"):
                for i in range(6):
                    path = os.path.join(dst, folder, f"{i:06d}.png")
                    self.assertEqual(black_out_frames.png_header(path), (WIDTH, HEIGHT, 8, 0))
                    pixels = samples(path)
                    self.assertEqual(len(pixels), WIDTH * HEIGHT)
                    if 2 <= i < 5:
                        self.assertFalse(os.path.islink(path))
                        self.assertEqual(max(pixels), 0)
                    else:
                        self.assertTrue(os.path.islink(path))
                        self.assertEqual(min(pixels), 10 + i)
            self.assertTrue(os.path.islink(os.path.join(dst, "times.txt")))

    def test_bad_input_gives_one_line_and_a_non_zero_exit(self):
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "seq")
            make_sequence(src)
            cases = [
                ((os.path.join(tmp, "missing"), os.path.join(tmp, "a"), "--first", "0",
                  "--count", "1"), "no such folder"),
                ((src, os.path.join(tmp, "b"), "--first", "4", "--count", "5"), "fewer than"),
                ((src, src, "--first", "0", "--count", "1"), "already exists"),
                ((src, os.path.join(tmp, "c"), "--first", "0", "--count", "0"), "--count"),
            ]
            for args, expected in cases:
                result = run(*args)
                self.assertNotEqual(result.returncode, 0)
                self.assertIn(expected, result.stderr)
                self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)


if __name__ == "__main__":
    unittest.main()
