#!/usr/bin/env python3
"""Point values of Mitsuba 3.9.1's surface BSDFs for tests/bsdf_surfaces.rs.

Writes tests/data/bsdf_surfaces.json: for every configuration of `conductor`, `roughconductor`,
`plastic`, `roughplastic` and `mask` below, a few incident directions, and for each
  - Mitsuba's `sample(ctx, si, sample1, sample2)`: wo, pdf, weight (RGB), sampled type/component;
  - `eval_pdf` (and `eval`, `pdf` alone, which must agree) at the sampled wo and at independent
    directions (some below the surface);
  - `eval_null_transmission`.
The surface interaction is hand-built with the shading frame = world frame (so wi/wo are local) and
uv = (0.5, 0.5); the variant is `scalar_rgb`. Seeded, so the file is reproducible.

Configurations are written as {"type": plugin, "params": {name: value}} where a value is a number,
a string, a boolean, a 3-list (an <rgb>), or {"bsdf": configuration} for a nested BSDF.

Usage: python3 scripts/bsdf_point_values.py
"""
import json
import math
import os
import random

import mitsuba as mi

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


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


def main():
    mi.set_variant("scalar_rgb")
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
    path = os.path.join(ROOT, "tests", "data", "bsdf_surfaces.json")
    with open(path, "w") as fh:
        json.dump(result, fh, separators=(",", ":"))
    print("wrote %s (%d configurations)" % (path, len(result["configs"])))


if __name__ == "__main__":
    main()
