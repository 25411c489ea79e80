#!/usr/bin/env python3
"""nacre's exact thickness derivatives side by side with the differentiable TMMs of PyTorch,
tmm_fast 0.3.0 and DiffTMM 0.2.0, and with central finite differences of Byrnes' tmm (issue
33, part 1; BENCHMARKS.md, "Gradients side by side").

The work: 8 angles (0–70° every 10°) × 1000 wavelengths (400–800 nm) of 1, 4 and 8
constant-index films (indices 2.35, 1.38, 2.1, 1.46, 1.9, 1.6, 2.2, 1.7 top first,
thicknesses 60 + 17 j nm) on glass 1.52 in air — the stacks of ``spectrum_call.py`` — and
the derivatives of the unpolarised R = (R_s + R_p)/2 by every film's thickness. Timed, best
(shown; ``--stat median`` for the median: on a shared machine the best is the least
disturbed call) and median of N calls after warm-up, both in the JSON printed last, in a
subprocess per thread count (one thread and all cores: ``RAYON_NUM_THREADS`` for nacre,
``torch.set_num_threads`` for PyTorch):

* **the full Jacobian** ∂R/∂d_j at every (angle, wavelength) — nacre:
  ``nacre.spectrum(..., jacobian=True).dR_dd`` (the values come with it); PyTorch:
  ``torch.autograd.functional.jacobian(..., vectorize=True, strategy="forward-mode")``
  (one forward-mode pass per film, batched), the one way to get every point's derivatives
  without a backward pass per point;
* **the gradient of a scalar loss** Σ R (what an optimiser steps on) — nacre: the same call
  and a sum over the points; PyTorch: one forward and one backward pass.

Agreement: the largest difference of each Jacobian from nacre's, relative to the largest
derivative (``max|ΔJ| / max|J|``), and the largest elementwise relative difference over the
entries at least 1 % of that (``max rel``). Byrnes' ``tmm.coh_tmm`` takes central
differences (h = 10⁻³ nm) on the first 50 wavelengths of every angle (its rate per point is
reported; it is 10⁴× slower).

Conventions checked before timing, against Byrnes' tmm: tmm_fast takes metres and its own
complex128 indices (float64 throughout); DiffTMM 0.2.0 computes in complex64 (its dtype is
fixed) and multiplies its layer matrices M_L···M_1, so its results are Byrnes' with the
layers given **bottom first**: the bench gives them so (and checks it).

Run from the repository root, in a virtual environment with nacre installed
(``pip install ./python``) and ``pip install torch tmm_fast==0.3.0 difftmm==0.2.0 tmm``:

    python python/bench/gradient.py [--reps 10] [--films 1 4 8]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

ANGLES_DEG = np.arange(0.0, 71.0, 10.0)
WAVELENGTHS = np.linspace(400.0, 800.0, 1000)
FILM_INDICES = [2.35, 1.38, 2.1, 1.46, 1.9, 1.6, 2.2, 1.7]
SUBSTRATE = 1.52
FD_WAVELENGTHS = 50
FD_STEP_NM = 1e-3


def films(count: int) -> list[tuple[float, float]]:
    return [(FILM_INDICES[j], 60.0 + 17.0 * j) for j in range(count)]


def best_median(fn, reps: int) -> dict:
    for _ in range(2):
        fn()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return {"best_s": min(times), "median_s": float(np.median(times))}


# --- the three implementations: (values R, Jacobian dR/dd) as (angles, wavelengths[, films]) ---


def nacre_jacobian(count: int):
    import nacre

    stack = nacre.Stack(1.0, films(count), SUBSTRATE)
    s = nacre.spectrum(stack, ANGLES_DEG, WAVELENGTHS, jacobian=True)
    return np.asarray(s.R), np.asarray(s.dR_dd)


def _torch_setup(count: int, package: str):
    """R(d) as a torch function of the film thicknesses (nm), for `package`."""
    import torch

    layers = films(count)
    if package == "tmm_fast":
        import tmm_fast

        n = torch.tensor(np.array([1.0] + [n for n, _ in layers] + [SUBSTRATE], dtype=complex)).reshape(1, -1)
        theta = torch.tensor(np.radians(ANGLES_DEG))
        lam_m = torch.tensor(WAVELENGTHS * 1e-9)
        inf = torch.tensor([np.inf], dtype=torch.float64)

        def r_of(d_nm):
            t = torch.cat([inf, d_nm * 1e-9, inf]).reshape(1, -1)
            rs = tmm_fast.coh_tmm("s", n, t, theta, lam_m)["R"]
            rp = tmm_fast.coh_tmm("p", n, t, theta, lam_m)["R"]
            return ((rs + rp) / 2)[0]

        return r_of
    import difftmm

    # bottom first: see the module docs
    n = torch.tensor(np.array([n for n, _ in layers][::-1], dtype=complex)).reshape(1, -1)
    theta = torch.tensor(np.radians(ANGLES_DEG)).reshape(1, -1)
    lam = torch.tensor(WAVELENGTHS).reshape(1, -1)

    def r_of(d_nm):
        _, _, rs, rp = difftmm.create_jones_matrix_isotropic(
            n, torch.flip(d_nm, [0]).reshape(1, -1), lam, 1.0, SUBSTRATE, theta
        )
        return ((rs.abs() ** 2 + rp.abs() ** 2) / 2)[0].T

    return r_of


def torch_jacobian(count: int, package: str):
    import torch

    r_of = _torch_setup(count, package)
    d = torch.tensor([t for _, t in films(count)], dtype=torch.float64)
    j = torch.autograd.functional.jacobian(r_of, d, vectorize=True, strategy="forward-mode")
    return r_of(d).detach().numpy().astype(np.float64), j.detach().numpy().astype(np.float64)


def tmm_finite_differences(count: int):
    """Byrnes' tmm: R and central differences on the first FD_WAVELENGTHS wavelengths."""
    import tmm

    layers = films(count)
    n = [1.0] + [n for n, _ in layers] + [SUBSTRATE]
    d0 = [np.inf] + [d for _, d in layers] + [np.inf]

    def r(d, theta, wl):
        return 0.5 * (tmm.coh_tmm("s", n, d, theta, wl)["R"] + tmm.coh_tmm("p", n, d, theta, wl)["R"])

    wl = WAVELENGTHS[:FD_WAVELENGTHS]
    values = np.zeros((ANGLES_DEG.size, wl.size))
    jac = np.zeros((ANGLES_DEG.size, wl.size, count))
    t0 = time.perf_counter()
    for a, angle in enumerate(np.radians(ANGLES_DEG)):
        for w, lam in enumerate(wl):
            values[a, w] = r(d0, angle, lam)
            for j in range(count):
                up, down = list(d0), list(d0)
                up[j + 1] += FD_STEP_NM
                down[j + 1] -= FD_STEP_NM
                jac[a, w, j] = (r(up, angle, lam) - r(down, angle, lam)) / (2 * FD_STEP_NM)
    per_point = (time.perf_counter() - t0) / (ANGLES_DEG.size * wl.size)
    return values, jac, per_point


def agreement(j: np.ndarray, reference: np.ndarray) -> dict:
    scale = float(np.max(np.abs(reference)))
    big = np.abs(reference) >= 0.01 * scale
    return {
        "max_abs_over_max": float(np.max(np.abs(j - reference)) / scale),
        "max_rel": float(np.max(np.abs(j[big] - reference[big]) / np.abs(reference[big]))),
    }


# --- timing, one process per thread count ---


def worker(threads: int, counts: list[int], reps: int) -> dict:
    import torch

    torch.set_num_threads(threads)
    import nacre

    out: dict = {"torch_threads": torch.get_num_threads()}
    for count in counts:
        stack = nacre.Stack(1.0, films(count), SUBSTRATE)
        row: dict = {}

        def nacre_call():
            return nacre.spectrum(stack, ANGLES_DEG, WAVELENGTHS, jacobian=True).dR_dd

        row["nacre_jacobian"] = best_median(nacre_call, reps)
        row["nacre_gradient"] = best_median(lambda: nacre_call().sum(axis=(0, 1)), reps)
        for package in ("tmm_fast", "difftmm"):
            r_of = _torch_setup(count, package)
            d0 = torch.tensor([t for _, t in films(count)], dtype=torch.float64)

            def full():
                return torch.autograd.functional.jacobian(r_of, d0, vectorize=True, strategy="forward-mode")

            def gradient():
                d = d0.clone().requires_grad_(True)
                r_of(d).sum().backward()
                return d.grad

            row[f"{package}_jacobian"] = best_median(full, max(2, reps // 3))
            row[f"{package}_gradient"] = best_median(gradient, reps)
        out[str(count)] = row
    return out


def in_subprocess(threads: int, counts: list[int], reps: int) -> dict:
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    r = subprocess.run(
        [sys.executable, __file__, "--worker", str(threads), "--reps", str(reps), "--films", *map(str, counts)],
        env=env, check=True, capture_output=True, text=True,
    )
    return json.loads(r.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=10)
    ap.add_argument("--films", type=int, nargs="+", default=[1, 4, 8])
    ap.add_argument("--stat", choices=["best", "median"], default="best",
                    help="the time shown (best: the least disturbed call on a shared machine)")
    ap.add_argument("--worker", type=int, default=0, help=argparse.SUPPRESS)
    a = ap.parse_args()
    warnings.filterwarnings("ignore", category=FutureWarning)  # torch.jit.script in the packages
    if a.worker:
        print(json.dumps(worker(a.worker, a.films, a.reps)))
        return
    import importlib.metadata as md

    import nacre
    import torch

    versions = {p: md.version(p) for p in ("torch", "tmm_fast", "difftmm", "tmm")}
    cores = os.cpu_count() or 1
    points = ANGLES_DEG.size * WAVELENGTHS.size
    print(f"{ANGLES_DEG.size} angles x {WAVELENGTHS.size} wavelengths = {points} points; nacre "
          f"{nacre.__version__}, " + ", ".join(f"{k} {v}" for k, v in versions.items())
          + f", numpy {np.__version__}, Python {sys.version.split()[0]}, {cores} cores")
    print("\nAgreement with nacre's Jacobian (max|dJ|/max|J|; max elementwise rel. over |J| >= 1% max):")
    torch.set_num_threads(1)
    for count in a.films:
        values, ours = nacre_jacobian(count)
        line = []
        for package in ("tmm_fast", "difftmm"):
            theirs_r, theirs_j = torch_jacobian(count, package)
            g = agreement(theirs_j, ours)
            line.append(f"{package} R {np.max(np.abs(theirs_r - values)):.1e}, "
                        f"J {g['max_abs_over_max']:.1e} / {g['max_rel']:.1e}")
        fd_r, fd_j, per_point = tmm_finite_differences(count)
        g = agreement(fd_j, ours[:, :FD_WAVELENGTHS])
        line.append(f"tmm FD R {np.max(np.abs(fd_r - values[:, :FD_WAVELENGTHS])):.1e}, "
                    f"J {g['max_abs_over_max']:.1e} / {g['max_rel']:.1e} ({per_point * 1e3:.2f} ms/point)")
        print(f"  {count} films: " + "; ".join(line))
    runs = {1: in_subprocess(1, a.films, a.reps)}
    if cores > 1:
        runs[cores] = in_subprocess(cores, a.films, a.reps)
    print(f"\nTimes ({a.stat} of the calls, ms; in brackets: x nacre's time on the same threads):")
    print(f"{'threads':>7} {'films':>5} {'nacre J':>9} {'tmm_fast J':>16} {'DiffTMM J':>16} "
          f"{'nacre grad':>10} {'tmm_fast grad':>16} {'DiffTMM grad':>16}")
    for threads, run in runs.items():
        for count in a.films:
            row = run[str(count)]
            ms = {k: v[f"{a.stat}_s"] * 1e3 for k, v in row.items()}
            nj, ng = ms["nacre_jacobian"], ms["nacre_gradient"]
            print(f"{threads:7d} {count:5d} {nj:9.2f} "
                  f"{ms['tmm_fast_jacobian']:9.1f} ({ms['tmm_fast_jacobian'] / nj:4.0f}x) "
                  f"{ms['difftmm_jacobian']:9.1f} ({ms['difftmm_jacobian'] / nj:4.0f}x) "
                  f"{ng:10.2f} {ms['tmm_fast_gradient']:9.1f} ({ms['tmm_fast_gradient'] / ng:4.0f}x) "
                  f"{ms['difftmm_gradient']:9.1f} ({ms['difftmm_gradient'] / ng:4.0f}x)")
    print("\n" + json.dumps({str(k): v for k, v in runs.items()}))


if __name__ == "__main__":
    main()
