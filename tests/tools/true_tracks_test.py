#!/usr/bin/env python3
"""scripts/true-tracks.py on a hand-made ground truth: known association in, known ids out.
  true_tracks_test.py SCRIPT WORKDIR

Three true lines over 60 frames. Line 7 is unseen in frames 20-44 (a gap of more than 20
frames: a new track after it). The tracker's tracks: track 100 follows line 5 and slips onto
line 6 at frame 30; track 101 follows line 6 and then line 5 (the two swap); a detection 3
degrees from every line is left out. Each detection lies 0.05 degree off its line."""
import csv
import math
import subprocess
import sys
from pathlib import Path

script, work = sys.argv[1], Path(sys.argv[2])
(work / "ground_truth").mkdir(parents=True, exist_ok=True)
true = {5: -2.0, 6: -1.9, 7: 1.0}  # bearing at frame 0 [rad]; each turns 0.001 rad a frame


def bearing(line, frame):
    return true[line] + 0.001 * frame


def seen(line, frame):
    return not (line == 7 and 20 <= frame < 45)


with open(work / "ground_truth/lines.csv", "w") as f:
    f.write("#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer [px]\n")
    for k in range(60):
        for line in true:
            if seen(line, k):
                f.write(f"{k * 1000},{k},{line},{bearing(line, k):.9f},60.0,215.0\n")

off = math.radians(0.05)
fields = ["frame", "timestamp_ns", "track_id", "bearing_rad", "image_angle_rad", "edge_pixels"]
rows = []
for k in range(60):
    a, b = (5, 6) if k < 30 else (6, 5)  # tracks 100 and 101 swap lines at frame 30
    for track, line in ((100, a), (101, b), (102, 7)):
        if seen(line, k):
            rows.append([k, k * 1000, track, bearing(line, k) + off, bearing(line, k) + off, 90])
    if k == 10:
        rows.append([k, k * 1000, 103, 0.5, 0.5, 40])  # 3 degrees and more from every line
with open(work / "tracks.csv", "w", newline="") as f:
    w = csv.writer(f, lineterminator="\n")
    w.writerow(fields)
    w.writerows(rows)


def run(*extra):
    out = work / "out.csv"
    subprocess.run([sys.executable, script, str(work), str(work / "tracks.csv"), str(out), *extra],
                   check=True)
    with open(out, newline="") as f:
        return list(csv.DictReader(f))


failures = []


def expect(cond, what):
    if not cond:
        failures.append(what)


got = run()
expect(len(got) == len(rows) - 1, f"{len(got)} rows, expected {len(rows) - 1}")
# The true line of each row, from its bearing (0.05 degree off), then: one id per line and
# stretch, the same id across the slip at frame 30, a new one for line 7 after its gap.
ids = {}
for r in got:
    k, b = int(r["frame"]), float(r["bearing_rad"])
    line = min(true, key=lambda l: abs(bearing(l, k) - b))
    expect(abs(b - bearing(line, k) - off) < 1e-9, f"frame {k}: bearing moved without --true-bearings")
    stretch = 1 if line == 7 and k >= 45 else 0
    ids.setdefault((line, stretch), set()).add(r["track_id"])
expect(all(len(v) == 1 for v in ids.values()), f"ids per line and stretch: {ids}")
expect(len({next(iter(v)) for v in ids.values()}) == 4, f"four tracks expected: {ids}")
expect(set(ids) == {(5, 0), (6, 0), (7, 0), (7, 1)}, f"stretches: {sorted(ids)}")

# --true-bearings: every bearing (and image angle) on its true line, exactly.
for r in run("--true-bearings"):
    k, b = int(r["frame"]), float(r["bearing_rad"])
    d = min(abs(bearing(l, k) - b) for l in true)
    expect(d < 1e-9 and r["image_angle_rad"] == r["bearing_rad"], f"frame {k}: {b} not on a line")

# A tolerance below the detections' offset: nothing is on a true line.
expect(len(run("--tolerance-deg", "0.04")) == 0, "rows found within 0.04 degree")

if failures:
    sys.exit("\n".join(failures))
print(f"true-tracks: {len(got)} rows, 4 tracks, as expected")
