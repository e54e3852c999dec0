#!/usr/bin/env python3
"""Render Mitsuba 3 reference images (mean + per-sample variance) for snee's regression tests.

For every scene (default: all scenes/*.xml) this renders the scene with Mitsuba 3 at a high sample
count and writes

  reference/NAME.exr   float32, six channels, all of size width x height of the scene's film:
                         R, G, B             the pixel mean (the developed film: sum w*L / sum w)
                         var.R, var.G, var.B the per-sample variance of a pixel:
                                             m2 - mean^2, where m2 = sum w*L^2 / sum w is the
                                             filter-weighted second moment of the sample values.
                       (OpenEXR stores channels sorted by name, so the file lists them in the order
                       B, G, R, var.B, var.G, var.R; read them by name.)  Written with
                       PIZ compression, FLOAT (32-bit) pixel type for every channel; checked after
                       writing by parsing the EXR header.
  reference/NAME.json  {scene, spp, variant, seconds, cpu_seconds, cores, mitsuba_version, width,
                        height, seed, passes, rfilter, variance_factor, integrator}
                       (seconds: wall time of the render passes, JIT compilation included;
                       cpu_seconds: CPU time of all threads, meaningful on a shared machine)

How to use the variance (what a Z-test needs): the variance of one pixel of an image rendered with
N samples per pixel is approximately

    Var[pixel] = var * variance_factor / N

where variance_factor = (integral of w^2) / (integral of w)^2 for the film's reconstruction filter
w(x, y) = w1(x) w1(y) (box: 1, tent radius 1: 4/9, gaussian stddev 0.5: 1/pi = 0.318, gaussian
stddev 0.4: 0.497). That is the interior value; pixels within the filter radius of the image border
receive fewer samples and have a larger factor (up to 4x in a corner): `pixel_variance_factor()`
below computes the exact per-pixel map. The reference mean has its own noise of
var * factor / spp_ref, to be added when comparing against it.

How the moments are computed: Mitsuba's `moment` integrator records the first and second moments
of the nested integrator's samples in CIE XYZ (channels nested.X/Y/Z, m2_nested.X/Y/Z), from which
per-channel RGB variances cannot be recovered (they need the RGB cross moments; converting the XYZ
variances linearly is wrong and can go negative). So this script wraps the scene's integrator in a
small Python integrator `rgb_moment`, which is Mitsuba's `moment` integrator in RGB: it calls the
nested integrator's sample() once and returns its RGB value and the squares (and, with --validate,
the cross products) as AOVs. `--validate` renders with both `moment` and `rgb_moment` at the same
seed and checks that the means agree and that E[Y^2] from the RGB second and cross moments equals
`moment`'s m2_nested.Y.

Rendering is done in passes of at most ~4M samples (pixels x spp_pass) with seeds seed*10007 + k
(independent sampler); the raw (unnormalised) film sums sum w*L, sum w*L^2 and sum w are added
over the passes and divided at the end, so the result is the same estimator as one big render.

`--check N` is the sanity check of the variance channel: each scene is rendered twice at N spp with
disjoint seeds, and z = (A - B) / sqrt(2 * var * factor / N) is summarised (should be ~ N(0, 1)).

Usage:
  python3 scripts/make_references.py                      # all scenes, default spp per scene
  python3 scripts/make_references.py scenes/default.xml --spp 1024
  python3 scripts/make_references.py --check 256          # z-score sanity check, writes nothing
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

import common
from common import ROOT, develop, mean_and_variance, render_sums

# Reference sample counts, chosen so that each scene takes about a minute or less with llvm_ad_rgb
# on 2 cores (see the `seconds` recorded in reference/NAME.json).
DEFAULT_SPP = {
    "cornell_box": 16384,
    "glass_envmap": 16384,
    "rough_glass_ggx": 8192,
    "rough_glass_beckmann": 12288,
    "directional_area": 16384,
    "spot_point": 16384,
    "default": 12288,
    "media_smooth_glass": 16384,
    "media_rough_glass": 12288,
    "media_null": 16384,
    "media_inside": 16384,
    "media_thin": 16384,
    "media_spot": 16384,
    "media_camera_inside": 16384,
    "surfaces_metals": 8192,
    "surfaces_plastics": 8192,
    "surfaces_translucent": 8192,
    "surfaces_anisotropic": 8192,
}
FALLBACK_SPP = 4096
BLOCK = 8  # block size of the block-averaged z statistics printed by --check

SRGB_TO_XYZ_Y = np.array([0.212671, 0.715160, 0.072169])  # row Y of Mitsuba's srgb_to_xyz

# ----------------------------------------------------------------------------- mitsuba setup

mi = None


def setup_mitsuba(variant):
    """Import mitsuba, set `variant` (scalar_rgb when LLVM is missing), register `rgb_moment`."""
    global mi
    mi, variant = common.setup_mitsuba(variant)
    common.register_rgb_moment(mi)
    return variant


# ----------------------------------------------------------------------------- rendering

def load_scene(path):
    return mi.load_file(path)


def render_reference(path, spp, seed):
    scene = load_scene(path)
    integrator = mi.load_dict({"type": "rgb_moment", "nested": scene.integrator()})
    sums, (seconds, cpu_seconds), passes = render_sums(scene, integrator, spp, seed)
    mean, var = mean_and_variance(sums)
    return scene, mean, var, (seconds, cpu_seconds), passes


# ----------------------------------------------------------------------------- filter factor

def interior_variance_factor(scene, n=4096):
    rf, radius, w = common.filter_1d(mi, scene)
    xs = (np.arange(n) + 0.5) / n * 2 * radius - radius
    wx = w(xs)
    a = wx.sum() * 2 * radius / n
    b = (wx * wx).sum() * 2 * radius / n
    return float((b / (a * a)) ** 2)


# ----------------------------------------------------------------------------- EXR output

def write_exr(path, mean, var):
    data = np.concatenate([mean, var], axis=-1).astype(np.float32)
    bmp = mi.Bitmap(np.ascontiguousarray(data), pixel_format=mi.Bitmap.PixelFormat.MultiChannel,
                    channel_names=["R", "G", "B", "var.R", "var.G", "var.B"])
    bmp.write(path)


def check_exr_layout(path):
    chans = dict(common.exr_channels(path))
    want = ["R", "G", "B", "var.R", "var.G", "var.B"]
    if sorted(chans) != sorted(want) or any(chans[c] != 2 for c in want):
        raise RuntimeError(f"{path}: unexpected channel layout {chans}")
    bmp = mi.Bitmap(path)
    return [bmp.struct_()[i].name for i in range(bmp.channel_count())]


# ----------------------------------------------------------------------------- checks

def validate_against_moment(path, spp=16, seed=7):
    """Same seed: Mitsuba's `moment` (XYZ) vs `rgb_moment` (RGB): means and E[Y^2] must agree."""
    scene = load_scene(path)
    nested = scene.integrator()
    ours = mi.load_dict({"type": "rgb_moment", "nested": nested, "cross": True})
    theirs = mi.load_dict({"type": "moment", "nested": nested})
    a, _, _ = render_sums(scene, ours, spp, seed)
    b, _, _ = render_sums(scene, theirs, spp, seed)
    mean = develop(a, ["mean.R", "mean.G", "mean.B"])
    m2 = develop(a, ["m2.R", "m2.G", "m2.B"])
    cross = develop(a, ["m2.RG", "m2.GB", "m2.RB"])
    y = SRGB_TO_XYZ_Y
    ey2 = (y[0] ** 2 * m2[..., 0] + y[1] ** 2 * m2[..., 1] + y[2] ** 2 * m2[..., 2]
           + 2 * (y[0] * y[1] * cross[..., 0] + y[1] * y[2] * cross[..., 1]
                  + y[0] * y[2] * cross[..., 2]))
    their_y = develop(b, ["nested.Y"])[..., 0]
    their_y2 = develop(b, ["m2_nested.Y"])[..., 0]
    ours_y = mean @ y
    scale = max(1e-6, float(np.abs(their_y2).max()))
    err_mean = float(np.abs(ours_y - their_y).max()) / max(1e-6, float(np.abs(their_y).max()))
    err_m2 = float(np.abs(ey2 - their_y2).max()) / scale
    rgb_same = float(np.abs(mean - develop(b, ["R", "G", "B"])).max())
    ok = err_mean < 1e-4 and err_m2 < 1e-4 and rgb_same < 1e-4
    print(f"  validate {os.path.basename(path)}: max rel |Y - moment Y| = {err_mean:.2e}, "
          f"max rel |E[Y^2] - moment m2 Y| = {err_m2:.2e}, max |RGB mean - film RGB| = "
          f"{rgb_same:.2e} -> {'ok' if ok else 'MISMATCH'}")
    return ok


def zscore_check(path, spp, ref_var=None):
    """Render twice at `spp` with disjoint seeds; summarise z = (A-B)/sqrt(2 var f / spp)."""
    scene, a, var_a, _, _ = render_reference(path, spp, seed=1000)
    _, b, var_b, _, _ = render_reference(path, spp, seed=2000)
    var = ref_var if ref_var is not None else 0.5 * (var_a + var_b)
    f = common.pixel_variance_factor(mi, scene)[..., None]
    denom = np.sqrt(2.0 * var * f / spp)
    mask = np.broadcast_to(denom > 0, a.shape)
    z = (a - b)[mask] / denom[mask]
    n = z.size
    # Sidak-corrected two-sided test over all pixel channels at family-wise level 1%.
    from scipy.stats import norm
    alpha = 1.0 - (1.0 - 0.01) ** (1.0 / max(n, 1))
    zcrit = norm.isf(alpha / 2)
    res = dict(scene=os.path.basename(path), spp=spp, n=int(n), mean=float(z.mean()),
               std=float(z.std()), frac_gt2=float(np.mean(np.abs(z) > 2)),
               frac_gt3=float(np.mean(np.abs(z) > 3)), max_abs=float(np.abs(z).max()),
               zcrit=float(zcrit), n_fail=int(np.sum(np.abs(z) > zcrit)),
               zero_var=int(np.sum(~mask)))
    print(f"  {res['scene']:26s} spp={spp:5d} pixels: n={n:6d}  mean z={res['mean']:+.3f}  "
          f"std z={res['std']:.3f}  |z|>2: {100 * res['frac_gt2']:.2f}% (4.55)  "
          f"|z|>3: {100 * res['frac_gt3']:.3f}% (0.27)  max|z|={res['max_abs']:.2f}  "
          f"Sidak crit {zcrit:.2f}: {res['n_fail']} over  ({res['zero_var']} zero-var)")

    # Block test: means over BxB pixel blocks. For blocks much larger than the filter, every
    # sample's weights over the block's pixels sum to ~1/spp, so Var[block mean] ~ mean(var)/(spp B^2)
    # (filter factor ~1, not f: neighbouring pixels are correlated through shared samples).
    bs = BLOCK
    h, w = a.shape[0] // bs * bs, a.shape[1] // bs * bs

    def blocks(x):
        return x[:h, :w].reshape(h // bs, bs, w // bs, bs, -1).mean(axis=(1, 3))

    bvar = blocks(var) / (spp * bs * bs)
    bmask = bvar > 0
    zb = (blocks(a) - blocks(b))[bmask] / np.sqrt(2.0 * bvar[bmask])
    nb = zb.size
    zcrit_b = norm.isf((1.0 - (1.0 - 0.01) ** (1.0 / max(nb, 1))) / 2)
    res.update(block=bs, block_n=int(nb), block_std=float(zb.std()),
               block_max_abs=float(np.abs(zb).max()), block_zcrit=float(zcrit_b),
               block_n_fail=int(np.sum(np.abs(zb) > zcrit_b)))
    print(f"  {'':26s} {'':9s} {bs}x{bs} blocks: n={nb:5d}  mean z={zb.mean():+.3f}  "
          f"std z={zb.std():.3f}  max|z|={res['block_max_abs']:.2f}  "
          f"Sidak crit {zcrit_b:.2f}: {res['block_n_fail']} over")
    return res


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(
        description="Render Mitsuba 3 reference images (mean + variance EXR and JSON) for snee.",
        epilog="The EXR layout and how to use the variance are described at the top of this file.")
    ap.add_argument("scenes", nargs="*", help="scene files (default: all scenes/*.xml)")
    ap.add_argument("--spp", type=int, default=None,
                    help=f"samples per pixel for every scene (default: per scene, {DEFAULT_SPP})")
    ap.add_argument("--variant", default="llvm_ad_rgb",
                    help="Mitsuba variant (default llvm_ad_rgb; falls back to scalar_rgb)")
    ap.add_argument("--out", default=os.path.join(ROOT, "reference"), help="output folder")
    ap.add_argument("--seed", type=int, default=0, help="base seed (default 0)")
    ap.add_argument("--check", type=int, metavar="SPP", default=None,
                    help="instead of writing references: render each scene twice at SPP with "
                         "different seeds and print z-score statistics of the difference "
                         "against the variance channel")
    ap.add_argument("--validate", action="store_true",
                    help="also check rgb_moment against Mitsuba's moment integrator (same seed)")
    args = ap.parse_args()

    variant = setup_mitsuba(args.variant)
    scenes = args.scenes or sorted(glob.glob(os.path.join(ROOT, "scenes", "*.xml")))
    if not scenes:
        ap.error("no scenes given and none found in scenes/")

    if args.validate:
        ok = all(validate_against_moment(p) for p in scenes)
        if not ok:
            sys.exit(1)

    if args.check is not None:
        print(f"z-score check with {variant}: z = (A - B) / sqrt(2 var factor / spp), "
              "var from the committed reference if present")
        results = []
        for path in scenes:
            name = os.path.splitext(os.path.basename(path))[0]
            ref = os.path.join(args.out, name + ".exr")
            ref_var = None
            if os.path.exists(ref):
                arr = mi.Bitmap(ref)
                names = [arr.struct_()[i].name for i in range(arr.channel_count())]
                a = np.array(arr)
                ref_var = np.stack([a[..., names.index(c)] for c in ("var.R", "var.G", "var.B")],
                                   axis=-1).astype(np.float64)
            results.append(zscore_check(path, args.check, ref_var))
        return

    os.makedirs(args.out, exist_ok=True)
    for path in scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        spp = args.spp or DEFAULT_SPP.get(name, FALLBACK_SPP)
        scene, mean, var, (seconds, cpu_seconds), passes = render_reference(path, spp, args.seed)
        exr = os.path.join(args.out, name + ".exr")
        write_exr(exr, mean, var)
        layout = check_exr_layout(exr)
        rf = scene.sensors()[0].film().rfilter()
        w, h = scene.sensors()[0].film().crop_size()
        meta = {
            "scene": os.path.relpath(os.path.abspath(path), ROOT),
            "spp": spp,
            "variant": variant,
            "seconds": round(seconds, 2),
            "cpu_seconds": round(cpu_seconds, 2),
            "cores": os.cpu_count(),
            "mitsuba_version": mi.__version__,
            "width": int(w),
            "height": int(h),
            "seed": args.seed,
            "passes": passes,
            "rfilter": str(rf).replace("\n", " "),
            "variance_factor": round(interior_variance_factor(scene), 6),
            "integrator": str(scene.integrator()).replace("\n", " ").replace("  ", " "),
        }
        js = os.path.join(args.out, name + ".json")
        with open(js, "w") as fh:
            json.dump(meta, fh, indent=2)
            fh.write("\n")
        print(f"wrote {exr} ({w}x{h}, channels {','.join(layout)}, float32) and {js}: "
              f"spp={spp} in {seconds:.1f} s, cpu {cpu_seconds:.1f} s ({passes} passes), mean RGB "
              f"{np.round(mean.mean(axis=(0, 1)), 4).tolist()}")


if __name__ == "__main__":
    main()
