#!/usr/bin/env python3
"""Expected shading frames for tests/plugins/shading_frame.rs, computed with Mitsuba 3.

For each shape (given as Mitsuba XML, rotated so the frame's orientation matters) a few rays are
traced with Mitsuba's `scalar_rgb` variant; for every hit the script stores the point, geometric
normal, shading frame (s, t, n) and uv. snee must reproduce them: the tangent `s` orients
anisotropic BSDFs (Mitsuba derives it from dp/du, see `interaction::shading_frame`).

Writes tests/data/shading_frames.json.
Usage: python3 scripts/shading_frame_expected.py   (needs `pip install mitsuba`, tested with 3.9.1)
"""
import argparse
import json
import math
import os

import mitsuba as mi

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
ROT = '<rotate x="1" angle="-55"/><rotate y="1" angle="35"/><rotate z="1" angle="20"/>'

CASES = [
    ("sphere", f'<shape type="sphere"><point name="center" x="0.1" y="0.2" z="0.3"/><float name="radius" value="0.5"/>'
               f'<transform name="to_world">{ROT}<translate y="0.5"/></transform></shape>'),
    ("sphere_flipped", f'<shape type="sphere"><boolean name="flip_normals" value="true"/>'
                       f'<transform name="to_world"><scale value="0.7"/>{ROT}</transform></shape>'),
    ("disk", f'<shape type="disk"><transform name="to_world"><scale value="0.8"/>{ROT}<translate z="0.2"/></transform></shape>'),
    ("disk_flipped", f'<shape type="disk"><boolean name="flip_normals" value="true"/>'
                     f'<transform name="to_world">{ROT}</transform></shape>'),
    ("rectangle", f'<shape type="rectangle"><transform name="to_world"><scale x="0.6" y="1.3"/>{ROT}</transform></shape>'),
    ("rectangle_flipped", f'<shape type="rectangle"><boolean name="flip_normals" value="true"/>'
                          f'<transform name="to_world"><scale x="0.6" y="1.3"/>{ROT}</transform></shape>'),
    ("cube", f'<shape type="cube"><transform name="to_world"><scale value="0.5"/>{ROT}</transform></shape>'),
    ("ply_uv_normals", f'<shape type="ply"><string name="filename" value="meshes/pebble.ply"/>'
                       f'<transform name="to_world">{ROT}</transform></shape>'),
    ("ply_uv_face_normals_flipped", f'<shape type="ply"><string name="filename" value="meshes/pebble.ply"/>'
                                    f'<boolean name="face_normals" value="true"/><boolean name="flip_normals" value="true"/>'
                                    f'<transform name="to_world">{ROT}</transform></shape>'),
    ("ply_normals_no_uv", f'<shape type="ply"><string name="filename" value="meshes/blob.ply"/>'
                          f'<transform name="to_world"><scale value="0.8"/>{ROT}</transform></shape>'),
    ("ply_face_normals_no_uv_flipped", f'<shape type="ply"><string name="filename" value="meshes/blob.ply"/>'
                                       f'<boolean name="face_normals" value="true"/><boolean name="flip_normals" value="true"/>'
                                       f'<transform name="to_world"><scale value="0.8"/>{ROT}</transform></shape>'),
]


def rays():
    """Rays from 12 directions around the origin towards points near it (deterministic)."""
    out = []
    for k in range(12):
        z = 1 - 2 * (k + 0.5) / 12
        phi = k * 2.399963
        r = math.sqrt(1 - z * z)
        d = [r * math.cos(phi), r * math.sin(phi), z]
        target = [0.13 * math.sin(3 * k + 1), 0.5 * (k % 2) + 0.11 * math.cos(5 * k), 0.12 * math.sin(7 * k + 2)]
        o = [target[i] + 6 * d[i] for i in range(3)]
        out.append((o, [-x for x in d]))
    return out


def main():
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    mi.set_variant("scalar_rgb")
    mi.file_resolver().prepend(os.path.join(ROOT, "scenes"))
    v = lambda x: [float(x[0]), float(x[1]), float(x[2])]
    cases = []
    for name, xml in CASES:
        scene = mi.load_string(f'<scene version="3.0.0">{xml}</scene>')
        hits = []
        for o, d in rays():
            si = scene.ray_intersect(mi.Ray3f(o, d))
            if not si.is_valid():
                continue
            f = si.sh_frame
            hits.append({"o": o, "d": d, "t": float(si.t), "p": v(si.p), "n": v(si.n), "s": v(f.s), "tt": v(f.t),
                         "sh_n": v(f.n), "uv": [float(si.uv[0]), float(si.uv[1])]})
        assert len(hits) >= 6, (name, len(hits))
        cases.append({"name": name, "xml": xml, "hits": hits})
    path = os.path.join(ROOT, "tests", "data", "shading_frames.json")
    with open(path, "w") as fh:
        json.dump({"generator": "scripts/shading_frame_expected.py", "mitsuba": mi.__version__, "cases": cases}, fh,
                  indent=1)
    print(f"wrote {path}: {sum(len(c['hits']) for c in cases)} hits in {len(cases)} cases")


if __name__ == "__main__":
    main()
