#!/usr/bin/env python3
"""Side-by-side pictures of Khronos' iridescence sample assets: nacre's render (left) beside
the asset's own reference screenshot (right), for docs/gltf-samples.md.

    cargo build --release -p nacre-cli
    pip install pillow
    python3 scripts/gltf_side_by_side.py --nacre target/release/nacre \
        --samples ../shared/gltf-samples --out docs/images/gltf

Each asset is rendered with nacre's defaults (technique `lut`, falling back to `fourier` per
material; the default environment; exposure 0 EV; PBR Neutral tone mapping, as the glTF
Sample Viewer) from the view in VIEWS, at the screenshot's aspect ratio. The screenshots are
the assets' own (CC BY 4.0 or CC0 1.0: see docs/gltf-samples.md for the credits).
"""
import argparse
import pathlib
import subprocess
import sys

from PIL import Image, ImageDraw

# Per asset: the render's extra arguments (a view close to the screenshot's).
VIEWS = {
    "IridescenceDielectricSpheres": ["--yaw", "35", "--pitch", "25"],
    "IridescenceMetallicSpheres": ["--yaw", "35", "--pitch", "25"],
    "IridescenceSuzanne": [],
    "IridescenceLamp": ["--pitch", "8"],
    "IridescentDishWithOlives": ["--camera", "0"],
    "IridescenceAbalone": ["--pitch", "40"],
}

HEIGHT = 320
CAPTION = 22


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nacre", required=True, help="the nacre binary")
    ap.add_argument("--samples", required=True, help="the glTF sample assets directory")
    ap.add_argument("--out", required=True, help="output directory")
    args = ap.parse_args()
    samples = pathlib.Path(args.samples)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, view in VIEWS.items():
        shot = Image.open(samples / name / "screenshot" / "screenshot.jpg").convert("RGB")
        width = round(HEIGHT * shot.width / shot.height)
        shot = shot.resize((width, HEIGHT), Image.LANCZOS)
        render_path = out / f"{name}-nacre.tmp.png"
        cmd = [
            args.nacre, "render", "--gltf", str(samples / name / "glTF" / f"{name}.gltf"),
            "--width", str(width), "--height", str(HEIGHT), "-o", str(render_path), *view,
        ]
        print(" ".join(cmd), file=sys.stderr)
        subprocess.run(cmd, check=True)
        ours = Image.open(render_path).convert("RGB")
        render_path.unlink()
        pair = Image.new("RGB", (2 * width + 8, HEIGHT + CAPTION), (255, 255, 255))
        pair.paste(ours, (0, CAPTION))
        pair.paste(shot, (width + 8, CAPTION))
        draw = ImageDraw.Draw(pair)
        label = "nacre render --gltf " + " ".join(view) if view else "nacre render --gltf"
        draw.text((4, 4), label, fill=(0, 0, 0))
        draw.text((width + 12, 4), "Khronos reference screenshot", fill=(0, 0, 0))
        pair.save(out / f"{name}.png", optimize=True)
        print(f"wrote {out / (name + '.png')}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
