"""How much of the billboard planes' rectangles tighter cards could cut (issue 19, item 2),
measured on baked impostors before building them: per plane, the texels any mip uploaded can
sample with alpha above 0 (each nonzero texel's bilinear reach, `--reach` texels of its mip around
its centre), then the area a convex card around them keeps, and the area an N × N grid of occupied
cells keeps, as fractions of the rectangles' area (summed over every plane of every cloud LOD).

    python3 scripts/card_area.py data/trade/impostors [--mips 3] [--reach 1.5] [--grid 8]

Needs Pillow.
"""
import argparse
import glob
import os
import tomllib

from PIL import Image


def convex_hull(points):
    points = sorted(set(points))
    if len(points) < 3:
        return points

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def half(points):
        chain = []
        for p in points:
            while len(chain) >= 2 and cross(chain[-2], chain[-1], p) <= 0:
                chain.pop()
            chain.append(p)
        return chain[:-1]

    return half(points) + half(list(reversed(points)))


def area(polygon):
    n = len(polygon)
    return abs(sum(polygon[i][0] * polygon[(i + 1) % n][1] - polygon[(i + 1) % n][0] * polygon[i][1] for i in range(n))) / 2


def plane_support(mips, rect, reach):
    """The uv boxes of every texel with alpha above 0 that a sample in `rect` can reach."""
    u0, v0, u1, v1 = rect
    boxes = []
    for image in mips:
        w, h = image.size
        alpha = image.getchannel("A").load()
        for y in range(max(0, int(v0 * h) - 2), min(h, int(v1 * h) + 2)):
            for x in range(max(0, int(u0 * w) - 2), min(w, int(u1 * w) + 2)):
                if alpha[x, y] > 0:
                    box = (max(u0, (x + 0.5 - reach) / w), max(v0, (y + 0.5 - reach) / h),
                           min(u1, (x + 0.5 + reach) / w), min(v1, (y + 0.5 + reach) / h))
                    if box[0] < box[2] and box[1] < box[3]:
                        boxes.append(box)
    return boxes


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("impostors")
    parser.add_argument("--mips", type=int, default=3, help="mip levels the draw samples")
    parser.add_argument("--reach", type=float, default=1.5, help="texels of its mip a texel reaches")
    parser.add_argument("--grid", type=int, default=8, help="cells per side of the occupied-cell card")
    args = parser.parse_args()
    totals = [0.0, 0.0, 0.0]
    print(f"{'model':<16} {'planes':>6} {'convex':>8} {'grid':>8}")
    for manifest in sorted(glob.glob(os.path.join(args.impostors, "*", "impostor.toml"))):
        folder = os.path.dirname(manifest)
        lods = tomllib.load(open(manifest, "rb"))["lods"]
        model = [0.0, 0.0, 0.0]
        planes = 0
        for k, lod in enumerate(lods):
            mips = [Image.open(os.path.join(folder, f"lod{k}_mip{m}.png")).convert("RGBA") for m in range(args.mips)]
            for plane in lod["planes"]:
                rect = (*plane["uv_min"], *plane["uv_max"])
                u0, v0, u1, v1 = rect
                rect_area = (u1 - u0) * (v1 - v0)
                boxes = plane_support(mips, rect, args.reach)
                corners = [(b[i], b[j]) for b in boxes for i in (0, 2) for j in (1, 3)]
                g = args.grid
                cells = {(cx, cy) for b in boxes
                         for cx in range(int((b[0] - u0) / (u1 - u0) * g), min(g - 1, int((b[2] - u0) / (u1 - u0) * g)) + 1)
                         for cy in range(int((b[1] - v0) / (v1 - v0) * g), min(g - 1, int((b[3] - v0) / (v1 - v0) * g)) + 1)}
                model[0] += rect_area
                model[1] += area(convex_hull(corners)) if len(corners) > 2 else 0.0
                model[2] += rect_area * len(cells) / (g * g)
                planes += 1
        print(f"{os.path.basename(folder):<16} {planes:>6} {model[1] / model[0]:>8.3f} {model[2] / model[0]:>8.3f}")
        totals = [t + m for t, m in zip(totals, model)]
    print(f"{'all':<16} {'':>6} {totals[1] / totals[0]:>8.3f} {totals[2] / totals[0]:>8.3f}")


if __name__ == "__main__":
    main()
