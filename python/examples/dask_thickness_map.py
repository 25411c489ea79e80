#!/usr/bin/env python3
"""A thickness map of 10⁴ spectra fitted with Dask on a ``LocalCluster``, and the proof that
it is the serial fit, bit for bit (issue 33, part 5: the route past one machine is an
existing engine, not ours).

The wafer: a SiO₂ film on silicon whose thickness varies smoothly over a 100 × 100 grid
(250–1350 nm), measured at normal incidence from 400 to 800 nm every 2 nm with Gaussian
noise σ = 0.002 (a fixed seed). Each spectrum is fitted from the bounds alone (10–2000 nm):

* serially — one ``nacre.fit_spectrum`` call on the whole (10⁴, 201) array in this process
  (nacre fits the rows in parallel on its own threads; the result does not depend on how
  many);
* with Dask — the rows cut into chunks, each chunk one ``nacre.fit_spectrum`` call on a
  worker of a ``dask.distributed.LocalCluster`` (processes, one thread each), gathered in
  order.

Both maps must be equal bit for bit (fitted thicknesses, σ, rms residuals): a fit depends on
its spectrum alone. Swap the ``LocalCluster`` for any other Dask cluster (SSH, Kubernetes,
SLURM through dask-jobqueue) to go past one machine; nothing else changes.

Run, from a virtual environment outside the repository (dask is no dependency of nacre):

    python -m venv ~/nacre-dask && . ~/nacre-dask/bin/activate
    pip install ./python "dask[distributed]"
    python python/examples/dask_thickness_map.py            # 10 000 spectra
    python python/examples/dask_thickness_map.py --n 400    # a quick look

It prints the times of both runs, the largest error against the true thicknesses, and
whether the maps are identical (exit status 1 if not).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import nacre

WAVELENGTHS_NM = np.arange(400.0, 801.0, 2.0)
LAYERS = ["sio2@10:2000"]
SUBSTRATE = "si"
NOISE = 0.002


def true_thickness_nm(n: int) -> np.ndarray:
    """The wafer's thickness map, flattened: a smooth bowl plus a tilt over a square grid."""
    side = int(np.ceil(np.sqrt(n)))
    y, x = np.mgrid[0:side, 0:side] / max(side - 1, 1)
    d = 250.0 + 900.0 * ((x - 0.4) ** 2 + (y - 0.6) ** 2) + 200.0 * x
    return d.ravel()[:n]


def synthetic_spectra(thickness_nm: np.ndarray, seed: int = 33) -> np.ndarray:
    """R at normal incidence of SiO₂ (thickness_nm) on Si, plus Gaussian noise: (n, points)."""
    stack = nacre.Stack(1.0, [("sio2", 100.0)], SUBSTRATE)
    # One call sweeps the film's thickness over every value: (1, wavelengths, n).
    r = nacre.spectrum(stack, [0.0], WAVELENGTHS_NM, thickness_nm=thickness_nm).R[0].T
    rng = np.random.default_rng(seed)
    return np.ascontiguousarray(r + rng.normal(0.0, NOISE, r.shape))


def fit_rows(spectra: np.ndarray, starts: int) -> np.ndarray:
    """One chunk's fit: the columns thickness, σ, rms (what a worker sends back)."""
    f = nacre.fit_spectrum(spectra, WAVELENGTHS_NM, LAYERS, substrate=SUBSTRATE, starts=starts)
    return np.column_stack([f.x[:, 0], f.sigma[:, 0], f.rms])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=10_000, help="spectra (default 10 000)")
    ap.add_argument("--workers", type=int, default=2, help="Dask worker processes (default 2)")
    ap.add_argument("--chunk", type=int, default=250, help="spectra per Dask task (default 250)")
    ap.add_argument("--starts", type=int, default=64, help="most starts of each global search")
    a = ap.parse_args()

    from dask.distributed import Client, LocalCluster

    truth = true_thickness_nm(a.n)
    spectra = synthetic_spectra(truth)
    print(f"{a.n} spectra × {len(WAVELENGTHS_NM)} wavelengths, SiO2 {truth.min():.0f}–{truth.max():.0f} nm on Si, noise σ = {NOISE}")

    t0 = time.perf_counter()
    serial = fit_rows(spectra, a.starts)
    t_serial = time.perf_counter() - t0
    print(f"serial (one nacre.fit_spectrum call, nacre's own threads): {t_serial:.2f} s, {a.n / t_serial:.0f} spectra/s")

    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
        chunks = [spectra[i : i + a.chunk] for i in range(0, a.n, a.chunk)]
        # Warm the workers (import nacre) outside the timing.
        client.run(lambda: __import__("nacre") and None)
        t0 = time.perf_counter()
        # The spectra go to the workers once, as data (not inside the task graph).
        data = client.scatter(chunks)
        futures = client.map(fit_rows, data, starts=a.starts, pure=False)
        parts = client.gather(futures)
        t_dask = time.perf_counter() - t0
    distributed = np.concatenate(parts)
    print(f"dask LocalCluster ({a.workers} workers × 1 thread, {len(chunks)} tasks of ≤ {a.chunk}): {t_dask:.2f} s, {a.n / t_dask:.0f} spectra/s")

    same = serial.shape == distributed.shape and serial.tobytes() == distributed.tobytes()
    err = np.abs(serial[:, 0] - truth)
    good = np.mean(err <= np.maximum(1.0, 0.005 * truth))
    print(f"fitted thickness − truth: median {np.median(err):.3f} nm, largest {err.max():.3f} nm; within max(1 nm, 0.5 %): {100 * good:.2f} %")
    print(f"median σ {np.median(serial[:, 1]):.3f} nm, median rms residual {np.median(serial[:, 2]):.5f}")
    print(f"dask map identical to the serial map (thickness, σ, rms, bit for bit): {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
