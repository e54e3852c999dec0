#!/usr/bin/env python3
"""Reference values from Mitsuba 3 for the sensor and film tests: writes tests/data/sensor.json.

For several perspective-camera configurations this calls Mitsuba's
`sensor.sample_ray(time, wavelength_sample, position_sample, aperture_sample)` and prints the
ray origin, direction and length, together with the camera's `to_world` matrix as Mitsuba built it
(so the Rust test does not depend on our own `look_at`) ("cameras"). Mitsuba's `position_sample` is
relative to the film's crop window; the stored `pos` is the same point in pixels of the full film
(`crop_offset + position_sample * crop_size`), which is what `Camera::sample_ray` takes.
It also stores `rfilter.eval(x)` for the gaussian, tent and box filters ("filters") and the weights
and developed values of an ImageBlock splatted with a few samples, per filter ("image_block").
Numbers keep 10 significant digits (8 for the image blocks).

Usage: python3 scripts/sensor_expected.py            (needs `pip install mitsuba==3.9.1`)
"""
import argparse

import common

mi = None  # the mitsuba module, set in main()

CONFIGS = [
    # name, sensor parameters (besides film and to_world), film (w, h, crop), look_at (origin, target, up) or None
    ("fov_x_default", {"fov": 45.0}, (64, 48, None), None),
    ("focal_default", {}, (768, 576, None), ((0, 0, 5), (0, 0, 0), (0, 1, 0))),
    ("focal_35mm_tall", {"focal_length": "35mm"}, (40, 90, None), ((1, 2, 3), (0, 0.5, 0), (0, 0, 1))),
    ("fov_y", {"fov": 30.0, "fov_axis": "y"}, (100, 50, None), ((2, -1, 4), (0, 0, 0), (0, 1, 0))),
    ("fov_diagonal", {"fov": 60.0, "fov_axis": "diagonal"}, (30, 20, None), None),
    ("fov_smaller_tall", {"fov": 50.0, "fov_axis": "smaller"}, (20, 30, None), ((0, 3, 0), (0, 0, 0), (0, 0, -1))),
    ("fov_larger_tall", {"fov": 50.0, "fov_axis": "larger"}, (20, 30, None), None),
    ("crop_window", {"fov": 40.0, "near_clip": 0.5, "far_clip": 200.0}, (64, 48, (10, 6, 20, 30)),
     ((-3, 1, 2), (0.5, 0, 0), (0, 1, 0))),
    ("principal_point", {"fov": 40.0, "principal_point_offset_x": 0.1, "principal_point_offset_y": -0.2},
     (64, 48, (8, 4, 32, 24)), None),
]

# Crop-relative position samples.
SAMPLES = [(0.5, 0.5), (0.0, 0.0), (1.0, 1.0), (0.25, 0.8), (0.9, 0.1)]


def num(x, digits=10):
    """A number rounded as the tests read it: `digits` significant digits."""
    return common.rounded(x, digits)


def vec(v):
    return [num(x) for x in v]


def cameras():
    out = []
    for name, params, (w, h, crop), look in CONFIGS:
        film = {"type": "hdrfilm", "width": w, "height": h}
        if crop is not None:
            film.update(crop_offset_x=crop[0], crop_offset_y=crop[1], crop_width=crop[2], crop_height=crop[3])
        d = {"type": "perspective", "film": film, **params}
        if look is not None:
            d["to_world"] = mi.ScalarTransform4f().look_at(origin=look[0], target=look[1], up=look[2])
        sensor = mi.load_dict(d)
        m = mi.traverse(sensor)["to_world"].matrix
        rows = [[float(m[r][c]) for c in range(4)] for r in range(4)]
        co = crop[:2] if crop else (0, 0)
        cs = crop[2:] if crop else (w, h)
        rays = []
        for s in SAMPLES:
            ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(*s), mi.Point2f(0.5, 0.5))
            pos = (co[0] + s[0] * cs[0], co[1] + s[1] * cs[1])
            rays.append({"pos": vec(pos), "o": vec(ray.o), "d": vec(ray.d), "maxt": num(ray.maxt)})
        out.append({"name": name, "params": params, "film": {"width": w, "height": h, "crop": crop},
                    "look_at": look, "to_world_rows": [vec(r) for r in rows], "rays": rays})
    return out


FILTERS = [{"type": "gaussian"}, {"type": "gaussian", "stddev": 0.3}, {"type": "gaussian", "stddev": 1.0},
           {"type": "tent"}, {"type": "tent", "radius": 1.5}, {"type": "box"}]


def filters():
    xs = [0.0, 0.1, 0.25, 0.49, 0.5, 0.75, 1.0, 1.2, 1.5, 1.9, 1.99, 2.0, 2.3, 2.5, 3.0, 3.5, -0.3, -1.1]
    out = []
    for d in FILTERS:
        f = mi.load_dict(d)
        out.append({"filter": d, "radius": float(f.radius()), "border": int(f.border_size()),
                    "values": [[float(f"{x:.3}"), num(f.eval(x))] for x in xs]})
    return out


# ImageBlock test: interior offset/size, and samples (x, y, value); some fall outside the block.
BLOCK_OFFSET, BLOCK_SIZE = (10, 20), (6, 5)
BLOCK_SAMPLES = [(12.3, 22.7, 1.0), (13.9, 21.2, 2.0), (10.05, 20.5, 3.0), (15.99, 24.99, 4.0),
                 (9.2, 23.4, 5.0), (14.5, 26.1, 6.0), (12.5, 22.5, 7.0), (17.3, 19.6, 8.0)]


def image_blocks():
    """Splat BLOCK_SAMPLES with Mitsuba's ImageBlock as the llvm variants render (eval, no table):
    per filter the weights and the developed values of the interior pixels, row-major."""
    import numpy as np
    common.setup_mitsuba("llvm_ad_rgb")
    xs, ys, vs = (mi.Float([s[i] for s in BLOCK_SAMPLES]) for i in range(3))
    blocks = []
    for d in [FILTERS[0], FILTERS[4], FILTERS[2], FILTERS[5]]:
        f = mi.load_dict(d)
        b = mi.ImageBlock(size=BLOCK_SIZE, offset=BLOCK_OFFSET, channel_count=2, rfilter=f, border=False,
                          normalize=False, coalesce=True)
        b.put(pos=mi.Point2f(xs, ys), values=[vs, mi.Float(1.0)])
        t = np.array(b.tensor())
        w = t[:, :, 1].ravel()
        v = np.where(w != 0, t[:, :, 0].ravel() / np.where(w != 0, w, 1), 0)
        blocks.append({"filter": d, "weights": [num(x, 8) for x in w], "values": [num(x, 8) for x in v]})
    return {"offset": BLOCK_OFFSET, "size": BLOCK_SIZE, "samples": BLOCK_SAMPLES, "blocks": blocks}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default scalar_rgb)")
    args = ap.parse_args()
    global mi
    mi, _ = common.setup_mitsuba(args.variant)
    out = {"mitsuba_version": mi.__version__, "variant": args.variant, "cameras": cameras(), "filters": filters()}
    out["image_block"] = {"variant": "llvm_ad_rgb", **image_blocks()}
    print(f"wrote {common.write_test_json('sensor.json', out, indent=1)}")


if __name__ == "__main__":
    main()
