#!/usr/bin/python3
"""Agreement of two salient datasets made from the same frames, e.g. self-supervised labels
(`sba-slam saliency make-dataset --stable`) against semantic-gaze labels (`make-dataset --sim`).
Scores the first dataset's maps against the second's maps and fixations, and the second's
unfiltered geometric density the same way, as a baseline; means over the common frames.

usage: label_agreement.py FIRST_DATASET SECOND_DATASET
"""

import csv
import os
import sys

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from saliency_metrics import auc_judd, cc, kld, nss  # noqa: E402


def samples(folder):
    with open(os.path.join(folder, "dataset.csv")) as f:
        return {os.path.basename(r["image"]): r for r in csv.DictReader(f)}


def read(folder, relative):
    image = cv2.imread(os.path.join(folder, relative), cv2.IMREAD_GRAYSCALE)
    if image is None:
        sys.exit(f"{os.path.join(folder, relative)}: cannot read the image")
    return image.astype(np.float64) / 255.0


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    first_dir, second_dir = sys.argv[1], sys.argv[2]
    first, second = samples(first_dir), samples(second_dir)
    common = sorted(set(first) & set(second))
    if not common:
        sys.exit(f"{first_dir} and {second_dir}: no frame in common")
    rng = np.random.default_rng(7)
    scores = {k: [] for k in ["CC", "KLD (second || first)", "NSS on second's fixations",
                              "AUC-Judd on second's fixations", "NSS of second on first's fixations",
                              "baseline CC (unfiltered density)",
                              "baseline NSS (unfiltered density)"]}
    for name in common:
        a, b = first[name], second[name]
        first_map, second_map = read(first_dir, a["map"]), read(second_dir, b["map"])
        first_fix = read(first_dir, a["fixations"]) > 0
        second_fix = read(second_dir, b["fixations"]) > 0
        unfiltered = read(second_dir, b["unfiltered"])
        scores["CC"].append(cc(first_map, second_map))
        scores["KLD (second || first)"].append(kld(first_map, second_map))
        scores["NSS on second's fixations"].append(nss(first_map, second_fix))
        scores["AUC-Judd on second's fixations"].append(auc_judd(first_map, second_fix, rng))
        scores["NSS of second on first's fixations"].append(nss(second_map, first_fix))
        scores["baseline CC (unfiltered density)"].append(cc(unfiltered, second_map))
        scores["baseline NSS (unfiltered density)"].append(nss(unfiltered, second_fix))
    print(f"{len(common)} common frames ({len(first)} and {len(second)})")
    for key, values in scores.items():
        print(f"{key:38s} {np.mean(values):.3f}")


if __name__ == "__main__":
    main()
