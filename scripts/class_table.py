#!/usr/bin/env python3
"""Per-class variance and energy shares of snee's integrators (`snee render --classes --moment`).

For every configuration (a scene of scenes/paper/) and method (an integrator with options), render
`--seeds` independent images at `--spp` with `--classes --moment` and report, per transport class
(docs/classes.md):
- energy share: sum over pixels and RGB of the class mean, over the same sum of the image;
- variance share: sum over pixels and RGB of the class's per-sample variance (m2 - mean^2), over
  the sum of that over all classes (classes of one path are exclusive per sample, so their
  covariances are -mean_a*mean_b per pixel, small; `var(classes)/var(image)` says how close the sum
  of class variances is to the image's variance).
Numbers are means over the seeds, with the spread (min-max) of the variance share.

    python3 scripts/class_table.py                          # the default table (4 configs x 3 methods)
    python3 scripts/class_table.py --spp 64 --seeds 4 --width 48 --height 64 --json out.json

Needs `cargo build --release` first; writes its renders to --out (default /tmp/snee_class_table).
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

read_exr = common.read_exr

CLASSES = ["surface", "single", "snee_support", "snee_hidden", "surface_before_last", "internal_reflection", "other"]
CONFIGS = ["sphere_smooth_st34", "sphere_ggx004_st34", "directional_ggx004_st34", "sphere_smooth_st02"]
# name -> (integrator, XML options added to the integrator element)
METHODS = {
    "volpath": ("volpath", ""),
    "snee_paper": ("volpath_snee", '<string name="connection" value="paper"/>'),
    "snee_complete": ("volpath_snee", '<string name="connection" value="complete"/>'),
}
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scene_file(config, method, out):
    """The paper scene with the method's integrator (options spliced into the element)."""
    integrator, extra = METHODS[method]
    src = os.path.join(ROOT, "scenes", "paper", config + ".xml")
    with open(src) as f:
        xml = f.read()
    xml = xml.replace('<integrator type="$integrator">', f'<integrator type="{integrator}">{extra}')
    # Written to `out`, with the assets (statue.ply, sun_sky.exr) by absolute path.
    for asset in ("statue.ply", "sun_sky.exr"):
        xml = xml.replace(f'value="{asset}"', f'value="{os.path.join(ROOT, "scenes", "paper", asset)}"')
    path = os.path.join(out, f"{config}_{method}.xml")
    with open(path, "w") as f:
        f.write(xml)
    return path


def render(snee, scene, out_exr, spp, seed, width, height, threads):
    cmd = [snee, "render", scene, "-q", "--classes", "--moment", "--spp", str(spp), "--seed", str(seed),
           "-D", f"width={width}", "-D", f"height={height}", "--threads", str(threads), "-o", out_exr]
    subprocess.run(cmd, check=True)
    return read_exr(out_exr)


def shares(ch):
    """(energy share, variance per class, image variance) of one render, summed over pixels and RGB."""
    rgb = ["R", "G", "B"]
    image = sum(ch[c].astype(np.float64).sum() for c in rgb)
    energy, var = {}, {}
    for k in CLASSES:
        mean = [ch[f"{k}.{c}"].astype(np.float64) for c in rgb]
        m2 = [ch[f"{k}.m2.{c}"].astype(np.float64) for c in rgb]
        energy[k] = sum(m.sum() for m in mean) / image if image > 0 else 0.0
        var[k] = sum(np.maximum(s - m * m, 0.0).sum() for m, s in zip(mean, m2))
    var_image = sum(np.maximum(ch[f"m2.{c}"].astype(np.float64) - ch[c].astype(np.float64) ** 2, 0.0).sum()
                    for c in rgb)
    return energy, var, var_image


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--width", type=int, default=48)
    ap.add_argument("--height", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--configs", nargs="*", default=CONFIGS)
    ap.add_argument("--methods", nargs="*", default=list(METHODS))
    ap.add_argument("--out", default="/tmp/snee_class_table")
    ap.add_argument("--json", help="also write the numbers as JSON")
    ap.add_argument("--snee", default=os.path.join(ROOT, "target", "release", "snee"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    results = {}
    for config in args.configs:
        for method in args.methods:
            scene = scene_file(config, method, args.out)
            runs = []
            for seed in range(args.seeds):
                exr = os.path.join(args.out, f"{config}_{method}_s{seed}.exr")
                runs.append(shares(render(args.snee, scene, exr, args.spp, seed, args.width, args.height,
                                          args.threads)))
            row = {}
            for k in CLASSES:
                e = [r[0][k] for r in runs]
                v = [r[1][k] / max(sum(r[1].values()), 1e-300) for r in runs]
                row[k] = {"energy": float(np.mean(e)), "variance": float(np.mean(v)),
                          "variance_min": float(np.min(v)), "variance_max": float(np.max(v))}
            row["var_classes_over_image"] = float(np.mean([sum(r[1].values()) / max(r[2], 1e-300) for r in runs]))
            results[f"{config}/{method}"] = row
            print(f"done {config} {method}", file=sys.stderr)

    keys = list(results)
    print(f"spp {args.spp}, {args.seeds} seeds, {args.width}x{args.height}; "
          "cells: % of variance (min-max over seeds) / % of image energy\n")
    print("| class | " + " | ".join(keys) + " |")
    print("|---|" + "---|" * len(keys))
    for k in CLASSES:
        cells = [f"{100 * results[c][k]['variance']:.1f} ({100 * results[c][k]['variance_min']:.1f}–"
                 f"{100 * results[c][k]['variance_max']:.1f}) / {100 * results[c][k]['energy']:.1f}" for c in keys]
        print(f"| {k} | " + " | ".join(cells) + " |")
    print("| Σ class variances / image variance | " + " | ".join(
        f"{results[c]['var_classes_over_image']:.3f}" for c in keys) + " |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"spp": args.spp, "seeds": args.seeds, "width": args.width, "height": args.height,
                       "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
