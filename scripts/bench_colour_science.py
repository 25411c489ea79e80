#!/usr/bin/env python3
"""Throughput of colour-science's vectorised numpy thin-film TMM (baseline for nacre).

What it measures
----------------
* ``colour.phenomena.thin_film_tmm(n, t, wavelength, theta)`` (colour-science
  0.4.x, module ``colour/phenomena/interference.py``, built on
  ``colour.phenomena.tmm.matrix_transfer_tmm``).  For a single film it
  evaluates the full outer product angles x wavelengths x thicknesses in one
  call and returns R and T with shape (W, A, T, 2), both polarisations at
  once.  One *evaluation* = one (angle, wavelength, thickness) triple with
  both polarisations (R_s, R_p, T_s, T_p), counted once.
* The stack is a single lossless film: ambient 1.0 | film n = 1.33 |
  substrate 1.5 (constant indices), thickness 50..1040 nm, 380..780 nm,
  0..89 deg.  Several grid shapes are timed (one big call, and the same work
  split into per-angle calls); each shape is run several times and the best
  wall time is kept.
* ``colour.phenomena.multilayer_tmm(n, t, wavelength, theta)`` on nacre's
  five-layer dispersive stack (the ``five-layer-dispersive`` and
  ``five-distinct-dispersive`` groups of ``cargo bench -p nacre-optics
  --bench sweep``: TiO2 56.45 nm | MgF2 99.75 | TiO2 56.45 (or Si 20) | fused
  silica 120 | Au 10 on BK7 in air, 0..89 deg x 380..780 nm every 1 nm), the
  indices read from ``tables/materials/`` by ``gen_tmm_golden.py``'s own
  refractiveindex.info reader (not nacre's) and resolved once per wavelength
  outside the timing.  One evaluation = one (angle, wavelength) pair with
  both polarisations.
* For comparison, Byrnes' scalar ``tmm.coh_tmm`` (one call per polarisation
  per point); its evaluations/s = 1 / (time of the 's' call + the 'p' call).
* Correctness: colour-science's R and T are compared with tmm at sampled grid
  points for the lossless film (expected to agree to ~1e-15).  Two further
  informational checks show known limitations of colour-science 0.4.7: an
  absorbing substrate at oblique incidence (its Snell's law uses Re(n) and its
  T uses a real refraction angle) and a dispersive film at oblique incidence
  (its per-layer angles are computed from the first wavelength's indices only).

numpy is forced single-threaded (OMP/OPENBLAS/MKL/NUMEXPR_NUM_THREADS=1 are
set before numpy is imported) so the numbers compare with one CPU core.

Run (from the repository root; takes ~1 minute):

    python3 scripts/bench_colour_science.py [--reps 5] [--quick]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
             "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import importlib.metadata  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # "Matplotlib related API features are not available"
    import colour  # noqa: E402
    from colour.phenomena import multilayer_tmm, thin_film_tmm  # noqa: E402

import tmm  # noqa: E402

from gen_tmm_golden import parse_material  # noqa: E402  (scripts/ is on sys.path)

N_AMB, N_FILM, N_SUB = 1.0, 1.33, 1.5


def grid(n_ang, n_wl, n_t):
    ang = np.linspace(0.0, 89.0, n_ang)
    wl = np.linspace(380.0, 780.0, n_wl)
    th = np.linspace(50.0, 1040.0, n_t)
    return ang, wl, th


def best_of(fn, reps):
    best = math.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bench_colour(shape, reps, per_angle=False):
    ang, wl, th = grid(*shape)
    n = [N_AMB, N_FILM, N_SUB]
    if per_angle:
        def run():
            for a in ang:
                thin_film_tmm(n, th, wl, a)
    else:
        def run():
            thin_film_tmm(n, th, wl, ang)
    run()  # warm-up
    dt = best_of(run, reps)
    evals = len(ang) * len(wl) * len(th)
    return evals, dt


def bench_tmm(reps, n_points=2000):
    rng = np.random.default_rng(1)
    pts = [(math.radians(rng.uniform(0, 89)), rng.uniform(380, 780), rng.uniform(50, 1040))
           for _ in range(n_points)]
    n_list = np.array([N_AMB, N_FILM, N_SUB], dtype=complex)

    def run():
        for th0, lam, d in pts:
            tmm.coh_tmm("s", n_list, [np.inf, d, np.inf], th0, lam)
            tmm.coh_tmm("p", n_list, [np.inf, d, np.inf], th0, lam)

    run()
    dt = best_of(run, reps)
    return n_points, dt


# The stacks of nacre's five-layer sweep benchmarks (crates/optics/benches/common/mod.rs),
# films top first: (material, thickness in nm), on BK7 in air.
FIVE_LAYER = [("tio2", 56.45), ("mgf2", 99.75), ("tio2", 56.45), ("fused-silica", 120.0),
              ("au", 10.0)]
FIVE_DISTINCT = [("tio2", 56.45), ("mgf2", 99.75), ("si", 20.0), ("fused-silica", 120.0),
                 ("au", 10.0)]


def stack_indices(films, wl):
    """(media, wavelengths) complex indices: air, the films, BK7 (refractiveindex.info data)."""
    names = ["air"] + [m for m, _ in films] + ["bk7"]
    return np.array([[parse_material(m).nk(w / 1000.0) for w in wl] for m in names])


def bench_multilayer(films, reps):
    ang = np.arange(90, dtype=float)  # 0..89 deg, as nacre's bench
    wl = 380.0 + np.arange(401, dtype=float)  # 380..780 nm every 1 nm
    n = stack_indices(films, wl)
    t = [d for _, d in films]

    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            multilayer_tmm(n, t, wl, ang)

    run()  # warm-up
    dt = best_of(run, reps)
    return len(ang) * len(wl), dt


def multilayer_vs_tmm(films, max_points=60, seed=3):
    """Max |colour - tmm| of the five-layer stack at sampled (angle, wavelength) points."""
    ang = np.array([0.0, 30.0, 60.0, 85.0])
    wl = np.linspace(380.0, 780.0, 21)
    n = stack_indices(films, wl)
    d_list = [np.inf] + [d for _, d in films] + [np.inf]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        R, T = multilayer_tmm(n, [d for _, d in films], wl, ang)
    R, T = np.real(R), np.real(T)
    rng = np.random.default_rng(seed)
    idx = [(i, j) for i in range(len(wl)) for j in range(len(ang))]
    idx = [idx[m] for m in rng.choice(len(idx), min(max_points, len(idx)), replace=False)]
    worst = {0.0: 0.0, "oblique": 0.0}
    for i, j in idx:
        ref = tmm_point(list(n[:, i]), d_list, float(ang[j]), float(wl[i]))
        got = np.array([R[i, j, 0, 0], R[i, j, 0, 1], T[i, j, 0, 0], T[i, j, 0, 1]])
        key = 0.0 if ang[j] == 0.0 else "oblique"
        diff = float(np.max(np.abs(got - ref))) if np.all(np.isfinite(got)) else math.inf
        worst[key] = max(worst[key], diff)
    return worst, len(idx)


def tmm_point(n_list, d_list, ang_deg, lam):
    th0 = math.radians(ang_deg)
    s = tmm.coh_tmm("s", np.array(n_list, dtype=complex), d_list, th0, lam)
    p = tmm.coh_tmm("p", np.array(n_list, dtype=complex), d_list, th0, lam)
    return np.array([s["R"], p["R"], s["T"], p["T"]], dtype=float)


def compare(n_stack, ang, wl, th, n_tmm_for_wl, max_points=300, seed=2):
    """Max |colour - tmm| over sampled grid points of a single-film outer product."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        R, T = thin_film_tmm(n_stack, th, wl, ang)
    R, T = np.real(R), np.real(T)
    rng = np.random.default_rng(seed)
    idx = [(i, j, k) for i in range(len(wl)) for j in range(len(ang)) for k in range(len(th))]
    if len(idx) > max_points:
        idx = [idx[m] for m in rng.choice(len(idx), max_points, replace=False)]
    worst = 0.0
    nan_count = 0
    for i, j, k in idx:
        ref = tmm_point(n_tmm_for_wl(i), [np.inf, float(th[k]), np.inf], float(ang[j]), float(wl[i]))
        got = np.array([R[i, j, k, 0], R[i, j, k, 1], T[i, j, k, 0], T[i, j, k, 1]])
        if not np.all(np.isfinite(got)):
            nan_count += 1
            continue
        worst = max(worst, float(np.max(np.abs(got - ref))))
    return worst, len(idx), nan_count


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def main():
    ap = argparse.ArgumentParser(description="benchmark colour-science thin_film_tmm vs tmm")
    ap.add_argument("--reps", type=int, default=5, help="repetitions per timing (best kept)")
    ap.add_argument("--quick", action="store_true", help="smaller grids, fewer reps")
    args = ap.parse_args()
    reps = 2 if args.quick else args.reps

    print("colour-science thin-film TMM benchmark")
    print(f"  colour-science {colour.__version__}, tmm {importlib.metadata.version('tmm')}, "
          f"numpy {np.__version__}, Python {platform.python_version()}")
    print(f"  CPU: {cpu_model()}; nproc = {os.cpu_count()}"
          f" (affinity: {len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else '?'})")
    print("  numpy forced single-threaded: OMP_NUM_THREADS=OPENBLAS_NUM_THREADS="
          "MKL_NUM_THREADS=1 set before import")
    print(f"  stack: {N_AMB} | film n={N_FILM} | {N_SUB}; best of {reps} repetitions; "
          "1 evaluation = (angle, wavelength, thickness) with s+p R,T")
    print()

    shapes = [
        ("one call", (90, 81, 100), False),
        ("one call", (9, 81, 1000), False),
        ("one call", (900, 81, 10), False),
        ("one call", (30, 81, 30), False),
        ("per-angle calls", (90, 81, 100), True),
    ]
    if args.quick:
        shapes = [("one call", (30, 81, 30), False), ("per-angle calls", (30, 81, 30), True)]

    rows = []
    for label, shape, per_angle in shapes:
        evals, dt = bench_colour(shape, reps, per_angle)
        rows.append((f"colour thin_film_tmm, {label}", "x".join(map(str, shape)), evals, dt))
    n_pts, dt = bench_tmm(reps, 500 if args.quick else 2000)
    rows.append(("tmm.coh_tmm ('s' + 'p' calls)", f"{n_pts} pts", n_pts, dt))

    print(f"{'method':40s} {'A x W x T':>12s} {'evals':>9s} {'best s':>9s} "
          f"{'evals/s':>12s} {'us/eval':>9s}")
    for name, shp, evals, dt in rows:
        print(f"{name:40s} {shp:>12s} {evals:9d} {dt:9.4f} {evals / dt:12.4g} {1e6 * dt / evals:9.3f}")
    best = max(rows[:-1], key=lambda r: r[2] / r[3])
    tmm_rate = rows[-1][2] / rows[-1][3]
    print()
    print(f"best colour-science: {best[2] / best[3]:.4g} evals/s ({best[0]}, {best[1]}); "
          f"tmm.coh_tmm: {tmm_rate:.4g} evals/s ({1e6 / tmm_rate:.1f} us per s+p pair); "
          f"ratio {best[2] / best[3] / tmm_rate:.0f}x")

    print()
    print("five-layer dispersive stacks (nacre's five-layer sweep benchmarks), "
          "multilayer_tmm, one call over 90 angles x 401 wavelengths:")
    for label, films in (("five-layer-dispersive", FIVE_LAYER),
                         ("five-distinct-dispersive", FIVE_DISTINCT)):
        evals, dt = bench_multilayer(films, reps)
        print(f"  {label:26s} {evals:7d} evals  best {dt:8.4f} s  {evals / dt:10.4g} evals/s")
    worst, n_cmp = multilayer_vs_tmm(FIVE_LAYER)
    print(f"  five-layer-dispersive against tmm.coh_tmm ({n_cmp} points): max |diff| "
          f"{worst[0.0]:.3e} at normal incidence, {worst['oblique']:.3e} oblique "
          "(known limitations of colour-science 0.4.7: T's\n    substrate factor and the layer angles "
          "come from the first wavelength's indices, and Snell's law uses Re(n))")

    print()
    print("correctness vs tmm.coh_tmm (max |diff| over R_s, R_p, T_s, T_p at sampled points):")
    ang = np.array([0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 89.0])
    wl = np.array([380.0, 450.0, 555.5, 632.8, 780.0])
    th = np.array([0.0, 10.0, 120.0, 400.0, 1000.0])
    worst, n_cmp, n_nan = compare([N_AMB, N_FILM, N_SUB], ang, wl, th,
                                  lambda i: [N_AMB, N_FILM, N_SUB])
    print(f"  lossless film 1.0|1.33|1.5          : max diff {worst:.3e} over {n_cmp} points"
          f"{f', {n_nan} non-finite' if n_nan else ''}  -> "
          f"{'MATCHES' if worst < 1e-10 and not n_nan else 'DOES NOT MATCH'}")

    sub = 0.27 + 2.9j
    worst, n_cmp, n_nan = compare([N_AMB, N_FILM, sub], ang, wl, th,
                                  lambda i: [N_AMB, N_FILM, sub])
    print(f"  absorbing substrate 0.27+2.9i        : max diff {worst:.3e} over {n_cmp} points"
          f"{f', {n_nan} non-finite' if n_nan else ''}  (known limitation: Re(n) Snell, real T angle)")
    worst0, n0, _ = compare([N_AMB, N_FILM, sub], np.array([0.0]), wl, th,
                            lambda i: [N_AMB, N_FILM, sub])
    print(f"    same, normal incidence only        : max diff {worst0:.3e} over {n0} points")

    n_disp = np.array([1.30 + 0.1 * (0.5 / (w / 1000.0)) ** 2 for w in wl])  # Cauchy-like film
    stack = np.array([np.full(len(wl), N_AMB), n_disp, np.full(len(wl), N_SUB)])
    worst, n_cmp, n_nan = compare(stack, ang, wl, th, lambda i: [N_AMB, n_disp[i], N_SUB])
    print(f"  dispersive film (n 1.47..1.34)       : max diff {worst:.3e} over {n_cmp} points"
          f"{f', {n_nan} non-finite' if n_nan else ''}  (layer angles taken from wavelength 0 only)")
    worst, n_cmp, n_nan = compare([1.52, 1.38, 1.0], np.array([30.0, 45.0, 60.0]), wl, th,
                                  lambda i: [1.52, 1.38, 1.0])
    print(f"  TIR 1.52|1.38|1.0 at 30/45/60 deg    : max diff {worst:.3e} over {n_cmp - n_nan} finite points, "
          f"{n_nan} non-finite (arcsin of >1 gives NaN past the critical angle)")


if __name__ == "__main__":
    main()
