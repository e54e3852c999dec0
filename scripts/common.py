"""Shared helpers for the asset scripts (make_assets.py, make_figure_assets.py): Mitsuba's
lat-long envmap directions, a procedural sun-and-sky, vertex normals and a binary PLY writer.

Import it from a script in this folder with `import common` (the scripts run as
`python3 scripts/NAME.py`, which puts scripts/ on the import path)."""

import math

import numpy as np


def envmap_direction(theta, phi):
    """Direction for polar angle theta (from +Y) and azimuth phi = 2*pi*u (Mitsuba envmap)."""
    st = np.sin(theta)
    return np.stack([st * np.sin(phi), np.cos(theta), -st * np.cos(phi)], axis=-1)


def sun_direction(elevation_deg, azimuth_deg):
    """Unit direction to the sun at `elevation_deg` above the horizon, `azimuth_deg` = 360*u."""
    return envmap_direction(np.float64(math.radians(90.0 - elevation_deg)), np.float64(math.radians(azimuth_deg)))


def lat_long_sky(sun, sun_radius_deg, sun_radiance, zenith, horizon, glow, glow_sharpness, glow_color, ground,
                 width=256, height=128, supersample=4):
    """Lat-long sky, shape (height, width, 3), float32, Mitsuba's lat-long layout: above the horizon
    `horizon` to `zenith` blue by sqrt(height), a glow `glow * exp(glow_sharpness (cos - 1))` around
    the sun, the sun disc (`sun_radiance`), below the horizon `ground`, darker straight down. Each
    texel is supersampled over its bilinear footprint, so the sun disc has soft, stable edges."""
    cos_sun_radius = math.cos(math.radians(sun_radius_deg))
    img = np.zeros((height, width, 3))
    offs = (np.arange(supersample) + 0.5) / supersample - 0.5
    for oy in offs:
        for ox in offs:
            j = np.clip(np.arange(height)[:, None] + oy, 0, height - 1)
            i = np.arange(width)[None, :] + ox
            theta = j / (height - 1) * np.pi
            phi = (i + 0.5) / width * 2 * np.pi
            theta, phi = np.broadcast_arrays(theta, phi)
            d = envmap_direction(theta, phi)
            y = d[..., 1]
            cos_to_sun = d @ sun
            h = np.clip(y, 0.0, 1.0)[..., None]
            sky = np.array(horizon) + (np.array(zenith) - np.array(horizon)) * np.sqrt(h)
            sky = sky + glow * np.exp(glow_sharpness * (cos_to_sun - 1.0))[..., None] * np.array(glow_color)
            g = np.clip(-y, 0.0, 1.0)[..., None]
            ground_col = np.array(ground) * (1.0 - 0.5 * g)
            col = np.where((y >= 0.0)[..., None], sky, ground_col)
            col = np.where((cos_to_sun >= cos_sun_radius)[..., None], sun_radiance, col)
            img += col
    img /= supersample * supersample
    # Round to values a half float can hold (stored as float32): the zeroed low mantissa bits
    # let the lossless PIZ compressor keep the file small.
    return img.astype(np.float16).astype(np.float32)


def vertex_normals(verts, faces):
    """Area-weighted vertex normals of a triangle mesh."""
    fn = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    n = np.zeros_like(verts)
    for k in range(3):
        np.add.at(n, faces[:, k], fn)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def write_ply_binary(path, verts, faces, normals, comment):
    """Binary little-endian PLY with float positions and normals and uchar/int triangle lists."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment {comment}\n"
        f"element vertex {len(verts)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    vdata = np.hstack([verts, normals]).astype("<f4")
    fdata = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    fdata["n"] = 3
    fdata["i"] = faces
    with open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(vdata.tobytes())
        fh.write(fdata.tobytes())


# ============================================================================= study helpers
# Shared by scripts/reproduce_figures.py and scripts/first_figure.py (and roughness_sweep.py's
# EXR reading): snee's EXR output, relative errors, Sidak thresholds, bootstrap intervals,
# Mitsuba 3 set-up, and feature detection of the snee binary.

import json  # noqa: E402
import os  # noqa: E402
import struct  # noqa: E402
import subprocess  # noqa: E402
import zlib  # noqa: E402

# libLLVM candidates for Mitsuba's llvm_ad_rgb (Debian's libllvm19 first).
MI_LLVM_CANDIDATES = ["/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-18.so", "/usr/lib/x86_64-linux-gnu/libLLVM-17.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-16.so", "/usr/lib/x86_64-linux-gnu/libLLVM-15.so",
                      "/usr/lib/x86_64-linux-gnu/libLLVM-14.so"]


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


def rgb_of(channels, prefix=""):
    """(H, W, 3) float64 image of channels PREFIX R, G, B (e.g. prefix "m2." or "single.")."""
    return np.stack([channels[prefix + c] for c in ("R", "G", "B")], axis=-1).astype(np.float64)


def rel_mse(a, ref, denom):
    """Mean over pixels and channels of (a - ref)^2 / denom (denom = d^2 + eps, see the study)."""
    return float(np.mean((a - ref) ** 2 / denom))


def sidak_z(alpha, m):
    """Two-sided |z| threshold at family-wise level alpha over m independent tests (Sidak)."""
    from scipy.stats import norm
    per_test = 1.0 - (1.0 - alpha) ** (1.0 / max(m, 1))
    return float(norm.isf(per_test / 2.0))


def bootstrap_ci(stat, n, b=2000, level=0.95, seed=1):
    """Percentile bootstrap over n units: stat(indices) -> float for resampled index arrays.
    Returns (lo, hi); non-finite replicates are dropped."""
    rng = np.random.default_rng(seed)
    vals = []
    for _ in range(b):
        v = stat(rng.integers(0, n, n))
        if np.isfinite(v):
            vals.append(v)
    if not vals:
        return float("nan"), float("nan")
    q = (1.0 - level) / 2.0
    return float(np.quantile(vals, q)), float(np.quantile(vals, 1.0 - q))


def mitsuba_setup(variant="auto"):
    """Import Mitsuba 3 and set a variant: llvm_ad_rgb if libLLVM loads (DRJIT_LIBLLVM_PATH or a
    standard path), else scalar_rgb. Returns (mi, dr, variant, notes); raises ImportError when the
    package is missing and RuntimeError when no variant works."""
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        for cand in MI_LLVM_CANDIDATES:
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                break
    import drjit as dr
    import mitsuba as mi
    notes = []
    for v in (["llvm_ad_rgb", "scalar_rgb"] if variant == "auto" else [variant]):
        try:
            mi.set_variant(v)
            if v.startswith("llvm"):  # set_variant succeeds without libLLVM; the first kernel fails
                x = mi.Float(1.0) + 1.0
                dr.eval(x)
            return mi, dr, v, notes
        except Exception as err:  # noqa: BLE001 - any failure to set up the JIT backend
            notes.append(f"{v} unavailable: {str(err).splitlines()[0] if str(err) else type(err).__name__}")
    raise RuntimeError("no usable Mitsuba variant: " + "; ".join(notes))


def snee_supports(snee, flag):
    """Whether `snee render --help` lists FLAG (e.g. "--classes"), so scripts work before and
    after a feature lands."""
    try:
        out = subprocess.run([snee, "render", "--help"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return False
    return flag in out


def write_json_atomic(path, obj):
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        json.dump(obj, fh, indent=1)
    os.replace(tmp, path)
