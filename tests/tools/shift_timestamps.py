#!/usr/bin/env python3
"""Copies a dataset folder and shifts every timestamp (cam0, wheel0, ground_truth) so that the
last one is the largest int64, 9223372036854775807 ns: stamps at the limit of their type.
  shift_timestamps.py DATASET OUT"""
import shutil
import sys
from pathlib import Path

src, out = Path(sys.argv[1]), Path(sys.argv[2])
shutil.rmtree(out, ignore_errors=True)
shutil.copytree(src, out)
csvs = [out / "cam0/data.csv", out / "wheel0/data.csv"] + [
    p for p in (out / "ground_truth/poses.csv", out / "ground_truth/lines.csv") if p.exists()]
last = max(int(l.split(",")[0]) for f in csvs[:2] for l in f.read_text().splitlines()[1:] if l.strip())
shift = 2**63 - 1 - last
for f in csvs:
    lines = f.read_text().splitlines()
    rows = [lines[0]] + [str(int(l.split(",")[0]) + shift) + "," + l.split(",", 1)[1]
                         for l in lines[1:] if l.strip()]
    f.write_text("\n".join(rows) + "\n")
