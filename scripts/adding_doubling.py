#!/usr/bin/env python3
"""Adding-doubling reference values for a thick (semi-infinite) scattering slab, via iadpython.

Writes tests/data/adding_doubling.json and prints a table.

Setup: a plane-parallel slab of optical thickness b = 1e4 (far beyond the diffusion length of every
case here, so it behaves as semi-infinite: the transmittance is ~1e-24 or smaller), single-scattering
albedo a, Henyey-Greenstein phase function with anisotropy g, refractive index n, in air (no glass
slides: n_above = n_below = 1, so the boundary is a smooth Fresnel interface air | n). A collimated
beam hits it at normal incidence.

iadpython conventions (checked in iadpython 0.5.3's source, iadpython/ad.py, and numerically):
  * `Sample(a, b, g, n=..., n_above=1, n_below=1, quad_pts=Q).rt()` returns FOUR values
    (UR1, UT1, URU, UTU) -- not two as the class docstring's example says. UR1 and UT1 are the total
    reflected and transmitted fractions of a collimated beam at normal incidence (nu_0 = 1);
    URU and UTU are the same for diffuse (Lambertian) illumination.
  * UR1 INCLUDES the specular (unscattered) reflection at the top surface: the boundary layer's
    reflection matrix is combined into R (Sample.rt_matrices: boundary_layer + add_same_slides) and
    UR1 is read off the total R. Checked: with a = 0 (nothing scatters back) UR1 equals
    ((n - 1) / (n + 1))^2 exactly (0.04 for n = 1.5), which is also what
    `Sample.unscattered_rt()[0]` returns. So R_total = UR1 = R_specular + R_diffuse.
  * Unscattered light reflected from the bottom surface would also count, but at b = 1e4 none
    reaches it.
  * The HG phase function is handled with the delta-M method truncated at Q terms, so the result
    depends on the quadrature order Q. Radau quadrature over [0, 1] (used when n = 1) becomes
    numerically unstable for Q >= 32 in this version (UR1 jumps, e.g. 0.39955 -> 0.61778 at
    a = 0.99, g = 0.9), and for n != 1 (Gauss + Radau split at the critical angle) for Q >= 48.
    We therefore use Q = 24 for n = 1 and Q = 40 for n != 1, and report the change from Q = 16
    (n = 1) or Q = 32 (n != 1) as `quad_change`, an estimate of the quadrature error
    (all < 1e-4: at most 5e-5, for g = 0.9).

What a renderer should compare with: R_specular = ((n-1)/(n+1))^2 is the Fresnel reflectance at
normal incidence; a directional light reflected by a smooth dielectric is a delta peak that a
path tracer sampling from an irradiance meter above the slab cannot hit, so such a measurement
gives R_diffuse = R_total - R_specular (also stored).

Independent check (printed): for g = 0 and n = 1 the semi-infinite albedo problem has the exact
answer R(mu_0 = 1) = 1 - H(1) sqrt(1 - a), with Chandrasekhar's H-function for isotropic
scattering, solved here by fixed-point iteration on a fine Gauss-Legendre grid.

Usage:  python3 scripts/adding_doubling.py [--out tests/data/adding_doubling.json]
"""
import argparse
import itertools
import json
import os
import warnings

import numpy as np

import common

ALBEDOS = [0.3, 0.8, 0.95, 0.99]
GS = [0.0, 0.5, -0.3, 0.9]
NS = [1.0, 1.33, 1.5]
B = 1e4


def quad_orders(n):
    """(quadrature order used, coarser order for the error estimate)."""
    return (24, 16) if n == 1.0 else (40, 32)


def ur1(a, g, n, b, quad_pts):
    import iadpython
    s = iadpython.Sample(a=a, b=b, g=g, n=n, n_above=1.0, n_below=1.0, quad_pts=quad_pts)
    ur1_, ut1, _uru, _utu = s.rt()
    return float(ur1_), float(ut1), float(s.unscattered_rt()[0])


def chandrasekhar_h1(a, nodes=400, iters=2000):
    """H(1) of the isotropic H-function: 1/H(mu) = sqrt(1-a) + a/2 int_0^1 mu' H(mu')/(mu+mu') dmu'."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    mu, w = 0.5 * (x + 1.0), 0.5 * w
    h = np.ones(nodes)
    for _ in range(iters):
        integral = (w * mu * h)[None, :] / (mu[:, None] + mu[None, :])
        h_new = 1.0 / (np.sqrt(1.0 - a) + 0.5 * a * integral.sum(axis=1))
        if np.max(np.abs(h_new - h)) < 1e-14:
            h = h_new
            break
        h = h_new
    return 1.0 / (np.sqrt(1.0 - a) + 0.5 * a * np.sum(w * mu * h / (1.0 + mu)))


def main():
    ap = argparse.ArgumentParser(description="Adding-doubling (iadpython) total reflectance of a "
                                             "semi-infinite slab under a normal collimated beam.")
    ap.add_argument("--out", default=os.path.join(common.TEST_DATA, "adding_doubling.json"),
                    help="output JSON (default: tests/data/adding_doubling.json)")
    args = ap.parse_args()

    import iadpython
    entries = []
    print(f"{'albedo':>6} {'g':>5} {'n':>5} {'b':>7} {'R_total':>9} {'R_specular':>10} "
          f"{'R_diffuse':>9} {'T_total':>8} {'Q':>3} {'quad_change':>11}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for a, g, n in itertools.product(ALBEDOS, GS, NS):
            q, q_coarse = quad_orders(n)
            r, t, r_unscattered = ur1(a, g, n, B, q)
            r_coarse = ur1(a, g, n, B, q_coarse)[0]
            r_spec = ((n - 1.0) / (n + 1.0)) ** 2
            assert abs(r_unscattered - r_spec) < 1e-12, (r_unscattered, r_spec)
            e = dict(albedo=a, g=g, n=n, b=B, R_total=round(r, 8), R_specular=round(r_spec, 8),
                     R_diffuse=round(r - r_spec, 8), T_total=t, quad_pts=q,
                     quad_change=float(f"{abs(r - r_coarse):.2e}"))
            entries.append(e)
            print(f"{a:6.2f} {g:5.2f} {n:5.2f} {B:7.0e} {r:9.6f} {r_spec:10.6f} {r - r_spec:9.6f} "
                  f"{t:8.1e} {q:3d} {abs(r - r_coarse):11.2e}")

    print("\nCheck against Chandrasekhar's H-function (g = 0, n = 1): R = 1 - H(1) sqrt(1 - a)")
    worst = 0.0
    for e in entries:
        if e["g"] == 0.0 and e["n"] == 1.0:
            exact = 1.0 - chandrasekhar_h1(e["albedo"]) * np.sqrt(1.0 - e["albedo"])
            worst = max(worst, abs(exact - e["R_total"]))
            print(f"  a = {e['albedo']:.2f}: iadpython {e['R_total']:.6f}  H-function {exact:.6f}  "
                  f"diff {e['R_total'] - exact:+.1e}")
    if worst > 1e-3:
        raise SystemExit(f"adding-doubling disagrees with the H-function solution by {worst:.1e}")

    doc = {
        "description": "Total reflectance of a semi-infinite slab (optical thickness b) under a "
                       "collimated beam at normal incidence, HG phase function, smooth boundary "
                       "air | n, by adding-doubling (iadpython). R_total = UR1 includes the "
                       "specular Fresnel reflection R_specular = ((n-1)/(n+1))^2; "
                       "R_diffuse = R_total - R_specular. Written by scripts/adding_doubling.py.",
        "iadpython_version": iadpython.__version__,
        "entries": entries,
    }
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"\nwrote {args.out} ({len(entries)} entries)")


if __name__ == "__main__":
    main()
