"""The Python package gives the ``nacre`` binary's numbers: its CSV output (12 significant
digits), committed under ``fixtures/`` by ``cli_cases.py``, equals the Python results
formatted the same way, character for character, for ``nacre spectrum`` and every
``nacre color`` method. When a ``nacre`` binary is at hand the fixtures are also checked to
be what it writes today."""

from __future__ import annotations

import filecmp
import pathlib

import numpy as np
import pytest

import nacre
from cli_cases import COLOR_CASES, FIXTURES, POINTS, SPECTRUM_CASES, find_nacre, run_all
from conftest import fmt_sig, read_csv


def _stack(s):
    return nacre.Stack(s["ambient"], s["layers"], s["substrate"])


def _unique(values):
    out = []
    for v in values:
        if not out or out[-1] != v:
            out.append(v)
    return out


@pytest.mark.parametrize("name", sorted(SPECTRUM_CASES))
def test_spectrum_matches_cli(name):
    stack, _, _ = SPECTRUM_CASES[name]
    cli = read_csv(FIXTURES / f"{name}.csv")
    angles = [float(a) for a in _unique(cli["angle_deg"])]
    wavelengths = [float(w) for w in cli["wavelength_nm"][: len(cli["wavelength_nm"]) // len(angles)]]
    s = nacre.spectrum(_stack(stack), angles, wavelengths)
    assert s.R.shape == (len(angles), len(wavelengths))
    assert [float(a) for a in cli["angle_deg"]] == list(np.repeat(angles, len(wavelengths)))
    for key in ("R_s", "R_p", "R", "T_s", "T_p", "T", "A"):
        ours = [fmt_sig(v) for v in s[key].ravel()]
        assert ours == cli[key], f"{name}: {key}"


@pytest.mark.parametrize("name", sorted(COLOR_CASES))
def test_color_matches_cli(name):
    stack, method, opts, use_points = COLOR_CASES[name]
    cli = read_csv(FIXTURES / f"{name}.csv")
    if use_points:
        a, d, n = (np.array(c) for c in zip(*POINTS))
        c = nacre.color(_stack(stack), a, d, n, method, **opts)
    else:
        a = np.array([float(x) for x in cli["angle_deg"]])
        c = nacre.color(_stack(stack), a, method=method, **opts)
    assert [float(x) for x in cli["angle_deg"]] == list(c.angle_deg)
    assert [float(x) for x in cli["thickness_nm"]] == list(c.thickness_nm)
    assert [float(x) for x in cli["film_ior"]] == list(c.film_ior)
    for k, col in enumerate("XYZ"):
        assert [fmt_sig(v) for v in c.xyz[:, k]] == cli[col], f"{name}: {col}"
    for k, col in enumerate("RGB"):
        assert [fmt_sig(v) for v in c.rgb[:, k]] == cli[col], f"{name}: {col}"


def test_every_color_method_is_covered():
    methods = {m.split(":")[0] for _, m, _, _ in COLOR_CASES.values()}
    assert methods >= {
        "spectral", "lut", "rgb3", "samples", "stack", "fourier", "fourier-exact",
        "gaussian", "rough-lut", "rough-mc",
    }


def test_fixtures_are_what_the_binary_writes(tmp_path: pathlib.Path):
    nacre_bin = find_nacre()
    if nacre_bin is None:
        pytest.skip("no nacre binary (NACRE_BIN or target/{release,debug}/nacre)")
    names = run_all(nacre_bin, tmp_path)
    for name in names:
        assert filecmp.cmp(tmp_path / f"{name}.csv", FIXTURES / f"{name}.csv", shallow=False), (
            f"{name}: the binary's output differs from the committed fixture; regenerate with "
            "python python/tests/cli_cases.py"
        )


def test_conformance_matches_committed_set():
    """``nacre.conformance()`` against ``docs/conformance/conformance.csv`` (the binary's
    ``nacre conformance -o docs/conformance``), every row and column."""
    cli = read_csv(nacre_repo() / "docs" / "conformance" / "conformance.csv")
    rows = nacre.conformance("default")
    assert list(rows["base_ior"]) == cli["base_ior"]
    for key in ("angle_deg", "thickness_nm", "film_ior"):
        assert list(rows[key]) == [float(x) for x in cli[key]]
    for k, col in enumerate("XYZ"):
        assert [fmt_sig(v) for v in rows["xyz"][:, k]] == cli[col]
    for k, col in enumerate("RGB"):
        assert [fmt_sig(v) for v in rows["rgb"][:, k]] == cli[col]
    err = read_csv(nacre_repo() / "docs" / "conformance" / "gltf-reference-error.csv")
    assert [f"{v:.6f}" for v in rows["delta_e_2000"]] == err["delta_e_2000"]
    for k, col in enumerate("RGB"):
        assert [fmt_sig(v) for v in rows["gltf_rgb"][:, k]] == err[col]


def nacre_repo() -> pathlib.Path:
    return FIXTURES.parents[2]
