#!/usr/bin/env python3
"""Reproduce Koerner et al. 2016, Section 6 (Figures 3 and 4) with snee, beside Mitsuba 3's volpath.

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
  Mitsuba   Mitsuba 3's `volpath` on the same XML file, unchanged (its default integrator=volpath),
            at equal time: paper_fig4_mitsuba.png has Figure 4's layout with Mitsuba volpath in
            the left halves and snee volpath_snee (the same images as in Figure 4) in the right.
            It runs in a subprocess per configuration (this script with --mitsuba-worker), so a
            missing package or a crash only marks Mitsuba's columns "not run" / "failed".
            Variant llvm_ad_rgb (libLLVM from DRJIT_LIBLLVM_PATH or a few standard paths), else
            scalar_rgb; the variant used is printed and recorded. Thread count: drjit's
            dr.set_thread_count(T), the same T as snee's, set after loading the scene (Mitsuba
            3.9.1 deadlocks loading the envmap scenes with a 1-thread pool; loading is untimed).
            Mitsuba has no time budget, so after loading the scene it renders 1 spp untimed
            (warm-up: JIT compilation, first-use setup), then a timed probe of MI_PROBE_SPP spp
            (not used in the estimates) gives the rate for the first run's spp (SERIES[0] x rate);
            later runs take spp from the rate measured so far, exactly as for snee. Seeds differ
            per run and per pass. Each run is rendered with Mitsuba's `moment` integrator around
            volpath (the same samples as plain volpath, plus second moments, as snee's --moment),
            in passes of at most 2^22 samples.
            What is timed: wall clock (perf_counter) around mi.render(...) of every pass and the
            copy of the developed image to numpy, MINUS the LLVM backend compilation time of the
            kernels those calls compiled (drjit's kernel history, `backend_time`; llvm kernels are
            recompiled when spp changes, and cached on disk by drjit). Excluded: Python start-up,
            scene loading, the warm-up and the probe, compilation. Tracing (codegen) and
            execution are included. The CPU time of the process is recorded too, as a check.
  reference volpath_snee (snee = mis, all transport), two independent halves of REF_TIME seconds
            each, averaged. It is a long SNEE render, not a method-independent ground truth: no
            path tracer converges for a directional light behind a smooth boundary. Its own noise
            is estimated from the two halves: floor = relMSE(half A, half B) / 4 (the relMSE a
            perfect estimate would show against this reference).

relMSE is snee's (`snee compare`): mean over pixels and channels of (a - ref)^2 / (ref^2 + 1e-2), for
all three methods against the same reference. Times are render seconds (snee: from the stats JSON,
scene loading excluded; Mitsuba: as above), wall-clock on a shared machine. For each configuration
and method it fits relMSE = c * t^s over the series, reports the time to reach relMSE = TARGET
((TARGET/c)^(1/s) with the fitted slope; "never" when the error does not decrease, s > -0.5), the
relMSE at the equal time, and SNEE's efficiency ratio
  eff = (relMSE_volpath * t_volpath) / (relMSE_snee * t_snee)  (= efficiency 1/(relMSE t) of
volpath_snee over volpath's; > 1: SNEE wins), also with the reference floor subtracted, and the
same ratio against Mitsuba's volpath, plus t_target(Mitsuba) / t_target(volpath_snee).
It also checks consistency: z-scores of each image's mean against the reference's (standard
errors from the per-pixel second moments; for Mitsuba on luminance Y, because its `moment`
integrator records second moments in XYZ; the reference's Y standard error is then bounded by
assuming fully correlated channels), and, for Figure 3, snee = forward against snee = mis (both
estimate the same integral).

Outputs (in --out, default figures/): paper_fig3.png, paper_fig4.png, paper_fig4_mitsuba.png,
paper_relmse_vs_time.png, paper_results.md (the table, as printed), paper_results.json. Renders
are cached in --work (default target/paper_figures/<mode>): delete it or pass --force to render again.

Modes:
  --quick   FIG3_SPP = 32, SERIES = 0.5 0.5 1 2 s (cumulative 0.5..4 s), REF_TIME = 2 x 8 s.
            About 10-12 minutes with --threads 1 (~33 s per configuration, of which Mitsuba ~6 s).
  (full)    FIG3_SPP = 500 (the paper's), SERIES = 4 4 8 16 s (cumulative 4..32 s, the paper
            uses 30 s), REF_TIME = 2 x 300 s: about 4.7 hours with --threads 1.

Requires: cargo build --release; pip install -r scripts/requirements.txt (numpy, matplotlib;
mitsuba only for the Mitsuba columns: --no-mitsuba skips them).

Usage:  python3 scripts/reproduce_figures.py [--quick] [--threads 1] [--only PATTERN] [--force]
                                            [--no-mitsuba] [--mitsuba-variant auto|llvm_ad_rgb|scalar_rgb]
"""
import argparse
import fnmatch
import json
import math
import os
import re
import struct
import subprocess
import sys
import time
import zlib

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
# Mitsuba: libLLVM candidates for llvm_ad_rgb (Debian's libllvm19 first), probe size, pass size.
MI_LLVM_CANDIDATES = ["/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-18.so", "/usr/lib/x86_64-linux-gnu/libLLVM-17.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-16.so", "/usr/lib/x86_64-linux-gnu/libLLVM-15.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-14.so"]
MI_PROBE_SPP = 8
MI_MAX_SAMPLES_PER_PASS = 1 << 22
MI_NOT_INSTALLED = 3  # the worker's exit code when `import mitsuba` fails
Y_WEIGHTS = np.array([0.212671, 0.715160, 0.072169])  # row Y of Mitsuba's sRGB -> XYZ matrix
# snee's integrator variants: name -> (integrator type, extra XML properties)
VARIANTS = {
    "volpath": ("volpath", ""),
    "snee": ("volpath_snee", ""),
    "fig3_forward": ("volpath_snee", '<string name="snee" value="forward"/><string name="transport" value="snee"/>'),
    # Figure 3 compares the techniques at equal samples: SNEE at every vertex (snee_rate = 1).
    "fig3_snee": ("volpath_snee", '<string name="snee" value="mis"/><string name="transport" value="snee"/>'
                  '<float name="snee_rate" value="1"/>'),
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
    ch = read_exr(out)
    rgb = np.stack([ch[c] for c in ("R", "G", "B")], axis=-1).astype(np.float64)
    m2 = np.stack([ch[c] for c in ("m2.R", "m2.G", "m2.B")], axis=-1).astype(np.float64)
    with open(stats) as fh:
        st = json.load(fh)
    return rgb, m2, st


def read_exr(path):
    """Minimal OpenEXR reader (numpy + zlib) for snee's output, so that the snee part needs no
    `mitsuba` package: single part, scan lines or one-level tiles, compression none / ZIPS / ZIP,
    half or float channels. Returns {channel name: (H, W) float32 array}."""
    with open(path, "rb") as fh:
        buf = fh.read()
    magic, version = struct.unpack_from("<ii", buf, 0)
    if magic != 20000630 or version & 0x1800:
        raise ValueError(f"{path}: not a single-part, flat OpenEXR file")
    tiled = bool(version & 0x200)
    pos, attrs = 8, {}
    while buf[pos] != 0:  # header: name\0 type\0 size value, until an empty name
        end = buf.index(b"\0", pos)
        end2 = buf.index(b"\0", end + 1)
        (size,) = struct.unpack_from("<i", buf, end2 + 1)
        attrs[buf[pos:end].decode()] = buf[end2 + 5:end2 + 5 + size]
        pos = end2 + 5 + size
    pos += 1
    channels, cpos, chlist = [], 0, attrs["channels"]
    while chlist[cpos] != 0:  # name\0 pixel_type pLinear reserved[3] xSampling ySampling
        end = chlist.index(b"\0", cpos)
        (ptype,) = struct.unpack_from("<i", chlist, end + 1)
        sampling = struct.unpack_from("<ii", chlist, end + 9)
        if sampling != (1, 1) or ptype not in (1, 2):
            raise ValueError(f"{path}: subsampled or integer channels are not supported")
        channels.append((chlist[cpos:end].decode(), np.dtype(np.float16 if ptype == 1 else np.float32)))
        cpos = end + 17
    comp = attrs["compression"][0]
    if comp not in (0, 2, 3):
        raise ValueError(f"{path}: compression {comp} is not supported (only none, ZIPS, ZIP)")
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    out = {name: np.zeros((height, width), np.float32) for name, _ in channels}
    if tiled:
        tw, th, tmode = struct.unpack("<IIB", attrs["tiles"])
        if tmode & 0xF:
            raise ValueError(f"{path}: mip- or rip-mapped tiles are not supported")
        nchunks = -(-width // tw) * -(-height // th)
    else:
        lines = 16 if comp == 3 else 1
        nchunks = -(-height // lines)
    for off in struct.unpack_from(f"<{nchunks}Q", buf, pos):
        if tiled:
            tx, ty, _, _, size = struct.unpack_from("<iiiii", buf, off)
            data = buf[off + 20:off + 20 + size]
            bx, by = tx * tw, ty * th
            w, h = min(tw, width - bx), min(th, height - by)
        else:
            y, size = struct.unpack_from("<ii", buf, off)
            data = buf[off + 8:off + 8 + size]
            bx, by = 0, y - y0
            w, h = width, min(lines, height - by)
        raw_size = w * h * sum(t.itemsize for _, t in channels)
        if comp != 0 and size < raw_size:  # zlib, then undo the predictor and the byte interleaving
            t = np.frombuffer(zlib.decompress(data), np.uint8).astype(np.int64)
            t[1:] -= 128
            t = (np.cumsum(t) & 0xFF).astype(np.uint8)
            half = (len(t) + 1) // 2
            data = np.empty_like(t)
            data[0::2], data[1::2] = t[:half], t[half:]
            data = data.tobytes()
        p = 0
        for row in range(h):  # each scan line: every channel's w values, channels in header order
            for name, typ in channels:
                out[name][by + row, bx:bx + w] = np.frombuffer(data, typ, w, p)
                p += w * typ.itemsize
    return out


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


# ----------------------------------------------------------------------------- Mitsuba 3

def mitsuba_worker(spec_path):
    """Runs in a subprocess (--mitsuba-worker SPEC.json): render one configuration's equal-time
    series with Mitsuba's volpath and write result.json + runs.npz into spec["out"]."""
    with open(spec_path) as fh:
        spec = json.load(fh)
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        for cand in MI_LLVM_CANDIDATES:
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                break
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as err:
        print(f"cannot import mitsuba: {err}", file=sys.stderr)
        return MI_NOT_INSTALLED
    variant, notes = None, []
    wanted = ["llvm_ad_rgb", "scalar_rgb"] if spec["variant"] == "auto" else [spec["variant"]]
    for v in wanted:
        try:
            mi.set_variant(v)
            if v.startswith("llvm"):  # set_variant succeeds without libLLVM; the first kernel fails
                x = mi.Float(1.0) + 1.0
                dr.eval(x)
            variant = v
            break
        except Exception as err:  # noqa: BLE001 - any failure to set up the JIT backend
            notes.append(f"{v} unavailable: {str(err).splitlines()[0] if str(err) else type(err).__name__}")
    if variant is None:
        print("no usable Mitsuba variant: " + "; ".join(notes), file=sys.stderr)
        return 2
    llvm = variant.startswith("llvm")
    if llvm:
        dr.set_flag(dr.JitFlag.KernelHistory, True)

    t0 = time.perf_counter()
    scene = mi.load_file(spec["scene"], integrator="volpath")
    load_seconds = time.perf_counter() - t0
    # The thread count is set only now: with a 1-thread pool, Mitsuba 3.9.1 / drjit 1.5 deadlock while
    # loading the envmap scenes (both variants); rendering with it works.
    dr.set_thread_count(spec["threads"])
    # `moment` around the scene's volpath: its first three channels are volpath's image (the same
    # samples as without it), then nested.X/Y/Z and m2_nested.X/Y/Z.
    integrator = mi.load_dict({"type": "moment", "nested": scene.integrator()})
    width, height = scene.sensors()[0].film().crop_size()
    pass_spp = max(1, MI_MAX_SAMPLES_PER_PASS // (width * height))

    def run(spp, seed):
        """spp samples in passes; returns the mean image (H, W, 9) and the timings."""
        if llvm:
            dr.kernel_history()  # clears the history
        acc, done, k = None, 0, 0
        c0, t0 = time.process_time(), time.perf_counter()
        while done < spp:
            n = min(pass_spp, spp - done)
            img = np.array(mi.render(scene, integrator=integrator, seed=seed + k, spp=n), dtype=np.float64)
            acc = img * n if acc is None else acc + img * n
            done += n
            k += 1
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        compile_s = sum(h.get("backend_time", 0.0) for h in dr.kernel_history()) / 1000.0 if llvm else 0.0
        timing = {"spp": spp, "seed": seed, "passes": k, "seconds": wall - compile_s, "wall_seconds": wall,
                  "cpu_seconds": cpu, "compile_seconds": compile_s}
        return acc / spp, timing

    _, warmup = run(1, 1)
    _, probe = run(MI_PROBE_SPP, 2)
    rate = MI_PROBE_SPP / max(probe["seconds"], 1e-6)
    runs, arrays, spp_sum, sec_sum = [], {}, 0, 0.0
    for i, target in enumerate(np.cumsum(spec["series"])):
        if i > 0:
            rate = spp_sum / sec_sum
        spp = max(1, int(round(rate * (target - sec_sum))))
        img, timing = run(spp, 1000 * (i + 1))
        runs.append(timing)
        spp_sum += spp
        sec_sum += timing["seconds"]
        arrays[f"rgb{i}"] = img[..., 0:3].astype(np.float32)
        arrays[f"y{i}"] = img[..., 4].astype(np.float32)
        arrays[f"m2y{i}"] = img[..., 7].astype(np.float32)
    os.makedirs(spec["out"], exist_ok=True)
    np.savez_compressed(os.path.join(spec["out"], "runs.npz"), **arrays)
    result = {"spec": spec, "variant": variant, "variant_notes": notes, "mitsuba_version": mi.__version__,
              "thread_count": dr.thread_count(), "load_seconds": load_seconds, "warmup": warmup,
              "probe": probe, "runs": runs}
    tmp = os.path.join(spec["out"], "result.json.tmp")
    with open(tmp, "w") as fh:
        json.dump(result, fh, indent=1)
    os.replace(tmp, os.path.join(spec["out"], "result.json"))
    return 0


def mitsuba_series(args, work, config, series):
    """Mitsuba's runs for one configuration (cached in WORK/mitsuba/CONFIG): a dict with status "ok",
    the worker's result and the per-run arrays, or status "not installed" / "failed: ..."."""
    out = os.path.join(work, "mitsuba", config)
    spec = {"scene": os.path.join(SCENES, config + ".xml"), "threads": args.threads, "series": list(series),
            "variant": args.mitsuba_variant, "out": out}
    result_path = os.path.join(out, "result.json")
    cached = None
    if not args.force and os.path.exists(result_path):
        with open(result_path) as fh:
            cached = json.load(fh)
        if cached.get("spec") != spec:
            cached = None
    if cached is None:
        os.makedirs(out, exist_ok=True)
        if os.path.exists(result_path):
            os.remove(result_path)
        spec_path = os.path.join(out, "spec.json")
        with open(spec_path, "w") as fh:
            json.dump(spec, fh, indent=1)
        cmd = [sys.executable, os.path.abspath(__file__), "--mitsuba-worker", spec_path]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120 + 10 * sum(series))
        except subprocess.TimeoutExpired:
            return {"status": "failed: timed out"}
        if proc.returncode == MI_NOT_INSTALLED:
            return {"status": "not installed", "detail": proc.stderr.strip()}
        if proc.returncode != 0 or not os.path.exists(result_path):
            tail = "\n".join(proc.stderr.strip().splitlines()[-15:])
            print(f"warning: Mitsuba failed on {config} (exit code {proc.returncode}):\n{tail}", file=sys.stderr)
            last = tail.splitlines()[-1] if tail else f"exit code {proc.returncode}"
            return {"status": f"failed: {last[:200]}"}
        with open(result_path) as fh:
            cached = json.load(fh)
    with np.load(os.path.join(out, "runs.npz")) as z:
        arrays = {k: z[k].astype(np.float64) for k in z.files}
    return {"status": "ok", "result": cached, "arrays": arrays}


class MitsubaEstimate:
    """spp-weighted running average of Mitsuba's runs: RGB image, luminance and its second moment."""

    def __init__(self):
        self.rgb = self.y = self.m2y = None
        self.spp = 0
        self.seconds = 0.0

    def add(self, rgb, y, m2y, spp, seconds):
        if self.rgb is None:
            self.rgb, self.y, self.m2y = rgb * spp, y * spp, m2y * spp
        else:
            self.rgb, self.y, self.m2y = self.rgb + rgb * spp, self.y + y * spp, self.m2y + m2y * spp
        self.spp += spp
        self.seconds += seconds

    @property
    def mean(self):
        return self.rgb / self.spp

    def y_mean_and_se(self):
        mu = self.y / self.spp
        var_pix = np.maximum(self.m2y / self.spp - mu * mu, 0.0) / self.spp
        return float(mu.mean()), float(math.sqrt(var_pix.sum()) / mu.size)


def y_mean_and_se_bound(est):
    """Luminance mean of a snee estimate, and an upper bound of its standard error: per-pixel
    sd(Y) <= sum_c w_c sd(c) (channels fully correlated; no cross moments are recorded)."""
    mu = est.mean
    sd = np.sqrt(np.maximum(est.sum_m2 / est.spp - mu * mu, 0.0) / est.spp)
    var_y = (sd @ Y_WEIGHTS) ** 2
    return float((mu @ Y_WEIGHTS).mean()), float(math.sqrt(var_y.sum()) / var_y.size)


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


METHODS = [  # key in the results, legend label, plot style
    ("volpath", "snee volpath", dict(marker="o", color="C0", ls="-")),
    ("snee", "snee volpath_snee", dict(marker="s", color="C1", ls="-")),
    ("mitsuba", "Mitsuba volpath", dict(marker="^", color="C2", ls="--")),
]


def chart_png(path, results, mode, cum_times, mi_note):
    """relMSE vs time, log-log: rows = lights, columns = extinction x boundary."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedLocator, FuncFormatter, LogLocator, NullFormatter, NullLocator
    cols = [(e, b) for e in EXTINCTIONS for b in BOUNDARIES]
    fig, axes = plt.subplots(len(LIGHTS), len(cols), figsize=(2.75 * len(cols), 2.5 * len(LIGHTS) + 1.0),
                             squeeze=False)
    label = FuncFormatter(lambda v, _: f"{v:g}")
    handles = {}
    for r, l in enumerate(LIGHTS):
        for c, (e, b) in enumerate(cols):
            ax = axes[r, c]
            res = results.get(f"{l}_{b}_{e}")
            if r == 0:
                ax.set_title(f"{LABEL[e]}, {LABEL[b]}", fontsize=9)
            if c == 0:
                ax.set_ylabel(f"{LABEL[l]}\nrelMSE", fontsize=9)
            if res is None:
                ax.text(0.5, 0.5, "not rendered", ha="center", va="center", fontsize=8, color="gray",
                        transform=ax.transAxes)
                ax.set_xticks([])
                ax.set_yticks([])
                continue
            lo, hi = res["ref_floor"], res["ref_floor"]
            t_lo, t_hi = cum_times[0], cum_times[-1]
            for key, name, style in METHODS:
                m = res.get(key, {})
                if not m.get("times"):
                    continue
                (h,) = ax.loglog(m["times"], m["relmse"], ms=3.5, lw=1.2, label=name, **style)
                handles[name] = h
                lo, hi = min(lo, min(m["relmse"])), max(hi, max(m["relmse"]))
                t_lo, t_hi = min(t_lo, min(m["times"])), max(t_hi, max(m["times"]))
            h = ax.axhline(res["ref_floor"], color="gray", lw=0.8, ls=":", label="reference noise floor")
            handles["reference noise floor"] = h
            # Few, plain tick labels: x at the series' times, y at decades (1-2-5 if < 1.5 decades).
            ax.set_xlim(t_lo / 1.25, t_hi * 1.25)
            ax.xaxis.set_major_locator(FixedLocator(cum_times))
            ax.xaxis.set_major_formatter(label)
            ax.xaxis.set_minor_locator(NullLocator())
            ax.set_ylim(lo / 1.5, hi * 1.5)
            subs = (1.0,) if math.log10(hi / lo) > 1.2 else (1.0, 2.0, 5.0)
            ax.yaxis.set_major_locator(LogLocator(base=10, subs=subs, numticks=6))
            ax.yaxis.set_major_formatter(label)
            ax.yaxis.set_minor_formatter(NullFormatter())
            ax.tick_params(labelsize=7, pad=1.5)
            ax.grid(True, which="major", lw=0.3, alpha=0.5)
            if r == len(LIGHTS) - 1:
                ax.set_xlabel("render time [s]", fontsize=8)
    fig.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=len(handles), fontsize=9,
               frameon=False)
    fig.suptitle(f"relMSE vs render time, log-log ({mode} mode; reference: volpath_snee, "
                 f"2 x {MODES[mode]['ref_time']:g} s; {mi_note})", fontsize=10)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97), h_pad=0.6, w_pad=0.4)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def zscore(mu, se, ref_mu, ref_se):
    den = math.sqrt(se * se + ref_se * ref_se)
    return (mu - ref_mu) / den if den > 0 else 0.0


def ratio(a, b):
    """a / b for times to target: inf / finite = inf; finite / inf = 0; inf / inf = nan."""
    if a is None or b is None or (math.isinf(a) and math.isinf(b)):
        return float("nan")
    return a / b if b > 0 else float("nan")


def fmt_ratio(x):
    return "inf" if math.isinf(x) else fmt(x)


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="short renders (about 10-12 minutes)")
    ap.add_argument("--threads", type=int, default=1,
                    help="render threads for snee and Mitsuba (default 1: the machine is shared)")
    ap.add_argument("--only", default="*", help="glob over configuration names, e.g. 'directional_*'")
    ap.add_argument("--out", default=os.path.join(ROOT, "figures"))
    ap.add_argument("--work", default=None, help="render cache (default target/paper_figures/<mode>)")
    ap.add_argument("--force", action="store_true", help="render again even if cached")
    ap.add_argument("--no-mitsuba", action="store_true", help="skip Mitsuba 3's volpath (its columns: 'not run')")
    ap.add_argument("--mitsuba-variant", default="auto", choices=["auto", "llvm_ad_rgb", "scalar_rgb"],
                    help="auto (default): llvm_ad_rgb if libLLVM loads, else scalar_rgb")
    ap.add_argument("--mitsuba-worker", metavar="SPEC.json", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.mitsuba_worker:
        return mitsuba_worker(args.mitsuba_worker)
    mode = "quick" if args.quick else "full"
    P = MODES[mode]
    work = os.path.abspath(args.work or os.path.join(ROOT, "target", "paper_figures", mode))
    os.makedirs(args.out, exist_ok=True)
    if not os.path.exists(SNEE):
        sys.exit(f"{SNEE} not found: run `cargo build --release` first")

    names = [n for n in configs() if fnmatch.fnmatch(n, args.only)]
    t_start = time.time()
    results, fig3, fig4, fig4mi = {}, {}, {}, {}
    cum_times = [float(t) for t in np.cumsum(P["series"])]
    mi_status = "not run (--no-mitsuba)" if args.no_mitsuba else None
    mi_variants = set()
    print(f"mode {mode}: {len(names)} configurations, Figure 3 at {P['fig3_spp']} spp, series {P['series']} s, "
          f"reference 2 x {P['ref_time']:g} s, --threads {args.threads}, Mitsuba: "
          f"{mi_status or 'volpath, variant ' + args.mitsuba_variant}", flush=True)
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

        # Equal-time series, snee's methods interleaved so that they see similar machine load.
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
                          z_vs_ref=zscore(mu, se, ref_mu, ref_se),
                          final_relmse=res[m]["relmse"][-1], final_time=res[m]["times"][-1])

        # Mitsuba 3's volpath at equal time, in a subprocess.
        mi_est = None
        if mi_status is None:
            mr = mitsuba_series(args, work, name, P["series"])
            if mr["status"] == "not installed":
                mi_status = "not run (the mitsuba Python package is not installed)"
                print(f"warning: Mitsuba columns not run: {mr.get('detail', '')}", file=sys.stderr)
            elif mr["status"] != "ok":
                res["mitsuba"] = {"status": mr["status"]}
            else:
                info = mr["result"]
                if info["variant_notes"] and info["variant"] not in mi_variants:
                    print(f"warning: Mitsuba uses {info['variant']}: {'; '.join(info['variant_notes'])}",
                          file=sys.stderr)
                mi_variants.add(info["variant"])
                mi_est = MitsubaEstimate()
                rm = {"status": "ok", "variant": info["variant"], "variant_notes": info["variant_notes"],
                      "thread_count": info["thread_count"], "load_seconds": info["load_seconds"],
                      "warmup": info["warmup"], "probe": info["probe"], "runs": info["runs"],
                      "times": [], "relmse": [], "spp": []}
                for i, r in enumerate(info["runs"]):
                    a = mr["arrays"]
                    mi_est.add(a[f"rgb{i}"], a[f"y{i}"], a[f"m2y{i}"], r["spp"], r["seconds"])
                    rm["times"].append(mi_est.seconds)
                    rm["relmse"].append(rel_mse(mi_est.mean, ref_img))
                    rm["spp"].append(mi_est.spp)
                c, s = fit_power(rm["times"], rm["relmse"])
                mu, se = mi_est.y_mean_and_se()
                ref_y, ref_y_se = y_mean_and_se_bound(ref)
                busy = sum(r["cpu_seconds"] - r["compile_seconds"] for r in info["runs"]) / mi_est.seconds
                rm.update(fit_c=c, fit_slope=s, time_to_target=time_to(c, s, TARGET), mean_y=mu, ref_mean_y=ref_y,
                          z_vs_ref=zscore(mu, se, ref_y, ref_y_se), cpu_per_second=busy,
                          final_relmse=rm["relmse"][-1], final_time=rm["times"][-1])
                if busy > 1.15 * args.threads:
                    print(f"warning: Mitsuba used {busy:.2f} CPU seconds per second, more than --threads "
                          f"{args.threads}", file=sys.stderr)
                res["mitsuba"] = rm
        if mi_status is not None:
            res["mitsuba"] = {"status": mi_status}

        # Figure 3: equal samples, SNEE's transport only.
        f3 = {}
        for v in ("fig3_forward", "fig3_snee"):
            est = Estimate()
            est.add(*render(args, work, name, v, "f3", seed=7, spp=P["fig3_spp"]))
            f3[v] = est
        (mf, sf), (ms, ss) = f3["fig3_forward"].mean_and_se(), f3["fig3_snee"].mean_and_se()
        res["fig3"] = {"forward_mean": mf, "snee_mean": ms, "z_forward_vs_snee": zscore(mf, sf, ms, ss),
                       "forward_seconds": f3["fig3_forward"].seconds, "snee_seconds": f3["fig3_snee"].seconds}
        results[name] = res

        # Images (exposure from the reference for Figure 4, from SNEE's image for Figure 3).
        key = (ext, light, boundary)
        e4 = exposure(ref_img)
        snee_tile = tonemap(ests["snee"].mean, e4)
        fig4[key] = split(tonemap(ests["volpath"].mean, e4), snee_tile)
        if mi_est is not None:
            fig4mi[key] = split(tonemap(mi_est.mean, e4), snee_tile)
        e3 = exposure(f3["fig3_snee"].mean)
        fig3[key] = split(tonemap(f3["fig3_forward"].mean, e3), tonemap(f3["fig3_snee"].mean, e3))
        vp, sn, mr = res["volpath"], res["snee"], res["mitsuba"]
        mi_text = (f"Mitsuba@{mr['final_time']:.2f}s {mr['final_relmse']:.3g} (z {mr['z_vs_ref']:.1f}, "
                   f"{mr['variant']}, {mr['spp'][-1]} spp)" if mr["status"] == "ok" else f"Mitsuba {mr['status']}")
        print(f"[{k + 1}/{len(names)}] {name}: relMSE volpath@{vp['final_time']:.2f}s {vp['final_relmse']:.3g}, "
              f"snee@{sn['final_time']:.2f}s {sn['final_relmse']:.3g}, {mi_text}, floor {floor:.2g}; "
              f"z(mean vs ref) volpath {vp['z_vs_ref']:.1f} snee {sn['z_vs_ref']:.1f}; "
              f"fig3 z(forward vs snee) {res['fig3']['z_forward_vs_snee']:.1f}  "
              f"[{time.time() - t_start:.0f} s]", flush=True)

    total = time.time() - t_start
    if mi_status is None:
        mi_status = "variant " + "/".join(sorted(mi_variants)) if mi_variants else "failed"
    mi_note = f"Mitsuba volpath: {mi_status}"
    # ------------------------------------------------------------------ outputs
    grid_png(os.path.join(args.out, "paper_fig3.png"),
             f"Figure 3: equal samples ({P['fig3_spp']} spp), SNEE's transport only - left: volpath (snee=forward), "
             f"right: volpath_snee (MIS)", fig3,
             "each tile exposed by the 99th percentile of its SNEE half; sRGB")
    grid_png(os.path.join(args.out, "paper_fig4.png"),
             f"Figure 4: equal time ({cum_times[-1]:g} s render, {args.threads} thread(s)), all transport - "
             f"left: volpath, right: volpath_snee (MIS)", fig4,
             "each tile exposed by the 99th percentile of its reference; sRGB")
    grid_png(os.path.join(args.out, "paper_fig4_mitsuba.png"),
             f"Figure 4 against Mitsuba 3: equal time ({cum_times[-1]:g} s render, {args.threads} thread(s)), "
             f"all transport - left: Mitsuba volpath, right: snee volpath_snee (MIS)", fig4mi,
             f"each tile exposed by the 99th percentile of its reference; sRGB; {mi_note}")
    chart_png(os.path.join(args.out, "paper_relmse_vs_time.png"), results, mode, cum_times, mi_note)

    head = ("| configuration | volpath relMSE | volpath_snee relMSE | Mitsuba volpath relMSE | "
            "time (vp / snee / Mitsuba) [s] | ref floor | SNEE eff. ratio | eff. ratio (floor subtracted) | "
            f"SNEE eff. ratio vs Mitsuba | t to relMSE {TARGET:g}: volpath / snee / Mitsuba [s] | "
            "t ratio Mitsuba / snee | fit slopes (vp / snee / Mitsuba) | z mean vs ref (vp / snee / Mitsuba Y) | "
            "Fig.3 z (fwd vs snee) |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for name in names:
        r = results[name]
        vp, sn, mr = r["volpath"], r["snee"], r["mitsuba"]
        eff = (vp["final_relmse"] * vp["final_time"]) / (sn["final_relmse"] * sn["final_time"])
        dv, ds = vp["final_relmse"] - r["ref_floor"], sn["final_relmse"] - r["ref_floor"]
        effc = (dv * vp["final_time"]) / (ds * sn["final_time"]) if dv > 0 and ds > 0 else float("nan")
        r["eff_ratio"], r["eff_ratio_floor"] = eff, effc
        if mr["status"] == "ok":
            r["eff_ratio_mitsuba"] = (mr["final_relmse"] * mr["final_time"]) / (sn["final_relmse"] * sn["final_time"])
            r["t_target_ratio_mitsuba"] = ratio(mr["time_to_target"], sn["time_to_target"])
            mi_cells = (fmt(mr["final_relmse"]), f"{mr['final_time']:.2f}", fmt(r["eff_ratio_mitsuba"]),
                        fmt(mr["time_to_target"]), fmt_ratio(r["t_target_ratio_mitsuba"]), f"{mr['fit_slope']:.2f}",
                        f"{mr['z_vs_ref']:.1f}")
        else:
            cell = "failed" if mr["status"].startswith("failed") else "not run"
            mi_cells = (cell, "-", cell, "-", "-", "-", "-")
        lines.append(
            f"| {name} | {fmt(vp['final_relmse'])} | {fmt(sn['final_relmse'])} | {mi_cells[0]} | "
            f"{vp['final_time']:.2f} / {sn['final_time']:.2f} / {mi_cells[1]} | {fmt(r['ref_floor'], 2)} | "
            f"{fmt(eff)} | {fmt(effc)} | {mi_cells[2]} | "
            f"{fmt(vp['time_to_target'])} / {fmt(sn['time_to_target'])} / {mi_cells[3]} | {mi_cells[4]} | "
            f"{vp['fit_slope']:.2f} / {sn['fit_slope']:.2f} / {mi_cells[5]} | "
            f"{vp['z_vs_ref']:.1f} / {sn['z_vs_ref']:.1f} / {mi_cells[6]} | "
            f"{r['fig3']['z_forward_vs_snee']:.1f} |")
    table = "\n".join(lines)
    summary = (f"mode {mode}; {len(names)} configurations; wall time {total:.0f} s; reference per configuration: "
               f"volpath_snee 2 x {P['ref_time']:g} s; equal time {cum_times[-1]:g} s; Figure 3 {P['fig3_spp']} spp; "
               f"--threads {args.threads}; {mi_note}")
    print()
    print(table)
    print()
    print(summary)
    with open(os.path.join(args.out, "paper_results.md"), "w") as fh:
        fh.write(f"<!-- written by scripts/reproduce_figures.py {'--quick' if args.quick else ''} -->\n{summary}\n\n{table}\n")
    with open(os.path.join(args.out, "paper_results.json"), "w") as fh:
        json.dump(finite({"mode": mode, "params": P, "target": TARGET, "threads": args.threads, "mitsuba": mi_note,
                          "wall_seconds": total, "results": results}), fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
