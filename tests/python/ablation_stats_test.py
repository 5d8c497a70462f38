"""python/ablation_stats.py on inputs whose answers are known (run by ctest)."""

import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import ablation_stats  # noqa: E402

RUNS = [1.0, 1.1, 0.9, 1.05, 0.95, 1.02, 0.98, 1.2, 0.8, 1.0]
HALVED = [v * 0.5 for v in RUNS]
TOOL = os.path.join(ROOT, "python", "ablation_stats.py")


class Summary(unittest.TestCase):
    def test_identical_arms_give_ratio_one_inside_the_interval(self):
        r = ablation_stats.summary(RUNS, RUNS, 2000, 1)
        self.assertAlmostEqual(r["ratio"], 1.0, places=12)
        self.assertLess(r["interval_90"][0], 1.0)
        self.assertGreater(r["interval_90"][1], 1.0)

    def test_halved_arm_meets_one_but_not_a_target_below_its_spread(self):
        r = ablation_stats.summary(RUNS, HALVED, 2000, 1)
        self.assertAlmostEqual(r["ratio"], 0.5, places=12)
        self.assertLess(r["interval_90"][1], 1.0)
        self.assertEqual(r["share_meeting_target"], 1.0)
        # resampled ratios range over [0.4 / 1.2, 0.6 / 0.8]; few resamples reach 0.4 or below
        r = ablation_stats.summary(RUNS, HALVED, 2000, 1, target=0.4)
        self.assertLess(r["share_meeting_target"], 0.05)

    def test_medians_and_ranges(self):
        r = ablation_stats.summary(RUNS, HALVED, 200, 1)
        self.assertEqual(r["uniform_range"], (0.8, 1.2))
        self.assertEqual(r["uniform_median"], 1.0)
        self.assertEqual(r["salient_median"], 0.5)

    def test_the_same_seed_gives_the_same_interval(self):
        self.assertEqual(ablation_stats.summary(RUNS, HALVED, 500, 7),
                         ablation_stats.summary(RUNS, HALVED, 500, 7))


class PermutationTest(unittest.TestCase):
    def test_identical_arms_do_not_differ(self):
        t = ablation_stats.permutation_test(RUNS, list(RUNS), 500, 1)
        self.assertEqual((t["median_difference"], t["mean_difference"]), (0.0, 0.0))
        self.assertEqual((t["median_p"], t["mean_p"]), (1.0, 1.0))

    def test_separated_arms_differ_and_close_arms_do_not(self):
        t = ablation_stats.permutation_test(RUNS, HALVED, 2000, 1)
        self.assertAlmostEqual(t["median_difference"], -0.5, places=12)
        self.assertLess(max(t["median_p"], t["mean_p"]), 0.01)
        shifted = [v + 0.01 for v in RUNS]  # a tenth of the spread
        t = ablation_stats.permutation_test(RUNS, shifted, 2000, 1)
        self.assertGreater(min(t["median_p"], t["mean_p"]), 0.5)

    def test_the_observed_split_counts_so_p_is_never_zero(self):
        # No shuffle of fully separated arms is as extreme as the observed split but the split
        # itself (and its mirror image, which the arms' unequal sizes rule out).
        far = [v + 100.0 for v in RUNS[:5]]
        t = ablation_stats.permutation_test(RUNS, far, 999, 1)
        self.assertGreaterEqual(t["median_p"], 1 / 1000)
        self.assertLess(t["median_p"], 0.02)
        self.assertGreater(t["mean_p"], 0.0)


class CommandLine(unittest.TestCase):
    def run_tool(self, *args):
        return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)

    def write(self, directory, name, text):
        path = os.path.join(directory, name)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        return path

    def test_prints_the_ratio_and_the_share_meeting_the_target(self):
        with tempfile.TemporaryDirectory() as d:
            u = self.write(d, "u", "\n".join(map(str, RUNS)) + "\n")
            s = self.write(d, "s", "\n".join(map(str, HALVED)) + "\n")
            out = self.run_tool(u, s, "--target", "0.5")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("ratio 0.500", out.stdout)
        self.assertIn("P(ratio <= 0.5)", out.stdout)
        self.assertNotIn("permutation", out.stdout)

    def test_permutation_line_on_request(self):
        with tempfile.TemporaryDirectory() as d:
            u = self.write(d, "u", "\n".join(map(str, RUNS)) + "\n")
            s = self.write(d, "s", "\n".join(map(str, HALVED)) + "\n")
            out = self.run_tool(u, s, "--permutation", "--resamples", "500")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertRegex(out.stdout, r"permutation test: medians differ by -0.5 \(p 0\.00\d\), "
                                     r"means by -0.5 \(p 0\.00\d\)")

    def test_labels_name_the_arms_and_tiny_p_reads_below_a_thousandth(self):
        with tempfile.TemporaryDirectory() as d:
            u = self.write(d, "u", "\n".join(map(str, RUNS)) + "\n")
            s = self.write(d, "s", "\n".join(map(str, HALVED)) + "\n")
            out = self.run_tool(u, s, "--permutation", "--resamples", "2000",
                                "--labels", "target", "model")
            empty = self.run_tool(u, s, "--labels", "target", " ")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertRegex(out.stdout, r"^target 1 \(0\.8-1\.2\)  model 0\.5 ")
        self.assertNotIn("uniform", out.stdout)
        self.assertIn("(p < 0.001)", out.stdout)
        self.assertNotEqual(empty.returncode, 0)
        self.assertIn("--labels", empty.stderr)

    def test_bad_input_is_one_line_naming_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            good = self.write(d, "good", "1.0\n")
            cases = {
                "missing": (os.path.join(d, "missing"), "No such file"),
                "text": (self.write(d, "text", "1.0\nrun failed\n"), "not a number"),
                "nan": (self.write(d, "nan", "nan\n"), "positive and finite"),
                "empty": (self.write(d, "empty", "\n"), "no values"),
            }
            for name, (path, message) in cases.items():
                out = self.run_tool(good, path)
                self.assertNotEqual(out.returncode, 0, name)
                self.assertIn(path, out.stderr, name)
                self.assertIn(message, out.stderr, name)
                self.assertEqual(len(out.stderr.strip().splitlines()), 1, name)


if __name__ == "__main__":
    unittest.main()
