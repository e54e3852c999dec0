#!/usr/bin/env python3
"""Stability where path tracing fails: relative standard deviation across seeds, at equal samples,
of `volpath` and `volpath_snee` on a thick slab (sigma_t = 1, albedo 0.8, isotropic, 100 mean free
paths deep) behind a dielectric boundary (n = 1.33) of GGX roughness alpha in {0.2, 0.04, 0.01,
0.001} or smooth, under a directional light at normal incidence, read by an irradiancemeter on a
null quad above it (the scene of tests/transport/snee_slab.rs with n = 1.33).

    python3 scripts/roughness_sweep.py [--spp 8192] [--seeds 8] [--threads 2] [--rate R]
        [--connection paper|complete] [--integrators volpath,volpath_snee] [--alphas 0.2,0.04,0.01,0.001,smooth]
        [--no-surface]

Prints one table row per integrator: the relative std of the meter's reading across seeds (std /
mean of the seeds' readings), and the mean reading. volpath reads exactly 0 behind the smooth
boundary ("black"). volpath_snee runs with its default SNEE rate unless --rate is given, and with
the given `connection` (default `paper`; `complete` adds manifold NEE, docs/manifold.md).
With --no-surface also the reading without the transport class `surface` (paths with no medium
vertex: the glint of the light on the rough top face, docs/classes.md), rendered with --classes.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

import common

SNEE = os.environ.get("SNEE", os.path.join(common.ROOT, "target", "release", "snee"))


def boundary(alpha):
    if alpha is None:
        return '<bsdf type="dielectric"><float name="int_ior" value="1.33"/></bsdf>'
    return ('<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>'
            f'<float name="alpha" value="{alpha}"/><float name="int_ior" value="1.33"/></bsdf>')


def scene(integrator, alpha, spp, rate, connection="paper"):
    extra = f'<float name="snee_rate" value="{rate}"/>' if rate is not None and integrator == "volpath_snee" else ""
    if integrator == "volpath_snee":
        extra += f'<string name="connection" value="{connection}"/>'
    return f"""<scene version="3.0.0">
    <integrator type="{integrator}"><integer name="max_depth" value="-1"/>{extra}</integrator>
    <emitter type="directional"><vector name="direction" value="0, 0, -1"/><rgb name="irradiance" value="1, 1, 1"/></emitter>
    <medium type="homogeneous" id="slab"><float name="albedo" value="0.8"/><float name="sigma_t" value="1"/><phase type="isotropic"/></medium>
    <shape type="cube">
        <transform name="to_world"><scale x="100" y="100" z="50"/><translate z="-50"/></transform>
        {boundary(alpha)}
        <ref name="interior" id="slab"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="5"/><rotate x="1" angle="180"/><translate z="0.01"/></transform>
        <bsdf type="null"/>
        <sensor type="irradiancemeter">
            <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/><rfilter type="box"/></film>
        </sensor>
    </shape>
</scene>"""


def read_exr_pixel(path):
    """Channel R of a 1x1 snee EXR (float, uncompressed or zip), without mitsuba."""
    return float(common.read_exr(path)["R"].reshape(-1)[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rate", type=float, default=None, help="volpath_snee's snee_rate (default: its automatic rate)")
    ap.add_argument("--connection", default="paper", choices=["paper", "complete"], help="volpath_snee's connection")
    ap.add_argument("--integrators", default="volpath,volpath_snee", help="comma-separated")
    ap.add_argument("--alphas", default="0.2,0.04,0.01,0.001,smooth", help="comma-separated; 'smooth': dielectric")
    ap.add_argument("--no-surface", action="store_true", help="also report without the class `surface` (no medium vertex)")
    args = ap.parse_args()
    alphas = [None if a == "smooth" else float(a) for a in args.alphas.split(",")]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for integrator in args.integrators.split(","):
            cells, cells_ns = [], []
            for alpha in alphas:
                xml = os.path.join(tmp, "slab.xml")
                with open(xml, "w") as fh:
                    fh.write(scene(integrator, alpha, args.spp, args.rate, args.connection))
                vals, vals_ns = [], []
                for s in range(args.seeds):
                    out = os.path.join(tmp, "o.exr")
                    extra = ["--classes"] if args.no_surface else []
                    subprocess.run([SNEE, "render", xml, "-o", out, "--seed", str(1 + s), "--threads",
                                    str(args.threads)] + extra, check=True, capture_output=True)
                    if args.no_surface:
                        ch = common.read_exr(out)
                        vals.append(float(ch["R"].reshape(-1)[0]))
                        vals_ns.append(vals[-1] - float(ch["surface.R"].reshape(-1)[0]))
                    else:
                        vals.append(read_exr_pixel(out))
                m = statistics.fmean(vals)
                rel = statistics.stdev(vals) / m if m > 0 else float("nan")
                cells.append((m, rel))
                if vals_ns:
                    m = statistics.fmean(vals_ns)
                    cells_ns.append((m, statistics.stdev(vals_ns) / m if m > 0 else float("nan")))
            rows[integrator] = cells
            if cells_ns:
                rows[integrator + " without `surface`"] = cells_ns
    head = ["smooth" if a is None else f"{a}" for a in alphas]
    rate = "automatic" if args.rate is None else args.rate
    print(f"slab n = 1.33, albedo 0.8, directional light; {args.seeds} seeds x {args.spp} spp; snee_rate {rate}; "
          f"connection {args.connection}" )
    print("| alpha | " + " | ".join(head) + " |")
    print("|---|" + "---|" * len(head))
    for integrator, cells in rows.items():
        print(f"| {integrator} rel. std | " + " | ".join(
            "black" if m == 0 else f"{100 * r:.1f} %" for m, r in cells) + " |")
    for integrator, cells in rows.items():
        print(f"| {integrator} mean | " + " | ".join(f"{m:.4f}" for m, r in cells) + " |")
    print(json.dumps({k: [[m, r] for m, r in v] for k, v in rows.items()}))


if __name__ == "__main__":
    main()
