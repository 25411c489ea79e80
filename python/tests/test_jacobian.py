"""``nacre.spectrum(..., jacobian=True)``: the exact thickness derivatives, against the
``nacre`` binary's ``--jacobian`` columns (committed fixtures, character for character) and
against central finite differences of ``nacre.spectrum`` itself."""

from __future__ import annotations

import numpy as np
import pytest

import nacre
from cli_cases import FIXTURES, JACOBIAN_CASES
from conftest import fmt_sig, read_csv


def _stack(s):
    return nacre.Stack(s["ambient"], s["layers"], s["substrate"])


@pytest.mark.parametrize("name", sorted(JACOBIAN_CASES))
def test_jacobian_matches_cli(name):
    stack, _, _ = JACOBIAN_CASES[name]
    cli = read_csv(FIXTURES / f"{name}.csv")
    angles = sorted({float(a) for a in cli["angle_deg"]})
    wavelengths = [float(w) for w in cli["wavelength_nm"][: len(cli["wavelength_nm"]) // len(angles)]]
    s = nacre.spectrum(_stack(stack), angles, wavelengths, jacobian=True)
    films = len(stack["layers"])
    shape = (len(angles), len(wavelengths))
    assert s.d_thickness.shape == shape + (films, 4)
    assert s.dR_dd.shape == s.dT_dd.shape == shape + (films,)
    for key in ("R_s", "R_p", "R", "T_s", "T_p", "T", "A"):
        assert [fmt_sig(v) for v in s[key].ravel()] == cli[key], f"{name}: {key}"
    for j in range(films):
        for q, d in (("R", s.dR_dd), ("T", s.dT_dd)):
            col = f"d{q}_dd{j + 1}"
            assert [fmt_sig(v) for v in d[..., j].ravel()] == cli[col], f"{name}: {col}"


STACKS = [
    # lossless multilayer on glass
    (1.0, [(2.35, 60.0), (1.38, 120.0), (2.1, 85.0)], 1.52),
    # absorbing films on a metal
    (1.0, [(1.5 + 0.02j, 250.0), (2.0 + 0.3j, 40.0)], 0.27 + 2.9j),
    # total internal reflection from glass, frustrated by a thin gap
    (1.52, [(1.0, 150.0), (1.45, 90.0)], 1.33),
]


@pytest.mark.parametrize("index", range(len(STACKS)))
def test_jacobian_matches_finite_differences(index):
    ambient, films, substrate = STACKS[index]
    angles = [0.0, 45.0, 70.0, 88.0]
    wavelengths = np.linspace(400.0, 750.0, 37)
    s = nacre.spectrum(nacre.Stack(ambient, films, substrate), angles, wavelengths, jacobian=True)
    h = 1e-3
    for j in range(len(films)):

        def powers(delta):
            shifted = [(n, d + delta if k == j else d) for k, (n, d) in enumerate(films)]
            return nacre.spectrum(nacre.Stack(ambient, shifted, substrate), angles, wavelengths).powers

        fd = (powers(h) - powers(-h)) / (2 * h)
        exact = s.d_thickness[..., j, :]
        # Relative to the largest derivative of each quantity over the sweep.
        scale = np.maximum(np.abs(exact).max(axis=(0, 1)), 1e-6)
        err = np.abs(exact - fd).max(axis=(0, 1)) / scale
        assert np.all(err < 1e-6), (j, err)


def test_jacobian_refuses_what_it_cannot_do():
    stack = nacre.Stack(1.0, [(1.38, 100.0)], 1.52)
    with pytest.raises(nacre.NacreError, match="jacobian"):
        nacre.spectrum(stack, 0, 500, thickness_nm=[10.0], jacobian=True)
    plain = nacre.spectrum(stack, 0, 500)
    with pytest.raises(nacre.NacreError, match="jacobian=True"):
        plain.dR_dd
    pane = nacre.Stack("air", [("bk7", 2e6, True)], "air")
    with pytest.raises(nacre.NacreError, match="derivatives"):
        nacre.spectrum(pane, 0, 500, jacobian=True)
    # No films: empty derivative arrays, the powers as always.
    bare = nacre.spectrum(nacre.Stack(1.0, [], 1.52), [0, 30], [500, 600], jacobian=True)
    assert bare.d_thickness.shape == (2, 2, 0, 4)
    assert np.array_equal(bare.powers, nacre.spectrum(nacre.Stack(1.0, [], 1.52), [0, 30], [500, 600]).powers)
