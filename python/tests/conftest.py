"""Shared helpers of the nacre Python tests."""

from __future__ import annotations

import csv
import math
import pathlib
from typing import Dict, List

REPO = pathlib.Path(__file__).resolve().parents[2]


def fmt_sig(v: float) -> str:
    """``nacre_bake::commands::spectrum::fmt_sig``: 12 significant digits, fixed notation for
    magnitudes in [1e-5, 1e6), Rust's scientific notation (``1.5e-9``) otherwise."""
    if v == 0.0 or not math.isfinite(v):
        if v == 0.0:
            return "-0" if math.copysign(1.0, v) < 0 else "0"
        return {math.inf: "inf", -math.inf: "-inf"}.get(v, "NaN")
    e = math.floor(math.log10(abs(v)))
    if -5 <= e < 6:
        return f"{v:.{max(11 - e, 0)}f}"
    mantissa, exponent = f"{v:.11e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def read_csv(path: pathlib.Path) -> Dict[str, List[str]]:
    """Columns of a CSV file, as text."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: [r[i] for r in body] for i, name in enumerate(header)}
