#!/usr/bin/env python3
"""Copies a KITTI-layout sequence with some frames black, as if the lens were covered.

Tracking loses the map on the black frames and starts a new one after them, so the copy tests
recovery from a loss and map merging. Every other file is a symbolic link to the original.

    python3 python/black_out_frames.py SRC DST --first F --count N

SRC is a sequence folder (image_0/, image_1/ when stereo, times.txt, calib.txt); DST must not
exist. Frames F .. F+N-1 of every image_* folder become black images of the same size.
"""

import argparse
import os
import struct
import sys
import zlib

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}  # PNG colour type -> samples per pixel (no palettes)


def fail(message):
    print(f"black_out_frames: {message}", file=sys.stderr)
    sys.exit(1)


def png_header(path):
    """(width, height, bit depth, colour type) of a PNG file."""
    with open(path, "rb") as f:
        head = f.read(29)
    if len(head) < 29 or head[:8] != PNG_SIGNATURE or head[12:16] != b"IHDR":
        fail(f"{path}: not a PNG image")
    width, height, depth, colour = struct.unpack(">IIBB", head[16:26])
    if colour not in CHANNELS or depth not in (8, 16):
        fail(f"{path}: PNG colour type {colour} / depth {depth} not supported")
    return width, height, depth, colour


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))


def black_png(width, height, depth, colour):
    """A PNG of the given layout whose every sample is 0."""
    row = b"\x00" + bytes(width * CHANNELS[colour] * depth // 8)  # filter byte, then samples
    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    return (PNG_SIGNATURE + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(row * height)) + chunk(b"IEND", b""))


def image_folders(src):
    folders = sorted(d for d in os.listdir(src) if d.startswith("image_")
                     and os.path.isdir(os.path.join(src, d)))
    if not folders:
        fail(f"{src}: no image_* folder (not a KITTI sequence)")
    return folders


def black_out(src, dst, first, count):
    if not os.path.isdir(src):
        fail(f"{src}: no such folder")
    if os.path.exists(dst):
        fail(f"{dst}: already exists")
    folders = image_folders(src)
    os.makedirs(dst)
    for name in sorted(os.listdir(src)):
        if name not in folders:
            os.symlink(os.path.abspath(os.path.join(src, name)), os.path.join(dst, name))
    blacked = 0
    for folder in folders:
        images = sorted(os.listdir(os.path.join(src, folder)))
        if first + count > len(images):
            fail(f"{os.path.join(src, folder)}: {len(images)} images, fewer than frame "
                 f"{first + count - 1}")
        os.makedirs(os.path.join(dst, folder))
        for index, name in enumerate(images):
            source = os.path.abspath(os.path.join(src, folder, name))
            target = os.path.join(dst, folder, name)
            if first <= index < first + count:
                with open(target, "wb") as f:
                    f.write(black_png(*png_header(source)))
                blacked += 1
            else:
                os.symlink(source, target)
    return blacked


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("src")
    parser.add_argument("dst")
    parser.add_argument("--first", type=int, required=True, help="first black frame")
    parser.add_argument("--count", type=int, required=True, help="how many frames")
    args = parser.parse_args()
    if args.first < 0 or args.count < 1:
        fail(f"--first must be >= 0 and --count >= 1, got {args.first} and {args.count}")
    blacked = black_out(args.src, args.dst, args.first, args.count)
    print(f"{args.dst}: frames {args.first}-{args.first + args.count - 1} black "
          f"({blacked} images)")


if __name__ == "__main__":
    main()
