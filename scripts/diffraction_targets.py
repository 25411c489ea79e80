"""Issue 37's accuracy targets: the diffraction scenes against their Mitsuba references, per
source.

For each scene (cd-disc, dvd-disc, snake-skin, grating-plane) renders the path-traced reference under
the directional light alone and under the environment alone (``python -m nacre.reference
SCENE --lighting light|environment``), and ``nacre render --scene SCENE --lighting
light|environment|both``; the reference under both is the sum of the two (rendering is linear
in the sources), its halves likewise. Prints, per scene and source, the ΔE2000 mean / p95 of
the real-time picture against the reference and the reference's own noise (its two
independent halves: ``nacre.reference.compare.noise``), against the targets: mean ≤ 1 under
the light; mean ≤ 2 and p95 ≤ 6 under the environment (and under both).

References are kept in OUT (default ``target/diffraction-targets``) as
``SCENE-SOURCE-SIZE-SPP.npz`` (linear, half_a, half_b, seconds) and reused when present, so
that a converged reference is rendered once; ``--fresh`` renders them again. With
``--pictures DIR`` the displayed pictures (reference and real time, per source) are written
there as PNGs.

Needs the ``nacre`` binary (``NACRE_BIN`` or target/debug/nacre) and ``nacre[mitsuba]``
(DRJIT_LIBLLVM_PATH as scripts/test_python.sh sets it). Run from the repository root:

    python scripts/diffraction_targets.py --size 160 --spp 4096
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

SCENES = ["cd-disc", "dvd-disc", "snake-skin", "grating-plane"]
SOURCES = ["light", "environment"]
TARGETS = {"light": (1.0, None), "environment": (2.0, 6.0), "both": (2.0, 6.0)}


def reference(scene: str, source: str, size: int, spp: int, out: str, fresh: bool, roughness: float):
    """The reference of ``scene`` under ``source``: (linear, half_a, half_b, seconds), from
    the cache in ``out`` unless ``fresh``."""
    tag = f"-rough{roughness}" if roughness > 0 else ""
    path = os.path.join(out, f"{scene}{tag}-{source}-{size}-{spp}.npz")
    if os.path.exists(path) and not fresh:
        z = np.load(path)
        return z["linear"], z["half_a"], z["half_b"], float(z["seconds"])
    from nacre import reference as ref_module

    started = time.perf_counter()
    ref = ref_module.render(scene, size, size, spp=spp, seed=1, passes=8, roughness=roughness,
                            lighting=source, progress=ref_module._bar)
    seconds = time.perf_counter() - started
    tmp = path + ".tmp.npz"
    np.savez(tmp, linear=ref.linear, half_a=ref.half_a, half_b=ref.half_b, seconds=seconds)
    os.replace(tmp, path)
    return ref.linear, ref.half_a, ref.half_b, seconds


def realtime(binary: str, scene: str, source: str, size: int, out: str, roughness: float, extra):
    """``nacre render``'s displayed picture of ``scene`` under ``source``."""
    from nacre.reference import compare

    path = os.path.join(out, f"{scene}-{source}-{size}-nacre.png")
    command = [binary, "render", "--scene", scene, "--width", str(size), "--height", str(size),
               "--lighting", source, "-o", path] + list(extra)
    if roughness > 0:
        command += ["--roughness", str(roughness)]
    subprocess.run(command, check=True, capture_output=True)
    return compare.read_picture(path, None)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=160, help="width = height, pixels (default 160)")
    parser.add_argument("--spp", type=int, default=4096, help="reference samples per pixel (default 4096)")
    parser.add_argument("--scenes", default=",".join(SCENES), help="comma-separated scenes (default all four)")
    parser.add_argument("--roughness", type=float, default=0.0, help="GGX α of the gratings (default 0)")
    parser.add_argument("--out", default="target/diffraction-targets", help="folder of the cached references")
    parser.add_argument("--fresh", action="store_true", help="render the references again")
    parser.add_argument("--pictures", help="write the displayed pictures here")
    parser.add_argument("--nacre-arg", action="append", default=[], help="one more argument to nacre render")
    args = parser.parse_args(argv)
    from nacre.reference import SCENES as DEFINITIONS
    from nacre.reference import compare, tone_map

    binary = os.environ.get("NACRE_BIN", "target/debug/nacre")
    os.makedirs(args.out, exist_ok=True)
    if args.pictures:
        os.makedirs(args.pictures, exist_ok=True)
    print(f"{args.size}², reference {args.spp} spp per source (Mitsuba 3, {binary})")
    print("| scene | source | nacre render vs reference mean / p95 | reference noise mean / p95 | target | met |")
    print("|---|---|---|---|---|---|")
    for scene in args.scenes.split(","):
        tone = DEFINITIONS[scene].tone_map
        parts = {s: reference(scene, s, args.size, args.spp, args.out, args.fresh, args.roughness) for s in SOURCES}
        parts["both"] = tuple(parts["light"][i] + parts["environment"][i] for i in range(3)) + (
            parts["light"][3] + parts["environment"][3],)
        for source in ("light", "environment", "both"):
            linear, a, b, seconds = parts[source]
            shown_ref = tone_map(linear, tone)
            shown = realtime(binary, scene, source, args.size, args.out, args.roughness, args.nacre_arg)
            d = compare.displayed_delta_e(shown_ref, shown)
            n = compare.noise(a, b, tone)
            mean_max, p95_max = TARGETS[source]
            met = d["mean"] <= mean_max and (p95_max is None or d["p95"] <= p95_max)
            target = f"mean ≤ {mean_max:g}" + (f", p95 ≤ {p95_max:g}" if p95_max else "")
            print(f"| {scene} | {source} | {d['mean']:.2f} / {d['p95']:.2f} | {n['mean']:.2f} / {n['p95']:.2f} "
                  f"| {target} | {'yes' if met else 'no'} |")
            sys.stdout.flush()
            if args.pictures:
                import mitsuba as mi

                for name, picture in (("reference", shown_ref), ("nacre", shown)):
                    mi.Bitmap(np.round(picture * 255.0).astype(np.uint8), mi.Bitmap.PixelFormat.RGB).write(
                        os.path.join(args.pictures, f"{name}-{scene}-{source}.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
