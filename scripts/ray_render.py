#!/usr/bin/env python3
"""Render one scene as sample-range tasks on a Ray cluster and merge the parts with `snee merge`.

    python3 scripts/ray_render.py SCENE.xml --spp 1024 -o out.exr            # this machine, all cores
    python3 scripts/ray_render.py SCENE.xml --spp 1024 -o out.exr --address auto   # join `ray start`

Each task runs `snee render SCENE --sample-range START..END` (same seed and spp for all tasks), so
the parts are disjoint pieces of one single-process render and `snee merge` reproduces it up to
float summation order. Task boundaries sit on snee's sampler chunk boundaries (0, 1, 2, 4, ... 64,
then every 64 samples) when they can, so no task replays samples another task records.

Tasks return their partial EXR as bytes, so only the driver needs to write files; every node
needs the snee binary and the scene folder at the same paths as the driver (a shared filesystem
or the same checkout everywhere; see the README, "Rendering on several machines"). A task whose
worker or node dies is retried (--max-retries); a task whose snee exits with an error is not
(bad input fails the same way everywhere), and the driver reports snee's message.

Needs: `pip install -r scripts/requirements-ray.txt` (Ray only).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

import common

REPO = common.ROOT


def chunk_boundaries(spp):
    """Sample indices where snee's sampler chunks start, up to spp."""
    b, i = [0], 1
    while i < min(spp, 64):
        b.append(i)
        i *= 2
    i = 64
    while i < spp:
        b.append(i)
        i += 64
    return b + [spp]


def split_ranges(spp, tasks):
    """About `tasks` disjoint ranges covering 0..spp, each boundary moved to the nearest chunk boundary."""
    tasks = max(1, min(tasks, spp))
    chunks = chunk_boundaries(spp)
    cuts = [0]
    for k in range(1, tasks):
        ideal = spp * k / tasks
        near = min(chunks, key=lambda c: (abs(c - ideal), c))
        if cuts[-1] < near < spp:
            cuts.append(near)
    cuts.append(spp)
    return list(zip(cuts[:-1], cuts[1:]))


def render_part(snee, scene, start, end, args):
    """Run snee for samples start..end; return the partial EXR's bytes (raises with snee's message on failure).

    With --checkpoint-dir the task checkpoints into DIR/part_START_END.exr and a retried task
    resumes from the checkpoint it finds there (on a shared folder, whichever node runs it)."""
    with tempfile.TemporaryDirectory(prefix="snee-part-") as tmp:
        out = os.path.join(args.checkpoint_dir or tmp, f"part_{start}_{end}.exr")
        cmd = [snee, "render", scene, "-o", out, "--spp", str(args.spp), "--seed", str(args.seed),
               "--sample-range", f"{start}..{end}", "--threads", str(args.cpus_per_task), "-q"]
        for d in args.define:
            cmd += ["-D", d]
        if args.moment:
            cmd.append("--moment")
        if args.checkpoint_dir:
            cmd += ["--checkpoint", str(args.checkpoint)]
            if os.path.exists(out):
                cmd += ["--resume", out]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"snee failed on samples {start}..{end}: {r.stderr.strip()}")
        with open(out, "rb") as f:
            return f.read()


def progress(done, total, t0, width=40):
    frac = done / total if total else 1.0
    bar = "#" * int(frac * width)
    sys.stderr.write(f"\r[{bar:<{width}}] {done}/{total} tasks  {time.time() - t0:6.1f} s")
    sys.stderr.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True, help="merged EXR")
    ap.add_argument("--spp", type=int, required=True, help="samples per pixel of the whole render")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("-D", dest="define", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--moment", action="store_true", help="also merge second moments (m2.* channels)")
    ap.add_argument("--tasks", type=int, default=0, help="number of sample-range tasks (default: 4 per CPU)")
    ap.add_argument("--cpus-per-task", type=int, default=1, help="CPUs reserved per task (= snee --threads)")
    ap.add_argument("--address", default=None, help="Ray cluster to join (e.g. auto, or HEAD_IP:6379); default: start one here")
    ap.add_argument("--num-cpus", type=int, default=None, help="CPUs of the local cluster (default: all)")
    ap.add_argument("--max-retries", type=int, default=3, help="retries of a task whose worker or node dies")
    ap.add_argument("--snee", default=os.path.join(REPO, "target", "release", "snee"), help="snee binary (same path on every node)")
    ap.add_argument("--checkpoint-dir", default=None, metavar="DIR",
                    help="tasks checkpoint into DIR (a folder every node sees) and retries resume from there")
    ap.add_argument("--checkpoint", type=float, default=60.0, metavar="SECONDS", help="checkpoint interval of tasks")
    ap.add_argument("--keep-parts", default=None, metavar="DIR", help="also keep the partial EXRs in DIR")
    ap.add_argument("-q", "--quiet", action="store_true")
    args = ap.parse_args()
    if args.spp < 1:
        ap.error("--spp must be at least 1")

    import ray  # imported here so that --help works without Ray

    snee = os.path.abspath(args.snee)
    if args.checkpoint_dir:
        args.checkpoint_dir = os.path.abspath(args.checkpoint_dir)
        os.makedirs(args.checkpoint_dir, exist_ok=True)
    scene = os.path.abspath(args.scene)
    for path, what in ((snee, "snee binary"), (scene, "scene")):
        if not os.path.exists(path):
            ap.error(f"{what} {path} not found")

    if args.address:
        ray.init(address=args.address, log_to_driver=False)
    else:
        # address="local": always a new cluster on this machine, never one found in RAY_ADDRESS
        # or left over from an earlier `ray start`.
        ray.init(address="local", num_cpus=args.num_cpus, include_dashboard=False, log_to_driver=False)
    try:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        tasks = args.tasks or max(1, 4 * cpus // args.cpus_per_task)
        ranges = split_ranges(args.spp, tasks)
        remote = ray.remote(render_part).options(
            num_cpus=args.cpus_per_task, max_retries=args.max_retries, retry_exceptions=False)
        pending = {remote.remote(snee, scene, s, e, args): (s, e) for s, e in ranges}
        parts = {}
        t0 = time.time()
        if not args.quiet:
            sys.stderr.write(f"{len(ranges)} tasks on {cpus} CPUs, {args.spp} spp\n")
            progress(0, len(ranges), t0)
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                rng = pending.pop(ref)
                parts[rng] = ray.get(ref)
                if not args.quiet:
                    progress(len(parts), len(ranges), t0)
        if not args.quiet:
            sys.stderr.write("\n")
    finally:
        ray.shutdown()

    folder = args.keep_parts or tempfile.mkdtemp(prefix="snee-parts-")
    os.makedirs(folder, exist_ok=True)
    files = []
    for (s, e), data in sorted(parts.items()):
        f = os.path.join(folder, f"part_{s:06d}_{e:06d}.exr")
        with open(f, "wb") as fh:
            fh.write(data)
        files.append(f)
    cmd = [snee, "merge", *files, "-o", args.output] + (["-q"] if args.quiet else [])
    r = subprocess.run(cmd)
    if not args.keep_parts:
        for f in files:
            os.remove(f)
        os.rmdir(folder)
    sys.exit(r.returncode)


if __name__ == "__main__":
    main()
