"""Rough diffracting surfaces against their Mitsuba references (issue 37, item 4).

For each (scene, α): renders the path-traced reference (``python -m nacre.reference SCENE
--roughness α``, Mitsuba 3 with nacre's rough ``nacre_grating``), the real-time picture
(``nacre render --scene SCENE --roughness α``) and the smooth real-time picture, and prints
the ΔE2000 mean / p95 of each against the reference and the reference's own noise (its two
independent halves: ``nacre.reference.compare.noise``). Writes every picture to OUT (default
``target/rough-diffraction``: SCENE-α.png real time, SCENE-α-reference.png and .npy the
reference) and, with ``--readme``, copies the rough CD's pair (α = 0.2) to the README's
``docs/images/reference/{reference,nacre}-cd-disc-rough.png``.

Needs the ``nacre`` binary (``NACRE_BIN`` or target/debug/nacre) and ``nacre[mitsuba]``
(DRJIT_LIBLLVM_PATH as scripts/test_python.sh sets it). Run from the repository root:

    python scripts/rough_diffraction.py --size 160 --spp 512
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

import numpy as np

CASES = [("cd-disc", 0.05), ("cd-disc", 0.2), ("grating-plane", 0.05)]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=160, help="width = height, pixels (default 160)")
    parser.add_argument("--spp", type=int, default=512, help="reference samples per pixel (default 512)")
    parser.add_argument("--out", default="target/rough-diffraction", help="folder for the pictures")
    parser.add_argument("--readme", action="store_true", help="write docs/images/render-cd-disc-rough.png")
    args = parser.parse_args(argv)
    from nacre import reference
    from nacre.reference import compare

    binary = os.environ.get("NACRE_BIN", "target/debug/nacre")
    os.makedirs(args.out, exist_ok=True)
    size = str(args.size)
    print("| scene | α | real time vs reference (mean / p95) | smooth real time vs reference | reference noise |")
    print("|---|---|---|---|---|")
    pictures = {}
    for scene, alpha in CASES:
        ref = reference.render(scene, args.size, args.size, spp=args.spp, seed=1, passes=8, roughness=alpha)
        shown_ref = ref.display()
        noise = compare.noise(ref.half_a, ref.half_b, ref.scene.tone_map)
        rows = []
        for a in (alpha, 0.0):
            out = os.path.join(args.out, f"{scene}-{a}.png")
            subprocess.run([binary, "render", "--scene", scene, "--width", size, "--height", size,
                            "--roughness", str(a), "-o", out], check=True, capture_output=True)
            shown = compare.read_picture(out, None)
            rows.append(compare.displayed_delta_e(shown_ref, shown))
            pictures[(scene, a)] = shown
        pictures[(scene, alpha, "reference")] = shown_ref
        np.save(os.path.join(args.out, f"{scene}-{alpha}-reference.npy"), ref.linear)
        import mitsuba as mi

        mi.Bitmap(np.round(shown_ref * 255.0).astype(np.uint8), mi.Bitmap.PixelFormat.RGB).write(
            os.path.join(args.out, f"{scene}-{alpha}-reference.png"))
        print(f"| {scene} | {alpha} | {rows[0]['mean']:.2f} / {rows[0]['p95']:.2f} | "
              f"{rows[1]['mean']:.2f} / {rows[1]['p95']:.2f} | {noise['mean']:.2f} / {noise['p95']:.2f} |")
        sys.stdout.flush()
    if args.readme:
        import shutil

        for src, dst in (("cd-disc-0.2-reference.png", "reference-cd-disc-rough.png"),
                         ("cd-disc-0.2.png", "nacre-cd-disc-rough.png")):
            shutil.copyfile(os.path.join(args.out, src), os.path.join("docs/images/reference", dst))
    return 0


if __name__ == "__main__":
    sys.exit(main())
