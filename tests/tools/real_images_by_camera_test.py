#!/usr/bin/env python3
"""scripts/real-images-by-camera.py on a hand-made real_images.csv: known counts in, known
per-camera percentages out.
  real_images_by_camera_test.py SCRIPT WORKDIR

Two images in the sub-folder rig/ and two at the top (camA1.jpg, camA_2.png: one camera,
camA), one of them failed (ok 0: left out). Rotation, centre detected: rig 20 looked for, 15
found, 12 right nearest neighbours, 14 among the same polarity -> 75.0 / 80.0 / 93.3."""
import subprocess
import sys
from pathlib import Path

script, work = sys.argv[1], Path(sys.argv[2])
work.mkdir(parents=True, exist_ok=True)
kinds = ["rotation_detected", "rotation_given", "lighting_detected", "lighting_given"]
header = "#image,ok,width,height,center_x,center_y,r_min,r_max,lines,max_centre_shift_px," + ",".join(
    f"{k}_{c}" for k in kinds for c in ("looked_for", "found", "nn_correct", "nn_correct_same_polarity"))
rows = [
    ("rig/1.jpg", 1, 12, (10, 8, 6, 7)),
    ("rig/2.jpg", 1, 20, (10, 7, 6, 7)),
    ("camA1.jpg", 1, 5, (4, 4, 4, 4)),
    ("camA_2.png", 0, 0, (0, 0, 0, 0)),
]
with open(work / "real_images.csv", "w") as f:
    f.write(header + "\n")
    for name, ok, lines, c in rows:
        f.write(f"{name},{ok},640,480,320,240,60,215,{lines},0.1," + ",".join(map(str, c * 4)) + "\n")
out = subprocess.run([sys.executable, script, str(work / "real_images.csv")], capture_output=True,
                     text=True, check=True).stdout.splitlines()
table = {l.split("|")[1].strip(): [c.strip() for c in l.split("|")[2:-1]] for l in out[2:]}
expect = {
    "rig": ["2", "12-20", "75.0 / 80.0 / 93.3"],
    "camA": ["1", "5-5", "100.0 / 100.0 / 100.0"],
    "all": ["3", "5-20", "79.2 / 84.2 / 94.7"],
}
bad = [f"{cam}: {table.get(cam)} != {want}" for cam, want in expect.items()
       if table.get(cam, [])[:3] != want or len(set(table.get(cam, [])[2:])) != 1]
# A file that is not the study's: a message naming it and its line, exit code not 0.
p = subprocess.run([sys.executable, script, str(work / "nothing.csv")], capture_output=True, text=True)
if p.returncode == 0 or "nothing.csv" not in p.stderr:
    bad.append(f"a missing file: exit {p.returncode}, '{p.stderr.strip()}'")
print("\n".join(bad) if bad else "real-images-by-camera: 3 cameras as expected")
sys.exit(1 if bad else 0)
