#!/usr/bin/env python3
"""Calibrates a simulated run and plots the filter's convergence (the paper's Fig. 25).

  calibrate_simulated.py [--out DIR] [--world corridor] [--trajectory paper] [--seed 1]

Renders the run with omnivert.simulate (the paper's experiment by default: 2.3 m straight,
then 180 degrees on the spot), calibrates it with omnivert.calibrate_dataset (filter and batch
refinement) and draws phi, rho and psi with their 3-sigma bands against the frame, the
simulator's truth dashed, into DIR/convergence-python.png.
"""
import argparse
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import omnivert  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="python-example")
    ap.add_argument("--world", default="corridor")
    ap.add_argument("--trajectory", default="paper")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    run = os.path.join(a.out, "run")
    s = omnivert.simulate(run, world=a.world, trajectory=a.trajectory, seed=a.seed, force=True)
    print(f"simulated {s['frames']} frames, {s['distance']:.2f} m driven")

    r = omnivert.calibrate_dataset(run, os.path.join(a.out, "calib"), refine=True)
    print(r.brief_report())
    h, truth = r.calibration.history, r.truth
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 7))
    for ax, key, scale, unit in zip(axes, ("phi", "rho", "psi"), (180 / math.pi, 1000, 180 / math.pi),
                                    ("deg", "mm", "deg")):
        value, sigma = h[key] * scale, h["sigma_" + key] * scale
        ax.plot(h["frame"], value, label="filter")
        ax.fill_between(h["frame"], value - 3 * sigma, value + 3 * sigma, alpha=0.3,
                        label="3 sigma")
        if truth is not None:
            ax.axhline(getattr(truth, key) * scale, linestyle="--", color="k", label="truth")
        ax.set_ylabel(f"{key} [{unit}]")
    axes[0].legend(loc="upper right")
    axes[-1].set_xlabel("frame")
    fig.tight_layout()
    picture = os.path.join(a.out, "convergence-python.png")
    fig.savefig(picture, dpi=100)
    print("convergence plot:", picture)
    return 0 if r.observable else 3


if __name__ == "__main__":
    raise SystemExit(main())
