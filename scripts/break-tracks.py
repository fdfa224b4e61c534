#!/usr/bin/env python3
"""Break the tracks of a tracks.csv as a tracker that loses lines would.

Usage: scripts/break-tracks.py IN.csv OUT.csv P SEED

Each track gets a new id with probability P at each frame after its first (the line is lost
and found again under a new id; the bearings are untouched). For studying the calibration's
joining of pieces of one line from pixels (`omnivert calibrate DATASET --tracks OUT.csv`,
with and without `--no-join`; docs/theory/association.md#pieces-of-one-line).
"""
import csv
import random
import sys


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    src, dst, p, seed = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    random.seed(seed)
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{src}: no rows")
    next_id = max(int(r["track_id"]) for r in rows) + 1
    current, last_frame = {}, {}
    rows.sort(key=lambda r: (int(r["frame"]), int(r["track_id"])))
    for r in rows:
        t, k = int(r["track_id"]), int(r["frame"])
        if t not in current:
            current[t] = t
        elif k != last_frame[t] and random.random() < p:
            current[t] = next_id
            next_id += 1
        last_frame[t] = k
        r["track_id"] = str(current[t])
    with open(dst, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
