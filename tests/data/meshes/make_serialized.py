#!/usr/bin/env python3
"""Write the small Mitsuba `.serialized` test files in this folder (an independent writer for
tests/meshes/formats.rs), following the format of Mitsuba 3.9 `src/shapes/serialized.cpp`.

    python3 make_serialized.py            # writes two_meshes_v4.serialized, two_meshes_v3.serialized
    python3 make_serialized.py --check    # also loads them with Mitsuba and prints what it read
"""
import struct, sys, zlib, os

HAS_NORMALS, HAS_TEXCOORDS, HAS_COLORS, FACE_NORMALS = 0x1, 0x2, 0x8, 0x10
SINGLE, DOUBLE = 0x1000, 0x2000


def mesh_stream(version, name, positions, faces, normals=None, uvs=None, colors=None, double=False, extra_flags=0):
    flags = (DOUBLE if double else SINGLE) | extra_flags
    if normals: flags |= HAS_NORMALS
    if uvs: flags |= HAS_TEXCOORDS
    if colors: flags |= HAS_COLORS
    fmt = '<d' if double else '<f'
    body = struct.pack('<I', flags)
    if version == 4:
        body += name.encode() + b'\0'
    body += struct.pack('<QQ', len(positions), len(faces))
    for arr in (positions, normals, uvs, colors):
        if arr:
            body += b''.join(struct.pack(fmt, c) for v in arr for c in v)
    body += b''.join(struct.pack('<I', i) for f in faces for i in f)
    return struct.pack('<HH', 0x041C, version) + zlib.compress(body)


def write(path, version, meshes):
    data, offsets = b'', []
    for m in meshes:
        offsets.append(len(data))
        data += mesh_stream(version, **m)
    ofmt = '<Q' if version == 4 else '<I'
    data += b''.join(struct.pack(ofmt, o) for o in offsets) + struct.pack('<I', len(meshes))
    open(path, 'wb').write(data)


MESHES = [
    dict(name='quad', positions=[(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], faces=[(0, 1, 2), (0, 2, 3)],
         normals=[(0, 0, 2), (0, 0, 1), (0, 0.6, 0.8), (0, 0, 1)], uvs=[(0, 0), (1, 0), (1, 1), (0.25, 0.75)]),
    dict(name='tri_double', positions=[(0.1, 0.2, 0.3), (1.7, -2.5, 1e-3), (3.14159265358979, 2.0, -1.0)],
         faces=[(2, 1, 0)], colors=[(1, 0, 0), (0, 1, 0), (0, 0, 1)], double=True, extra_flags=FACE_NORMALS),
]

if __name__ == '__main__':
    here = os.path.dirname(os.path.abspath(__file__))
    write(os.path.join(here, 'two_meshes_v4.serialized'), 4, MESHES)
    write(os.path.join(here, 'two_meshes_v3.serialized'), 3, MESHES)
    if '--check' in sys.argv:
        import mitsuba as mi
        mi.set_variant('scalar_rgb')
        for f in ('two_meshes_v4.serialized', 'two_meshes_v3.serialized'):
            for idx in (0, 1):
                m = mi.load_dict({'type': 'serialized', 'filename': os.path.join(here, f), 'shape_index': idx})
                print(f, idx, 'V', m.vertex_count(), 'F', m.face_count())
                print('  pos', [float(x) for x in m.vertex_positions_buffer()])
                print('  faces', [int(x) for x in m.faces_buffer()])
                if m.has_vertex_texcoords():
                    print('  uv', [float(x) for x in m.vertex_texcoords_buffer()])
                print('  normals', [float(x) for x in m.vertex_normals_buffer()])
            try:
                mi.load_dict({'type': 'serialized', 'filename': os.path.join(here, f), 'shape_index': 2})
                print(f, 'index 2: loaded (!)')
            except Exception as e:
                print(f, 'index 2:', str(e)[-120:])
