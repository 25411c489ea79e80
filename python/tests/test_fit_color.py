"""``nacre.fit_color`` gives the numbers of ``nacre fit color``: the binary's recipes, report
rows and printed lines for the cases of ``cli_cases.FIT_CASES`` (``fit-color*``) are
committed under ``fixtures/`` (checked against the binary by
``test_fit.py::test_fit_fixtures_are_what_the_binary_writes``) and compared here with the
same design from numpy arrays; recipes are shortest round-trip decimals, so equal text means
equal bits."""

from __future__ import annotations

import csv
import pathlib

import numpy as np
import pytest

import nacre
from cli_cases import FIT_CASES, FIT_LOOK, FIT_LOOK_LAB, FIXTURES, REPO


def _targets(path: str, columns: tuple) -> tuple:
    """The angles, the colour columns (rows, 3) and the weights (or None) of a targets CSV."""
    rows = list(csv.DictReader(line for line in open(REPO / path) if not line.startswith("#")))
    angles = np.array([float(r["angle_deg"]) for r in rows])
    colours = np.array([[float(r[c]) for c in columns] for r in rows])
    weights = np.array([float(r["weight"]) for r in rows]) if "weight" in rows[0] else None
    return angles, colours, weights


def _report(name: str) -> list:
    return list(csv.DictReader(open(FIXTURES / name)))


def _check_report(design: nacre.ColourDesign, rows: list, channels: tuple) -> None:
    """Every number of the command's ``--report`` CSV, formatted as the command formats it."""
    k_rows = design.delta_e.shape[1]
    assert len(rows) == design.x.shape[0] * k_rows
    for j, row in enumerate(rows):
        k, i = divmod(j, k_rows)
        assert int(row["solution"]) == k + 1
        for c, name in enumerate("Lab"):
            assert row[f"target_{name}"] == f"{design.target_lab[i, c]:.4f}"
            assert row[name] == f"{design.lab[k, i, c]:.4f}"
        for c, name in enumerate(channels):
            assert row[name] == f"{design.colour[k, i, c]:.6f}"
        assert row["delta_e_2000"] == f"{design.delta_e[k, i]:.4f}"
        assert float(row["weight"]) == design.weights[i]


def test_rgb_look_matches_the_cli():
    angles, rgb, _ = _targets(FIT_LOOK, ("R", "G", "B"))
    design = nacre.fit_color(angles, ["tio2@20:300"], rgb=rgb, substrate="bk7", targets_name=FIT_LOOK)
    assert design.params == ["layer1_thickness_nm"]
    assert design.recipes == [(FIXTURES / "fit-color.toml").read_text()]
    assert design.summary == (FIXTURES / "fit-color.txt").read_text().splitlines()
    _check_report(design, _report("fit-color-report.csv"), ("R", "G", "B"))
    # The look was made from 137 nm of TiO2: reached, and found again.
    assert design.reached == [True] and design.max_delta_e[0] <= 1.0
    assert abs(design["layer1_thickness_nm"][0] - 137.0) < 1.0
    # The achieved colours are nacre.color's on the designed stack.
    stack = nacre.Stack.from_recipe(_write(design.recipes[0]))
    again = nacre.color(stack, angles)
    assert np.array_equal(again.rgb, design.colour[0])
    assert np.allclose(design.target_colour, rgb, rtol=0, atol=1e-12)


def test_lab_look_with_weights_solutions_and_colour_options_matches_the_cli():
    angles, lab, weights = _targets(FIT_LOOK_LAB, ("L", "a", "b"))
    design = nacre.fit_color(
        angles, [((1.3, 2.4), (20, 300))], lab=lab, weights=weights, substrate="bk7",
        illuminant="d50", space="rec2020", solutions=2, distinct_nm=20, starts=8,
        targets_name=FIT_LOOK_LAB,
    )
    assert design.params == ["layer1_index", "layer1_thickness_nm"]
    files = ["fit-color-lab.toml"] + sorted(p.name for p in FIXTURES.glob("fit-color-lab-[0-9]*.toml"))
    assert design.recipes == [(FIXTURES / f).read_text() for f in files]
    assert design.x.shape == (len(files), 2) and design.colour.shape == (len(files), len(angles), 3)
    # The command names the file's line, the binding the row of its argument.
    cli = (FIXTURES / "fit-color-lab.txt").read_text().replace("(line 4)", "(lab[1])")
    assert design.summary == cli.splitlines()
    assert design.summary[0].endswith("not reached: the closest stack stays ΔE2000 27.13 away at 30° (lab[1])")
    _check_report(design, _report("fit-color-lab-report.csv"), ("R", "G", "B"))
    # No film on BK7 reaches this look: the closest stack says how far it stays.
    assert design.reached[0] is False
    assert "not reached: the closest stack stays ΔE2000" in design.summary[0]
    assert np.array_equal(design.target_lab, lab)
    assert design.mean_delta_e[0] == pytest.approx(np.sum(design.delta_e[0] * weights) / weights.sum())


def test_transmitted_colour_and_xyz_targets_agree_with_rgb_targets():
    """The same look given as X, Y, Z designs the same stack; ``quantity="t"`` designs for
    the transmitted colour (``nacre.color(..., quantity="t")`` of the designed stack)."""
    stack = nacre.Stack("air", [("tio2", 210.0)], "bk7")
    angles = np.array([0.0, 30.0, 55.0])
    look = nacre.color(stack, angles, quantity="t")
    by_rgb = nacre.fit_color(angles, ["tio2@20:300"], rgb=look.rgb, substrate="bk7", quantity="t")
    by_xyz = nacre.fit_color(angles, ["tio2@20:300"], xyz=look.xyz, substrate="bk7", quantity="t")
    assert by_rgb.max_delta_e[0] <= 1.0 and by_xyz.max_delta_e[0] <= 1.0
    assert np.allclose(by_rgb.target_lab, by_xyz.target_lab, rtol=0, atol=1e-9)
    designed = nacre.Stack.from_recipe(_write(by_rgb.recipes[0]))
    assert np.array_equal(nacre.color(designed, angles, quantity="t").rgb, by_rgb.colour[0])


def _write(text: str) -> pathlib.Path:
    import tempfile

    f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
    f.write(text)
    f.close()
    return pathlib.Path(f.name)


@pytest.mark.parametrize("kwargs,message", [
    ({"rgb": None}, "rgb, xyz, lab: give the target colours as exactly one of them, got none"),
    ({"lab": [[50.0, 0.0, 0.0]] * 2}, "got rgb, lab"),
    ({"rgb": [[0.1, 0.2]] * 2}, "rgb: expected one colour of three values per row"),
    ({"rgb": [[0.1, float("nan"), 0.1]] * 2}, "rgb[0, 1] `NaN`: expected a finite number"),
    ({"angles_deg": [0.0, 90.0]}, "angles_deg[1] `90`: must lie strictly between -90 and 90"),
    ({"angles_deg": [0.0, 10.0, 20.0]}, "angles_deg `3 values`: expected one per target row: 2"),
    ({"weights": [1.0, 0.0]}, "weights[1] `0`: must be positive"),
    ({"rgb": None, "lab": [[50.0, 0.0, 0.0], [120.0, 0.0, 0.0]]}, "lab[1, 0] `120`: must lie in 0–100"),
    ({"layers": ["tio2@300:20"]}, "layers `tio2@300:20`: thickness bounds 300:20 are inverted"),
    ({"solutions": 0}, "solutions `0`: expected 1 to 100 stacks"),
    ({"distinct_nm": -1.0}, "distinct_nm `-1`: expected a thickness tolerance"),
    ({"quantity": "x"}, "quantity `x`: expected r or t"),
    ({"space": "cmyk"}, "space"),
    ({"illuminant": "f2000"}, "illuminant"),
])
def test_bad_input_is_a_clear_error(kwargs, message):
    args = {
        "angles_deg": [0.0, 30.0],
        "layers": ["tio2@20:300"],
        "rgb": [[0.1, 0.05, 0.02], [0.08, 0.06, 0.03]],
        "substrate": "bk7",
    }
    args.update(kwargs)
    with pytest.raises(nacre.NacreError) as e:
        nacre.fit_color(**args)
    assert message in str(e.value), str(e.value)


def test_the_color_fixtures_are_cli_cases():
    """The fixtures compared above are the binary's outputs for these cases (regenerated by
    ``python python/tests/cli_cases.py``)."""
    assert {"fit-color.toml", "fit-color-lab.toml"} <= set(FIT_CASES)
    for name in ("fit-color.toml", "fit-color.txt", "fit-color-report.csv", "fit-color-lab.toml",
                 "fit-color-lab.txt", "fit-color-lab-report.csv"):
        assert (FIXTURES / name).is_file(), name
