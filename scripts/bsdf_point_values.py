#!/usr/bin/env python3
"""Point values of Mitsuba 3.9.1's BSDFs for the BSDF tests (tests/plugins/bsdf.rs, bsdf_surfaces.rs).

Writes two files into tests/data/ (variant `scalar_rgb`, both seeded, so they are reproducible):

bsdf_dielectric_diffuse.json, for tests/plugins/bsdf.rs: `roughdielectric` over distributions,
roughnesses, IORs and sampling modes (a sample and eval_pdf at three directions each), the smooth
models `dielectric`, `thindielectric`, `null` (a sample per context and eval_null_transmission), and
`diffuse` / `twosided(diffuse)` (a sample and eval_pdf). Numbers are rounded to 9 significant digits
(round-trip exact for f32).

bsdf_surfaces.json, for tests/plugins/bsdf_surfaces.rs: for every configuration of `conductor`,
`roughconductor`, `plastic`, `roughplastic` and `mask` below, a few incident directions, and for each
  - Mitsuba's `sample(ctx, si, sample1, sample2)`: wo, pdf, weight (RGB), sampled type/component;
  - `eval_pdf` (and `eval`, `pdf` alone, which must agree) at the sampled wo and at independent
    directions (some below the surface);
  - `eval_null_transmission`.
The surface interaction is hand-built with the shading frame = world frame (so wi/wo are local) and
uv = (0.5, 0.5); the variant is `scalar_rgb`. Seeded, so the file is reproducible.

Configurations are written as {"type": plugin, "params": {name: value}} where a value is a number,
a string, a boolean, a 3-list (an <rgb>), or {"bsdf": configuration} for a nested BSDF.

Usage: python3 scripts/bsdf_point_values.py [--help]
"""
import argparse
import math
import random

import mitsuba as mi

import common


def to_mitsuba(cfg):
    d = {"type": cfg["type"]}
    for k, v in cfg["params"].items():
        if isinstance(v, list):
            d[k] = {"type": "rgb", "value": v}
        elif isinstance(v, dict) and "bsdf" in v:
            d[k] = to_mitsuba(v["bsdf"])
        else:
            d[k] = v
    return d


def configs():
    out = []
    # conductor
    for params in [{}, {"material": "Au"}, {"material": "Cu", "specular_reflectance": [0.9, 0.6, 0.4]},
                   {"eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.1]}, {"material": "none"}]:
        out.append({"type": "conductor", "params": params})
    # roughconductor
    materials = ["Al", "Cr", "Ag", "Au"]
    i = 0
    for dist in ["beckmann", "ggx"]:
        for alpha in [0.05, 0.3, (0.05, 0.3), (0.4, 0.1)]:
            for visible in [True, False]:
                p = {"distribution": dist, "sample_visible": visible, "material": materials[i % 4]}
                i += 1
                if isinstance(alpha, tuple):
                    p["alpha_u"], p["alpha_v"] = alpha
                else:
                    p["alpha"] = alpha
                out.append({"type": "roughconductor", "params": p})
    out.append({"type": "roughconductor", "params": {}})
    out.append({"type": "roughconductor", "params": {"eta": [1.5, 1.2, 0.9], "k": [2.0, 3.0, 4.0], "alpha": 0.2,
                                                     "specular_reflectance": [0.5, 0.7, 0.9]}})
    # plastic
    for params in [{}, {"diffuse_reflectance": [0.1, 0.27, 0.36], "int_ior": 1.9},
                   {"diffuse_reflectance": [0.8, 0.3, 0.1], "nonlinear": True},
                   {"specular_reflectance": [0.7, 0.5, 0.3], "int_ior": "water", "ext_ior": "air"},
                   {"int_ior": 1.0, "ext_ior": 1.33, "diffuse_reflectance": [0.6, 0.6, 0.2]}]:
        out.append({"type": "plastic", "params": params})
    # roughplastic
    j = 0
    for dist in ["beckmann", "ggx"]:
        for alpha in [0.05, 0.3, 0.7]:
            for visible in [True, False]:
                p = {"distribution": dist, "alpha": alpha, "sample_visible": visible,
                     "diffuse_reflectance": [[0.5, 0.5, 0.5], [0.8, 0.3, 0.1], [0.1, 0.4, 0.9]][j % 3]}
                if j % 4 == 1:
                    p["nonlinear"] = True
                if j % 5 == 2:
                    p["int_ior"] = 1.9
                if j % 6 == 3:
                    p["specular_reflectance"] = [0.6, 0.8, 1.0]
                j += 1
                out.append({"type": "roughplastic", "params": p})
    out.append({"type": "roughplastic", "params": {}})
    out.append({"type": "roughplastic", "params": {"int_ior": 1.0, "ext_ior": 1.5, "alpha": 0.2,
                                                   "distribution": "ggx"}})
    # mask
    out.append({"type": "mask", "params": {"opacity": 0.3, "inner": {"bsdf": {"type": "diffuse", "params": {
        "reflectance": [0.2, 0.5, 0.8]}}}}})
    out.append({"type": "mask", "params": {"inner": {"bsdf": {"type": "roughconductor", "params": {
        "material": "Au", "alpha": 0.2, "distribution": "ggx"}}}}})
    out.append({"type": "mask", "params": {"opacity": [0.9, 0.6, 0.3], "inner": {"bsdf": {
        "type": "plastic", "params": {}}}}})
    out.append({"type": "mask", "params": {"opacity": 1.3, "inner": {"bsdf": {"type": "diffuse", "params": {}}}}})
    return out


def sph(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]


def si_for(wi):
    si = mi.SurfaceInteraction3f()
    si.p = [0, 0, 0]
    si.n = [0, 0, 1]
    si.sh_frame = mi.Frame3f([0, 0, 1])
    si.uv = [0.5, 0.5]
    si.wi = wi
    return si


def vec(v):
    return [float(v[0]), float(v[1]), float(v[2])]


def f9(x):
    """A float rounded to 9 significant digits (what the tests read as f32, round-trip exact)."""
    return common.rounded(x, 9)


def v9(v):
    return [f9(v[0]), f9(v[1]), f9(v[2])]


def dielectric_diffuse_cases():
    """roughdielectric, the smooth models and diffuse/twosided: the tables of tests/plugins/bsdf.rs."""
    rng = random.Random(12345)
    rough = []
    for dist in ["beckmann", "ggx"]:
        for (au, av) in [(0.05, 0.05), (0.2, 0.2), (0.7, 0.7), (0.1, 0.4)]:
            for (int_ior, ext_ior) in [(1.33, 1.0), (1.5, 1.0), (1.0, 1.5)]:
                for visible in [True, False]:
                    d = {"type": "roughdielectric", "distribution": dist, "int_ior": int_ior, "ext_ior": ext_ior,
                         "sample_visible": visible}
                    if au == av:
                        d["alpha"] = au
                    else:
                        d["alpha_u"], d["alpha_v"] = au, av
                    b = mi.load_dict(d)
                    theta = rng.choice([25.0, 60.0, 80.0, 120.0, 165.0])
                    wi = mi.Vector3f(sph(theta, rng.uniform(0, 360)))
                    si = si_for(wi)
                    mode = rng.choice([mi.TransportMode.Radiance, mi.TransportMode.Importance])
                    ctx = mi.BSDFContext(mode)
                    # a sampled direction (valid) and an independent direction
                    s1, s2 = rng.random(), [rng.random(), rng.random()]
                    bs, w = b.sample(ctx, si, s1, s2)
                    bs2, _ = b.sample(ctx, si, rng.random(), [rng.random(), rng.random()])
                    wo3 = mi.Vector3f(sph(rng.uniform(0, 180), rng.uniform(0, 360)))
                    for wo in [bs.wo, bs2.wo, wo3]:
                        e, p = b.eval_pdf(ctx, si, wo)
                        e2, p2 = b.eval(ctx, si, wo)[0], b.pdf(ctx, si, wo)
                        assert abs(e[0] - e2) <= 1e-6 * max(1, abs(e[0])) and abs(p - p2) <= 1e-6 * max(1, abs(p))
                        rough.append({
                            "distribution": dist, "alpha_u": f9(au), "alpha_v": f9(av), "int_ior": f9(int_ior),
                            "ext_ior": f9(ext_ior), "sample_visible": visible,
                            "mode": "Radiance" if mode == mi.TransportMode.Radiance else "Importance",
                            "wi": v9(wi), "wo": v9(wo), "eval": f9(e[0]), "pdf": f9(p), "sample1": f9(s1),
                            "sample2": [f9(s2[0]), f9(s2[1])], "s_wo": v9(bs.wo), "s_pdf": f9(bs.pdf),
                            "s_weight": f9(w[0]), "s_eta": f9(bs.eta), "s_type": int(bs.sampled_type)})

    # Smooth models: (plugin, ctx, wi, sample1) -> sample (sample2 = (0.3, 0.6)), eval_null_transmission.
    smooth = []
    for plugin in ["dielectric", "thindielectric", "null"]:
        for (int_ior, ext_ior) in ([(None, None), (1.33, 1.0), (1.0, 1.5)] if plugin != "null" else [(None, None)]):
            d = {"type": plugin}
            if int_ior is not None:
                d["int_ior"], d["ext_ior"] = int_ior, ext_ior
            b = mi.load_dict(d)
            combos = [(t, c, s1) for t in [10.0, 55.0, 85.0, 130.0, 170.0]
                      for c in [("Radiance", -1, 0x1FF), ("Importance", -1, 0x1FF), ("Radiance", 0, 0x1FF),
                                ("Radiance", 1, 0x1FF), ("Radiance", -1, 0x40 if plugin == "dielectric" else 0x1)]
                      for s1 in [0.02, 0.5, 0.97]]
            for (theta, (mode, comp, mask), s1) in rng.sample(combos, 12):
                wi = mi.Vector3f(sph(theta, rng.uniform(0, 360)))
                si = si_for(wi)
                ctx = mi.BSDFContext(mi.TransportMode.Radiance if mode == "Radiance" else mi.TransportMode.Importance,
                                     mask, comp if comp >= 0 else 0xFFFFFFFF)
                bs, w = b.sample(ctx, si, s1, [0.3, 0.6])
                smooth.append({
                    "plugin": plugin, "int_ior": f9(int_ior if int_ior else 1.5046),
                    "ext_ior": f9(ext_ior if ext_ior else 1.000277), "mode": mode, "component": comp,
                    "type_mask": mask, "wi": v9(wi), "sample1": f9(s1), "wo": v9(bs.wo), "pdf": f9(bs.pdf),
                    "weight": f9(w[0]), "eta": f9(bs.eta), "s_type": int(bs.sampled_type),
                    "s_component": int(bs.sampled_component),
                    "null_transmission": f9(b.eval_null_transmission(si)[0])})

    # diffuse and twosided(diffuse), reflectance (0.2, 0.5, 0.8); sample1 = 0.5.
    diffuse = []
    for two in [False, True]:
        inner = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.8]}}
        b = mi.load_dict({"type": "twosided", "m": inner} if two else inner)
        for theta in [20.0, 70.0, 110.0, 160.0]:
            wi = mi.Vector3f(sph(theta, rng.uniform(0, 360)))
            si = si_for(wi)
            ctx = mi.BSDFContext()
            s2 = [rng.random(), rng.random()]
            bs, w = b.sample(ctx, si, 0.5, s2)
            wo = mi.Vector3f(sph(rng.choice([30.0, 150.0]), rng.uniform(0, 360)))
            e, p = b.eval_pdf(ctx, si, wo)
            diffuse.append({"twosided": two, "wi": v9(wi), "sample2": [f9(s2[0]), f9(s2[1])], "s_wo": v9(bs.wo),
                            "s_pdf": f9(bs.pdf), "s_weight": v9(w), "wo": v9(wo), "eval": v9(e), "pdf": f9(p)})
    return {"mitsuba_version": mi.__version__, "variant": "scalar_rgb", "rough_dielectric": rough,
            "smooth": smooth, "diffuse": diffuse}


def main():
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    common.setup_mitsuba("scalar_rgb")
    data = dielectric_diffuse_cases()
    path = common.write_test_json("bsdf_dielectric_diffuse.json", data)
    print("wrote %s (%d + %d + %d cases)" % (path, len(data["rough_dielectric"]), len(data["smooth"]),
                                             len(data["diffuse"])))
    surface_cases()


def surface_cases():
    random.seed(20261127)
    result = {"mitsuba_version": mi.__version__, "variant": "scalar_rgb", "configs": []}
    for cfg in configs():
        b = mi.load_dict(to_mitsuba(cfg))
        ncomp = b.component_count()
        cases = []
        for theta in [5.0, 35.0, 65.0, 86.0, 120.0]:
            wi = mi.Vector3f(sph(theta, random.uniform(0, 360)))
            si = si_for(wi)
            # contexts: all lobes, plus one restricted to a random component
            ctxs = [(mi.TransportMode.Radiance, 0x1FF, -1)]
            if theta == 35.0:
                ctxs.append((mi.TransportMode.Radiance, 0x1FF, random.randrange(ncomp)))
            if theta == 65.0:
                ctxs.append((mi.TransportMode.Importance, 0x1FF, -1))
            for (mode, mask, comp) in ctxs:
                ctx = mi.BSDFContext(mode, mask, comp if comp >= 0 else 0xFFFFFFFF)
                for _ in range(2):
                    s1, s2 = random.random(), [random.random(), random.random()]
                    bs, w = b.sample(ctx, si, s1, s2)
                    wos = [bs.wo, mi.Vector3f(sph(random.uniform(0, 89), random.uniform(0, 360))),
                           mi.Vector3f(sph(random.uniform(0, 180), random.uniform(0, 360)))]
                    evals = []
                    for wo in wos:
                        e, p = b.eval_pdf(ctx, si, wo)
                        e2, p2 = b.eval(ctx, si, wo), b.pdf(ctx, si, wo)
                        evals.append({"wo": vec(wo), "eval": vec(e), "pdf": float(p), "eval_alone": vec(e2),
                                      "pdf_alone": float(p2)})
                    cases.append({
                        "mode": "Radiance" if mode == mi.TransportMode.Radiance else "Importance",
                        "component": comp, "wi": vec(wi), "sample1": s1, "sample2": s2,
                        "s_wo": vec(bs.wo), "s_pdf": float(bs.pdf), "s_weight": vec(w),
                        "s_type": int(bs.sampled_type), "s_component": int(bs.sampled_component),
                        "s_eta": float(bs.eta), "evals": evals,
                        "null_transmission": vec(b.eval_null_transmission(si)),
                    })
        result["configs"].append({"config": cfg, "flags": [int(b.flags(i)) for i in range(ncomp)], "cases": cases})
    path = common.write_test_json("bsdf_surfaces.json", result)
    print("wrote %s (%d configurations)" % (path, len(result["configs"])))


if __name__ == "__main__":
    main()
