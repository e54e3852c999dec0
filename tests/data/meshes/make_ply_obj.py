#!/usr/bin/env python3
"""Write the PLY/OBJ files of this folder that tests/meshes/formats.rs compares against Mitsuba 3.9.

    python3 make_ply_obj.py            # (re)writes the files
    python3 make_ply_obj.py --check    # also prints what Mitsuba loads from them
"""
import os, struct, sys

HERE = os.path.dirname(os.path.abspath(__file__))
POS = [(0.1, 0.2, 0.3), (1.0, 0.0, -0.5), (1.25, 1.5, 0.0), (-0.3333333333, 1.0, 2.0), (0.5, 0.5, 0.7)]
NRM = [(0, 0, 1), (0, 2, 0), (1, 1, 0), (0.3, -0.4, 0.5), (0, 0, -1)]
UV = [(0.0, 0.0), (1.0, 0.1), (0.7, 0.9), (0.2, 0.6), (0.5, 0.5)]
TRI = [(0, 1, 2), (0, 2, 3), (3, 4, 0), (4, 1, 0)]


def binary_le():
    # double positions, float normals, s/t uvs, ignored colour; faces with an extra int and a
    # uint index list named vertex_index; then an extra scalar element Mitsuba skips.
    h = ("ply\nformat binary_little_endian 1.0\ncomment made by make_ply_obj.py\n"
         "element vertex %d\nproperty double x\nproperty double y\nproperty double z\n"
         "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nproperty float s\nproperty float t\n"
         "element face %d\nproperty int flags\nproperty list uchar uint vertex_index\n"
         "element extra 2\nproperty short a\nproperty double b\nend_header\n") % (len(POS), len(TRI))
    b = h.encode()
    for p, n, uv in zip(POS, NRM, UV):
        b += struct.pack('<3d3f3B2f', *p, *n, 10, 20, 30, *uv)
    for k, t in enumerate(TRI):
        b += struct.pack('<iB3I', 7 * k, 3, *t)
    b += struct.pack('<hd', 1, 2.0) + struct.pack('<hd', 3, 4.0)
    open(os.path.join(HERE, 'mitsuba_le.ply'), 'wb').write(b)


def binary_be():
    h = ("ply\nformat binary_big_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
         "property float z\nproperty float texture_u\nproperty float texture_v\nelement face %d\n"
         "property list int int vertex_indices\nend_header\n") % (len(POS), len(TRI))
    b = h.encode()
    for p, uv in zip(POS, UV):
        b += struct.pack('>5f', *p, *uv)
    for t in TRI:
        b += struct.pack('>4i', 3, *t)
    open(os.path.join(HERE, 'mitsuba_be.ply'), 'wb').write(b)


def ascii_ply():
    s = ("ply\r\nformat ascii 1.0\r\nelement vertex %d\r\nproperty float x\r\nproperty float y\r\n"
         "property float z\r\nproperty float nx\r\nproperty float ny\r\nproperty float nz\r\n"
         "property float u\r\nproperty float v\r\nelement face %d\r\n"
         "property list uchar int vertex_indices\r\nend_header\r\n") % (len(POS), len(TRI))
    for p, n, uv in zip(POS, NRM, UV):
        s += " ".join(repr(float(x)) for x in (*p, *n, *uv)) + "\r\n"
    for t in TRI:
        s += "3 %d %d %d\r\n" % t
    open(os.path.join(HERE, 'mitsuba_ascii.ply'), 'w', newline='').write(s)


OBJ = """# Mitsuba comparison: dedup of (v, vt, vn), quads and a pentagon, uv flip
mtllib none.mtl
o thing
v 0.1 0.2 0.3
v 1 0 -0.5
v 1.25 1.5 0
v -0.3333333333 1 2
v 0.5 0.5 0.7
v 9 9 9
vt 0 0
vt 1 0.1
vt 0.7 0.9
vt 0.2 0.6
vn 0 0 1
vn 0 2 0
vn 0.3 -0.4 0.5
g group
usemtl m
s 1
f 1/1/1 2/2/1 3/3/1 4/4/1
f 1/1/1 3/3/1 5/4/2
f 2/2/1 1/1/1 5/4/2 4/1/3 3/3/3
\tf\t5/4/2 4/4/1 1/1/3
"""


def obj():
    open(os.path.join(HERE, 'mitsuba_dedup.obj'), 'w').write(OBJ)


def check():
    import mitsuba as mi
    mi.set_variant('scalar_rgb')
    for f in ('mitsuba_le.ply', 'mitsuba_be.ply', 'mitsuba_ascii.ply', 'mitsuba_dedup.obj'):
        m = mi.load_dict({'type': f.split('.')[-1], 'filename': os.path.join(HERE, f)})
        print(f, 'V', m.vertex_count(), 'F', m.face_count())
        print('  pos', [float(x) for x in m.vertex_positions_buffer()])
        print('  faces', [int(x) for x in m.faces_buffer()])
        if m.has_vertex_texcoords():
            print('  uv', [float(x) for x in m.vertex_texcoords_buffer()])
        print('  normals', [float(x) for x in m.vertex_normals_buffer()])


if __name__ == '__main__':
    binary_le(); binary_be(); ascii_ply(); obj()
    if '--check' in sys.argv:
        check()
