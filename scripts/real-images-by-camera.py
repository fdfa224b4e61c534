#!/usr/bin/env python3
"""The real-image study's table per camera, from its real_images.csv.

Usage: scripts/real-images-by-camera.py OUT/real_images.csv

`omnivert study real-images DIR --out OUT` writes one row per image. This sums the counts of
each camera's images: a camera is an image's sub-folder, or, for an image at the top of DIR,
its name without the trailing digits and extension (VMRImage0.jpg -> VMRImage). For each
camera it prints the range of lines per image and, for rotation and lighting with the centre
detected and given, found % / NN % / NN among the same polarity % (docs/validation.md#real-images).
"""
import collections
import csv
import os
import re
import sys

KINDS = ("rotation_detected", "rotation_given", "lighting_detected", "lighting_given")


def camera_of(image):
    folder = os.path.dirname(image)
    if folder:
        return folder
    return re.sub(r"[_-]?\d+$", "", os.path.splitext(os.path.basename(image))[0])


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[2].strip())
    path = sys.argv[1]
    try:
        with open(path, newline="") as f:
            lines = [l for l in f if l.strip()]
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")
    if not lines or not lines[0].startswith("#image,"):
        sys.exit(f"{path}:1: not a real_images.csv (its header must begin '#image,')")
    rows = list(csv.DictReader([lines[0][1:]] + lines[1:]))
    cameras = collections.OrderedDict()
    for n, r in enumerate(rows, 2):
        try:
            if int(r["ok"]) != 1:
                continue
            cameras.setdefault(camera_of(r["image"]), []).append(r)
        except (KeyError, TypeError, ValueError):
            sys.exit(f"{path}:{n}: a row without its image, ok or count columns")
    cameras["all"] = [r for rs in list(cameras.values()) for r in rs]
    print("| camera | images | lines per image | " + " | ".join(k.replace("_", ", ") for k in KINDS)
          + " |")
    print("| --- " * (3 + len(KINDS)) + "|")
    for name, rs in cameras.items():
        lines_per = [int(r["lines"]) for r in rs]
        cells = [name, str(len(rs)), f"{min(lines_per)}-{max(lines_per)}" if rs else "-"]
        for k in KINDS:
            looked = sum(int(r[k + "_looked_for"]) for r in rs)
            found = sum(int(r[k + "_found"]) for r in rs)
            nn = sum(int(r[k + "_nn_correct"]) for r in rs)
            pol = sum(int(r[k + "_nn_correct_same_polarity"]) for r in rs)
            pct = lambda a, b: f"{100.0 * a / b:.1f}" if b else "-"
            cells.append(f"{pct(found, looked)} / {pct(nn, found)} / {pct(pol, found)}")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
