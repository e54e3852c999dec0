"""The one module the scripts in this folder share: paths, Mitsuba set-up, Mitsuba renders with
per-pixel moments, EXR reading, statistics (relMSE, Šidák), the JSON tables of Mitsuba values that
the tests read, and the mesh/sky writers of the asset scripts. Scripts import this module, never
each other.

Import it from a script in this folder with `import common` (the scripts run as
`python3 scripts/NAME.py`, which puts scripts/ on the import path). The sections below are
independent; each starts with a `# ====` banner."""

import json
import math
import os
import struct
import subprocess
import sys
import time
import zlib

import numpy as np


# ==== Paths ====

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
TEST_DATA = os.path.join(ROOT, "tests", "data")


# ==== Mitsuba set-up ====

LLVM_CANDIDATES = ["/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so",
                   "/usr/lib/x86_64-linux-gnu/libLLVM-18.so", "/usr/lib/x86_64-linux-gnu/libLLVM-17.so",
                   "/usr/lib/x86_64-linux-gnu/libLLVM-16.so", "/usr/lib/x86_64-linux-gnu/libLLVM-15.so",
                   "/usr/lib/x86_64-linux-gnu/libLLVM-14.so"]


def point_drjit_at_llvm():
    """Set DRJIT_LIBLLVM_PATH to the first libLLVM found, unless it is set already."""
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        for cand in LLVM_CANDIDATES:
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                break


def setup_mitsuba(variant="scalar_rgb"):
    """Import mitsuba and set `variant`; returns (mitsuba module, variant set). For an llvm variant
    DRJIT_LIBLLVM_PATH is pointed at the first libLLVM found (unless set); when the variant cannot
    be set (no LLVM) it falls back to scalar_rgb with a warning."""
    if "llvm" in variant:
        point_drjit_at_llvm()
    import mitsuba as mi
    try:
        mi.set_variant(variant)
    except Exception as err:  # noqa: BLE001 - any failure to set up the JIT backend
        if variant == "scalar_rgb":
            raise
        print(f"warning: variant {variant} unavailable ({err}); falling back to scalar_rgb", file=sys.stderr)
        variant = "scalar_rgb"
        mi.set_variant(variant)
    return mi, variant


# ==== Mitsuba renders with per-pixel moments (references, self-test) ====

MAX_SAMPLES_PER_PASS = 1 << 22


def register_rgb_moment(mi):
    """Register `rgb_moment`: Mitsuba's `moment` integrator in RGB. It calls the nested integrator's
    sample() once and returns its RGB value and the squares (with `cross`, also the cross products)
    as AOVs mean.R/G/B, m2.R/G/B (+ m2.RG/GB/RB); the image channels are the nested integrator's,
    from the same samples. (Mitsuba's own `moment` stores X, Y, Z and their squares: without the
    cross moments they do not give the per-channel RGB variances.)"""

    class RGBMomentIntegrator(mi.SamplingIntegrator):
        def __init__(self, props):
            super().__init__(props)
            self.nested = props["nested"]
            self.cross = props.get("cross", False)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            spec, valid, _ = self.nested.sample(scene, sampler, ray, medium, active)
            c = mi.Color3f(spec)
            aovs = [c.x, c.y, c.z, c.x * c.x, c.y * c.y, c.z * c.z]
            if self.cross:
                aovs += [c.x * c.y, c.y * c.z, c.x * c.z]
            return spec, valid, aovs

        def aov_names(self):
            names = ["mean.R", "mean.G", "mean.B", "m2.R", "m2.G", "m2.B"]
            return names + (["m2.RG", "m2.GB", "m2.RB"] if self.cross else [])

        def to_string(self):
            return f"RGBMomentIntegrator[nested={self.nested}]"

    mi.register_integrator("rgb_moment", lambda props: RGBMomentIntegrator(props))


def raw_channels(film):
    """The film's raw (unnormalised) storage as {channel name: (H, W) float64 array}."""
    bmp = film.bitmap(raw=True)
    arr = np.array(bmp, copy=True).astype(np.float64)
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    return {n: arr[..., i] for i, n in enumerate(names)}


def render_sums(scene, integrator, spp, seed):
    """Render `spp` samples per pixel in passes of at most MAX_SAMPLES_PER_PASS samples (seeds
    seed * 10007 + k); return the summed raw channels, (wall, CPU) seconds and the pass count."""
    sensor = scene.sensors()[0]
    w, h = sensor.film().crop_size()
    pass_spp = max(1, min(spp, MAX_SAMPLES_PER_PASS // (w * h)))
    sums, done, k = None, 0, 0
    t0, c0 = time.time(), time.process_time()
    while done < spp:
        n = min(pass_spp, spp - done)
        integrator.render(scene, sensor, seed=seed * 10007 + k, spp=n, develop=False)
        ch = raw_channels(sensor.film())
        sums = ch if sums is None else {c: sums[c] + ch[c] for c in sums}
        done += n
        k += 1
    return sums, (time.time() - t0, time.process_time() - c0), k


def develop(sums, names):
    """Channels `names` of summed raw channels divided by the summed filter weight W, (H, W, len)."""
    wsum = np.maximum(sums["W"], 1e-30)
    return np.stack([sums[n] / wsum for n in names], axis=-1)


def mean_and_variance(sums):
    """Pixel mean and per-sample variance (m2 - mean^2) of an `rgb_moment` render."""
    mean = develop(sums, ["mean.R", "mean.G", "mean.B"])
    m2 = develop(sums, ["m2.R", "m2.G", "m2.B"])
    return mean, np.maximum(m2 - mean * mean, 0.0)


def filter_1d(mi, scene):
    """The film's reconstruction filter, its radius and a vectorised w(x)."""
    rf = scene.sensors()[0].film().rfilter()
    radius = rf.radius()

    def w(x):
        flat = np.asarray(x, dtype=np.float64).ravel()
        if mi.variant().startswith("scalar"):
            vals = np.array([rf.eval(float(v)) for v in flat])
        else:
            vals = np.array(rf.eval(mi.Float(flat)))
        return vals.reshape(np.shape(x))

    return rf, radius, w


def pixel_variance_factor(mi, scene, samples_per_px=64):
    """Per-pixel (H, W) map of sum(w^2) / (sum w)^2 * spp for uniform sample density 1/px^2.

    Samples are drawn only inside the image, so border pixels see part of their filter support.
    """
    rf, radius, w = filter_1d(mi, scene)
    width, height = scene.sensors()[0].film().crop_size()

    def factor_1d(n):
        xs = (np.arange(n * samples_per_px) + 0.5) / samples_per_px   # quadrature over [0, n)
        centres = np.arange(n) + 0.5
        wx = w(xs[None, :] - centres[:, None])
        a = wx.sum(axis=1) / samples_per_px
        b = (wx * wx).sum(axis=1) / samples_per_px
        return b / (a * a)

    return factor_1d(height)[:, None] * factor_1d(width)[None, :]


# ==== EXR I/O ====

def exr_header(buf, path="EXR"):
    """Parse the header of an OpenEXR file held in `buf`: returns ({attribute: raw bytes}, offset
    just past the header)."""
    magic, version = struct.unpack_from("<ii", buf, 0)
    if magic != 20000630:
        raise ValueError(f"{path}: not an OpenEXR file")
    pos, attrs = 8, {}
    while buf[pos] != 0:  # header: name\0 type\0 size value, until an empty name
        end = buf.index(b"\0", pos)
        end2 = buf.index(b"\0", end + 1)
        (size,) = struct.unpack_from("<i", buf, end2 + 1)
        attrs[buf[pos:end].decode()] = buf[end2 + 5:end2 + 5 + size]
        pos = end2 + 5 + size
    return attrs, pos + 1


def exr_channels(path):
    """[(channel name, pixel type)] of an OpenEXR file (pixel type 0 uint, 1 half, 2 float)."""
    with open(path, "rb") as fh:
        attrs, _ = exr_header(fh.read(1 << 16), path)
    if "channels" not in attrs:
        raise ValueError(f"{path}: no channels attribute")
    return [(name, ptype) for name, ptype, _ in channel_list(attrs["channels"])]


def channel_list(chlist):
    """[(name, pixel type, (x sampling, y sampling))] from a raw `channels` attribute."""
    chans, cpos = [], 0
    while chlist[cpos] != 0:  # name\0 pixel_type pLinear reserved[3] xSampling ySampling
        end = chlist.index(b"\0", cpos)
        (ptype,) = struct.unpack_from("<i", chlist, end + 1)
        chans.append((chlist[cpos:end].decode(), ptype, struct.unpack_from("<ii", chlist, end + 9)))
        cpos = end + 17
    return chans


def read_exr(path):
    """Minimal OpenEXR reader (numpy + zlib) for snee's output, so that reading it needs no
    `mitsuba` package: single part, scan lines or one-level tiles, compression none / ZIPS / ZIP,
    half or float channels. Returns {channel name: (H, W) float32 array}. (Mitsuba writes PIZ:
    read its files with `bitmap_channels`.)"""
    with open(path, "rb") as fh:
        buf = fh.read()
    (version,) = struct.unpack_from("<i", buf, 4)
    if version & 0x1800:
        raise ValueError(f"{path}: not a single-part, flat OpenEXR file")
    tiled = bool(version & 0x200)
    attrs, pos = exr_header(buf, path)
    channels = []
    for name, ptype, sampling in channel_list(attrs["channels"]):
        if sampling != (1, 1) or ptype not in (1, 2):
            raise ValueError(f"{path}: subsampled or integer channels are not supported")
        channels.append((name, np.dtype(np.float16 if ptype == 1 else np.float32)))
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


def bitmap_channels(mi, path):
    """Any image Mitsuba reads (EXR with any compression, PNG, ...) as {channel name: (H, W)
    float64 array}."""
    bmp = mi.Bitmap(path)
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    arr = np.array(bmp, dtype=np.float64).reshape(bmp.height(), bmp.width(), -1)
    return {n: arr[..., i] for i, n in enumerate(names)}


def rgb(channels, prefix=""):
    """Channels R, G, B (with `prefix`, e.g. "var.") of a channel dictionary as an (H, W, 3) array."""
    return np.stack([channels[prefix + c] for c in "RGB"], axis=-1)


# ==== Statistics ====

def sidak(alpha, n):
    """Per-test level for a family-wise level `alpha` over `n` independent tests (Šidák)."""
    return 1.0 - (1.0 - alpha) ** (1.0 / max(n, 1))


# ==== Mitsuba values for the tests (JSON files in tests/data/) ====

def rounded(x, digits):
    """`x` rounded to `digits` significant digits: what the tests read (9 or more digits round-trip
    an f32 exactly)."""
    return float(f"{float(x):.{digits - 1}e}")


def write_test_json(name, data, indent=None):
    """Write `data` to tests/data/NAME; returns the path."""
    path = os.path.join(TEST_DATA, name)
    with open(path, "w") as fh:
        if indent is None:
            json.dump(data, fh, separators=(",", ":"))
        else:
            json.dump(data, fh, indent=indent)
    return path


# ==== Meshes and skies (make_assets.py, make_figure_assets.py) ====

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


def rgb_of(channels, prefix=""):
    """rgb() as float64 (e.g. prefix "m2." or "single.")."""
    return rgb(channels, prefix).astype(np.float64)


def rel_mse(a, ref, denom):
    """Mean over pixels and channels of (a - ref)^2 / denom (denom = d^2 + eps, see the study)."""
    return float(np.mean((a - ref) ** 2 / denom))


def sidak_z(alpha, m):
    """Two-sided |z| threshold at family-wise level alpha over m independent tests (Sidak)."""
    from scipy.stats import norm
    return float(norm.isf(sidak(alpha, m) / 2.0))


def bootstrap_ci(stat, n, b=2000, level=0.95, seed=1, method="percentile", theta=None):
    """Bootstrap interval over n units: stat(indices) -> float for resampled index arrays.
    method "percentile": the replicates' quantiles. method "bca": bias-corrected and accelerated
    (Efron 1987; Efron & Tibshirani 1993, Eq. 14.9-14.15): the quantile levels are moved by the
    bias z0 = Phi^-1(share of replicates below theta, ties counted half) and the acceleration a =
    sum d^3 / (6 (sum d^2)^1.5) of the jackknife (d_i = mean of the leave-one-out values - the
    value without unit i). theta: the point estimate the replicates scatter around (default
    stat(range(n))). Returns (lo, hi); non-finite replicates are dropped; BCa falls back to the
    percentile interval where it is undefined (n < 3, a non-finite theta or jackknife value)."""
    rng = np.random.default_rng(seed)
    vals = []
    for _ in range(b):
        v = stat(rng.integers(0, n, n))
        if np.isfinite(v):
            vals.append(v)
    if not vals:
        return float("nan"), float("nan")
    q = (1.0 - level) / 2.0
    probs = np.array([q, 1.0 - q])
    if method == "bca" and n >= 3:
        from scipy.stats import norm
        vals = np.array(vals)
        theta = stat(np.arange(n)) if theta is None else theta
        jack = np.array([stat(np.delete(np.arange(n), i)) for i in range(n)])
        if np.isfinite(theta) and np.all(np.isfinite(jack)):
            below = (np.count_nonzero(vals < theta) + 0.5 * np.count_nonzero(vals == theta)) / vals.size
            z0 = norm.ppf(min(max(below, 1.0 / (vals.size + 1)), vals.size / (vals.size + 1.0)))
            d = jack.mean() - jack
            ss = float(np.sum(d * d))
            a = float(np.sum(d ** 3)) / (6.0 * ss ** 1.5) if ss > 0 else 0.0
            w = z0 + norm.ppf(probs)
            den = 1.0 - a * w
            # 1 - a w <= 0: the adjusted level runs off the end of the distribution (its extreme)
            probs = np.where(den > 0, norm.cdf(z0 + w / np.where(den > 0, den, 1.0)), (w > 0).astype(float))
    else:
        vals = np.array(vals)
    return float(np.quantile(vals, probs[0])), float(np.quantile(vals, probs[1]))


def mitsuba_setup(variant="auto"):
    """Import Mitsuba 3 and set a variant: llvm_ad_rgb if libLLVM loads (DRJIT_LIBLLVM_PATH or a
    standard path), else scalar_rgb. Returns (mi, dr, variant, notes); raises ImportError when the
    package is missing and RuntimeError when no variant works."""
    point_drjit_at_llvm()
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
