#!/usr/bin/env python3
"""Writes the emission-texture test models of tests/data/emissive_tex (run once; outputs committed).

glow.png        8x8 texture, black but for its top-right 2x2 texels, white (sRGB 255: linear 1):
                a label's glowing accent.
screen.obj      a grey box (1 x 1 x 1, Kd 0.6) and in front of it a 1 x 1 quad facing +z with UVs,
                material 'screen': Kd 0, map_Ke glow.png and no Ke (the texture alone: Ke 1).
screen.mtl      its materials.
screen.gltf     the same quad in glTF 2.0, emissiveTexture glow.png with emissiveFactor [4, 4, 4].
nofactor.gltf   the same without emissiveFactor: glTF's default factor is 0, nothing emitted.
panel.obj       a 1 x 1 quad at y = 0.3 with UVs (u along +x), no materials.
rg.png          2x1 texture: red, green (linear 1).
lit.json        a white floor lit only by panel.obj as a two-sided emitter whose emission is
                3 x rg.png ("emission_texture"), seen from the side: red light on the left, green on the right.
"""
import base64, json, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png_bytes(w, h, rows):
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def glow():
    rows = []
    for y in range(8):
        row = []
        for x in range(8):
            row += (255, 255, 255) if (x >= 6 and y < 2) else (0, 0, 0)
        rows.append(row)
    return png_bytes(8, 8, rows)


QUAD_P = [(-0.5, -0.5, 0.6), (0.5, -0.5, 0.6), (0.5, 0.5, 0.6), (-0.5, 0.5, 0.6)]
QUAD_T = [(0, 0), (1, 0), (1, 1), (0, 1)]


def write_obj():
    with open(os.path.join(HERE, "screen.mtl"), "w") as f:
        f.write("# screen.obj's materials: a grey box, a screen whose emission is its texture\n")
        f.write("newmtl box\nKd 0.6 0.6 0.6\n\nnewmtl screen\nKd 0 0 0\nmap_Ke glow.png\n")
    lines = ["# a grey box and a screen in front of it (make.py)", "mtllib screen.mtl", "o box"]
    for x in (-0.5, 0.5):
        for y in (-0.5, 0.5):
            for z in (-0.5, 0.5):
                lines.append("v %g %g %g" % (x, y, z))
    lines.append("usemtl box")
    # vertex index = 1 + 4 ix + 2 iy + iz
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines += ["f %d %d %d %d" % f for f in faces]
    lines.append("o screen")
    lines += ["v %g %g %g" % p for p in QUAD_P]
    lines += ["vt %g %g" % t for t in QUAD_T]
    lines.append("usemtl screen")
    lines.append("f 9/1 10/2 11/3 12/4")
    with open(os.path.join(HERE, "screen.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_gltf(name, factor):
    pos = b"".join(struct.pack("<3f", *p) for p in QUAD_P)
    uv = b"".join(struct.pack("<2f", u, 1.0 - v) for u, v in QUAD_T)  # glTF's v runs down
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    buf = pos + uv + idx
    mat = {"name": "screen", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
           "emissiveTexture": {"index": 0}}
    if factor is not None:
        mat["emissiveFactor"] = factor
    g = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [mat],
        "textures": [{"source": 0}], "images": [{"uri": "glow.png"}],
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(uv)},
                        {"buffer": 0, "byteOffset": len(pos) + len(uv), "byteLength": len(idx)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0.6], "max": [0.5, 0.5, 0.6]},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }
    with open(os.path.join(HERE, name), "w") as f:
        json.dump(g, f, indent=1)
        f.write("\n")


def write_lit():
    with open(os.path.join(HERE, "panel.obj"), "w") as f:
        f.write("# a 1 x 1 quad at y = 0.3 with texture coordinates (make.py)\n")
        for x, z in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
            f.write("v %g 0.3 %g\n" % (x, z))
        for u, v in QUAD_T:
            f.write("vt %g %g\n" % (u, v))
        f.write("f 1/1 2/2 3/3 4/4\n")
    scene = {
        "description": "A floor lit by a panel whose emission is a texture (make.py)",
        "materials": {"white": {"albedo": [0.8, 0.8, 0.8]},
                      "panel": {"albedo": [0, 0, 0], "emission": [3, 3, 3], "emission_texture": "rg.png", "two_sided": True}},
        "objects": [{"name": "floor", "quad": [[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]], "material": "white"},
                    {"name": "panel", "mesh": "panel.obj", "material": "panel"}],
        "camera": {"pos": [0, 0.25, 1.6], "look": [0, 0.05, 0], "fov": 50},
    }
    with open(os.path.join(HERE, "lit.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    with open(os.path.join(HERE, "glow.png"), "wb") as f:
        f.write(glow())
    write_obj()
    write_gltf("screen.gltf", [4, 4, 4])
    write_gltf("nofactor.gltf", None)
    with open(os.path.join(HERE, "rg.png"), "wb") as f:
        f.write(png_bytes(2, 1, [[255, 0, 0, 0, 255, 0]]))
    write_lit()
