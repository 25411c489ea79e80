#!/usr/bin/env python3
"""Speed of ``nacre.spectrum`` on the Rust benchmark's single-film sweep, against the Rust
benchmark itself and colour-science's ``thin_film_tmm``, in one run (BENCHMARKS.md,
"Python").

The sweep: ambient 1.0 | film n = 1.33 | substrate 1.5 (constant indices), 90 angles
(0–89°) × 81 wavelengths (380–780 nm) × 100 thicknesses (0–990 nm): 729 000 evaluations,
each R_s, R_p, T_s, T_p in f64 — ``cargo bench -p nacre-optics --bench sweep``'s
``single-film/90x81x100``. Timed:

* ``nacre.spectrum(stack, angles, wavelengths, thickness_nm=…)`` from Python, one thread
  (``RAYON_NUM_THREADS=1``, in a subprocess) and all threads; best and median of N calls
  after warm-up, the numpy arrays included;
* the Rust benchmark (criterion's mean and interval), unless ``--no-rust`` or no cargo;
* ``colour.phenomena.thin_film_tmm`` on the same grid (one call over the whole grid, and
  one call per angle), numpy single-threaded, best of N; and its largest difference from
  nacre's R_s, R_p, T_s, T_p (a check that both compute the same thing).

Run from the repository root, in a virtual environment with nacre installed
(``pip install ./python``) and ``pip install colour-science``:

    python python/bench/sweep.py [--reps 20] [--no-rust]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import pathlib  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

import nacre  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]
ANGLES = np.arange(90, dtype=float)
WAVELENGTHS = 380.0 + 5.0 * np.arange(81)
THICKNESSES = 10.0 * np.arange(100)
EVALS = ANGLES.size * WAVELENGTHS.size * THICKNESSES.size


def time_nacre(reps: int) -> dict:
    stack = nacre.Stack(1.0, [(1.33, 0.0)], 1.5)
    run = lambda: nacre.spectrum(stack, ANGLES, WAVELENGTHS, thickness_nm=THICKNESSES)  # noqa: E731
    for _ in range(3):
        run()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return {"best_s": min(times), "median_s": float(np.median(times))}


def nacre_in_subprocess(reps: int, threads: int) -> dict:
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run(
        [sys.executable, __file__, "--worker", "--reps", str(reps)],
        env=env, check=True, capture_output=True, text=True,
    ).stdout
    return json.loads(out)


def rust_bench() -> dict:
    """Runs criterion's single-film benches; returns {name: (low, mean, high) seconds}."""
    if shutil.which("cargo") is None:
        return {}
    r = subprocess.run(
        ["cargo", "bench", "-p", "nacre-optics", "--bench", "sweep", "--", "single-film/90x81x100"],
        cwd=REPO, capture_output=True, text=True,
    )
    if r.returncode != 0:
        print(r.stderr[-2000:], file=sys.stderr)
        return {}
    scale = {"ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    found = {}
    for m in re.finditer(
        r"single-film/(90x81x100 [a-z ]+?)\s+time:\s+\[([\d.]+) (\S+) ([\d.]+) (\S+) ([\d.]+) (\S+)\]",
        r.stdout,
    ):
        name = m.group(1).strip()
        found[name] = tuple(float(m.group(i)) * scale[m.group(i + 1)] for i in (2, 4, 6))
    return found


def time_colour(reps: int) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
        from colour.phenomena import thin_film_tmm
    n = [1.0, 1.33, 1.5]

    def whole():
        return thin_film_tmm(n, THICKNESSES, WAVELENGTHS, ANGLES)

    def per_angle():
        for a in ANGLES:
            thin_film_tmm(n, THICKNESSES, WAVELENGTHS, a)

    out = {"version": colour.__version__}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, fn in (("whole grid", whole), ("per angle", per_angle)):
            fn()
            best = min(_timed(fn) for _ in range(reps))
            out[name] = best
        R, T = whole()  # shape (wavelengths, angles, thicknesses, 2): s, p
    s = nacre.spectrum(nacre.Stack(1.0, [(1.33, 0.0)], 1.5), ANGLES, WAVELENGTHS, thickness_nm=THICKNESSES)
    ours = {"R_s": s.R_s, "R_p": s.R_p, "T_s": s.T_s, "T_p": s.T_p}
    theirs = {
        "R_s": np.real(R[..., 0]).transpose(1, 0, 2), "R_p": np.real(R[..., 1]).transpose(1, 0, 2),
        "T_s": np.real(T[..., 0]).transpose(1, 0, 2), "T_p": np.real(T[..., 1]).transpose(1, 0, 2),
    }
    out["max_diff"] = max(float(np.nanmax(np.abs(ours[k] - theirs[k]))) for k in ours)
    return out


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def rate(seconds: float) -> str:
    return f"{EVALS / seconds / 1e6:6.1f} M/s"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=20)
    ap.add_argument("--no-rust", action="store_true", help="skip the Rust benchmark")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        print(json.dumps(time_nacre(a.reps)))
        return
    print(f"single film 1.0 | 1.33 | 1.5, {ANGLES.size} x {WAVELENGTHS.size} x {THICKNESSES.size} "
          f"= {EVALS} evaluations; nacre {nacre.__version__}, numpy {np.__version__}, "
          f"Python {sys.version.split()[0]}, {os.cpu_count()} CPUs")
    one = nacre_in_subprocess(a.reps, 1)
    threads = os.cpu_count() or 1
    alln = nacre_in_subprocess(a.reps, threads)
    rust = {} if a.no_rust else rust_bench()
    cs = time_colour(max(3, a.reps // 4))
    print(f"{'what':52s} {'time':>22s} {'rate':>10s}")
    print(f"{'nacre.spectrum, Python, 1 thread (best / median)':52s} "
          f"{one['best_s']*1e3:8.2f} / {one['median_s']*1e3:6.2f} ms {rate(one['best_s'])}")
    print(f"{f'nacre.spectrum, Python, {threads} threads (best / median)':52s} "
          f"{alln['best_s']*1e3:8.2f} / {alln['median_s']*1e3:6.2f} ms {rate(alln['best_s'])}")
    for name, (lo, mean, hi) in sorted(rust.items()):
        print(f"{'Rust criterion ' + name + ' [low mean high]':52s} "
              f"{lo*1e3:6.2f} {mean*1e3:6.2f} {hi*1e3:6.2f} ms {rate(mean)}")
    for name in ("whole grid", "per angle"):
        print(f"{'colour-science ' + cs['version'] + ' thin_film_tmm, ' + name:52s} "
              f"{cs[name]*1e3:15.1f} ms {rate(cs[name])}")
    print()
    if "90x81x100 one thread" in rust:
        mean = rust["90x81x100 one thread"][1]
        print(f"Python / Rust, one thread: {one['median_s'] / mean:.3f} (median over criterion mean), "
              f"{one['best_s'] / rust['90x81x100 one thread'][0]:.3f} (best over criterion low)")
    best_cs = min(cs["whole grid"], cs["per angle"])
    print(f"nacre (Python, 1 thread) vs colour-science's best: {best_cs / one['best_s']:.1f}x faster; "
          f"max |difference| of R_s, R_p, T_s, T_p: {cs['max_diff']:.2e}")


if __name__ == "__main__":
    main()
