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
