#!/usr/bin/env python3
"""Write the assets of the paper-figure scenes (Koerner et al. 2016, Section 6) into scenes/paper/.

Outputs (deterministic: fixed seeds, no clocks):

  scenes/paper/statue.ply   binary little-endian PLY, float x y z nx ny nz, int face indices.
                            A procedural "statue": a closed surface of revolution (pedestal,
                            body, neck, head; 1.0 m tall, y in [0, 1], base centred on the origin)
                            whose axis sways, whose cross-sections are elliptic, and which is
                            displaced radially by several octaves of sinusoidal relief (wavelengths
                            down to ~1 cm, amplitudes up to ~8 % of the local radius), so that
                            the boundary normals vary at high frequency as on a carved statue.
                            RINGS x SEGMENTS quad grid plus two pole fans: 124,160 triangles,
                            62,082 vertices (3.1 MB); outward (counter-clockwise from outside) winding,
                            area-weighted vertex normals.
  scenes/paper/sun_sky.exr  256x128 lat-long environment map, float32 RGB, Mitsuba's layout
                            (row 0 = +Y pole, u = atan2(d.x, -d.z)/2pi): a gradient sky, a dim
                            ground, and a small very bright sun disc (angular radius
                            SUN_RADIUS_DEG, radiance SUN_RADIANCE) at elevation 55 deg.

After writing, both files are loaded with Mitsuba 3 (scalar_rgb) and checked.

Usage:  python3 scripts/make_figure_assets.py [--out scenes/paper]
"""
import argparse
import math
import os
import sys

import numpy as np

import common

RINGS = 322  # rings of the surface of revolution (including the two pole rings)
SEGMENTS = 194  # vertices around each ring
SUN_ELEVATION_DEG = 55.0
SUN_AZIMUTH_DEG = 150.0  # phi = 2*pi*u, measured from -Z towards +X: in front of the camera, to the right
SUN_RADIUS_DEG = 2.0
SUN_RADIANCE = np.array([1500.0, 1400.0, 1250.0])

# The statue's profile, (radius, height) from the bottom pole to the top pole, in metres.
PROFILE = [
    (0.0, 0.0), (0.19, 0.0), (0.20, 0.01), (0.20, 0.09), (0.19, 0.10), (0.15, 0.11),
    (0.14, 0.14), (0.15, 0.25), (0.16, 0.38), (0.14, 0.50), (0.13, 0.58), (0.15, 0.66),
    (0.15, 0.70), (0.10, 0.74), (0.055, 0.77), (0.055, 0.80), (0.085, 0.84), (0.095, 0.89),
    (0.085, 0.95), (0.05, 0.99), (0.0, 1.0),
]


# ----------------------------------------------------------------------------- statue mesh

def resample_profile(n):
    """n points along PROFILE, equally spaced in arc length, corners rounded by smoothing."""
    p = np.array(PROFILE, dtype=np.float64)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], n)
    r = np.interp(t, s, p[:, 0])
    y = np.interp(t, s, p[:, 1])
    # Round the corners: a few passes of a [1 2 1]/4 filter, keeping both poles fixed.
    for _ in range(6):
        r[1:-1] = 0.25 * r[:-2] + 0.5 * r[1:-1] + 0.25 * r[2:]
        y[1:-1] = 0.25 * y[:-2] + 0.5 * y[1:-1] + 0.25 * y[2:]
    r[0] = r[-1] = 0.0
    return r, y


def relief(phi, y, rng):
    """Relative radial displacement: octaves of oriented sinusoids (deterministic phases)."""
    d = np.zeros(np.broadcast(phi, y).shape)
    octaves = [  # (angular frequency, vertical frequency [1/m], amplitude)
        (3, 4.0, 0.060), (5, 9.0, 0.040), (9, 17.0, 0.030), (14, 31.0, 0.022),
        (23, 53.0, 0.016), (37, 89.0, 0.012), (61, 150.0, 0.009),
    ]
    for fa, fy, amp in octaves:
        for _ in range(2):
            ph1, ph2 = rng.uniform(0.0, 2.0 * np.pi, 2)
            tilt = rng.uniform(-1.0, 1.0)
            d += amp * np.sin(fa * phi + ph1 + tilt * fy * y) * np.sin(fy * y + ph2)
    # Vertical grooves ("drapery folds") on the body.
    folds = 0.05 * np.sin(11.0 * phi + 3.0 * np.sin(7.0 * y)) ** 3
    body = np.clip((y - 0.12) / 0.06, 0.0, 1.0) * np.clip((0.70 - y) / 0.06, 0.0, 1.0)
    return d + folds * body


def statue_mesh():
    rng = np.random.default_rng(20161115)
    r0, y = resample_profile(RINGS)
    phi = np.arange(SEGMENTS) * (2.0 * np.pi / SEGMENTS)
    P, Y = np.meshgrid(phi, y)  # (RINGS, SEGMENTS)
    R = r0[:, None] * (1.0 + relief(P, Y, rng))
    # Elliptic cross-sections (broader across x) and a gentle sway of the axis.
    ax = 1.0 + 0.15 * np.clip((Y - 0.1) / 0.2, 0.0, 1.0)
    cx = 0.03 * np.sin(3.0 * Y) * np.clip(Y / 0.12, 0.0, 1.0)
    cz = 0.02 * np.sin(5.0 * Y + 1.0) * np.clip(Y / 0.12, 0.0, 1.0)
    X = cx + R * ax * np.cos(P)
    Z = cz - R * np.sin(P)
    # Interior rings only; each pole is one vertex.
    ring_v = np.stack([X[1:-1], Y[1:-1], Z[1:-1]], axis=-1).reshape(-1, 3)
    bottom = np.array([[0.0, y[0], 0.0]])
    top = np.array([[cx[-1, 0], y[-1], cz[-1, 0]]])
    verts = np.concatenate([bottom, ring_v, top])
    nr = RINGS - 2

    def vid(i, j):  # ring i in [0, nr), segment j
        return 1 + i * SEGMENTS + (j % SEGMENTS)

    faces = []
    j = np.arange(SEGMENTS)
    faces.append(np.stack([np.zeros(SEGMENTS, int), vid(0, j + 1), vid(0, j)], axis=1))
    for i in range(nr - 1):
        a, b, c, d = vid(i, j), vid(i, j + 1), vid(i + 1, j + 1), vid(i + 1, j)
        faces.append(np.stack([a, b, c], axis=1))
        faces.append(np.stack([a, c, d], axis=1))
    last = len(verts) - 1
    faces.append(np.stack([np.full(SEGMENTS, last), vid(nr - 1, j), vid(nr - 1, j + 1)], axis=1))
    faces = np.concatenate(faces).astype(np.int64)
    if signed_volume(verts, faces) < 0.0:
        faces = faces[:, ::-1].copy()
    return verts, faces


def signed_volume(verts, faces):
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def check_closed(faces):
    """Every undirected edge is shared by exactly two faces, with opposite orientations."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    directed = {tuple(x) for x in e.tolist()}
    assert len(directed) == len(e), "a directed edge appears twice (inconsistent winding)"
    for a, b in e.tolist():
        assert (b, a) in directed, "open edge"


def write_ply_binary(path, verts, faces, normals):
    common.write_ply_binary(path, verts, faces, normals, "procedural statue written by scripts/make_figure_assets.py")


# ----------------------------------------------------------------------------- environment map

def sun_direction():
    return common.sun_direction(SUN_ELEVATION_DEG, SUN_AZIMUTH_DEG)


def make_sun_sky(width=256, height=128, supersample=4):
    """Lat-long sun and sky, shape (height, width, 3), float32."""
    return common.lat_long_sky(sun_direction(), SUN_RADIUS_DEG, SUN_RADIANCE, zenith=[0.10, 0.22, 0.60],
                               horizon=[0.60, 0.68, 0.80], glow=0.8, glow_sharpness=12.0, glow_color=[1.0, 0.8, 0.55],
                               ground=[0.12, 0.10, 0.08], width=width, height=height, supersample=supersample)


# ----------------------------------------------------------------------------- scenes

# The three lights of the paper's Section 6, all from the sun's direction of sun_sky.exr, with
# about the sun's irradiance (SUN_RADIANCE x the disc's solid angle).
LIGHT_SOLID_ANGLE = 0.006  # sr, the distant sphere light (100x the Sun's)
LIGHT_DISTANCE = 100.0  # m, centre of the distant sphere light
LIGHTS = ["envmap", "sphere", "directional"]
BOUNDARIES = {  # name -> (label, BSDF XML)
    "ggx020": ("rough GGX a=0.2",
               '<bsdf type="roughdielectric">\n'
               '            <string name="distribution" value="ggx"/>\n'
               '            <float name="alpha" value="0.2"/>\n'
               '            <float name="int_ior" value="1.5"/>\n'
               '            <float name="ext_ior" value="1.0"/>\n'
               '        </bsdf>'),
    "ggx004": ("rough GGX a=0.04",
               '<bsdf type="roughdielectric">\n'
               '            <string name="distribution" value="ggx"/>\n'
               '            <float name="alpha" value="0.04"/>\n'
               '            <float name="int_ior" value="1.5"/>\n'
               '            <float name="ext_ior" value="1.0"/>\n'
               '        </bsdf>'),
    "smooth": ("smooth",
               '<bsdf type="dielectric">\n'
               '            <float name="int_ior" value="1.5"/>\n'
               '            <float name="ext_ior" value="1.0"/>\n'
               '        </bsdf>'),
}
EXTINCTIONS = {"st02": 2.0, "st34": 34.0}


def scene_name(light, boundary, ext):
    return f"{light}_{boundary}_{ext}"


def sun_irradiance():
    solid = 2.0 * np.pi * (1.0 - math.cos(math.radians(SUN_RADIUS_DEG)))
    return SUN_RADIANCE * solid


def light_xml(light):
    d = sun_direction()
    e = sun_irradiance()
    if light == "envmap":
        return ('<emitter type="envmap">\n'
                '        <string name="filename" value="sun_sky.exr"/>\n'
                '    </emitter>')
    if light == "directional":
        return ('<emitter type="directional">\n'
                f'        <vector name="direction" x="{-d[0]:.6f}" y="{-d[1]:.6f}" z="{-d[2]:.6f}"/>\n'
                f'        <rgb name="irradiance" value="{e[0]:.6f}, {e[1]:.6f}, {e[2]:.6f}"/>\n'
                '    </emitter>')
    # Sphere of angular radius asin(r/D) with solid angle 2pi(1 - cos) = LIGHT_SOLID_ANGLE.
    cos_a = 1.0 - LIGHT_SOLID_ANGLE / (2.0 * np.pi)
    radius = LIGHT_DISTANCE * math.sqrt(1.0 - cos_a * cos_a)
    c = LIGHT_DISTANCE * d
    le = e / LIGHT_SOLID_ANGLE
    return ('<!-- Distant sphere light: solid angle %.4f sr seen from the statue. -->\n'
            '    <shape type="sphere">\n'
            f'        <point name="center" x="{c[0]:.4f}" y="{c[1]:.4f}" z="{c[2]:.4f}"/>\n'
            f'        <float name="radius" value="{radius:.6f}"/>\n'
            '        <emitter type="area">\n'
            f'            <rgb name="radiance" value="{le[0]:.4f}, {le[1]:.4f}, {le[2]:.4f}"/>\n'
            '        </emitter>\n'
            '    </shape>') % LIGHT_SOLID_ANGLE


SCENE_TEMPLATE = """<!-- Koerner et al. 2016, Section 6 configuration "{name}": the procedural statue (1 m tall,
     statue.ply) bounding a homogeneous medium (albedo 0.8, isotropic phase, extinction {sigma_t:g} /m)
     behind a {label} dielectric boundary (IOR 1.5), lit by the {light} light.
     Written by scripts/make_figure_assets.py; loads unchanged in Mitsuba 3 (integrator volpath).
     snee: -D integrator=volpath_snee (its options snee/transport are added by
     scripts/reproduce_figures.py in derived files). -->
<scene version="3.0.0">
    <default name="integrator" value="volpath"/>
    <default name="spp" value="64"/>
    <default name="width" value="96"/>
    <default name="height" value="128"/>
    <default name="max_depth" value="-1"/>

    <integrator type="$integrator">
        <integer name="max_depth" value="$max_depth"/>
    </integrator>

    <sensor type="perspective">
        <string name="fov_axis" value="y"/>
        <float name="fov" value="21"/>
        <transform name="to_world">
            <lookat origin="0, 0.55, 3.2" target="0, 0.5, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/>
            <integer name="height" value="$height"/>
            <rfilter type="box"/>
        </film>
    </sensor>

    {light_xml}

    <medium type="homogeneous" id="interior">
        <rgb name="albedo" value="0.8"/>
        <float name="sigma_t" value="{sigma_t:g}"/>
        <phase type="isotropic"/>
    </medium>

    <shape type="ply">
        <string name="filename" value="statue.ply"/>
        <ref name="interior" id="interior"/>
        {bsdf_xml}
    </shape>
</scene>
"""


def write_scenes(out):
    names = []
    for ext, sigma_t in EXTINCTIONS.items():
        for light in LIGHTS:
            for boundary, (label, bsdf_xml) in BOUNDARIES.items():
                name = scene_name(light, boundary, ext)
                text = SCENE_TEMPLATE.format(name=name, sigma_t=sigma_t, label=label, light=light,
                                             light_xml=light_xml(light), bsdf_xml=bsdf_xml)
                with open(os.path.join(out, name + ".xml"), "w") as fh:
                    fh.write(text)
                names.append(name)
    return names


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--out", default=os.path.join(here, "..", "scenes", "paper"))
    args = ap.parse_args()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)

    verts, faces = statue_mesh()
    check_closed(faces)
    normals = common.vertex_normals(verts, faces)
    ply = os.path.join(out, "statue.ply")
    write_ply_binary(ply, verts, faces, normals)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    print(f"statue.ply: {len(verts)} vertices, {len(faces)} triangles, "
          f"volume {signed_volume(verts, faces):.4f} m^3, bbox {np.round(lo, 3)} .. {np.round(hi, 3)}, "
          f"{os.path.getsize(ply) / 1e6:.2f} MB")

    mi, _ = common.setup_mitsuba("scalar_rgb")
    sky = make_sun_sky()
    exr = os.path.join(out, "sun_sky.exr")
    mi.Bitmap(sky, pixel_format=mi.Bitmap.PixelFormat.RGB).write(exr)
    print(f"sun_sky.exr: {sky.shape[1]}x{sky.shape[0]}, max {sky.max():.0f}, "
          f"{os.path.getsize(exr) / 1e3:.0f} KB")

    # Load both with Mitsuba and check what it sees.
    mesh = mi.load_dict({"type": "ply", "filename": ply})
    assert mesh.vertex_count() == len(verts) and mesh.face_count() == len(faces), "Mitsuba PLY mismatch"
    assert mesh.has_vertex_normals(), "Mitsuba found no vertex normals"
    bmp = np.array(mi.Bitmap(exr))
    assert bmp.shape == sky.shape and np.array_equal(bmp, sky), "Mitsuba EXR mismatch"
    print("mitsuba: statue.ply and sun_sky.exr load and match")

    names = write_scenes(out)
    # Mitsuba substitutes "$integrator" in the type attribute (checked here with volpathmis too).
    want = str(mi.load_dict({"type": "volpath"}))
    for name in names:
        path = os.path.join(out, name + ".xml")
        scene = mi.load_file(path)
        assert str(scene.integrator()) == want, scene.integrator()
        assert scene.shapes()[-1].face_count() == len(faces) or len(scene.shapes()) == 2
    mis = mi.load_file(os.path.join(out, names[0] + ".xml"), integrator="volpathmis")
    assert str(mis.integrator()) == str(mi.load_dict({"type": "volpathmis"}))
    print(f"mitsuba: {len(names)} scenes in {out} load (integrator volpath)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
