#!/usr/bin/env python3
"""The README's first figure: scenes/first.xml (a translucent cube behind smooth glass under a sun and a
sky) rendered by snee's volpath_snee (connection = complete) next to Mitsuba 3's volpath at equal time.

    python3 scripts/first_figure.py [--seconds 10] [--threads 2]

snee renders the scene as written (`--time SECONDS`, time from --stats, scene loading excluded).
Mitsuba loads the same XML with the <integrator> element swapped for its `volpath` (same max_depth;
Mitsuba has no volpath_snee); after an untimed 1-spp warm-up and a timed probe for its rate, it renders
spp = rate x snee's measured seconds, timed as wall clock around mi.render minus drjit's LLVM
compile time, in passes at the rate measured so far until its time reaches snee's. Both with the same
thread count. Outputs figures/first.png (left: snee, right: Mitsuba,
the same exposure) and figures/first.json (spp, seconds, image means; the means differ because
volpath cannot connect to the sun through the smooth glass: the medium is lit by the sky and the sunlit floor
only). Neither renders the unscattered sun refracted through the cube onto the floor (a caustic; the cube's
transmittance along it is about exp(-12 x 0.4) = 1 %).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCENE = os.path.join(ROOT, "scenes", "first.xml")
SNEE = os.path.join(ROOT, "target", "release", "snee")
LUM = np.array([0.2126, 0.7152, 0.0722])


def mitsuba_xml(text):
    """The scene with Mitsuba's volpath in place of the volpath_snee element."""
    new, n = re.subn(r"<integrator type=\"volpath_snee\">.*?</integrator>",
                     '<integrator type="volpath"><integer name="max_depth" value="$max_depth"/></integrator>',
                     text, flags=re.S)
    assert n == 1
    return new


def render_mitsuba(seconds, threads, seed):
    mi, dr, variant, notes = common.mitsuba_setup("auto")
    llvm = variant.startswith("llvm")
    if llvm:
        dr.set_flag(dr.JitFlag.KernelHistory, True)
    scene = mi.load_string(mitsuba_xml(open(SCENE).read()))
    dr.set_thread_count(threads)

    def run(spp, s):
        if llvm:
            dr.kernel_history()
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, seed=s, spp=spp), dtype=np.float64)[..., :3]
        wall = time.perf_counter() - t0
        compile_s = sum(h.get("backend_time", 0.0) for h in dr.kernel_history()) / 1000.0 if llvm else 0.0
        return img, wall - compile_s

    run(1, 1)  # warm-up
    spp, t = 1, 0.0
    while t < seconds / 8 and spp < 1 << 16:  # probe: doubling until an eighth of the budget
        spp *= 2
        _, t = run(spp, 2)
    # Passes (each at the rate measured so far) until Mitsuba has rendered as long as snee did.
    rate, acc, n, total, k = spp / t, None, 0, 0.0, 0
    while total < 0.98 * seconds and k < 20:
        m = max(1, int(round(rate * (seconds - total))))
        img, t = run(m, seed + 1000 * k)
        acc = img * m if acc is None else acc + img * m
        n, total, k = n + m, total + t, k + 1
        rate = n / total
    return acc / n, {"spp": n, "seconds": total, "passes": k, "variant": variant, "notes": notes,
                     "mitsuba_version": mi.__version__}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="equal render time (default 10)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "figures"))
    ap.add_argument("--work", default=os.path.join(ROOT, "target", "first_figure"))
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    os.makedirs(args.out, exist_ok=True)
    exr, stats = os.path.join(args.work, "snee.exr"), os.path.join(args.work, "snee.json")
    subprocess.run([SNEE, "render", SCENE, "-o", exr, "--time", str(args.seconds), "--threads", str(args.threads),
                    "--stats", stats, "--seed", "1", "-q"], check=True)
    snee_img = common.rgb_of(common.read_exr(exr))
    with open(stats) as fh:
        st = json.load(fh)
    mi_img, mi_info = render_mitsuba(st["seconds"], args.threads, seed=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scale = 0.9 / max(np.percentile(snee_img @ LUM, 99.0), 1e-6)

    def srgb(x):
        x = np.clip(x * scale, 0, 1)
        return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)

    h, w = snee_img.shape[:2]
    fig, axes = plt.subplots(1, 2, figsize=(2 * w / 100 + 0.2, h / 100 + 0.55), dpi=150)
    for ax, img, title in ((axes[0], snee_img, f"snee volpath_snee: {st['spp']} spp, {st['seconds']:.1f} s"),
                           (axes[1], mi_img, f"Mitsuba 3 volpath: {mi_info['spp']} spp, {mi_info['seconds']:.1f} s")):
        ax.imshow(srgb(img), interpolation="nearest")
        ax.set_title(title, fontsize=6)
        ax.axis("off")
    fig.tight_layout(pad=0.2)
    fig.savefig(os.path.join(args.out, "first.png"))
    plt.close(fig)
    numbers = {"scene": "scenes/first.xml", "threads": args.threads, "seconds_requested": args.seconds,
               "load_average": os.getloadavg()[0],
               "snee": {"integrator": "volpath_snee (connection = complete)", "spp": st["spp"],
                        "seconds": st["seconds"], "mean": float(snee_img.mean())},
               "mitsuba": dict(mi_info, integrator="volpath", mean=float(mi_img.mean()))}
    common.write_json_atomic(os.path.join(args.out, "first.json"), numbers)
    print(json.dumps(numbers, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
