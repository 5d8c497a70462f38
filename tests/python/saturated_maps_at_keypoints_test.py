"""python/saturated_maps_at_keypoints.py on a made-up sequence (run by ctest with Debian's python3)."""

import os
import subprocess
import sys
import tempfile
import unittest

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "python", "saturated_maps_at_keypoints.py")
H, W = 120, 160


def write(folder, name, image):
    os.makedirs(folder, exist_ok=True)
    assert cv2.imwrite(os.path.join(folder, name), image)


class SaturatedMapsAtKeypointsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.dir = self.tmp.name
        y, x = np.mgrid[0:H, 0:W]
        board = (((x // 16) + (y // 16)) % 2 * 255).astype(np.uint8)  # corners on both halves
        labels = np.where(x < W // 2, 11, 26).astype(np.uint8)  # building | car
        depth = np.full((H, W), 5 * 256, np.uint16)  # 5 m: "near"
        dimmed = np.where(x < W // 2, 255, 2).astype(np.uint8)  # 2 / 255 / 0.02 = 0.39 on the car
        for i in range(2):
            name = f"{i:06d}.png"
            write(os.path.join(d, "seq", "image_0"), name, board)
            write(os.path.join(d, "seq", "semantic"), name, labels)
            write(os.path.join(d, "seq", "depth"), name, depth)
            write(os.path.join(d, "a"), name, np.full((H, W), 255, np.uint8))
            write(os.path.join(d, "b"), name, dimmed)

    def tearDown(self):
        self.tmp.cleanup()

    def run_tool(self):
        return subprocess.run([sys.executable, TOOL, *(os.path.join(self.dir, p) for p in
                                                       ("seq", "a", "b")), "--every", "1"],
                              capture_output=True, text=True)

    def test_groups_keypoints_by_class_and_compares_the_saturated_maps(self):
        r = self.run_tool()
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {tuple(line.split(",")[:2]): line.split(",")[2:]
                for line in r.stdout.splitlines()[1:]}
        self.assertEqual(set(rows), {("car", "near"), ("static", "near")})
        self.assertGreater(int(rows[("car", "near")][0]), 0)
        self.assertEqual(rows[("car", "near")][1:5], ["1.000", "0.392", "0.000", "1.000"])
        self.assertEqual(rows[("static", "near")][1:3], ["1.000", "1.000"])

    def test_missing_map_names_the_file(self):
        os.remove(os.path.join(self.dir, "b", "000001.png"))
        r = self.run_tool()
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(os.path.join("b", "000001.png"), r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)


if __name__ == "__main__":
    unittest.main()
