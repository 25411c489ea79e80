"""``fit_spectrum``, ``fit_color`` and ``fit_gltf``: the computations of ``nacre fit
spectrum``, ``nacre fit color`` and ``nacre fit gltf`` with numpy arrays (re-exported by
:mod:`nacre`)."""

from __future__ import annotations

import json
import numbers
import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _nacre
from ._nacre import NacreError, Stack

FloatArray = NDArray[np.float64]

#: A film of a fit template: the ``--layer`` text of ``nacre fit spectrum``
#: (``"sio2@50:400"``, ``"1.3:1.7@100:600"``, ``"tio2@30nm"``), or a tuple
#: ``(material, thickness_nm)`` where a range is a pair: ``("sio2", (50, 400))``,
#: ``((1.3, 1.7), (100, 600))``, ``("tio2", 30)``; a third item ``True`` marks an
#: incoherent slab.
TemplateLayer = Union[str, Tuple[Any, Any], Tuple[Any, Any, bool]]


def _number(v: Any) -> str:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise NacreError(f"layers: expected a number or a (low, high) pair, got {v!r}")
    text = repr(float(v))
    return text[:-2] if text.endswith(".0") else text


def _material_text(m: Any, where: str) -> str:
    """A material as the command line writes it (``1.5``, ``0.27+2.9i``, a name, a path)."""
    if isinstance(m, bool):
        raise NacreError(f"{where}: a material is a number, a complex number, a name or a path, not a bool")
    if isinstance(m, complex):
        sign = "-" if m.imag < 0 else "+"
        return f"{float(m.real)!r}{sign}{abs(float(m.imag))!r}i"
    if isinstance(m, numbers.Real):
        return repr(float(m))
    if isinstance(m, (str, os.PathLike)):
        return os.fspath(m)
    raise NacreError(f"{where}: a material is a number, a complex number, a name or a path, not {type(m).__name__}")


def _range_text(v: Any) -> str:
    if isinstance(v, (tuple, list)):
        if len(v) != 2:
            raise NacreError(f"layers: a range is a (low, high) pair, got {v!r}")
        return f"{_number(v[0])}:{_number(v[1])}"
    return _number(v)


def _layer_text(i: int, layer: Any) -> str:
    """A template layer as its ``--layer`` text, parsed by the command line's parser."""
    if isinstance(layer, str):
        return layer
    if not isinstance(layer, (tuple, list)) or len(layer) not in (2, 3):
        raise NacreError(
            f"layers[{i}]: expected a `--layer` text (\"sio2@50:400\") or (material, thickness_nm[, incoherent]), got {layer!r}"
        )
    material, thickness = layer[0], layer[1]
    if isinstance(material, (tuple, list)):
        m = _range_text(material)
    else:
        m = _material_text(material, f"layers[{i}]")
    text = f"{m}@{_range_text(thickness)}"
    if len(layer) == 3:
        if not isinstance(layer[2], bool):
            raise NacreError(f"layers[{i}]: the third item (incoherent) must be a bool, got {layer[2]!r}")
        if layer[2]:
            text += ":incoherent"
    return text


def _baseline_text(v: Any, name: str) -> str:
    if isinstance(v, str):
        return v
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise NacreError(f"{name}: expected a number, \"free\" or \"poly:N\", got {v!r}")
    return repr(float(v))


@dataclass(frozen=True, eq=False)
class SpectrumFit:
    """The result of :func:`fit_spectrum`: for one spectrum (a 1-D ``measured``) each field
    holds that spectrum's values; for many (2-D ``measured``, one spectrum per row) every
    array gains a first axis of spectra and every list holds one item per spectrum.

    The same numbers as ``nacre fit spectrum`` (its recipe's values and ``[fit]`` table, or
    its thickness map's rows)."""

    params: List[str]
    """The free parameters, in the order of ``x``: ``layer1_thickness_nm``,
    ``layer2_index``, … (films top first, a film's index before its thickness)."""
    x: FloatArray
    """The fitted values, shape ([spectra,] params)."""
    sigma: FloatArray
    """Their 1σ uncertainties from the Jacobian (NaN where undetermined)."""
    rms: Union[float, FloatArray]
    """Root-mean-square of measured − fitted (unweighted)."""
    chi2: Union[float, FloatArray]
    """χ² = Σ ((measured − fitted)/σ)² (σ = 1 where not given)."""
    points: Union[int, List[int]]
    """Points fitted (inside ``fit_range``)."""
    scale: FloatArray
    """Scale polynomial coefficients in wavenumber, lowest degree first (the fixed value
    when fixed)."""
    offset: FloatArray
    """Offset polynomial coefficients, likewise."""
    iterations: Union[int, List[int]]
    """Levenberg–Marquardt iterations, all starts together."""
    starts: Union[int, List[int]]
    """Starts of the global search used."""
    on_bound: Union[List[bool], List[List[bool]]]
    """Per parameter: whether it sits on a bound of its range."""
    fringes: FloatArray
    """Per parameter: interference fringes its film spans over the data (NaN for an
    index)."""
    ambiguous: Union[Optional[List[float]], List[Optional[List[float]]]]
    """Another set of parameters that fits about as well (another fringe order), or None."""
    fitted: FloatArray
    """The fitted values a·R + b at every point fitted, shape ([spectra,] points)."""
    warnings: Union[List[str], List[List[str]]]
    """The command's warnings: a parameter on its bound, too few fringes, an ambiguous fit."""
    recipe: Union[str, List[str]]
    """The fitted stack as the recipe ``nacre fit spectrum -o FIT.toml`` writes (values with
    ``thickness_sigma_nm`` beside them and a ``[fit]`` table); ``Stack.from_recipe`` reads
    it."""

    def __getitem__(self, param: str) -> Union[float, FloatArray]:
        """The fitted value(s) of a parameter by name: ``fit["layer1_thickness_nm"]``."""
        try:
            k = self.params.index(param)
        except ValueError:
            raise KeyError(param) from None
        return self.x[..., k]  # type: ignore[no-any-return]

    def as_dict(self) -> Dict[str, Any]:
        """The fields as a dict."""
        return {f: getattr(self, f) for f in self.__dataclass_fields__}


def fit_spectrum(
    measured: ArrayLike,
    wavelengths_nm: ArrayLike,
    layers: Optional[Sequence[TemplateLayer]] = None,
    *,
    ambient: Any = None,
    substrate: Any = None,
    recipe: Optional[Union[str, "os.PathLike[str]"]] = None,
    angles_deg: ArrayLike = 0.0,
    sigma: Optional[ArrayLike] = None,
    quantity: str = "r",
    scale: Union[str, float] = 1.0,
    offset: Union[str, float] = 0.0,
    fit_range: Optional[Union[str, Tuple[float, float]]] = None,
    loss: str = "cauchy",
    starts: int = 64,
    material_db: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> SpectrumFit:
    """Fits a stack's free thicknesses and indices to measured reflectance (``quantity="r"``)
    or transmittance (``"t"``) spectra, globally over the bounds: ``nacre fit spectrum``.

    ``measured`` is one spectrum (1-D, one value per point) or many (2-D, one spectrum per
    row, all at the same points; fitted in parallel with the GIL released, each alone, so
    the results do not depend on the thread count). ``wavelengths_nm`` (vacuum, nm),
    ``angles_deg`` (incidence in the ambient; a number for all points) and ``sigma`` (each
    point's standard deviation) give the points; within an angle the wavelengths must
    increase.

    The template: ``layers``, top first, with ranges for the free values — the ``--layer``
    texts of the command (``"sio2@50:400"``: thickness free in 50–400 nm;
    ``"1.3:1.7@100:600"``: index free too) or tuples (``("sio2", (50, 400))``,
    ``((1.3, 1.7), (100, 600))``); ``ambient`` and ``substrate`` materials (default 1.0);
    or ``recipe``, a template recipe (TOML, ``thickness_nm = [LO, HI]``).

    ``scale`` and ``offset`` model R_measured ≈ a(λ)·R + b(λ): a number (fixed), ``"free"``
    or ``"poly:N"`` (a polynomial of degree N in wavenumber). ``fit_range``: only
    wavelengths in ``"START:END"`` or ``(START, END)`` nm. ``loss``: ``"cauchy"`` (robust)
    or ``"linear"``. ``starts``: most starts of the global search.
    """
    m = np.asarray(measured, dtype=np.float64)
    if m.ndim not in (1, 2):
        raise NacreError(f"measured: expected one spectrum (1-D) or one per row (2-D), got shape {m.shape}")
    one = m.ndim == 1
    m2 = np.ascontiguousarray(m.reshape(1, -1) if one else m)
    w = np.ascontiguousarray(np.asarray(wavelengths_nm, dtype=np.float64).reshape(-1))
    a = np.asarray(angles_deg, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(w.shape, float(a))
    a = np.ascontiguousarray(a.reshape(-1))
    s = None if sigma is None else np.ascontiguousarray(np.asarray(sigma, dtype=np.float64).reshape(-1))
    if recipe is not None and (layers is not None or ambient is not None or substrate is not None):
        raise NacreError("recipe: give either a template recipe or layers/ambient/substrate, not both")
    texts = None if layers is None else [_layer_text(i, l) for i, l in enumerate(layers)]
    amb = None if ambient is None else _material_text(ambient, "ambient")
    sub = None if substrate is None else _material_text(substrate, "substrate")
    if isinstance(fit_range, (tuple, list)):
        if len(fit_range) != 2:
            raise NacreError(f"fit_range: expected (START, END) in nm, got {fit_range!r}")
        fit_range = f"{_number(fit_range[0])}:{_number(fit_range[1])}"
    if isinstance(starts, bool) or not isinstance(starts, (int, np.integer)):
        raise NacreError(f"starts: expected a whole number, got {starts!r}")
    names = ["measured"] if one else [f"measured[{i}]" for i in range(m2.shape[0])]
    r = _nacre.fit_spectrum(
        m2,
        w,
        a,
        s,
        texts,
        amb,
        sub,
        None if recipe is None else os.fspath(recipe),
        None if material_db is None else os.fspath(material_db),
        quantity,
        _baseline_text(scale, "scale"),
        _baseline_text(offset, "offset"),
        fit_range,
        loss,
        max(int(starts), 0),
        names,
    )
    if one:
        return SpectrumFit(
            params=list(r["params"]),
            x=r["x"][0],
            sigma=r["sigma"][0],
            rms=float(r["rms"][0, 0]),
            chi2=float(r["chi2"][0, 0]),
            points=int(r["points"][0]),
            scale=r["scale"][0],
            offset=r["offset"][0],
            iterations=int(r["iterations"][0]),
            starts=int(r["starts"][0]),
            on_bound=list(r["on_bound"][0]),
            fringes=r["fringes"][0],
            ambiguous=r["ambiguous"][0],
            fitted=r["fitted"][0],
            warnings=list(r["warnings"][0]),
            recipe=r["recipes"][0],
        )
    return SpectrumFit(
        params=list(r["params"]),
        x=r["x"],
        sigma=r["sigma"],
        rms=r["rms"][:, 0],
        chi2=r["chi2"][:, 0],
        points=list(r["points"]),
        scale=r["scale"],
        offset=r["offset"],
        iterations=list(r["iterations"]),
        starts=list(r["starts"]),
        on_bound=[list(b) for b in r["on_bound"]],
        fringes=r["fringes"],
        ambiguous=list(r["ambiguous"]),
        fitted=r["fitted"],
        warnings=[list(w) for w in r["warnings"]],
        recipe=list(r["recipes"]),
    )


@dataclass(frozen=True, eq=False)
class ColourDesign:
    """The result of :func:`fit_color`: up to ``solutions`` distinct stacks, best first, each
    with the colour it achieves at every target row and the CIEDE2000 to the target there.

    The same numbers as ``nacre fit color`` (its recipes, ``--report`` rows and the lines it
    prints): the achieved colours are recomputed by ``nacre color``'s ``spectral`` method on
    the designed stack, so ``nacre.color(Stack.from_recipe(...), angles)`` shows them too."""

    params: List[str]
    """The free parameters, in the order of ``x``: ``layer1_thickness_nm``,
    ``layer2_index``, … (films top first, a film's index before its thickness)."""
    x: FloatArray
    """The designed values, shape (solutions, params): thicknesses rounded to 0.001 nm and
    indices to 10⁻⁵, as the recipe writes them."""
    colour: FloatArray
    """The achieved colour, linear in ``space`` (or XYZ), shape (solutions, rows, 3)."""
    lab: FloatArray
    """The achieved CIELAB under the illuminant, shape (solutions, rows, 3)."""
    delta_e: FloatArray
    """CIEDE2000 between target and achieved colour, shape (solutions, rows)."""
    iterations: List[int]
    """Levenberg–Marquardt iterations of each solution's polish."""
    target_lab: FloatArray
    """The targets in CIELAB, shape (rows, 3)."""
    target_colour: FloatArray
    """The targets as linear colours in ``space``, shape (rows, 3)."""
    samples: int
    """Samples of the global search over the bounds."""
    starts: int
    """Local polishes from the best samples."""
    reached_delta_e: float
    """A solution reaches the look when its largest ΔE2000 is at most this (1)."""
    recipes: List[str]
    """Each solution as the recipe ``nacre fit color -o FIT.toml`` writes (the designed stack
    and a ``[fit]`` table); ``Stack.from_recipe`` reads it."""
    summary: List[str]
    """The lines ``nacre fit color`` prints, one per solution: its values, ΔE2000 mean and
    max, and whether it reaches the look or how far the closest stack stays (at which row:
    ``lab[1]`` where the command names the file's line)."""
    weights: FloatArray
    """The rows' weights."""

    @property
    def mean_delta_e(self) -> FloatArray:
        """Per solution: the weighted mean ΔE2000 over the rows."""
        return (self.delta_e @ self.weights) / self.weights.sum()  # type: ignore[no-any-return]

    @property
    def max_delta_e(self) -> FloatArray:
        """Per solution: the largest ΔE2000 over the rows."""
        return self.delta_e.max(axis=1)  # type: ignore[no-any-return]

    @property
    def reached(self) -> List[bool]:
        """Per solution: whether every row is within ``reached_delta_e``."""
        return [bool(m <= self.reached_delta_e) for m in self.max_delta_e]

    def __getitem__(self, param: str) -> FloatArray:
        """The designed value of a parameter by name, one per solution:
        ``design["layer1_thickness_nm"]``."""
        try:
            k = self.params.index(param)
        except ValueError:
            raise KeyError(param) from None
        return self.x[:, k]  # type: ignore[no-any-return]

    def as_dict(self) -> Dict[str, Any]:
        """The fields as a dict."""
        return {f: getattr(self, f) for f in self.__dataclass_fields__}


def _whole(v: Any, name: str) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise NacreError(f"{name}: expected a whole number, got {v!r}")
    return int(v)


def fit_color(
    angles_deg: ArrayLike,
    layers: Optional[Sequence[TemplateLayer]] = None,
    *,
    rgb: Optional[ArrayLike] = None,
    xyz: Optional[ArrayLike] = None,
    lab: Optional[ArrayLike] = None,
    weights: Optional[ArrayLike] = None,
    ambient: Any = None,
    substrate: Any = None,
    recipe: Optional[Union[str, "os.PathLike[str]"]] = None,
    quantity: str = "r",
    observer: Optional[str] = None,
    illuminant: Optional[str] = None,
    space: Optional[str] = None,
    solutions: int = 1,
    distinct_nm: float = 10.0,
    starts: int = 16,
    material_db: Optional[Union[str, "os.PathLike[str]"]] = None,
    targets_name: str = "targets",
) -> ColourDesign:
    """Designs a stack's free thicknesses and indices for target colours seen at angles,
    globally over the bounds: ``nacre fit color``.

    The targets, one row per angle of ``angles_deg`` (incidence in the ambient, degrees),
    given as exactly one of ``rgb`` (linear R, G, B in ``space``, as :func:`color` returns
    them in ``Colour.rgb``), ``xyz`` (under the illuminant, perfect reflector Y = 1) or
    ``lab`` (CIELAB under the illuminant), each of shape (rows, 3); ``weights`` (> 0, one
    per row, default 1). ``quantity``: the reflected (``"r"``) or transmitted (``"t"``)
    colour. ``observer`` (``"1931"``, ``"1964"``), ``illuminant`` (``"d65"``, ``"d50"``,
    ``"a"``, ``"e"``) and ``space`` (``"srgb"``, ``"rec2020"``, ``"p3"``, ``"acescg"``,
    ``"xyz"``) as in :func:`color` (default 1931, d65, srgb).

    The template as in :func:`fit_spectrum`: ``layers`` with ranges for the free values
    (``"tio2@20:300"``, ``("sio2", (20, 300))``, ``((1.3, 1.7), (100, 600))``), ``ambient``
    and ``substrate``, or a template ``recipe``.

    The objective is the weighted sum of squared CIEDE2000 over the rows; the search samples
    the whole box and polishes the ``starts`` best samples with Levenberg–Marquardt on the
    exact ΔE2000 gradient. ``solutions``: up to K (1–100) distinct stacks, best first (two
    differ when a free thickness differs by more than ``distinct_nm``). A look out of reach
    still gets its closest stack; ``ColourDesign.summary`` says how far it stays. The GIL is
    released while it runs. ``targets_name`` is what the recipes name the targets (the
    command names the file).
    """
    given = [(k, v) for k, v in (("rgb", rgb), ("xyz", xyz), ("lab", lab)) if v is not None]
    if len(given) != 1:
        raise NacreError(
            "rgb, xyz, lab: give the target colours as exactly one of them, "
            f"got {', '.join(k for k, _ in given) or 'none'}"
        )
    kind, values = given[0]
    t = np.asarray(values, dtype=np.float64)
    if t.ndim == 1 and t.shape[0] == 3:
        t = t.reshape(1, 3)
    if t.ndim != 2 or t.shape[1] != 3:
        raise NacreError(f"{kind}: expected one colour of three values per row, shape (rows, 3), got shape {t.shape}")
    a = np.asarray(angles_deg, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(t.shape[0], float(a))
    if a.ndim != 1:
        raise NacreError(f"angles_deg: expected a number or a 1-D sequence, got shape {a.shape}")
    w = None if weights is None else np.ascontiguousarray(np.asarray(weights, dtype=np.float64).reshape(-1))
    if recipe is not None and (layers is not None or ambient is not None or substrate is not None):
        raise NacreError("recipe: give either a template recipe or layers/ambient/substrate, not both")
    texts = None if layers is None else [_layer_text(i, l) for i, l in enumerate(layers)]
    amb = None if ambient is None else _material_text(ambient, "ambient")
    sub = None if substrate is None else _material_text(substrate, "substrate")
    n_solutions = _whole(solutions, "solutions")
    if n_solutions < 0:
        raise NacreError(f"solutions `{n_solutions}`: expected 1 to 100 stacks")
    n_starts = _whole(starts, "starts")
    if isinstance(distinct_nm, bool) or not isinstance(distinct_nm, numbers.Real):
        raise NacreError(f"distinct_nm: expected a thickness in nm, got {distinct_nm!r}")
    r = _nacre.fit_color(
        np.ascontiguousarray(t),
        kind,
        np.ascontiguousarray(a),
        w,
        texts,
        amb,
        sub,
        None if recipe is None else os.fspath(recipe),
        None if material_db is None else os.fspath(material_db),
        quantity,
        observer,
        illuminant,
        space,
        n_solutions,
        float(distinct_nm),
        max(n_starts, 0),
        str(targets_name),
    )
    return ColourDesign(
        params=list(r["params"]),
        x=r["x"],
        colour=r["colour"],
        lab=r["lab"],
        delta_e=r["delta_e"],
        iterations=list(r["iterations"]),
        target_lab=r["target_lab"],
        target_colour=r["target_colour"],
        samples=int(r["samples"]),
        starts=int(r["starts"]),
        reached_delta_e=float(r["reached_delta_e"]),
        recipes=list(r["recipes"]),
        summary=list(r["summary"]),
        weights=np.ones(t.shape[0]) if w is None else w,
    )


@dataclass(frozen=True)
class GltfFilm:
    """A ``KHR_materials_iridescence`` material's parameters."""

    iridescence_ior: float
    thickness_min_nm: float
    thickness_max_nm: float
    factor: float
    base_ior: Optional[float] = None
    """A dielectric base's ``KHR_materials_ior`` (None for a metal)."""
    base_colour: Optional[Tuple[float, float, float]] = None
    """A metallic base's base colour (its F0), linear sRGB (None for a dielectric)."""


@dataclass(frozen=True, eq=False)
class GltfFit:
    """The result of :func:`fit_gltf`: the fitted material and the naive mapping, each
    with its ΔE2000 (``mean``, ``max``) over 0–85° against the stack's exact colour."""

    film: GltfFilm
    errors: Dict[str, float]
    naive: GltfFilm
    naive_errors: Dict[str, float]
    evaluations: int
    """Evaluations of the glTF reference the fit took."""
    material_json: str
    """The glTF material object as ``nacre fit gltf -o FILE.json`` writes it."""

    @property
    def material(self) -> Dict[str, Any]:
        """The glTF material object, parsed."""
        return json.loads(self.material_json)  # type: ignore[no-any-return]


def _film(d: Dict[str, Any]) -> GltfFilm:
    colour = d.get("base_colour")
    return GltfFilm(
        iridescence_ior=d["iridescence_ior"],
        thickness_min_nm=d["thickness_min_nm"],
        thickness_max_nm=d["thickness_max_nm"],
        factor=d["factor"],
        base_ior=d.get("base_ior"),
        base_colour=None if colour is None else tuple(colour),  # type: ignore[arg-type]
    )


def fit_gltf(stack: Stack, thicknesses: Optional[Union[str, Tuple[float, float]]] = None) -> GltfFit:
    """The glTF ``KHR_materials_iridescence`` material (``iridescenceIor``, thickness minimum
    and maximum, factor, and ``KHR_materials_ior`` or a metallic base colour) whose glTF
    reference evaluation comes closest in CIEDE2000 to ``stack``'s exact reflected colour
    over 0–85°, scored beside the naive mapping: ``nacre fit gltf``. ``thicknesses``
    (``"START:END"`` or ``(START, END)`` nm): the top film's thickness over a thickness
    texture's range."""
    if isinstance(thicknesses, (tuple, list)):
        if len(thicknesses) != 2:
            raise NacreError(f"thickness_nm: expected (START, END) in nm, got {thicknesses!r}")
        thicknesses = f"{_number(thicknesses[0])}:{_number(thicknesses[1])}"
    r = _nacre.fit_gltf(stack, thicknesses)
    return GltfFit(
        film=_film(r["film"]),
        errors=dict(r["errors"]),
        naive=_film(r["naive"]),
        naive_errors=dict(r["naive_errors"]),
        evaluations=int(r["evaluations"]),
        material_json=r["material_json"],
    )
