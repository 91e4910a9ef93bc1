#!/usr/bin/env python3
"""NDVI of nc's Landsat 7 (band 4 against band 3) under each land-cover class of nc's land use, and
within the forest class by brightness: the figures docs/building.md quotes for `--nir-band`.

    python3 scripts/ndvi_by_class.py [../shared/data/nc]

Needs numpy and tifffile (scripts/requirements-docs.txt). Each Landsat pixel (28.5 m) is classed
by the land-use cell (10 m) under its centre; both files are in EPSG:32119, north up."""
import sys

import numpy as np
import tifffile

nc = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/nc"
landsat = tifffile.TiffFile(f"{nc}/landsat_multiband.tif")
landuse = tifffile.TiffFile(f"{nc}/landuse_r.tif")


def frame(tiff):
    tags = tiff.pages[0].tags
    tie, scale = tags["ModelTiepointTag"].value, tags["ModelPixelScaleTag"].value
    return tie[3], tie[4], scale[0]


bands = landsat.asarray().astype(float)
blue, green, red, nir = (bands[..., k] for k in range(4))
valid = (red > -9999) & (nir > -9999) & (red + nir > 0)
ndvi = np.where(valid, (nir - red) / np.where(valid, nir + red, 1.0), np.nan)
codes = landuse.asarray()
(x0, y0, px), (lx0, ly0, lpx) = frame(landsat), frame(landuse)
rows, cols = np.mgrid[0 : ndvi.shape[0], 0 : ndvi.shape[1]]
east, north = x0 + (cols + 0.5) * px, y0 - (rows + 0.5) * px
col, row = ((east - lx0) / lpx).astype(int), ((ly0 - north) / lpx).astype(int)
inside = (col >= 0) & (col < codes.shape[1]) & (row >= 0) & (row < codes.shape[0]) & valid
classes = np.full(ndvi.shape, 255)
classes[inside] = codes[row[inside], col[inside]]
names = {1: "developed", 2: "agriculture", 3: "herbaceous", 4: "shrubland", 5: "forest", 6: "water", 7: "sediment"}
print("class         pixels   NDVI 5th / 25th / median / 75th / 95th percentile")
for code, name in names.items():
    values = ndvi[classes == code]
    if values.size:
        p = np.percentile(values, [5, 25, 50, 75, 95])
        print(f"{name:<12} {values.size:>7}   " + " / ".join(f"{v:.2f}" for v in p))
forest = classes == 5
brightness = red + green + blue
for label, mask in [
    ("forest, brightest tenth", forest & (brightness > np.percentile(brightness[forest], 90))),
    ("forest, darker half", forest & (brightness < np.percentile(brightness[forest], 50))),
]:
    print(f"{label:<24} median NDVI {np.median(ndvi[mask]):.2f} ({mask.sum()} pixels)")
