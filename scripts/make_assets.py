#!/usr/bin/env python3
"""Write the small assets the test scenes use (textures and meshes) into scenes/.

Outputs (all deterministic, each well under 200 KB):

  scenes/textures/sky.exr      256x128 lat-long environment map, float32 RGB (channels R,G,B,
                               PIZ-compressed; values rounded to half-float precision).
                               Mitsuba's envmap convention: row 0 is the +Y pole, the last row
                               the -Y pole (row j <-> theta = j/(H-1)*pi), column i <-> u = (i+0.5)/W,
                               u = atan2(d.x, -d.z) / 2pi, so the centre column looks along +Z.
                               A gradient sky (zenith blue -> pale horizon, brighter towards the
                               sun), a dim brown ground below the horizon, and a small very bright
                               sun disc (angular radius SUN_RADIUS_DEG, radiance SUN_RADIANCE) in
                               direction (-0.66, 0.64, -0.38) (elevation 40 deg, azimuth -60 deg:
                               towards -X and -Z, i.e. u = 5/6).
  scenes/textures/checker.png  64x64 8-bit sRGB checkerboard (8x8 tiles) with a gentle red ramp
                               along +u (x to the right) and green ramp along +v (image rows
                               downward), so flipped or transposed uv mappings show.
  scenes/meshes/blob.ply       binary little-endian PLY: closed "bunny-like" blob (displaced
                               icosphere, 642 vertices, 1280 triangles), float x y z nx ny nz,
                               outward (counter-clockwise seen from outside) winding, unit size.
  scenes/meshes/pebble.ply     ascii PLY: closed squashed icosphere (162 vertices, 320 triangles)
                               with per-vertex u v (no normals: the loader computes them).
  scenes/meshes/cylinder.obj   closed 16-sided cylinder, radius 0.5, y in [0, 1], with v/vt/vn
                               faces: side quads (smooth normals, u around, v up) and two
                               16-gon caps (flat normals) that the loader must fan-triangulate.
  scenes/meshes/two_meshes.serialized
                               Mitsuba serialized file (format 0x041C, version 4, zlib) holding two
                               meshes: shape_index 0 = "rock" (icosphere blob with vertex normals),
                               shape_index 1 = "torus" (with uvs, no normals).

After writing, every mesh is loaded with Mitsuba 3 and its vertex/face counts are checked
(serialized: both shape_index 0 and 1).

Usage:  python3 scripts/make_assets.py [--out scenes]
"""
import argparse
import math
import os
import struct
import sys
import zlib

import numpy as np

import common

SUN_ELEVATION_DEG = 40.0
SUN_AZIMUTH_DEG = -60.0  # azimuth phi = 2*pi*u measured from +Z towards +X
SUN_RADIUS_DEG = 3.5
SUN_RADIANCE = np.array([150.0, 140.0, 120.0])


# ----------------------------------------------------------------------------- textures

def sun_direction():
    return common.sun_direction(SUN_ELEVATION_DEG, SUN_AZIMUTH_DEG)


def make_sky(width=256, height=128, supersample=4):
    """Lat-long sky, shape (height, width, 3), float32, Mitsuba's lat-long layout: zenith blue to a
    pale horizon, a glow around the sun, the sun disc, a dim warm brown ground."""
    return common.lat_long_sky(sun_direction(), SUN_RADIUS_DEG, SUN_RADIANCE, zenith=[0.18, 0.35, 0.85],
                               horizon=[0.85, 0.9, 1.0], glow=0.6, glow_sharpness=8.0, glow_color=[1.0, 0.85, 0.6],
                               ground=[0.3, 0.25, 0.2], width=width, height=height, supersample=supersample)


def srgb_encode(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def make_checker(size=64, tiles=8):
    """8-bit sRGB checkerboard, shape (size, size, 3), uint8."""
    idx = np.arange(size)
    tile = size // tiles
    cx = (idx[None, :] // tile + idx[:, None] // tile) % 2
    u = (idx[None, :] + 0.5) / size          # grows to the right
    v = (idx[:, None] + 0.5) / size          # grows downward (row index)
    light = np.array([0.75, 0.72, 0.65])
    dark = np.array([0.08, 0.1, 0.16])
    base = np.where(cx[..., None] == 0, light, dark)
    ramp = np.stack(np.broadcast_arrays(0.6 + 0.4 * u, 0.6 + 0.4 * v, np.full_like(u, 0.8)),
                    axis=-1)
    lin = base * ramp
    return np.round(srgb_encode(lin) * 255.0).astype(np.uint8)


# ----------------------------------------------------------------------------- meshes

def icosphere(subdivisions):
    """Unit icosphere: (vertices (n,3) float64, faces (m,3) int) with outward CCW winding."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
             (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(v, dtype=np.float64) / np.linalg.norm(v) for v in verts]
    for _ in range(subdivisions):
        cache = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    return np.array(verts), np.array(faces, dtype=np.int64)


def check_outward(verts, faces):
    """Signed volume must be positive for outward counter-clockwise winding."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    assert vol > 0, f"mesh winding is inward (signed volume {vol})"


def blob_mesh():
    """Displaced icosphere: a lumpy, vaguely bunny-like closed blob, about unit size."""
    v, f = icosphere(3)
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    r = (1.0 + 0.18 * np.sin(3.0 * x + 0.5) * np.sin(2.0 * y + 1.0)
         + 0.12 * np.cos(4.0 * z - 0.3 * x) + 0.25 * np.clip(y, 0, 1) ** 3 * (x > 0))
    v = v * r[:, None] * np.array([1.0, 0.85, 0.9])
    return v, f


def pebble_mesh():
    v, f = icosphere(2)
    v = v * np.array([1.0, 0.55, 0.8])
    uv = np.stack([0.5 + np.arctan2(v[:, 0], -v[:, 2]) / (2 * np.pi),
                   np.arccos(np.clip(v[:, 1] / 0.55, -1, 1)) / np.pi], axis=1)
    return v, f, uv


def torus_mesh(major=0.7, minor=0.25, nu=24, nv=12):
    verts, uvs, faces = [], [], []
    for i in range(nu):
        a = 2 * np.pi * i / nu
        for j in range(nv):
            b = 2 * np.pi * j / nv
            r = major + minor * np.cos(b)
            verts.append((r * np.cos(a), minor * np.sin(b), r * np.sin(a)))
            uvs.append((i / nu, j / nv))
    for i in range(nu):
        for j in range(nv):
            p = i * nv + j
            q = ((i + 1) % nu) * nv + j
            pn = i * nv + (j + 1) % nv
            qn = ((i + 1) % nu) * nv + (j + 1) % nv
            faces += [(p, pn, qn), (p, qn, q)]
    v, f = np.array(verts), np.array(faces, dtype=np.int64)
    # Orient outward (the torus is closed, so the signed volume tells).
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    if np.einsum("ij,ij->i", a, np.cross(b, c)).sum() < 0:
        f = f[:, ::-1].copy()
    return v, f, np.array(uvs)


def write_ply_binary(path, verts, faces, normals):
    common.write_ply_binary(path, verts, faces, normals, "snee test asset written by scripts/make_assets.py")


def write_ply_ascii(path, verts, faces, uvs):
    lines = [
        "ply", "format ascii 1.0", "comment snee test asset written by scripts/make_assets.py",
        f"element vertex {len(verts)}",
        "property float x", "property float y", "property float z",
        "property float u", "property float v",
        f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header",
    ]
    for p, t in zip(verts, uvs):
        lines.append(f"{p[0]:.6f} {p[1]:.6f} {p[2]:.6f} {t[0]:.6f} {t[1]:.6f}")
    for a, b, c in faces:
        lines.append(f"3 {a} {b} {c}")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def write_cylinder_obj(path, segments=16, radius=0.5, height=1.0):
    """Closed cylinder with v/vt/vn faces: quads on the side, one polygon per cap."""
    out = ["# snee test asset written by scripts/make_assets.py",
           f"# closed {segments}-sided cylinder, radius {radius}, y in [0, {height}]",
           "o cylinder"]
    for y in (0.0, height):
        for i in range(segments):
            a = 2 * np.pi * i / segments
            out.append(f"v {radius * np.cos(a):.6f} {y:.6f} {radius * np.sin(a):.6f}")
    # Texture coordinates: side (segments+1 columns x 2 rows), then caps (disc mapping).
    for row in (0.0, 1.0):
        for i in range(segments + 1):
            out.append(f"vt {i / segments:.6f} {row:.6f}")
    for i in range(segments):
        a = 2 * np.pi * i / segments
        out.append(f"vt {0.5 + 0.5 * np.cos(a):.6f} {0.5 + 0.5 * np.sin(a):.6f}")
    # Normals: side (one per segment), bottom, top.
    for i in range(segments):
        a = 2 * np.pi * i / segments
        out.append(f"vn {np.cos(a):.6f} 0 {np.sin(a):.6f}")
    out += ["vn 0 -1 0", "vn 0 1 0"]
    s = segments
    for i in range(s):
        j = (i + 1) % s
        b0, b1, t0, t1 = 1 + i, 1 + j, 1 + s + i, 1 + s + j
        uvb0, uvb1 = 1 + i, 2 + i
        uvt0, uvt1 = 1 + (s + 1) + i, 2 + (s + 1) + i
        n0, n1 = 1 + i, 1 + j
        # Outward winding: seen from outside, counter-clockwise (b0 -> t0 -> t1 -> b1).
        out.append(f"f {b0}/{uvb0}/{n0} {t0}/{uvt0}/{n0} {t1}/{uvt1}/{n1} {b1}/{uvb1}/{n1}")
    cap_uv0 = 1 + 2 * (s + 1)
    nb, nt = s + 1, s + 2
    # Bottom cap, seen from below (normal -y): counter-clockwise = increasing angle.
    out.append("f " + " ".join(f"{1 + i}/{cap_uv0 + i}/{nb}" for i in range(s)))
    # Top cap, seen from above (normal +y): decreasing angle.
    out.append("f " + " ".join(f"{1 + s + i}/{cap_uv0 + i}/{nt}" for i in reversed(range(s))))
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")


def serialized_mesh_block(name, verts, faces, normals=None, uvs=None):
    """One mesh of a Mitsuba .serialized file (version 4): uncompressed header + zlib stream."""
    flags = 0x1000  # single precision
    if normals is not None:
        flags |= 0x0001
    if uvs is not None:
        flags |= 0x0002
    body = struct.pack("<I", flags) + name.encode("utf-8") + b"\0"
    body += struct.pack("<QQ", len(verts), len(faces))
    body += np.asarray(verts, dtype="<f4").tobytes()
    if normals is not None:
        body += np.asarray(normals, dtype="<f4").tobytes()
    if uvs is not None:
        body += np.asarray(uvs, dtype="<f4").tobytes()
    body += np.asarray(faces, dtype="<u4").tobytes()
    return struct.pack("<HH", 0x041C, 0x0004) + zlib.compress(body, 9)


def write_serialized(path, meshes):
    blocks = [serialized_mesh_block(**m) for m in meshes]
    offsets, pos = [], 0
    for b in blocks:
        offsets.append(pos)
        pos += len(b)
    with open(path, "wb") as fh:
        for b in blocks:
            fh.write(b)
        fh.write(struct.pack(f"<{len(offsets)}Q", *offsets))
        fh.write(struct.pack("<I", len(blocks)))


# ----------------------------------------------------------------------------- main

def verify_with_mitsuba(out, expected):
    mi, _ = common.setup_mitsuba("scalar_rgb")
    for fname, plugin, extra, nv, nf in expected:
        d = {"type": plugin, "filename": os.path.join(out, "meshes", fname), **extra}
        shape = mi.load_dict(d)
        got = (shape.vertex_count(), shape.face_count())
        ok = got == (nv, nf)
        print(f"  mitsuba {plugin:10s} {fname:24s} {extra!s:20s} vertices={got[0]:5d} "
              f"faces={got[1]:5d} {'ok' if ok else f'EXPECTED {nv}, {nf}'}")
        if not ok:
            sys.exit(1)
    bmp = mi.Bitmap(os.path.join(out, "textures", "sky.exr"))
    print(f"  mitsuba bitmap sky.exr: {bmp}".replace("\n", " ")[:160])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "scenes"),
                    help="scenes folder to write textures/ and meshes/ into (default: scenes/)")
    args = ap.parse_args()
    out = os.path.normpath(args.out)
    os.makedirs(os.path.join(out, "textures"), exist_ok=True)
    os.makedirs(os.path.join(out, "meshes"), exist_ok=True)

    mi, _ = common.setup_mitsuba("scalar_rgb")

    sky = make_sky()
    sky_path = os.path.join(out, "textures", "sky.exr")
    mi.Bitmap(sky, pixel_format=mi.Bitmap.PixelFormat.RGB).write(sky_path)
    print(f"wrote {sky_path}  (256x128 float32 RGB, max {sky.max():.1f}, "
          f"mean {sky.mean():.3f})")

    checker = make_checker()
    checker_path = os.path.join(out, "textures", "checker.png")
    bmp = mi.Bitmap(checker, pixel_format=mi.Bitmap.PixelFormat.RGB)
    bmp.set_srgb_gamma(True)
    bmp.write(checker_path)
    print(f"wrote {checker_path}  (64x64 8-bit sRGB)")

    bv, bf = blob_mesh()
    check_outward(bv, bf)
    blob_path = os.path.join(out, "meshes", "blob.ply")
    write_ply_binary(blob_path, bv, bf, common.vertex_normals(bv, bf))
    print(f"wrote {blob_path}  ({len(bv)} vertices, {len(bf)} triangles, binary, normals)")

    pv, pf, puv = pebble_mesh()
    check_outward(pv, pf)
    pebble_path = os.path.join(out, "meshes", "pebble.ply")
    write_ply_ascii(pebble_path, pv, pf, puv)
    print(f"wrote {pebble_path}  ({len(pv)} vertices, {len(pf)} triangles, ascii, uv)")

    obj_path = os.path.join(out, "meshes", "cylinder.obj")
    write_cylinder_obj(obj_path)
    print(f"wrote {obj_path}  (16-sided closed cylinder, v/vt/vn, quads + 16-gon caps)")

    rv, rf = icosphere(2)
    rv = rv * (1.0 + 0.1 * np.sin(5 * rv[:, 0]) * np.cos(3 * rv[:, 2]))[:, None] * 0.5
    check_outward(rv, rf)
    tv, tf, tuv = torus_mesh()
    check_outward(tv, tf)
    ser_path = os.path.join(out, "meshes", "two_meshes.serialized")
    write_serialized(ser_path, [
        dict(name="rock", verts=rv, faces=rf, normals=common.vertex_normals(rv, rf)),
        dict(name="torus", verts=tv, faces=tf, uvs=tuv),
    ])
    print(f"wrote {ser_path}  (0: rock {len(rv)} v / {len(rf)} f with normals; "
          f"1: torus {len(tv)} v / {len(tf)} f with uvs)")

    s = 16  # cylinder segments
    verify_with_mitsuba(out, [
        ("blob.ply", "ply", {}, len(bv), len(bf)),
        ("pebble.ply", "ply", {}, len(pv), len(pf)),
        ("two_meshes.serialized", "serialized", {"shape_index": 0}, len(rv), len(rf)),
        ("two_meshes.serialized", "serialized", {"shape_index": 1}, len(tv), len(tf)),
    ])
    obj = mi.load_dict({"type": "obj", "filename": obj_path})
    print(f"  mitsuba obj        cylinder.obj             vertices={obj.vertex_count():5d} "
          f"faces={obj.face_count():5d} (expected faces {2 * s + 2 * (s - 2)})")
    if obj.face_count() != 2 * s + 2 * (s - 2):
        sys.exit(1)
    for f in sorted(os.listdir(os.path.join(out, "meshes"))) + ["../textures/sky.exr",
                                                               "../textures/checker.png"]:
        p = os.path.normpath(os.path.join(out, "meshes", f))
        print(f"  {os.path.relpath(p)}: {os.path.getsize(p)} bytes")


if __name__ == "__main__":
    main()
