"""python/ideal_saliency_maps.py on small made-up images (run by ctest with Debian's python3)."""

import os
import subprocess
import sys
import tempfile
import unittest

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "python", "ideal_saliency_maps.py")


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)


def write(folder, name, image):
    os.makedirs(folder, exist_ok=True)
    assert cv2.imwrite(os.path.join(folder, name), image)


def read(folder, name):
    return cv2.imread(os.path.join(folder, name), cv2.IMREAD_GRAYSCALE)


class IdealSaliencyMapsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.images = os.path.join(self.dir, "image_0")
        for i in range(5):
            write(self.images, f"{i:06d}.png", np.full((6, 9), 40 * i, np.uint8))

    def tearDown(self):
        self.tmp.cleanup()

    def test_constant_is_255_at_each_images_size(self):
        out = os.path.join(self.dir, "const")
        self.assertEqual(run("constant", self.images, out).returncode, 0)
        self.assertEqual(sorted(os.listdir(out)), sorted(os.listdir(self.images)))
        m = read(out, "000003.png")
        self.assertEqual(m.shape, (6, 9))
        self.assertTrue((m == 255).all())

    def test_class_mask_keeps_only_the_static_classes(self):
        labels = os.path.join(self.dir, "semantic")
        ids = np.array([[7, 11, 22, 23, 24, 26]], np.uint8)  # road building terrain sky person car
        write(labels, "000000.png", ids)
        out = os.path.join(self.dir, "mask")
        self.assertEqual(run("class-mask", labels, out).returncode, 0)
        self.assertEqual(read(out, "000000.png").tolist(), [[255, 255, 255, 0, 0, 0]])

    def test_dataset_maps_fill_missing_frames_from_the_nearest(self):
        ds = os.path.join(self.dir, "ds")
        write(os.path.join(ds, "maps"), "a.png", np.full((6, 9), 10, np.uint8))
        write(os.path.join(ds, "maps"), "b.png", np.full((6, 9), 20, np.uint8))
        with open(os.path.join(ds, "dataset.csv"), "w") as f:
            f.write("image,labels,map\n")
            f.write(f"{self.images}/000000.png,x,maps/a.png\n")
            f.write(f"{self.images}/000003.png,x,maps/b.png\n")
        out = os.path.join(self.dir, "maps")
        self.assertEqual(run("dataset", ds, self.images, out).returncode, 0)
        # frame 1 is nearest to 0, frame 2 to 3, frame 4 to 3
        got = [int(read(out, f"{i:06d}.png")[0, 0]) for i in range(5)]
        self.assertEqual(got, [10, 10, 20, 20, 20])

    def test_a_missing_folder_is_a_one_line_error_naming_it_and_makes_no_output(self):
        missing = os.path.join(self.dir, "nope")
        out = os.path.join(self.dir, "out")
        result = run("constant", missing, out)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn(f"{missing}: not a folder", result.stderr)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
