"""The diffraction BSDF ``nacre_grating`` for Mitsuba 3 (spectral variants): Stam's BRDF over
a periodic height field, per wavelength, with the exact power spectrum.

Stam (1999, "Diffraction Shaders"), as ``nacre_optics::diffraction`` writes it (Single 2014,
Eq. 1.8–1.9; Dhillon et al. 2014 for the coherence window): with (u, v, w) = −ω_i − ω_r in
the grating frame (x across the lines, z the normal), k = 2π/λ,

    P_j(s) = (1/M) Σ_m e^{i s h_m} e^{+iκ_j·x_m}               s = k w  (exact: no Taylor series)
    P̃(q) = Σ_j P_j(s) exp(−σ_s² |q − κ_j|² / 2)                q = k (u, v)
    ρ(ω_i, ω_r, λ) = F²(θ_h) · G / w² · |P̃(q)|²,  G = (1 + ω_i·ω_r)² / (cos θ_i cos θ_r)

ρ is the relative reflectance of ``nacre diffraction`` (a flat perfect mirror gives 1 in its
specular direction). A flat mirror's lobe |P̃|² integrates to π/(σ_s k)² over (u, v), and
du dv = cos θ_r dω_r, so the BRDF whose mirror reflects all the light is

    f(ω_i, ω_r, λ) = ρ(ω_i, ω_r, λ) · (σ_s k)² / π                   (Stam's k² at every λ)

The P_j(s) are tabulated for every bin j of the height field at ``S_SAMPLES`` values of
s ∈ [−2 k_max, 0] by FFTs of e^{ish} and interpolated linearly in s (the phase s·h moves by
under 0.06 rad between samples for |h| ≤ 0.1 µm); the bins within reach of the window
(window weights ≥ 10⁻⁵) are summed coherently.

Sampling: one of the path's wavelengths λ (uniformly), a bin j with probability ∝
|P_j(s₀)|² (s₀ at 555 nm, normal incidence), then q ~ N(κ_j, 1/(2σ_s²)) per axis (the lobe
|P̃|² at k = 2π/λ), mixed with 10 % cosine-weighted directions; the density of the mixture
(over the wavelengths, bins and the cosine lobe) is evaluated exactly, so the estimator is
unbiased.

Rough gratings (``roughness``, GGX α > 0): the two-scale model (Holzschuch & Pacanowski,
"A two-scale microfacet reflectance model combining reflection and diffraction", SIGGRAPH
2017): the height field lies on microfacets whose normals m follow GGX of roughness α, and
Stam's BRDF f_μ is evaluated in each facet's frame (the grating frame turned so that its
normal is m, the direction across the lines kept as near as it can be). With Smith's
uncorrelated masking-shadowing G₂ = G₁(ω_i, m) G₁(ω_r, m) (Heitz, "Understanding the
masking-shadowing function", JCGT 3(2), 2014), the microfacet BRDF

    f(ω_i, ω_r) cos θ_r = ∫ f_μ(ω_i, ω_r; m) |ω_i·m| |ω_r·m| D(m) G₂ / cos θ_i dm
                        = E_{m ~ D_{ω_i}} [ f_μ(ω_i, ω_r; m) (ω_r·m)₊ G₁(ω_r, m) ]

with D_{ω_i}(m) = G₁(ω_i, m) (ω_i·m)₊ D(m) / cos θ_i the distribution of visible normals,
sampled exactly (Heitz, "Sampling the GGX distribution of visible normals", JCGT 7(4), 2018).
``eval`` draws one facet per call from a hash of the hit point, the path's wavelengths and ω_r
(every sample of a pixel lands elsewhere, so the pixel's mean is a Monte-Carlo estimate of the
integral), importance-sampled: a facet's lobe is 1/(σ_s k |w|) wide in slope, a few hundredths
of GGX's spread, so facets drawn from the visible normals would rarely put the light in it;
the slope is drawn instead, mostly, so that the light lands in one of the smooth lobes, and
the estimate divides by that mixture's density (``_rough_estimate``); ``sample`` draws a facet, then a direction from the smooth grating's lobes in the
facet's frame, with the weight f_μ (ω_r·m)₊ G₁(ω_r, m) / p_m(ω_r), an unbiased estimate of
f cos θ_r / p. The density reported to the integrator's MIS (``pdf``, ``bs.pdf``) is the
smooth grating's lobe mixture in the facet-free frame, one deterministic function of (ω_i, ω_r)
for both, so the MIS weights still sum to one. This is an independent estimate of the
two-scale model: no Gaussian in it, the change of w, G/w², F² and the masking kept.

Per point, the scenes may give the grating frame (``set_frame_function``: world normal and
direction across the lines) and the grating's coverage c ∈ [0, 1]; where c < 1 the surface
is a smooth mirror of reflectance F² (weight 1 − c), and an optional Lambertian ``base``
adds its albedo/π, scaled per point by ``set_base_weight_function`` where the scene gives one
(the snake's scales: a tint per scale).
"""

from __future__ import annotations

import math
from typing import Callable, Optional

import drjit as dr
import mitsuba as mi
import numpy as np

#: Samples of s = k·w in the P_j(s) tables.
S_SAMPLES = 96
#: Shortest wavelength served, nm (Mitsuba's spectral range starts at 360 nm).
MIN_WAVELENGTH_NM = 360.0
#: Window weights below this are dropped (nacre_optics::diffraction drops them below 1e-10;
#: here the neighbourhood summed per lookup is what costs, and a dropped bin changes
#: |P̃|² by at most 2·10⁻⁵ of its peak).
WINDOW_CUTOFF = 1e-5
#: Probability of a cosine-weighted direction in `sample`.
P_COSINE = 0.1
#: Probability that a rough grating's ``eval`` draws its facet through the smooth lobes (else
#: from GGX's slopes): see ``NacreGrating._rough_estimate``.
P_FACET_LOBE = 0.8


class Spectra:
    """P_j(s) of a height field ``heights_um`` (shape (ny, nx), µm, mean removed here), spaced
    ``pitch_um`` apart, as the interleaved float32 table Dr.Jit gathers from."""

    def __init__(self, heights_um: np.ndarray, pitch_um: float, coherence_diameter_um: float):
        h = np.atleast_2d(np.asarray(heights_um, dtype=np.float64))
        h = h - h.mean()
        self.ny, self.nx = h.shape
        self.pitch_um = float(pitch_um)
        self.sigma_um = coherence_diameter_um / 4.0
        self.dk = (2.0 * math.pi / (self.nx * pitch_um), 2.0 * math.pi / (self.ny * pitch_um))
        k_max = 2.0 * math.pi / (MIN_WAVELENGTH_NM * 1e-3)
        self.s_min = -2.0 * k_max
        s = np.linspace(self.s_min, 0.0, S_SAMPLES)
        # P[s, jy, jx] with DC at index 0 (numpy's order: negative frequencies last).
        p = np.fft.ifft2(np.exp(1j * s[:, None, None] * h[None, :, :]), axes=(1, 2))
        self.p = p
        self.table = np.stack([p.real, p.imag], axis=-1).astype(np.float32).reshape(-1)
        # Bins within reach of the window: |q − κ| ≤ reach.
        reach = math.sqrt(-2.0 * math.log(WINDOW_CUTOFF)) / self.sigma_um
        self.rx = 0 if self.nx == 1 else int(math.ceil(reach / self.dk[0]))
        self.ry = 0 if self.ny == 1 else int(math.ceil(reach / self.dk[1]))
        # Sampling weights: |P_j|² at 555 nm, normal incidence.
        k0 = 2.0 * math.pi / 0.555
        s0 = -2.0 * k0
        w = np.abs(np.fft.ifft2(np.exp(1j * s0 * h))) ** 2
        self.weights = w.reshape(-1)

    def bin_index(self, jx, jy):
        """Table index of signed bin (jx, jy) (Dr.Jit ints) and whether it exists."""
        valid = (jx >= -(self.nx // 2)) & (jx < (self.nx + 1) // 2) & (jy >= -(self.ny // 2)) & (jy < (self.ny + 1) // 2)
        ix = dr.select(jx < 0, jx + self.nx, jx)
        iy = dr.select(jy < 0, jy + self.ny, jy)
        return mi.UInt32(dr.select(valid, iy * self.nx + ix, 0)), valid


def cd_tracks(nx: int, ny: int, pitch_um: float, depth_um: float, seed: int) -> np.ndarray:
    """The CD-like height field of ``nacre_optics::diffraction::HeightField::cd_tracks`` (tracks
    along y 1.6 µm apart, seeded pits and lands 3T–11T long, 0.5 µm wide, exact box
    coverage), the same numbers: shape (ny, nx), µm, mean not removed."""
    track_pitch_nominal, pit_width, bit = 1.6, 0.5, 0.2777
    mask = (1 << 64) - 1

    def mix(z):
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        return z ^ (z >> 31)

    class Rng:
        def __init__(self, s, stream):
            self.state = mix(s ^ mix((stream + 1) & mask))

        def next_u64(self):
            self.state = (self.state + 0x9E3779B97F4A7C15) & mask
            return mix(self.state)

        def next_f64(self):
            return (self.next_u64() >> 11) * (1.0 / float(1 << 53))

    lx, ly = nx * pitch_um, ny * pitch_um
    tracks = max(int(round(lx / track_pitch_nominal)), 1)
    track_pitch = lx / tracks
    h = np.zeros((ny, nx))

    def cover(a, b, out, wrap):
        for shift in (-wrap, 0.0, wrap):
            a2, b2 = (a + shift) / pitch_um, (b + shift) / pitch_um
            lo = max(int(math.floor(a2)), 0)
            hi = min(max(int(math.ceil(b2)), 0), len(out))
            for i in range(lo, hi):
                out[i] += max(min(b2, i + 1.0) - max(a2, float(i)), 0.0)

    for t in range(tracks):
        rng = Rng(seed, t)
        centre = (t + 0.5) * track_pitch
        cov_x = [0.0] * nx
        cover(centre - 0.5 * pit_width, centre + 0.5 * pit_width, cov_x, lx)
        lengths, total = [], 0.0
        while total < ly or len(lengths) % 2 == 1:
            run = 3 + rng.next_u64() % 9
            lengths.append(run * bit)
            total += run * bit
        scale = ly / total
        y = rng.next_f64() * ly
        cov_y = [0.0] * ny
        for i, length in enumerate(lengths):
            length *= scale
            if i % 2 == 0:
                a = y % ly
                cover(a, a + length, cov_y, ly)
            y += length
        h -= depth_um * np.outer(np.array(cov_y), np.array(cov_x))
    return h


def fresnel_unpolarised(n: float, cos_theta):
    """Unpolarised Fresnel reflectance of a bulk dielectric of index ``n`` from air."""
    c = dr.clip(cos_theta, 0.0, 1.0)
    s2 = 1.0 - c * c
    ct = dr.sqrt(dr.maximum(1.0 - s2 / (n * n), 0.0))
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return 0.5 * (rs * rs + rp * rp)


def _hash_uniforms(*values):
    """Two uniforms in [0, 1) per lane from Dr.Jit floats: their bits mixed (the finaliser of
    MurmurHash3, Appleby 2008) — the per-call random numbers of a rough grating's ``eval``."""
    h = mi.UInt32(0x9E3779B9)
    for v in values:
        h = (h ^ dr.reinterpret_array(mi.UInt32, mi.Float(v))) * 0x85EBCA6B
        h = h ^ (h >> 13)
        h = h * 0xC2B2AE35
        h = h ^ (h >> 16)
    h2 = (h ^ 0x68E31DA4) * 0x1B873593
    h2 = h2 ^ (h2 >> 15)
    h2 = h2 * 0x85EBCA6B
    h2 = h2 ^ (h2 >> 13)
    scale = 1.0 / 16777216.0
    return mi.Float(h >> 8) * scale, mi.Float(h2 >> 8) * scale


def ggx_visible_normal(wi, alpha: float, u1, u2):
    """A GGX normal (roughness ``alpha``) from the distribution of normals visible from ``wi``
    (local frame, z up): Heitz 2018, "Sampling the GGX distribution of visible normals"."""
    vh = dr.normalize(mi.Vector3f(alpha * wi.x, alpha * wi.y, wi.z))
    lensq = vh.x * vh.x + vh.y * vh.y
    inv = dr.rsqrt(dr.maximum(lensq, 1e-20))
    t1 = dr.select(lensq > 1e-12, mi.Vector3f(-vh.y * inv, vh.x * inv, 0.0), mi.Vector3f(1.0, 0.0, 0.0))
    t2 = dr.cross(vh, t1)
    r = dr.sqrt(u1)
    phi = 2.0 * dr.pi * u2
    p1 = r * dr.cos(phi)
    p2 = r * dr.sin(phi)
    s = 0.5 * (1.0 + vh.z)
    p2 = (1.0 - s) * dr.sqrt(dr.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    nh = p1 * t1 + p2 * t2 + dr.sqrt(dr.maximum(1.0 - p1 * p1 - p2 * p2, 0.0)) * vh
    return dr.normalize(mi.Vector3f(alpha * nh.x, alpha * nh.y, dr.maximum(nh.z, 1e-6)))


def ggx_g1(v, m, alpha: float):
    """Smith's masking G₁(v, m) of GGX (Heitz 2014, Eq. 72): 2 / (1 + √(1 + α² tan²θ_v)) where
    v·m > 0 and v·n > 0, else 0."""
    cos2 = dr.maximum(v.z * v.z, 1e-12)
    tan2 = dr.maximum(1.0 - cos2, 0.0) / cos2
    g = 2.0 / (1.0 + dr.sqrt(1.0 + alpha * alpha * tan2))
    return dr.select((dr.dot(v, m) > 0) & (v.z > 0), g, 0.0)


def facet_frame(m):
    """The grating frame turned onto the facet normal ``m`` (local coordinates): x′ the
    direction across the lines made perpendicular to m, y′ = m × x′."""
    x = dr.normalize(mi.Vector3f(1.0 - m.x * m.x, -m.x * m.y, -m.x * m.z))
    return mi.Frame3f(x, dr.cross(m, x), m)


def _p_mirror(coverage):
    """Probability of sampling the clear part's mirror: 0.9 (1 − coverage), so that the
    glossy and diffuse lobes keep a chance where the grating is absent."""
    return 0.9 * (1.0 - coverage)


class NacreGrating(mi.BSDF):
    """Mitsuba BSDF ``nacre_grating`` (see the module docstring). Properties:

    * ``period_um`` and ``amplitude_um``: a sinusoidal grating h = a sin(2πx/d) (defaults
      1.6 µm, 0.05 µm); any periodic height field through :meth:`set_height_field`;
    * ``coherence_um`` — coherence diameter 4σ_s (default 32 µm, the bundled tables');
    * ``fresnel_ior`` — F² of a bulk dielectric at θ_h (default: F = 1);
    * ``base`` — RGB albedo of a Lambertian layer (default none);
    * ``roughness`` — GGX α of the grating's microfacets (default 0: smooth; see the module
      docstring).
    """

    def __init__(self, props: "mi.Properties") -> None:
        mi.BSDF.__init__(self, props)
        self._coherence_um = float(props.get("coherence_um", 32.0))
        period = float(props.get("period_um", 1.6))
        self.set_sine(period, float(props.get("amplitude_um", 0.05)))
        self.fresnel_ior = props.get("fresnel_ior", None)
        self.base = None
        if "base" in props:
            self.base = mi.load_dict({"type": "srgb", "color": props.get("base")})
        self.frame_fn: Optional[Callable] = None
        self.base_weight_fn: Optional[Callable] = None
        self.roughness = float(props.get("roughness", 0.0))
        if not (math.isfinite(self.roughness) and 0.0 <= self.roughness <= 1.0):
            raise ValueError(f"nacre_grating: roughness {self.roughness} (expected 0 to 1, the GGX α)")
        flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.DiffuseReflection
        self.m_components = [
            mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide,
            mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.FrontSide,
            mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide,
        ]
        self.m_flags = flags | mi.BSDFFlags.FrontSide

    def set_sine(self, period_um: float, amplitude_um: float, samples: int = 64) -> None:
        """A sinusoidal grating h = a sin(2πx/d), one period of ``samples`` samples."""
        x = np.arange(samples) * period_um / samples
        self.set_height_field((amplitude_um * np.sin(2.0 * math.pi * x / period_um))[None, :], period_um / samples)

    def set_height_field(self, heights_um: np.ndarray, pitch_um: float) -> None:
        """A periodic height field, shape (ny, nx) or (nx,), µm, ``pitch_um`` apart."""
        self.spectra = Spectra(heights_um, pitch_um, self._coherence_um)
        self._table = mi.Float(self.spectra.table)
        self._sampler = mi.DiscreteDistribution(mi.Float(self.spectra.weights.astype(np.float32)))

    def set_frame_function(self, fn: Optional[Callable]) -> None:
        """``fn(si) -> (normal, across, coverage)``: world unit normal, world direction across
        the lines (any length, not parallel to the normal) and grating coverage in [0, 1]."""
        self.frame_fn = fn

    def set_base_weight_function(self, fn: Optional[Callable]) -> None:
        """``fn(si) -> weight``: a factor ≥ 0 on the ``base`` albedo at each point (default 1)."""
        self.base_weight_fn = fn

    # ─── Frames ────────────────────────────────────────────────────────────────────

    def _frame(self, si):
        """(grating frame in world space, coverage); default: the shading frame, coverage 1."""
        if self.frame_fn is None:
            return mi.Frame3f(si.sh_frame.s, si.sh_frame.t, si.sh_frame.n), mi.Float(1.0)
        n, across, coverage = self.frame_fn(si)
        s = dr.normalize(across - n * dr.dot(across, n))
        return mi.Frame3f(s, dr.cross(n, s), n), coverage

    def _to_grating(self, si, frame, v_local):
        return frame.to_local(si.to_world(v_local))

    # ─── The BRDF ──────────────────────────────────────────────────────────────────

    def _p_tilde(self, k, wi, wo):
        """|P̃(q)|² at q = k(u, v), s = k w, per lane (Dr.Jit floats)."""
        sp = self.spectra
        u = -wi.x - wo.x
        v = -wi.y - wo.y
        w = -wi.z - wo.z
        s = k * w
        qx, qy = k * u, k * v
        # Interpolation in s.
        x = dr.clip((s - sp.s_min) / (-sp.s_min) * (S_SAMPLES - 1), 0.0, S_SAMPLES - 1.001)
        i0 = mi.UInt32(dr.floor(x))
        t = x - mi.Float(i0)
        plane = sp.nx * sp.ny
        cx = mi.Int32(dr.round(qx / sp.dk[0]))
        cy = mi.Int32(dr.round(qy / sp.dk[1])) if sp.ny > 1 else mi.Int32(0)
        sig2 = sp.sigma_um * sp.sigma_um
        side = 2 * sp.rx + 1
        count = side * (2 * sp.ry + 1)

        # One bin of the neighbourhood per iteration: a symbolic loop keeps the kernel small
        # (an unrolled 7 × 7 neighbourhood for 4 wavelengths took LLVM ~25 s to compile).
        def body(n, re, im):
            jx = cx + mi.Int32(n % side) - sp.rx
            jy = cy + mi.Int32(n // side) - sp.ry
            idx, valid = sp.bin_index(jx, jy)
            dx = qx - mi.Float(jx) * sp.dk[0]
            dy = qy - mi.Float(jy) * sp.dk[1]
            g = dr.exp(-0.5 * sig2 * (dx * dx + dy * dy))
            ok = valid & (g >= WINDOW_CUTOFF)
            a = 2 * (i0 * plane + idx)
            b = 2 * ((i0 + 1) * plane + idx)
            pr = dr.lerp(dr.gather(mi.Float, self._table, a, ok), dr.gather(mi.Float, self._table, b, ok), t)
            pi = dr.lerp(dr.gather(mi.Float, self._table, a + 1, ok), dr.gather(mi.Float, self._table, b + 1, ok), t)
            return n + 1, re + dr.select(ok, pr * g, 0.0), im + dr.select(ok, pi * g, 0.0)

        _, re, im = dr.while_loop(
            state=(mi.UInt32(0), dr.zeros(mi.Float, dr.width(qx)), dr.zeros(mi.Float, dr.width(qx))),
            cond=lambda n, re, im: n < count,
            body=body,
        )
        return re * re + im * im

    def rho(self, wi, wo, wavelength_nm):
        """ρ(ω_i, ω_r, λ) in the grating frame (both directions pointing away)."""
        k = 2.0 * dr.pi / (wavelength_nm * 1e-3)
        cos_i, cos_o = wi.z, wo.z
        w = -(cos_i + cos_o)
        g = dr.square(1.0 + dr.dot(wi, wo)) / dr.maximum(cos_i * cos_o, 1e-12)
        value = g / dr.maximum(w * w, 1e-12) * self._p_tilde(k, wi, wo)
        if self.fresnel_ior is not None:
            h = dr.normalize(wi + wo)
            value *= fresnel_unpolarised(float(self.fresnel_ior), dr.dot(wi, h))
        return value

    def brdf(self, wi, wo, wavelength_nm):
        """f(ω_i, ω_r, λ) = ρ (σ_s k)²/π (per steradian, without the cosine)."""
        k = 2.0 * dr.pi / (wavelength_nm * 1e-3)
        return self.rho(wi, wo, wavelength_nm) * dr.square(self.spectra.sigma_um * k) / dr.pi

    def _base_term(self, si, wo, active):
        """The Lambertian base's albedo/π · cos θ_r (0 without one)."""
        if self.base is None:
            return mi.Spectrum(0.0)
        weight = dr.inv_pi * wo.z
        if self.base_weight_fn is not None:
            weight *= self.base_weight_fn(si)
        return self.base.eval(si, active) * weight

    def _q_density(self, qx, qy):
        """Density in q of the bin-and-Gaussian sampling (a bin j ∝ |P_j(s₀)|², then
        q ~ N(κ_j, 1/(2σ_s²)) per axis) at q = (qx, qy), rad/µm."""
        sp = self.spectra
        cx = mi.Int32(dr.round(qx / sp.dk[0]))
        cy = mi.Int32(dr.round(qy / sp.dk[1])) if sp.ny > 1 else mi.Int32(0)
        inv = 1.0 / float(self.spectra.weights.astype(np.float32).sum(dtype=np.float64))
        sig2 = sp.sigma_um * sp.sigma_um
        side = 2 * sp.rx + 1
        count = side * (2 * sp.ry + 1)

        def body(n, total):
            jx = cx + mi.Int32(n % side) - sp.rx
            jy = cy + mi.Int32(n // side) - sp.ry
            idx, valid = sp.bin_index(jx, jy)
            p_j = dr.gather(mi.Float, self._sampler.pmf, idx, valid) * inv
            dx = qx - mi.Float(jx) * sp.dk[0]
            dy = qy - mi.Float(jy) * sp.dk[1]
            return n + 1, total + dr.select(valid, p_j * dr.exp(-sig2 * (dx * dx + dy * dy)), 0.0)

        _, total = dr.while_loop(
            state=(mi.UInt32(0), dr.zeros(mi.Float, dr.width(qx))),
            cond=lambda n, total: n < count,
            body=body,
        )
        return total * (sig2 / dr.pi)

    def _rough_estimate(self, wi, wo, si):
        """One-sample estimate of the rough grating's f cos θ_r (module docstring) per
        wavelength lane, the facet's slope s drawn from a mixture: with probability
        ``P_FACET_LOBE`` through the smooth lobes (a lane, a bin and a Gaussian offset give q′,
        and s = (q′ − q)/(k w) puts the light in that lobe to first order), else from GGX's
        slope distribution P₂₂; the estimate is f_μ (ω_r·m)₊ G₁(ω_r, m) D_{ω_i}(s) / p(s),
        with D_{ω_i}(s) = G₁(ω_i, m) (cos θ_i − ω_i,t·s)₊ P₂₂(s) / cos θ_i the visible normals'
        density over slopes and p the mixture's density (over every lane), exact."""
        sp = self.spectra
        alpha = self.roughness
        a2 = alpha * alpha
        u1, u2 = _hash_uniforms(si.p.x, si.p.y, si.p.z, si.wavelengths[0], wo.x, wo.y)
        u3, u4 = _hash_uniforms(u1, u2, si.p.x, wo.z)
        u5, _ = _hash_uniforms(u3, u4, si.p.z)
        lanes = len(si.wavelengths)
        w = -(wi.z + wo.z)
        u, v = -wi.x - wo.x, -wi.y - wo.y
        # The lane, the bin and the Gaussian offset of the lobe branch.
        pick = dr.clip(u3, 0.0, 0.999999) * lanes
        lane = dr.floor(pick)
        k_sel = mi.Float(2.0 * dr.pi / (si.wavelengths[0] * 1e-3))
        for i in range(1, lanes):
            k_sel = dr.select(lane == i, 2.0 * dr.pi / (si.wavelengths[i] * 1e-3), k_sel)
        j = self._sampler.sample(dr.clip(pick - lane, 0.0, 0.999999))
        jx = mi.Int32(j % sp.nx)
        jy = mi.Int32(j // sp.nx)
        jx = dr.select(jx >= (sp.nx + 1) // 2, jx - sp.nx, jx)
        jy = dr.select(jy >= (sp.ny + 1) // 2, jy - sp.ny, jy)
        r = dr.sqrt(-dr.log(dr.maximum(1.0 - u1, 1e-12))) / sp.sigma_um
        phi = 2.0 * dr.pi * u2
        qx = mi.Float(jx) * sp.dk[0] + r * dr.cos(phi)
        qy = mi.Float(jy) * sp.dk[1] + r * dr.sin(phi)
        s_lobe_x = (qx - k_sel * u) / (k_sel * w)
        s_lobe_y = (qy - k_sel * v) / (k_sel * w)
        # GGX's slopes: |s| = α √(ξ/(1 − ξ)), uniform azimuth.
        rg = alpha * dr.sqrt(u4 / dr.maximum(1.0 - u4, 1e-7))
        lobe_branch = u5 < P_FACET_LOBE
        sx = dr.select(lobe_branch, s_lobe_x, rg * dr.cos(phi))
        sy = dr.select(lobe_branch, s_lobe_y, rg * dr.sin(phi))
        s2 = sx * sx + sy * sy
        p22 = 1.0 / (dr.pi * a2 * dr.square(1.0 + s2 / a2))
        density = (1.0 - P_FACET_LOBE) * p22
        lobe = mi.Float(0.0)
        for i in range(lanes):
            k = 2.0 * dr.pi / (si.wavelengths[i] * 1e-3)
            lobe += self._q_density(k * (u + w * sx), k * (v + w * sy)) * dr.square(k * w)
        density += P_FACET_LOBE * lobe / lanes
        m = dr.normalize(mi.Vector3f(-sx, -sy, 1.0))
        visible = ggx_g1(wi, m, alpha) * dr.maximum(wi.z - wi.x * sx - wi.y * sy, 0.0) * p22 / dr.maximum(wi.z, 1e-12)
        ratio = dr.select(density > 0, visible / density, 0.0)
        return self._facet_value(wi, wo, m, si.wavelengths) * ratio

    def _facet_value(self, wi, wo, m, wavelengths):
        """f_μ(ω_i, ω_r; m) (ω_r·m)₊ G₁(ω_r, m) per wavelength lane: Stam's BRDF in the facet's
        frame (both directions in the grating frame; 0 where either is below the facet)."""
        frame = facet_frame(m)
        wi_m, wo_m = frame.to_local(wi), frame.to_local(wo)
        ok = (wi_m.z > 0) & (wo_m.z > 0)
        lanes = [self.brdf(wi_m, wo_m, wavelengths[lane]) for lane in range(len(wavelengths))]
        weight = dr.select(ok, wo_m.z * ggx_g1(wo, m, self.roughness), 0.0)
        return mi.Spectrum(mi.UnpolarizedSpectrum(*lanes)) * weight

    def _mirror_f2(self, cos_i):
        if self.fresnel_ior is None:
            return mi.Float(1.0)
        return fresnel_unpolarised(float(self.fresnel_ior), cos_i)

    # ─── Sampling density of the lobe mixture ──────────────────────────────────────

    def _lobe_pdf(self, wi, wo, k):
        """Density (per solid angle) of the bin-and-Gaussian sampling at wavenumber ``k``
        (rad/µm): the density in q (``_q_density``) times dq/dω_r = k² cos θ_r."""
        qx, qy = k * (-wi.x - wo.x), k * (-wi.y - wo.y)
        return self._q_density(qx, qy) * k * k * dr.maximum(wo.z, 0.0)

    def _eval_pdf(self, ctx, si, wo_local, active):
        frame, coverage = self._frame(si)
        wi = self._to_grating(si, frame, si.wi)
        wo = self._to_grating(si, frame, wo_local)
        active = active & (wi.z > 0) & (wo.z > 0) & (mi.Frame3f.cos_theta(wo_local) > 0)
        value = mi.Spectrum(0.0)
        if self.roughness > 0.0:
            # One facet per call, importance-sampled (module docstring).
            value = self._rough_estimate(wi, wo, si) * coverage
        else:
            lanes = []
            for lane in range(len(si.wavelengths)):
                lanes.append(self.brdf(wi, wo, si.wavelengths[lane]))
            value = mi.Spectrum(mi.UnpolarizedSpectrum(*lanes)) * (coverage * wo.z)
        value += self._base_term(si, wo, active)
        lanes = len(si.wavelengths)
        lobe = mi.Float(0.0)
        for lane in range(lanes):
            lobe += self._lobe_pdf(wi, wo, 2.0 * dr.pi / (si.wavelengths[lane] * 1e-3))
        pdf = (1.0 - P_COSINE) * lobe / lanes + P_COSINE * dr.inv_pi * wo.z
        pdf *= 1.0 - _p_mirror(coverage)
        return dr.select(active, value, 0.0), dr.select(active, pdf, 0.0)

    def eval(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)[0]

    def pdf(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)[1]

    def eval_pdf(self, ctx, si, wo, active=True):
        return self._eval_pdf(ctx, si, wo, active)

    def sample(self, ctx, si, sample1, sample2, active=True):
        frame, coverage = self._frame(si)
        wi = self._to_grating(si, frame, si.wi)
        active = active & (wi.z > 0)
        bs = dr.zeros(mi.BSDFSample3f)
        # The clear part (1 − coverage): a smooth mirror, chosen with probability p_m.
        p_m = _p_mirror(coverage)
        mirror = sample1 < p_m
        u1 = dr.select(mirror, 0.0, (sample1 - p_m) / (1.0 - p_m))
        cosine = u1 < P_COSINE
        # A bin, then a Gaussian offset in q (Box–Muller on sample2).
        sp = self.spectra
        # One of the path's wavelengths, uniformly, places the lobes (the density is the
        # mixture over all of them, so every wavelength's orders are sampled).
        lanes = len(si.wavelengths)
        u2 = dr.clip((u1 - P_COSINE) / (1.0 - P_COSINE), 0.0, 0.999999) * lanes
        lane = dr.floor(u2)
        wavelength = si.wavelengths[0]
        for i in range(1, lanes):
            wavelength = dr.select(lane == i, si.wavelengths[i], wavelength)
        k = 2.0 * dr.pi / (wavelength * 1e-3)
        j = self._sampler.sample(dr.clip(u2 - lane, 0.0, 0.999999))
        jx = mi.Int32(j % sp.nx)
        jy = mi.Int32(j // sp.nx)
        jx = dr.select(jx >= (sp.nx + 1) // 2, jx - sp.nx, jx)
        jy = dr.select(jy >= (sp.ny + 1) // 2, jy - sp.ny, jy)
        r = dr.sqrt(-dr.log(dr.maximum(1.0 - sample2.x, 1e-12))) / sp.sigma_um
        phi = 2.0 * dr.pi * sample2.y
        qx = mi.Float(jx) * sp.dk[0] + r * dr.cos(phi)
        qy = mi.Float(jy) * sp.dk[1] + r * dr.sin(phi)
        # A rough grating: a facet from the visible normals, and the lobes in its frame.
        rough = self.roughness > 0.0
        if rough:
            v1, v2 = _hash_uniforms(sample1, sample2.x, sample2.y)
            m = ggx_visible_normal(wi, self.roughness, v1, v2)
            facet = facet_frame(m)
            wi_s = facet.to_local(wi)
        else:
            wi_s = wi
        ox = -wi_s.x - qx / k
        oy = -wi_s.y - qy / k
        oz2 = 1.0 - ox * ox - oy * oy
        wo_lobe = mi.Vector3f(ox, oy, dr.sqrt(dr.maximum(oz2, 0.0)))
        wo_cos = mi.warp.square_to_cosine_hemisphere(sample2)
        wo_s = dr.select(cosine, wo_cos, wo_lobe)
        wo_g = facet.to_world(wo_s) if rough else wo_s
        wo_world_g = si.to_local(frame.to_world(wo_g))
        value, pdf = self._eval_pdf(ctx, si, wo_world_g, active)
        ok_g = active & (cosine | (oz2 > 0)) & (pdf > 0)
        if rough:
            # f cos θ_r / p estimated as f_μ (ω_r·m)₊ G₁ / p_m (module docstring), with p_m the
            # lobe mixture's density in the facet's frame; `pdf` (the facet-free mixture) is
            # what the integrator's MIS sees.
            lobe = mi.Float(0.0)
            for i in range(lanes):
                lobe += self._lobe_pdf(wi_s, wo_s, 2.0 * dr.pi / (si.wavelengths[i] * 1e-3))
            density = ((1.0 - P_COSINE) * lobe / lanes + P_COSINE * dr.inv_pi * dr.maximum(wo_s.z, 0.0)) * (1.0 - p_m)
            value = self._facet_value(wi, wo_g, m, si.wavelengths) * coverage + self._base_term(si, wo_g, active)
            ok_g = ok_g & (wi_s.z > 0) & (wo_g.z > 0) & (density > 0)
        else:
            density = pdf
        weight_g = value / dr.select(density > 0, density, 1.0)
        # The mirror.
        wo_m = si.to_local(frame.to_world(mi.Vector3f(-wi.x, -wi.y, wi.z)))
        weight_m = mi.Spectrum(self._mirror_f2(wi.z) * (1.0 - coverage) / dr.maximum(p_m, 1e-6))
        bs.wo = dr.select(mirror, wo_m, wo_world_g)
        bs.pdf = dr.select(mirror, 1.0, pdf)
        bs.eta = 1.0
        bs.sampled_type = dr.select(mirror, mi.UInt32(+mi.BSDFFlags.DeltaReflection), mi.UInt32(+mi.BSDFFlags.GlossyReflection))
        bs.sampled_component = dr.select(mirror, mi.UInt32(1), mi.UInt32(0))
        weight = dr.select(mirror, weight_m, weight_g)
        ok = dr.select(mirror, active & (mi.Frame3f.cos_theta(wo_m) > 0), ok_g)
        return bs, dr.select(ok, weight, 0.0)

    def traverse(self, callback) -> None:
        pass

    def to_string(self) -> str:
        sp = self.spectra
        return f"NacreGrating[{sp.nx}×{sp.ny} samples, pitch {sp.pitch_um} µm, σ_s {sp.sigma_um} µm]"
