#!/usr/bin/env python3
"""Run the reference regression test of `tests/references.rs` on Mitsuba's own renders.

A scene is fit for that test only if Mitsuba, compared with its own reference, passes it about as
often as the significance level says (fails in ~1 % of trials). Heavy-tailed scenes (caustics,
light that reaches a medium only through a narrow glossy lobe) fail much more often: their batch
means are skewed, so the t-test over batches is not calibrated at the test's sample count.

For each scene and each trial this renders, with Mitsuba (llvm_ad_rgb, independent sampler, fresh
seeds), BATCHES = 16 batches of SPP_PER_BATCH samples with the `rgb_moment` wrapper (common.py,
as make_references.py renders the references), and applies exactly the statistics of tests/references.rs against
reference/NAME.exr:
  - per pixel: z = (mean - ref) / sqrt(var_ours + var_ref + (1e-4 ref)^2), var_ours from the
    second-moment channel times the filter's per-pixel variance factor over the total spp,
    var_ref = var.* x factor / spp_ref; Sidak-corrected level 1 % over all pixel-channels;
  - 8x8 blocks and the whole image: Welch-style t-test (15 dof), our variance from the 16 batch
    means, the reference's from its variance channel; Sidak over all regions x 3 channels.
It prints, per trial, the smallest p-values and whether the test would pass.

Usage:
  python3 scripts/self_test.py scenes/media_spot.xml --spp-per-batch 16 --trials 5
"""
import argparse
import json
import os

import numpy as np

import common
from common import ROOT, sidak

ALPHA = 0.01
BATCHES = 16
BLOCK = 8
PRECISION = 1e-4


def read_reference(mi, name):
    ch = common.bitmap_channels(mi, os.path.join(ROOT, "reference", name + ".exr"))
    mean, var = common.rgb(ch), common.rgb(ch, "var.")
    with open(os.path.join(ROOT, "reference", name + ".json")) as fh:
        spp_ref = json.load(fh)["spp"]
    return mean, var, spp_ref


def trial(scene, integrator, spp, seed0, ref_mean, ref_var_pix, factor):
    from scipy.stats import norm, t as student_t
    batches, m2s = [], []
    for b in range(BATCHES):
        sums, _, _ = common.render_sums(scene, integrator, spp, seed0 + b)
        mean, _ = common.mean_and_variance(sums)
        batches.append(mean)
        m2s.append(common.develop(sums, ["m2.R", "m2.G", "m2.B"]))
    batches = np.array(batches)
    mean = batches.mean(axis=0)
    m2 = np.mean(m2s, axis=0)
    total = spp * BATCHES
    var_ours = np.maximum(m2 - mean * mean, 0.0) * factor[..., None] / total
    var = var_ours + ref_var_pix + (PRECISION * ref_mean) ** 2
    d = mean - ref_mean
    with np.errstate(divide="ignore", invalid="ignore"):
        p_pix = np.where(var > 0, 2 * norm.sf(np.abs(d) / np.sqrt(var)),
                         np.where(np.abs(d) > 1e-5 * np.abs(ref_mean) + 1e-6, 0.0, 1.0))
    h, w = mean.shape[:2]
    regions = [(slice(y, min(y + BLOCK, h)), slice(x, min(x + BLOCK, w)))
               for y in range(0, h, BLOCK) for x in range(0, w, BLOCK)]
    regions.append((slice(0, h), slice(0, w)))
    p_reg = []
    for ys, xs in regions:
        n = (ys.stop - ys.start) * (xs.stop - xs.start)
        per_batch = batches[:, ys, xs].mean(axis=(1, 2))            # (BATCHES, 3)
        m = per_batch.mean(axis=0)
        vo = per_batch.var(axis=0, ddof=1) / BATCHES
        vr = ref_var_pix[ys, xs].sum(axis=(0, 1)) / (n * n)
        rm = ref_mean[ys, xs].mean(axis=(0, 1))
        v = vo + vr + (PRECISION * rm) ** 2
        dd = m - rm
        with np.errstate(divide="ignore", invalid="ignore"):
            p = np.where(v > 0, 2 * student_t.sf(np.abs(dd) / np.sqrt(v), BATCHES - 1),
                         np.where(np.abs(dd) > 1e-6, 0.0, 1.0))
        p_reg.append(p)
    p_reg = np.array(p_reg)
    lvl_pix = sidak(ALPHA, p_pix.size)
    lvl_reg = sidak(ALPHA, p_reg.size)
    return (float(p_pix.min()), lvl_pix, int((p_pix < lvl_pix).sum()), float(p_reg.min()), lvl_reg,
            int((p_reg < lvl_reg).sum()), float(p_reg[-1].min()))


def main():
    ap = argparse.ArgumentParser(description="Apply tests/references.rs's statistics to Mitsuba's "
                                 "own renders (how often would Mitsuba fail its own test?).")
    ap.add_argument("scenes", nargs="+", help="scene files with a reference/NAME.exr")
    ap.add_argument("--spp-per-batch", type=int, default=16, help="spp of each of the 16 batches")
    ap.add_argument("--trials", type=int, default=5, help="independent repetitions (default 5)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()
    mi, variant = common.setup_mitsuba(args.variant)
    common.register_rgb_moment(mi)
    print(f"Mitsuba {mi.__version__} {variant}: {BATCHES} batches x {args.spp_per_batch} spp "
          f"per trial, tests of tests/references.rs at family-wise {ALPHA}")
    for path in args.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        ref_mean, ref_var, spp_ref = read_reference(mi, name)
        scene = mi.load_file(path)
        integrator = mi.load_dict({"type": "rgb_moment", "nested": scene.integrator()})
        factor = common.pixel_variance_factor(mi, scene)
        ref_var_pix = ref_var * factor[..., None] / spp_ref
        fails_pix = fails_reg = 0
        for k in range(args.trials):
            pp, lp, npix, pr, lr, nreg, pimg = trial(scene, integrator, args.spp_per_batch,
                                                     100000 + 1000 * k, ref_mean, ref_var_pix,
                                                     factor)
            fails_pix += npix > 0
            fails_reg += nreg > 0
            print(f"  {name:22s} trial {k}: per-pixel min p {pp:.1e} (level {lp:.1e}, {npix} over)"
                  f"  regions min p {pr:.1e} (level {lr:.1e}, {nreg} over)  whole-image min p "
                  f"{pimg:.2f}")
        print(f"  {name:22s} would fail: per-pixel test in {fails_pix}/{args.trials} trials, "
              f"block/image test in {fails_reg}/{args.trials} trials")


if __name__ == "__main__":
    main()
