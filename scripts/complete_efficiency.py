#!/usr/bin/env python3
"""Equal-time efficiency of `volpath_snee connection = complete` over snee `volpath` on one paper
configuration, per seed, at equal spp, with a second build's CPU time for a before/after of an exact change.

    python3 scripts/complete_efficiency.py --config sphere_smooth_st02 --work /tmp/eff \
        --after target/release/snee --before /tmp/snee_old [--spp 2048 --seeds 12 --before-spp 1024]

Per seed s (1..seeds): `volpath` and `complete` rendered by AFTER at SPP spp with `--moment` (48x64,
1 thread, seed s); BEFORE renders the same (at BEFORE_SPP, with `--moment`) for its CPU time only: the
two builds must render the same images (check that first, e.g. with `scripts/bit_identity.sh`), so V is
shared. Cost = CPU seconds per spp (user + system of the process, the median of three 1-spp runs
subtracted: scene loading). V = mean over pixels and channels of sigma^2_p / (d_p^2 + eps), with
sigma^2_p = (m2 - x^2) n / (n - 1), d = per-pixel median over 16 `volpath` reference renders of REF_SPP
spp (seeds 5000-5015, rendered once into WORK/ref) taken over 4x4 blocks, eps = 1e-2 max(mean d,
|mean|)^2. Efficiency 1/(V c); printed: per-seed ratios complete/volpath, their geometric mean with a
95 % bootstrap interval over seeds, and the ratio pooled over seeds (mean V, mean c).
"""
import argparse, json, math, os, re, resource, statistics, subprocess
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
W, H = 48, 64
VARIANTS = {"volpath": ("volpath", ""), "complete": ("volpath_snee", '<string name="connection" value="complete"/>')}


def exr(path):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    return {name: np.array(b).reshape(H, W, 3) for name, b in mi.Bitmap(path).split()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config", default="sphere_smooth_st02")
    ap.add_argument("--work", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--before", required=True)
    ap.add_argument("--spp", type=int, default=2048)
    ap.add_argument("--before-spp", type=int, default=1024)
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--ref-spp", type=int, default=2048)
    a = ap.parse_args()
    xml_dir = os.path.join(a.work, "xml")
    os.makedirs(xml_dir, exist_ok=True)
    paper = os.path.join(ROOT, "scenes", "paper")
    for asset in ("statue.ply", "sun_sky.exr"):
        if not os.path.exists(os.path.join(xml_dir, asset)):
            os.symlink(os.path.join(paper, asset), os.path.join(xml_dir, asset))
    text = open(os.path.join(paper, a.config + ".xml")).read()
    xml = {}
    for v, (itype, extra) in VARIANTS.items():
        xml[v] = os.path.join(xml_dir, f"{a.config}.{v}.xml")
        t, n = re.subn(r'<integrator type="\$integrator">', f'<integrator type="{itype}">{extra}', text)
        assert n == 1
        open(xml[v], "w").write(t)

    def render(binary, v, seed, spp, out, moment=True):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([binary, "render", xml[v], "--threads", "1", "--spp", str(spp), "--seed", str(seed), "-D",
                        f"width={W}", "-D", f"height={H}", "-q", "-o", out] + (["--moment"] if moment else []),
                       check=True, env=dict(os.environ, RAYON_NUM_THREADS="1"))
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        return (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)

    ref = os.path.join(a.work, "ref")
    os.makedirs(ref, exist_ok=True)
    parts = []
    for i in range(16):
        p = os.path.join(ref, f"part{i}.exr")
        if not os.path.exists(p):
            render(a.after, "volpath", 5000 + i, a.ref_spp, p, moment=False)
        parts.append(exr(p)["<root>"])
    parts = np.stack(parts)
    d = np.median(parts.reshape(16, H // 4, 4, W // 4, 4, 3).mean(axis=(2, 4)), axis=0)
    d = np.repeat(np.repeat(d, 4, 0), 4, 1)
    eps = 1e-2 * max(float(d.mean()), abs(float(parts.mean()))) ** 2

    def V(path, n):
        c = exr(path)
        x, m2 = c["<root>"], c["m2"]
        return float(np.mean(np.maximum(m2 - x * x, 0) * n / (n - 1) / (d * d + eps)))

    runs = os.path.join(a.work, "runs")
    os.makedirs(runs, exist_ok=True)
    load = {(b, v): statistics.median(render(binary, v, 999, 1, os.path.join(runs, "load.exr")) for _ in range(3))
            for b, binary in (("after", a.after), ("before", a.before)) for v in VARIANTS}
    rows = []
    for seed in range(1, a.seeds + 1):
        row = {"seed": seed}
        for v in VARIANTS:
            out = os.path.join(runs, f"{v}.s{seed}.exr")
            row[f"after.{v}.tps"] = (render(a.after, v, seed, a.spp, out) - load[("after", v)]) / a.spp
            row[f"{v}.V"] = V(out, a.spp)
            t = render(a.before, v, seed, a.before_spp, os.path.join(runs, "before.exr"))
            row[f"before.{v}.tps"] = (t - load[("before", v)]) / a.before_spp
        rows.append(row)
        print(json.dumps(row), flush=True)
    json.dump({"rows": rows, "eps": eps, "spp": a.spp}, open(os.path.join(a.work, "result.json"), "w"), indent=1)
    rng = np.random.default_rng(1)
    n = len(rows)
    for tag in ("after", "before"):
        eff = np.array([(r["volpath.V"] * r[f"{tag}.volpath.tps"]) / (r["complete.V"] * r[f"{tag}.complete.tps"])
                        for r in rows])
        lr = np.log(eff)
        lo, hi = np.percentile([math.exp(rng.choice(lr, n).mean()) for _ in range(4000)], [2.5, 97.5])

        def pooled(idx):
            m = lambda k: np.mean([rows[i][k] for i in idx])
            return m("volpath.V") * m(f"{tag}.volpath.tps") / (m("complete.V") * m(f"{tag}.complete.tps"))
        plo, phi = np.percentile([pooled(rng.integers(0, n, n)) for _ in range(4000)], [2.5, 97.5])
        t = math.exp(np.mean([math.log(r[f"{tag}.complete.tps"] / r[f"{tag}.volpath.tps"]) for r in rows]))
        print(f"{tag}: complete/volpath efficiency per seed {np.round(eff, 2).tolist()}; geometric mean "
              f"{math.exp(lr.mean()):.3f} [{lo:.3f}, {hi:.3f}]; pooled {pooled(range(n)):.3f} [{plo:.3f}, {phi:.3f}]; "
              f"CPU time per sample ratio (geometric mean) {t:.3f}")


if __name__ == "__main__":
    main()
