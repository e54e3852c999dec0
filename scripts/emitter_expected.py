#!/usr/bin/env python3
"""Reference values from Mitsuba 3 for snee's emitter and texture tests.

Writes the small test images into tests/data/ and, for each case, the inputs and Mitsuba's outputs
(rounded to 10 significant digits) into tests/data/emitters.json (read by the emitter tests) and
tests/data/textures.json (read by the texture tests). Each table's key names what it holds; "d" is a
direction towards the emitter, "ref" a reference point, matrices are row-major as Mitsuba prints them.

Requires: mitsuba (3.9), numpy, pillow.   Usage: python3 scripts/emitter_expected.py [--help]
"""
import argparse
import math
import os

import numpy as np

import common

DATA = common.TEST_DATA


def num(x):
    """A number as the tests read it: 10 significant digits (round-trip exact for f32)."""
    return common.rounded(x, 10)


def vec(v):
    return [num(x) for x in v]


def mat_rows(t):
    m = np.array(t.matrix, dtype=np.float64)
    return [vec(m[i]) for i in range(4)]


def make_images(mi):
    os.makedirs(DATA, exist_ok=True)
    from PIL import Image

    # Environment map: 12x6, smooth sky with a bright sun, distinct per pixel; saved by Mitsuba
    # as half-float PIZ (its default), channels stored B, G, R.
    w, h = 12, 6
    env = np.zeros((h, w, 3), np.float32)
    for y in range(h):
        for x in range(w):
            env[y, x] = [0.1 + 0.05 * x + 0.2 * y, 0.3 + 0.1 * y, 1.0 + 0.02 * x * y]
    env[1, 3] = [40.0, 30.0, 20.0]
    bmp = mi.Bitmap(env, pixel_format=mi.Bitmap.PixelFormat.RGB)
    bmp = bmp.convert(component_format=mi.Struct.Type.Float16)
    bmp.write(os.path.join(DATA, "envmap_half_piz.exr"))

    # 8-bit sRGB PNG, 4x3.
    a = np.zeros((3, 4, 3), np.uint8)
    for y in range(3):
        for x in range(4):
            a[y, x] = [x * 60 + 10, y * 100 + 20, (x * y * 37 + 5) % 256]
    Image.fromarray(a).save(os.path.join(DATA, "tex_rgb8.png"))

    # Float32 EXRs written by Mitsuba (PIZ): luminance only, and RGBA.
    y_img = np.array([[0.25 * (x + 1) + y for x in range(3)] for y in range(2)], np.float32)[..., None]
    mi.Bitmap(y_img, pixel_format=mi.Bitmap.PixelFormat.Y).write(os.path.join(DATA, "tex_y_float.exr"))
    rgba = np.zeros((2, 3, 4), np.float32)
    for y in range(2):
        for x in range(3):
            rgba[y, x] = [0.1 * x, 0.2 * y + 0.05, 0.3, 0.5 + 0.1 * x]
    mi.Bitmap(rgba, pixel_format=mi.Bitmap.PixelFormat.RGBA).write(os.path.join(DATA, "tex_rgba_float.exr"))
    return env, a


def emitter_values(mi):
    out = {}
    # ---- envmap eval: envmap_half_piz.exr, scale 1.5, to_world = rotate(y, 30) . rotate(x, 20) ----
    to_world = mi.ScalarTransform4f().rotate([0, 1, 0], 30).rotate([1, 0, 0], 20)
    dirs = [[0, 0, 1], [0, 1, 0], [1, 0, 0], [-0.3, 0.5, 0.8], [0.6, -0.7, 0.2], [0.1, 0.95, -0.2],
            [-0.9, 0.1, -0.3], [0.2, -0.1, -0.97], [0.35, 0.82, 0.41]]
    dirs = [list(np.array(d) / np.linalg.norm(d)) for d in dirs]
    env = mi.load_dict({"type": "envmap", "filename": os.path.join(DATA, "envmap_half_piz.exr"),
                        "scale": 1.5, "to_world": to_world})
    out["env_to_world"] = mat_rows(to_world)
    out["env_eval"] = []
    for d in dirs:
        si = mi.SurfaceInteraction3f()
        si.wi = -mi.Vector3f(d)
        out["env_eval"].append({"d": vec(d), "value": vec(env.eval(si))})
    # tex_rgb8.png as an envmap (sRGB -> linear), identity transform.
    # (Not straight up: at the pole u depends on the sign of a zero in Mitsuba's arithmetic.)
    env_png = mi.load_dict({"type": "envmap", "filename": os.path.join(DATA, "tex_rgb8.png")})
    out["env_png_eval"] = []
    for d in [dirs[0]] + dirs[2:6]:
        si = mi.SurfaceInteraction3f()
        si.wi = -mi.Vector3f(d)
        out["env_png_eval"].append({"d": vec(d), "value": vec(env_png.eval(si))})

    # ---- spot: cutoff 30, beam 12, intensity (2,3,4), to_world = look_at([1,2,3] -> [1,0,3.5], up z) ----
    spot_to_world = mi.ScalarTransform4f().look_at(origin=[1, 2, 3], target=[1, 0, 3.5], up=[0, 0, 1])
    spot = mi.load_dict({"type": "spot", "cutoff_angle": 30.0, "beam_width": 12.0, "to_world": spot_to_world,
                         "intensity": mi.ScalarColor3f(2.0, 3.0, 4.0)})
    spot_default = mi.load_dict({"type": "spot"})
    out["spot_to_world"] = mat_rows(spot_to_world)
    out["spot_weight"] = []
    for ang in [0, 5, 11.9, 12.5, 15, 20, 25, 29.5, 31, 60]:
        for phi in [0.0, 1.3]:
            a, p = math.radians(ang), phi
            local = np.array([math.sin(a) * math.cos(p), math.sin(a) * math.sin(p), math.cos(a)])
            dist = 1.7 + ang / 50
            world_dir = np.array(spot_to_world @ mi.ScalarVector3f(local))
            ref = np.array([1, 2, 3]) + dist * world_dir
            it = mi.Interaction3f()
            it.p = mi.Point3f(ref)
            ds, wgt = spot.sample_direction(it, mi.Point2f(0.5, 0.5))
            out["spot_weight"].append({"ref": vec(ref), "weight": vec(wgt)})
    # spot with defaults (cutoff 20, beam 15) at the origin, along +z
    out["spot_default_weight"] = []
    for ang in [0, 10, 14.9, 16, 18, 19.9, 21]:
        a = math.radians(ang)
        ref = 2.0 * np.array([math.sin(a), 0, math.cos(a)])
        it = mi.Interaction3f()
        it.p = mi.Point3f(ref)
        ds, wgt = spot_default.sample_direction(it, mi.Point2f(0.5, 0.5))
        out["spot_default_weight"].append({"ref": vec(ref), "weight": vec(wgt)})
    # spot: cutoff 40 (beam 30), texture tex_rgb8.png, to_world = spot_to_world
    spot_tex = mi.load_dict({"type": "spot", "cutoff_angle": 40.0, "to_world": spot_to_world,
                             "texture": {"type": "bitmap", "filename": os.path.join(DATA, "tex_rgb8.png")}})
    out["spot_textured_weight"] = []
    for ang, phi in [(0, 0), (10, 0.3), (20, 2.0), (25, -1.0), (33, 4.0), (38, 1.0), (45, 0)]:
        a = math.radians(ang)
        local = np.array([math.sin(a) * math.cos(phi), math.sin(a) * math.sin(phi), math.cos(a)])
        ref = np.array([1, 2, 3]) + 2.5 * np.array(spot_to_world @ mi.ScalarVector3f(local))
        it = mi.Interaction3f()
        it.p = mi.Point3f(ref)
        ds, wgt = spot_tex.sample_direction(it, mi.Point2f(0.5, 0.5))
        out["spot_textured_weight"].append({"ref": vec(ref), "weight": vec(wgt)})

    # ---- point, directional, constant (sample_direction from (0.3,-0.2,0.5)) ----
    it = mi.Interaction3f()
    it.p = mi.Point3f(0.3, -0.2, 0.5)
    point = mi.load_dict({"type": "point", "position": [1, 2, 3], "intensity": mi.ScalarColor3f(5, 6, 7)})
    ds, wgt = point.sample_direction(it, mi.Point2f(0.5, 0.5))
    out["point"] = {"d": vec(ds.d), "dist": num(ds.dist), "weight": vec(wgt)}
    dl = mi.load_dict({"type": "directional", "direction": [1, -2, 0.5], "irradiance": mi.ScalarColor3f(3, 2, 1)})
    ds, wgt = dl.sample_direction(it, mi.Point2f(0.5, 0.5))
    out["directional"] = {"d": vec(ds.d), "weight": vec(wgt)}
    const = mi.load_dict({"type": "constant", "radiance": mi.ScalarColor3f(0.5, 1, 2)})
    ds, wgt = const.sample_direction(it, mi.Point2f(0.3, 0.7))
    out["constant"] = {"d": vec(ds.d), "pdf": num(ds.pdf), "weight": vec(wgt)}
    return out


def texture_values(mi):
    out = {}
    uvs = [[0.1, 0.1], [0.6, 0.3], [-0.3, 1.2], [0.125, 1 / 6], [0.99, 0.51], [1.7, -0.45], [0.5, 0.5]]
    out["uvs"] = [vec(uv) for uv in uvs]
    si = mi.SurfaceInteraction3f()

    def values(t, at):
        vals = []
        for uv in at:
            si.uv = mi.Point2f(uv)
            vals.append(vec(t.eval(si)))
        return vals

    cb_uv = mi.ScalarTransform4f().scale([3, 2, 1]).translate([0.1, 0.2, 0])
    cbs = [("default", mi.load_dict({"type": "checkerboard"})),
           ("custom", mi.load_dict({"type": "checkerboard", "color0": mi.ScalarColor3f(0.9, 0.5, 0.1),
                                   "color1": mi.ScalarColor3f(0.05, 0.1, 0.7), "to_uv": cb_uv}))]
    out["checker_to_uv"] = mat_rows(cb_uv)
    cb_uvs = uvs + [[0.25, 0.75], [0.75, 0.75], [0.5, 0.25], [0.0, 0.0], [0.5, 0.5], [0.50001, 0.49999]]
    out["checker_uvs"] = [vec(uv) for uv in cb_uvs]
    for name, t in cbs:
        out[f"checker_{name}"] = values(t, cb_uvs)
    png = os.path.join(DATA, "tex_rgb8.png")
    tex_uv = mi.ScalarTransform4f().scale([2, 0.5, 1]).translate([0.3, 0, 0])
    out["bitmap_uv_matrix"] = mat_rows(tex_uv)
    cases = []
    for ft in ["bilinear", "nearest"]:
        for wm in ["repeat", "mirror", "clamp"]:
            cases.append((f"{ft}_{wm}", {"filter_type": ft, "wrap_mode": wm}))
    cases.append(("raw", {"raw": True}))
    cases.append(("to_uv", {"to_uv": tex_uv}))
    # bitmap tex_rgb8.png with the parameters in the key (to_uv = bitmap_uv_matrix); "mean" is t.mean().
    for name, extra in cases:
        t = mi.load_dict({"type": "bitmap", "filename": png, **extra})
        out[f"bitmap_{name}"] = {"mean": num(t.mean()), "values": values(t, uvs)}
    for fname in ["tex_y_float.exr", "tex_rgba_float.exr"]:
        t = mi.load_dict({"type": "bitmap", "filename": os.path.join(DATA, fname)})
        out["bitmap_" + fname.split(".")[0]] = {"mean": num(t.mean()), "values": values(t, uvs)}
    return out


def main():
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    mi, _ = common.setup_mitsuba("scalar_rgb")
    make_images(mi)
    print(f"wrote images to {DATA}")
    for name, values in [("emitters.json", emitter_values(mi)), ("textures.json", texture_values(mi))]:
        values = {"mitsuba_version": mi.__version__, "variant": "scalar_rgb", **values}
        print(f"wrote {common.write_test_json(name, values, indent=1)}")


if __name__ == "__main__":
    main()
