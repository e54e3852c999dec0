#!/usr/bin/env python3
"""Mitsuba 3's ray queries (Embree, inside its LLVM variant) on the rays of snee's traversal benchmark.

`cargo run --release --example bench_traversal -- SCENE... --save-rays DIR` writes each scene's rays
(closest-hit rays, then shadow rays; per ray o, d, tmax as little-endian f32) to `DIR/<scene>.rays`.
This script loads the same scene in Mitsuba, traces the same rays with
`Scene::ray_intersect_preliminary` (closest hit: distance, shape and triangle, no surface record) and
`Scene::ray_test` (any hit), and reports M rays/s on one thread (Dr.Jit's pool at one thread; the
best of `--reps` launches, each launch tracing every ray of its kind once, after one warm-up launch
that compiles the kernel), with the hit and blocked counts to check that both renderers answer the
same queries; where bench_traversal also wrote `DIR/<scene>.groups` (one byte per closest ray: from a
mesh outward or inward, from an analytic shape outward or inward), the closest rays of each group too.
A kernel launch includes Dr.Jit's own work around the Embree calls (the ray arrays in,
the hit arrays out), as a render's does.

Usage:
  python3 scripts/embree_rays.py --rays-dir out/rays scenes/cornell_box.xml scenes/paper/sphere_smooth_st02.xml [--json]
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import common


def time_queries(mi, dr, scene, rays, reps):
    """[closest M rays/s, hits, CPU / wall time, shadow M rays/s, blocked, CPU / wall time] for `rays` =
    (closest, shadow) arrays (N, 7)."""
    out = []
    for kind, arr in zip(("closest", "shadow"), rays):
        o = mi.Point3f(*(arr[:, i].copy() for i in range(3)))
        d = mi.Vector3f(*(arr[:, i].copy() for i in range(3, 6)))
        tmax = arr[:, 6].copy()
        # Infinite maxt is Mitsuba's "no limit" as its largest finite float.
        tmax = np.where(np.isfinite(tmax), tmax, np.finfo(np.float32).max).astype(np.float32)
        ray = mi.Ray3f(o, d, mi.Float(tmax), 0.0, mi.Color0f())
        dr.eval(ray)
        best, count, cpu = float("inf"), 0, 0.0
        for k in range(reps + 1):
            t0, c0 = time.perf_counter(), time.process_time()
            if kind == "closest":
                pi = scene.ray_intersect_preliminary(ray)
                valid = pi.is_valid()
                dr.eval(pi.t, valid)
            else:
                valid = scene.ray_test(ray)
                dr.eval(valid)
            dr.sync_thread()
            dt = time.perf_counter() - t0
            if k > 0 and dt < best:  # the first launch compiles the kernel
                # CPU time of the process over the same launch: about dt when one thread traced.
                best, cpu = dt, time.process_time() - c0
            count = int(np.count_nonzero(np.asarray(valid)))
        out += [len(arr) / best / 1e6, count, cpu / best]
    return out


# bench_traversal's groups of closest rays (`<scene>.groups`), by index.
GROUPS = ["mesh outward", "mesh inward", "analytic outward", "analytic inward"]


def closest_by_origin(mi, dr, scene, closest, groups_path, reps):
    """{group label: {rays, hits, closest_mrays}} for the closest rays `closest` (N, 7) split by
    bench_traversal's `<scene>.groups` file at `groups_path` (one thread); None when there is no such file."""
    if not os.path.exists(groups_path):
        return None
    groups = np.fromfile(groups_path, dtype=np.uint8)
    if len(groups) != len(closest):
        sys.exit(f"{groups_path}: {len(groups)} entries for {len(closest)} closest rays")
    by_group = {}
    dr.set_thread_count(1)
    try:
        for g, label in enumerate(GROUPS):
            sub = closest[groups == g]
            if len(sub):
                r = time_queries(mi, dr, scene, (sub, closest[:1]), reps)
                by_group[label] = dict(rays=len(sub), hits=r[1], closest_mrays=r[0])
    finally:
        dr.set_thread_count(os.cpu_count())
    return by_group


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--rays-dir", required=True, help="where bench_traversal --save-rays wrote <scene>.rays")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    mi, variant = common.setup_mitsuba(args.variant)
    if "llvm" not in variant:
        sys.exit(f"variant {variant}: Embree runs only in the LLVM variants")
    import drjit as dr

    rows = []
    for path in args.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        raw = np.fromfile(os.path.join(args.rays_dir, name + ".rays"), dtype="<f4")
        if raw.size % 14 != 0:
            sys.exit(f"{name}.rays: {raw.size} floats, not two equal sets of 7-float rays")
        arr = raw.reshape(-1, 7)
        n = len(arr) // 2
        scene = mi.load_file(path)
        dr.set_thread_count(1)
        try:
            mc, hits, cpu_c, ms, blocked, cpu_s = time_queries(mi, dr, scene, (arr[:n], arr[n:]), args.reps)
        finally:
            dr.set_thread_count(os.cpu_count())
        rows.append(dict(scene=path, rays=n, closest_mrays=mc, hits=hits, shadow_mrays=ms, blocked=blocked,
                         cpu_per_wall=[round(cpu_c, 2), round(cpu_s, 2)],
                         variant=args.variant, mitsuba_version=mi.__version__))
        if not args.json:
            print(f"{path}: Mitsuba {args.variant} (Embree), {n} rays each: closest {mc:.2f} Mrays/s ({hits} hits), "
                  f"shadow {ms:.2f} Mrays/s ({blocked} blocked); CPU / wall time {cpu_c:.2f}, {cpu_s:.2f}")
        # The closest rays by where they start (bench_traversal's groups), when it wrote them.
        by_group = closest_by_origin(mi, dr, scene, arr[:n], os.path.join(args.rays_dir, name + ".groups"), args.reps)
        if by_group is not None:
            rows[-1]["closest_by_origin"] = by_group
            if not args.json:
                for label, v in by_group.items():
                    print(f"{path}: closest from {label}: {v['rays']} rays, {v['hits']} hits, "
                          f"{v['closest_mrays']:.2f} Mrays/s")
    if args.json:
        print(json.dumps(rows))


if __name__ == "__main__":
    main()
