#!/usr/bin/env python3
"""Time snee against Mitsuba 3 on the same scene, resolution and sample count, and print the ratio.

snee:    `cargo build --release` first (not timed), then
         `cargo run --release -- render SCENE -o OUT/snee.exr --spp N --stats OUT/snee_stats.json`.
         Its render time is read from the stats file (keys `seconds`, `spp`, `samples_per_second`):
         from the first sample to the developed image in memory (every pass, the merge of the tile
         blocks and the film development; not scene loading, BVH build or EXR writing, like
         Mitsuba's time below). The process's wall time (all of it included) is shown too.
Mitsuba: variant llvm_ad_rgb (falls back to scalar_rgb), the same scene file and spp, rendered with
         `mi.render` once as a warm-up so that the LLVM JIT compilation of the kernels is EXCLUDED
         from the timing, then rendered again (another seed) and timed until the image is in memory.
         Scene loading is excluded as well. Large sample counts are rendered in passes of at most
         ~4M samples (the wavefront would not fit in memory otherwise), exactly as in
         make_references.py; the pass loop is part of the timing.
Both use every core of the machine. The ratio printed is snee seconds / Mitsuba seconds
(< 1: snee is faster). The mean pixel value of both images is printed as a sanity check (they
should agree up to noise), and everything is written to OUT/bench.json.

Several scenes can be given: each is timed as above (Mitsuba's warm-up is per scene, since every
scene compiles its own kernels) and a Markdown table of all of them is printed at the end.
`--repeat K` renders each scene K times with both renderers, interleaved (snee, Mitsuba, snee, ...,
after Mitsuba's warm-up), and reports the fastest run of each and the median and range of the K
paired ratios (the machine is shared: the minimum is the least disturbed measurement, the paired
median the one least moved by load that changes between runs).

Suite (`--suite`, the default without scene arguments): the speed table of the README in one run:
cornell_box, glass_envmap, media_null, media_rough_glass and the paper statue (sphere light, smooth
boundary, sigma_t 2 and 34) with `volpath`, plus the statue with snee's `volpath_snee` (timed against
Mitsuba's `volpath`, which has no SNEE), each at 1 and 2 threads (`--threads`), with per-scene sample
counts (`SUITE`, scaled by `--spp-scale`); then the traversal benchmark
(`cargo run --release --example bench_traversal`): closest-hit and shadow M rays/s on one thread, bytes
per triangle, Embree's M rays/s on the same rays inside Mitsuba's LLVM variant (`embree_rays.py`), and,
when valgrind is installed, instructions per ray (callgrind, 10,000 rays).
Timings on a shared machine are noisy: use `--repeat` and compare ratios measured in the same run.

Usage:
  python3 scripts/bench.py                                  # the suite (about 5 minutes)
  python3 scripts/bench.py scenes/default.xml --spp 64      # one scene, every core
  python3 scripts/bench.py scenes/cornell_box.xml scenes/glass_envmap.xml --spp 256 \
      --snee target/release/snee --repeat 3                 # several scenes, one table
  python3 scripts/bench.py scenes/cornell_box.xml --spp 256
  python3 scripts/bench.py scenes/default.xml --snee target/release/snee   # a prebuilt binary
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time

import numpy as np

import common
from common import MAX_SAMPLES_PER_PASS, ROOT


def snee_command(args, scene, out_dir):
    """The snee render command for `scene`, its EXR and its stats file."""
    exr = os.path.join(out_dir, "snee.exr")
    stats_path = os.path.join(out_dir, "snee_stats.json")
    if args.snee:
        cmd = [args.snee]
    else:
        print("building snee (cargo build --release, not timed) ...", flush=True)
        subprocess.run(["cargo", "build", "--release"], cwd=ROOT, check=True)
        cmd = ["cargo", "run", "--release", "--quiet", "--"]
    cmd += ["render", scene, "-o", exr, "--spp", str(args.spp), "--stats", stats_path, "-q"]
    if args.threads_now:
        cmd += ["--threads", str(args.threads_now)]
    for name, value in args.defines:
        cmd += ["-D", f"{name}={value}"]
    print("running:", " ".join(shlex.quote(c) for c in cmd), flush=True)
    return cmd, exr, stats_path


def snee_once(args, cmd, stats_path):
    """One snee render: (process wall seconds, its stats)."""
    if os.path.exists(stats_path):
        os.remove(stats_path)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(f"snee failed with exit code {proc.returncode}")
    with open(stats_path) as fh:
        stats = json.load(fh)
    for key in ("seconds", "spp", "samples_per_second"):
        if key not in stats:
            sys.exit(f"{stats_path}: missing key {key!r} (has {sorted(stats)})")
    if int(stats["spp"]) != args.spp:
        print(f"warning: snee rendered {stats['spp']} spp, asked for {args.spp}", file=sys.stderr)
    return wall, stats


def mitsuba_render(mi, scene, spp, seed):
    """Render `spp` samples in passes; returns the image as a numpy array (H, W, C)."""
    w, h = scene.sensors()[0].film().crop_size()
    pass_spp = max(1, min(spp, MAX_SAMPLES_PER_PASS // (w * h)))
    acc, done, k = None, 0, 0
    while done < spp:
        n = min(pass_spp, spp - done)
        img = np.array(mi.render(scene, spp=n, seed=seed * 10007 + k), dtype=np.float64)
        acc = img * n if acc is None else acc + img * n
        done += n
        k += 1
    return acc / spp


def timed_pairs(args, mi, variant, scene_path, out_dir):
    """Mitsuba's scene loaded and its kernels compiled (a warm-up render, not timed), then
    `--repeat` rounds of one snee render and one Mitsuba render, interleaved so that both see the
    same machine state. Returns (snee, mitsuba, per-round ratios snee / Mitsuba)."""
    cmd, exr, stats_path = (None, None, None) if args.skip_snee else snee_command(args, scene_path, out_dir)
    scene = mi.load_file(scene_path, **{k: v for k, v in args.mitsuba_defines})
    w, h = scene.sensors()[0].film().crop_size()
    import drjit as dr
    if args.threads_now:
        # Only around the renders: Mitsuba 3.9.1 deadlocks reading or writing EXR files with
        # Dr.Jit's pool at one thread.
        dr.set_thread_count(args.threads_now)
    try:
        t0 = time.perf_counter()
        mitsuba_render(mi, scene, min(args.spp, max(1, MAX_SAMPLES_PER_PASS // (w * h))), seed=1)
        warmup = time.perf_counter() - t0
        snee_best, m_seconds, img, ratios, m_all, s_all = None, None, None, [], [], []
        for k in range(args.repeat):
            s_seconds = None
            if cmd is not None:
                wall, stats = snee_once(args, cmd, stats_path)
                s_seconds = float(stats["seconds"])
                s_all.append(s_seconds)
                if snee_best is None or s_seconds < float(snee_best[1]["seconds"]):
                    snee_best = (wall, stats)
            t0 = time.perf_counter()
            im = mitsuba_render(mi, scene, args.spp, seed=2 + k)
            dt = time.perf_counter() - t0
            m_all.append(dt)
            if s_seconds is not None:
                ratios.append(s_seconds / dt)
            if m_seconds is None or dt < m_seconds:
                m_seconds, img = dt, im
    finally:
        if args.threads_now:
            dr.set_thread_count(os.cpu_count())
    m_exr = os.path.join(out_dir, "mitsuba.exr")
    mi.Bitmap(img[..., :3].astype(np.float32)).write(m_exr)
    mits = dict(seconds=m_seconds, all_seconds=m_all, warmup_seconds=warmup, spp=args.spp, variant=variant,
                samples_per_second=w * h * args.spp / m_seconds, image=m_exr, width=w, height=h,
                mitsuba_version=mi.__version__)
    snee = None
    if snee_best is not None:
        wall, stats = snee_best
        snee = dict(seconds=float(stats["seconds"]), all_seconds=s_all, wall_seconds=wall, spp=int(stats["spp"]),
                    samples_per_second=float(stats["samples_per_second"]), image=exr, stats=stats)
    return snee, mits, ratios


def mean_rgb(mi, path):
    ch = common.bitmap_channels(mi, path)
    if not all(c in ch for c in "RGB"):  # unnamed channels: the first three
        ch = dict(zip("RGB", list(ch.values())[:3]))
    return common.rgb(ch).mean(axis=(0, 1))


def bench_scene(args, mi, variant, scene):
    tag = os.path.splitext(os.path.basename(scene))[0] + "".join(f"_{v}" for _, v in args.defines)
    if args.threads_now:
        tag += f"_t{args.threads_now}"
    out_dir = os.path.abspath(os.path.join(args.out, tag))
    os.makedirs(out_dir, exist_ok=True)

    snee, mits, ratios = timed_pairs(args, mi, variant, scene, out_dir)

    px = mits["width"] * mits["height"]
    print(f"\nscene {os.path.relpath(scene, ROOT)}: {mits['width']}x{mits['height']}, "
          f"{args.spp} spp ({px * args.spp / 1e6:.2f} M samples)")
    print(f"  {'':8s} {'seconds':>9s} {'Msamples/s':>11s}  mean RGB")
    m_mean = mean_rgb(mi, mits["image"])
    print(f"  {'mitsuba':8s} {mits['seconds']:9.3f} {mits['samples_per_second'] / 1e6:11.3f}  "
          f"{np.round(m_mean, 4).tolist()}  ({mits['variant']}, JIT warm-up "
          f"{mits['warmup_seconds']:.2f} s excluded)")
    result = dict(scene=os.path.relpath(scene, ROOT), spp=args.spp, repeat=args.repeat, mitsuba=mits,
                  threads=args.threads_now, defines=dict(args.defines))
    if snee is not None:
        s_mean = mean_rgb(mi, snee["image"])
        print(f"  {'snee':8s} {snee['seconds']:9.3f} {snee['samples_per_second'] / 1e6:11.3f}  "
              f"{np.round(s_mean, 4).tolist()}  (process wall time {snee['wall_seconds']:.2f} s)")
        ratio = snee["seconds"] / mits["seconds"]
        median = float(np.median(ratios))
        print(f"  time ratio snee / mitsuba = {ratio:.3f} (fastest of each), {median:.3f} (median of "
              f"{len(ratios)} interleaved pairs, range {min(ratios):.3f}-{max(ratios):.3f})  "
              f"({'snee' if ratio < 1 else 'mitsuba'} is {max(ratio, 1 / ratio):.2f}x faster)")
        result.update(snee=snee, ratio_seconds=ratio, ratio_median=median, ratios=ratios,
                      mean_rgb_snee=s_mean.tolist())
    result.update(mean_rgb_mitsuba=m_mean.tolist())
    path = os.path.join(out_dir, "bench.json")
    with open(path, "w") as fh:
        json.dump(result, fh, indent=2, default=str)
        fh.write("\n")
    print(f"wrote {path}")
    return result


def print_table(results):
    print("\n| scene | integrator (snee) | threads | size | spp | snee render s | snee Msamples/s | "
          "snee process s | Mitsuba s | Mitsuba Msamples/s | Mitsuba JIT warm-up s (excluded) | snee / Mitsuba | "
          "median of paired ratios (range) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        m = r["mitsuba"]
        s = r.get("snee")
        cells = [os.path.splitext(os.path.basename(r["scene"]))[0], r["defines"].get("integrator", "(scene's)"),
                 str(r["threads"] or "all"), f"{m['width']}x{m['height']}", str(r["spp"]),
                 f"{s['seconds']:.2f}" if s else "-", f"{s['samples_per_second'] / 1e6:.3f}" if s else "-",
                 f"{s['wall_seconds']:.2f}" if s else "-",
                 f"{m['seconds']:.2f}", f"{m['samples_per_second'] / 1e6:.3f}", f"{m['warmup_seconds']:.2f}",
                 f"{r['ratio_seconds']:.2f}" if s else "-",
                 f"{r['ratio_median']:.2f} ({min(r['ratios']):.2f}–{max(r['ratios']):.2f})" if s else "-"]
        print("| " + " | ".join(cells) + " |")


# (scene, snee integrator override or None, spp): the README's speed table.
SUITE = [
    ("scenes/cornell_box.xml", None, 64),
    ("scenes/glass_envmap.xml", None, 32),
    ("scenes/media_null.xml", None, 64),
    ("scenes/media_rough_glass.xml", None, 64),
    ("scenes/paper/sphere_smooth_st02.xml", "volpath", 16),
    ("scenes/paper/sphere_smooth_st02.xml", "volpath_snee", 16),
    ("scenes/paper/sphere_smooth_st34.xml", "volpath", 8),
    ("scenes/paper/sphere_smooth_st34.xml", "volpath_snee", 8),
]
TRAVERSAL_SCENES = ["scenes/cornell_box.xml", "scenes/media_null.xml", "scenes/paper/sphere_smooth_st02.xml"]


def callgrind_instructions(binary, scene, function, rays):
    """Instructions executed inside `function` per ray (valgrind's callgrind), or None."""
    out = os.path.join(ROOT, "out", "bench", "callgrind.out")
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", f"--toggle-collect={function}",
           binary, scene, "--rays", str(rays), "--reps", "1"]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0 or not os.path.exists(out):
        return None
    with open(out) as fh:
        for line in fh:
            if line.startswith(("summary:", "totals:")):
                return int(line.split()[1]) / rays
    return None


def run_traversal(args, mi, variant):
    """The traversal benchmark: M rays/s (one thread) and, with valgrind, instructions per ray; beside
    it Embree's M rays/s inside Mitsuba's LLVM variant on the same rays (`embree_rays.py`)."""
    print("\nbuilding the traversal benchmark (not timed) ...", flush=True)
    subprocess.run(["cargo", "build", "--release", "--example", "bench_traversal"], cwd=ROOT, check=True)
    binary = os.path.join(ROOT, "target", "release", "examples", "bench_traversal")
    scenes = [os.path.join(ROOT, s) for s in TRAVERSAL_SCENES]
    rays_dir = os.path.join(os.path.abspath(args.out), "rays")
    proc = subprocess.run([binary, *scenes, "--json", "--save-rays", rays_dir], cwd=ROOT, capture_output=True,
                          text=True, check=True)
    rows = json.loads(proc.stdout)
    for row in rows:
        row["embree_closest_mrays"] = row["embree_shadow_mrays"] = None
        if "llvm" in variant:
            import drjit as dr
            import embree_rays
            name = os.path.splitext(os.path.basename(row["scene"]))[0]
            arr = np.fromfile(os.path.join(rays_dir, name + ".rays"), dtype="<f4").reshape(-1, 7)
            n = len(arr) // 2
            scene = mi.load_file(row["scene"])
            dr.set_thread_count(1)
            try:
                mc, hits, _, ms, blocked, _ = embree_rays.time_queries(mi, dr, scene, (arr[:n], arr[n:]), 5)
            finally:
                dr.set_thread_count(os.cpu_count())
            row.update(embree_closest_mrays=mc, embree_shadow_mrays=ms, embree_hits=hits, embree_blocked=blocked)
            # The closest rays by where they start (bench_traversal's groups), on the same rays.
            row["embree_closest_by_origin"] = embree_rays.closest_by_origin(
                mi, dr, scene, arr[:n], os.path.join(rays_dir, name + ".groups"), 5)
    have_valgrind = not args.no_callgrind and subprocess.run(["which", "valgrind"], capture_output=True).returncode == 0
    for row in rows:
        row["closest_instructions_per_ray"] = row["shadow_instructions_per_ray"] = None
        if have_valgrind:
            row["closest_instructions_per_ray"] = callgrind_instructions(
                binary, row["scene"], "snee::shape::accel::Accel::intersect", 10000)
            row["shadow_instructions_per_ray"] = callgrind_instructions(
                binary, row["scene"], "snee::shape::accel::Accel::occluded", 10000)
    print("\n| scene | triangles | BVH bytes / triangle | load + build s | closest Mrays/s | shadow Mrays/s | "
          "Embree closest / shadow Mrays/s (same rays) | instructions / closest ray | instructions / shadow ray |")
    print("|---|---|---|---|---|---|---|---|---|")
    fmt = lambda v: "-" if v is None else f"{v:.0f}"  # noqa: E731
    for r in rows:
        embree = "-" if r["embree_closest_mrays"] is None else \
            f"{r['embree_closest_mrays']:.2f} / {r['embree_shadow_mrays']:.2f}"
        print(f"| {os.path.relpath(r['scene'], ROOT)} | {r['triangles']} | {r['bytes_per_triangle']:.1f} | "
              f"{r['load_s']:.3f} | {r['closest_mrays']:.2f} | {r['shadow_mrays']:.2f} | {embree} | "
              f"{fmt(r['closest_instructions_per_ray'])} | {fmt(r['shadow_instructions_per_ray'])} |")
    print("\nClosest rays by where they start (M rays/s, one thread; rays from a mesh leaving it or turned into "
          "it, from an analytic shape likewise):\n")
    print("| scene | origin | rays | hits | snee | Embree | Embree / snee |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        embree = r.get("embree_closest_by_origin") or {}
        for label, v in r.get("closest_by_origin", {}).items():
            e = embree.get(label)
            ratio = "-" if e is None else f"{e['closest_mrays'] / v['closest_mrays']:.2f}"
            e_rate = "-" if e is None else f"{e['closest_mrays']:.2f}"
            print(f"| {os.path.relpath(r['scene'], ROOT)} | {label} | {v['rays']} | {v['hits']} | "
                  f"{v['closest_mrays']:.2f} | {e_rate} | {ratio} |")
    return rows


def main():
    ap = argparse.ArgumentParser(description="Time snee vs Mitsuba 3 (same scene, resolution, spp).",
                                 epilog="Mitsuba's LLVM JIT compile time is excluded (warm-up run).")
    ap.add_argument("scenes", nargs="*", help="scene files (default: the suite)")
    ap.add_argument("--suite", action="store_true", help="the README's speed table (default without scenes)")
    ap.add_argument("--threads", default=None,
                    help="comma-separated thread counts for both renderers (suite default: 1,2; else all cores)")
    ap.add_argument("--spp-scale", type=float, default=1.0, help="multiply the suite's sample counts")
    ap.add_argument("-D", dest="define", action="append", default=[], metavar="NAME=VALUE",
                    help="scene parameter for both renderers (e.g. integrator=volpath)")
    ap.add_argument("--no-traversal", action="store_true", help="skip the traversal benchmark")
    ap.add_argument("--no-callgrind", action="store_true", help="skip the instruction counts")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel (default 64)")
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    ap.add_argument("--snee", default=None,
                    help="path of a built snee binary (default: cargo run --release --)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench"),
                    help="output folder for images and bench.json (default: out/bench)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="render each scene this many times per renderer, snee and Mitsuba interleaved; "
                         "the table shows the fastest of each and the median of the paired ratios (default 1)")
    ap.add_argument("--skip-snee", action="store_true", help="only time Mitsuba")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")

    suite = args.suite or not args.scenes
    threads = [int(t) for t in (args.threads or ("1,2" if suite else "0")).split(",")]
    if suite:
        jobs = [(os.path.join(ROOT, sc), integ, max(1, round(spp * args.spp_scale))) for sc, integ, spp in SUITE]
    else:
        jobs = [(os.path.abspath(sc), None, args.spp) for sc in args.scenes]
    if args.snee is None:
        print("building snee (cargo build --release, not timed) ...", flush=True)
        subprocess.run(["cargo", "build", "--release"], cwd=ROOT, check=True)
        args.snee = os.path.join(ROOT, "target", "release", "snee")
    mi, variant = common.setup_mitsuba(args.variant)
    base_defines = [tuple(d.split("=", 1)) for d in args.define]
    results = []
    for scene, integrator, spp in jobs:
        for t in threads:
            args.threads_now = t or None
            args.spp = spp
            args.defines = base_defines + ([("integrator", integrator)] if integrator else [])
            # Mitsuba has no volpath_snee: it renders the scene's volpath for comparison.
            args.mitsuba_defines = [(k, v) for k, v in args.defines if not (k == "integrator" and v == "volpath_snee")]
            args.mitsuba_defines += [("integrator", "volpath")] if integrator == "volpath_snee" else []
            results.append(bench_scene(args, mi, variant, scene))
    print_table(results)
    summary = dict(results=results)
    if suite and not args.no_traversal:
        summary["traversal"] = run_traversal(args, mi, variant)
    print(f"\n(machine: {os.cpu_count()} logical CPUs, shared with other jobs: timings are noisy)")
    path = os.path.join(os.path.abspath(args.out), "bench_summary.json")
    with open(path, "w") as fh:
        json.dump(summary, fh, indent=2, default=str)
        fh.write("\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.stdout.reconfigure(line_buffering=True)
    main()
