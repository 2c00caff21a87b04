#!/usr/bin/env python3
"""Writes the small broken mesh files the bad-scene suite refers to (run once; the outputs are
checked in). python3 make_meshes.py, from this directory."""
import struct
import zlib

QUAD = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]


def write(name, data):
    with open(name, "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data)


def obj(verts, faces):
    return "".join(f"v {x} {y} {z}\n" for x, y, z in verts) + "".join(
        "f " + " ".join(str(i) for i in f) + "\n" for f in faces)


# OBJ: a face refers to vertex 9 of 4 (1-based); a NaN coordinate; vertices only; not an OBJ.
write("bad_index.obj", obj(QUAD, [(1, 2, 3), (1, 3, 9)]))
write("nan_vertex.obj", obj([(0, 0, 0), (1, "nan", 0), (1, 1, 0)], [(1, 2, 3)]))
write("no_faces.obj", obj(QUAD, []))
write("garbage.obj", "v 0 0 0\nv 1 0 0\nv zero one two\nf 1 2 3\n")

HEAD = "ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n" \
       "property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n"


def ascii_ply(verts, faces, nv=None):
    h = HEAD.format(fmt="ascii", nv=len(verts) if nv is None else nv, nf=len(faces))
    return h + "".join(f"{x} {y} {z}\n" for x, y, z in verts) + "".join(
        f"{len(f)} " + " ".join(map(str, f)) + "\n" for f in faces)


write("bad_index.ply", ascii_ply(QUAD, [(0, 1, 2), (0, 2, 9)]))
# The header claims 8 vertices, the body has 4 (then the faces are read as vertices and the
# file ends early).
write("wrong_vertex_count.ply", ascii_ply(QUAD, [(0, 1, 2), (0, 2, 3)], nv=8))
write("nan_vertex.ply", ascii_ply([(0, 0, 0), (1, 0, "nan"), (1, 1, 0)], [(0, 1, 2)]))

# Binary little-endian PLY cut in the middle of the face list.
body = b"".join(struct.pack("<3f", *v) for v in QUAD)
body += b"".join(struct.pack("<B3i", 3, *f) for f in [(0, 1, 2), (0, 2, 3)])
whole = HEAD.format(fmt="binary_little_endian", nv=4, nf=2).encode() + body
write("truncated_binary.ply", whole[:-7])
# A binary PLY claiming 4·10⁹ vertices in a few bytes: must fail fast, without allocating.
write("huge_count.ply",
      HEAD.format(fmt="binary_little_endian", nv=4000000000, nf=1).encode() + body)


# Mitsuba .serialized (version 4, single precision, no normals).
def serialized_shape(verts, tris):
    raw = struct.pack("<I", 0x1000) + b"tri\0" + struct.pack("<QQ", len(verts), len(tris))
    raw += b"".join(struct.pack("<3f", *v) for v in verts)
    raw += b"".join(struct.pack("<3I", *t) for t in tris)
    return struct.pack("<HH", 0x041C, 4) + zlib.compress(raw)


def serialized_file(shapes):
    out, offsets = b"", []
    for s in shapes:
        offsets.append(len(out))
        out += s
    return out + b"".join(struct.pack("<Q", o) for o in offsets) + struct.pack("<I", len(shapes))


tri = serialized_file([serialized_shape(QUAD[:3], [(0, 1, 2)])])
write("triangle.serialized", tri)
bad = bytearray(tri)
bad[0:2] = b"\x1c\x05"
write("bad_header.serialized", bytes(bad))
# Cut inside the zlib stream, with the offset table and count re-appended so that the table is
# readable and the stream itself ends early.
cut = serialized_shape(QUAD[:3], [(0, 1, 2)])
cut = cut[: len(cut) // 2]
write("truncated.serialized", cut + struct.pack("<Q", 0) + struct.pack("<I", 1))
# Bytes flipped inside the zlib stream.
corrupt = bytearray(tri)
for i in range(8, 16):
    corrupt[i] ^= 0x5A
write("corrupt_zlib.serialized", bytes(corrupt))

# Round two: a negative PLY index, a 0 index in OBJ (indices are 1-based), and a .serialized
# shape whose header claims 2^40 vertices.
write("negative_index.ply", ascii_ply(QUAD, [(0, 1, 2), (0, 2, -1)]))
write("zero_index.obj", obj(QUAD, [(1, 2, 3), (0, 3, 4)]))
raw = struct.pack("<I", 0x1000) + b"tri\0" + struct.pack("<QQ", 1 << 40, 1)
raw += b"".join(struct.pack("<3f", *v) for v in QUAD[:3]) + struct.pack("<3I", 0, 1, 2)
write("lying_count.serialized",
      serialized_file([struct.pack("<HH", 0x041C, 4) + zlib.compress(raw)]))
# An element with no properties and 1.8·10¹⁹ instances before a valid mesh: nothing to read, so
# it must not take 10¹⁹ steps either (the mesh then fails on its out-of-range face).
write("empty_element.ply",
      "ply\nformat ascii 1.0\nelement junk 18000000000000000000\n"
      + ascii_ply(QUAD, [(0, 1, 2), (0, 2, 5)]).split("\n", 2)[2])

# Mesh attributes: a quad with a vertex colour (8-bit) and a face weight; the same with a NaN
# face weight.
ATTR = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n" \
       "property float z\nproperty uchar r\nproperty uchar g\nproperty uchar b\n" \
       "element face 2\nproperty list uchar int vertex_indices\nproperty float weight_0\n" \
       "end_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n"
write("attributes.ply", ATTR + "3 0 1 2 0.5\n3 0 2 3 0.25\n")
write("nan_attribute.ply", ATTR + "3 0 1 2 0.5\n3 0 2 3 nan\n")
