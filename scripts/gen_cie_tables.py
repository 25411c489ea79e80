#!/usr/bin/env python3
"""Write the CIE colorimetric tables in ``tables/cie/`` from colour-science 0.4.7.

Files written (run from the repository root):

* ``cmf-cie1931-2deg.csv``, ``cmf-cie1964-10deg.csv``: the CIE standard observers,
  copied value for value from ``colour.MSDS_CMFS[...]`` (360-830 nm, 1 nm).
* ``illuminant-d65.csv``, ``illuminant-d50.csv``: CIE daylight illuminants computed
  with ``colour.sd_CIE_illuminant_D_series`` at the 5 nm native interval of the
  S0/S1/S2 basis functions (300-830 nm), from the CIE 015 chromaticity of the
  nominal CCT (T x 1.4388/1.4380, ``colour.temperature.CCT_to_xy_CIE_D``) with M1
  and M2 rounded to 3 decimals, then linearly interpolated to 1 nm
  (``numpy.interp``).
* ``illuminant-a.csv``: ``colour.sd_CIE_standard_illuminant_A`` evaluated at every
  nm of 300-830 (the closed-form Planck expression of CIE 015 / ISO 11664-2).

Wavelengths are written as integers (nm) and every value with Python ``repr()``
(shortest exact round trip).

    python3 scripts/gen_cie_tables.py           # (re)write tables/cie/*.csv
    python3 scripts/gen_cie_tables.py --check   # compare with disk byte for byte
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")  # colour warns about the missing matplotlib

import colour  # noqa: E402
from colour import SpectralShape  # noqa: E402
from colour.temperature import CCT_to_xy_CIE_D  # noqa: E402

OUT = Path("tables/cie")
COLOUR_VERSION = colour.__version__
LICENCE = [
    "Licence: CIE standard reference data, published in the standards cited above and",
    "  freely usable with a citation of the standard (the CIE also distributes them from",
    "  https://cie.co.at/data-tables under its own terms). colour-science redistributes",
    f"  them in its BSD-3-Clause-licensed package (colour-science {COLOUR_VERSION},",
    "  https://www.colour-science.org) with no further terms on the data.",
]


def fmt(v: float) -> str:
    return repr(float(v))


def table(header: list[str], columns: list[str], rows) -> str:
    lines = [f"# {h}" if h else "#" for h in header]
    lines.append(",".join(columns))
    for wavelength_nm, *values in rows:
        assert float(wavelength_nm).is_integer(), wavelength_nm
        lines.append(",".join([str(int(wavelength_nm)), *(fmt(v) for v in values)]))
    return "\n".join(lines) + "\n"


def cmf_file(key: str, what: str, source: list[str]) -> str:
    cmfs = colour.MSDS_CMFS[key]
    wl = cmfs.wavelengths
    assert wl[0] == 360 and wl[-1] == 830 and np.all(np.diff(wl) == 1), cmfs.shape
    header = [
        what,
        *source,
        f"Extracted from colour-science {COLOUR_VERSION}: colour.MSDS_CMFS[\"{key}\"]",
        "  (colour-science takes these tables from CVRL, http://cvrl.ioo.ucl.ac.uk/cie.htm).",
        "  Values copied unchanged.",
        *LICENCE,
        "Sampling: 360-830 nm inclusive, every 1 nm (471 rows). Columns: vacuum wavelength",
        "  in nm; x_bar, y_bar, z_bar colour-matching functions (dimensionless, y_bar peak 1).",
        "Generator: scripts/gen_cie_tables.py",
    ]
    rows = ((w, *v) for w, v in zip(wl, cmfs.values))
    return table(header, ["wavelength_nm", "x_bar", "y_bar", "z_bar"], rows)


def daylight_file(name: str, cct_nominal: float) -> str:
    cct = cct_nominal * 1.4388 / 1.4380
    xy = CCT_to_xy_CIE_D(cct)
    sd5 = colour.sd_CIE_illuminant_D_series(xy)  # 300-830 nm, 5 nm, M1/M2 rounded
    assert sd5.shape.start == 300 and sd5.shape.end == 830 and sd5.shape.interval == 5
    wl1 = np.arange(300, 831, 1.0)
    v1 = np.interp(wl1, sd5.wavelengths, sd5.values)
    tab = colour.SDS_ILLUMINANTS[name]  # CIE tabulated values, 300-780 nm at 5 nm
    n = len(tab.values)
    assert np.all(tab.wavelengths == sd5.wavelengths[:n])
    dev = np.max(np.abs(sd5.values[:n] - tab.values))
    assert dev < 1e-3, dev
    header = [
        f"CIE standard illuminant {name}: relative spectral power distribution, "
        "normalised to 100 at 560 nm.",
        "Source: CIE 015:2018 Colorimetry, 4th ed. (CIE daylight method:",
        "  S(lambda) = S0 + M1 S1 + M2 S2); ISO/CIE 11664-2 (formerly CIE S 014-2),",
        "  CIE standard illuminants.",
        f"Generated with colour-science {COLOUR_VERSION} (no 1 nm {name} table ships with it;",
        f"  colour.SDS_ILLUMINANTS[\"{name}\"] is 5 nm and stops at 780 nm):",
        f"  xy = colour.temperature.CCT_to_xy_CIE_D({cct_nominal} * 1.4388 / 1.4380)",
        f"     = ({xy[0]!r}, {xy[1]!r})",
        "  sd = colour.sd_CIE_illuminant_D_series(xy)  # M1, M2 rounded to 3 decimals",
        "       (CIE 015), on the 5 nm grid 300-830 nm of the S0, S1, S2 basis functions;",
        "  then numpy.interp to every nm: linear interpolation, as CIE 015 recommends for",
        "  the daylight illuminants (the official CIE 1 nm D65 table is likewise the linear",
        "  interpolation of its 5 nm values).",
        f"  Largest difference from the CIE tabulated {name} (colour.SDS_ILLUMINANTS[\"{name}\"],",
        f"  300-780 nm at 5 nm, rounded to 4 decimals): {dev:.2g} (on the scale 100 at 560 nm).",
        *LICENCE,
        "Sampling: 300-830 nm inclusive, every 1 nm (531 rows). Columns: vacuum wavelength",
        "  in nm; relative spectral power (dimensionless, 100 at 560 nm).",
        "Generator: scripts/gen_cie_tables.py",
    ]
    return table(header, ["wavelength_nm", "relative_power"], zip(wl1, v1))


def illuminant_a_file() -> str:
    sd = colour.sd_CIE_standard_illuminant_A(SpectralShape(300, 830, 1))
    tab = colour.SDS_ILLUMINANTS["A"]
    dev = np.max(np.abs(sd[tab.wavelengths] - tab.values))
    assert dev < 1e-3, dev
    header = [
        "CIE standard illuminant A: relative spectral power distribution of a Planckian",
        "  radiator at about 2856 K, normalised to 100 at 560 nm.",
        "Source: CIE 015:2018 Colorimetry, 4th ed.; ISO/CIE 11664-2 (formerly",
        "  CIE S 014-2), CIE standard illuminants:",
        "  S_A(lambda) = 100 (560/lambda)^5 [exp(1.435e7/(2848*560)) - 1] / "
        "[exp(1.435e7/(2848*lambda)) - 1],",
        "  lambda in nm (c2 = 1.435e7 nm K, T = 2848 K as fixed by the standard).",
        f"Generated with colour-science {COLOUR_VERSION}:",
        "  colour.sd_CIE_standard_illuminant_A(colour.SpectralShape(300, 830, 1)).",
        "  Largest difference from the CIE tabulated A (colour.SDS_ILLUMINANTS[\"A\"],",
        f"  300-780 nm at 5 nm): {dev:.2g} (on the scale 100 at 560 nm).",
        *LICENCE,
        "Sampling: 300-830 nm inclusive, every 1 nm (531 rows). Columns: vacuum wavelength",
        "  in nm; relative spectral power (dimensionless, 100 at 560 nm).",
        "Generator: scripts/gen_cie_tables.py",
    ]
    return table(
        header, ["wavelength_nm", "relative_power"], zip(sd.wavelengths, sd.values)
    )


def files() -> dict[str, str]:
    return {
        "cmf-cie1931-2deg.csv": cmf_file(
            "CIE 1931 2 Degree Standard Observer",
            "CIE 1931 standard colorimetric observer (2 degree): colour-matching functions.",
            [
                "Source: CIE 015:2018 Colorimetry, 4th ed.; ISO/CIE 11664-1:2019",
                "  (formerly CIE S 014-1), CIE standard colorimetric observers.",
            ],
        ),
        "cmf-cie1964-10deg.csv": cmf_file(
            "CIE 1964 10 Degree Standard Observer",
            "CIE 1964 supplementary standard colorimetric observer (10 degree): "
            "colour-matching functions.",
            [
                "Source: CIE 015:2018 Colorimetry, 4th ed.; ISO/CIE 11664-1:2019",
                "  (formerly CIE S 014-1), CIE standard colorimetric observers.",
            ],
        ),
        "illuminant-d65.csv": daylight_file("D65", 6500.0),
        "illuminant-d50.csv": daylight_file("D50", 5000.0),
        "illuminant-a.csv": illuminant_a_file(),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with disk only")
    args = parser.parse_args()
    bad = 0
    for name, text in files().items():
        path = OUT / name
        if args.check:
            if not path.exists() or path.read_text() != text:
                print(f"differs: {path}")
                bad += 1
        else:
            OUT.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            print(f"wrote {path}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
