#!/usr/bin/env python3
"""The KHR_draco_mesh_compression test assets of tests/golden/gltf/draco/.

Writes `source.gltf`: a UV sphere of radius 1 (12 segments x 8 rings, the seam and the
poles' vertices repeated: 117 vertices, 168 triangles) with POSITION, NORMAL, TEXCOORD_0
(u = longitude / 2 pi, v = colatitude / pi) and COLOR_0 (RGBA, r = u, g = v, b = 0.5,
a = 1), one buffer as a base64 `data:` URI. Then compresses it with glTF-Transform's
`draco` command (Google's Draco encoder, compiled to WebAssembly), once per connectivity
method:

    source-edgebreaker.glb   --method edgebreaker
    source-sequential.glb    --method sequential

with the command's default quantisation (position 14 bits, normal 10, texcoord 12,
colour 8). crates/runtime/tests/gltf_draco.rs decodes both and compares them with the
source mesh. Needs Node.js and npm's `npx` (it fetches @gltf-transform/cli at the pinned
version). Run from the repository root:

    python3 scripts/gen_draco_fixture.py
"""

import base64
import json
import math
import struct
import subprocess
from pathlib import Path

GLTF_TRANSFORM = "@gltf-transform/cli@4.5.1"
OUT = Path("tests/golden/gltf/draco")
SEGMENTS, RINGS = 12, 8


def sphere():
    """Vertices (position, normal, uv, colour) and triangle indices of the UV sphere."""
    vertices = []
    for ring in range(RINGS + 1):
        theta = math.pi * ring / RINGS
        for seg in range(SEGMENTS + 1):
            phi = 2.0 * math.pi * seg / SEGMENTS
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            u, v = seg / SEGMENTS, ring / RINGS
            vertices.append((n, n, (u, v), (u, v, 0.5, 1.0)))
    indices = []
    row = SEGMENTS + 1
    for ring in range(RINGS):
        for seg in range(SEGMENTS):
            a, b = ring * row + seg, (ring + 1) * row + seg
            # Counter-clockwise seen from outside.
            if ring != 0:
                indices += [a, a + 1, b]
            if ring != RINGS - 1:
                indices += [a + 1, b + 1, b]
    return vertices, indices


def source_gltf():
    vertices, indices = sphere()
    count = len(vertices)
    blob = bytearray()
    views, accessors = [], []

    def add(data, target=None):
        while len(blob) % 4:
            blob.append(0)
        view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        blob.extend(data)
        views.append(view)
        return len(views) - 1

    def attribute(values, kind):
        flat = [x for v in values for x in v]
        view = add(struct.pack(f"<{len(flat)}f", *flat), 34962)
        n = len(values[0])
        accessors.append({
            "bufferView": view, "componentType": 5126, "count": count, "type": kind,
            "min": [min(v[k] for v in values) for k in range(n)],
            "max": [max(v[k] for v in values) for k in range(n)],
        })
        return len(accessors) - 1

    position = attribute([v[0] for v in vertices], "VEC3")
    normal = attribute([v[1] for v in vertices], "VEC3")
    uv = attribute([v[2] for v in vertices], "VEC2")
    colour = attribute([v[3] for v in vertices], "VEC4")
    index_view = add(struct.pack(f"<{len(indices)}H", *indices), 34963)
    accessors.append({"bufferView": index_view, "componentType": 5123,
                      "count": len(indices), "type": "SCALAR"})
    while len(blob) % 4:
        blob.append(0)
    return {
        "asset": {"version": "2.0", "generator": "nacre scripts/gen_draco_fixture.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": position, "NORMAL": normal, "TEXCOORD_0": uv,
                           "COLOR_0": colour},
            "indices": len(accessors) - 1,
            "material": 0,
        }]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                                "metallicFactor": 0.0,
                                                "roughnessFactor": 0.5}}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(bytes(blob)).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    source = OUT / "source.gltf"
    source.write_text(json.dumps(source_gltf(), indent=1) + "\n")
    for method in ["edgebreaker", "sequential"]:
        out = OUT / f"source-{method}.glb"
        subprocess.run(["npx", "--yes", GLTF_TRANSFORM, "draco", str(source), str(out),
                        "--method", method], check=True)
        print(f"wrote {out} ({out.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
