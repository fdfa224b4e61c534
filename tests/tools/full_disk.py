#!/usr/bin/env python3
"""An output folder on a full disk: a small tmpfs, filled up, in a private mount namespace
(`unshare -m`, which needs root, as CI runs; exit 77, a skip, where it cannot be had). Each of
`track`, `calibrate`, `simulate` and `import` writing there must exit 2 with a message naming
the output, and leave no output under its final name that is partial (scripts/kill-test's
checks).
  full_disk.py OMNIVERT DATASET RECORDING WORK"""

import importlib.machinery
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
kill_test = importlib.machinery.SourceFileLoader("kill_test", str(ROOT / "scripts" / "kill-test")).load_module()


def main():
    if len(sys.argv) == 6 and sys.argv[1] == "--inside":
        return inside(*sys.argv[2:])
    ov, data, recording, work = sys.argv[1:5]
    Path(work).mkdir(parents=True, exist_ok=True)
    probe = subprocess.run(["unshare", "-m", "true"], capture_output=True)
    if probe.returncode != 0:
        print("no private mount namespace here (needs root): skipped")
        return 77
    r = subprocess.run(["unshare", "-m", sys.executable, __file__, "--inside", ov, data, recording, work])
    return r.returncode


def inside(ov, data, recording, work):
    disk = Path(work) / "disk"
    disk.mkdir(exist_ok=True)
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(disk)], check=True)
    # Leave 16 KiB free: the outputs' first bytes fit, the rest does not.
    with open(disk / "filler", "wb") as f:
        f.write(b"\0" * (240 * 1024))
    runs = {
        "track": [ov, "track", data, "--out", str(disk / "track")],
        "calibrate": [ov, "calibrate", data, "--out", str(disk / "cal")],
        "simulate": [ov, "simulate", "--frames", "3", "--out", str(disk / "sim")],
        "import": [ov, "import", recording, "--out", str(disk / "imp"),
                   "--image-topic", "/camera/image_raw", "--odometry-topic", "/odom",
                   "--wheel-base", "0.5"],
    }
    failed = 0
    for name, argv in runs.items():
        r = subprocess.run(argv, capture_output=True, text=True, timeout=600)
        out = Path(argv[argv.index("--out") + 1])
        problems = kill_test.check_tree(out) if out.exists() else []
        message = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
        ok = r.returncode == 2 and str(disk) in message and not problems
        print(f"{name}: exit {r.returncode}: {message}" + "".join(f"\n  {p}" for p in problems))
        failed += not ok
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
