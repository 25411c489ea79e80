"""ΔE2000 between two pictures of one scene, as a person sees them.

``python -m nacre.reference.compare A B [--tone-map pbr_neutral|max_channel]``: A and B are
PNGs as ``nacre render`` writes them (sRGB-encoded, displayed) or linear-radiance OpenEXR /
``.npy`` files, which are tone-mapped the way ``nacre render`` does (the scene's tone
mapper: ``--tone-map``, or ``--scene`` to take it from the scene). Prints the mean, p95 and
max ΔE2000 over the pixels.

ΔE2000 (CIE 142-2001; Sharma, Wu & Dalal 2005, "The CIEDE2000 color-difference formula:
implementation notes", Color Res. Appl. 30(1)) between CIELAB values of the displayed sRGB
colours, D65 white (IEC 61966-2-1 primaries).
"""

from __future__ import annotations

import argparse
import sys
from typing import Dict, Optional

import numpy as np

from ._scenes import SCENES, srgb_to_linear, tone_map

_SRGB_TO_XYZ = np.array(
    [[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750], [0.0193339, 0.1191920, 0.9503041]]
)
_D65 = _SRGB_TO_XYZ.sum(axis=1)


def lab(encoded: np.ndarray) -> np.ndarray:
    """CIELAB (D65) of sRGB-encoded values in [0, 1], shape (..., 3)."""
    xyz = srgb_to_linear(np.clip(encoded, 0.0, 1.0)) @ _SRGB_TO_XYZ.T / _D65
    eps, kappa = 216.0 / 24389.0, 24389.0 / 27.0
    f = np.where(xyz > eps, np.cbrt(xyz), (kappa * xyz + 16.0) / 116.0)
    return np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]), 200.0 * (f[..., 1] - f[..., 2])], -1)


def delta_e2000(lab1: np.ndarray, lab2: np.ndarray) -> np.ndarray:
    """CIEDE2000 per pixel (k_L = k_C = k_H = 1)."""
    l1, a1, b1 = np.moveaxis(lab1, -1, 0)
    l2, a2, b2 = np.moveaxis(lab2, -1, 0)
    c1, c2 = np.hypot(a1, b1), np.hypot(a2, b2)
    cm7 = ((c1 + c2) / 2.0) ** 7
    g = 0.5 * (1.0 - np.sqrt(cm7 / (cm7 + 25.0**7)))
    a1p, a2p = (1.0 + g) * a1, (1.0 + g) * a2
    c1p, c2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1p = np.degrees(np.arctan2(b1, a1p)) % 360.0
    h2p = np.degrees(np.arctan2(b2, a2p)) % 360.0
    dl = l2 - l1
    dc = c2p - c1p
    dh = h2p - h1p
    dh = np.where(dh > 180.0, dh - 360.0, np.where(dh < -180.0, dh + 360.0, dh))
    dh = np.where(c1p * c2p == 0.0, 0.0, dh)
    dhh = 2.0 * np.sqrt(c1p * c2p) * np.sin(np.radians(dh) / 2.0)
    lm = (l1 + l2) / 2.0
    cm = (c1p + c2p) / 2.0
    hs = h1p + h2p
    hm = np.where(
        c1p * c2p == 0.0,
        hs,
        np.where(np.abs(h1p - h2p) <= 180.0, hs / 2.0, np.where(hs < 360.0, (hs + 360.0) / 2.0, (hs - 360.0) / 2.0)),
    )
    t = (
        1.0
        - 0.17 * np.cos(np.radians(hm - 30.0))
        + 0.24 * np.cos(np.radians(2.0 * hm))
        + 0.32 * np.cos(np.radians(3.0 * hm + 6.0))
        - 0.20 * np.cos(np.radians(4.0 * hm - 63.0))
    )
    dtheta = 30.0 * np.exp(-(((hm - 275.0) / 25.0) ** 2))
    cm7p = cm**7
    rc = 2.0 * np.sqrt(cm7p / (cm7p + 25.0**7))
    sl = 1.0 + 0.015 * (lm - 50.0) ** 2 / np.sqrt(20.0 + (lm - 50.0) ** 2)
    sc = 1.0 + 0.045 * cm
    sh = 1.0 + 0.015 * cm * t
    rt = -np.sin(np.radians(2.0 * dtheta)) * rc
    return np.sqrt((dl / sl) ** 2 + (dc / sc) ** 2 + (dhh / sh) ** 2 + rt * (dc / sc) * (dhh / sh))


def stats(de: np.ndarray) -> Dict[str, float]:
    """Mean, p95 and max of per-pixel ΔE."""
    return {"mean": float(de.mean()), "p95": float(np.percentile(de, 95)), "max": float(de.max())}


def displayed_delta_e(a: np.ndarray, b: np.ndarray) -> Dict[str, float]:
    """ΔE2000 statistics between two displayed (sRGB-encoded, [0, 1]) pictures."""
    if a.shape != b.shape:
        raise ValueError(f"pictures of different sizes: {a.shape[1]}×{a.shape[0]} and {b.shape[1]}×{b.shape[0]}")
    return stats(delta_e2000(lab(a), lab(b)))


def noise(half_a: np.ndarray, half_b: np.ndarray, tone: str) -> Dict[str, float]:
    """The reference's own noise from its two independent halves (linear radiance): the
    ΔE2000 between the halves' displayed pictures, halved — each half's error is √2 times
    that of their mean, and their difference √2 times a half's, so the mean's error is
    about half their difference."""
    de = delta_e2000(lab(tone_map(half_a, tone)), lab(tone_map(half_b, tone))) / 2.0
    return stats(de)


def read_picture(path: str, tone: Optional[str]) -> np.ndarray:
    """A displayed picture in [0, 1]: a PNG as it is, a linear EXR or .npy tone-mapped."""
    lower = path.lower()
    if lower.endswith(".npy"):
        linear = np.load(path)[..., :3]
    else:
        import mitsuba as mi

        if not mi.variant():
            mi.set_variant("scalar_rgb")
        bitmap = mi.Bitmap(path)
        if lower.endswith(".png"):
            # The stored (sRGB-encoded) values as they are: no conversion, which would decode them.
            data = np.array(bitmap)
            if data.ndim == 2:
                data = np.repeat(data[..., None], 3, axis=-1)
            scale = 65535.0 if data.dtype == np.uint16 else 255.0
            return data[..., :3].astype(np.float64) / scale
        linear = np.array(bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False), dtype=np.float64)
    if tone is None:
        raise ValueError(f"{path}: a linear picture needs --tone-map or --scene")
    return tone_map(linear, tone)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m nacre.reference.compare", description=__doc__.split("\n\n")[0])
    parser.add_argument("a", help="reference: PNG (displayed) or linear EXR/.npy")
    parser.add_argument("b", help="picture to measure: PNG (displayed) or linear EXR/.npy")
    parser.add_argument("--tone-map", choices=["pbr_neutral", "max_channel"], help="tone mapper of linear inputs")
    parser.add_argument("--scene", choices=sorted(SCENES), help="take the tone mapper from this scene")
    args = parser.parse_args(argv)
    tone = args.tone_map or (SCENES[args.scene].tone_map if args.scene else None)
    try:
        s = displayed_delta_e(read_picture(args.a, tone), read_picture(args.b, tone))
    except (ValueError, OSError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"ΔE2000 mean {s['mean']:.3f}  p95 {s['p95']:.3f}  max {s['max']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
