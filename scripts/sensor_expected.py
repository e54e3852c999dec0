#!/usr/bin/env python3
"""Print reference values from Mitsuba 3 for tests/sensor.rs and tests/film.rs.

For several perspective-camera configurations this calls Mitsuba's
`sensor.sample_ray(time, wavelength_sample, position_sample, aperture_sample)` and prints the
ray origin, direction and length, together with the camera's `to_world` matrix as Mitsuba built it
(so the Rust test does not depend on our own `look_at`). Mitsuba's `position_sample` is relative to
the film's crop window; the printed `pos` is the same point in pixels of the full film
(`crop_offset + position_sample * crop_size`), which is what `Camera::sample_ray` takes.
It also prints `rfilter.eval(x)` for the gaussian, tent and box filters.

Usage: python3 scripts/sensor_expected.py            (needs `pip install mitsuba==3.9.1`)
Output goes to stdout as Rust array literals to paste into the tests.
"""
import argparse
import os

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
import mitsuba as mi  # noqa: E402

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


def fmt(v):
    return "[" + ", ".join(f"{float(x):.9e}" for x in v) + "]"


def cameras():
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
        print(f"// {name}: {params} film {w}x{h} crop {crop} look_at {look}")
        print("Case {")
        print(f"    name: {name!r},".replace("'", '"'))
        ps = ", ".join(f'("{k}", F({float(v)!r}))' if not isinstance(v, str) else f'("{k}", S("{v}"))'
                       for k, v in params.items())
        print(f"    params: &[{ps}],")
        print(f"    film: ({w}, {h}, {'Some(' + repr(tuple(crop)) + ')' if crop else 'None'}),")
        print(f"    to_world_rows: [{', '.join(fmt(r) for r in rows)}],")
        print("    rays: &[")
        for s in SAMPLES:
            ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(*s), mi.Point2f(0.5, 0.5))
            pos = (co[0] + s[0] * cs[0], co[1] + s[1] * cs[1])
            print(f"        ({fmt(pos)}, {fmt(ray.o)}, {fmt(ray.d)}, {float(ray.maxt):.9e}),")
        print("    ],")
        print("},")


def filters():
    xs = [0.0, 0.1, 0.25, 0.49, 0.5, 0.75, 1.0, 1.2, 1.5, 1.9, 1.99, 2.0, 2.3, 2.5, 3.0, 3.5, -0.3, -1.1]
    for name, d in [("gaussian", {"type": "gaussian"}), ("gaussian_0.3", {"type": "gaussian", "stddev": 0.3}),
                    ("gaussian_1", {"type": "gaussian", "stddev": 1.0}), ("tent", {"type": "tent"}),
                    ("tent_1.5", {"type": "tent", "radius": 1.5}), ("box", {"type": "box"})]:
        f = mi.load_dict(d)
        print(f"// {name}: radius {f.radius()}, border {f.border_size()}")
        print("&[" + ", ".join(f"({x:.3}, {float(f.eval(x)):.9e})" for x in xs) + "],")


# ImageBlock test: interior offset/size, and samples (x, y, value); some fall outside the block.
BLOCK_OFFSET, BLOCK_SIZE = (10, 20), (6, 5)
BLOCK_SAMPLES = [(12.3, 22.7, 1.0), (13.9, 21.2, 2.0), (10.05, 20.5, 3.0), (15.99, 24.99, 4.0),
                 (9.2, 23.4, 5.0), (14.5, 26.1, 6.0), (12.5, 22.5, 7.0), (17.3, 19.6, 8.0)]


def image_blocks():
    """Splat BLOCK_SAMPLES with Mitsuba's ImageBlock as the llvm variants render (eval, no table)."""
    import numpy as np
    mi.set_variant("llvm_ad_rgb")
    xs, ys, vs = (mi.Float([s[i] for s in BLOCK_SAMPLES]) for i in range(3))
    for name, d in [("gaussian", {"type": "gaussian"}), ("tent_1.5", {"type": "tent", "radius": 1.5}),
                    ("gaussian_1", {"type": "gaussian", "stddev": 1.0}), ("box", {"type": "box"})]:
        f = mi.load_dict(d)
        b = mi.ImageBlock(size=BLOCK_SIZE, offset=BLOCK_OFFSET, channel_count=2, rfilter=f, border=False,
                          normalize=False, coalesce=True)
        b.put(pos=mi.Point2f(xs, ys), values=[vs, mi.Float(1.0)])
        t = np.array(b.tensor())
        w = t[:, :, 1].ravel()
        v = np.where(w != 0, t[:, :, 0].ravel() / np.where(w != 0, w, 1), 0)
        print(f"// ImageBlock {name}: weights, then developed values (row-major {BLOCK_SIZE[0]}x{BLOCK_SIZE[1]})")
        print("(&[" + ", ".join(f"{x:.7e}" for x in w) + "],")
        print(" &[" + ", ".join(f"{x:.7e}" for x in v) + "]),")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default scalar_rgb)")
    args = ap.parse_args()
    mi.set_variant(args.variant)
    cameras()
    filters()
    image_blocks()


if __name__ == "__main__":
    main()
