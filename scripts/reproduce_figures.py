#!/usr/bin/env python3
"""Reproduce Koerner et al. 2016, Section 6 (Figures 3 and 4) with snee, and measure SNEE's efficiency.

The 18 configurations are scenes/paper/{light}_{boundary}_{extinction}.xml (written by
scripts/make_figure_assets.py): light in {envmap, sphere (0.006 sr), directional}, boundary in
{ggx020, ggx004, smooth}, extinction in {st02 (2 /m), st34 (34 /m)}; medium albedo 0.8, isotropic.

For every configuration it renders with ./target/release/snee (one render at a time, --threads T):

  Figure 3  equal samples, transport = snee (only the suffixes SNEE can make): left half
            volpath_snee with snee = forward (= volpath restricted to that transport), right half
            volpath_snee with snee = mis; FIG3_SPP samples per pixel each.
  Figure 4  equal time, all transport: left half `volpath`, right half `volpath_snee` (snee = mis).
            Each method renders len(SERIES) independent runs (seeds differ): the first with
            --time SERIES[0] (a timed probe; snee's --time stops between passes of doubling size,
            so it can overshoot), the others with --spp chosen from the measured samples/second so
            that the cumulative render time tracks cumsum(SERIES) (e.g. 0.5, 1, 2, 4 s). The
            spp-weighted running averages are the estimates at those times; the last one is the
            equal-time image of Figure 4.
  reference volpath_snee (snee = mis, all transport), two independent halves of REF_TIME seconds
            each, averaged. It is a long SNEE render, not a method-independent ground truth: no
            path tracer converges for a directional light behind a smooth boundary. Its own noise
            is estimated from the two halves: floor = relMSE(half A, half B) / 4 (the relMSE a
            perfect estimate would show against this reference).

relMSE is snee's (`snee compare`): mean over pixels and channels of (a - ref)^2 / (ref^2 + 1e-2).
Times are render seconds from the stats JSON (scene loading excluded), wall-clock on a shared
machine. For each configuration and method it fits relMSE = c * t^s over the series, reports the
time to reach relMSE = TARGET (c^(1/-s) form with the fitted slope; "never" when the error does not
decrease, s > -0.5), the relMSE at the equal time, and SNEE's efficiency ratio
  eff = (relMSE_volpath * t_volpath) / (relMSE_snee * t_snee)  (= efficiency 1/(relMSE t) of
volpath_snee over volpath's; > 1: SNEE wins), also with the reference floor subtracted.
It also checks consistency: z-scores of each image's mean against the reference's (standard
errors from the per-pixel second moments, --moment), and, for Figure 3, snee = forward against
snee = mis (both estimate the same integral).

Outputs (in --out, default figures/): paper_fig3.png, paper_fig4.png, paper_relmse_vs_time.png,
paper_results.md (the table, as printed), paper_results.json. Renders are cached in --work
(default target/paper_figures/<mode>): delete it or pass --force to render again.

Modes:
  --quick   FIG3_SPP = 32, SERIES = 0.5 0.5 1 2 s (cumulative 0.5..4 s), REF_TIME = 2 x 8 s.
            About 11-14 minutes with --threads 1 (loading the scene takes ~0.8 s per render).
  (full)    FIG3_SPP = 500 (the paper's), SERIES = 4 4 8 16 s (cumulative 4..32 s, the paper
            uses 30 s), REF_TIME = 2 x 300 s: about 4.5 hours with --threads 1.

Usage:  python3 scripts/reproduce_figures.py [--quick] [--threads 1] [--only PATTERN] [--force]
"""
import argparse
import fnmatch
import json
import math
import os
import re
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCENES = os.path.join(ROOT, "scenes", "paper")
SNEE = os.path.join(ROOT, "target", "release", "snee")
LIGHTS = ["envmap", "sphere", "directional"]
BOUNDARIES = ["ggx020", "ggx004", "smooth"]
EXTINCTIONS = ["st02", "st34"]
LABEL = {"envmap": "envmap", "sphere": "sphere 0.006 sr", "directional": "directional",
         "ggx020": "GGX 0.2", "ggx004": "GGX 0.04", "smooth": "smooth",
         "st02": "sigma_t 2/m", "st34": "sigma_t 34/m"}
TARGET = 0.01  # relMSE the "time to reach" column refers to
MODES = {
    "quick": {"fig3_spp": 32, "series": [0.5, 0.5, 1.0, 2.0], "ref_time": 8.0},
    "full": {"fig3_spp": 500, "series": [4.0, 4.0, 8.0, 16.0], "ref_time": 300.0},
}
# Integrator variants: name -> (integrator type, extra XML properties)
VARIANTS = {
    "volpath": ("volpath", ""),
    "snee": ("volpath_snee", ""),
    "fig3_forward": ("volpath_snee", '<string name="snee" value="forward"/><string name="transport" value="snee"/>'),
    "fig3_snee": ("volpath_snee", '<string name="snee" value="mis"/><string name="transport" value="snee"/>'),
}


def configs():
    return [f"{l}_{b}_{e}" for e in EXTINCTIONS for l in LIGHTS for b in BOUNDARIES]


# ----------------------------------------------------------------------------- rendering

def variant_xml(work, config, variant):
    """A copy of the configuration with the variant's integrator (asset paths made absolute)."""
    itype, extra = VARIANTS[variant]
    text = open(os.path.join(SCENES, config + ".xml")).read()
    text = text.replace('value="statue.ply"', f'value="{os.path.join(SCENES, "statue.ply")}"')
    text = text.replace('value="sun_sky.exr"', f'value="{os.path.join(SCENES, "sun_sky.exr")}"')
    text, n = re.subn(r'<integrator type="\$integrator">',
                      f'<integrator type="{itype}">{extra}', text)
    assert n == 1, config
    path = os.path.join(work, "xml", f"{config}.{variant}.xml")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as fh:
        fh.write(text)
    return path


def render(args, work, config, variant, tag, seed, spp=None, seconds=None):
    """Render once (cached); returns (rgb, m2, stats)."""
    out = os.path.join(work, "renders", f"{config}.{variant}.{tag}.exr")
    stats = out[:-4] + ".json"
    if args.force or not (os.path.exists(out) and os.path.exists(stats)):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        cmd = [SNEE, "render", variant_xml(work, config, variant), "-o", out, "--seed", str(seed),
               "--threads", str(args.threads), "--stats", stats, "-q", "--moment"]
        cmd += ["--spp", str(spp)] if spp is not None else ["--time", str(seconds)]
        subprocess.run(cmd, check=True)
    import mitsuba as mi
    a = np.array(mi.Bitmap(out), dtype=np.float64)
    st = json.load(open(stats))
    return a[..., :3], a[..., 3:6], st


class Estimate:
    """spp-weighted running average of independent renders, with per-pixel second moments."""

    def __init__(self):
        self.sum = None
        self.sum_m2 = None
        self.spp = 0
        self.seconds = 0.0

    def add(self, rgb, m2, st):
        s = st["spp"]
        self.sum = rgb * s if self.sum is None else self.sum + rgb * s
        self.sum_m2 = m2 * s if self.sum_m2 is None else self.sum_m2 + m2 * s
        self.spp += s
        self.seconds += st["seconds"]

    @property
    def mean(self):
        return self.sum / self.spp

    def mean_and_se(self):
        """Image mean and its standard error (pixels independent)."""
        mu = self.mean
        var_pix = np.maximum(self.sum_m2 / self.spp - mu * mu, 0.0) / self.spp
        return float(mu.mean()), float(math.sqrt(var_pix.sum()) / mu.size)


def rel_mse(a, ref):
    return float(np.mean((a - ref) ** 2 / (ref * ref + 1e-2)))


# ----------------------------------------------------------------------------- analysis

def fit_power(ts, errs):
    """Least-squares fit of log relMSE = log c + s log t; returns (c, s)."""
    lt, le = np.log(ts), np.log(np.maximum(errs, 1e-300))
    s, lc = np.polyfit(lt, le, 1)
    return float(math.exp(lc)), float(s)


def time_to(c, s, target):
    if s > -0.5:
        return math.inf
    return (target / c) ** (1.0 / s)


def finite(x):
    """JSON-safe copy: non-finite floats become null."""
    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if isinstance(x, float) and math.isinf(x):
        return "never"
    return f"{x:.{digits}g}"


def tonemap(img, scale):
    x = np.clip(img * scale, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def split(left, right):
    w = left.shape[1]
    out = np.concatenate([left[:, : w // 2], right[:, w // 2:]], axis=1)
    out[:, w // 2 - 0] = 1.0  # a thin white divider
    return out


def exposure(ref):
    lum = ref @ np.array([0.2126, 0.7152, 0.0722])
    return 0.9 / max(np.percentile(lum, 99.0), 1e-6)


def grid_png(path, title, tiles, note):
    """tiles[(ext, light, boundary)] = image; rows = extinctions, columns = light x boundary."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = [(l, b) for l in LIGHTS for b in BOUNDARIES]
    fig, axes = plt.subplots(len(EXTINCTIONS), len(cols), figsize=(1.9 * len(cols), 2.9 * len(EXTINCTIONS) + 0.6))
    for r, e in enumerate(EXTINCTIONS):
        for c, (l, b) in enumerate(cols):
            ax = axes[r, c]
            img = tiles.get((e, l, b))
            if img is not None:
                ax.imshow(img, interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"{LABEL[l]}\n{LABEL[b]}", fontsize=9)
            if c == 0:
                ax.set_ylabel(LABEL[e], fontsize=10)
    fig.suptitle(title, fontsize=11)
    fig.text(0.5, 0.01, note, ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def chart_png(path, results, mode):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(EXTINCTIONS) * 1, 9, figsize=(22, 5.6), sharex=True)
    cols = [(l, b) for l in LIGHTS for b in BOUNDARIES]
    legend = None
    for r, e in enumerate(EXTINCTIONS):
        for c, (l, b) in enumerate(cols):
            ax = axes[r, c]
            res = results.get(f"{l}_{b}_{e}")
            if res is None:
                continue
            for m, style in (("volpath", "o-"), ("snee", "s-")):
                ts, errs = res[m]["times"], res[m]["relmse"]
                ax.loglog(ts, errs, style, ms=3, label="volpath" if m == "volpath" else "volpath_snee")
            ax.axhline(res["ref_floor"], color="gray", lw=0.8, ls=":", label="ref. noise floor")
            legend = legend or ax
            ax.set_title(f"{LABEL[l]} / {LABEL[b]}\n{LABEL[e]}", fontsize=8)
            ax.tick_params(labelsize=7)
            if c == 0:
                ax.set_ylabel("relMSE", fontsize=8)
            if r == len(EXTINCTIONS) - 1:
                ax.set_xlabel("render time [s]", fontsize=8)
    if legend is not None:
        legend.legend(fontsize=6)
    fig.suptitle(f"relMSE vs render time ({mode} mode; reference: volpath_snee, 2 x {MODES[mode]['ref_time']:g} s)",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="short renders (about 12 minutes)")
    ap.add_argument("--threads", type=int, default=1, help="render threads (default 1: the machine is shared)")
    ap.add_argument("--only", default="*", help="glob over configuration names, e.g. 'directional_*'")
    ap.add_argument("--out", default=os.path.join(ROOT, "figures"))
    ap.add_argument("--work", default=None, help="render cache (default target/paper_figures/<mode>)")
    ap.add_argument("--force", action="store_true", help="render again even if cached")
    args = ap.parse_args()
    mode = "quick" if args.quick else "full"
    P = MODES[mode]
    work = os.path.abspath(args.work or os.path.join(ROOT, "target", "paper_figures", mode))
    os.makedirs(args.out, exist_ok=True)
    if not os.path.exists(SNEE):
        sys.exit(f"{SNEE} not found: run `cargo build --release` first")
    import mitsuba as mi
    mi.set_variant("scalar_rgb")

    names = [n for n in configs() if fnmatch.fnmatch(n, args.only)]
    t_start = time.time()
    results, fig3, fig4 = {}, {}, {}
    cum_times = list(np.cumsum(P["series"]))
    print(f"mode {mode}: {len(names)} configurations, Figure 3 at {P['fig3_spp']} spp, series {P['series']} s, "
          f"reference 2 x {P['ref_time']:g} s, --threads {args.threads}", flush=True)
    for k, name in enumerate(names):
        light, boundary, ext = name.split("_")
        # Reference: two independent halves.
        halves = []
        for h in range(2):
            est = Estimate()
            est.add(*render(args, work, name, "snee", f"ref{h}", seed=1000 + h, seconds=P["ref_time"]))
            halves.append(est)
        ref = Estimate()
        for h in halves:
            ref.sum = h.sum if ref.sum is None else ref.sum + h.sum
            ref.sum_m2 = h.sum_m2 if ref.sum_m2 is None else ref.sum_m2 + h.sum_m2
            ref.spp += h.spp
            ref.seconds += h.seconds
        ref_img = ref.mean
        floor = rel_mse(halves[0].mean, halves[1].mean) / 4.0
        ref_mu, ref_se = ref.mean_and_se()
        res = {"ref_spp": ref.spp, "ref_seconds": ref.seconds, "ref_floor": floor, "ref_mean": ref_mu}

        # Equal-time series, methods interleaved so that they see similar machine load.
        ests = {"volpath": Estimate(), "snee": Estimate()}
        for m in ests:
            res[m] = {"times": [], "relmse": [], "spp": []}
        for i, target in enumerate(cum_times):
            for m in ("volpath", "snee"):
                seed = 10 * i + (1 if m == "snee" else 2)
                if i == 0:  # the timed probe
                    run = render(args, work, name, m, f"t{i}", seed=seed, seconds=P["series"][0])
                else:  # spp from the measured rate, so the cumulative time tracks the target
                    rate = ests[m].spp / ests[m].seconds
                    spp = max(1, int(round(rate * (target - ests[m].seconds))))
                    run = render(args, work, name, m, f"t{i}", seed=seed, spp=spp)
                ests[m].add(*run)
                res[m]["times"].append(ests[m].seconds)
                res[m]["relmse"].append(rel_mse(ests[m].mean, ref_img))
                res[m]["spp"].append(ests[m].spp)
        for m, est in ests.items():
            c, s = fit_power(res[m]["times"], res[m]["relmse"])
            mu, se = est.mean_and_se()
            res[m].update(fit_c=c, fit_slope=s, time_to_target=time_to(c, s, TARGET), mean=mu,
                          z_vs_ref=(mu - ref_mu) / math.sqrt(se * se + ref_se * ref_se) if se + ref_se > 0 else 0.0,
                          final_relmse=res[m]["relmse"][-1], final_time=res[m]["times"][-1])

        # Figure 3: equal samples, SNEE's transport only.
        f3 = {}
        for v in ("fig3_forward", "fig3_snee"):
            est = Estimate()
            est.add(*render(args, work, name, v, "f3", seed=7, spp=P["fig3_spp"]))
            f3[v] = est
        (mf, sf), (ms, ss) = f3["fig3_forward"].mean_and_se(), f3["fig3_snee"].mean_and_se()
        res["fig3"] = {"forward_mean": mf, "snee_mean": ms,
                       "z_forward_vs_snee": (mf - ms) / math.sqrt(sf * sf + ss * ss) if sf + ss > 0 else 0.0,
                       "forward_seconds": f3["fig3_forward"].seconds, "snee_seconds": f3["fig3_snee"].seconds}
        results[name] = res

        # Images (exposure from the reference for Figure 4, from SNEE's image for Figure 3).
        key = (ext, light, boundary)
        e4 = exposure(ref_img)
        fig4[key] = split(tonemap(ests["volpath"].mean, e4), tonemap(ests["snee"].mean, e4))
        e3 = exposure(f3["fig3_snee"].mean)
        fig3[key] = split(tonemap(f3["fig3_forward"].mean, e3), tonemap(f3["fig3_snee"].mean, e3))
        vp, sn = res["volpath"], res["snee"]
        print(f"[{k + 1}/{len(names)}] {name}: relMSE@{vp['final_time']:.2f}s volpath {vp['final_relmse']:.3g}, "
              f"snee@{sn['final_time']:.2f}s {sn['final_relmse']:.3g}, floor {floor:.2g}; "
              f"z(mean vs ref) volpath {vp['z_vs_ref']:.1f} snee {sn['z_vs_ref']:.1f}; "
              f"fig3 z(forward vs snee) {res['fig3']['z_forward_vs_snee']:.1f}  "
              f"[{time.time() - t_start:.0f} s]", flush=True)

    total = time.time() - t_start
    # ------------------------------------------------------------------ outputs
    grid_png(os.path.join(args.out, "paper_fig3.png"),
             f"Figure 3: equal samples ({P['fig3_spp']} spp), SNEE's transport only - left: volpath (snee=forward), "
             f"right: volpath_snee (MIS)", fig3,
             "each tile exposed by the 99th percentile of its SNEE half; sRGB")
    grid_png(os.path.join(args.out, "paper_fig4.png"),
             f"Figure 4: equal time ({cum_times[-1]:g} s render, 1 thread), all transport - left: volpath, "
             f"right: volpath_snee (MIS)", fig4,
             "each tile exposed by the 99th percentile of its reference; sRGB")
    chart_png(os.path.join(args.out, "paper_relmse_vs_time.png"), results, mode)

    head = ("| configuration | volpath relMSE | volpath_snee relMSE | time (vp / snee) [s] | ref floor | "
            "SNEE eff. ratio | eff. ratio (floor subtracted) | t to relMSE "
            f"{TARGET:g}: volpath / snee [s] | fit slopes | z mean vs ref (vp / snee) | Fig.3 z (fwd vs snee) |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for name in names:
        r = results[name]
        vp, sn = r["volpath"], r["snee"]
        eff = (vp["final_relmse"] * vp["final_time"]) / (sn["final_relmse"] * sn["final_time"])
        dv, ds = vp["final_relmse"] - r["ref_floor"], sn["final_relmse"] - r["ref_floor"]
        effc = (dv * vp["final_time"]) / (ds * sn["final_time"]) if dv > 0 and ds > 0 else float("nan")
        r["eff_ratio"], r["eff_ratio_floor"] = eff, effc
        lines.append(
            f"| {name} | {fmt(vp['final_relmse'])} | {fmt(sn['final_relmse'])} | "
            f"{vp['final_time']:.2f} / {sn['final_time']:.2f} | {fmt(r['ref_floor'], 2)} | {fmt(eff)} | {fmt(effc)} | "
            f"{fmt(vp['time_to_target'])} / {fmt(sn['time_to_target'])} | "
            f"{vp['fit_slope']:.2f} / {sn['fit_slope']:.2f} | {vp['z_vs_ref']:.1f} / {sn['z_vs_ref']:.1f} | "
            f"{r['fig3']['z_forward_vs_snee']:.1f} |")
    table = "\n".join(lines)
    summary = (f"mode {mode}; {len(names)} configurations; wall time {total:.0f} s; reference per configuration: "
               f"volpath_snee 2 x {P['ref_time']:g} s; equal time {cum_times[-1]:g} s; Figure 3 {P['fig3_spp']} spp; "
               f"--threads {args.threads}")
    print()
    print(table)
    print()
    print(summary)
    with open(os.path.join(args.out, "paper_results.md"), "w") as fh:
        fh.write(f"<!-- written by scripts/reproduce_figures.py {'--quick' if args.quick else ''} -->\n{summary}\n\n{table}\n")
    with open(os.path.join(args.out, "paper_results.json"), "w") as fh:
        json.dump(finite({"mode": mode, "params": P, "target": TARGET, "wall_seconds": total, "results": results}),
                  fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
