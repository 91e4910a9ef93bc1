#!/usr/bin/env python3
"""Memory of soak flights (`scripts/soak.sh`): every 100 frames, the floor of the anonymous and the
total resident memory over the 100 frames before; the rise of the anonymous floor from the first
window after the warm-up to the last (bound 16 MiB); and a plot of both into OUT.PNG.

The warm-up is WARM_UP frames (environment; 300 by default). Memory rises with the heaviest
frame drawn so far, until the flight has shown its heaviest view: soak.sh flies its path there
and back several times and passes the first leg as the warm-up, so that what is judged is
growth over views already seen.

    scripts/soak_plot.py OUT.PNG LOG.JSONL...
"""
import json
import os
import sys
from pathlib import Path

from PIL import Image, ImageDraw

WINDOW = 100
WARM_UP = int(os.environ.get("WARM_UP", "300"))
BOUND_MIB = 16.0


def windows(log):
    anon, rss = [], []
    for line in open(log):
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            break  # a flight cut short ends in a partial line

        anon.append(record.get("anonymous_kib") or 0)
        rss.append(record.get("resident_kib") or 0)
    floors = []
    for start in range(0, len(anon) - WINDOW + 1, WINDOW):
        floors.append((start + WINDOW, min(anon[start:start + WINDOW]) / 1024, min(rss[start:start + WINDOW]) / 1024))
    return floors


def main():
    out, logs = sys.argv[1], sys.argv[2:]
    series, failed = [], False
    for log in logs:
        name = Path(log).parent.name
        floors = windows(log)
        if not floors:
            print(f"{name}: too few frames")
            continue
        print(f"{name}: frame, anonymous floor MiB, resident floor MiB")
        for frame, anon, rss in floors:
            print(f"  {frame:>6} {anon:8.1f} {rss:8.1f}")
        after = [f for f in floors if f[0] > WARM_UP + WINDOW] or floors
        rise = after[-1][1] - after[0][1]
        verdict = "ok" if rise <= BOUND_MIB else "OVER THE BOUND"
        failed |= rise > BOUND_MIB
        print(f"{name}: anonymous floor rose {rise:+.1f} MiB from frame {after[0][0]} to {after[-1][0]} "
              f"(bound {BOUND_MIB} MiB): {verdict}")
        series.append((name, floors))
    draw(out, series)
    sys.exit(1 if failed else 0)


def draw(out, series):
    width, height, margin = 900, 420, 60
    image = Image.new("RGB", (width, height), "white")
    d = ImageDraw.Draw(image)
    frames = max((f[-1][0] for _, f in series), default=1)
    top = max((max(x[2] for x in f) for _, f in series), default=1) * 1.1
    sx = lambda frame: margin + (width - 2 * margin) * frame / frames
    sy = lambda mib: height - margin - (height - 2 * margin) * mib / top
    d.line([(margin, height - margin), (width - margin, height - margin)], fill="black")
    d.line([(margin, margin), (margin, height - margin)], fill="black")
    for k in range(5):
        mib = top * k / 4
        d.text((4, sy(mib) - 6), f"{mib:.0f} MiB", fill="black")
    d.text((width / 2 - 20, height - margin + 20), f"frame (0 to {frames})", fill="black")
    colours = [("#1f77b4", "#aec7e8"), ("#d62728", "#ff9896"), ("#2ca02c", "#98df8a")]
    for (name, floors), (anon_colour, rss_colour) in zip(series, colours):
        for index, colour, label in [(2, rss_colour, "resident"), (1, anon_colour, "anonymous")]:
            d.line([(sx(f[0]), sy(f[index])) for f in floors], fill=colour, width=2)
            d.text((sx(floors[-1][0]) - 120, sy(floors[-1][index]) - 14), f"{name} {label}", fill=colour)
    image.save(out)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()
