"""Bad input raises a ``ValueError`` subclass (``nacre.NacreError`` and its kinds) with the
``nacre`` binary's message, its parameters named as the Python arguments; NaN and huge
values never crash the interpreter: they give finite results or an exception."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import nacre

SOAP = nacre.Stack(1.0, [(1.33, 400.0)], 1.0)


def test_hierarchy():
    for e in (nacre.MaterialError, nacre.TableError, nacre.ParseError):
        assert issubclass(e, nacre.NacreError)
    assert issubclass(nacre.NacreError, ValueError)


@pytest.mark.parametrize(
    "build, error, message",
    [
        (lambda: nacre.Stack("nope", [], "air"), nacre.MaterialError,
         "ambient: unknown material `nope`: expected a number (`1.5`), a complex index (`0.27+2.9i`), a bundled material"),
        (lambda: nacre.Stack("air", [("water", 1.0), ("unobtainium", 5.0)], "air"), nacre.MaterialError,
         "layers[1]: unknown material `unobtainium`"),
        (lambda: nacre.Stack("air", [], "bogus"), nacre.MaterialError, "(with material_db)"),
        (lambda: nacre.Stack("air", [("water", -3.0)], "air"), nacre.NacreError,
         "layers[0] `-3`: thickness_nm must be finite and non-negative"),
        (lambda: nacre.Stack("air", [("water", float("nan"))], "air"), nacre.NacreError,
         "layers[0] `NaN`: thickness_nm must be finite and non-negative"),
        (lambda: nacre.Stack("air", [(1.5 - 0.1j, 10.0)], "air"), nacre.MaterialError,
         "layers[0]: invalid refractive index `1.5-0.1i`: the extinction coefficient κ must be finite and non-negative"),
        (lambda: nacre.Stack(float("nan"), [], "air"), nacre.MaterialError, "ambient: "),
        (lambda: nacre.Stack(0.0, [], "air"), nacre.MaterialError, "the real part n must be finite and positive"),
        (lambda: nacre.Stack(1.5 + 0.1j, [], "air"), nacre.NacreError, "ambient: "),
        (lambda: nacre.Stack("air", [], "main/Au/Johnson"), nacre.MaterialError, "material_db"),
        (lambda: nacre.Stack("air", [], "main/Au/Nobody", material_db="/nonexistent"), nacre.MaterialError,
         "substrate: the material database folder /nonexistent (material_db) does not exist"),
    ],
)
def test_stack_errors(build, error, message):
    with pytest.raises(error) as e:
        build()
    assert message in str(e.value), str(e.value)


def test_not_a_material_is_a_type_error():
    with pytest.raises(TypeError):
        nacre.Stack(True, [], "air")
    with pytest.raises(TypeError):
        nacre.Stack([1.0], [], "air")


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: nacre.spectrum(SOAP, 90, 500), nacre.NacreError,
         "angles_deg `90`: incidence angles must lie strictly between −90° and 90°"),
        (lambda: nacre.spectrum(SOAP, np.nan, 500), nacre.NacreError, "angles_deg `NaN`"),
        (lambda: nacre.spectrum(SOAP, 0, -5), nacre.NacreError,
         "wavelengths_nm `-5`: wavelengths must be positive (vacuum nm)"),
        (lambda: nacre.spectrum(SOAP, 0, np.nan), nacre.NacreError, "wavelengths_nm `NaN`"),
        (lambda: nacre.spectrum(SOAP, 0, np.inf), nacre.NacreError, "must be finite"),
        (lambda: nacre.spectrum(nacre.Stack("air", [], "au"), 0, 5000), nacre.MaterialError, "wavelengths_nm: "),
        (lambda: nacre.spectrum(SOAP, 0, 500, thickness_nm=[np.inf]), nacre.NacreError,
         "thickness_nm `inf`: thickness must be finite and non-negative"),
        (lambda: nacre.spectrum(SOAP, [[0, 1]], 500), nacre.NacreError, "angles_deg: expected a number or a 1-D sequence"),
        (lambda: nacre.spectrum(SOAP, np.zeros(4000), np.ones(4000)), nacre.NacreError, "exceeds the limit of 10000000"),
        (lambda: nacre.color(SOAP, 0, method="magic"), nacre.NacreError, "method `magic`: expected spectral, lut:NAME|PATH"),
        (lambda: nacre.color(SOAP, 0, method="rough-mc"), nacre.NacreError, "method `rough-mc`: needs roughness"),
        (lambda: nacre.color(SOAP, 0, roughness=0.3), nacre.NacreError,
         "roughness `0.3`: applies only to method='rough-lut:NAME' and rough-mc"),
        (lambda: nacre.color(SOAP, 0, method="rough-mc", roughness=2.0), nacre.NacreError,
         "roughness `2`: GGX roughness α must lie in (0, 1]"),
        (lambda: nacre.color(SOAP, 0, observer="1900"), nacre.NacreError, "observer `1900`: "),
        (lambda: nacre.color(SOAP, 0, space="cmyk"), nacre.NacreError, "space `cmyk`: "),
        (lambda: nacre.color(SOAP, 0, quantity="x"), nacre.NacreError, "quantity `x`: expected 'r'"),
        (lambda: nacre.color(SOAP, 0, method="rgb3", space="xyz"), nacre.NacreError,
         "method `rgb3`: rgb3 gives RGB directly: choose an RGB space"),
        (lambda: nacre.color(SOAP, 0, method="lut:soap-film", space="rec2020"), nacre.NacreError,
         "space `rec2020`: table `soap-film` was baked for `srgb`"),
        (lambda: nacre.color(nacre.Stack(1.0, [(1.33, 400.0)], 1.5), 0, method="lut:soap-film"), nacre.NacreError,
         "the table was baked for base `1.0`"),
        (lambda: nacre.color(SOAP, 0, method="gaussian", quantity="t"), nacre.NacreError,
         "method='gaussian': the Gaussian fit evaluates reflectance only (use quantity='r')"),
        (lambda: nacre.color(nacre.Stack(1.0, [], 1.5), 0, thickness_nm=100.0), nacre.NacreError,
         "the stack has no film to override: give at least one layers"),
        (lambda: nacre.color(SOAP, 95.0), nacre.NacreError, "angles_deg `95`: must lie strictly between -90 and 90"),
        (lambda: nacre.color(SOAP, np.nan), nacre.NacreError, "angles_deg `NaN`"),
        (lambda: nacre.color(SOAP, 0, np.inf), nacre.NacreError, "thickness_nm `inf`: must be finite and non-negative"),
        (lambda: nacre.color(SOAP, 0, 100.0, np.nan), nacre.NacreError, "film_ior `NaN`: must be finite and positive"),
        (lambda: nacre.color(SOAP, 0, 100.0, -1.0), nacre.NacreError, "film_ior `-1`"),
        (lambda: nacre.Table.load("no-such-table"), nacre.NacreError, "no-such-table.json"),
        (lambda: nacre.Table.load("soap-film").lookup(np.nan, 1.0, 1.3), nacre.NacreError, "lookup coordinates must be finite"),
        (lambda: nacre.Table.load("soap-film").texels("emission"), nacre.NacreError, "quantity `emission`"),
        (lambda: nacre.Table.load("film-gold").texels("transmittance"), nacre.NacreError,
         "quantity='transmittance': table `film-gold` has no transmittance"),
    ],
)
def test_call_errors(call, error, message):
    with pytest.raises(error) as e:
        call()
    assert message in str(e.value), str(e.value)


def test_file_errors_name_file_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('substrate = "bk7"\n[[layers]]\nmaterial = "mgf2"\nthickness_nm = -1\n')
    with pytest.raises(nacre.ParseError, match=r"bad\.toml:4: thickness_nm = -1: must be finite and non-negative"):
        nacre.Stack.from_recipe(bad)
    csv = tmp_path / "m.csv"
    csv.write_text("wavelength_nm,n,k\n400,1.5,0\n500,1.5,-1\n")
    with pytest.raises(nacre.MaterialError, match=r"m\.csv:3: k = -1 must be non-negative"):
        nacre.Stack("air", [(csv, 10.0)], "air")
    recipe = tmp_path / "r.toml"
    recipe.write_text("kind = \"film-lut\"\nbogus = 1\n")
    with pytest.raises(nacre.NacreError, match=r"r\.toml"):
        nacre.bake(recipe, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_huge_values_give_finite_results():
    for wavelengths, thicknesses in (([1e-300, 500.0], [0.0, 1.0]), ([500.0, 1e300], [0.0, 1e300])):
        s = nacre.spectrum(SOAP, [0.0, 89.999999], wavelengths, thickness_nm=thicknesses)
        for key in s:
            assert np.all(np.isfinite(s[key])), (key, wavelengths, thicknesses)
    # a phase 2π ñ d / λ beyond f64 is refused rather than turned into NaN
    with pytest.raises(nacre.NacreError, match=r"wavelengths_nm: film 1 \(`1.33`, 1e300 nm\) at 1e-300 nm: its phase"):
        nacre.spectrum(SOAP, 0.0, [1e-300, 500.0], thickness_nm=[0.0, 1e300])
    with pytest.raises(nacre.NacreError, match="overflows"):
        nacre.spectrum(nacre.Stack(1.0, [(1.33, 1e300)], 1.0), 0.0, 1e-10)
    t = nacre.Table.load("soap-film")
    out = t.lookup([1e300, -1e300, 0.5], [1e300, 0.0, 1e-300], [1e300, 1e-300, 1.3])
    assert np.all(np.isfinite(out))
    c = nacre.color(SOAP, [0.0, 89.999999], [0.0, 1e-300], [1e-6, 1e6], method="samples:5")
    assert np.all(np.isfinite(c.rgb))
    # indices beyond [1e-6, 1e6] would over- or underflow the Fresnel terms: refused
    for n in (1e-300, 1e-20, 1e100, 1e300):
        with pytest.raises(nacre.MaterialError, match=r"the real part n must lie in \[1e-6, 1e6\]"):
            nacre.color(SOAP, 0.0, 100.0, n, method="samples:5")
        with pytest.raises(nacre.MaterialError, match=r"layers\[0\]: invalid refractive index"):
            nacre.Stack(1.0, [(n, 10.0)], 1.0)
    with pytest.raises(nacre.MaterialError, match=r"κ must be at most 1e6"):
        nacre.Stack(1.0, [], 1.0 + 1e7j)
    for m in (1e-6, 1e6, 1e-6 + 1e6j, 1e6 + 1e6j):
        with warnings.catch_warnings():
            # n = 1e6 over 100 nm is 2·10⁸ orders at 1e-3 nm: rightly warned as undersampled
            warnings.simplefilter("ignore", nacre.UndersamplingWarning)
            s = nacre.spectrum(nacre.Stack(1.0, [(m, 100.0)], m), [0.0, 45.0, 89.99], [1e-3, 500.0, 1e6])
        assert all(np.all(np.isfinite(s[k])) for k in s), m
    for method in ("stack", "fourier:auto", "fourier-exact:3", "gaussian", "rgb3", "lut:soap-film"):
        c = nacre.color(SOAP, [0.0, 60.0], 1e300, method=method)
        assert np.all(np.isfinite(c.rgb)), method
    # the exact integration would need more than 2^22 wavelengths: refused, not allocated
    for method, roughness in (("spectral", None), ("rough-mc:16", 0.3)):
        with pytest.raises(nacre.NacreError, match="optical path difference of the spectral rule"):
            nacre.color(SOAP, 0.0, 1e300, method=method, roughness=roughness)
