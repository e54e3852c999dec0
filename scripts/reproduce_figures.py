#!/usr/bin/env python3
"""The equal-time study of volpath_snee (Koerner et al. 2016, Section 6, Figures 3 and 4) against snee's
volpath and Mitsuba 3's volpath, on the 18 configurations of scenes/paper/ (written by
scripts/make_figure_assets.py): light in {envmap, sphere (0.006 sr), directional}, boundary in {ggx020,
ggx004, smooth}, extinction in {st02 (2 /m), st34 (34 /m)}; medium albedo 0.8, isotropic.

    python3 scripts/reproduce_figures.py --standard --refs-only --refs DIR   # references ahead, any load
    python3 scripts/reproduce_figures.py --standard --refs DIR --work WORK   # ~45 min on 2 idle cores
    python3 scripts/reproduce_figures.py --paper [--address auto]   # Ray cluster; figures/paper_size/

Per configuration (one after the other; cached per render and per configuration in --work, the
references in --refs, so an interrupted run resumes where it stopped; --force recomputes the
results from the cached renders, --force-renders renders again):

Reference (never produced by a compared method's runs), rendered by spp, not by time, so it can be
rendered ahead on a loaded machine (--refs-only) and reused:
  * resolution 1/ref_scale (2) of the width and height: with the box filter each reference pixel
    estimates the mean of a 2 x 2 block of run pixels, so the image mean (the bias test) is the
    same integral, relMSE compares the runs' 2 x 2 block averages with it, and d is replicated to
    the block's four pixels. A quarter of the pixels makes ref_factor x the spp affordable.
  * wherever volpath converges (every configuration except directional + smooth): snee `volpath`,
    ref_parts (8) independent renders (seeds 5000+) of equal spp, together >= ref_factor (100) x
    the spp of one volpath run. The spp are planned ahead from volpath's CPU-time rate (1 thread,
    measured where the reference renders: REFS/plan/) x threads x run_time x REF_HEADROOM (1.25:
    idle cores are faster than loaded ones); if the runs' probe finds a faster machine, the
    reference is topped up with more parts of the same spp, so the factor always holds.
  * directional + smooth (volpath cannot sample a delta light through a delta boundary): the same
    scene with the directional light replaced by a sphere light of solid angle Omega in the same
    direction at 1 km with the same irradiance (radiance E / (pi sin^2 alpha)), rendered with
    `volpath` for each Omega in OMEGAS, each at ds_factor (1) x ref_factor x a planned run's spp of
    that scene, and the image mean extrapolated linearly in Omega to Omega = 0 (weighted least
    squares). Its error: the intercept's standard error, and the fit's chi^2 (1 degree of freedom
    with 3 radii) as a check of the linear model. d there: ref_parts volpath_snee renders at
    d_factor (25) x a run's spp (seeds 6000+, which no run uses; d only weights pixels).
  * d, the per-pixel denominator of relative errors: the per-pixel, per-channel MEDIAN of the
    reference's independent parts: robust to fireflies and independent of the runs. Denominator
    d^2 + eps with eps = 1e-2 * (mean of d)^2.
  * the reference's own error: standard error of its image mean (per-pixel moments; channels
    bounded as fully correlated), and its own relative variance RV_ref = mean(var / (d^2 + eps)).

Methods: snee `volpath`, snee `volpath_snee` (default `connection = paper`), Mitsuba 3 `volpath`, and
  snee `volpath_snee connection = complete` where it renders something else than `paper`: decided per
  configuration by one 4-spp render of each at the same seed, compared pixel by pixel (where the
  manifold connection does not apply it draws nothing and the images are identical; the table then
  reads "same as paper").
Runs (interleaved: volpath, volpath_snee, [complete,] Mitsuba, volpath, ... so all see the same load):
  each method first renders one probe of probe x RUN_TIME seconds (not used) to measure its rate,
  then RUNS (16) independent runs with distinct seeds at the FIXED spp n = rate * RUN_TIME. snee:
  common random numbers across methods: run i of volpath, volpath_snee and complete has the same seed
  (100 + i), so the runs of one method are independent and run i of two methods is a pair. The ratios'
  bootstrap resamples run indices jointly (below), the paired bootstrap, valid whatever the correlation
  within a pair. Why: where two methods compute the same estimator (volpath_snee runs volpath's loop
  where none of its techniques applies, `forward_only`), their V_run agree run by run and the ratio
  reads their cost ratio; with disjoint seeds it read two independent draws of a heavy-tailed V
  (envmap smooth sigma_t 2: 0.82 [0.71, 0.93] for complete over volpath, which is volpath's image at
  equal seed), an interval that excluded the true value. Elsewhere the streams part at the first
  technique that draws differently, and what correlation is left only narrows the intervals. Mitsuba's
  runs keep seeds 1000 + i (another generator: no pairing). snee:
  --moment, time t from --stats (scene loading excluded). Mitsuba: a persistent worker process (this
  script with --mitsuba-worker) that loaded the unchanged XML once (default integrator volpath); a
  run is two renders of the same samples (same seed and n): the scene's volpath, timed (t is the
  wall clock around mi.render minus drjit's LLVM compile time), and `rgb_moment`
  (common.register_rgb_moment) nesting that same volpath, which returns each sample's RGB and its
  square as AOVs, so the box-filtered film holds per-pixel sample means and mean squares exactly as
  snee's --moment. Why two renders: the moment render writes 6 more film channels per sample, an
  overhead not shown to be below 2 % (JSON moment_time_over_plain_median: 0.97-1.06 per
  configuration at load 7-10, i.e. lost in the noise there), so it is not timed; JSON
  plain_vs_moment_max_rel_diff shows both are the same samples (<= 3e-7: float rounding).
  Mitsuba's own `moment` integrator is not used: it writes X, Y, Z and their squares, and the
  per-channel RGB variances need cross moments it does not write (R is a combination of X, Y, Z).
  One untimed warm-up of each kernel at n compiles them first. Variant llvm_ad_rgb (else
  scalar_rgb), dr.set_thread_count(THREADS).
Sequential runs (a rule fixed before it ran on any configuration; every mode): after the first RUNS
  runs, a configuration where a compared method's V rests on fewer than NEFF_MIN (10) effective runs
  gets RUNS more runs of every method (interleaved as above; run i has seed base + i, so new runs
  have new seeds), and again, until every compared method is at >= 10 or one more batch would pass
  the cap (max_runs: standard 48, paper 24, smoke 6; --max-runs overrides it, --max-runs RUNS is
  the fixed design). The rule reads only the runs' V_run, never a ratio, the reference or another
  configuration. JSON: runs, sequential (each step's effective runs), per method n_eff_runs and
  V_first_batch (V of the first RUNS runs: the fixed design's).
  * Effective runs: V is the mean of the runs' V_run; with w_i = V_run_i / sum V_run the runs'
    shares, Kish's n_eff = 1 / sum w_i^2 = (sum V_run)^2 / sum V_run^2 = N / (1 + CV^2) (CV: the
    V_run's coefficient of variation, ddof 0): N for equal runs, 1 when one run carries all. The
    bootstrap resamples runs, so n_eff is how many units its interval really rests on. Why 10: the
    largest share is >= 1 / n_eff, so below 10 a single run carries more than a tenth of V, more than
    the summary's +-10 % resolution, and whether it (or another like it) was drawn moves the
    ratios by more than that; at N = 16 it means CV > 0.77, a relative standard error of V of
    sqrt(1 / n_eff - 1 / N) > 19 %.
  * Not counted: methods that cannot sample the configuration's transport (CANNOT_SAMPLE: volpath
    and Mitsuba under directional + smooth, known a priori; their V is that of another integral).
  * The cap: a batch of 16 x 1 s costs ~85 s with 4 methods on 2 idle cores. In the 16-run study
    committed before this rule, 8 of 18 configurations had a method below 10 at 16 runs (4 of them
    below 5); at two batches (the cap) for those 4 and one for the others, ~12 batches, ~17 min:
    ~47 min in all; if every configuration ran to 48, ~80 min, within the 90 min the standard size
    must fit (a cap of 64 could reach ~130 min).
  * Bias of stopping on the tails: more runs follow where the first runs happened to hold rare large
    V_run (V high, n_eff low) and none where they did not (V low), so the final V is biased low (V of
    the first RUNS runs is not). Simulated (20000 repetitions of the rule, against the first 16 runs
    of the same repetitions) with the 64 real V_run of volpath_snee on sphere_ggx004_st34 as the
    population: -2.5 % on V (28 runs on average); lognormal V_run (sigma 1, 1.5): -2.8 %, -3 %;
    Pareto (alpha 2.5, 1.8): -2.2 %, -6.5 %: small against the intervals (median x/÷ 1.25 in
    the 16-run study). The efficiency 1 / (V c) is biased up at any fixed N (Jensen:
    +7 %, +10 %, +35 %, +3 %, +10 % at 16 runs there), which the rule changes by -14 to +3 points. The
    rule does not raise the intervals' coverage (a tail no run drew is missing either way; 95 % BCa
    intervals of V, 400 repetitions: 0.89 fixed 16 and 0.86 sequential on the real runs, 0.92 at a
    fixed 32); what it buys is fewer cells resting on one or two runs. The cap bounds the cost;
    where a method is still below 10 at the cap, its ratio cells are flagged (‡ in the table).

Efficiency (per method): V = per-sample relative variance = mean over pixels and channels of
sigma^2_p / (d_p^2 + eps); c = seconds per sample per pixel = sum t / (N n); a render of time t has
relative variance RV(t) = V c / t, so efficiency = 1 / (RV t) = 1 / (V c).
  * V from per-pixel moments, the same way for every method (snee's and Mitsuba's): per run,
    sigma^2_p = (m2_p - x_p^2) n / (n - 1) (m2 is the per-pixel mean of the squared samples;
    unbiased per run); V_run = mean over pixels and channels of sigma^2_p / (d_p^2 + eps); V = mean
    over runs.
  * A check (JSON V_spread, V_over_V_spread = [V / V_spread, 95 % bootstrap interval]): V from the
    spread of the runs: with s^2_p the sample variance (ddof 1) of pixel p over the N runs,
    E[s^2_p] = sigma^2_p / n, so V_spread = n * mean(s^2_p / (d^2 + eps)) estimates the same
    quantity from the same samples (before Mitsuba's runs had moments, its V).
  * Ratios volpath_snee / volpath, volpath_snee / Mitsuba volpath (and complete / volpath_snee),
    with a 95 % BCa bootstrap over the N runs (run indices resampled jointly for all methods:
    interleaved runs share the load); in the V_spread check's bootstrap a resampled spread estimate
    is multiplied by N / (N - 1) (the bootstrap's bias of a ddof-1 variance). An undecided
    ratio whose interval lies within [1/1.1, 1.1] is counted as "equal within +-10 %". Seed
    stability: every ratio is also computed from each half of the runs (seeds +0..N/2-1 and
    +N/2..N-1, JSON `halves`, with their own bootstrap intervals); the summary counts the
    configurations whose two halves' intervals overlap and, where they do not, names the method
    whose V differs most between the halves (JSON V_halves). JSON V_top_pixel_share: per run, the
    largest single pixel's share of V_run, averaged over the runs (near 1: V rests on a few rare,
    bright samples, and 8 runs may or may not contain one).
  * Why BCa (common.bootstrap_ci; Efron & Tibshirani 1993, Ch. 14) and not the percentile interval:
    V_run is right-skewed where V rests on rare bright samples, so the mean of 16 of them is
    skewed and the percentile interval's upper end is too low (its misses lie below the truth).
    BCa moves the quantile levels by the replicates' median bias and the jackknife's skewness
    (acceleration); it is second-order accurate for smooth functions of means such as the
    efficiency ratio, where the percentile interval is first-order. Coverage of 95 % intervals of V
    from 16 runs (400 repetitions, common.bootstrap_ci): runs drawn from the 64 real V_run of
    volpath_snee on sphere_ggx004_st34, percentile 0.88, BCa 0.89 (drawn without replacement, as
    a check: 0.89 and 0.94); lognormal V_run sigma 1 / 1.5: 0.84 / 0.72 and 0.87 / 0.79; Pareto
    alpha 2.5 / 1.8: 0.81 / 0.68 and 0.83 / 0.72. Better in every case, nominal in none: a tail that
    no run drew widens no interval.
  * Why 16 runs x 1 s (figures/README.md, "Choosing the standard size"): V is a mean of squared,
    heavy-tailed samples; its relative error falls as 1/sqrt(samples per method), and the width of
    the intervals is set by the samples, not by the number of pixels, so the standard size buys
    samples (~16 M per method on 2 idle cores) and enough runs (16) for the bootstrap.
  * A ratio where the compared method fails the bias test measures the variance of an estimate of
    a different integral (volpath under directional + smooth is black): flagged in the table.
Bias: image mean (pixels and channels) of the N-run average against the reference; standard
  error from the moments (every method; for Mitsuba also, as a check, a t statistic from the spread
  of the runs' means: JSON t_stat_spread), plus the reference's; |z| judged at the Sidak threshold
  for family-wise 1 % over all tests.
Firefly rate: each method renders the scene once at FIREFLY_SCALE times the width and height with
  1 spp (box filter: each pixel is one sample, distributed over the film as the samples of the
  normal render); rate = samples per 10^6 whose luminance exceeds 100 x the reference image's mean
  luminance.
relMSE (secondary): mean over the reference's pixels of (2 x 2 block average of the runs' average -
  reference)^2 / (d^2 + eps); its expectation is RV(average, at that resolution) + RV_ref + bias^2.
Transport classes: when `snee render --help` lists --classes, one more untimed run per snee method
  at n spp with --classes --moment: each class's share of V (V_class / V, from the same samples) and
  of the energy, and the classes' sum against the image (max |sum - image| / max image, must be
  <= CLASS_SUM_TOL = 1e-5, float32 rounding) -- on every configuration.
Figure 3: equal samples (FIG3_SPP), transport = snee: volpath_snee snee = forward (left halves)
  against snee = mis with snee_rate = 1 (right halves); z of the image means.
Figure 4: the average of the N runs (equal time) of volpath | volpath_snee, and Mitsuba | snee.

Time: the script prints an a-priori estimate (estimate_seconds) at the start, a projection after
each configuration and the wall time at the end; the JSON has each configuration's phases
(`timing`). References missing from --refs are rendered (or topped up) first and add to it.

Sizes:
  --standard  RUN_TIME 1 s x 16 runs (up to 48, sequential), probe 0.25 s, references 1/2 resolution at
              >= 100 x a volpath run's spp (8 parts), directional + smooth 1 x that per radius, FIG3_SPP
              32, 2 threads, firefly renders at 6x resolution. Outputs committed in figures/.
  --paper     RUN_TIME 30 s x 8 runs (up to 24), references >= 100 x (10 parts), FIG3_SPP 500 (the paper's), 1
              thread per task, firefly renders at 16x resolution; each configuration is one Ray task
              (`ray.init()` here by default, --address to join a cluster started with `ray start`;
              --work and --refs must then be folders every node sees). Outputs in figures/paper_size/.
  --smoke     seconds per configuration, to check the pipeline (also with --ray); its numbers mean nothing.

Outputs (--out): study.md (the table), study.json (everything), study_error_vs_time.png,
paper_fig3.png, paper_fig4.png, paper_fig4_mitsuba.png.
Requires: cargo build --release; pip install -r scripts/requirements.txt; Ray for --paper.
"""
import argparse
import fnmatch
import glob
import json
import math
import os
import re
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import read_exr, rgb_of  # noqa: E402,F401  (read_exr: also imported by roughness_sweep.py)

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCENES = os.path.join(ROOT, "scenes", "paper")
SNEE = os.path.join(ROOT, "target", "release", "snee")
LIGHTS = ["envmap", "sphere", "directional"]
BOUNDARIES = ["ggx020", "ggx004", "smooth"]
EXTINCTIONS = ["st02", "st34"]
LABEL = {"envmap": "envmap", "sphere": "sphere 0.006 sr", "directional": "directional",
         "ggx020": "GGX 0.2", "ggx004": "GGX 0.04", "smooth": "smooth",
         "st02": "sigma_t 2/m", "st34": "sigma_t 34/m"}
MODES = {
    "standard": {"fig3_spp": 32, "run_time": 1.0, "runs": 16, "probe": 0.25, "ref_factor": 100, "ref_parts": 8,
                 "ref_scale": 2, "ds_factor": 1, "d_factor": 25, "omegas": [0.006, 0.003, 0.0015],
                 "firefly_scale": 6, "threads": 2, "boot": 2000, "max_runs": 48},
    "paper": {"fig3_spp": 500, "run_time": 30.0, "runs": 8, "probe": 0.25, "ref_factor": 100, "ref_parts": 10,
              "ref_scale": 2, "ds_factor": 2, "d_factor": 25, "omegas": [0.006, 0.003, 0.0015],
              "firefly_scale": 16, "threads": 1, "boot": 4000, "max_runs": 24},
    # --smoke: a check that the pipeline runs (seconds per configuration); its numbers mean nothing.
    "smoke": {"fig3_spp": 4, "run_time": 0.1, "runs": 3, "probe": 0.5, "ref_factor": 4, "ref_parts": 2,
              "ref_scale": 2, "ds_factor": 1, "d_factor": 2, "omegas": [0.006, 0.003, 0.0015],
              "firefly_scale": 2, "threads": 2, "boot": 200, "max_runs": 6},
}
# The references' spp come from a CPU-time rate measured on the (possibly loaded) machine that renders
# them; an idle machine's runs get more spp per second (no hyper-thread or cache contention): the
# planned spp are this factor above the measured rate's prediction.
REF_HEADROOM = 1.25
SPHERE_DISTANCE = 1000.0  # m: the irradiance varies by +-0.1 % over the 1 m statue
FIREFLY_FACTOR = 100.0
ALPHA = 0.01  # family-wise level of the bias tests
CLASS_ORDER = ["surface", "single", "snee_support", "snee_hidden", "surface_before_last", "internal_reflection",
               "other"]  # docs/classes.md
BOOT = "bca"  # the intervals' bootstrap (common.bootstrap_ci); why BCa: the module docstring
EQUAL_WITHIN = 0.1  # an undecided ratio whose interval lies in [1/1.1, 1.1] reads "equal within +-10 %"
RUN_COUNTS = (1, 2, 4, 8, 16, 32)  # relMSE of the average of the first k runs (and of all; JSON relmse_k, the chart)
# Sequential runs (module docstring, "Runs"): a configuration where a compared method's V rests on fewer
# than NEFF_MIN effective runs (Kish) gets more runs, a batch of the mode's `runs` at a time, up to the
# mode's `max_runs`; where it is still below at the cap, its ratio cells are flagged. Fixed before the
# extended design ran on any configuration; why 10: see the docstring.
NEFF_MIN = 10.0
# (light, boundary) -> methods that cannot sample its transport (a delta light through a delta boundary):
# their V is that of a different integral, so their effective runs do not extend the runs.
CANNOT_SAMPLE = {("directional", "smooth"): ("volpath", "mitsuba")}
# Expected extension batches per configuration, for the a-priori time estimate only: in the committed
# 16 x 1 s run, 8 of 18 configurations had a compared method below NEFF_MIN at 16 runs; counting the 4 of
# them below 5 at two batches (to the cap) and the 4 others at one, 12 batches for 18 configurations.
EXPECTED_BATCHES_PER_CONFIG = 12 / 18
CLASS_SUM_TOL = 1e-5  # the classes' sum against the image: max |difference| / max |image| (float32 EXR)
LUM = np.array([0.212671, 0.715160, 0.072169])
MI_NOT_INSTALLED = 3
MI_V_NOTE = "Mitsuba's from rgb_moment AOVs of the same samples as a plain, timed render"
MI_RUN = "mitsuba.momentrun"  # cache tag of Mitsuba's runs (NAME.mitsuba.momentrunI.npy/.json)
RENDERED = [0]  # renders this process ran (a re-analysis of cached renders keeps the first run's times)
# snee's integrator variants: name -> (integrator type, extra XML properties)
VARIANTS = {
    "volpath": ("volpath", ""),
    "snee": ("volpath_snee", ""),
    "fig3_forward": ("volpath_snee", '<string name="snee" value="forward"/><string name="transport" value="snee"/>'),
    "fig3_snee": ("volpath_snee", '<string name="snee" value="mis"/><string name="transport" value="snee"/>'
                  '<float name="snee_rate" value="1"/>'),
    "complete": ("volpath_snee", '<string name="connection" value="complete"/>'),
}
METHODS = [  # key, label, plot style
    ("volpath", "snee volpath", dict(color="C0", marker="o")),
    ("snee", "snee volpath_snee", dict(color="C1", marker="s")),
    ("mitsuba", "Mitsuba volpath", dict(color="C2", marker="^")),
    ("complete", "snee volpath_snee connection=complete", dict(color="C3", marker="D")),
]


def run_counts(n):
    """The run counts of relmse_k and the chart: RUN_COUNTS up to n, and n."""
    return sorted({k for k in RUN_COUNTS if k <= n} | {n})


def configs():
    return [f"{l}_{b}_{e}" for e in EXTINCTIONS for l in LIGHTS for b in BOUNDARIES]


# ----------------------------------------------------------------------------- scenes and renders

def scene_text(config):
    text = open(os.path.join(SCENES, config + ".xml")).read()
    text = text.replace('value="statue.ply"', f'value="{os.path.join(SCENES, "statue.ply")}"')
    return text.replace('value="sun_sky.exr"', f'value="{os.path.join(SCENES, "sun_sky.exr")}"')


def with_sphere_light(text, omega):
    """The directional light replaced by a sphere light of solid angle omega, same direction and
    irradiance (pi L sin^2 alpha = E on a plane facing it), at SPHERE_DISTANCE."""
    m = re.search(r'<emitter type="directional">.*?</emitter>', text, re.S)
    d = np.array([float(v) for v in re.search(r'x="([^"]+)" y="([^"]+)" z="([^"]+)"', m.group(0)).groups()])
    e = np.array([float(v) for v in re.search(r'name="irradiance" value="([^"]+)"', m.group(0)).group(1).split(",")])
    d /= np.linalg.norm(d)
    cos_a = 1.0 - omega / (2.0 * math.pi)
    sin_a = math.sqrt(1.0 - cos_a * cos_a)
    c = -d * SPHERE_DISTANCE
    radiance = e / (math.pi * sin_a * sin_a)
    sphere = (f'<shape type="sphere"><point name="center" x="{c[0]:.6f}" y="{c[1]:.6f}" z="{c[2]:.6f}"/>'
              f'<float name="radius" value="{SPHERE_DISTANCE * sin_a:.6f}"/><emitter type="area">'
              f'<rgb name="radiance" value="{radiance[0]:.6f}, {radiance[1]:.6f}, {radiance[2]:.6f}"/>'
              f'</emitter></shape>')
    return text[:m.start()] + sphere + text[m.end():]


def variant_xml(work, config, variant, omega=None):
    """A copy of the configuration with the variant's integrator (and, with omega, the sphere light)."""
    itype, extra = VARIANTS[variant]
    text = scene_text(config)
    if omega is not None:
        text = with_sphere_light(text, omega)
    text, n = re.subn(r'<integrator type="\$integrator">', f'<integrator type="{itype}">{extra}', text)
    assert n == 1, config
    tag = f"{config}.{variant}" + (f".omega{omega:g}" if omega is not None else "")
    path = os.path.join(work, "xml", tag + ".xml")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if not os.path.exists(path) or open(path).read() != text:
        with open(path, "w") as fh:
            fh.write(text)
    return path


def snee_render(args, work, xml, tag, seed, spp=None, seconds=None, extra=()):
    """One snee render (cached in WORK/renders/TAG.exr + .json); returns (channels, stats)."""
    out = os.path.join(work, "renders", tag + ".exr")
    stats = out[:-4] + ".json"
    if args.force_renders or not (os.path.exists(out) and os.path.exists(stats)):
        RENDERED[0] += 1
        os.makedirs(os.path.dirname(out), exist_ok=True)
        cmd = [args.snee, "render", xml, "-o", out, "--seed", str(seed), "--threads", str(args.threads),
               "--stats", stats, "-q", *extra]
        cmd += ["--spp", str(spp)] if spp is not None else ["--time", str(seconds)]
        subprocess.run(cmd, check=True)
    with open(stats) as fh:
        return read_exr(out), json.load(fh)


# ----------------------------------------------------------------------------- Mitsuba worker

def mitsuba_worker(scene, threads, variant):
    """Runs in a subprocess: load SCENE once, then answer JSON commands read line by line on stdin
    with one line "@@{json}" on stdout each: {"cmd": "probe", "seconds": S}, {"cmd": "render",
    "spp": N, "seed": S, "out": NPY or null, "moment": bool}, {"cmd": "run", "spp": N, "seed": S,
    "out": NPY}, {"cmd": "firefly", "scale": K, "seed": S, "out": NPY}.

    "run" is one of the study's runs: a plain render (the scene's volpath; timed: its seconds are
    the run's t) and a render of the same samples (same seed and spp) with `rgb_moment` nesting
    that volpath (common.register_rgb_moment: the RGB value and its square per sample as AOVs);
    NPY gets the latter's per-pixel means and mean squares, (H, W, 6) = R, G, B, m2.R, m2.G, m2.B.
    Its reply also has the moment render's seconds and the largest difference between the two
    images relative to the image's maximum (the same samples: float rounding)."""
    def reply(obj):
        sys.stdout.write("@@" + json.dumps(obj) + "\n")
        sys.stdout.flush()
    try:
        mi, dr, variant, notes = common.mitsuba_setup(variant)
    except ImportError as err:
        reply({"error": f"cannot import mitsuba: {err}"})
        return MI_NOT_INSTALLED
    llvm = variant.startswith("llvm")
    if llvm:
        dr.set_flag(dr.JitFlag.KernelHistory, True)
    t0 = time.perf_counter()
    sc = mi.load_file(scene, integrator="volpath")
    load_seconds = time.perf_counter() - t0
    # Set only now: with a 1-thread pool Mitsuba 3.9.1 deadlocks loading the envmap scenes.
    dr.set_thread_count(threads)
    width, height = sc.sensors()[0].film().crop_size()
    scaled = {}
    common.register_rgb_moment(mi)
    moment = mi.load_dict({"type": "rgb_moment", "nested": sc.integrator()})

    def run(scene_obj, spp, seed, integrator=None):
        """(image channels, timing): all channels (with `moment`: R, G, B, mean.R/G/B, m2.R/G/B)."""
        if llvm:
            dr.kernel_history()  # clears the history
        c0, t0 = time.process_time(), time.perf_counter()
        img = np.array(mi.render(scene_obj, integrator=integrator, seed=seed, spp=spp), dtype=np.float32)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        compile_s = sum(h.get("backend_time", 0.0) for h in dr.kernel_history()) / 1000.0 if llvm else 0.0
        return img, {"spp": spp, "seed": seed, "seconds": wall - compile_s, "wall_seconds": wall,
                     "cpu_seconds": cpu, "compile_seconds": compile_s}

    reply({"ready": True, "variant": variant, "notes": notes, "load_seconds": load_seconds,
           "mitsuba_version": mi.__version__, "thread_count": dr.thread_count(), "size": [width, height]})
    for line in sys.stdin:
        cmd = json.loads(line)
        if cmd["cmd"] == "quit":
            break
        if cmd["cmd"] == "probe":  # doubling spp until a render takes at least a quarter of the budget
            run(sc, 1, 1)
            spp = 1
            while True:
                _, t = run(sc, spp, 2)
                if t["seconds"] >= cmd["seconds"] / 4 or spp >= 1 << 20:
                    break
                spp *= 2
            reply({"rate": spp / max(t["seconds"], 1e-9), "probe": t})
        elif cmd["cmd"] == "render":
            img, t = run(sc, cmd["spp"], cmd["seed"], moment if cmd.get("moment") else None)
            if cmd.get("out"):
                np.save(cmd["out"], img[..., :3])
            reply(t)
        elif cmd["cmd"] == "run":
            plain, t = run(sc, cmd["spp"], cmd["seed"])
            img, tm = run(sc, cmd["spp"], cmd["seed"], moment)
            np.save(cmd["out"], img[..., 3:9])  # mean.R/G/B, m2.R/G/B
            t.update(moment_seconds=tm["seconds"], moment_compile_seconds=tm["compile_seconds"],
                     plain_vs_moment=float(np.max(np.abs(plain[..., :3] - img[..., 3:6])) /
                                           max(float(np.max(np.abs(plain[..., :3]))), 1e-30)))
            reply(t)
        elif cmd["cmd"] == "firefly":
            k = cmd["scale"]
            if k not in scaled:
                scaled[k] = mi.load_file(scene, integrator="volpath", width=width * k, height=height * k)
            img, t = run(scaled[k], 1, cmd["seed"])
            np.save(cmd["out"], img[..., :3])
            reply(t)
    return 0


def mi_warm_up(mit, spp):
    """Untimed renders at the runs' spp that compile the plain and the moment kernel."""
    for moment in (False, True):
        mit.call({"cmd": "render", "spp": spp, "seed": 3, "out": None, "moment": moment})


class Mitsuba:
    """The persistent worker, started on first use; status "ok", "not installed" or "failed: ..."."""

    def __init__(self, args, config):
        self.args, self.config, self.proc, self.info, self.status = args, config, None, None, "ok"

    def call(self, cmd):
        if self.status != "ok":
            return None
        if self.proc is None:
            spec = [sys.executable, os.path.abspath(__file__), "--mitsuba-worker",
                    os.path.join(SCENES, self.config + ".xml"), str(self.args.threads), self.args.mitsuba_variant]
            self.proc = subprocess.Popen(spec, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
            self.info = self._read()
            if self.info is None or "error" in self.info:
                self.status = "not installed" if self.info and "import" in self.info.get("error", "") else \
                    f"failed: {(self.info or {}).get('error', 'worker exited')}"
                return None
        self.proc.stdin.write(json.dumps(cmd) + "\n")
        self.proc.stdin.flush()
        r = self._read()
        if r is None:
            self.status = "failed: worker exited"
        return r

    def _read(self):
        for line in self.proc.stdout:
            if line.startswith("@@"):
                return json.loads(line[2:])
        return None

    def close(self):
        if self.proc is not None:
            try:
                self.proc.stdin.write('{"cmd": "quit"}\n')
                self.proc.stdin.close()
            except (BrokenPipeError, OSError):
                pass
            self.proc.wait(timeout=60)


# ----------------------------------------------------------------------------- statistics

def sample_var(x, m2, n):
    """Per-pixel, per-channel unbiased per-sample variance from the per-pixel means x and mean
    squares m2 of n samples (box filter: each pixel's own samples)."""
    return np.maximum(m2 - x * x, 0.0) * n / max(n - 1, 1)


def moment_var(ch, n, prefix=""):
    """sample_var of a snee --moment render of n spp (channels R/G/B and m2.R/G/B, or a class's)."""
    x = rgb_of(ch, prefix)
    m2 = rgb_of(ch, prefix + "m2.") if prefix == "" else rgb_of(ch, prefix[:-1] + ".m2.")
    return sample_var(x, m2, n)


def mean_se_bound(mean, var_sample, n):
    """Image mean (pixels, channels) and an upper bound of its standard error (channels of a pixel
    fully correlated: sd of the channel average <= average of the channel sds)."""
    sd_pix = np.sqrt(var_sample / n).mean(axis=-1)
    return float(mean.mean()), float(math.sqrt(np.sum(sd_pix ** 2)) / sd_pix.size)


def zscore(mu, se, ref_mu, ref_se):
    den = math.sqrt(se * se + ref_se * ref_se)
    return (mu - ref_mu) / den if den > 0 else (0.0 if mu == ref_mu else math.copysign(math.inf, mu - ref_mu))


def class_shares(ch, n, denom):
    """Per transport class (channels CLASS.R/G/B, CLASS.m2.R/G/B of a --classes --moment render of n
    spp): its share V_class / V of the per-sample relative variance, and the classes' sum against
    the image (max relative difference)."""
    names = sorted({c[:-2] for c in ch if c.endswith(".R") and not c.startswith("m2.") and ".m2." not in c})
    v_total = float(np.mean(moment_var(ch, n) / denom))
    img = rgb_of(ch)
    total = sum(rgb_of(ch, c + ".") for c in names)
    return {"V": v_total, "sum_max_rel_diff": float(np.max(np.abs(total - img)) / max(np.max(np.abs(img)), 1e-30)),
            "share": {c: safe_div(float(np.mean(moment_var(ch, n, c + ".") / denom)), v_total) for c in names},
            "energy": {c: safe_div(float(rgb_of(ch, c + ".").sum()), float(img.sum())) for c in names}}


def kish(v):
    """Kish's effective number of runs behind a mean of per-run values v (here V_run): (sum v)^2 /
    sum v^2 = 1 / sum w_i^2 with w_i = v_i / sum v the runs' shares; N for equal runs, 1 when one run
    carries everything; the largest share is >= 1 / kish. None when every v is 0 (nothing to estimate)."""
    v = np.asarray(v, dtype=np.float64)
    ss = float(np.sum(v * v))
    return float(np.sum(v)) ** 2 / ss if ss > 0 else None


def safe_div(a, b):
    """a / b with x / 0 = inf (x > 0), 0 / 0 = nan, inf / inf = nan."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.float64(a) / np.float64(b))


def firefly_rate(img, ref_mean_lum):
    lum = img @ LUM
    return float(np.count_nonzero(lum > FIREFLY_FACTOR * ref_mean_lum) / lum.size * 1e6)


# ----------------------------------------------------------------------------- one configuration

def film_size(config):
    """(width, height) of a configuration's film (its <default> values)."""
    text = scene_text(config)
    w, h = (int(re.search(rf'<default name="{k}" value="(\d+)"/>', text).group(1)) for k in ("width", "height"))
    return w, h


def half_size(config, scale):
    w, h = film_size(config)
    assert w % scale == 0 and h % scale == 0, config
    return ["-D", f"width={w // scale}", "-D", f"height={h // scale}"]


def cpu_rate(args, refs, xml, tag):
    """Samples per CPU-second of one thread rendering XML at the run's resolution (cached in
    REFS/plan/TAG.json): the CPU times of two 1-thread renders (2 and 18 spp) differ by 16 spp, so
    scene loading cancels. Measured under any load (CPU time, not wall time)."""
    path = os.path.join(refs, "plan", tag + ".json")
    if os.path.exists(path):
        with open(path) as fh:
            return json.load(fh)["samples_per_cpu_second"]
    os.makedirs(os.path.dirname(path), exist_ok=True)
    out = os.path.join(refs, "plan", tag + ".probe.exr")

    def cpu(spp):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([args.snee, "render", xml, "-o", out, "--spp", str(spp), "--threads", "1", "-q"], check=True)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        return (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)
    w, h = film_size(tag.split(".")[0])
    seconds = max(cpu(18) - cpu(2), 1e-3)
    rate = 16 * w * h / seconds
    os.remove(out)
    common.write_json_atomic(path, {"samples_per_cpu_second": rate, "cpu_seconds_16spp": seconds})
    return rate


def planned_spp(args, P, refs, name, xml, tag, factor):
    """Reference spp per pixel (at 1/ref_scale resolution), a multiple of ref_parts: factor x the
    spp a run of XML would get on an idle machine (args.threads threads x run_time x the 1-thread
    CPU rate, times REF_HEADROOM: idle cores run faster than the loaded ones the rate was
    measured on)."""
    w, h = film_size(name)
    run_spp = args.threads * P["run_time"] * cpu_rate(args, refs, xml, tag) / (w * h) * REF_HEADROOM
    per_part = max(1, math.ceil(factor * run_spp / P["ref_parts"]))
    return per_part, run_spp


def render_parts(args, P, refs, name, xml, tag, per_part, seed0, need_spp=0):
    """ref_parts renders of per_part spp at 1/ref_scale resolution with --moment (seeds seed0 + k),
    plus as many more as reach need_spp in total (a reference that an idle machine's faster runs
    outgrew is topped up, not replaced)."""
    done = glob.glob(os.path.join(refs, "renders", glob.escape(tag) + ".*spp.0.json"))
    if done:  # parts rendered under an earlier plan (another headroom, rate or machine) stay valid
        per_part = int(re.search(r"\.(\d+)spp\.0\.json$", done[0]).group(1))
    count = max(P["ref_parts"], math.ceil(need_spp / per_part))
    return [snee_render(args, refs, xml, f"{tag}.{per_part}spp.{k}", seed=seed0 + k, spp=per_part,
                        extra=["--moment", *half_size(name, P["ref_scale"])]) for k in range(count)]


def pooled(parts):
    """spp-weighted mean, per-sample variance (ddof 1) and total spp of --moment parts."""
    n = sum(st["spp"] for _, st in parts)
    mean = sum(rgb_of(ch) * st["spp"] for ch, st in parts) / n
    m2 = sum(rgb_of(ch, "m2.") * st["spp"] for ch, st in parts) / n
    return mean, np.maximum(m2 - mean * mean, 0) * n / max(n - 1, 1), n


def reference(args, P, refs, name, need_spp=0):
    """The configuration's reference (see the module docstring), rendered into (or read from) REFS.
    Images (image, d) are at 1/ref_scale resolution; need_spp: the spp per pixel the volpath
    reference must reach (ref_factor x the volpath runs' spp), 0 before the runs are known."""
    light, boundary, _ = name.split("_")
    out = {"scale": P["ref_scale"]}
    if light == "directional" and boundary == "smooth":
        out["kind"] = (f"volpath, sphere lights of {', '.join(f'{o:g}' for o in P['omegas'])} sr at equal irradiance, "
                       "image mean extrapolated to 0 sr")
        pts = []
        for omega in P["omegas"]:
            xml = variant_xml(refs, name, "volpath", omega)
            tag = f"{name}.ref.omega{omega:g}.s{P['ref_scale']}"
            per_part, run_spp = planned_spp(args, P, refs, name, xml, f"{name}.volpath.omega{omega:g}",
                                            P["ref_factor"] * P["ds_factor"])
            parts = render_parts(args, P, refs, name, xml, tag, per_part, 5000)
            mean, var, n = pooled(parts)
            mu, se = mean_se_bound(mean, var, n)
            pts.append({"omega": omega, "mean": mu, "se": se, "spp": n, "idle_run_spp_predicted": run_spp,
                        "seconds": sum(st["seconds"] for _, st in parts)})
        if any(p["se"] <= 0 for p in pts):  # a radius never hit: no extrapolation
            pts = [dict(p, se=math.inf if p["se"] <= 0 else p["se"]) for p in pts]
        x = np.array([p["omega"] for p in pts])
        y = np.array([p["mean"] for p in pts])
        w = 1.0 / np.array([p["se"] for p in pts]) ** 2
        a = np.vstack([np.ones_like(x), x]).T
        if np.count_nonzero(w) >= 2:
            cov = np.linalg.inv(a.T @ (a * w[:, None]))
            coef = cov @ (a.T @ (w * y))
            chi2 = float(np.sum(w * (y - a @ coef) ** 2))
        else:
            cov, coef, chi2 = np.full((2, 2), np.nan), np.full(2, np.nan), math.nan
        out.update(mean=float(coef[0]), se=float(math.sqrt(cov[0, 0])), slope=float(coef[1]), chi2=chi2,
                   dof=len(pts) - 2, points=pts, seconds=sum(p["seconds"] for p in pts),
                   spp=sum(p["spp"] for p in pts), image=None)
        # No per-pixel reference here (only the extrapolated mean): relMSE is not reported. The
        # volpath renders of the sphere lights are too sparse for a per-pixel median, so d comes from
        # independent volpath_snee renders (seeds the runs never use; d only weights pixels).
        xml = variant_xml(refs, name, "snee")
        per_part, _ = planned_spp(args, P, refs, name, xml, f"{name}.snee", P["d_factor"])
        parts = render_parts(args, P, refs, name, xml, f"{name}.d.s{P['ref_scale']}", per_part, 6000)
        out["d_from"] = f"volpath_snee, {len(parts)} x {per_part} spp (seeds 6000+)"
        out["d"] = robust_d(parts)
        out["mean_lum"] = float(np.mean([(rgb_of(ch) @ LUM).mean() for ch, _ in parts]))
    else:
        xml = variant_xml(refs, name, "volpath")
        per_part, run_spp = planned_spp(args, P, refs, name, xml, f"{name}.volpath", P["ref_factor"])
        parts = render_parts(args, P, refs, name, xml, f"{name}.ref.s{P['ref_scale']}", per_part, 5000, need_spp)
        mean, var, n = pooled(parts)
        mu, se = mean_se_bound(mean, var, n)
        out["kind"] = f"volpath, {len(parts)} x {per_part} spp"
        out.update(mean=mu, se=se, image=mean, var_of_image=var / n, spp=n, idle_run_spp_predicted=run_spp)
        out["seconds"] = sum(st["seconds"] for _, st in parts)
        out["d"] = robust_d(parts)
        out["d_from"] = "the reference's parts"
        out["mean_lum"] = float((mean @ LUM).mean())
    out["eps"] = 1e-2 * max(float(out["d"].mean()), abs(out["mean"])) ** 2
    return out


def robust_d(parts):
    """Per-pixel, per-channel median over independent renders: the median drops a part's fireflies.
    (The parts are at 1/ref_scale resolution: each pixel already pools ref_scale^2 run pixels' area.)"""
    return np.median(np.stack([rgb_of(ch) for ch, _ in parts]), axis=0)


def downsample(img, s):
    """Mean over s x s pixel blocks (with the box filter: the image at 1/s resolution)."""
    h, w = img.shape[:2]
    return img.reshape(h // s, s, w // s, s, -1).mean(axis=(1, 3))


def upsample(img, s):
    return np.repeat(np.repeat(img, s, axis=0), s, axis=1)


def complete_check(args, work, name):
    """Whether `connection = complete` renders anything else than the default `paper` here: one
    4-spp render of each at the same seed, compared pixel by pixel (where the manifold connection
    does not apply it draws nothing, and the two images are identical)."""
    a, _ = snee_render(args, work, variant_xml(work, name, "snee"), f"{name}.snee.check", seed=33, spp=4)
    b, st = snee_render(args, work, variant_xml(work, name, "complete"), f"{name}.complete.check", seed=33, spp=4)
    same = all(np.array_equal(a[c], b[c]) for c in "RGB")
    return {"differs": not same, "manifold_attempts": st.get("manifold_attempts"),
            "manifold_solutions": st.get("manifold_solutions")}


def run_config(args, P, work, name):
    """Everything for one configuration; cached in WORK/results/NAME.json (+ .npz of images)."""
    res_path = os.path.join(work, "results", name + ".json")
    img_path = os.path.join(work, "results", name + ".npz")
    if not args.force and os.path.exists(res_path) and os.path.exists(img_path):
        with open(res_path) as fh:
            return json.load(fh)
    os.makedirs(os.path.dirname(res_path), exist_ok=True)
    t_cfg = time.time()
    load0 = os.getloadavg()[0]
    rendered0 = RENDERED[0]
    res = {"name": name}
    timing = {}

    # Which snee methods: `complete` only where it differs from `paper`.
    t1 = time.time()
    check = complete_check(args, work, name)
    res["complete"] = check
    snee_methods = ["volpath", "snee"] + (["complete"] if check["differs"] else [])

    # Probes (rates; a fraction of a run's budget), then the reference (topped up to ref_factor x the
    # volpath runs' spp if an idle machine outran its plan), then interleaved runs at fixed spp.
    mit = Mitsuba(args, name) if not args.no_mitsuba else None
    runs = {m: [] for m in snee_methods + ["mitsuba"]}
    spp, mstat = {}, {}
    for m in snee_methods:
        _, st = snee_render(args, work, variant_xml(work, name, m), f"{name}.{m}.probe", seed=90,
                            seconds=P["probe"] * P["run_time"])
        spp[m] = max(2, int(round(st["spp"] / st["seconds"] * P["run_time"])))
    if mit is not None:
        rdir = os.path.join(work, "renders")
        setup_json = os.path.join(rdir, f"{name}.mitsuba.setup.json")
        cached = not args.force_renders and os.path.exists(os.path.join(rdir, f"{name}.mitsuba.firefly.npy")) and all(
            os.path.exists(os.path.join(rdir, f"{name}.{MI_RUN}{i}.{x}"))
            for i in range(P["runs"]) for x in ("json", "npy"))
        if cached:  # the runs exist: no worker, no probe
            if os.path.exists(setup_json):
                with open(setup_json) as fh:
                    mstat = json.load(fh)
            with open(os.path.join(rdir, f"{name}.{MI_RUN}0.json")) as fh:
                spp["mitsuba"] = json.load(fh)["spp"]
        else:
            pr = mit.call({"cmd": "probe", "seconds": P["run_time"]})
            if pr is not None:
                spp["mitsuba"] = max(2, int(round(pr["rate"] * P["run_time"])))
                mi_warm_up(mit, spp["mitsuba"])
                # The probe's small renders carry a fixed cost per call, so its rate is low: one timed
                # render at that spp corrects n so that a run takes about run_time, like snee's.
                t = mit.call({"cmd": "render", "spp": spp["mitsuba"], "seed": 4, "out": None})
                if t is not None and t["seconds"] > 0:
                    pr["rate_probe"] = pr["rate"]
                    pr["rate"] = spp["mitsuba"] / t["seconds"]
                    spp["mitsuba"] = max(2, int(round(pr["rate"] * P["run_time"])))
                mstat = {"variant": mit.info["variant"], "notes": mit.info["notes"], "probe": pr,
                         "load_seconds": mit.info["load_seconds"], "thread_count": mit.info["thread_count"]}
                os.makedirs(rdir, exist_ok=True)
                common.write_json_atomic(setup_json, mstat)
    timing["check_probes_setup"] = time.time() - t1
    t1 = time.time()
    ref = reference(args, P, args.refs, name, need_spp=P["ref_factor"] * spp["volpath"])
    timing["reference_top_up"] = time.time() - t1
    s_ref = P["ref_scale"]
    denom_ref = ref["d"] ** 2 + ref["eps"]  # at the reference's resolution
    denom = upsample(denom_ref, s_ref)  # at the runs' resolution: each run pixel gets its block's d
    res["reference"] = {k: v for k, v in ref.items() if k not in ("image", "d", "var_of_image")}
    if "var_of_image" in ref:
        res["reference"]["rv"] = float(np.mean(ref["var_of_image"] / denom_ref))
        res["reference"]["spp_over_volpath_run_spp"] = ref["spp"] / spp["volpath"]

    t1 = time.time()
    # Common random numbers: run i of every snee method has seed 100 + i (module docstring, "Runs").
    seeds = {"volpath": 100, "snee": 100, "complete": 100}  # + run index (< 100: below the references' 5000+)
    mi_state = {"warm": mit is not None and mit.proc is not None, "failed": False}

    def one_run(i):
        """Run i of every method, interleaved; each run's V_run (its per-pixel variances over d^2 + eps)."""
        for m in snee_methods:
            ch, st = snee_render(args, work, variant_xml(work, name, m), f"{name}.{m}.run{i}",
                                 seed=seeds[m] + i, spp=spp[m], extra=["--moment"])
            var = moment_var(ch, st["spp"])
            runs[m].append({"x": rgb_of(ch), "var": var, "V": float(np.mean(var / denom)), "n": st["spp"],
                            "t": st["seconds"]})
        if "mitsuba" in spp and not mi_state["failed"]:  # a plain render (timed), the same samples with rgb_moment
            npy = os.path.join(work, "renders", f"{name}.{MI_RUN}{i}.npy")
            tj = npy[:-4] + ".json"
            if args.force_renders or not (os.path.exists(npy) and os.path.exists(tj)):
                RENDERED[0] += 1
                if not mi_state["warm"]:  # a worker started for extension runs only: compile first, untimed
                    mi_warm_up(mit, spp["mitsuba"])
                    mi_state["warm"] = True
                t = mit.call({"cmd": "run", "spp": spp["mitsuba"], "seed": 1000 + i, "out": npy})
                if t is None:
                    mi_state["failed"] = True
                    return
                common.write_json_atomic(tj, t)
            with open(tj) as fh:
                t = json.load(fh)
            mom = np.load(npy).astype(np.float64)
            var = sample_var(mom[..., :3], mom[..., 3:], t["spp"])
            runs["mitsuba"].append({"x": mom[..., :3], "var": var, "V": float(np.mean(var / denom)), "n": t["spp"],
                                    "t": t["seconds"], "t_moment": t["moment_seconds"],
                                    "plain_vs_moment": t["plain_vs_moment"], "cpu": t["cpu_seconds"]})

    # Sequential design (module docstring, "Runs"): batches of P["runs"] until every compared method's
    # V rests on >= NEFF_MIN effective runs or the cap is reached; decided from the runs alone.
    light, boundary, _ = name.split("_")
    excluded = CANNOT_SAMPLE.get((light, boundary), ())
    cap = max(P["runs"], args.max_runs or P["max_runs"])
    assert cap < 100, "seeds + run index must stay below the next method's seeds"
    steps = []
    while True:
        for i in range(len(runs["volpath"]), len(runs["volpath"]) + P["runs"]):
            one_run(i)
        n_done = len(runs["volpath"])
        if mi_state["failed"] or ("mitsuba" in spp and len(runs["mitsuba"]) < n_done):
            runs["mitsuba"], mi_state["failed"] = [], True
        n_eff = {m: kish([r["V"] for r in rs]) for m, rs in runs.items() if len(rs) == n_done}
        below = [m for m, k in n_eff.items() if k is not None and k < NEFF_MIN and m not in excluded]
        steps.append({"runs": n_done, "n_eff": n_eff, "below": below})
        if not below or n_done + P["runs"] > cap:
            break
    res["sequential"] = {"threshold": NEFF_MIN, "batch": P["runs"], "cap": cap, "excluded": list(excluded),
                         "steps": steps, "runs": n_done, "below_at_end": below}
    res["runs"] = n_done
    res["mitsuba_status"] = "not run (--no-mitsuba)" if mit is None else mit.status
    res["mitsuba"] = mstat
    timing["runs"] = time.time() - t1

    # Firefly renders.
    t1 = time.time()
    k = P["firefly_scale"]
    w, h = film_size(name)
    ff = {}
    for m in snee_methods:
        ch, _ = snee_render(args, work, variant_xml(work, name, m), f"{name}.{m}.firefly", seed=77, spp=1,
                            extra=["-D", f"width={w * k}", "-D", f"height={h * k}"])
        ff[m] = firefly_rate(rgb_of(ch), ref["mean_lum"])
    if runs["mitsuba"]:
        npy = os.path.join(work, "renders", f"{name}.mitsuba.firefly.npy")
        if args.force_renders or not os.path.exists(npy):
            mit.call({"cmd": "firefly", "scale": k, "seed": 77, "out": npy})
        if os.path.exists(npy):
            ff["mitsuba"] = firefly_rate(np.load(npy).astype(np.float64), ref["mean_lum"])
    if mit is not None:
        mit.close()
    timing["firefly"] = time.time() - t1

    # Transport classes (when the binary has them): one more run per snee method, untimed.
    t1 = time.time()
    classes = {}
    if args.classes:
        for m in snee_methods:
            ch, st = snee_render(args, work, variant_xml(work, name, m), f"{name}.{m}.classes", seed=400,
                                 spp=spp[m], extra=["--moment", "--classes"])
            classes[m] = class_shares(ch, st["spp"], denom)
    timing["classes"] = time.time() - t1

    # Per-method statistics, over the N runs of the sequential design.
    N = n_done
    stats, avg = {}, {}
    for m, rs in runs.items():
        if len(rs) < N:
            continue
        n = rs[0]["n"]
        X = np.stack([r["x"] for r in rs])
        t = np.array([r["t"] for r in rs])
        run_means = X.mean(axis=(1, 2, 3))
        spread = (X.var(axis=0, ddof=1) / denom).reshape(-1)  # per pixel-channel s^2 / denom

        # Bootstrap of the spread estimate through the runs' Gram matrix G_ij = mean_p x_ip x_jp / denom_p:
        # for weights w_i = count_i / N, the ddof-1 variance averaged over pixels is
        # N / (N - 1) (sum_i w_i G_ii - w^T G w); times N / (N - 1) for the bootstrap's bias.
        xd = (X / np.sqrt(denom)).reshape(N, -1)
        gram = xd @ xd.T / xd.shape[1]

        def v_spread(idx, resampled=True, gram=gram, n=n):
            k = len(idx)
            if k < 2:
                return math.nan
            w = np.bincount(idx, minlength=N) / k
            return n * float(w @ np.diag(gram) - w @ gram @ w) * (k / (k - 1)) ** (2 if resampled else 1)
        s = {"spp": n, "t": t.tolist(), "c": float(t.sum() / (N * n)), "run_means": run_means.tolist(),
             "V_spread": n * float(spread.mean())}
        vpix = [np.mean(r["var"] / denom, axis=-1) for r in rs]  # per run and pixel, from its per-pixel moments
        vm = np.array([r["V"] for r in rs])
        # How few samples carry V: per run, the largest single pixel's share of V_run (mean over runs).
        s_top = float(np.mean([safe_div(float(v.max()), float(v.sum())) for v in vpix if v.sum() > 0] or [math.nan]))
        s["V_runs"] = vm.tolist()
        s["V"] = float(vm.mean())
        s["n_eff_runs"] = kish(vm)  # Kish: the number of equal runs with the same concentration of V
        s["V_first_batch"] = float(vm[:P["runs"]].mean())  # the fixed design's V (no stopping rule)
        s["V_halves"] = [float(vm[:N // 2].mean()), float(vm[N // 2:2 * (N // 2)].mean())] if N >= 4 else []
        s["V_top_pixel_share"] = s_top
        s["V_from"] = "per-pixel moments" + (" (rgb_moment; t from a plain render of the same samples)"
                                              if m == "mitsuba" else " (--moment)")
        if m == "mitsuba":
            tm = np.array([r["t_moment"] for r in rs])
            s["cpu_per_second"] = float(sum(r["cpu"] for r in rs) / t.sum())
            s["t_moment"] = tm.tolist()  # the rgb_moment renders' times (not used for c)
            s["moment_time_over_plain_median"] = float(np.median(tm / t))
            s["plain_vs_moment_max_rel_diff"] = float(max(r["plain_vs_moment"] for r in rs))
        s["efficiency"] = safe_div(1.0, s["V"] * s["c"])
        a = X.mean(axis=0)
        avg[m] = a
        mu = float(run_means.mean())
        # standard error of the mean of all N n samples per pixel (moments)
        _, se = mean_se_bound(a, np.mean([r["var"] for r in rs], axis=0), N * n)
        z = zscore(mu, se, ref["mean"], ref["se"])
        if m == "mitsuba":  # cross-check from the N runs' means only: a t statistic, N - 1 degrees of freedom
            s["t_stat_spread"] = zscore(mu, float(run_means.std(ddof=1) / math.sqrt(N)), ref["mean"], ref["se"])
        # relMSE at the reference's resolution (the runs' averages downsampled: with the box filter
        # that is the image the reference estimates).
        s.update(mean=mu, se=se, z=z,
                 relmse=None if ref["image"] is None else common.rel_mse(downsample(a, s_ref), ref["image"], denom_ref),
                 relmse_k={} if ref["image"] is None else
                 {str(kk): common.rel_mse(downsample(X[:kk].mean(axis=0), s_ref), ref["image"], denom_ref)
                  for kk in run_counts(N)},
                 firefly_per_1e6=ff.get(m))
        s["_X"] = X
        s["_vspread"] = v_spread
        stats[m] = s

    def eff(m, idx, resampled=True):
        s = stats[m]
        v = float(np.mean(np.array(s["V_runs"])[idx]))
        return safe_div(1.0, v * float(np.sum(np.array(s["t"])[idx]) / (len(idx) * s["spp"])))

    # Seed stability: the same ratio and interval from each half of the runs (seeds +0..N/2-1 and
    # +N/2..N-1): intervals that do not depend on which seeds ran should overlap.
    halves = [np.arange(0, N // 2), np.arange(N // 2, 2 * (N // 2))] if N >= 4 else []

    ratios = {}  # volpath_snee over each other method; "complete/...": connection = complete over them
    for num, other, key in (("snee", "volpath", "volpath"), ("snee", "mitsuba", "mitsuba"),
                            ("complete", "snee", "complete/snee"), ("complete", "volpath", "complete/volpath"),
                            ("complete", "mitsuba", "complete/mitsuba")):
        if num in stats and other in stats:
            r = safe_div(stats[num]["efficiency"], stats[other]["efficiency"])
            lo, hi = common.bootstrap_ci(lambda idx, a=num, o=other: safe_div(eff(a, idx), eff(o, idx)), N, b=P["boot"],
                                         method=BOOT)
            ratios[key] = {"ratio": r, "lo": lo, "hi": hi, "halves": []}
            for hf in halves:
                hlo, hhi = common.bootstrap_ci(lambda j, a=num, o=other, hf=hf: safe_div(eff(a, hf[j]), eff(o, hf[j])),
                                               len(hf), b=P["boot"], method=BOOT)
                ratios[key]["halves"].append({"ratio": safe_div(eff(num, hf, False), eff(other, hf, False)),
                                              "lo": hlo, "hi": hhi})
    for m in stats:
        v = stats[m]
        v_runs = np.array(v["V_runs"])
        v["V_ci"] = list(common.bootstrap_ci(lambda idx, v_runs=v_runs: float(np.mean(v_runs[idx])), N, b=P["boot"],
                                             method=BOOT))
        # The two estimates of V from the same runs (moments; spread of the runs' images): their ratio
        # with a bootstrap interval over runs, a check of the moment estimate.
        point = safe_div(v["V"], v["V_spread"])
        v["V_over_V_spread"] = [point, *common.bootstrap_ci(
            lambda idx, v_runs=v_runs, f=v["_vspread"]: safe_div(float(np.mean(v_runs[idx])), f(idx)), N, b=P["boot"],
            method=BOOT, theta=point)]
        del v["_X"], v["_vspread"]
    res["methods"] = stats
    res["ratios"] = ratios
    res["classes"] = classes
    res["classes_sum_ok"] = all(c["sum_max_rel_diff"] <= CLASS_SUM_TOL for c in classes.values()) if classes else None

    # Figure 3: equal samples, SNEE's transport only.
    t1 = time.time()
    f3 = {}
    for v in ("fig3_forward", "fig3_snee"):
        ch, st = snee_render(args, work, variant_xml(work, name, v), f"{name}.{v}", seed=7, spp=P["fig3_spp"],
                             extra=["--moment"])
        f3[v] = (rgb_of(ch), *mean_se_bound(rgb_of(ch), moment_var(ch, st["spp"]), st["spp"]))
    res["fig3"] = {"forward_mean": f3["fig3_forward"][1], "snee_mean": f3["fig3_snee"][1],
                   "z_forward_vs_snee": zscore(f3["fig3_forward"][1], f3["fig3_forward"][2],
                                               f3["fig3_snee"][1], f3["fig3_snee"][2])}
    timing["fig3"] = time.time() - t1
    res["timing"] = timing
    res["wall_seconds"] = time.time() - t_cfg
    res["load_average"] = [load0, os.getloadavg()[0]]
    if RENDERED[0] == rendered0 and os.path.exists(res_path):  # nothing rendered: keep the rendering run's
        with open(res_path) as fh:
            old = json.load(fh)
        res["wall_seconds"], res["load_average"] = old.get("wall_seconds"), old.get("load_average")
        res["timing"] = old.get("timing", timing)
    np.savez_compressed(img_path, ref=upsample(ref["d"] if ref["image"] is None else ref["image"], s_ref), f3_forward=f3["fig3_forward"][0], f3_snee=f3["fig3_snee"][0],
                        **{f"avg_{m}": a for m, a in avg.items()})
    common.write_json_atomic(res_path, finite(res))
    return finite(res)


# A-priori time model of one configuration on an idle machine (seconds; calibrated on the smoke and
# one-configuration runs, see figures/README.md): per snee render, process start and scene loading;
# Mitsuba: worker start, scene load, probe and the compilation of the plain and the moment kernel (the
# quiet 16 x 1 s run spent 4-7 s in all set-up with drjit's kernel cache warm; a cold moment kernel
# compiles in about 4 s), and the firefly render's reload.
SNEE_START = 0.25
MITSUBA_SETUP = 10.0
MITSUBA_PER_RUN = 2.05  # a plain render of run_time and the rgb_moment render of the same samples
FIXED_PER_CONFIG = 8.0  # complete check, firefly renders, Figure 3 renders
REPORT = 30.0  # the report's statistics and figures, once


def estimate_seconds(P, names, complete_configs, batches=0.0):
    """Predicted wall time of the runs (references cached): every method renders a probe and the runs
    of run_time each, snee methods one more (classes) at about 1.3 run_time; batches: extension
    batches of P["runs"] runs per configuration (the sequential design; 0: none)."""
    total = REPORT
    for name in names:
        m_snee = 3 if name in complete_configs else 2
        per_run = m_snee * (P["run_time"] + SNEE_START) + MITSUBA_PER_RUN * P["run_time"]
        total += ((1 + batches) * P["runs"] * per_run + m_snee * (P["probe"] * P["run_time"] + SNEE_START)
                  + m_snee * (1.3 * P["run_time"] + SNEE_START) + MITSUBA_SETUP + 2 * P["run_time"] + FIXED_PER_CONFIG)
    return total


def missing_reference_seconds(P, refs, names):
    """Predicted wall time of the reference parts not yet in REFS (idle machine, all threads: a full
    reference costs ref_factor x REF_HEADROOM x run_time / ref_scale^2 seconds; directional + smooth
    ds_factor x that per radius plus its d renders)."""
    one = P["ref_factor"] * REF_HEADROOM * P["run_time"] / P["ref_scale"] ** 2
    total = 0.0
    for name in names:
        if name.startswith("directional_smooth"):
            jobs = [(f"{name}.ref.omega{o:g}.s{P['ref_scale']}", P["ds_factor"] * one) for o in P["omegas"]]
            jobs.append((f"{name}.d.s{P['ref_scale']}", one * P["d_factor"] / P["ref_factor"]))
        else:
            jobs = [(f"{name}.ref.s{P['ref_scale']}", one)]
        for tag, cost in jobs:
            have = len(glob.glob(os.path.join(refs, "renders", glob.escape(tag) + ".*spp.*.json")))
            total += cost * max(0, P["ref_parts"] - have) / P["ref_parts"]
    return total


def run_config_task(argv, name):
    """Ray task: the same as the local loop for one configuration (PYTHONPATH has scripts/)."""
    args, P, work = setup(argv)
    return run_config(args, P, work, name)


# ----------------------------------------------------------------------------- outputs

def finite(x):
    """JSON-safe copy: numpy scalars to floats, non-finite floats to null."""
    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def pct(x):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.0f}"


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def tonemap(img, scale):
    x = np.clip(img * scale, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def split(left, right):
    w = left.shape[1]
    out = np.concatenate([left[:, : w // 2], right[:, w // 2:]], axis=1)
    out[:, w // 2] = 1.0  # a thin white divider
    return out


def exposure(ref):
    return 0.9 / max(np.percentile(ref @ LUM, 99.0), 1e-6)


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


def chart_png(path, results, P, note):
    """Relative error against render time per configuration, at the reference's resolution (1/ref_scale):
    RV(t) = V c / (t ref_scale^2) (band: the bootstrap interval of V) for k = 1, 2, 4, ... runs
    averaged, and relMSE of those averages against the reference (markers; expectation RV + RV_ref +
    bias^2); dotted: the reference's own RV."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter, NullLocator
    cols = [(e, b) for e in EXTINCTIONS for b in BOUNDARIES]
    fig, axes = plt.subplots(len(LIGHTS), len(cols), figsize=(2.75 * len(cols), 2.5 * len(LIGHTS) + 1.0), squeeze=False)
    handles = {}
    for r, l in enumerate(LIGHTS):
        for c, (e, b) in enumerate(cols):
            ax = axes[r, c]
            res = results.get(f"{l}_{b}_{e}")
            if r == 0:
                ax.set_title(f"{LABEL[e]}, {LABEL[b]}", fontsize=9)
            if c == 0:
                ax.set_ylabel(f"{LABEL[l]}\nrelative error", fontsize=9)
            if res is None:
                ax.set_xticks([])
                ax.set_yticks([])
                continue
            for key, label, style in METHODS:
                s = res["methods"].get(key)
                if not s:
                    continue
                ks = np.array(run_counts(res.get("runs", P["runs"])))
                tk = ks * float(np.mean(s["t"]))
                # At the reference's resolution (the markers'): a block of s^2 independent pixels with one
                # d has 1/s^2 of their relative variance, so RV there is exactly V c / (t s^2).
                k2 = P["ref_scale"] ** 2
                rv = s["V"] * s["c"] / tk / k2
                lo, hi = (np.array(s["V_ci"]) * s["c"] / k2)[:, None] / tk[None, :] if s.get("V_ci") and None not in s["V_ci"] else (rv, rv)
                (hl,) = ax.loglog(tk, rv, color=style["color"], lw=1.2, label=f"{label}: RV")
                ax.fill_between(tk, lo, hi, color=style["color"], alpha=0.2, lw=0)
                rm = [s["relmse_k"].get(str(kk), np.nan) for kk in ks]
                (hm,) = ax.loglog(tk, rm, ls="none", mfc="none", ms=4, label=f"{label}: relMSE vs ref", **style)
                handles[hl.get_label()] = hl
                handles[hm.get_label()] = hm
            rv_ref = res["reference"].get("rv")
            if rv_ref:
                hr = ax.axhline(rv_ref, color="gray", ls=":", lw=0.8, label="reference's own RV")
                handles[hr.get_label()] = hr
            ax.xaxis.set_major_locator(FixedLocator([float(np.mean(res["methods"][m]["t"])) * kk
                                                     for m in list(res["methods"])[:1]
                                                     for kk in run_counts(res.get("runs", P["runs"]))]))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
            ax.xaxis.set_minor_locator(NullLocator())
            ax.yaxis.set_minor_formatter(NullFormatter())
            ax.tick_params(labelsize=7)
            ax.grid(True, which="major", lw=0.3, alpha=0.5)
            if r == len(LIGHTS) - 1:
                ax.set_xlabel("render time [s]", fontsize=8)
    fig.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(f"relative error against render time at the reference's 1/{P['ref_scale']} resolution (lines: RV = V c / "
                 f"(t {P['ref_scale'] ** 2}) with 95 % bootstrap band; markers: relMSE of 1, 2, 4, ... runs averaged); {note}", fontsize=9)
    fig.tight_layout(rect=(0, 0.06, 1, 0.97), h_pad=0.6, w_pad=0.4)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def report(args, P, mode, work, names, results, total, load):
    out = args.out
    os.makedirs(out, exist_ok=True)
    n_tests = sum(len(r["methods"]) for r in results.values())
    zcrit = common.sidak_z(ALPHA, n_tests)
    mi_variants = sorted({r["mitsuba"].get("variant") for r in results.values() if r.get("mitsuba")} - {None})
    mi_note = ("Mitsuba volpath " + "/".join(mi_variants)) if mi_variants else "Mitsuba not run"
    mi_v = sorted({r["methods"]["mitsuba"].get("V_from", "the spread of the runs' images")
                   for r in results.values() if "mitsuba" in r["methods"]})

    def few_runs(r, *ms):
        """The mark " ‡" where a method's V rests on < NEFF_MIN effective runs (after the sequential runs)."""
        excluded = (r.get("sequential") or {}).get("excluded", [])
        k = [r["methods"].get(m, {}).get("n_eff_runs") for m in ms if m not in excluded]
        return " ‡" if any(x is not None and x < NEFF_MIN for x in k) else ""

    def ratio_cell(r, other):
        q = r["ratios"].get(other)
        if not q:
            return "not run"
        if r["methods"][other]["mean"] == 0.0:
            return "∞: its image is black (no such transport)"
        flag = ""
        zo = r["methods"][other]["z"]
        if zo is not None and abs(zo) > zcrit:
            flag = " †"
        return f"{fmt(q['ratio'])} [{fmt(q['lo'])}, {fmt(q['hi'])}]{flag}{few_runs(r, 'snee', other)}"

    def complete_cell(r):
        c = r.get("complete") or {}
        if not c.get("differs"):
            return "same as paper (draws no manifold sample here)"
        q = r["ratios"].get("complete/snee")
        s = r["methods"].get("complete")
        if not q or not s:
            return "not run"
        z = s["z"]
        zs = "n/a" if z is None else (f"**{z:.1f}**" if abs(z) > zcrit else f"{z:.1f}")
        return f"{fmt(q['ratio'])} [{fmt(q['lo'])}, {fmt(q['hi'])}]{few_runs(r, 'complete', 'snee')}, z {zs}"

    def z_cell(r):
        cells = []
        for m in ("volpath", "snee", "mitsuba"):
            s = r["methods"].get(m)
            if not s:
                cells.append("–")
                continue
            z = s["z"]
            cells.append("n/a" if z is None else (f"**{z:.1f}**" if abs(z) > zcrit else f"{z:.1f}"))
        return " / ".join(cells)

    head = ("| configuration | eff. volpath_snee / volpath [95 %] | eff. volpath_snee / Mitsuba volpath [95 %] | "
            f"bias z vs reference: volpath / snee / Mitsuba (bold: \\|z\\| > {zcrit:.2f}) | "
            "eff. `connection = complete` / volpath_snee (paper) [95 %], its z | "
            "fireflies per 10⁶ samples: volpath / snee / Mitsuba | reference (error of its mean; spp ÷ a volpath run's) | "
            "relMSE vs ref: volpath / snee / Mitsuba |")
    lines = [head, "|" + "---|" * 8]
    for name in names:
        r = results[name]
        ref = r["reference"]
        ff = " / ".join(fmt(r["methods"].get(m, {}).get("firefly_per_1e6"), 2) for m in ("volpath", "snee", "mitsuba"))
        rm = " / ".join(fmt(r["methods"].get(m, {}).get("relmse"), 2) for m in ("volpath", "snee", "mitsuba"))
        kind = "sphere → 0 sr" if "sphere" in ref["kind"] else "volpath"
        factor = ref.get("spp_over_volpath_run_spp")
        factor = f"; ×{factor:.0f}" if factor else ""
        n_runs = r.get("runs", P["runs"])
        runs_note = f" ({n_runs} runs)" if n_runs != P["runs"] else ""
        lines.append(f"| {name}{runs_note} | {ratio_cell(r, 'volpath')} | {ratio_cell(r, 'mitsuba')} | {z_cell(r)} | "
                     f"{complete_cell(r)} | {ff} | {kind}, ±"
                     f"{fmt(100 * ref['se'] / max(abs(ref['mean']), 1e-30) if ref.get('se') is not None else None, 2)} %"
                     f"{factor} | {rm} |")
    table = "\n".join(lines)
    render_wall = sum(results[n].get("wall_seconds") or 0.0 for n in names)
    loads = [x for n in names for x in (results[n].get("load_average") or []) if x is not None]
    ref_wall = sum(results[n].get("timing", {}).get("reference_top_up", 0.0) for n in names)
    summary = (f"mode {mode}: {len(names)} configurations, {P['runs']} runs x {P['run_time']:g} s per method "
               f"(--threads {args.threads}); references: snee volpath at 1/{P['ref_scale']} of the width and height, "
               f"≥ {P['ref_factor']} x the spp of a volpath run (rendered ahead, {ref_wall / 60:.1f} min of top-up "
               f"in this run); rendering wall time {render_wall / 60:.1f} min (estimated "
               f"{'-'.join(f'{e / 60:.1f}' for e in getattr(args, 'estimate', [])) or 'n/a'} min) at a load average of "
               f"{min(loads, default=0):.1f}-{max(loads, default=0):.1f}; {mi_note}"
               + (f", its V from {' / '.join(mi_v)}" if mi_v else "") + ".")
    verdicts = []
    for other, label in (("volpath", "snee volpath"), ("mitsuba", "Mitsuba volpath")):
        black = [n for n in names if results[n]["methods"].get(other, {}).get("mean") == 0.0]
        q = [results[n]["ratios"].get(other) for n in names if n not in black]
        q = [x for x in q if x and x.get("lo") is not None and x.get("hi") is not None]
        win = sum(1 for x in q if x["lo"] > 1)
        lose = sum(1 for x in q if x["hi"] < 1)
        undecided = [x for x in q if x["lo"] <= 1 <= x["hi"]]
        equal = sum(1 for x in undecided if x["lo"] >= 1 / (1 + EQUAL_WITHIN) and x["hi"] <= 1 + EQUAL_WITHIN)
        spans = [math.sqrt(x["hi"] / x["lo"]) for x in q if x["lo"] > 0]
        qn = [(n, results[n]["ratios"].get(other)) for n in names if n not in black]
        hv = [(n, x["halves"]) for n, x in qn if x and len(x.get("halves", [])) == 2 and
              all(h.get("lo") is not None and h.get("hi") is not None for h in x["halves"])]
        apart = [n for n, (a, b) in hv if not (a["lo"] <= b["hi"] and b["lo"] <= a["hi"])]
        overlap = len(hv) - len(apart)

        def halves_note(n, other=other):
            """The method of the pair whose V differs most between the halves (JSON V_halves)."""
            f = {m: max(h) / min(h) for m in ("snee", other) for h in [results[n]["methods"][m].get("V_halves")]
                 if h and min(h) > 0}
            if not f:
                return n
            m = max(f, key=f.get)
            return f"{n}: V of {dict((k, l) for k, l, _ in METHODS)[m]} differs ×{f[m]:.1f} between them"
        verdicts.append(f"volpath_snee vs {label}: more efficient (95 % interval above 1) in {win}, less efficient "
                        f"(below 1) in {lose}, undecided in {len(undecided)} (of them equal within "
                        f"±{100 * EQUAL_WITHIN:.0f} %: {equal}) of {len(q)} configurations where both render the "
                        f"transport (in {len(black)} more, {label} renders black); median interval ×/÷ "
                        f"{fmt(float(np.median(spans)) if spans else None)}; the two halves of the runs' seeds give "
                        f"overlapping intervals in {overlap} of {len(hv)}" +
                        (f" (not in {'; '.join(halves_note(n) for n in apart)})" if apart else ""))
    summary += " " + "; ".join(verdicts) + "."
    seq = {n: results[n].get("sequential") for n in names if results[n].get("sequential")}
    if seq:
        cap = max(q["cap"] for q in seq.values())
        ext = [f"{n} {q['runs']}" for n, q in seq.items() if q["runs"] > P["runs"]]
        label = dict((k, l) for k, l, _ in METHODS)
        low = [f"{n}: " + ", ".join(f"{label.get(m, m)} {fmt(results[n]['methods'].get(m, {}).get('n_eff_runs'))}"
                                    for m in q["below_at_end"])
               for n, q in seq.items() if q["below_at_end"]]
        summary += (f" Runs: {P['runs']} per method, and batches of {P['runs']} more (up to {cap}) where a compared "
                    f"method's V rested on fewer than {NEFF_MIN:g} effective runs (Kish): more runs in {len(ext)} of "
                    f"{len(seq)} configurations" + (f" ({', '.join(ext)} runs)" if ext else "")
                    if cap > P["runs"] else f" Runs: {P['runs']} per method (fixed: no more runs allowed)")
        summary += (f"; below {NEFF_MIN:g} effective runs at the end (‡): {'; '.join(low)}." if low else
                    f"; every compared method's V rests on ≥ {NEFF_MIN:g} effective runs.")
    vv = [(n, m, s["V_over_V_spread"]) for n in names for m, s in results[n]["methods"].items()
          if s.get("V_over_V_spread") and None not in s["V_over_V_spread"]]
    if vv:
        q = {m: sorted(x[0] for _, mm, x in vv if mm == m) for m in dict.fromkeys(mm for _, mm, _ in vv)}
        summary += (" V from the moments over V from the spread of the runs' images (a check; 95 % bootstrap interval "
                    f"containing 1 in {sum(1 for _, _, x in vv if x[1] <= 1 <= x[2])} of {len(vv)}): " +
                    ", ".join(f"{dict((k, l) for k, l, _ in METHODS).get(m, m)} {x[0]:.2f}-{x[-1]:.2f}"
                              for m, x in q.items()) + ".")
    cls_names = sorted({k for n in names for c in results[n].get("classes", {}).values() for k in c["share"]},
                       key=lambda k: (CLASS_ORDER.index(k) if k in CLASS_ORDER else len(CLASS_ORDER), k))
    cls_lines, diffs = [], []
    for name in names:
        for m, c in results[name].get("classes", {}).items():
            cells = " | ".join(f"{pct(c['share'].get(k))} / {pct(c.get('energy', {}).get(k))}" for k in cls_names)
            diffs.append(c["sum_max_rel_diff"])
            cls_lines.append(f"| {name} | {dict((k, l) for k, l, _ in METHODS).get(m, m)} | {cells} | "
                             f"{c['sum_max_rel_diff']:.1e} |")
    text = [f"<!-- written by scripts/reproduce_figures.py --{mode}; do not edit -->", "", summary, "", table, "",
            "† the compared method fails the bias test there (it misses transport): its efficiency is that of an "
            "estimate of a different integral.", "",
            f"‡ V of one of the two methods rests on fewer than {NEFF_MIN:g} effective runs (Kish: (Σ V_run)² / Σ "
            "V_run²) after the sequential runs: one run carries more than a tenth of it, so the interval may still "
            "depend on which seeds ran (JSON `n_eff_runs`, `sequential`).", ""]
    if cls_lines:
        missing = [n for n in names if not results[n].get("classes")]
        ok = sum(1 for d in diffs if d <= CLASS_SUM_TOL)
        text += [f"Transport classes (docs/classes.md), one extra run per snee method at the runs' spp: each class's "
                 f"share of V (V_class / V) / of the image's energy, in %. The classes sum to the image (max |sum - "
                 f"image| / max image ≤ {CLASS_SUM_TOL:g}) in {ok} of {len(diffs)} renders (largest "
                 f"{max(diffs):.1e})" + (f"; not rendered: {', '.join(missing)}" if missing else "") + ".", "",
                 "| configuration | method | " + " | ".join(f"`{k}`" for k in cls_names) + " | Σ classes vs image |",
                 "|" + "---|" * (len(cls_names) + 3), *cls_lines, ""]
    else:
        text += ["Transport classes: this snee binary has no `--classes`; not measured.", ""]
    with open(os.path.join(out, "study.md"), "w") as fh:
        fh.write("\n".join(text))
    readme = os.path.join(out, "README.md")  # figures/README.md carries the same table between markers
    if os.path.exists(readme):
        body = open(readme).read()
        begin, end = "<!-- study table: written by scripts/reproduce_figures.py", "<!-- /study table -->"
        i, j = body.find(begin), body.find(end)
        if 0 <= i < j:
            i = body.index("\n", i) + 1
            body = body[:i] + "\n".join(text[2:]) + "\n" + body[j:]
            with open(readme, "w") as fh:
                fh.write(body)
    common.write_json_atomic(os.path.join(out, "study.json"), finite(
        {"mode": mode, "params": P, "threads": args.threads, "z_threshold_sidak": zcrit, "alpha": ALPHA,
         "wall_seconds": total, "estimated_seconds": getattr(args, "estimate", None), "load_average": load, "mitsuba": mi_note, "results": results}))
    # Figures from the cached images.
    fig3, fig4, fig4mi = {}, {}, {}
    for name in names:
        light, boundary, ext = name.split("_")
        with np.load(os.path.join(work, "results", name + ".npz")) as z:
            key = (ext, light, boundary)
            e4 = exposure(z["ref"])
            if "avg_snee" in z.files and "avg_volpath" in z.files:
                fig4[key] = split(tonemap(z["avg_volpath"], e4), tonemap(z["avg_snee"], e4))
            if "avg_mitsuba" in z.files:
                fig4mi[key] = split(tonemap(z["avg_mitsuba"], e4), tonemap(z["avg_snee"], e4))
            e3 = exposure(z["f3_snee"])
            fig3[key] = split(tonemap(z["f3_forward"], e3), tonemap(z["f3_snee"], e3))
    n_runs = sorted({results[n].get("runs", P["runs"]) for n in names})
    eq = f"{'-'.join(str(k) for k in n_runs[::max(1, len(n_runs) - 1)])} x {P['run_time']:g} s"
    grid_png(os.path.join(out, "paper_fig3.png"), f"Figure 3: equal samples ({P['fig3_spp']} spp), SNEE's transport "
             "only - left: volpath (snee=forward), right: volpath_snee (MIS)", fig3,
             "each tile exposed by the 99th percentile of its SNEE half; sRGB")
    grid_png(os.path.join(out, "paper_fig4.png"), f"Figure 4: equal time ({eq}, {args.threads} threads), all "
             "transport - left: volpath, right: volpath_snee", fig4, "exposure from the reference; sRGB")
    grid_png(os.path.join(out, "paper_fig4_mitsuba.png"), f"Figure 4 against Mitsuba 3: equal time ({eq}) - left: "
             "Mitsuba volpath, right: snee volpath_snee", fig4mi, f"exposure from the reference; {mi_note}")
    chart_png(os.path.join(out, "study_error_vs_time.png"), results, P, mi_note)
    print("\n".join(text))


# ----------------------------------------------------------------------------- main

def parser():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    size = ap.add_mutually_exclusive_group()
    size.add_argument("--standard", action="store_true", help="the committed size (default)")
    size.add_argument("--paper", action="store_true", help="the paper's size, as Ray tasks")
    size.add_argument("--smoke", action="store_true", help="tiny sizes: checks the pipeline, numbers mean nothing")
    ap.add_argument("--threads", type=int, default=None, help="render threads per method (default: the mode's)")
    ap.add_argument("--only", default="*", help="globs over configuration names, comma-separated, e.g. "
                    "'directional_*' or 'sphere_ggx0*_st34,envmap_ggx020_st02'")
    ap.add_argument("--out", default=None, help="outputs (default figures/ or figures/paper_size/)")
    ap.add_argument("--work", default=None, help="render cache (default target/study/<mode>)")
    ap.add_argument("--refs", default=None, help="reference cache (default WORK/refs); may be rendered ahead "
                    "with --refs-only, on any machine, under any load")
    ap.add_argument("--snee", default=SNEE, help="the snee binary (default target/release/snee)")
    ap.add_argument("--refs-only", action="store_true", help="render the references (and their rate probes) only")
    ap.add_argument("--force", action="store_true", help="recompute the configurations' results (renders stay cached)")
    ap.add_argument("--force-renders", action="store_true", help="render everything again")
    ap.add_argument("--max-runs", type=int, default=None, help="cap of the sequential runs (default: the mode's; "
                    "the mode's run count: the fixed design, e.g. a re-analysis of cached runs without new renders)")
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--mitsuba-variant", default="auto", choices=["auto", "llvm_ad_rgb", "scalar_rgb"])
    ap.add_argument("--ray", action="store_true", help="run configurations as Ray tasks (default with --paper)")
    ap.add_argument("--address", default=None, help="Ray cluster to join (auto or HEAD_IP:6379); implies --ray")
    ap.add_argument("--mitsuba-worker", nargs=3, metavar=("SCENE", "THREADS", "VARIANT"), help=argparse.SUPPRESS)
    return ap


def setup(argv):
    args = parser().parse_args(argv)
    mode = "paper" if args.paper else "smoke" if args.smoke else "standard"
    P = MODES[mode]
    args.mode = mode
    args.threads = args.threads or P["threads"]
    args.out = os.path.abspath(args.out or os.path.join(ROOT, "figures", {"standard": "", "paper": "paper_size", "smoke": "smoke"}[mode]))
    args.snee = os.path.abspath(args.snee)
    args.classes = common.snee_supports(args.snee, "--classes")
    work = os.path.abspath(args.work or os.path.join(ROOT, "target", "study", mode))
    args.refs = os.path.abspath(args.refs or os.path.join(work, "refs"))
    return args, P, work


def pid_alive(text):
    try:
        os.kill(int(text.strip()), 0)
    except (ValueError, ProcessLookupError):
        return False
    except PermissionError:
        return True
    return True


def main():
    argv = sys.argv[1:]
    args, P, work = setup(argv)
    if args.mitsuba_worker:
        scene, threads, variant = args.mitsuba_worker
        return mitsuba_worker(scene, int(threads), variant)
    if not os.path.exists(args.snee):
        sys.exit(f"{args.snee} not found: run `cargo build --release` first")
    names = [n for n in configs() if any(fnmatch.fnmatch(n, g) for g in args.only.split(","))]
    t0, load0 = time.time(), os.getloadavg()[0]
    print(f"mode {args.mode}: {len(names)} configurations, {P['runs']} runs x {P['run_time']:g} s, reference "
          f"{P['ref_factor']} x, --threads {args.threads}, transport classes: "
          f"{'yes' if args.classes else 'not in this binary'}; V of every method, Mitsuba's too, from per-pixel "
          f"moments ({MI_V_NOTE}); load average {load0:.2f}", flush=True)
    smooth = [n for n in names if "_smooth_" in n]
    cap = max(P["runs"], args.max_runs or P["max_runs"])
    most = (cap - P["runs"]) // P["runs"]  # extension batches at the cap
    batches = min(EXPECTED_BATCHES_PER_CONFIG, most)
    est0, est1 = estimate_seconds(P, names, [], batches), estimate_seconds(P, names, smooth, batches)
    est_ref = missing_reference_seconds(P, args.refs, names)
    est0, est1 = est0 + est_ref, est1 + est_ref
    args.estimate = [est0, est1]
    worst = estimate_seconds(P, names, smooth, most) + est_ref
    print(f"estimated wall time on an idle machine: {est0 / 60:.1f} min, {est1 / 60:.1f} min if `connection = "
          f"complete` differs from paper on the {len(smooth)} smooth configurations (of it {est_ref / 60:.1f} min "
          f"for reference parts missing from {args.refs}; with {batches:.2f} extension batches of {P['runs']} runs "
          f"per configuration as in the committed run; {worst / 60:.1f} min if every configuration runs to the cap "
          f"of {cap})", flush=True)
    pid_file = os.path.join(args.refs, "refs_only.pid")
    if not args.refs_only and os.path.exists(pid_file) and pid_alive(open(pid_file).read()):
        sys.exit(f"a --refs-only run (pid {open(pid_file).read().strip()}) is rendering into {args.refs}: wait for "
                 f"it or stop it (kill PID; its finished parts stay) and remove {pid_file}")
    results = {}
    if args.refs_only:  # directional + smooth (the largest) last
        os.makedirs(args.refs, exist_ok=True)
        pid_file = os.path.join(args.refs, "refs_only.pid")  # present while a --refs-only run renders
        with open(pid_file, "w") as fh:
            fh.write(f"{os.getpid()}\n")
        for name in sorted(names, key=lambda n: n.startswith("directional_smooth")):
            t1 = time.time()
            ref = reference(args, P, args.refs, name)
            print(f"{name}: reference {ref['kind']}, {ref['spp']} spp, mean {ref['mean']:.5g} +- {ref['se']:.2g}, "
                  f"{ref['seconds']:.0f} s rendering [{time.time() - t1:.0f} s, total {time.time() - t0:.0f} s, "
                  f"load {os.getloadavg()[0]:.1f}]", flush=True)
        os.remove(pid_file)
        return 0
    if args.ray or args.paper or args.address:
        import ray
        ray.init(address=args.address or "local", include_dashboard=False, log_to_driver=False,
                 runtime_env={"env_vars": {"PYTHONPATH": os.path.dirname(os.path.abspath(__file__))}})
        try:
            task = ray.remote(run_config_task).options(num_cpus=args.threads, max_retries=3, retry_exceptions=False)
            pending = {task.remote(argv, n): n for n in names}
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1)
                for r in ready:
                    results[pending.pop(r)] = ray.get(r)
                    sys.stderr.write(f"\r{len(results)}/{len(names)} configurations  {time.time() - t0:7.0f} s")
            sys.stderr.write("\n")
        finally:
            ray.shutdown()
    else:
        for k, name in enumerate(names):
            r = run_config(args, P, work, name)
            results[name] = r
            q = r["ratios"]
            print(f"[{k + 1}/{len(names)}] {name}: eff snee/volpath "
                  f"{fmt(q.get('volpath', {}).get('ratio'))} [{fmt(q.get('volpath', {}).get('lo'))}, "
                  f"{fmt(q.get('volpath', {}).get('hi'))}], snee/Mitsuba {fmt(q.get('mitsuba', {}).get('ratio'))}; "
                  f"z " + " / ".join(fmt(s['z'], 2) for s in r["methods"].values()) +
                  f"; {r['wall_seconds']:.0f} s, load {r['load_average'][1]:.2f}  [{time.time() - t0:.0f} s, "
                  f"projected total {(time.time() - t0) / (k + 1) * len(names) / 60:.1f} min]", flush=True)
        print(f"wall time: {(time.time() - t0) / 60:.1f} min (estimated {est0 / 60:.1f}-{est1 / 60:.1f} min)", flush=True)
    report(args, P, args.mode, work, names, results, time.time() - t0, [load0, os.getloadavg()[0]])
    return 0


if __name__ == "__main__":
    sys.exit(main())
