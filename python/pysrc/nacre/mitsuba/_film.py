"""The thin-film / multilayer BSDF ``nacre_film`` for Mitsuba 3 (spectral variants).

Reflectance of a coherent stack ambient | films (top first) | substrate at the vacuum
wavelength λ of each Mitsuba spectral lane, by the recursive Airy (Rouard) form of the
transfer-matrix method, the computation of ``nacre.spectrum`` (Born & Wolf, *Principles of
Optics*, §1.6; Heavens, *Optical Properties of Thin Solid Films*, 1955, §4):

    q_j = ñ_j cos θ_j = sqrt(ñ_j² − ñ_0² sin² θ_0)           (complex Snell's law, Im q_j ≥ 0)
    r_s(i, j) = (q_i − q_j) / (q_i + q_j)
    r_p(i, j) = (ñ_j² q_i − ñ_i² q_j) / (ñ_j² q_i + ñ_i² q_j)
    β_j = 2π d_j q_j / λ                                      (phase thickness of film j)
    Γ_{N+1} = r(N, N+1);  Γ_j = (r(j−1, j) + Γ_{j+1} e^{2iβ_j}) / (1 + r(j−1, j) Γ_{j+1} e^{2iβ_j})
    R = (|Γ_1^s|² + |Γ_1^p|²) / 2

The indices ñ_j(λ) = n + iκ are nacre's: :meth:`nacre.Stack.indices_at` tabulated every nm
from 360 to 830 nm and interpolated linearly (exact for the constant indices of the film
scenes). The top film's thickness is a parameter (``thickness_nm``) or a per-point function
of the surface interaction (:meth:`NacreFilm.set_thickness_function`, the scenes' thickness
maps). Transmission (``transmission=True``, a thin shell in one medium such as a soap
bubble) passes straight through with T = 1 − R, which needs a non-absorbing stack whose
substrate equals its ambient.

Surfaces: smooth (``alpha`` = 0, a delta reflection) or rough, the GGX microfacet model
with the film at the microfacet: f = R(ω_i·m) D(m) G(ω_i, ω_o) / (4 cos θ_i cos θ_o)
(Walter et al. 2007, Eq. 20), visible normals sampled (Heitz 2018); plus an optional
Lambertian base under the film weighted by 1 − R(cos θ_i) (``base`` RGB albedo). The BSDF
is two-sided: from below, the stack is seen mirrored.
"""

from __future__ import annotations

from typing import Callable, Optional, Sequence, Tuple

import drjit as dr
import mitsuba as mi
import numpy as np

import nacre

#: Wavelength grid of the index tables, nm (Mitsuba's spectral range).
GRID_START_NM = 360.0
GRID_END_NM = 830.0


def index_table(stack: "nacre.Stack") -> np.ndarray:
    """ñ_j(λ) of every medium of ``stack`` (ambient, films, substrate) every nm from
    :data:`GRID_START_NM` to :data:`GRID_END_NM`: shape (media, wavelengths, 2) as (n, κ)."""
    grid = np.arange(GRID_START_NM, GRID_END_NM + 0.5, 1.0)
    return np.array([stack.indices_at(float(w)) for w in grid], dtype=np.float64).transpose(1, 0, 2)


# ─── Complex arithmetic on pairs (re, im) of Dr.Jit floats ──────────────────────────────


def _cmul(a, b):
    return (a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])


def _cdiv(a, b):
    d = b[0] * b[0] + b[1] * b[1]
    return ((a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d)


def _cadd(a, b):
    return (a[0] + b[0], a[1] + b[1])


def _csub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _csqrt(z):
    """Principal square root (Re ≥ 0; Im ≥ 0 when Im z ≥ 0)."""
    r = dr.sqrt(z[0] * z[0] + z[1] * z[1])
    re = dr.sqrt(dr.maximum((r + z[0]) * 0.5, 0.0))
    im = dr.sqrt(dr.maximum((r - z[0]) * 0.5, 0.0))
    return (re, dr.select(z[1] < 0, -im, im))


def _cexp_i(z):
    """e^{i z}."""
    m = dr.exp(-z[1])
    return (m * dr.cos(z[0]), m * dr.sin(z[0]))


def stack_reflectance(indices: Sequence[Tuple], thickness_nm: Sequence, cos_theta, wavelength_nm):
    """Unpolarised reflectance R of ambient | films | substrate (see the module's equations).

    ``indices``: (n, κ) per medium as Dr.Jit floats (or numbers), ambient first;
    ``thickness_nm``: one per film (top first); ``cos_theta`` in the ambient (≥ 0);
    ``wavelength_nm`` vacuum. Works on any Dr.Jit float type, scalar floats included."""
    n0 = indices[0]
    sin2 = dr.maximum(1.0 - cos_theta * cos_theta, 0.0)
    n0_sq = _cmul(n0, n0)
    s2 = (n0_sq[0] * sin2, n0_sq[1] * sin2)
    eps = [_cmul(n, n) for n in indices]
    q = [_csqrt(_csub(e, s2)) for e in eps]
    # The ambient's own q: ñ_0 cos θ_0 (its sign fixed by the incoming direction).
    q[0] = (n0[0] * cos_theta, n0[1] * cos_theta)
    k = 2.0 * dr.pi / wavelength_nm
    total = 0.0
    for pol in ("s", "p"):
        def r(i, j):
            if pol == "s":
                return _cdiv(_csub(q[i], q[j]), _cadd(q[i], q[j]))
            a = _cmul(eps[j], q[i])
            b = _cmul(eps[i], q[j])
            return _cdiv(_csub(a, b), _cadd(a, b))

        last = len(indices) - 1
        gamma = r(last - 1, last)
        for j in range(last - 1, 0, -1):
            beta2 = (2.0 * k * thickness_nm[j - 1] * q[j][0], 2.0 * k * thickness_nm[j - 1] * q[j][1])
            g = _cmul(gamma, _cexp_i(beta2))
            rij = r(j - 1, j)
            gamma = _cdiv(_cadd(rij, g), _cadd((1.0, 0.0), _cmul(rij, g)))
        total = total + 0.5 * (gamma[0] * gamma[0] + gamma[1] * gamma[1])
    return total


class NacreFilm(mi.BSDF):
    """Mitsuba BSDF ``nacre_film`` (see the module docstring). Properties:

    * ``ambient``, ``film_ior``, ``thickness_nm``, ``substrate`` — one real film (defaults
      1.0, 1.33, 300 nm, 1.5); any coherent :class:`nacre.Stack` through :meth:`set_stack`;
    * ``alpha`` — GGX roughness α (0: smooth);
    * ``transmission`` — a thin shell transmitting 1 − R straight through;
    * ``base`` — RGB albedo of a Lambertian layer under the film (default none).
    """

    def __init__(self, props: "mi.Properties") -> None:
        mi.BSDF.__init__(self, props)
        self.thickness_fn: Optional[Callable] = None
        self.set_stack(
            nacre.Stack(
                float(props.get("ambient", 1.0)),
                [(float(props.get("film_ior", 1.33)), float(props.get("thickness_nm", 300.0)))],
                float(props.get("substrate", 1.5)),
            )
        )
        self.alpha = float(props.get("alpha", 0.0))
        self.transmission = bool(props.get("transmission", False))
        self._check_transmission()
        self.base = None
        if "base" in props:
            self.base = mi.load_dict({"type": "srgb", "color": props.get("base")})
        self.smooth = self.alpha <= 0.0
        self.distr = None if self.smooth else mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)
        flags = mi.BSDFFlags.DeltaReflection if self.smooth else mi.BSDFFlags.GlossyReflection
        flags = flags | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
        components = [flags]
        if self.transmission:
            components.append(mi.BSDFFlags.Null | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide)
            flags = flags | components[-1]
        if self.base is not None:
            components.append(mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide)
            flags = flags | components[-1]
        self.m_components = components
        self.m_flags = flags

    def set_stack(self, stack: "nacre.Stack", thickness_nm: Optional[float] = None) -> None:
        """Uses ``stack`` (a coherent :class:`nacre.Stack`), its top film ``thickness_nm`` thick
        when given."""
        if any(stack.incoherent):
            raise nacre.NacreError("nacre_film: incoherent layers are not supported")
        self.stack = stack
        table = index_table(stack)
        self._table = table
        self._media = table.shape[0]
        self._n = [mi.Float(np.ascontiguousarray(table[m, :, 0])) for m in range(self._media)]
        self._k = [mi.Float(np.ascontiguousarray(table[m, :, 1])) for m in range(self._media)]
        self._constant = [bool(np.all(table[m] == table[m, 0])) for m in range(self._media)]
        self._constant_values = [tuple(float(x) for x in table[m, 0]) for m in range(self._media)]
        self.thicknesses = [float(d) for _, d in stack.layers]
        if thickness_nm is not None:
            self.thicknesses[0] = float(thickness_nm)
        if getattr(self, "transmission", False):
            self._check_transmission()

    def _check_transmission(self) -> None:
        if not self.transmission:
            return
        t = self._table
        if np.any(t[:, :, 1] != 0.0) or not np.array_equal(t[0], t[-1]):
            raise nacre.NacreError(
                "nacre_film: transmission needs a non-absorbing stack whose substrate is its ambient"
            )

    def set_thickness_function(self, fn: Optional[Callable]) -> None:
        """``fn(si) -> mi.Float``: the top film's thickness (nm) at each surface point."""
        self.thickness_fn = fn

    # ─── Reflectance per spectral lane ─────────────────────────────────────────────

    def _index(self, m: int, wavelength):
        if self._constant[m]:
            n, k = self._constant_values[m]
            return (mi.Float(n), mi.Float(k))
        x = dr.clip(wavelength - GRID_START_NM, 0.0, GRID_END_NM - GRID_START_NM - 1e-4)
        i = mi.UInt32(dr.floor(x))
        t = x - mi.Float(i)
        n = dr.lerp(dr.gather(mi.Float, self._n[m], i), dr.gather(mi.Float, self._n[m], i + 1), t)
        k = dr.lerp(dr.gather(mi.Float, self._k[m], i), dr.gather(mi.Float, self._k[m], i + 1), t)
        return (n, k)

    def _thicknesses(self, si):
        d = list(self.thicknesses)
        if self.thickness_fn is not None:
            d[0] = self.thickness_fn(si)
        return d

    def reflectance(self, si, cos_theta):
        """R per spectral lane of ``si.wavelengths`` at incidence cosine ``cos_theta``."""
        d = self._thicknesses(si)
        lanes = []
        for lane in range(len(si.wavelengths)):
            wl = si.wavelengths[lane]
            idx = [self._index(m, wl) for m in range(self._media)]
            lanes.append(stack_reflectance(idx, d, dr.abs(cos_theta), wl))
        return mi.UnpolarizedSpectrum(*lanes)

    # ─── Mitsuba interface ─────────────────────────────────────────────────────────

    def _local(self, si, wo=None):
        """(wi, wo, flipped): directions mirrored into the upper hemisphere when wi is below."""
        flip = mi.Frame3f.cos_theta(si.wi) < 0
        wi = mi.Vector3f(si.wi.x, si.wi.y, dr.abs(si.wi.z))
        if wo is None:
            return wi, None, flip
        return wi, mi.Vector3f(wo.x, wo.y, dr.select(flip, -wo.z, wo.z)), flip

    def _p_diffuse(self):
        return 0.0 if self.base is None else 0.2

    def _eval_pdf(self, ctx, si, wo, active):
        wi, wo_l, _ = self._local(si, wo)
        cos_i = mi.Frame3f.cos_theta(wi)
        cos_o = mi.Frame3f.cos_theta(wo_l)
        active = active & (cos_i > 0) & (cos_o > 0)
        value = mi.Spectrum(0.0)
        pdf = mi.Float(0.0)
        pd = self._p_diffuse()
        if not self.smooth and ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0):
            m = dr.normalize(wi + wo_l)
            d = self.distr.eval(m)
            g = self.distr.G(wi, wo_l, m)
            f = self.reflectance(si, dr.dot(wi, m))
            value += f * (d * g / (4.0 * cos_i))
            pdf += (1.0 - pd) * self.distr.pdf(wi, m) / (4.0 * dr.abs(dr.dot(wo_l, m)))
        if self.base is not None and ctx.is_enabled(mi.BSDFFlags.DiffuseReflection, len(self.m_components) - 1):
            r_i = self.reflectance(si, cos_i)
            albedo = self.base.eval(si, active)
            value += (1.0 - r_i) * albedo * (dr.inv_pi * cos_o)
            pdf += pd * dr.inv_pi * cos_o
        value = dr.select(active, value, 0.0)
        pdf = dr.select(active, pdf, 0.0)
        return value, pdf

    def eval(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)[0]

    def pdf(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)[1]

    def eval_pdf(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)

    def sample(self, ctx, si, sample1, sample2, active=True):
        wi, _, flip = self._local(si)
        cos_i = mi.Frame3f.cos_theta(wi)
        active = active & (cos_i > 0)
        bs = dr.zeros(mi.BSDFSample3f)
        pd = self._p_diffuse()
        use_diffuse = sample1 < pd
        if self.smooth:
            r = self.reflectance(si, cos_i)
            wo = mi.reflect(wi)
            weight = r
            prob = mi.Float(1.0)
            sampled_type = mi.UInt32(+mi.BSDFFlags.DeltaReflection)
            component = mi.UInt32(0)
            if self.transmission:
                # Reflect with probability of the lanes' mean R (kept away from 0 and 1).
                p_r = dr.clip(dr.mean(r), 0.02, 0.98)
                u = dr.select(use_diffuse, 0.0, (sample1 - pd) / (1.0 - pd))
                through = u >= p_r
                wo = dr.select(through, -wi, wo)
                weight = dr.select(through, (1.0 - r) / (1.0 - p_r), r / p_r)
                prob = dr.select(through, 1.0 - p_r, p_r)
                sampled_type = dr.select(through, mi.UInt32(+mi.BSDFFlags.Null), sampled_type)
                component = dr.select(through, mi.UInt32(1), component)
            bs.wo = wo
            bs.pdf = prob
            bs.eta = 1.0
            bs.sampled_type = sampled_type
            bs.sampled_component = component
            weight = weight / (1.0 - pd)
            if self.base is not None:
                wo_d = mi.warp.square_to_cosine_hemisphere(sample2)
                r_i = self.reflectance(si, cos_i)
                albedo = self.base.eval(si, active)
                bs.wo = dr.select(use_diffuse, wo_d, bs.wo)
                bs.pdf = dr.select(use_diffuse, pd * mi.warp.square_to_cosine_hemisphere_pdf(wo_d), bs.pdf)
                bs.sampled_type = dr.select(use_diffuse, mi.UInt32(+mi.BSDFFlags.DiffuseReflection), bs.sampled_type)
                bs.sampled_component = dr.select(use_diffuse, mi.UInt32(len(self.m_components) - 1), bs.sampled_component)
                weight = dr.select(use_diffuse, (1.0 - r_i) * albedo / pd, weight)
        else:
            m, _ = self.distr.sample(wi, sample2)
            wo_s = mi.reflect(wi, m)
            wo_d = mi.warp.square_to_cosine_hemisphere(sample2)
            wo = dr.select(use_diffuse, wo_d, wo_s)
            bs.wo = wo
            bs.eta = 1.0
            bs.sampled_type = dr.select(use_diffuse, mi.UInt32(+mi.BSDFFlags.DiffuseReflection), mi.UInt32(+mi.BSDFFlags.GlossyReflection))
            bs.sampled_component = dr.select(use_diffuse, mi.UInt32(len(self.m_components) - 1), mi.UInt32(0))
            # The mixture's own value and density (one-sample MIS over the two lobes).
            wo_world = mi.Vector3f(wo.x, wo.y, dr.select(flip, -wo.z, wo.z))
            value, pdf = self._eval_pdf(mi.BSDFContext(), si, wo_world, active)
            bs.pdf = pdf
            weight = value / dr.select(pdf > 0, pdf, 1.0)
            active = active & (pdf > 0)
        bs.wo = mi.Vector3f(bs.wo.x, bs.wo.y, dr.select(flip, -bs.wo.z, bs.wo.z))
        return bs, dr.select(active, mi.Spectrum(weight), 0.0)

    def traverse(self, callback) -> None:
        pass

    def to_string(self) -> str:
        return f"NacreFilm[stack={self.stack!r}, alpha={self.alpha}, transmission={self.transmission}]"
