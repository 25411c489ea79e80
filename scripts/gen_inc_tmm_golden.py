#!/usr/bin/env python3
"""Generate golden data for stacks with incoherent layers with Byrnes' ``tmm.inc_tmm``.

Writes ``tests/golden/tmm/incoherent.json``: a list of random stacks (seeded, so the
file is reproducible) that mix coherent thin films (lossless and absorbing) with thick
incoherent slabs (lossless and absorbing, micrometres to millimetres), each with its
angles (0-85 degrees), vacuum wavelengths (nm) and, per (angle, wavelength), angle-major,
the row ``[angle_deg, wavelength_nm, R_s, R_p, T_s, T_p]`` from

    tmm.inc_tmm(pol, n_list, d_list, c_list, th_0, lam_vac)

with ``c_list`` 'c' (coherent) or 'i' (incoherent) per medium (the ambient and substrate
'i'), ``d_list = [inf, d1, ..., dN, inf]`` in nm. Floats are written by ``json`` (``repr``,
shortest round trip). Materials are the strings of ``scripts/gen_tmm_golden.py`` (a real
number, ``n+ki``, or a bundled material of ``tables/materials``), evaluated by that
script's own material code (independent of the Rust code).

The stacks avoid the two places where ``tmm`` departs from exact arithmetic: a coherent
layer whose single-pass attenuation Im(delta) reaches its clamp (35; limit here 30), and an
incoherent slab passing less than 1e-30 in one pass (``tmm`` clamps P there; nacre refuses
such a slab). The ambient is non-absorbing and no slab is evanescent.

Usage (from the repository root, with ``tmm``, ``numpy`` and ``pyyaml`` installed):

    python3 scripts/gen_inc_tmm_golden.py            # (re)write the JSON
    python3 scripts/gen_inc_tmm_golden.py --check    # compare with the file on disk
"""

from __future__ import annotations

import argparse
import cmath
import importlib.metadata
import json
import math
import random
import sys
from pathlib import Path

import numpy as np
import tmm

sys.path.insert(0, str(Path(__file__).resolve().parent))
import gen_tmm_golden as g  # noqa: E402  (material parsing shared with the coherent goldens)

REPO = Path(__file__).resolve().parent.parent
OUT = REPO / "tests" / "golden" / "tmm" / "incoherent.json"
SEED = 31
CASES = 40
MAX_IM_DELTA = 30.0
MIN_PASS = 1e-25

NAMED_FILMS = ["mgf2", "tio2", "fused-silica", "bk7", "water"]
NAMED_SLABS = ["bk7", "fused-silica", "water"]
NAMED_SUBSTRATES = ["bk7", "fused-silica", "1.0", "1.52", "si", "au"]


def random_case(rng: random.Random, index: int) -> dict:
    ambient = rng.choice(["1.0", "1.0", "1.0", "1.33", "air"])
    substrate = rng.choice(NAMED_SUBSTRATES)
    layers = []
    for _ in range(rng.randint(1, 6)):
        kind = rng.random()
        if kind < 0.35:
            # An incoherent slab: lossless or weakly absorbing, 1 um .. 5 mm.
            d = 10 ** rng.uniform(3.0, 6.7)
            if rng.random() < 0.4:
                mat = f"{rng.uniform(1.4, 2.0):.4f}+{10 ** rng.uniform(-9, -5.5):.3e}i"
            else:
                mat = rng.choice(NAMED_SLABS + [f"{rng.uniform(1.4, 2.4):.4f}"])
            if index % 7 == 3 and rng.random() < 0.5:
                # A thin, strongly absorbing incoherent layer.
                d = rng.uniform(500.0, 3000.0)
                mat = f"{rng.uniform(1.5, 2.5):.3f}+{rng.uniform(0.005, 0.05):.4f}i"
            layers.append({"material": mat, "thickness_nm": round(d, 3), "incoherent": True})
        elif kind < 0.85:
            mat = rng.choice(NAMED_FILMS + [f"{rng.uniform(1.3, 2.5):.4f}"])
            layers.append(
                {"material": mat, "thickness_nm": round(rng.uniform(0.0, 400.0), 3), "incoherent": False}
            )
        else:
            # An absorbing coherent film (metal-like or lossy dielectric).
            mat = rng.choice(["0.27+2.9i", "1.8+0.3i", "au", "cr", f"{rng.uniform(1.5, 3):.3f}+{rng.uniform(0.01, 1):.3f}i"])
            layers.append(
                {"material": mat, "thickness_nm": round(rng.uniform(0.0, 40.0), 3), "incoherent": False}
            )
    # Some stacks are the common cases exactly: coating | slab | coating.
    if index % 5 == 0:
        layers = [
            {"material": "mgf2", "thickness_nm": 99.0, "incoherent": False},
            {"material": "bk7", "thickness_nm": 2.0e6, "incoherent": True},
            {"material": "tio2", "thickness_nm": round(rng.uniform(20.0, 120.0), 3), "incoherent": False},
            {"material": "mgf2", "thickness_nm": 99.0, "incoherent": False},
        ]
        substrate = "1.0"
        ambient = "1.0"
    angles = sorted(rng.sample([0.0, 10.0, 25.0, 40.0, 55.0, 70.0, 80.0, 85.0], 5))
    wavelengths = sorted(round(rng.uniform(400.0, 750.0), 2) for _ in range(7))
    return {
        "name": f"random-{index:02d}",
        "ambient": ambient,
        "substrate": substrate,
        "layers": layers,
        "angles_deg": angles,
        "wavelengths_nm": wavelengths,
    }


def compute(case: dict) -> list[list[float]] | None:
    """The golden rows, or None when the stack touches one of tmm's clamps."""
    media = [case["ambient"]] + [l["material"] for l in case["layers"]] + [case["substrate"]]
    mats = [g.parse_material(m) for m in media]
    d_list = [math.inf] + [l["thickness_nm"] for l in case["layers"]] + [math.inf]
    c_list = ["i"] + ["i" if l["incoherent"] else "c" for l in case["layers"]] + ["i"]
    rows = []
    for ang in case["angles_deg"]:
        th0 = math.radians(ang)
        for wl in case["wavelengths_nm"]:
            n_list = np.array([m.nk(wl / 1000.0) for m in mats], dtype=complex)
            if n_list[0].imag != 0.0:
                return None
            th_list = tmm.list_snell(n_list, th0)
            for i in range(1, len(n_list) - 1):
                im_delta = (2 * math.pi * n_list[i] * cmath.cos(th_list[i]) / wl * d_list[i]).imag
                if c_list[i] == "c" and im_delta > MAX_IM_DELTA:
                    return None
                if c_list[i] == "i" and math.exp(-2 * im_delta) < MIN_PASS:
                    return None
            vals = []
            for pol in ("s", "p"):
                r = tmm.inc_tmm(pol, n_list, d_list, c_list, th0, wl)
                vals.append((float(r["R"]), float(r["T"])))
            row = [ang, wl, vals[0][0], vals[1][0], vals[0][1], vals[1][1]]
            if not all(math.isfinite(v) and -1e-12 <= v <= 1 + 1e-12 for v in row[2:]):
                raise ValueError(f"{case['name']}: bad powers {row}")
            rows.append(row)
    return rows


def build() -> str:
    rng = random.Random(SEED)
    cases = []
    index = 0
    while len(cases) < CASES:
        case = random_case(rng, index)
        index += 1
        rows = compute(case)
        if rows is None:
            continue
        case["rows"] = rows
        cases.append(case)
    doc = {
        "generator": "scripts/gen_inc_tmm_golden.py",
        "tmm": importlib.metadata.version("tmm"),
        "columns": ["angle_deg", "wavelength_nm", "R_s", "R_p", "T_s", "T_p"],
        "cases": cases,
    }
    return json.dumps(doc, indent=1) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="compare with the file on disk")
    args = ap.parse_args()
    text = build()
    if args.check:
        same = OUT.exists() and OUT.read_text() == text
        print(("ok   " if same else "DIFF ") + str(OUT.relative_to(REPO)))
        return 0 if same else 1
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(REPO)} ({len(text)} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
