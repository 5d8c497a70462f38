#!/usr/bin/env python3
"""Compares two saliency-map folders where Salient BA reads them: at ORB keypoints, after the
saturation S_init = min(1, S / (255 tau)) that tracking applies (saturated_saliency in
src/sbaslam/saliency/depth_correction.cc), grouped by semantic class (static, car, other) and by
rendered depth (near < 10 m, mid < 30 m, far).

Usage: saturated_maps_at_keypoints.py SEQUENCE MAPS_A MAPS_B [--every N] [--tau T]
  SEQUENCE: a rendered KITTI-layout sequence (image_0/, semantic/, depth/ of `sba-slam simulate`)
  MAPS_A, MAPS_B: folders of 8-bit maps named like the images (what `--saliency DIR` reads)
Needs Debian's python3 (cv2, numpy).
"""

import argparse
import os
import sys

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ideal_saliency_maps import STATIC_IDS  # noqa: E402

CAR_ID = 26  # Cityscapes "car"
DEPTH_PNG_SCALE = 256.0  # the renderer's depth PNGs: metres = value / 256, 0 = none
DEPTH_BINS = (("near", 10.0), ("mid", 30.0), ("far", float("inf")))


def read(path, flags=cv2.IMREAD_GRAYSCALE):
    image = cv2.imread(path, flags) if os.path.isfile(path) else None  # no OpenCV warning line
    if image is None:
        sys.exit(f"saturated_maps_at_keypoints.py: error: {path}: missing or unreadable image")
    return image


def groups(label, depth):
    cls = "static" if label in STATIC_IDS else ("car" if label == CAR_ID else "other")
    return cls, next(name for name, limit in DEPTH_BINS if depth < limit)


def sample(seq, maps_a, maps_b, every, tau):
    names = sorted(n for n in os.listdir(os.path.join(seq, "image_0")) if n.endswith(".png"))
    if not names:
        sys.exit(f"saturated_maps_at_keypoints.py: error: {seq}/image_0: no PNG images")
    orb = cv2.ORB_create(2000)
    values = {}
    for name in names[::every]:
        image = read(os.path.join(seq, "image_0", name))
        labels = read(os.path.join(seq, "semantic", name), cv2.IMREAD_UNCHANGED)
        depth = read(os.path.join(seq, "depth", name), cv2.IMREAD_UNCHANGED) / DEPTH_PNG_SCALE
        sat = [np.minimum(1.0, read(os.path.join(d, name)) / (255.0 * tau)) for d in (maps_a, maps_b)]
        for k in orb.detect(image, None):
            x, y = int(k.pt[0]), int(k.pt[1])
            values.setdefault(groups(labels[y, x], depth[y, x]), []).append(
                (sat[0][y, x], sat[1][y, x]))
    return values


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("sequence")
    p.add_argument("maps_a")
    p.add_argument("maps_b")
    p.add_argument("--every", type=int, default=5, help="every Nth frame (default 5)")
    p.add_argument("--tau", type=float, default=0.02, help="Saliency.saturation (default 0.02)")
    args = p.parse_args()
    if args.every < 1 or not 0 < args.tau <= 1:
        sys.exit("saturated_maps_at_keypoints.py: error: --every must be >= 1, --tau in (0, 1]")
    values = sample(args.sequence, args.maps_a, args.maps_b, args.every, args.tau)
    print("class,depth,keypoints,mean_a,mean_b,below_half_a,below_half_b,mean_abs_difference")
    for (cls, depth), v in sorted(values.items()):
        v = np.array(v)
        print(f"{cls},{depth},{len(v)},{v[:, 0].mean():.3f},{v[:, 1].mean():.3f},"
              f"{np.mean(v[:, 0] < 0.5):.3f},{np.mean(v[:, 1] < 0.5):.3f},"
              f"{np.abs(v[:, 0] - v[:, 1]).mean():.3f}")


if __name__ == "__main__":
    main()
