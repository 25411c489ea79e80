"""Shapes, broadcasting and consistency of the Python API."""

from __future__ import annotations

import math

import numpy as np
import pytest

import nacre

SOAP = nacre.Stack(1.0, [(1.33, 400.0)], 1.0)


def test_spectrum_shapes_and_mapping():
    s = nacre.spectrum(SOAP, [0, 30, 60], np.linspace(400, 700, 7))
    assert s.shape == (3, 7)
    assert set(s) == {"R_s", "R_p", "R", "T_s", "T_p", "T", "A"}
    for key in s:
        assert s[key].shape == (3, 7)
    assert np.array_equal(s.R, (s.R_s + s.R_p) * 0.5)
    assert np.array_equal(s.T, (s.T_s + s.T_p) * 0.5)
    assert np.all(s.A >= 0)
    # lossless: R + T = 1
    assert np.allclose(s.R + s.T, 1.0, atol=1e-14, rtol=0)
    one = nacre.spectrum(SOAP, 45, 550)
    assert one.R.shape == (1, 1)
    with pytest.raises(KeyError):
        s["X"]


def test_thickness_sweep_is_a_third_axis():
    stack = nacre.Stack("air", [("water", 0.0), ("tio2", 60.0)], "bk7")
    d = np.array([0.0, 100.0, 250.0, 1000.0])
    s = nacre.spectrum(stack, [0, 40], [450, 550, 650], thickness_nm=d)
    assert s.shape == (2, 3, 4)
    for k, dk in enumerate(d):
        one = nacre.spectrum(nacre.Stack("air", [("water", dk), ("tio2", 60.0)], "bk7"), [0, 40], [450, 550, 650])
        for key in ("R_s", "R_p", "T_s", "T_p"):
            np.testing.assert_allclose(s[key][:, :, k], one[key], rtol=0, atol=1e-13)
    # the second film instead
    s2 = nacre.spectrum(stack, 10, 500, thickness_nm=[60.0], layer=2)
    one = nacre.spectrum(stack, 10, 500)
    np.testing.assert_allclose(s2.R[:, :, 0], one.R, rtol=0, atol=1e-13)
    with pytest.raises(nacre.NacreError, match="layer"):
        nacre.spectrum(stack, 10, 500, thickness_nm=[1.0], layer=3)


def test_color_broadcasts_like_numpy():
    a = np.array([0.0, 20.0, 40.0, 60.0, 80.0])[:, None]
    d = np.array([100.0, 300.0, 500.0, 700.0])[None, :]
    c = nacre.color(SOAP, a, d)
    assert c.xyz.shape == (5, 4, 3) and c.rgb.shape == (5, 4, 3)
    assert c.angle_deg.shape == (5, 4) and c.thickness_nm.shape == (5, 4)
    assert np.array_equal(c.film_ior, np.full((5, 4), 1.33))
    one = nacre.color(SOAP, 40.0, 500.0)
    assert one.rgb.shape == (3,)
    assert np.array_equal(one.rgb, c.rgb[2, 2])
    flat = nacre.color(SOAP, np.repeat(a, 4, axis=1).ravel(), np.repeat(d, 5, axis=0).ravel())
    assert np.array_equal(flat.rgb.reshape(5, 4, 3), c.rgb)
    # film_ior broadcast too; the override equals a stack built with that index
    c2 = nacre.color(SOAP, [0.0, 30.0], 400.0, 1.5, method="samples:8")
    ref = nacre.color(nacre.Stack(1.0, [(1.5, 400.0)], 1.0), [0.0, 30.0], method="samples:8")
    assert np.array_equal(c2.rgb, ref.rgb)
    with pytest.raises(nacre.NacreError, match="broadcast"):
        nacre.color(SOAP, [0, 1, 2], [1, 2])


def test_xyz_space_gives_xyz_twice():
    c = nacre.color(SOAP, [0, 45], method="spectral", space="xyz")
    assert np.array_equal(c.xyz, c.rgb)


def test_table_lookup_is_the_lut_method():
    t = nacre.Table.load("soap-film")
    assert t.kind == "film-lut" and t.name == "soap-film"
    assert [a["name"] for a in t.axes][0] == "cos_theta"
    nz, ny, nx, three = t.texels().shape
    assert three == 3 and t.texels().dtype == np.float32
    assert (nx, ny, nz) == tuple(a["count"] for a in t.axes)
    assert t.quantities == ["reflectance", "transmittance"]
    angles = np.linspace(0, 85, 18)
    d = np.linspace(0, 900, 18)
    n = np.linspace(1.2, 1.6, 18)
    by_color = nacre.color(SOAP, angles, d, n, method="lut:soap-film")
    by_table = t.lookup(np.cos(np.radians(angles)), d, n)
    # nacre takes cos θ from its own deterministic cos (nacre_optics::elementary), numpy from
    # the platform's: they may differ by an ulp, which moves a lookup by ~1e-16, never 1e-12.
    np.testing.assert_allclose(by_color.rgb, by_table, rtol=0, atol=1e-12)
    t_col = nacre.color(SOAP, angles, d, n, method="lut:soap-film", quantity="t")
    np.testing.assert_allclose(
        t_col.rgb,
        t.lookup(np.cos(np.radians(angles)), d, n, quantity="transmittance"),
        rtol=0,
        atol=1e-12,
    )
    # texel centres: at t = i/(count-1) the lookup returns the texel itself
    tex = t.texels()
    assert t.lookup(1.0, 0.0, t.axes[2]["min"]).tolist() == tex[0, 0, nx - 1].astype(float).tolist()
    # broadcasting
    assert t.lookup(np.ones((2, 3)), 400.0, 1.33).shape == (2, 3, 3)


def test_rough_table_needs_a_roughness():
    t = nacre.Table.load("rough-film-dielectric")
    stack = nacre.Stack(1.0, [(1.33, 400.0)], 1.5)
    c = nacre.color(stack, [0, 30, 60], method="rough-lut:rough-film-dielectric", roughness=0.3)
    out = t.lookup(np.cos(np.radians([0, 30, 60])), 400.0, 1.33, roughness=0.3)
    # numpy's cos against nacre's deterministic one: an ulp apart at most (see above).
    np.testing.assert_allclose(out, c.rgb, rtol=0, atol=1e-12)
    with pytest.raises(nacre.NacreError, match="roughness"):
        t.lookup(1.0, 400.0, 1.33)


def test_fourier_table_samples():
    t = nacre.Table.load("fourier-srgb")
    assert t.kind == "fourier"
    s = t.sample(np.array([0.0, 1000.0, 5000.0]), 0.0)
    assert s.shape == (3, 3) and s.dtype == np.complex128
    with pytest.raises(nacre.NacreError):
        t.texels()


def test_materials_and_stack_introspection(tmp_path):
    names = [m[0] for m in nacre.materials()]
    assert "water" in names and "au" in names
    s = nacre.Stack("air", [("mgf2", 99.75), (1.5 + 0.01j, 10.0)], "bk7")
    assert s.layers == [("mgf2", 99.75), ("1.5+0.01i", 10.0)]
    assert s.ambient == "air" and s.substrate == "bk7"
    n = s.indices_at(550.0)
    assert len(n) == 4 and n[2] == (1.5, 0.01)
    # a wavelength_nm,n,k CSV file and a refractiveindex.info page of a local database
    csv_path = tmp_path / "film.csv"
    csv_path.write_text("wavelength_nm,n,k\n300,1.45,0\n900,1.45,0\n")
    a = nacre.spectrum(nacre.Stack(1.0, [(csv_path, 300.0)], 1.5), 0, 500)
    b = nacre.spectrum(nacre.Stack(1.0, [(1.45, 300.0)], 1.5), 0, 500)
    assert np.array_equal(a.R, b.R)
    page = tmp_path / "db" / "database" / "data" / "main" / "Au" / "nk" / "Johnson.yml"
    page.parent.mkdir(parents=True)
    page.write_text((nacre_repo() / "tables" / "materials" / "au.yml").read_text())
    a = nacre.spectrum(nacre.Stack(1.0, [], "main/Au/Johnson", material_db=tmp_path / "db"), [0, 60], [500, 600])
    b = nacre.spectrum(nacre.Stack(1.0, [], "au"), [0, 60], [500, 600])
    assert np.array_equal(a.R, b.R)


def test_stack_from_recipe():
    s = nacre.Stack.from_recipe(nacre_repo() / "tables" / "examples" / "ar-coating.toml")
    assert s.substrate == "bk7" and s.layers == [("mgf2", 99.75)]


def test_bake_is_the_default_set(tmp_path):
    recipe = nacre_repo() / "tables" / "recipes" / "soap-film.toml"
    (manifest,) = nacre.bake(recipe, tmp_path)
    assert manifest == tmp_path / "soap-film.json"
    ours, committed = nacre.Table.load(manifest), nacre.Table.load("soap-film")
    assert np.array_equal(ours.texels(), committed.texels())
    assert np.array_equal(ours.texels("transmittance"), committed.texels("transmittance"))
    for f in ours.manifest["files"]:
        assert (tmp_path / f["path"]).read_bytes() == (nacre_repo() / "tables" / "baked" / f["path"]).read_bytes()


def test_conformance_quick_rows():
    rows = nacre.conformance("quick")
    n = len(rows["angle_deg"])
    assert n == 2080
    assert rows["xyz"].shape == (n, 3) and rows["gltf_rgb"].shape == (n, 3)
    assert rows["delta_e_2000"].shape == (n,)
    assert set(rows["base_ior"]) == {"1", "1.25", "1.5", "1.75", "2", "2.5", "au", "ag", "cu", "al"}
    with pytest.raises(nacre.NacreError, match="grid"):
        nacre.conformance("medium")


def test_results_are_deterministic():
    stack = nacre.Stack("air", [("tio2", 60.0), ("au", 10.0)], "bk7")
    a = nacre.color(stack, np.linspace(0, 80, 9), method="stack")
    b = nacre.color(stack, np.linspace(0, 80, 9), method="stack")
    assert np.array_equal(a.rgb, b.rgb)
    c = nacre.color(SOAP, [0, 45], method="rough-mc:64", roughness=0.5)
    d = nacre.color(SOAP, [0, 45], method="rough-mc:64", roughness=0.5)
    assert np.array_equal(c.rgb, d.rgb) and c.monte_carlo is not None
    assert c.monte_carlo[0] == 64 and math.isfinite(c.monte_carlo[1])


def nacre_repo():
    import pathlib

    return pathlib.Path(__file__).resolve().parents[2]


def test_the_gil_is_released_while_nacre_computes():
    """Another Python thread keeps running while nacre computes: the longest pause the main
    thread sees during a computation is far shorter than the computation (with the GIL held
    in native code, it would wait for all of it)."""
    import threading
    import time

    d = np.linspace(0.0, 2000.0, 1500)

    def work():
        return nacre.color(SOAP, 30.0, d)

    t0 = time.perf_counter()
    work()
    alone = time.perf_counter() - t0
    done = threading.Event()
    worker = threading.Thread(target=lambda: (work(), done.set()))
    worker.start()
    last = time.perf_counter()
    longest = 0.0
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    assert alone > 0.05, alone
    assert longest < 0.5 * alone, (longest, alone)


def test_incoherent_layers_take_the_cli_syntax_or_a_flag():
    """A slab is `(material, thickness_nm, True)` or the binary's `--layer` text; both give
    the same stack (the binary's own numbers: test_cli_identity's coated-pane cases)."""
    tuples = nacre.Stack("air", [("mgf2", 99.75), ("bk7", 2e6, True), ("mgf2", 99.75)], "air")
    texts = nacre.Stack("air", ["mgf2@99.75nm", "bk7@2mm:incoherent", "mgf2@99.75"], "air")
    assert tuples.incoherent == texts.incoherent == [False, True, False]
    assert tuples.layers == texts.layers == [("mgf2", 99.75), ("bk7", 2e6), ("mgf2", 99.75)]
    assert '("bk7", 2000000, True)' in repr(tuples)
    a = nacre.spectrum(tuples, [0, 45], [500, 501, 502])
    b = nacre.spectrum(texts, [0, 45], [500, 501, 502])
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    # incoherent: no 2 mm fringes from one nanometre to the next
    assert np.ptp(a.R[0]) < 1e-3
    with pytest.warns(nacre.UndersamplingWarning, match=r"layer 2 \(`bk7`, 2000000 nm\) is coherent"):
        coherent = nacre.spectrum(nacre.Stack("air", ["mgf2@99.75nm", "bk7@2mm", "mgf2@99.75"], "air"), 0, [500, 501, 502])
    assert np.ptp(coherent.R[0]) > 1e-2
    assert nacre.Stack(1.0, [(1.33, 400.0, False)], 1.0).incoherent == [False]
    with pytest.raises(nacre.NacreError, match=r"layers\[1\].*bk7@2mm:incoherant.*unknown suffix"):
        nacre.Stack("air", ["mgf2@99.75", "bk7@2mm:incoherant"], "air")
    with pytest.raises(nacre.NacreError, match=r"layers\[0\].*bk7@1000mm:incoherent.*thinner than 1 m"):
        nacre.Stack("air", ["bk7@1000mm:incoherent"], "air")
    with pytest.raises(TypeError, match=r"layers\[0\]: the third item"):
        nacre.Stack("air", [("bk7", 2e6, "incoherent")], "air")
    with pytest.raises(nacre.NacreError, match="incoherent"):
        nacre.color(tuples, [0.0], method="fourier")
