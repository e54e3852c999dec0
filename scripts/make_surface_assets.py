#!/usr/bin/env python3
"""Textures for the surface-BSDF scenes (scenes/surfaces_*.xml) and image-format test files.

scenes/textures/planks.jpg   256x256 sRGB JPEG (quality 95, no chroma subsampling): a wood-like
                              plank pattern, used as a roughplastic diffuse_reflectance.
scenes/textures/dots.png      128x128 8-bit grey PNG: round dots, used as a mask opacity and as a
                              roughconductor roughness (raw).
tests/data/formats/           the same small 8x6 test pattern as PNG, JPEG, BMP, TGA (8-bit, RGB and
                              grey), RGBE (.hdr) and PFM (colour and grey, both byte orders), plus
                              formats.json: Mitsuba 3.9.1's decoded linear values of each (what its
                              `bitmap` texture sees, with and without `raw`).

Usage: python3 scripts/make_surface_assets.py
"""
import json
import os

import numpy as np
from PIL import Image

import common

ROOT = common.ROOT


def planks():
    n = 256
    y, x = np.mgrid[0:n, 0:n].astype(np.float64) / n
    plank = np.floor(y * 4)
    offset = (plank * 0.37) % 1.0
    grain = 0.5 + 0.5 * np.sin(2 * np.pi * (x * 3 + offset) + 6 * np.sin(2 * np.pi * (y * 4 + x * 0.5)))
    base = np.stack([0.55 + 0.2 * grain, 0.35 + 0.15 * grain, 0.18 + 0.08 * grain], -1)
    base *= (0.8 + 0.2 * ((plank * 0.61) % 1.0))[..., None]
    seam = (np.abs((y * 4) % 1.0 - 0.5) > 0.47)
    base[seam] *= 0.35
    img = (np.clip(base, 0, 1) * 255 + 0.5).astype(np.uint8)
    Image.fromarray(img, "RGB").save(os.path.join(ROOT, "scenes", "textures", "planks.jpg"), quality=95,
                                     subsampling=0)


def dots():
    n = 128
    y, x = np.mgrid[0:n, 0:n].astype(np.float64) / n
    d = np.hypot((x * 4) % 1.0 - 0.5, (y * 4) % 1.0 - 0.5)
    v = np.clip((0.38 - d) * 25, 0, 1) * 0.9 + 0.05
    Image.fromarray((v * 255 + 0.5).astype(np.uint8), "L").save(os.path.join(ROOT, "scenes", "textures", "dots.png"))


def pattern(w=8, h=6):
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    return np.stack([x / (w - 1), y / (h - 1), ((x + 2 * y) % 5) / 4.0], -1)


def write_pfm(path, img, little_endian):
    h, w = img.shape[:2]
    grey = img.ndim == 2
    with open(path, "wb") as fh:
        fh.write(b"Pf\n" if grey else b"PF\n")
        fh.write(b"%d %d\n" % (w, h))
        fh.write(b"-1.0\n" if little_endian else b"1.0\n")
        rows = img[::-1].astype("<f4" if little_endian else ">f4")
        fh.write(rows.tobytes())


def formats():
    mi, _ = common.setup_mitsuba("scalar_rgb")
    out_dir = os.path.join(ROOT, "tests", "data", "formats")
    os.makedirs(out_dir, exist_ok=True)
    p = pattern()
    rgb8 = (p * 255 + 0.5).astype(np.uint8)
    grey8 = (p[..., 0] * 255 + 0.5).astype(np.uint8)
    Image.fromarray(rgb8, "RGB").save(os.path.join(out_dir, "rgb.png"))
    Image.fromarray(rgb8, "RGB").save(os.path.join(out_dir, "rgb.jpg"), quality=100, subsampling=0)
    Image.fromarray(grey8, "L").save(os.path.join(out_dir, "grey.jpg"), quality=100)
    Image.fromarray(rgb8, "RGB").save(os.path.join(out_dir, "rgb.bmp"))
    Image.fromarray(rgb8, "RGB").save(os.path.join(out_dir, "rgb.tga"))
    Image.fromarray(grey8, "L").save(os.path.join(out_dir, "grey.tga"))
    hdr = (p * np.array([4.0, 0.5, 20.0])).astype(np.float32)
    mi.Bitmap(hdr).write(os.path.join(out_dir, "rgb.hdr"))
    write_pfm(os.path.join(out_dir, "rgb_le.pfm"), hdr, True)
    write_pfm(os.path.join(out_dir, "rgb_be.pfm"), hdr, False)
    write_pfm(os.path.join(out_dir, "grey.pfm"), hdr[..., 2].copy(), True)
    expected = {}
    for name in sorted(os.listdir(out_dir)):
        if name.endswith(".json"):
            continue
        for raw in [False, True]:
            t = mi.load_dict({"type": "bitmap", "filename": os.path.join(out_dir, name), "raw": raw,
                              "filter_type": "nearest"})
            si = mi.SurfaceInteraction3f()
            bmp = mi.Bitmap(os.path.join(out_dir, name))
            w, h = bmp.size()
            vals = []
            for yy in range(h):
                for xx in range(w):
                    si.uv = [(xx + 0.5) / w, (yy + 0.5) / h]
                    v = t.eval(si)
                    vals.append([float(v[0]), float(v[1]), float(v[2])])
            expected["%s%s" % (name, ":raw" if raw else "")] = {"width": w, "height": h, "rgb": vals}
    # Mean linear colour of the scenes' JPEG texture as Mitsuba decodes it (JPEG decoders may differ
    # by a level here and there; the mean must not).
    planks = mi.Bitmap(os.path.join(ROOT, "scenes", "textures", "planks.jpg")).convert(
        mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    expected["planks_mean"] = [float(v) for v in np.array(planks).reshape(-1, 3).astype(np.float64).mean(0)]
    with open(os.path.join(out_dir, "formats.json"), "w") as fh:
        json.dump(expected, fh, separators=(",", ":"))
    print("wrote %d decoded images" % len(expected))


if __name__ == "__main__":
    planks()
    dots()
    formats()
