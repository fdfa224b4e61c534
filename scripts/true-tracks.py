#!/usr/bin/env python3
"""Tracks with the true association, from a simulated dataset's ground truth.

Usage: scripts/true-tracks.py DATASET TRACKS.csv OUT.csv [--true-bearings] [--noise-deg S]
                              [--seed N] [--gap F] [--tolerance-deg T]

Each detection of TRACKS.csv (of `omnivert track` or `calibrate` on DATASET) is given the true
line whose bearing in DATASET/ground_truth/lines.csv is nearest in the same frame, within T
degrees (0.2), each true line at most once a frame; detections with none are left out. A
track is a stretch of one true line with gaps of at most F frames (20, the calibration's
max_missed_frames): a line seen again later is a new track, as a tracker that lost it would
report. With --true-bearings the bearing (and image angle) becomes the true one plus Gaussian
noise of S degrees (0), drawn from --seed (1).

For separating what the association costs the calibration from what the extractor's bearings
cost (`omnivert calibrate DATASET --tracks OUT.csv`; docs/validation.md#long-runs).
"""
import argparse
import bisect
import csv
import math
import random
import sys


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def read_truth(path):
    frames = {}
    with open(path, newline="") as f:
        for n, row in enumerate(csv.reader(f), start=1):
            if not row or row[0].startswith("#"):
                continue
            try:
                frame, line, bearing = int(row[1]), int(row[2]), float(row[3])
            except (IndexError, ValueError):
                sys.exit(f"{path}:{n}: expected timestamp, frame, line_id, bearing, ...")
            frames.setdefault(frame, []).append((wrap(bearing), line))
    for v in frames.values():
        v.sort()
    return frames


def nearest(lines, bearing, tolerance):
    """The (distance, line, true bearing) nearest `bearing` among a frame's sorted lines."""
    if not lines:
        return None
    i = bisect.bisect_left(lines, (bearing, -1))
    best = None
    for j in (i - 1, i, i + 1, 0, len(lines) - 1):  # neighbours, and both ends across +-pi
        if 0 <= j < len(lines):
            d = abs(wrap(lines[j][0] - bearing))
            if d <= tolerance and (best is None or d < best[0]):
                best = (d, lines[j][1], lines[j][0])
    return best


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("dataset")
    p.add_argument("tracks")
    p.add_argument("out")
    p.add_argument("--true-bearings", action="store_true")
    p.add_argument("--noise-deg", type=float, default=0.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--gap", type=int, default=20)
    p.add_argument("--tolerance-deg", type=float, default=0.2)
    a = p.parse_args()
    truth = read_truth(f"{a.dataset}/ground_truth/lines.csv")
    tolerance = math.radians(a.tolerance_deg)
    noise = math.radians(a.noise_deg)
    rng = random.Random(a.seed)
    with open(a.tracks, newline="") as f:
        reader = csv.DictReader(f)
        fields = reader.fieldnames
        rows = list(reader)
    needed = {"frame", "track_id", "bearing_rad", "image_angle_rad"}
    if not fields or not needed <= set(fields):
        sys.exit(f"{a.tracks}: a tracks.csv needs the columns {sorted(needed)}")
    rows.sort(key=lambda r: (int(r["frame"]), int(r["track_id"])))
    used, last_seen, track_of = set(), {}, {}
    kept, next_id = [], 0
    for r in rows:
        frame = int(r["frame"])
        hit = nearest(truth.get(frame, []), wrap(float(r["bearing_rad"])), tolerance)
        if hit is None or (frame, hit[1]) in used:
            continue
        used.add((frame, hit[1]))
        line = hit[1]
        if line not in last_seen or frame - last_seen[line] > a.gap:
            track_of[line] = next_id
            next_id += 1
        last_seen[line] = frame
        r["track_id"] = str(track_of[line])
        if a.true_bearings:
            b = repr(wrap(hit[2] + rng.gauss(0.0, noise) if noise > 0 else hit[2]))
            r["bearing_rad"] = r["image_angle_rad"] = b
        kept.append(r)
    with open(a.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        w.writeheader()
        w.writerows(kept)
    print(f"{a.out}: {len(kept)} of {len(rows)} detections on a true line, {next_id} tracks",
          file=sys.stderr)


if __name__ == "__main__":
    main()
