#!/usr/bin/python3
"""Folders of saliency maps for `sba-slam run --saliency DIR`, one 8-bit PNG per image of a
sequence and named like it, from sources better than the model (docs/RESULTS.md, "Session 41"):

  constant IMAGES OUT          every pixel 255 (only Algorithm 1's depth term is left)
  class-mask LABELS OUT        255 on the 13 static Cityscapes classes of the salient dataset,
                               0 elsewhere (LABELS: a render's semantic/ folder)
  dataset DATASET IMAGES OUT   the maps of a `sba-slam saliency make-dataset` output (semantic
                               gaze or stable points); an image the dataset has no map for takes
                               the map of the nearest frame that has one

usage: ideal_saliency_maps.py constant|class-mask|dataset ARGS...
"""

import csv
import os
import sys

import cv2
import numpy as np

# saliency/salient_dataset.cc, is_static_class: the paper's 13 classes.
STATIC_IDS = [7, 8, 9, 10, 11, 13, 15, 17, 18, 19, 20, 21, 22]


def pngs(folder):
    if not os.path.isdir(folder):
        sys.exit(f"{folder}: not a folder")
    names = sorted(n for n in os.listdir(folder) if n.endswith(".png"))
    if not names:
        sys.exit(f"{folder}: no PNG images")
    return names


def read_gray(path):
    image = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if image is None:
        sys.exit(f"{path}: cannot read the image")
    return image


def write(out, name, image):
    os.makedirs(out, exist_ok=True)  # only once an input has been read: bad input leaves no OUT
    if not cv2.imwrite(os.path.join(out, name), image):
        sys.exit(f"{os.path.join(out, name)}: cannot write the map")


def constant(images, out):
    for name in pngs(images):
        write(out, name, np.full(read_gray(os.path.join(images, name)).shape, 255, np.uint8))


def class_mask(labels, out):
    for name in pngs(labels):
        ids = read_gray(os.path.join(labels, name))
        write(out, name, np.where(np.isin(ids, STATIC_IDS), 255, 0).astype(np.uint8))


def from_dataset(dataset, images, out):
    listing = os.path.join(dataset, "dataset.csv")
    if not os.path.isfile(listing):
        sys.exit(f"{listing}: not found (not a make-dataset output)")
    with open(listing) as f:
        maps = {os.path.basename(r["image"]): os.path.join(dataset, r["map"])
                for r in csv.DictReader(f)}
    names = pngs(images)
    have = [i for i, n in enumerate(names) if n in maps]
    if not have:
        sys.exit(f"{listing}: no map for any image of {images}")
    for i, name in enumerate(names):
        nearest = names[min(have, key=lambda j: (abs(j - i), j))]
        write(out, name, read_gray(maps[nearest]))


def main():
    commands = {"constant": (constant, 2), "class-mask": (class_mask, 2),
                "dataset": (from_dataset, 3)}
    if len(sys.argv) < 2 or sys.argv[1] not in commands:
        sys.exit(__doc__)
    run, arity = commands[sys.argv[1]]
    if len(sys.argv) != arity + 2:
        sys.exit(__doc__)
    run(*sys.argv[2:])


if __name__ == "__main__":
    main()
