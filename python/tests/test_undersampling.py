"""A coherent layer far beyond the wavelength sampling's reach (issue 31): ``nacre.spectrum``
and ``nacre.color`` emit :class:`nacre.UndersamplingWarning` with the text the ``nacre``
binary prints after ``nacre: warning:``, and nothing for the same slab marked incoherent or
for thin films."""

from __future__ import annotations

import subprocess
import warnings

import numpy as np
import pytest

import nacre
from cli_cases import REPO, find_nacre

COATED = ["mgf2@99.75nm", "bk7@2mm", "mgf2@99.75"]
WAVELENGTHS = np.arange(400.0, 701.0, 1.0)
TEXT = (
    "layer 2 (`bk7`, 2000000 nm) is coherent but its fringes are {} nm apart near 400 nm, "
    "finer than the 1 nm wavelength step: its spectrum aliases; a layer that thick adds its "
    "reflections in intensity, mark it `:incoherent` (`bk7@2000000nm:incoherent`)"
)


def _messages(record) -> list:
    return [str(w.message) for w in record if issubclass(w.category, nacre.UndersamplingWarning)]


def test_spectrum_warns_with_the_cli_text():
    stack = nacre.Stack("air", COATED, "air")
    with pytest.warns(nacre.UndersamplingWarning) as record:
        nacre.spectrum(stack, [0.0], WAVELENGTHS)
    (message,) = _messages(record)
    period = message.split("fringes are ", 1)[1].split(" nm apart", 1)[0]
    assert message == TEXT.format(period)
    # 2 n d / λ² ≈ 2 · 1.53 · 2 mm / (400 nm)² ≈ 0.026 nm between fringes
    assert 0.02 < float(period) < 0.03
    # the warning points at the caller's line, not inside the package
    assert record[0].filename == __file__
    # the Jacobian sweeps the same grid and says the same
    with pytest.warns(nacre.UndersamplingWarning) as again:
        nacre.spectrum(stack, [0.0], WAVELENGTHS, jacobian=True)
    assert _messages(again) == [message]


def test_the_binary_prints_the_same_warning():
    nacre_bin = find_nacre()
    if nacre_bin is None:
        pytest.skip("no nacre binary (NACRE_BIN or target/{release,debug}/nacre)")
    layers = [a for layer in COATED for a in ("--layer", layer)]
    args = [nacre_bin, "spectrum", "--ambient", "air", *layers, "--substrate", "air", "--angles", "0",
            "--wavelengths", "400:700:1", "-o", "-"]
    r = subprocess.run(args, cwd=REPO, capture_output=True, text=True, check=True)
    with pytest.warns(nacre.UndersamplingWarning) as record:
        nacre.spectrum(nacre.Stack("air", COATED, "air"), [0.0], WAVELENGTHS)
    assert r.stderr.splitlines() == [f"nacre: warning: {m}" for m in _messages(record)]


def test_color_on_a_sampled_grid_warns():
    stack = nacre.Stack("air", ["bk7@50um"], "air")
    with pytest.warns(nacre.UndersamplingWarning, match=r"layer 1 \(`bk7`, 50000 nm\) is coherent"):
        nacre.color(stack, [0.0], method="samples:16")


def test_incoherent_slabs_and_thin_films_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nacre.spectrum(nacre.Stack("air", ["mgf2@99.75nm", "bk7@2mm:incoherent", "mgf2@99.75"], "air"),
                       [0.0], WAVELENGTHS)
        nacre.spectrum(nacre.Stack(1.0, [(1.33, 400.0), (2.3, 900.0)], 1.5), [0.0, 45.0], WAVELENGTHS)
        nacre.color(nacre.Stack("air", ["bk7@50um"], "air"), [0.0])  # spectral: steps by the fringes
        # a thin film on a deliberately sparse grid is no slab (10.6 orders at 100 nm)
        nacre.spectrum(nacre.Stack(1.0, [(1.33, 400.0)], 1.0), [0.0], [100.0, 150.0, 200.0])
