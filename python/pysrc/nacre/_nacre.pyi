# Type stubs of the native module nacre._nacre (python/src/*.rs). The public API, with
# broadcasting and docs, is nacre/__init__.py.
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import NDArray

__version__: str

class NacreError(ValueError): ...
class MaterialError(NacreError): ...
class TableError(NacreError): ...
class ParseError(NacreError): ...

_Material = Union[float, complex, str, "os.PathLike[str]"]

class Stack:
    def __init__(
        self,
        ambient: _Material,
        layers: Sequence[Union[Tuple[_Material, float], Tuple[_Material, float, bool], str]],
        substrate: _Material,
        material_db: Optional[Union[str, "os.PathLike[str]"]] = None,
    ) -> None: ...
    @staticmethod
    def from_recipe(
        path: Union[str, "os.PathLike[str]"],
        material_db: Optional[Union[str, "os.PathLike[str]"]] = None,
    ) -> "Stack": ...
    @property
    def ambient(self) -> str: ...
    @property
    def substrate(self) -> str: ...
    @property
    def layers(self) -> List[Tuple[str, float]]: ...
    @property
    def incoherent(self) -> List[bool]: ...
    def indices_at(self, wavelength_nm: float) -> List[Tuple[float, float]]: ...

class Table:
    @staticmethod
    def load(name_or_manifest: Union[str, "os.PathLike[str]"]) -> "Table": ...
    @property
    def path(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def manifest_json(self) -> str: ...
    @property
    def quantities(self) -> List[str]: ...
    def texels(self, quantity: str = "reflectance") -> NDArray[np.float32]: ...
    def lookup(
        self,
        cos_theta: NDArray[np.float64],
        thickness_nm: NDArray[np.float64],
        film_ior: NDArray[np.float64],
        quantity: str = "reflectance",
        roughness: Optional[NDArray[np.float64]] = None,
    ) -> NDArray[np.float64]: ...
    def sample(
        self, mu_nm: NDArray[np.float64], sigma_mu_nm: NDArray[np.float64]
    ) -> NDArray[np.complex128]: ...

def spectrum(
    stack: Stack,
    angles_deg: NDArray[np.float64],
    wavelengths_nm: NDArray[np.float64],
    thickness_nm: Optional[NDArray[np.float64]] = None,
    layer: int = 1,
) -> Tuple[NDArray[np.float64], List[str]]: ...
def spectrum_jacobian(
    stack: Stack,
    angles_deg: NDArray[np.float64],
    wavelengths_nm: NDArray[np.float64],
) -> Tuple[NDArray[np.float64], NDArray[np.float64], List[str]]: ...
def unpolarised(
    powers: NDArray[np.float64],
) -> List[NDArray[np.float64]]: ...
def color(
    stack: Stack,
    angles_deg: NDArray[np.float64],
    thickness_nm: Optional[NDArray[np.float64]] = None,
    film_ior: Optional[NDArray[np.float64]] = None,
    method: str = "spectral",
    quantity: str = "r",
    observer: Optional[str] = None,
    illuminant: Optional[str] = None,
    space: Optional[str] = None,
    roughness: Optional[float] = None,
    fourier_table: Optional[str] = None,
) -> Tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    Optional[Tuple[int, float]],
    List[str],
]: ...
def bake(recipes: Sequence[str], out_dir: str) -> List[str]: ...
def conformance(grid: str = "default") -> Dict[str, Any]: ...
def bundled_materials() -> List[Tuple[str, str, Tuple[float, float]]]: ...
def fit_spectrum(
    measured: NDArray[np.float64],
    wavelengths_nm: NDArray[np.float64],
    angles_deg: NDArray[np.float64],
    sigma: Optional[NDArray[np.float64]],
    layers: Optional[List[str]],
    ambient: Optional[str],
    substrate: Optional[str],
    recipe: Optional[str],
    material_db: Optional[str],
    quantity: str,
    scale: str,
    offset: str,
    fit_range: Optional[str],
    loss: str,
    starts: int,
    names: List[str],
) -> Dict[str, Any]: ...
def fit_color(
    targets: NDArray[np.float64],
    given: str,
    angles_deg: NDArray[np.float64],
    weights: Optional[NDArray[np.float64]],
    layers: Optional[List[str]],
    ambient: Optional[str],
    substrate: Optional[str],
    recipe: Optional[str],
    material_db: Optional[str],
    quantity: str,
    observer: Optional[str],
    illuminant: Optional[str],
    space: Optional[str],
    solutions: int,
    distinct_nm: float,
    starts: int,
    targets_name: str,
) -> Dict[str, Any]: ...
def fit_gltf(stack: Stack, thicknesses: Optional[str] = None) -> Dict[str, Any]: ...
