#!/usr/bin/env python3
"""The slices of one slicing of a baked impostor side by side, then composited front over back.

    terramp-data bake --model ../shared/data/models/Tree_1.glb --out /tmp/sl --slicings 6x5
    python3 scripts/slices_figure.py /tmp/sl/Tree_1 0 docs/slicings_tree1.png

Reads the folder's impostor.toml (its `slicing` table) and slicing_mip0.png; slicing `i`'s slices
are planes i·slices .. i·slices + slices − 1, the last nearest the side they face. Needs Pillow.
"""
import sys
import tomllib

from PIL import Image


def main(folder: str, slicing: int, out: str) -> None:
    with open(f"{folder}/impostor.toml", "rb") as f:
        manifest = tomllib.load(f)
    table = manifest.get("slicing")
    if table is None:
        sys.exit(f"{folder}: no slicing baked (terramp-data bake --slicings 6x5)")
    n = table["slices"]
    if not 0 <= slicing < table["orientations"]:
        sys.exit(f"slicing {slicing}: the impostor has {table['orientations']}")
    atlas = Image.open(f"{folder}/slicing_mip0.png").convert("RGBA")
    width, height = atlas.size
    planes = table["lod"]["planes"][slicing * n:(slicing + 1) * n]
    tiles = []
    for p in planes:
        box = (round(p["uv_min"][0] * width), round(p["uv_min"][1] * height),
               round(p["uv_max"][0] * width), round(p["uv_max"][1] * height))
        tiles.append(atlas.crop(box))
    w, h = tiles[0].size
    background = (200, 205, 215, 255)
    sheet = Image.new("RGBA", ((n + 1) * (w + 8) + 8, h + 16), (255, 255, 255, 255))
    composite = Image.new("RGBA", (w, h), background)
    for j, tile in enumerate(tiles):
        cell = Image.new("RGBA", (w, h), background)
        cell.alpha_composite(tile.resize((w, h)))
        sheet.paste(cell, (8 + j * (w + 8), 8))
        composite.alpha_composite(tile.resize((w, h)))
    sheet.paste(composite, (8 + n * (w + 8), 8))
    sheet.convert("RGB").save(out)
    print(f"wrote {out}: {n} slices of slicing {slicing} and their composite, {w}x{h} texels each")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3])
