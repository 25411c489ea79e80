"""nacre: thin-film interference colour, exact in f64, with numpy arrays.

Python bindings of the nacre Rust crates (nacre-optics, nacre-format, nacre-bake): the same
computations as the ``nacre`` command line, returning arrays instead of CSV files.

* :class:`Stack` — ambient | films (top first) | substrate, from numbers, complex numbers,
  bundled names, refractiveindex.info pages (``material_db=``) and ``.yml``/``.csv`` files;
* :func:`spectrum` — R_s, R_p, R, T_s, T_p, T, A over angle × wavelength (× thickness);
* :func:`color` — XYZ and RGB by every method of ``nacre color``;
* :class:`Table` — a baked table, its texels and the CPU lookup that reproduces a GPU's;
* :func:`fit_spectrum` — a template's free thicknesses and indices fitted to measured
  spectra (many in parallel); :func:`fit_color` — a stack designed for target colours over
  angles; :func:`fit_gltf` — the closest glTF iridescence material;
* :func:`bake`, :func:`conformance`, :func:`materials`.

Conventions (those of ``nacre spectrum``; Byrnes' ``tmm``): R = (R_s + R_p)/2, T is the
power crossing into the substrate (with the Re(ñ cos θ) factor), A = 1 − R − T (never below
0) is absorbed in the films. Angles are in the ambient, in degrees; wavelengths are vacuum
wavelengths in nm; thicknesses are physical thicknesses in nm.

Errors are :class:`NacreError` (a ``ValueError``) or its subclasses :class:`MaterialError`,
:class:`TableError` and :class:`ParseError`, with the messages of the ``nacre`` binary and the
arguments named as here (``angles_deg``, ``layers[0]``, ``method='lut:…'``).
"""

from __future__ import annotations

import json
import os
import pathlib
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _nacre
from ._nacre import MaterialError, NacreError, ParseError, Stack, TableError
from ._fit import ColourDesign, GltfFilm, GltfFit, SpectrumFit, fit_color, fit_gltf, fit_spectrum

__version__: str = _nacre.__version__

__all__ = [
    "Colour",
    "ColourDesign",
    "GltfFilm",
    "GltfFit",
    "MaterialError",
    "NacreError",
    "ParseError",
    "Spectrum",
    "SpectrumFit",
    "Stack",
    "Table",
    "TableError",
    "UndersamplingWarning",
    "bake",
    "color",
    "conformance",
    "fit_color",
    "fit_gltf",
    "fit_spectrum",
    "materials",
    "spectrum",
]

#: A material: a real index (``1.33``), a complex index ``n + κj`` (``0.27 + 2.9j``, κ ≥ 0),
#: a bundled name (``"water"``, ``"au"``, see :func:`materials`), a refractiveindex.info
#: page ``"SHELF/BOOK/PAGE"`` (with ``material_db=`` or ``NACRE_MATERIAL_DB``), or the path
#: of a refractiveindex.info ``.yml`` file or a ``wavelength_nm,n,k`` ``.csv`` file.
Material = Union[float, complex, str, "os.PathLike[str]"]

FloatArray = NDArray[np.float64]


class UndersamplingWarning(UserWarning):
    """A coherent film whose interference fringes the wavelength sampling cannot follow (its
    spectrum aliases): the warning ``nacre spectrum`` and ``nacre color`` print, with the
    same text. A layer that thick adds its reflections in intensity: mark it incoherent
    (``(material, thickness_nm, True)`` or ``"bk7@2mm:incoherent"``)."""


def _warn(texts: Sequence[str]) -> None:
    """Each library warning as an :class:`UndersamplingWarning` at the caller's caller."""
    import warnings

    for text in texts:
        warnings.warn(text, UndersamplingWarning, stacklevel=3)


def _axis(values: ArrayLike, name: str) -> FloatArray:
    """A scalar or 1-D sequence as a contiguous float64 array."""
    a = np.ascontiguousarray(np.asarray(values, dtype=np.float64))
    if a.ndim > 1:
        raise NacreError(f"{name}: expected a number or a 1-D sequence, got shape {a.shape}")
    return a.reshape(-1)


class Spectrum(Mapping[str, FloatArray]):
    """Reflectance and transmittance of a stack over (angles, wavelengths) or (angles,
    wavelengths, thicknesses): each quantity is an array of that shape.

    ``R_s``, ``R_p``, ``T_s``, ``T_p`` are views into :attr:`powers` (the sweep's own
    memory, handed over without a copy); ``R``, ``T`` and ``A`` are computed on first use
    by the library's definitions. Also a read-only mapping: ``s["R"]`` is ``s.R``, keys are
    the columns of ``nacre spectrum``'s CSV after ``angle_deg,wavelength_nm``.
    """

    _KEYS = ("R_s", "R_p", "R", "T_s", "T_p", "T", "A")

    def __init__(
        self,
        angles_deg: FloatArray,
        wavelengths_nm: FloatArray,
        thickness_nm: Optional[FloatArray],
        powers: FloatArray,
        d_thickness: Optional[FloatArray] = None,
    ) -> None:
        self.angles_deg = angles_deg
        """Incidence angles in the ambient, degrees."""
        self.wavelengths_nm = wavelengths_nm
        """Vacuum wavelengths, nm."""
        self.thickness_nm = thickness_nm
        """The swept film's thicknesses, nm (None: the stack's own)."""
        self.powers = powers
        """R_s, R_p, T_s, T_p along the last axis: shape (..., 4)."""
        self.d_thickness = d_thickness
        """With ``jacobian=True``: ∂R_s, ∂R_p, ∂T_s, ∂T_p per nm of each film's thickness
        (top film first) along the last axis, shape (angles, wavelengths, films, 4); else
        None."""
        self._unpolarised: Optional[Tuple[FloatArray, FloatArray, FloatArray]] = None
        self._d_unpolarised: Optional[Tuple[FloatArray, FloatArray]] = None

    @property
    def shape(self) -> Tuple[int, ...]:
        """(angles, wavelengths) or (angles, wavelengths, thicknesses)."""
        return tuple(self.powers.shape[:-1])

    @property
    def R_s(self) -> FloatArray:
        """Reflectance, s polarisation."""
        return self.powers[..., 0]

    @property
    def R_p(self) -> FloatArray:
        """Reflectance, p polarisation."""
        return self.powers[..., 1]

    @property
    def T_s(self) -> FloatArray:
        """Transmittance into the substrate, s polarisation."""
        return self.powers[..., 2]

    @property
    def T_p(self) -> FloatArray:
        """Transmittance into the substrate, p polarisation."""
        return self.powers[..., 3]

    def _rta(self) -> Tuple[FloatArray, FloatArray, FloatArray]:
        if self._unpolarised is None:
            r, t, a = _nacre.unpolarised(self.powers)
            self._unpolarised = (r, t, a)
        return self._unpolarised

    @property
    def R(self) -> FloatArray:
        """Unpolarised reflectance (R_s + R_p)/2."""
        return self._rta()[0]

    @property
    def T(self) -> FloatArray:
        """Unpolarised transmittance (T_s + T_p)/2."""
        return self._rta()[1]

    @property
    def A(self) -> FloatArray:
        """Absorptance 1 − R − T in the films (never below 0)."""
        return self._rta()[2]

    def _d_rt(self) -> Tuple[FloatArray, FloatArray]:
        if self.d_thickness is None:
            raise NacreError("no derivatives: call nacre.spectrum(..., jacobian=True)")
        if self._d_unpolarised is None:
            r, t, _ = _nacre.unpolarised(self.d_thickness)
            self._d_unpolarised = (r, t)
        return self._d_unpolarised

    @property
    def dR_dd(self) -> FloatArray:
        """∂R/∂d_j per nm (R unpolarised), shape (angles, wavelengths, films): the
        ``dR_dd1 … dR_ddL`` columns of ``nacre spectrum --jacobian``."""
        return self._d_rt()[0]

    @property
    def dT_dd(self) -> FloatArray:
        """∂T/∂d_j per nm (T unpolarised), shape (angles, wavelengths, films): the
        ``dT_dd1 … dT_ddL`` columns of ``nacre spectrum --jacobian``."""
        return self._d_rt()[1]

    def __getitem__(self, key: str) -> FloatArray:
        if key not in self._KEYS:
            raise KeyError(key)
        return getattr(self, key)  # type: ignore[no-any-return]

    def __iter__(self) -> Iterator[str]:
        return iter(self._KEYS)

    def __len__(self) -> int:
        return len(self._KEYS)

    def __repr__(self) -> str:
        return f"Spectrum(shape={self.shape})"


def spectrum(
    stack: Stack,
    angles_deg: ArrayLike,
    wavelengths_nm: ArrayLike,
    thickness_nm: Optional[ArrayLike] = None,
    layer: int = 1,
    jacobian: bool = False,
) -> Spectrum:
    """Exact reflectance and transmittance of ``stack`` (transfer matrices, complex Snell's
    law and Fresnel coefficients for absorbing media; the computation of ``nacre spectrum``).

    ``angles_deg`` (strictly between −90 and 90) and ``wavelengths_nm`` (vacuum, > 0) are
    numbers or 1-D sequences; the result's arrays have shape (angles, wavelengths). With
    ``thickness_nm`` (a 1-D sequence, nm ≥ 0), film number ``layer`` (1 = top film) takes each
    thickness in turn and the arrays have shape (angles, wavelengths, thicknesses).

    With ``jacobian=True`` (not with ``thickness_nm``; coherent stacks only) the result also
    holds the exact derivatives of the powers by every film's thickness, per nm, computed
    through the recurrence by a reverse sweep (the ``--jacobian`` columns of
    ``nacre spectrum``): :attr:`Spectrum.d_thickness`, shape (angles, wavelengths, films, 4)
    for ∂R_s, ∂R_p, ∂T_s, ∂T_p, and :attr:`Spectrum.dR_dd`, :attr:`Spectrum.dT_dd`, shape
    (angles, wavelengths, films), for the unpolarised R and T.

    A coherent film far thicker than the wavelength grid can follow (its fringes finer than
    the step, more than 20 orders thick) emits an :class:`UndersamplingWarning` with the
    text ``nacre spectrum`` prints (not for a ``thickness_nm`` sweep); mark such a slab
    incoherent.
    """
    a = _axis(angles_deg, "angles_deg")
    w = _axis(wavelengths_nm, "wavelengths_nm")
    d = None if thickness_nm is None else _axis(thickness_nm, "thickness_nm")
    if isinstance(layer, bool) or not isinstance(layer, (int, np.integer)) or layer < 1:
        raise NacreError(f"layer `{layer}`: expected a film number, 1 for the top film")
    if jacobian:
        if d is not None:
            raise NacreError("jacobian=True: derivatives are by the stack's own thicknesses, "
                             "not with thickness_nm")
        powers, d_thickness, warned = _nacre.spectrum_jacobian(stack, a, w)
        _warn(warned)
        return Spectrum(a, w, None, powers, d_thickness)
    powers, warned = _nacre.spectrum(stack, a, w, d, int(layer))
    _warn(warned)
    return Spectrum(a, w, d, powers)


@dataclass(frozen=True, eq=False)
class Colour:
    """Colours of a stack at broadcast points; ``xyz`` and ``rgb`` have the points' shape
    plus a last axis of 3.

    ``xyz`` is CIE XYZ under the illuminant with a perfect reflector at Y = 1; ``rgb`` is
    linear in the output space (equal to ``xyz`` for ``space="xyz"``). The colours of
    ``nacre color``'s CSV columns X, Y, Z and R, G, B.
    """

    angle_deg: FloatArray
    """Incidence angle of each point, degrees."""
    thickness_nm: FloatArray
    """The first film's thickness at each point, nm (0 with no film)."""
    film_ior: FloatArray
    """The first film's real index at each point (its index at 550 nm when not overridden;
    the ambient's with no film)."""
    xyz: FloatArray
    """CIE XYZ, shape (..., 3)."""
    rgb: FloatArray
    """Output-space colour, shape (..., 3)."""
    method: str
    """The method."""
    monte_carlo: Optional[Tuple[int, float]] = field(default=None)
    """``rough-mc`` only: samples per point and the largest standard error per channel."""


def color(
    stack: Stack,
    angles_deg: ArrayLike,
    thickness_nm: Optional[ArrayLike] = None,
    film_ior: Optional[ArrayLike] = None,
    method: str = "spectral",
    *,
    quantity: str = "r",
    observer: Optional[str] = None,
    illuminant: Optional[str] = None,
    space: Optional[str] = None,
    roughness: Optional[float] = None,
    fourier_table: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Colour:
    """The colour of ``stack``'s reflectance (``quantity="r"``) or transmittance into the
    substrate (``"t"``) by ``method`` — every method of ``nacre color``:

    * ``"spectral"``: the exact reference (integration over 360–830 nm resolving the
      stack's fringes);
    * ``"lut:NAME"`` / ``"lut:PATH.json"``: a baked film-lut, interpolated as a GPU samples
      it (the table fixes observer, illuminant and space);
    * ``"rough-lut:NAME"`` and ``"rough-mc[:N]"`` with ``roughness=`` (GGX α): the rough
      film lobe's directional albedo from a table, and its Monte Carlo reference;
    * ``"rgb3"``, ``"samples:N"``: one wavelength per channel, N wavelengths;
    * ``"stack"``, ``"stack:N"``: the real-time multilayer technique ``film_stack``;
    * ``"fourier:M"``, ``"fourier:auto"`` (``:SIGMA_NM``), ``"fourier-exact:…"``: Belcour &
      Barla 2017 Eq. 10 with exact Fresnel terms (``fourier_table=`` a name or manifest);
    * ``"gaussian"``: glTF ``KHR_materials_iridescence``'s Gaussian-fit approximation.

    ``angles_deg``, ``thickness_nm`` and ``film_ior`` broadcast against each other
    (numpy rules); a given ``thickness_nm`` / ``film_ior`` overrides the first film's
    thickness / real index at that point. ``observer``: ``"1931"`` or ``"1964"``;
    ``illuminant``: ``"d65"``, ``"d50"``, ``"a"``, ``"e"``; ``space``: ``"srgb"``,
    ``"rec2020"``, ``"p3"``, ``"acescg"``, ``"xyz"`` (default 1931, d65, srgb, or the table's).
    """
    arrays = [np.asarray(angles_deg, dtype=np.float64)]
    if thickness_nm is not None:
        arrays.append(np.asarray(thickness_nm, dtype=np.float64))
    if film_ior is not None:
        arrays.append(np.asarray(film_ior, dtype=np.float64))
    try:
        b = np.broadcast_arrays(*arrays)
    except ValueError as e:
        raise NacreError(f"angles_deg, thickness_nm and film_ior do not broadcast: {e}") from None
    shape = b[0].shape
    flat = [np.ascontiguousarray(x.reshape(-1)) for x in b]
    a = flat.pop(0)
    d = flat.pop(0) if thickness_nm is not None else None
    n = flat.pop(0) if film_ior is not None else None
    table = None if fourier_table is None else os.fspath(fourier_table)
    if roughness is not None:
        roughness = float(roughness)
    xyz, rgb, dd, nn, mc, warned = _nacre.color(
        stack, a, d, n, method, quantity, observer, illuminant, space, roughness, table
    )
    _warn(warned)
    return Colour(
        angle_deg=a.reshape(shape),
        thickness_nm=dd.reshape(shape),
        film_ior=nn.reshape(shape),
        xyz=xyz.reshape(shape + (3,)),
        rgb=rgb.reshape(shape + (3,)),
        method=method,
        monte_carlo=mc,
    )


class Table:
    """A baked table (``film-lut``, ``rough-film-lut``, ``fourier`` or ``diffraction``),
    read through its manifest with its checksums verified."""

    def __init__(self, native: _nacre.Table) -> None:
        self._t = native
        self._manifest: Dict[str, Any] = json.loads(native.manifest_json)

    @classmethod
    def load(cls, name_or_manifest: Union[str, "os.PathLike[str]"]) -> "Table":
        """A default-set table by name (``"soap-film"``, ``"film-dielectric"``, …: the
        ``tables/baked/`` folder of the working directory, else of the checkout nacre was
        built from) or a manifest path (``.json``)."""
        return cls(_nacre.Table.load(os.fspath(name_or_manifest)))

    @property
    def name(self) -> str:
        """The table's name."""
        return self._t.name

    @property
    def kind(self) -> str:
        """``film-lut``, ``fourier``, ``rough-film-lut`` or ``diffraction``."""
        return self._t.kind

    @property
    def path(self) -> pathlib.Path:
        """The manifest's path."""
        return pathlib.Path(self._t.path)

    @property
    def manifest(self) -> Dict[str, Any]:
        """The manifest (what ``nacre info`` prints), as a dict."""
        return json.loads(self._t.manifest_json)  # type: ignore[no-any-return]

    @property
    def axes(self) -> List[Dict[str, Any]]:
        """The axes as the manifest records them: name, unit, count, min, max, mapping and
        its forward and inverse formulas."""
        return list(self._manifest["axes"])

    @property
    def quantities(self) -> List[str]:
        """Quantities with texels: ``reflectance`` and, where baked, ``transmittance``."""
        return list(self._t.quantities)

    def texels(self, quantity: str = "reflectance") -> NDArray[np.float32]:
        """The texels of a film-lut or rough-film-lut, float32, shape (z, y, x, 3) (x =
        cos θ axis, y = optical path difference, z = film index; α blocks × index for a
        rough-film-lut)."""
        return self._t.texels(quantity)

    def lookup(
        self,
        cos_theta: ArrayLike,
        thickness_nm: ArrayLike,
        film_ior: ArrayLike,
        quantity: str = "reflectance",
        roughness: Optional[ArrayLike] = None,
    ) -> FloatArray:
        """The colour exactly as a GPU samples the table at (cos θ, thickness_nm,
        film_ior) — trilinear filtering with clamp-to-edge addressing at the manifest's
        texel-centre convention (``nacre color --method lut:``); a rough-film-lut needs
        ``roughness`` (GGX α). Arguments broadcast; the result has their shape plus 3."""
        args = [cos_theta, thickness_nm, film_ior] + ([] if roughness is None else [roughness])
        b = np.broadcast_arrays(*[np.asarray(x, dtype=np.float64) for x in args])
        shape = b[0].shape
        flat = [np.ascontiguousarray(x.reshape(-1)) for x in b]
        alpha = flat[3] if roughness is not None else None
        out = self._t.lookup(flat[0], flat[1], flat[2], quantity, alpha)
        return out.reshape(shape + (3,))

    def sample(self, mu_nm: ArrayLike, sigma_mu_nm: ArrayLike = 0.0) -> NDArray[np.complex128]:
        """A fourier table's sensitivity transforms Ŝ_j(μ) at optical path differences
        ``mu_nm``, prefiltered for a standard deviation ``sigma_mu_nm`` in μ — the mip-chain
        sample a GPU takes (Belcour & Barla 2017 Eq. 10's Ŝ). Shape: broadcast + (3,)."""
        b = np.broadcast_arrays(np.asarray(mu_nm, dtype=np.float64), np.asarray(sigma_mu_nm, dtype=np.float64))
        shape = b[0].shape
        out = self._t.sample(*[np.ascontiguousarray(x.reshape(-1)) for x in b])
        return out.reshape(shape + (3,))

    def __repr__(self) -> str:
        return repr(self._t)


def bake(
    recipes: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    out_dir: Union[str, "os.PathLike[str]"],
) -> List[pathlib.Path]:
    """Bakes table recipes (TOML, ``tables/recipes/*.toml``) into ``out_dir`` as
    ``nacre bake RECIPE… --out DIR`` does; every recipe is checked before any is baked.
    Returns the manifests written."""
    if isinstance(recipes, (str, os.PathLike)):
        recipes = [recipes]
    paths = [os.fspath(r) for r in recipes]
    return [pathlib.Path(p) for p in _nacre.bake(paths, os.fspath(out_dir))]


def conformance(grid: str = "default") -> Dict[str, Any]:
    """The reference data of ``nacre conformance`` (glTF ``KHR_materials_iridescence``):
    exact reflectance colours of air | film | base, CIE 1931 2°, D65, linear sRGB, one row
    per (base, angle, thickness, film index). ``grid``: ``"quick"`` (2 080 rows),
    ``"default"`` (48 510) or ``"fine"`` (202 730).

    Returns arrays keyed ``base_ior`` (labels: ``"1.5"``, ``"au"``, …), ``angle_deg``,
    ``thickness_nm``, ``film_ior``, ``xyz`` and ``rgb`` (rows, 3), and glTF's approximation
    ``gltf_rgb`` (rows, 3) with its ``delta_e_2000`` against the reference."""
    rows = dict(_nacre.conformance(grid))
    rows["base_ior"] = np.asarray(rows["base_ior"], dtype=str)
    return rows


def materials() -> List[Tuple[str, str, Tuple[float, float]]]:
    """The bundled materials: ``(name, description, (min_nm, max_nm))``."""
    return list(_nacre.bundled_materials())
