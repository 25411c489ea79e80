"""The points at which the Python package is checked against the ``nacre`` binary's CSV.

Each case is one ``nacre spectrum`` or ``nacre color`` command and the same computation
through ``nacre`` (Python). The binary's output is committed under ``fixtures/`` and
compared with the Python results by ``test_cli_identity.py``; regenerate it with

    cargo build --release -p nacre-cli
    python python/tests/cli_cases.py --nacre target/release/nacre

(run from anywhere; the commands run in the repository root, where ``tables/`` is). The
test also reruns the binary and compares with the committed files when one is found
(``NACRE_BIN``, else ``target/{release,debug}/nacre``).
"""

from __future__ import annotations

import argparse
import pathlib
import subprocess
import sys
from typing import Any, Dict, List, Optional, Tuple

REPO = pathlib.Path(__file__).resolve().parents[2]
FIXTURES = pathlib.Path(__file__).resolve().parent / "fixtures"

# Points for `--points` (angle_deg, thickness_nm, film_ior).
POINTS: List[Tuple[float, float, float]] = [
    (0.0, 250.0, 1.33),
    (15.0, 400.0, 1.33),
    (30.0, 120.5, 1.5),
    (45.0, 800.0, 1.2),
    (60.0, 0.0, 1.4),
    (75.0, 1500.0, 2.0),
    (85.0, 333.0, 1.9),
]


def _stack(ambient: Any, layers: List[Tuple[Any, float]], substrate: Any) -> Dict[str, Any]:
    return {"ambient": ambient, "layers": layers, "substrate": substrate}


def _stack_args(s: Dict[str, Any]) -> List[str]:
    args = ["--ambient", _cli(s["ambient"]), "--substrate", _cli(s["substrate"])]
    for m, d, *incoherent in s["layers"]:
        suffix = ":incoherent" if incoherent and incoherent[0] else ""
        args += ["--layer", f"{_cli(m)}@{d}{suffix}"]
    return args


def _cli(m: Any) -> str:
    if isinstance(m, complex):
        return f"{m.real}+{m.imag}i"
    return str(m)


SOAP = _stack(1.0, [(1.33, 400.0)], 1.0)
GLTF_BASE = _stack(1.0, [(1.5, 300.0)], 1.5)
ROUGH = _stack(1.0, [(1.33, 400.0)], 1.5)
# A 2 mm BK7 pane, incoherent, with a quarter-wave MgF2 coating on both faces (issue 31).
PANE = _stack("air", [("mgf2", 99.75), ("bk7", 2e6, True), ("mgf2", 99.75)], "air")

# name -> (command, stack, options). Spectrum options: angles, wavelengths (range text).
SPECTRUM_CASES: Dict[str, Tuple[Dict[str, Any], str, str]] = {
    "spectrum-soap": (_stack("air", [("water", 400.0)], "air"), "0:85:5", "380:780:10"),
    "spectrum-film-on-glass": (_stack(1.0, [(1.33, 550.0)], 1.5), "0:89:8", "380:780:20"),
    "spectrum-gold-on-bk7": (_stack("air", [("au", 30.0)], "bk7"), "0:80:20", "400:700:25"),
    "spectrum-absorbing-const": (_stack(1.0, [(1.5 + 0.01j, 250.0), ("tio2", 60.0)], 0.27 + 2.9j), "0:60:15", "380:780:40"),
    "spectrum-tir": (_stack(1.52, [(1.38, 200.0)], 1.0), "20:80:5", "450:650:50"),
    "spectrum-coated-pane": (PANE, "0:80:20", "380:780:20"),
    "spectrum-multilayer": (_stack("air", [("tio2", 56.45), ("mgf2", 99.75), ("tio2", 56.45), ("fused-silica", 120.0)], "bk7"), "0:60:30", "380:780:20"),
}

# `nacre spectrum --jacobian` (thickness derivatives): name -> (stack, angles, wavelengths).
JACOBIAN_CASES: Dict[str, Tuple[Dict[str, Any], str, str]] = {
    "jacobian-multilayer": (_stack("air", [("tio2", 56.45), ("mgf2", 99.75), ("tio2", 56.45), ("fused-silica", 120.0)], "bk7"), "0:60:30", "380:780:20"),
    "jacobian-absorbing-tir": (_stack(1.52, [(1.38, 200.0), (1.5 + 0.01j, 120.0)], 0.27 + 2.9j), "0:80:20", "450:650:50"),
}

# name -> (stack, method, extra options, use points)
COLOR_CASES: Dict[str, Tuple[Dict[str, Any], str, Dict[str, Any], bool]] = {
    "color-spectral": (_stack("air", [("water", 400.0)], "air"), "spectral", {}, False),
    "color-spectral-points": (GLTF_BASE, "spectral", {}, True),
    "color-spectral-t-1964-a": (_stack("air", [("water", 600.0)], "air"), "spectral", {"quantity": "t", "observer": "1964", "illuminant": "a"}, False),
    "color-spectral-rec2020": (_stack("air", [("oil", 450.0)], "water"), "spectral", {"space": "rec2020"}, False),
    "color-spectral-xyz-gold": (_stack("air", [("1.4", 120.0)], "au"), "spectral", {"space": "xyz"}, False),
    "color-spectral-coated-pane": (PANE, "spectral", {}, False),
    "color-spectral-coated-pane-t": (PANE, "spectral", {"quantity": "t"}, False),
    "color-samples-coated-pane": (PANE, "samples:8", {}, True),
    "color-lut": (SOAP, "lut:soap-film", {}, False),
    "color-lut-points": (SOAP, "lut:soap-film", {}, True),
    "color-lut-t": (SOAP, "lut:soap-film", {"quantity": "t"}, False),
    "color-rgb3": (SOAP, "rgb3", {}, False),
    "color-samples": (SOAP, "samples:5", {}, True),
    "color-stack": (_stack("air", [("tio2", 60.0), ("au", 10.0), ("mgf2", 99.75)], "bk7"), "stack", {}, False),
    "color-stack-n": (GLTF_BASE, "stack:24", {}, True),
    "color-fourier": (GLTF_BASE, "fourier:3", {}, True),
    "color-fourier-default": (GLTF_BASE, "fourier", {}, True),
    "color-fourier-auto-sigma": (GLTF_BASE, "fourier:auto:20", {}, True),
    "color-fourier-exact": (_stack(1.0, [(1.5, 300.0)], "au"), "fourier-exact:auto", {}, True),
    "color-gaussian": (GLTF_BASE, "gaussian", {}, True),
    "color-rough-lut": (ROUGH, "rough-lut:rough-film-dielectric", {"roughness": 0.3}, False),
    "color-rough-mc": (ROUGH, "rough-mc:256", {"roughness": 0.3}, False),
}

COLOR_ANGLES = "0:85:5"

# `nacre fit` cases: output file name -> arguments (run in the repository root; the measured
# CSVs are committed fixtures made by nacre.spectrum plus a fixed ripple, see their first
# line). `{out}` is the output folder (for a second output file).
FIT_MEASURED = "python/tests/fixtures/fit-measured.csv"
FIT_WIDE = "python/tests/fixtures/fit-wide.csv"
# `nacre fit color` targets: the linear sRGB look of 137 nm of TiO2 on BK7 at 0-60 degrees
# as `nacre color` wrote it, and a CIELAB look with weights that no film on BK7 reaches.
FIT_LOOK = "python/tests/fixtures/fit-color-look.csv"
FIT_LOOK_LAB = "python/tests/fixtures/fit-color-look-lab.csv"
FIT_CASES: Dict[str, List[str]] = {
    "fit-spectrum.toml": ["fit", "spectrum", FIT_MEASURED, "--layer", "sio2@10:2000", "--substrate", "si",
                          "--residuals", "{out}/fit-spectrum-residuals.csv"],
    "fit-spectrum-two.toml": ["fit", "spectrum", FIT_MEASURED, "--layer", "1.3:1.7@10:2000", "--substrate", "si",
                              "--offset", "free", "--loss", "linear", "--range", "420:780"],
    "fit-spectrum-wide.csv": ["fit", "spectrum", FIT_WIDE, "--layer", "sio2@10:2000", "--substrate", "si", "--scale", "free"],
    "fit-gltf.json": ["fit", "gltf", "--ambient", "air", "--layer", "tio2@120", "--layer", "sio2@180", "--substrate", "bk7"],
    "fit-gltf-range.json": ["fit", "gltf", "--layer", "1.33@400", "--substrate", "1.5", "--thicknesses", "200:600"],
    "fit-color.toml": ["fit", "color", FIT_LOOK, "--layer", "tio2@20:300", "--substrate", "bk7",
                       "--report", "{out}/fit-color-report.csv"],
    "fit-color-lab.toml": ["fit", "color", FIT_LOOK_LAB, "--layer", "1.3:2.4@20:300", "--substrate", "bk7",
                           "--quantity", "r", "--illuminant", "d50", "--space", "rec2020", "--solutions", "2",
                           "--distinct", "20", "--starts", "8", "--report", "{out}/fit-color-lab-report.csv"],
}


def spectrum_command(name: str) -> List[str]:
    stack, angles, wavelengths = SPECTRUM_CASES[name]
    return ["spectrum", *_stack_args(stack), "--angles", angles, "--wavelengths", wavelengths]


def jacobian_command(name: str) -> List[str]:
    stack, angles, wavelengths = JACOBIAN_CASES[name]
    return ["spectrum", *_stack_args(stack), "--angles", angles, "--wavelengths", wavelengths, "--jacobian"]


def color_command(name: str, points_csv: pathlib.Path) -> List[str]:
    stack, method, opts, use_points = COLOR_CASES[name]
    args = ["color", *_stack_args(stack), "--method", method]
    args += ["--points", str(points_csv)] if use_points else ["--angles", COLOR_ANGLES]
    for key in ("quantity", "observer", "illuminant", "space", "roughness"):
        if key in opts:
            args += [f"--{key}", str(opts[key])]
    return args


def write_points(path: pathlib.Path) -> None:
    lines = ["angle_deg,thickness_nm,film_ior"] + [f"{a},{d},{n}" for a, d, n in POINTS]
    path.write_text("\n".join(lines) + "\n")


def run_all(nacre: str, out: pathlib.Path) -> List[str]:
    """Runs every case with the binary `nacre`, writing `out/NAME.csv`; returns the names."""
    out.mkdir(parents=True, exist_ok=True)
    points = out / "points.csv"
    write_points(points)
    names = []
    for name in SPECTRUM_CASES:
        _run(nacre, spectrum_command(name), out / f"{name}.csv")
        names.append(name)
    for name in JACOBIAN_CASES:
        _run(nacre, jacobian_command(name), out / f"{name}.csv")
        names.append(name)
    for name in COLOR_CASES:
        _run(nacre, color_command(name, points.resolve()), out / f"{name}.csv")
        names.append(name)
    return names


def run_fit(nacre: str, out: pathlib.Path) -> List[str]:
    """Runs every `nacre fit` case, writing into `out`; returns the files written (the second
    outputs and further solutions too), and for `fit gltf` and `fit color` cases `NAME.txt`
    with what the command prints (the errors; the designs' summary lines)."""
    out.mkdir(parents=True, exist_ok=True)
    files = []
    for name, args in FIT_CASES.items():
        args = [a.replace("{out}", str(out.resolve())) for a in args]
        stderr = _run(nacre, args, out / name)
        files.append(name)
        files += [pathlib.Path(a).name for a in args if a.startswith(str(out.resolve()))]
        if args[1] == "color":
            # Solutions 2, 3, … beside the first (NAME-2.toml, …), and the lines printed.
            stem = name.rsplit(".", 1)[0]
            files += sorted(p.name for p in out.glob(f"{stem}-[0-9]*.toml"))
        if args[1] in ("gltf", "color"):
            txt = name.rsplit(".", 1)[0] + ".txt"
            (out / txt).write_text(stderr)
            files.append(txt)
    return files


def _run(nacre: str, args: List[str], output: pathlib.Path) -> str:
    cmd = [nacre, *args, "-o", str(output.resolve())]
    r = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr}")
    return r.stderr


def find_nacre() -> Optional[str]:
    import os

    env = os.environ.get("NACRE_BIN")
    if env:
        return env
    for profile in ("release", "debug"):
        p = REPO / "target" / profile / "nacre"
        if p.is_file():
            return str(p)
    return None


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nacre", default=find_nacre(), help="the nacre binary")
    ap.add_argument("--out", default=str(FIXTURES), help="output folder")
    a = ap.parse_args()
    if not a.nacre:
        sys.exit("no nacre binary: build one (cargo build --release -p nacre-cli) or pass --nacre")
    for n in run_all(a.nacre, pathlib.Path(a.out)):
        print(n)
    for n in run_fit(a.nacre, pathlib.Path(a.out)):
        print(n)
