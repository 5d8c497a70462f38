#!/usr/bin/env python3
"""One figure per synthetic scene: left image, depth and Cityscapes labels of one frame.

Renders the frames with `sba-slam simulate` into a temporary folder (or reads an existing output
folder per scene with --data), then writes docs/img/sim_<scene>.png.

    /usr/bin/python3 python/plot_scene_frames.py --cli build/sba-slam
"""

import argparse
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

# Cityscapes colours of the label ids the simulator writes.
CITYSCAPES = {
    7: ("road", (128, 64, 128)), 8: ("sidewalk", (244, 35, 232)), 9: ("parking", (250, 170, 160)),
    10: ("rail track", (230, 150, 140)), 11: ("building", (70, 70, 70)),
    13: ("fence", (190, 153, 153)), 15: ("bridge", (150, 100, 100)), 17: ("pole", (153, 153, 153)),
    18: ("polegroup", (153, 153, 153)), 19: ("traffic light", (250, 170, 30)),
    20: ("traffic sign", (220, 220, 0)), 21: ("vegetation", (107, 142, 35)),
    22: ("terrain", (152, 251, 152)), 23: ("sky", (70, 130, 180)), 24: ("person", (220, 20, 60)),
    25: ("rider", (255, 0, 0)), 26: ("car", (0, 0, 142)), 27: ("truck", (0, 0, 70)),
    28: ("bus", (0, 60, 100)),
}

# Scene -> frame shown (a frame with something to see: traffic, a turn, the room's clutter).
SCENES = {"city-loop": 60, "city-dynamic": 45, "room": 40, "straight": 20}


def read_png(path):
    import cv2  # OpenCV reads 16-bit PNGs unchanged

    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"plot_scene_frames: cannot read {path}")
    return image


def frame_paths(root, scene, index):
    kitti = os.path.join(root, "sequences", "00")
    if os.path.isdir(kitti):
        name = f"{index:06d}.png"
        return [os.path.join(kitti, d, name) for d in ("image_0", "depth", "semantic")]
    mav = os.path.join(root, "mav0")
    with open(os.path.join(mav, "cam0", "data.csv")) as f:
        names = [line.split(",")[1].strip() for line in f if not line.startswith("#")]
    name = names[index]
    return [os.path.join(mav, d, "data", name) for d in ("cam0", "depth0", "semantic0")]


def colour_labels(labels):
    rgb = np.zeros(labels.shape + (3,), np.uint8)
    for label_id, (_, colour) in CITYSCAPES.items():
        rgb[labels == label_id] = colour
    return rgb


def plot(scene, root, index, out_path):
    image_path, depth_path, label_path = frame_paths(root, scene, index)
    image = read_png(image_path)
    depth = read_png(depth_path).astype(np.float32) / 256.0
    labels = read_png(label_path)
    aspect = image.shape[1] / image.shape[0]
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 3 * 7.5 / aspect + 1.0), dpi=90)
    axes[0].imshow(image, cmap="gray", vmin=0, vmax=255)
    axes[0].set_title(f"{scene}, frame {index}: left image")
    valid = depth > 0
    shown = np.where(valid, depth, np.nan)
    vmax = np.percentile(depth[valid], 95) if valid.any() else 1.0
    im = axes[1].imshow(shown, cmap="viridis_r", vmin=0, vmax=vmax)
    axes[1].set_title("depth [m] (blank: sky)")
    fig.colorbar(im, ax=axes[1], fraction=0.025, pad=0.01)
    axes[2].imshow(colour_labels(labels))
    present = [CITYSCAPES[i][0] for i in sorted(np.unique(labels)) if i in CITYSCAPES]
    axes[2].set_title("labels: " + ", ".join(present), fontsize=8)
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out_path, dpi=90)
    plt.close(fig)
    print(f"{out_path}: {os.path.getsize(out_path) // 1024} KB")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="build/sba-slam", help="the sba-slam binary")
    parser.add_argument("--out-dir", default="docs/img")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--data", nargs="*", default=[],
                        help="SCENE=DIR pairs of existing simulate outputs to plot instead")
    args = parser.parse_args()
    given = dict(item.split("=", 1) for item in args.data)
    os.makedirs(args.out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for scene, index in SCENES.items():
            root = given.get(scene)
            if root is None:
                root = os.path.join(tmp, scene)
                subprocess.run([args.cli, "simulate", "--scene", scene, "--frames", str(index + 1),
                                "--seed", str(args.seed), "--dynamic-objects", "16", "--out", root],
                               check=True)
            plot(scene, root, index, os.path.join(args.out_dir, f"sim_{scene}.png"))


if __name__ == "__main__":
    main()
