#!/usr/bin/env python3
"""Writes shadow-scenes/assets/scenes/spot-lamp.gltf, the file behind the built-in scene
`spot-lamp`: a floor, a box on legs and a ball, lit by a KHR_lights_punctual spot light
pointing down (and a camera). The scene is loaded by the glTF loader like a user's file, so
the conformance suite covers the punctual-light path end to end.

    python3 scripts/make_spot_lamp_gltf.py
"""
import base64
import json
import math
import struct
from pathlib import Path


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    # Outward, counter-clockwise.
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    t = []
    for a, b, c, d in quads:
        t += [(a, b, c), (a, c, d)]
    return p, t


def sphere(c, r, rings=12, segs=24):
    p = [(c[0], c[1] + r, c[2])]
    for i in range(1, rings):
        th = math.pi * i / rings
        for s in range(segs):
            ph = 2 * math.pi * s / segs
            p.append((c[0] + r * math.sin(th) * math.cos(ph), c[1] + r * math.cos(th),
                      c[2] - r * math.sin(th) * math.sin(ph)))
    p.append((c[0], c[1] - r, c[2]))
    bottom = len(p) - 1
    idx = lambda i, s: 1 + (i - 1) * segs + s % segs
    t = [(0, idx(1, s), idx(1, s + 1)) for s in range(segs)]
    for i in range(1, rings - 1):
        for s in range(segs):
            a, b, cc, d = idx(i, s), idx(i, s + 1), idx(i + 1, s), idx(i + 1, s + 1)
            t += [(a, cc, d), (a, d, b)]
    t += [(idx(rings - 1, s), bottom, idx(rings - 1, s + 1)) for s in range(segs)]
    return p, t


def merge(parts):
    p, t = [], []
    for pp, tt in parts:
        base = len(p)
        p += pp
        t += [(a + base, b + base, c + base) for a, b, c in tt]
    return p, t


floor = ([(-3, 0, -3), (3, 0, -3), (3, 0, 3), (-3, 0, 3)], [(0, 2, 1), (0, 3, 2)])
table = merge([box((-0.6, 0.7, -0.4), (0.6, 0.8, 0.4))] +
              [box((x - 0.05, 0, z - 0.05), (x + 0.05, 0.7, z + 0.05))
               for x in (-0.5, 0.5) for z in (-0.3, 0.3)])
ball = sphere((0.9, 0.3, 0.7), 0.3)
meshes = [("floor", floor, [0.8, 0.8, 0.8, 1]), ("table", table, [0.7, 0.5, 0.3, 1]),
          ("ball", ball, [0.3, 0.5, 0.8, 1])]

buf, views, accessors, gl_meshes, materials = b"", [], [], [], []
for k, (name, (p, t), colour) in enumerate(meshes):
    pos = b"".join(struct.pack("<3f", *v) for v in p)
    ind = b"".join(struct.pack("<3I", *tri) for tri in t)
    for data, target in ((pos, 34962), (ind, 34963)):
        while len(buf) % 4:
            buf += b"\0"
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "target": target})
        buf += data
    lo = [min(v[i] for v in p) for i in range(3)]
    hi = [max(v[i] for v in p) for i in range(3)]
    accessors.append({"bufferView": 2 * k, "componentType": 5126, "count": len(p), "type": "VEC3",
                      "min": lo, "max": hi})
    accessors.append({"bufferView": 2 * k + 1, "componentType": 5125, "count": 3 * len(t),
                      "type": "SCALAR"})
    materials.append({"name": name, "pbrMetallicRoughness": {"baseColorFactor": colour}})
    gl_meshes.append({"name": name, "primitives": [
        {"attributes": {"POSITION": 2 * k}, "indices": 2 * k + 1, "material": k}]})

# -90 degrees about X turns the spot's -Z onto -Y (down).
down = [-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)]
# The camera at (0.1, 2.2, 2.6) looking down at about 35 degrees.
a = math.atan2(2.2 - 0.4, 2.6)
look = [-math.sin(a / 2), 0.0, 0.0, math.cos(a / 2)]
doc = {
    "asset": {"version": "2.0", "generator": "scripts/make_spot_lamp_gltf.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "spot", "type": "spot", "color": [1.0, 0.95, 0.9], "intensity": 1.0,
         "spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.9}}]}},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
    "nodes": [{"mesh": 0}, {"mesh": 1}, {"mesh": 2},
              {"name": "lamp", "translation": [0.2, 2.4, -0.1], "rotation": down,
               "extensions": {"KHR_lights_punctual": {"light": 0}}},
              {"name": "camera", "camera": 0, "translation": [0.1, 2.2, 2.6], "rotation": look}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 1.3333,
                                                        "znear": 0.05}}],
    "meshes": gl_meshes,
    "materials": materials,
    "buffers": [{"byteLength": len(buf),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    "bufferViews": views,
    "accessors": accessors,
}
out = Path(__file__).resolve().parent.parent / "shadow-scenes/assets/scenes/spot-lamp.gltf"
out.write_text(json.dumps(doc, indent=1) + "\n")
print(f"wrote {out} ({out.stat().st_size} bytes)")
