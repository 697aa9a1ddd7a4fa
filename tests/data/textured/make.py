#!/usr/bin/env python3
"""Writes the textured test models of tests/data/textured (run once; the outputs are committed).

quad4.png   8x8 texture, four 4x4 quadrants: top-left red, top-right green, bottom-left blue,
            bottom-right white (sRGB codes 255/0, so linear 1/0).
box.glb     closed cube [-0.5,0.5]^3, glTF 2.0 binary, the PNG embedded in its buffer; each face
            shows the whole texture, its top edge towards +y (the top and bottom faces: towards -z).
box.obj     the same cube as OBJ + box.mtl (Kd 1 1 1, map_Kd quad4.png).
openbox.obj the cube without its top face (an open model), same material.
missing.obj a quad whose material's map_Kd names a file that does not exist.
corrupt.obj a quad whose map_Kd is corrupt.png: a PNG signature and a header cut short.
huge.obj    a quad whose map_Kd is huge.png: a valid header claiming 8192 x 8192 texels (4 times the limit).
blob.ply    a closed bumpy sphere of 320 triangles, like a coarse scan (no texture).
"""
import base64, json, math, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png_bytes(w, h, rows):
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def quad4():
    R, G, B, W = (255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)
    rows = []
    for y in range(8):
        row = []
        for x in range(8):
            row += (R if x < 4 else G) if y < 4 else (B if x < 4 else W)
        rows.append(row)
    return png_bytes(8, 8, rows)


# Faces: outward normal, the corner at the image's bottom-left, the direction of the image's u
# (right) and v (up), each spanning the full face.
FACES = [
    ((0, 0, 1), (-1, -1, 1), (1, 0, 0), (0, 1, 0)),    # +z front
    ((0, 0, -1), (1, -1, -1), (-1, 0, 0), (0, 1, 0)),  # -z back
    ((1, 0, 0), (1, -1, 1), (0, 0, -1), (0, 1, 0)),    # +x
    ((-1, 0, 0), (-1, -1, -1), (0, 0, 1), (0, 1, 0)),  # -x
    ((0, 1, 0), (-1, 1, 1), (1, 0, 0), (0, 0, -1)),    # +y top
    ((0, -1, 0), (-1, -1, -1), (1, 0, 0), (0, 0, 1)),  # -y bottom
]


def cube(skip_top=False):
    """Positions (half size 0.5), normals, uvs (v up) and triangles of the cube's faces."""
    P, N, T, I = [], [], [], []
    for n, c, eu, ev in FACES:
        if skip_top and n == (0, 1, 0):
            continue
        base = len(P)
        for (a, b) in ((0, 0), (1, 0), (1, 1), (0, 1)):
            P.append(tuple(0.5 * (c[k] + 2 * a * eu[k] + 2 * b * ev[k]) for k in range(3)))
            N.append(n)
            T.append((a, b))
        I += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return P, N, T, I


def write_obj(name, mtl, skip_top=False, quad_only=False):
    if quad_only:
        P, N, T, I = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 0, 1)] * 4, [(0, 0), (1, 0), (1, 1), (0, 1)], [(0, 1, 2), (0, 2, 3)]
    else:
        P, N, T, I = cube(skip_top)
    with open(os.path.join(HERE, name), "w") as f:
        f.write("# written by make.py\nmtllib %s\nusemtl tex\n" % mtl)
        for p in P:
            f.write("v %g %g %g\n" % p)
        for t in T:
            f.write("vt %g %g\n" % t)
        for n in N:
            f.write("vn %g %g %g\n" % n)
        for tri in I:
            f.write("f %s\n" % " ".join("%d/%d/%d" % (i + 1, i + 1, i + 1) for i in tri))


def write_mtl(name, tex):
    with open(os.path.join(HERE, name), "w") as f:
        f.write("# written by make.py\nnewmtl tex\nKd 1 1 1\nmap_Kd %s\n" % tex)


def write_glb(png):
    P, N, T, I = cube()
    # glTF's texture coordinates run down from the image's top-left corner.
    T = [(u, 1 - v) for u, v in T]
    pos = b"".join(struct.pack("<3f", *p) for p in P)
    nrm = b"".join(struct.pack("<3f", *n) for n in N)
    uv = b"".join(struct.pack("<2f", *t) for t in T)
    idx = b"".join(struct.pack("<3H", *t) for t in I)
    pad = lambda b: b + b"\0" * (-len(b) % 4)
    parts = [pos, nrm, uv, pad(idx), pad(png)]
    views, off = [], 0
    for i, p in enumerate(parts):
        v = {"buffer": 0, "byteOffset": off, "byteLength": len(p) if i < 3 else (len(idx) if i == 3 else len(png))}
        if i < 3:
            v["target"] = 34962
        elif i == 3:
            v["target"] = 34963
        views.append(v)
        off += len(p)
    binary = b"".join(parts)
    gltf = {
        "asset": {"version": "2.0", "generator": "fovea tests/data/textured/make.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "box"}],
        "meshes": [{"name": "box", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"name": "quadrants", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "baseColorTexture": {"index": 0},
                                                                   "metallicFactor": 0, "roughnessFactor": 1}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"bufferView": 4, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(P), "type": "VEC3", "min": [-0.5] * 3, "max": [0.5] * 3},
            {"bufferView": 1, "componentType": 5126, "count": len(N), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": len(T), "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3 * len(I), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    js = json.dumps(gltf, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    with open(os.path.join(HERE, "box.glb"), "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)


def write_blob():
    # An icosahedron subdivided twice, each vertex pushed in or out by a smooth bump.
    t = (1 + 5 ** 0.5) / 2
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    V = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in V]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
         (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(2):
        cache, NF = {}, []
        def mid(a, b):
            k = (min(a, b), max(a, b))
            if k not in cache:
                m = [(V[a][i] + V[b][i]) / 2 for i in range(3)]
                l = math.sqrt(sum(x * x for x in m))
                V.append(tuple(x / l for x in m))
                cache[k] = len(V) - 1
            return cache[k]
        for a, b, c in F:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            NF += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        F = NF
    # 0.3 m tall-ish: a scan in metres, stretched along z like an animal's body.
    P = []
    for x, y, z in V:
        r = 1 + 0.12 * math.sin(5 * x) * math.cos(4 * y) + 0.08 * math.sin(7 * z)
        P.append((0.1 * r * x, 0.1 * r * y, 0.18 * r * z))
    with open(os.path.join(HERE, "blob.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment written by make.py\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(P), len(F)))
        for p in P:
            f.write("%.5f %.5f %.5f\n" % p)
        for a, b, c in F:
            f.write("3 %d %d %d\n" % (a, b, c))


png = quad4()
open(os.path.join(HERE, "quad4.png"), "wb").write(png)
write_glb(png)
write_mtl("box.mtl", "quad4.png")
write_obj("box.obj", "box.mtl")
write_obj("openbox.obj", "box.mtl", skip_top=True)
for name, tex in (("missing", "no-such-texture.png"), ("corrupt", "corrupt.png"), ("huge", "huge.png")):
    write_mtl(name + ".mtl", tex)
    write_obj(name + ".obj", name + ".mtl", quad_only=True)
open(os.path.join(HERE, "corrupt.png"), "wb").write(png[:40])
ihdr = struct.pack(">IIBBBBB", 8192, 8192, 8, 2, 0, 0, 0)
huge = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + ihdr + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr) & 0xFFFFFFFF)
huge += struct.pack(">I", 0) + b"IEND" + struct.pack(">I", zlib.crc32(b"IEND") & 0xFFFFFFFF)
open(os.path.join(HERE, "huge.png"), "wb").write(huge)
write_blob()
