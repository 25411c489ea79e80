#!/usr/bin/env python3
"""The cost of one ``nacre.spectrum`` call against the multilayer kernel alone and against
tmm_faster and Byrnes' tmm (issue 33, part 6; BENCHMARKS.md, "From Python: one spectrum
call").

The work: one angle (30°) × 10⁵ wavelengths (380–780 nm) of 1, 5 and 8 constant-index films
(indices 2.35, 1.38, 2.1, 1.46, 1.9, 1.6, 2.2, 1.7 top first, thicknesses 60 + 17 j nm) on
glass 1.52 in air, R_s, R_p, T_s, T_p in f64 — the stacks of ``cargo bench -p nacre-optics --bench
sweep -- spectrum-call``. Timed, one thread each, best and median of N calls after warm-up:

* ``nacre.spectrum(stack, [30], wavelengths)``, numpy arrays back (``RAYON_NUM_THREADS=1``,
  in a subprocess);
* the kernel alone on the same stack (criterion's ``spectrum-call/… kernel``: a sweep
  prepared beforehand, into a buffer allocated beforehand), unless ``--no-rust`` or no cargo;
* ``tmm_faster.calc_coherent`` (pip ``tmm_faster`` 0.1.3, C++/OpenMP with
  ``OMP_NUM_THREADS=1``) on the same grid, its index matrix built beforehand; and its
  largest difference from nacre's R_s, R_p, T_s, T_p;
* Byrnes' ``tmm.coh_tmm`` (pip ``tmm``), s and p per wavelength, on the first 2000
  wavelengths (its rate per evaluation).

Run from the repository root, in a virtual environment with nacre installed
(``pip install ./python``) and ``pip install tmm_faster==0.1.3 tmm``:

    python python/bench/spectrum_call.py [--reps 20] [--no-rust]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import pathlib  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]
ANGLE_DEG = 30.0
WAVELENGTHS = 380.0 + 0.004 * np.arange(100_000)
FILM_INDICES = [2.35, 1.38, 2.1, 1.46, 1.9, 1.6, 2.2, 1.7]
FILMS = (1, 5, 8)
BYRNES_WAVELENGTHS = 2000


def films(count: int) -> list[tuple[float, float]]:
    return [(FILM_INDICES[j], 60.0 + 17.0 * j) for j in range(count)]


def best_median(fn, reps: int) -> dict:
    for _ in range(3):
        fn()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return {"best_s": min(times), "median_s": float(np.median(times))}


def time_nacre(reps: int) -> dict:
    import nacre

    out = {}
    angles = np.array([ANGLE_DEG])
    for count in FILMS:
        stack = nacre.Stack(1.0, films(count), 1.52)
        out[str(count)] = best_median(lambda: nacre.spectrum(stack, angles, WAVELENGTHS), reps)
    return out


def nacre_one_thread(reps: int) -> dict:
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, __file__, "--worker", "--reps", str(reps)],
        env=env, check=True, capture_output=True, text=True,
    ).stdout
    return json.loads(out)


def rust_kernel() -> dict:
    """criterion's ``spectrum-call/N films 1x100000 kernel``: {films: (low, mean, high) s}."""
    if shutil.which("cargo") is None:
        return {}
    r = subprocess.run(
        ["cargo", "bench", "-p", "nacre-optics", "--bench", "sweep", "--", "spectrum-call/.*kernel",
         "--warm-up-time", "1", "--measurement-time", "5"],
        cwd=REPO, capture_output=True, text=True,
    )
    if r.returncode != 0:
        print(r.stderr[-2000:], file=sys.stderr)
        return {}
    scale = {"ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    found = {}
    for m in re.finditer(
        r"spectrum-call/(\d+) films 1x100000 kernel\s+time:\s+\[([\d.]+) (\S+) ([\d.]+) (\S+) ([\d.]+) (\S+)\]",
        r.stdout,
    ):
        found[m.group(1)] = tuple(float(m.group(i)) * scale[m.group(i + 1)] for i in (2, 4, 6))
    return found


def time_tmm_faster(reps: int) -> dict:
    import nacre
    import tmm_faster

    out = {"version": getattr(tmm_faster, "__version__", "?")}
    angles = np.array([ANGLE_DEG])
    for count in FILMS:
        layers = films(count)
        n = np.array([1.0] + [n for n, _ in layers] + [1.52], dtype=complex)
        n_matrix = np.ascontiguousarray(np.tile(n, (WAVELENGTHS.size, 1)))
        d = np.array([np.inf] + [d for _, d in layers] + [np.inf])
        out[str(count)] = best_median(
            lambda: tmm_faster.calc_coherent(n_matrix, d, angles, WAVELENGTHS), reps
        )
        theirs = tmm_faster.calc_coherent(n_matrix, d, angles, WAVELENGTHS)
        ours = nacre.spectrum(nacre.Stack(1.0, layers, 1.52), angles, WAVELENGTHS)
        diff = max(
            float(np.max(np.abs(np.asarray(getattr(ours, key))[0] - np.asarray(theirs[key])[:, 0])))
            for key in ("R_s", "R_p", "T_s", "T_p")
        )
        out[str(count)]["max_diff"] = diff
    return out


def time_byrnes() -> dict:
    import tmm

    out = {}
    theta = np.radians(ANGLE_DEG)
    wl = WAVELENGTHS[:BYRNES_WAVELENGTHS]
    for count in FILMS:
        layers = films(count)
        n = [1.0] + [n for n, _ in layers] + [1.52]
        d = [np.inf] + [d for _, d in layers] + [np.inf]

        def run():
            for w in wl:
                tmm.coh_tmm("s", n, d, theta, w)
                tmm.coh_tmm("p", n, d, theta, w)

        t0 = time.perf_counter()
        run()
        out[str(count)] = (time.perf_counter() - t0) / wl.size
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=20)
    ap.add_argument("--no-rust", action="store_true", help="skip the kernel's criterion bench")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        print(json.dumps(time_nacre(a.reps)))
        return
    import nacre

    evals = WAVELENGTHS.size
    print(f"1 angle x {evals} wavelengths, 1/5/8 constant-index films on 1.52, one thread; "
          f"nacre {nacre.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}")
    kernel = {} if a.no_rust else rust_kernel()
    ours = nacre_one_thread(a.reps)
    faster = time_tmm_faster(a.reps)
    byrnes = time_byrnes()
    rate = lambda s: evals / s / 1e6  # noqa: E731
    print(f"{'films':>5} {'nacre.spectrum M/s':>20} {'kernel M/s':>11} {'call/kernel':>11} "
          f"{'tmm_faster M/s':>15} {'x tmm_faster':>12} {'tmm M/s':>8} {'x tmm':>8} {'max|diff|':>9}")
    for count in FILMS:
        k = str(count)
        call = ours[k]["median_s"]
        kern = kernel.get(k)
        kern_rate = f"{rate(kern[1]):11.1f}" if kern else f"{'-':>11}"
        ratio = f"{kern[1] / call:11.2f}" if kern else f"{'-':>11}"
        tf = faster[k]["median_s"]
        per_eval = byrnes[k]
        print(f"{count:5d} {rate(call):20.1f} {kern_rate} {ratio} {rate(tf):15.2f} "
              f"{tf / call:12.1f} {1e-6 / per_eval:8.4f} {per_eval * evals / call:8.0f} "
              f"{faster[k]['max_diff']:9.1e}")
    print("(medians; nacre.spectrum best: "
          + ", ".join(f"{c} films {rate(ours[str(c)]['best_s']):.1f} M/s" for c in FILMS) + ")")


if __name__ == "__main__":
    main()
