"""nacre's structural colour as Mitsuba 3 plugins (the optional extra ``nacre[mitsuba]``).

Mitsuba 3 has no thin-film and no diffraction BSDF; :func:`register` adds nacre's, for the
spectral variants (``scalar_spectral``, ``llvm_ad_spectral``, ``cuda_ad_spectral``):

* ``nacre_film`` — a coherent thin-film / multilayer stack on a smooth or GGX-rough surface,
  per wavelength (:mod:`nacre.mitsuba._film`);
* ``nacre_grating`` — Stam's diffraction BRDF over a periodic height field, per wavelength,
  with the exact power spectrum of the height field (:mod:`nacre.mitsuba._grating`).

::

    import mitsuba as mi
    import nacre.mitsuba
    nacre.mitsuba.register("llvm_ad_spectral")
    bsdf = mi.load_dict({"type": "nacre_film", "film_ior": 1.33, "thickness_nm": 400.0})

The core package never imports this module (nor Mitsuba).
"""

from __future__ import annotations

import importlib
from typing import Optional

import mitsuba as mi

#: The Mitsuba version the plugins are tested with (``pip install nacre[mitsuba]``).
MITSUBA_VERSION = "3.9.1"

_registered: Optional[str] = None


def register(variant: Optional[str] = None) -> str:
    """Sets Mitsuba's ``variant`` (default: the current one, else ``llvm_ad_spectral``) and
    registers ``nacre_film`` and ``nacre_grating`` for it; returns the variant. The plugins
    need a spectral variant: they evaluate every wavelength of a path."""
    global _registered
    if variant is None:
        variant = mi.variant() or "llvm_ad_spectral"
    if "spectral" not in variant:
        raise ValueError(f"nacre.mitsuba: variant `{variant}` is not spectral (expected e.g. llvm_ad_spectral)")
    mi.set_variant(variant)
    if _registered == variant:
        return variant
    from . import _film, _grating

    # The classes derive from the variant's mi.BSDF: rebuilt for each variant.
    film = importlib.reload(_film)
    grating = importlib.reload(_grating)
    mi.register_bsdf("nacre_film", lambda props: film.NacreFilm(props))
    mi.register_bsdf("nacre_grating", lambda props: grating.NacreGrating(props))
    _registered = variant
    return variant
