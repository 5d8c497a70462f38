#!/usr/bin/env python3
"""The two figures of `evo_ape --plot` in one PNG, from an APE errors file of sba-slam.

Left: the reference and the aligned estimate seen from above, the estimate coloured by its error.
Right: the error along the trajectory, with its rmse, median and mean and the mean +- std band.

    sba-slam eval ape REF EST --format ... --align ... --save-errors errors.txt
    /usr/bin/python3 python/plot_trajectory.py errors.txt --out ape.png [--plane auto|xy|xz|yz]

The errors file holds "stamp error ref_x ref_y ref_z est_x est_y est_z" per matched pose (the
estimate as aligned). "auto" draws the plane of the reference's two widest axes (x-z for a
KITTI camera trajectory, x-y for EuRoC's world frame). Bad input exits 1 with one line naming
the file.
"""

import argparse
import math
import os
import sys

AXES = {"x": 0, "y": 1, "z": 2}


class InputError(Exception):
    pass


def read_errors(path):
    """(stamp name, relation, rows of [stamp, error, rx, ry, rz, ex, ey, ez])."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: file not found")
    with open(path) as f:
        lines = f.read().splitlines()
    header = lines[0].lstrip("# ").split() if lines and lines[0].startswith("#") else []
    if len(header) != 8 or header[2:] != ["ref_x", "ref_y", "ref_z", "est_x", "est_y", "est_z"]:
        raise InputError(f"{path}: not an APE errors file with positions "
                         "(write it with sba-slam eval ape ... --save-errors)")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split()
        try:
            values = [float(v) for v in fields]
        except ValueError:
            raise InputError(f"{path}:{number}: not a number in '{line}'") from None
        if len(values) != 8:
            raise InputError(f"{path}:{number}: expected 8 values, got {len(values)}")
        if not all(math.isfinite(v) for v in values):
            raise InputError(f"{path}:{number}: non-finite value in '{line}'")
        rows.append(values)
    if len(rows) < 2:
        raise InputError(f"{path}: {len(rows)} pose(s); a plot needs at least 2")
    return header[0], header[1], rows


def widest_plane(rows):
    """The two axes along which the reference spreads most, in x, y, z order."""
    extent = [max(r[2 + a] for r in rows) - min(r[2 + a] for r in rows) for a in range(3)]
    first, second = sorted(sorted(range(3), key=lambda a: -extent[a])[:2])
    return "xyz"[first] + "xyz"[second]


def plot(stamp_name, relation, rows, plane, out, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection

    data = np.array(rows)
    stamps, errors = data[:, 0], data[:, 1]
    a, b = AXES[plane[0]], AXES[plane[1]]
    ref, est = data[:, 2:5], data[:, 5:8]
    unit = {"trans_part": "m", "angle_deg": "deg", "angle_rad": "rad"}.get(relation, "")
    label = f"APE {relation}" + (f" ({unit})" if unit else "")

    fig, (top, along) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1, 1.3]})
    top.plot(ref[:, a], ref[:, b], "--", color="0.45", lw=1.2, label="reference")
    segments = np.stack([est[:-1][:, [a, b]], est[1:][:, [a, b]]], axis=1)
    line = LineCollection(segments, cmap="jet", linewidths=2.0)
    line.set_array(0.5 * (errors[:-1] + errors[1:]))
    top.add_collection(line)
    top.plot([], [], color="tab:blue", lw=2.0, label="estimate (aligned)")
    top.set_aspect("equal", adjustable="datalim")
    top.autoscale_view()
    top.set_xlabel(f"{plane[0]} (m)")
    top.set_ylabel(f"{plane[1]} (m)")
    top.legend(loc="best", fontsize=8)
    fig.colorbar(line, ax=top, label=label)

    rmse = float(np.sqrt(np.mean(errors**2)))
    mean, median, std = float(np.mean(errors)), float(np.median(errors)), float(np.std(errors))
    along.plot(stamps, errors, color="0.2", lw=1.0, label=label)
    along.axhline(rmse, color="tab:blue", lw=1.2, label=f"rmse {rmse:.4g}")
    along.axhline(median, color="tab:green", lw=1.2, label=f"median {median:.4g}")
    along.axhline(mean, color="tab:red", lw=1.2, label=f"mean {mean:.4g}")
    along.axhspan(mean - std, mean + std, color="tab:red", alpha=0.12, label=f"std {std:.4g}")
    along.set_xlabel("t (s)" if stamp_name == "timestamp" else stamp_name)
    along.set_ylabel(label)
    along.set_xlim(stamps[0], stamps[-1])
    along.legend(loc="upper left", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("errors", help="file of sba-slam eval ape --save-errors")
    parser.add_argument("--out", required=True, help="PNG to write")
    parser.add_argument("--plane", default="auto", choices=["auto", "xy", "xz", "yz"])
    parser.add_argument("--title", default="")
    args = parser.parse_args(argv)
    try:
        stamp_name, relation, rows = read_errors(args.errors)
        plane = widest_plane(rows) if args.plane == "auto" else args.plane
        out_dir = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(out_dir):
            raise InputError(f"{args.out}: folder {out_dir} not found")
        plot(stamp_name, relation, rows, plane, args.out, args.title)
    except InputError as e:
        print(f"plot_trajectory: {e}", file=sys.stderr)
        return 1
    print(f"wrote {args.out} ({len(rows)} poses, plane {plane})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
