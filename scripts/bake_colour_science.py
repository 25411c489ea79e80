#!/usr/bin/env python3
"""Bake ``film-dielectric`` with numpy + colour-science and time it: a baseline for nacre.

What it measures
----------------
The wall time that vectorised numpy + colour-science 0.4.7 needs to compute the
table that ``nacre bake tables/recipes/film-dielectric.toml`` computes (the
definitions are those of the module docs of ``crates/format/src/film_lut.rs`` and of
``nacre_optics::colour::Colorimeter``):

* stack: ambient n0 = 1.0 | one non-dispersive film of real index n | base 1.5;
* texel (x, y, z), 24 x 384 x 32 = 294,912 texels:
  x: cos theta = t^2, t = x/23, clamped so that cos theta >= 1e-6;
  y: optical path difference OPD = t * OPD_max, OPD_max = 2 * 1200 nm * 2.5, t = y/383;
  z: q = q_min + t^2 (q_max - q_min), t = z/31, q(n) = sqrt(n^2 - sin^2 theta),
  n_min = 1.0, n_max = 2.5; film index n = sqrt(q^2 + sin^2 theta), thickness
  d = OPD / (2 q(n)) (0 where OPD = 0);
* colour: unpolarised R = (R_s + R_p)/2 integrated over 360-830 nm with the CIE 015
  rectangle rule at 1 nm (471 wavelengths): XYZ weights u = CMF x D65 / sum(y_bar D65)
  (CIE 1931 2 deg CMFs from ``colour.MSDS_CMFS``; D65 at 1 nm from
  ``tables/cie/illuminant-d65.csv``, the file nacre embeds, since colour-science ships
  D65 only at 5 nm up to 780 nm), then XYZ -> linear sRGB with the sRGB primaries'
  matrix for that computed D65 white (``colour.normalised_primary_matrix``; it differs
  from the published sRGB matrix by < 3e-4 and makes a perfect reflector exactly
  (1, 1, 1), as nacre's Bradford-adapted matrix does; the adaptation is the identity
  here because the illuminant is the space's white). The transmittance colour
  (nacre bakes it too) comes from the same TMM call and costs one more small matmul.

nacre integrates with a phase-adaptive 2-point Gauss-Legendre rule (~500-900 nodes for
this table) instead of the 1 nm rectangle rule; the difference is reported when nacre's
baked EXR can be read (it is half precision, so ~5e-4 relative differences are just
rounding).

The reflectance comes from ``colour.phenomena.thin_film_tmm(n, d, wavelength, theta)``,
which evaluates the outer product angles x wavelengths x thicknesses in one call and
returns R and T for s and p, shape (W, A, T, 2). Every (theta, n) row of the table has
its own film index and its own thickness list, so the script loops over the 24 x 32 =
768 rows in Python and, within a row, vectorises over 384 thicknesses x 471
wavelengths (one call per row; the film index cannot be batched: colour-science takes
the layer angles of a "dispersive" n from the first wavelength only). The colour is then
one matmul per row.

For scale, a second timing uses the closed-form single-film Airy formula in plain numpy
(lossless film only: R = (r01^2 + r12^2 + 2 r01 r12 C) / (1 + r01^2 r12^2 + 2 r01 r12 C),
C = cos(2 pi OPD / lambda), T = 1 - R), vectorised over the whole table; it also checks
colour-science's table over every texel.

Checks printed: one row of colour-science's R_s, R_p against Byrnes' ``tmm.coh_tmm``
(lossless, so colour-science's TMM is valid there); colour-science vs the Airy table;
and, if ``tables/baked/film-dielectric.{reflectance,transmittance}.exr`` exist, both
against nacre's baked tables (max |dRGB| and CIEDE2000), read with a small built-in
OpenEXR reader (scan-line, NONE/ZIPS/ZIP compression only; skipped otherwise).

Timing: the timed region is everything after the imports (axes, weights, the TMM calls,
the colour sums), not the checks. By default the script times two runs: numpy
single-threaded (OMP/OPENBLAS/MKL/NUMEXPR/VECLIB_MAXIMUM_THREADS=1, set before numpy is
imported), in this process, then numpy with its default threads, in a child process
started with the caller's original environment. If the full table is projected to
take more than ``--max-seconds`` (default 300), only 1 row in 8 is run (the rows with
x + z = 0 mod 8, which cover every angle and every film index) and the time is
extrapolated (the output says so); ``--stride N`` forces such a subset.

Run (from the repository root; about 2-3 minutes on a 2-core machine):

    python3 scripts/bake_colour_science.py                 # both thread settings
    python3 scripts/bake_colour_science.py --threads 1     # single-threaded only
    python3 scripts/bake_colour_science.py --stride 8      # 1 row in 8, extrapolated
"""

import os
import sys

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")
_ORIGINAL_ENV = {v: os.environ.get(v) for v in _THREAD_VARS}


def _threads_arg(argv):
    for i, a in enumerate(argv):
        if a == "--threads" and i + 1 < len(argv):
            return argv[i + 1]
        if a.startswith("--threads="):
            return a.split("=", 1)[1]
    return "both"


SINGLE_THREADED = _threads_arg(sys.argv[1:]) != "default"
if SINGLE_THREADED:
    for _var in _THREAD_VARS:
        os.environ[_var] = "1"

import argparse  # noqa: E402
import importlib.metadata  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import struct  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
import zlib  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # "Matplotlib related API features are not available"
    import colour  # noqa: E402
    from colour.phenomena import thin_film_tmm  # noqa: E402

import tmm  # noqa: E402

# --- the recipe (tables/recipes/film-dielectric.toml) --------------------------------
N_AMBIENT = 1.0
N_BASE = 1.5
COS_COUNT, OPD_COUNT, IOR_COUNT = 24, 384, 32
THICKNESS_MAX_NM = 1200.0
IOR_MIN, IOR_MAX = 1.0, 2.5
OPD_MAX_NM = 2.0 * THICKNESS_MAX_NM * IOR_MAX
MIN_COS_THETA = 1e-6
WAVELENGTHS_NM = np.arange(360.0, 831.0, 1.0)  # 471 samples, CIE 015 rectangle rule

RECIPE = Path("tables/recipes/film-dielectric.toml")
D65_CSV = Path("tables/cie/illuminant-d65.csv")
BAKED = Path("tables/baked/film-dielectric")
NACRE_TIME_S = 2.1  # nacre bake of this recipe (R and T) on the 2-core dev machine


# --- colour weights ---------------------------------------------------------------------
def read_d65():
    rows = [line.split(",") for line in D65_CSV.read_text().splitlines()
            if line and not line.startswith("#")][1:]
    table = {int(r[0]): float(r[1]) for r in rows}
    return np.array([table[int(w)] for w in WAVELENGTHS_NM])


def colour_weights():
    """(471, 3) weights w with RGB = sum_lambda R(lambda) w(lambda), the XYZ->RGB matrix
    and the XYZ white of the perfect reflector."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    assert np.array_equal(cmfs.wavelengths, WAVELENGTHS_NM), cmfs.shape
    xyz_bar = np.asarray(cmfs.values, dtype=float)
    power = read_d65()
    u = xyz_bar * power[:, None] / np.sum(xyz_bar[:, 1] * power)
    white = u.sum(axis=0)
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    npm = colour.normalised_primary_matrix(srgb.primaries, white[:2] / white.sum())
    m = np.linalg.inv(npm)
    m = m / (u @ m.T).sum(axis=0)[:, None]  # R = 1 -> (1, 1, 1) to the last bits
    return u @ m.T, m, white


# --- axes (FilmLutAxes::texel_parameters) -----------------------------------------------
def row_parameters(x, z):
    """(cos theta, angle in degrees, film index, thicknesses[384]) of row (x, z)."""
    tx = max(x / (COS_COUNT - 1), math.sqrt(MIN_COS_THETA))
    tz = z / (IOR_COUNT - 1)
    c = tx * tx
    sin2 = max(1.0 - c * c, 0.0)

    def q_of(n):
        return math.sqrt(max(n * n - N_AMBIENT * N_AMBIENT * sin2, 0.0))

    q_min, q_max = q_of(IOR_MIN), q_of(IOR_MAX)
    q = q_min + tz * tz * (q_max - q_min)
    n = math.sqrt(q * q + N_AMBIENT * N_AMBIENT * sin2)
    q = q_of(n)
    opd = np.arange(OPD_COUNT) / (OPD_COUNT - 1) * OPD_MAX_NM
    d = np.where(opd > 0.0, opd / (2.0 * q) if q > 0 else np.inf, 0.0)
    return c, math.degrees(math.acos(c)), n, d


def all_rows():
    # nacre's row order: film index outer, cos theta inner
    return [(x, z) for z in range(IOR_COUNT) for x in range(COS_COUNT)]


def row_subset(rows, stride):
    """Every `stride`th row on diagonals (x + z = 0 mod stride), so that the subset covers
    every angle and every film index; all rows when stride = 1."""
    return [(x, z) for x, z in rows if (x + z) % stride == 0]


# --- the colour-science bake -------------------------------------------------------------
def bake_rows(rows, weights):
    """Reflectance and transmittance colours of `rows`; returns (R, T, seconds in TMM)."""
    out_r = np.zeros((len(rows), OPD_COUNT, 3))
    out_t = np.zeros((len(rows), OPD_COUNT, 3))
    t_tmm = 0.0
    for m, (x, z) in enumerate(rows):
        _, angle_deg, n, d = row_parameters(x, z)
        t0 = time.perf_counter()
        r, t = thin_film_tmm([N_AMBIENT, n, N_BASE], d, WAVELENGTHS_NM, angle_deg)
        t_tmm += time.perf_counter() - t0
        # (W, 1, T, 2) -> unpolarised (T, W), then one matmul each
        out_r[m] = np.real(r[:, 0, :, :]).mean(axis=-1).T @ weights
        out_t[m] = np.real(t[:, 0, :, :]).mean(axis=-1).T @ weights
    return out_r, out_t, t_tmm


def to_table(rows, values):
    """Scatter per-row results into a (z, y, x, 3) array (the atlas order)."""
    table = np.full((IOR_COUNT, OPD_COUNT, COS_COUNT, 3), np.nan)
    for m, (x, z) in enumerate(rows):
        table[z, :, x, :] = values[m]
    return table


# --- closed-form Airy baseline -------------------------------------------------------------
def bake_airy(weights):
    """The whole table with the single-film Airy formula, vectorised per cos theta column."""
    lam = WAVELENGTHS_NM
    opd = np.arange(OPD_COUNT) / (OPD_COUNT - 1) * OPD_MAX_NM
    cos2b = np.cos(2.0 * np.pi * opd[:, None] / lam[None, :])  # (384, 471), shared
    refl = np.zeros((IOR_COUNT, OPD_COUNT, COS_COUNT, 3))
    trans = np.zeros_like(refl)
    for x in range(COS_COUNT):
        params = [row_parameters(x, z) for z in range(IOR_COUNT)]
        c = params[0][0]
        sin2 = max(1.0 - c * c, 0.0)
        n1 = np.array([p[2] for p in params])
        q0 = N_AMBIENT * c
        q1 = np.sqrt(np.maximum(n1 * n1 - sin2, 0.0))
        q2 = math.sqrt(N_BASE * N_BASE - sin2)
        n0s, n2s = N_AMBIENT ** 2, N_BASE ** 2
        r_total = np.zeros((IOR_COUNT, OPD_COUNT, lam.size))
        for r01, r12 in (((q0 - q1) / (q0 + q1), (q1 - q2) / (q1 + q2)),
                         ((n1 * n1 * q0 - n0s * q1) / (n1 * n1 * q0 + n0s * q1),
                          (n2s * q1 - n1 * n1 * q2) / (n2s * q1 + n1 * n1 * q2))):
            r01, r12 = r01[:, None, None], r12[:, None, None]
            b = (2.0 * r01 * r12) * cos2b
            r_total += (r01 * r01 + r12 * r12 + b) / (1.0 + (r01 * r12) ** 2 + b)
        r_total *= 0.5
        refl[:, :, x, :] = r_total @ weights
        trans[:, :, x, :] = (1.0 - r_total) @ weights
    return refl, trans


# --- checks ------------------------------------------------------------------------------
def check_against_tmm(x, z):
    """Max |dR| (s and p) of colour-science vs tmm.coh_tmm on row (x, z)."""
    _, angle_deg, n, d = row_parameters(x, z)
    ys = [0, 1, 37, 191, 383]
    lams = np.array([360.0, 451.0, 555.0, 700.0, 830.0])
    r, _ = thin_film_tmm([N_AMBIENT, n, N_BASE], d[ys], lams, angle_deg)
    worst = 0.0
    n_list = np.array([N_AMBIENT, n, N_BASE], dtype=complex)
    for i, lam in enumerate(lams):
        for k, y in enumerate(ys):
            for p, pol in enumerate("sp"):
                ref = tmm.coh_tmm(pol, n_list, [np.inf, float(d[y]), np.inf],
                                  math.radians(angle_deg), float(lam))["R"]
                worst = max(worst, abs(float(np.real(r[i, 0, k, p])) - ref))
    return worst, len(ys) * len(lams) * 2, angle_deg, n


def read_exr(path):
    """Minimal OpenEXR reader: single-part scan-line, NONE/ZIPS/ZIP, HALF/FLOAT channels.
    Returns {channel: (height, width) float array}."""
    data = path.read_bytes()
    # version 2; flags: no tiles (0x200), deep data (0x800) or multiple parts (0x1000)
    if data[:4] != b"\x76\x2f\x31\x01" or data[4] != 2 or data[5] & 0x1a:
        raise ValueError("not a single-part scan-line OpenEXR file")
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        name = data[pos:name_end].decode()
        typ = data[name_end + 1:type_end].decode()
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        attrs[name] = (typ, data[type_end + 5:type_end + 5 + size])
        pos = type_end + 5 + size
    pos += 1
    channels, raw = [], attrs["channels"][1]
    i = 0
    while raw[i] != 0:
        end = raw.index(b"\0", i)
        ptype, _, xs, ys = struct.unpack_from("<iB3xii", raw, end + 1)
        if (xs, ys) != (1, 1) or ptype not in (1, 2):
            raise ValueError("subsampled or UINT channels are not supported")
        channels.append((raw[i:end].decode(), "<f2" if ptype == 1 else "<f4"))
        i = end + 17
    compression = attrs["compression"][1][0]
    lines_per_chunk = {0: 1, 2: 1, 3: 16}.get(compression)
    if lines_per_chunk is None:
        raise ValueError(f"compression {compression} is not supported")
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    chunks = -(-height // lines_per_chunk)
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    out = {name: np.zeros((height, width), dtype=np.float32) for name, _ in channels}
    line_bytes = sum(width * np.dtype(dt).itemsize for _, dt in channels)
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        block = data[off + 8:off + 8 + size]
        lines = min(lines_per_chunk, y1 - y + 1)
        if size < lines * line_bytes:  # compressed
            t = np.frombuffer(zlib.decompress(block), dtype=np.uint8)
            t = ((np.cumsum(t.astype(np.int64) - 128) + 128) & 0xFF).astype(np.uint8)
            half = (t.size + 1) // 2
            block = np.empty_like(t)
            block[0::2], block[1::2] = t[:half], t[half:]
            block = block.tobytes()
        p = 0
        for row in range(y - y0, y - y0 + lines):
            for name, dt in channels:
                nbytes = width * np.dtype(dt).itemsize
                out[name][row] = np.frombuffer(block[p:p + nbytes], dtype=dt)
                p += nbytes
    return out


def baked_table(path):
    ch = read_exr(path)
    atlas = np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).astype(float)
    return atlas.reshape(IOR_COUNT, OPD_COUNT, COS_COUNT, 3)


def delta_e_2000(rgb_a, rgb_b, m, white):
    """CIEDE2000 between two linear sRGB arrays (via XYZ and CIELAB under the D65 white)."""
    m_inv = np.linalg.inv(m)
    xy = white[:2] / white.sum()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lab_a = colour.XYZ_to_Lab(rgb_a @ m_inv.T, xy)
        lab_b = colour.XYZ_to_Lab(rgb_b @ m_inv.T, xy)
        return colour.delta_E(lab_a, lab_b, method="CIE 2000")


def describe_worst(diff):
    z, y, x = np.unravel_index(np.nanargmax(diff), diff.shape)
    c, angle, n, d = row_parameters(x, z)
    return (f"at cos theta {c:.4g} ({angle:.2f} deg), OPD {y / (OPD_COUNT - 1) * OPD_MAX_NM:.1f} nm "
            f"(d {d[y]:.4g} nm), n {n:.4f}")


def compare(label, a, b, m, white):
    diff = np.max(np.abs(a - b), axis=-1)
    de = delta_e_2000(a, b, m, white)
    print(f"  {label}: max |dRGB| {np.nanmax(diff):.3e} ({describe_worst(diff)}); "
          f"CIEDE2000 max {np.nanmax(de):.3g}, 99.9th pct {np.nanpercentile(de, 99.9):.3g}, "
          f"mean {np.nanmean(de):.3g}; without the cos theta = 1e-6 column: max |dRGB| "
          f"{np.nanmax(diff[:, :, 1:]):.3e}, CIEDE2000 max {np.nanmax(de[:, :, 1:]):.3g}")


# --- driver ------------------------------------------------------------------------------
def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def run(args):
    if SINGLE_THREADED:
        mode = "numpy single-threaded (*_NUM_THREADS=1)"
    else:
        set_vars = [f"{v}={val}" for v, val in _ORIGINAL_ENV.items() if val is not None]
        mode = f"numpy default threads ({', '.join(set_vars) or 'no *_NUM_THREADS set'})"
    print(f"== {mode} ==")
    total_texels = COS_COUNT * OPD_COUNT * IOR_COUNT
    rows = all_rows()

    t_start = time.perf_counter()
    weights, m, white = colour_weights()
    stride = args.stride
    if stride is None:  # probe: time 4 spread rows, decide whether the full table fits
        probe = [(1, 3), (9, 13), (16, 22), (23, 31)]
        t0 = time.perf_counter()
        bake_rows(probe, weights)
        projected = (time.perf_counter() - t0) / len(probe) * len(rows)
        stride = 1 if projected <= args.max_seconds else 8
        if stride > 1:
            print(f"  probe projects {projected:.0f} s for the full table (> {args.max_seconds:.0f} s): "
                  f"timing 1 row in {stride} and extrapolating")
        t_start = time.perf_counter()
        weights, m, white = colour_weights()
    subset = row_subset(rows, stride)
    values_r, values_t, t_tmm = bake_rows(subset, weights)
    elapsed = time.perf_counter() - t_start

    texels = len(subset) * OPD_COUNT
    full = elapsed * len(rows) / len(subset)
    what = "full table" if stride == 1 else \
        f"1 row in {stride} ({len(subset)} of {len(rows)} rows, every angle and film index)"
    print(f"  colour-science thin_film_tmm, {what}: {texels:,} texels x {WAVELENGTHS_NM.size} "
          f"wavelengths x 2 polarisations, R and T colours")
    print(f"    time {elapsed:.2f} s (thin_film_tmm {t_tmm:.2f} s, rest {elapsed - t_tmm:.2f} s); "
          f"{texels / elapsed:,.0f} texels/s; {texels * WAVELENGTHS_NM.size / elapsed:,.3g} "
          f"spectral samples/s")
    if stride > 1:
        print(f"    projected full table ({total_texels:,} texels): {full:.1f} s (extrapolated "
              f"linearly from {len(subset)} rows)")
    print(f"    vs nacre bake ({NACRE_TIME_S} s for R and T, 2 threads, dev machine): "
          f"{full / NACRE_TIME_S:.0f}x slower")

    t0 = time.perf_counter()
    airy_r, airy_t = bake_airy(weights)
    t_airy = time.perf_counter() - t0
    print(f"  closed-form Airy formula in numpy (single lossless film only), full table: "
          f"{t_airy:.2f} s; {total_texels / t_airy:,.0f} texels/s; "
          f"{t_airy / NACRE_TIME_S:.2f}x nacre's time")

    if args.no_checks:
        return {"cs": full, "airy": t_airy}

    print("checks (untimed):")
    xz = (12, 20)
    worst, count, angle, n = check_against_tmm(*xz)
    print(f"  colour-science vs tmm.coh_tmm, row cos index {xz[0]}, film index {xz[1]} "
          f"({angle:.2f} deg, n {n:.4f}): max |dR| {worst:.2e} over {count} (s, p) values")
    worst, count, angle, n = check_against_tmm(0, 0)
    print(f"  same, grazing row (cos theta 1e-6, n {n:.6f}, d up to "
          f"{row_parameters(0, 0)[3][-1]:.3g} nm): max |dR| {worst:.2e} over {count} values")
    table_r, table_t = to_table(subset, values_r), to_table(subset, values_t)
    nonfinite = int(np.sum(~np.isfinite(values_r))) + int(np.sum(~np.isfinite(values_t)))
    print(f"  non-finite colour-science colours: {nonfinite}")
    compare("colour-science vs Airy, reflectance  ", table_r, airy_r, m, white)
    compare("colour-science vs Airy, transmittance", table_t, airy_t, m, white)
    for quantity, ours, ours_airy in (("reflectance", table_r, airy_r),
                                      ("transmittance", table_t, airy_t)):
        path = Path(f"{BAKED}.{quantity}.exr")
        if not path.exists():
            print(f"  {path} not found: comparison with nacre skipped")
            continue
        try:
            nacre = baked_table(path)
        except (ValueError, KeyError, struct.error, zlib.error) as e:
            print(f"  {path}: cannot read ({e}); comparison with nacre skipped")
            continue
        compare(f"nacre {quantity:13s} (half) vs colour-science", nacre, ours, m, white)
        compare(f"nacre {quantity:13s} (half) vs Airy          ", nacre, ours_airy, m, white)
    print("  (nacre: phase-adaptive Gauss-Legendre rule, ~500-900 nodes, stored as half floats; "
          "here: CIE 015 1 nm rectangle rule, 471 nodes, float64)")
    return {"cs": full, "airy": t_airy}


def main():
    ap = argparse.ArgumentParser(description="bake film-dielectric with numpy + colour-science "
                                             "and time it (baseline for nacre)")
    ap.add_argument("--threads", choices=["both", "1", "default"], default="both",
                    help="numpy threads: 1, the default, or both runs (default)")
    ap.add_argument("--stride", type=int, default=None,
                    help="run 1 row in N and extrapolate (default: all rows unless the "
                         "probe projects more than --max-seconds)")
    ap.add_argument("--max-seconds", type=float, default=300.0,
                    help="projected full-table time above which only 1 row in 8 is run")
    ap.add_argument("--no-checks", action="store_true", help="timings only")
    args = ap.parse_args()
    if not RECIPE.exists():
        sys.exit("run from the repository root (tables/recipes/film-dielectric.toml not found)")

    print("film-dielectric bake with numpy + colour-science (baseline for nacre)")
    print(f"  colour-science {colour.__version__}, tmm {importlib.metadata.version('tmm')}, "
          f"numpy {np.__version__}, Python {platform.python_version()}")
    print(f"  CPU: {cpu_model()}; nproc = {os.cpu_count()}"
          f" (affinity: {len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else '?'})")
    print(f"  table: {COS_COUNT} cos theta x {OPD_COUNT} OPD (0-{OPD_MAX_NM:.0f} nm) x {IOR_COUNT} "
          f"film index ({IOR_MIN}-{IOR_MAX}) = {COS_COUNT * OPD_COUNT * IOR_COUNT:,} texels; "
          f"1.0 | film | 1.5; linear sRGB, D65, CIE 1931 2 deg")
    print("  spectral rule: CIE 015 rectangle rule, 360-830 nm every 1 nm (471 wavelengths); "
          "nacre uses a phase-adaptive Gauss-Legendre rule (~500-900 nodes)")
    print()
    run(args)
    if args.threads == "both":
        env = dict(os.environ)
        for v, val in _ORIGINAL_ENV.items():
            if val is None:
                env.pop(v, None)
            else:
                env[v] = val
        child = [sys.executable, __file__, "--threads", "default", "--no-checks",
                 "--max-seconds", str(args.max_seconds)]
        if args.stride is not None:
            child += ["--stride", str(args.stride)]
        print()
        sys.stdout.flush()
        out = subprocess.run(child, env=env, capture_output=True, text=True, check=True).stdout
        print(out[out.index("== "):], end="")


if __name__ == "__main__":
    main()
