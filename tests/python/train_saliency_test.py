"""python/train_saliency.py's saturated-map loss term (run by ctest with Debian's python3: torch)."""

import math
import os
import subprocess
import sys
import unittest

import torch

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
from train_saliency import saturated_map_loss  # noqa: E402

TAU = 0.02


def logits_of(density):
    return torch.log(density.clamp_min(1e-12))


class SaturatedMapLossTest(unittest.TestCase):
    def setUp(self):
        # One image, four pixels: the peak, one saturated (0.5 >= tau), one unsaturated
        # (0.002 = S_sat 0.1), one below the floor (1e-5 = S_sat 5e-4 < 0.01).
        self.target = torch.tensor([1.0, 0.5, 0.002, 1e-5]).reshape(1, 1, 1, 4)
        self.features = torch.ones_like(self.target)

    def loss(self, logits, features=None):
        f = self.features if features is None else features
        return saturated_map_loss(logits, self.target, f, TAU).item()

    def test_zero_for_the_target_itself_and_at_any_logit_offset(self):
        z = logits_of(self.target)
        self.assertAlmostEqual(self.loss(z), 0.0, places=6)
        self.assertAlmostEqual(self.loss(z + 7.0), 0.0, places=6)

    def test_saturated_pixels_may_be_anything_above_tau(self):
        z = logits_of(self.target).clone()
        z[0, 0, 0, 1] = math.log(0.05)  # still >= tau: saturates alike
        self.assertAlmostEqual(self.loss(z), 0.0, places=6)
        z[0, 0, 0, 1] = math.log(TAU / 4)  # S_sat 0.25 where the target's is 1: log 4 short
        self.assertAlmostEqual(self.loss(z), math.log(4) / 4, places=5)

    def test_an_unsaturated_pixel_costs_its_log_distance_both_ways(self):
        for factor in (3.0, 1 / 3.0):
            z = logits_of(self.target).clone()
            z[0, 0, 0, 2] += math.log(factor)
            self.assertAlmostEqual(self.loss(z), math.log(3) / 4, places=5)

    def test_below_the_floor_only_rising_above_it_costs(self):
        z = logits_of(self.target).clone()
        z[0, 0, 0, 3] -= 10.0
        self.assertAlmostEqual(self.loss(z), 0.0, places=6)
        z[0, 0, 0, 3] = math.log(TAU * 0.01 * math.e)  # one nat above the floor
        self.assertAlmostEqual(self.loss(z), 1.0 / 4, places=5)

    def test_weighted_by_the_features_and_differentiable(self):
        z = logits_of(self.target).clone()
        z[0, 0, 0, 2] += math.log(3.0)
        only_elsewhere = torch.tensor([1.0, 1.0, 0.0, 1.0]).reshape(1, 1, 1, 4)
        self.assertAlmostEqual(self.loss(z, only_elsewhere), 0.0, places=6)
        z.requires_grad_(True)
        saturated_map_loss(z, self.target, self.features, TAU).backward()
        self.assertGreater(z.grad[0, 0, 0, 2].item(), 0.0)  # pushed back down


class CommandLine(unittest.TestCase):
    def test_bad_term_settings_are_errors_naming_the_option(self):
        tool = os.path.join(ROOT, "python", "train_saliency.py")
        for args, message in ((["--saturated-weight", "nan"], "--saturated-weight must be"),
                              (["--saturated-weight", "-1"], "--saturated-weight must be"),
                              (["--saturation", "0"], "--saturation must be in (0, 1]")):
            out = subprocess.run([sys.executable, tool, "--train", "t", "--holdout", "h", "--out",
                                  "o", *args], capture_output=True, text=True)
            self.assertEqual(out.returncode, 2, args)
            self.assertIn(message, out.stderr.strip().splitlines()[-1], args)


if __name__ == "__main__":
    unittest.main()
