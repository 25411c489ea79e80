"""``python -m nacre.reference SCENE --width W --height H --spp N -o FILE.png``: the path-traced
reference of a ``nacre render`` scene (see :mod:`nacre.reference`). Writes FILE.png (tone
mapped as ``nacre render``), FILE.exr (linear radiance) and prints the render time and the
reference's own noise (ΔE2000 mean and p95, from two independent halves)."""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile

import numpy as np

from . import SCENES, _bar, render
from .compare import noise


def _write_atomic(path: str, write) -> None:
    folder = os.path.dirname(os.path.abspath(path))
    suffix = os.path.splitext(path)[1]
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=suffix)
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m nacre.reference", description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", choices=sorted(SCENES), metavar="SCENE", help=", ".join(sorted(SCENES)))
    parser.add_argument("--width", type=int, default=800, help="image width, pixels (default 800, as nacre render)")
    parser.add_argument("--height", type=int, default=600, help="image height, pixels (default 600)")
    parser.add_argument("--spp", type=int, default=256, help="samples per pixel (default 256)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first pass (default 0)")
    parser.add_argument("--variant", default="llvm_ad_spectral", help="Mitsuba variant (a spectral one)")
    parser.add_argument("-o", "--output", required=True, help="output PNG; the linear EXR goes beside it")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--roughness", type=float, default=0.0,
                        help="GGX α of the grating's microfacets, 0 to 1 (diffraction scenes; default 0)")
    parser.add_argument("--lighting", choices=["both", "light", "environment"], default="both",
                        help="which sources light the scene, as nacre render --lighting (default both)")
    args = parser.parse_args(argv)
    for flag, value, low, high in (("--width", args.width, 1, 8192), ("--height", args.height, 1, 8192),
                                   ("--spp", args.spp, 2, 1 << 20)):
        if not low <= value <= high:
            print(f"error: {flag} {value}: expected {low} to {high}", file=sys.stderr)
            return 2
    if not (math.isfinite(args.roughness) and 0.0 <= args.roughness <= 1.0):
        print(f"error: --roughness {args.roughness}: expected 0 to 1 (the GGX α)", file=sys.stderr)
        return 2
    if args.roughness > 0.0 and args.scene not in ("cd-disc", "dvd-disc", "snake-skin", "grating-plane"):
        print(f"error: --roughness {args.roughness}: the diffraction scenes (cd-disc, dvd-disc, snake-skin, "
              "grating-plane) only",
              file=sys.stderr)
        return 2
    if not args.output.lower().endswith(".png"):
        print(f"error: -o {args.output}: expected a .png file", file=sys.stderr)
        return 2
    folder = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(folder):
        print(f"error: -o {args.output}: folder {folder} does not exist", file=sys.stderr)
        return 2
    try:
        import mitsuba as mi
    except ImportError:
        print("error: nacre.reference needs Mitsuba 3: pip install 'nacre[mitsuba]'", file=sys.stderr)
        return 2
    ref = render(args.scene, args.width, args.height, args.spp, args.seed, args.variant,
                 passes=min(8, args.spp - args.spp % 2), progress=None if args.quiet else _bar,
                 roughness=args.roughness, lighting=args.lighting)
    shown = np.round(ref.display() * 255.0).astype(np.uint8)
    exr = os.path.splitext(args.output)[0] + ".exr"
    _write_atomic(args.output, lambda p: mi.Bitmap(shown, mi.Bitmap.PixelFormat.RGB).write(p))
    _write_atomic(exr, lambda p: mi.Bitmap(ref.linear.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(p))
    n = noise(ref.half_a, ref.half_b, ref.scene.tone_map)
    print(f"{args.scene}: {args.width}×{args.height}, {args.spp} spp in {ref.seconds:.1f} s; "
          f"noise ΔE2000 mean {n['mean']:.3f}, p95 {n['p95']:.3f}; wrote {args.output} and {exr}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
