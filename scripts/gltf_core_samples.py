#!/usr/bin/env python3
"""Renders every Khronos core sample model under ../shared/gltf-core-samples with
`nacre render --gltf`, for docs/gltf-core-samples.md.

    cargo build -p nacre-cli
    pip install pillow
    python3 scripts/gltf_core_samples.py --nacre target/debug/nacre \\
        --samples ../shared/gltf-core-samples --out docs/images/gltf-core

Per model: its `glTF/` file rendered at the size of its reference screenshot
(`screenshot/screenshot.*`, the glTF Sample Viewer's; not copied: the pictures are the
assets', CC BY 4.0 / CC0, see each LICENSE.md) from the view in VIEWS (the fitted orbit
camera by default), written as OUT/NAME.png. Every other variant (`glTF-Binary`,
`glTF-Draco`, `glTF-Quantized`) is rendered too, and the script prints one line per file:
rendered, or refused with nacre's message. With --compare DIR it also writes DIR/NAME.png: nacre's render beside
the reference screenshot, for looking at them (not for the repository: the screenshots are
not ours).
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw

# Per model: extra arguments of the render (a view close to the screenshot's).
BOX = ["--yaw", "35", "--pitch", "25"]
VIEWS = {
    "Box": BOX,
    "BoxInterleaved": BOX,
    "BoxTextured": BOX,
    "BoxVertexColors": BOX,
    "OrientationTest": BOX,
    "MultiUVTest": ["--yaw", "-40", "--pitch", "30"],
    "Duck": ["--pitch", "15"],
    "EmissiveStrengthTest": ["--pitch", "15"],
    "Cameras": ["--camera", "0"],
}

VARIANTS = ["glTF", "glTF-Binary", "glTF-Draco", "glTF-Quantized"]


def model_file(folder: pathlib.Path, variant: str):
    files = sorted(folder.glob(f"{variant}/*.gltf")) + sorted(folder.glob(f"{variant}/*.glb"))
    return files[0] if files else None


def render(nacre, path, width, height, out, view):
    cmd = [nacre, "render", "--gltf", str(path), "--width", str(width), "--height",
           str(height), "-o", str(out), *view]
    done = subprocess.run(cmd, capture_output=True, text=True)
    return done.returncode, (done.stderr.strip().splitlines() or [""])[-1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nacre", required=True, help="the nacre binary")
    ap.add_argument("--samples", required=True, help="../shared/gltf-core-samples")
    ap.add_argument("--out", required=True, help="output directory of the renders")
    ap.add_argument("--compare", help="also write render + screenshot pairs here")
    args = ap.parse_args()
    samples = pathlib.Path(args.samples)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    for folder in sorted(p for p in samples.iterdir() if p.is_dir()):
        name = folder.name
        shots = sorted(folder.glob("screenshot/screenshot.*"))
        shot = Image.open(shots[0]).convert("RGB")
        width, height = shot.size
        view = VIEWS.get(name, [])
        for variant in VARIANTS:
            path = model_file(folder, variant)
            if path is None:
                continue
            main_variant = variant == "glTF"
            with tempfile.TemporaryDirectory() as tmp:
                target = out / f"{name}.png" if main_variant else pathlib.Path(tmp) / "r.png"
                rc, last = render(args.nacre, path, width, height, target, view)
                if rc == 0:
                    print(f"{name}/{variant}: rendered")
                    if main_variant:
                        Image.open(target).convert("RGB").save(target, optimize=True)
                        if args.compare:
                            cmp_dir = pathlib.Path(args.compare)
                            cmp_dir.mkdir(parents=True, exist_ok=True)
                            ours = Image.open(target).convert("RGB")
                            pair = Image.new("RGB", (2 * width + 8, height + 16), "white")
                            pair.paste(ours, (0, 16))
                            pair.paste(shot, (width + 8, 16))
                            ImageDraw.Draw(pair).text((2, 2), "nacre | Khronos", fill="black")
                            pair.save(cmp_dir / f"{name}.png")
                elif rc == 2:
                    print(f"{name}/{variant}: refused: {last}")
                else:
                    print(f"{name}/{variant}: FAILED (exit {rc}): {last}")
                    failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
