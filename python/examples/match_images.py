#!/usr/bin/env python3
"""Extracts and matches the vertical lines of two omnidirectional images.

  match_images.py IMAGE1 IMAGE2 [--sensor cam0/sensor.yaml] [--out matches.png]

Each image's lines and 192-D descriptors come from omnivert.extract (the mirror centre is
estimated on each image unless --sensor gives it); each line of IMAGE1 is matched to its
nearest line of IMAGE2 by the paper's three tests (omnivert.match, eq. 8-10). Prints the
matches and draws both images with the matched lines in one colour per match.
"""
import argparse
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import omnivert  # noqa: E402


def draw(ax, image, f, colours):
    ax.imshow(image[..., ::-1] if image.ndim == 3 else image, cmap="gray")
    cx, cy = f.center
    for line, colour in zip(f.lines, colours):
        a = line.image_angle
        ax.plot([cx + line.r_inner * math.cos(a), cx + line.r_outer * math.cos(a)],
                [cy + line.r_inner * math.sin(a), cy + line.r_outer * math.sin(a)],
                color=colour or "0.6", linewidth=2 if colour else 1)
    ax.set_axis_off()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("image1")
    ap.add_argument("image2")
    ap.add_argument("--sensor", help="cam0/sensor.yaml of the camera (optional)")
    ap.add_argument("--out", default="matches.png")
    a = ap.parse_args()
    images = [omnivert.read_image(p) for p in (a.image1, a.image2)]
    try:
        f1, f2 = (omnivert.extract(im, a.sensor) for im in images)
    except omnivert.InputError as e:
        print("omnivert:", e)
        return 2
    m = omnivert.match(f1.descriptors, f2.descriptors)
    print(f"{len(f1)} and {len(f2)} lines; {int(m['accepted'].sum())} matched")
    cmap = plt.get_cmap("tab20")
    c1, c2 = [None] * len(f1), [None] * len(f2)
    for i, (j, ok) in enumerate(zip(m["best"], m["accepted"])):
        if ok:
            c1[i] = c2[j] = cmap(i % 20)
            print(f"line {i} (bearing {math.degrees(f1.lines[i].bearing):7.2f} deg) -> line {j} "
                  f"({math.degrees(f2.lines[j].bearing):7.2f} deg), distance {m['distance'][i]:.3f}")
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    draw(axes[0], images[0], f1, c1)
    draw(axes[1], images[1], f2, c2)
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print("picture:", a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
