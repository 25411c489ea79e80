"""The scenes of ``nacre render --scene`` rebuilt for Mitsuba 3, with the same camera, lights,
environment, geometry and materials (``crates/runtime/src/render/options.rs``,
``shaders/scene.wgsl``, ``crates/runtime/src/diffraction/scene.rs``,
``shaders/diffraction_scene.wgsl``, ``crates/runtime/src/environment.rs``,
``crates/runtime/src/thickness_map.rs``).

Each scene is a dict of plain numbers (:data:`SCENES`) and :func:`build` turns one into a
Mitsuba scene; the pure-numpy parts (environment, thickness map, tone mapping) need no
Mitsuba.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Dict, Tuple

import numpy as np

# ─── Scenes ─────────────────────────────────────────────────────────────────────────────


@dataclass(frozen=True)
class Scene:
    """One scene: camera, lights, environment, tone mapper, and its surface."""

    name: str
    eye: Tuple[float, float, float]
    target: Tuple[float, float, float]
    fov_y_deg: float
    #: Direction towards the directional light (not unit), its colour and irradiance.
    light_direction: Tuple[float, float, float]
    light_colour: Tuple[float, float, float]
    light_intensity: float
    #: The studio with its sun (film scenes) or without (diffraction scenes).
    env_sun: bool
    env_intensity: float
    #: "pbr_neutral" (film scenes) or "max_channel" (diffraction scenes).
    tone_map: str
    surface: Dict[str, Any] = field(default_factory=dict)


_SUN = (-0.45, 0.70, 0.55)
_FILM_LIGHT = dict(light_direction=_SUN, light_colour=(1.0, 0.95, 0.88), light_intensity=3.0,
                   env_sun=True, env_intensity=1.0, tone_map="pbr_neutral")
_SPHERE_CAMERA = dict(eye=(0.0, 1.45, 3.9), target=(0.0, 1.0, 0.0), fov_y_deg=36.0)

SCENES: Dict[str, Scene] = {
    "sphere": Scene(
        "sphere", **_SPHERE_CAMERA, **_FILM_LIGHT,
        surface=dict(kind="sphere", film_ior=1.9, substrate=1.5, mapping=("svt", 380.0, 220.0),
                     drain_nm=0.0, map_scale=1.5, alpha=0.06, base=(0.02, 0.02, 0.025),
                     transmission=False),
    ),
    "bubble": Scene(
        "bubble", **_SPHERE_CAMERA, **_FILM_LIGHT,
        surface=dict(kind="sphere", film_ior=1.33, substrate=1.0, mapping=("svt", 170.0, 80.0),
                     drain_nm=700.0, map_scale=1.0, alpha=0.0, base=None, transmission=True),
    ),
    "plane": Scene(
        "plane", eye=(0.0, 1.1, 3.0), target=(0.0, 0.0, -2.5), fov_y_deg=55.0, **_FILM_LIGHT,
        surface=dict(kind="plane", film_ior=1.47, substrate=1.333, mapping=("gltf", 100.0, 700.0),
                     drain_nm=0.0, map_scale=2.0 / 3.0, alpha=0.02, base=(0.015, 0.02, 0.025),
                     transmission=False),
    ),
    "cd-disc": Scene(
        "cd-disc", eye=(0.0, 1.9, 2.2), target=(0.0, -0.12, 0.0), fov_y_deg=40.0,
        light_direction=(-0.35, 0.8, -0.5), light_colour=(1.0, 0.97, 0.92), light_intensity=3.0,
        env_sun=False, env_intensity=0.5, tone_map="max_channel",
        surface=dict(kind="cd-disc", grating="cd", fresnel_ior=None, base=None),
    ),
    # `nacre render --scene dvd-disc` (table dvd-tracks): the CD's disc, camera, frame and
    # environment with a DVD's tracks (a sinusoid of period 0.74 µm, amplitude 0.06 µm:
    # tables/recipes/dvd-tracks.toml), under a light from the left, 16.7° from the zenith
    # (DiffractionScene::light: the CD's light would leave the first orders beyond 505 nm off
    # the disc).
    "dvd-disc": Scene(
        "dvd-disc", eye=(0.0, 1.9, 2.2), target=(0.0, -0.12, 0.0), fov_y_deg=40.0,
        light_direction=(-0.3, 1.0, 0.0), light_colour=(1.0, 0.97, 0.92), light_intensity=3.0,
        env_sun=False, env_intensity=0.5, tone_map="max_channel",
        surface=dict(kind="cd-disc", grating="sine:0.74:0.06", fresnel_ior=None, base=None),
    ),
    "snake-skin": Scene(
        "snake-skin", eye=(0.35, 2.6, 2.3), target=(0.0, 0.55, 0.0), fov_y_deg=42.0,
        light_direction=(0.3, 0.85, -0.45), light_colour=(1.0, 0.97, 0.92), light_intensity=3.0,
        env_sun=False, env_intensity=0.5, tone_map="max_channel",
        # The dark skin under the scales: the shader's radiance base · E₀ cos θ_i, base =
        # (0.022, 0.018, 0.014) × the scale's tint, is a Lambertian of albedo π · base
        # (radiance albedo/π · E₀ cos θ_i); the tint per scale is _build._snake_tint.
        surface=dict(kind="snake-skin", grating="sine:0.8:0.07", fresnel_ior=1.56,
                     base=tuple(math.pi * c for c in (0.022, 0.018, 0.014))),
    ),
    # `nacre render --scene grating-plane` (table grating-1200): a 1200 lines/mm sinusoidal
    # grating (period 0.833333 µm, amplitude 0.06 µm, F = 1) on the square |x|, |z| ≤ 1 of
    # y = 0, lines along x, under a white directional light straight overhead.
    "grating-plane": Scene(
        "grating-plane", eye=(0.0, 1.8, 2.0), target=(0.0, 0.0, 0.0), fov_y_deg=40.0,
        light_direction=(0.0, 1.0, 0.0), light_colour=(1.0, 0.97, 0.92), light_intensity=3.0,
        env_sun=False, env_intensity=0.5, tone_map="max_channel",
        surface=dict(kind="grating-plane", grating="sine:0.833333:0.06", fresnel_ior=None),
    ),
}


# ─── Environment (crates/runtime/src/environment.rs) ───────────────────────────────────


def _smoothstep(e0: float, e1: float, x: np.ndarray) -> np.ndarray:
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def studio_environment(width: int = 256, height: int = 128, sun: bool = True) -> np.ndarray:
    """``procedural_environment_with(width, height, sun)``: the studio (sky, tiled ground, five
    softboxes, and with ``sun`` the sun and its glow), linear RGB, shape (height, width, 3),
    row 0 the zenith, column i at azimuth 2π((i + ½)/width − ½) from −z towards +x.
    ``tables/env/studio.exr`` is this at 256 × 128 with the sun, in half floats."""
    theta = math.pi * (np.arange(height) + 0.5) / height
    phi = 2.0 * math.pi * ((np.arange(width) + 0.5) / width - 0.5)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], axis=-1)
    y = d[..., 1]
    t = np.maximum(y, 0.0) ** 0.4
    horizon, zenith = np.array([0.75, 0.73, 0.7]), np.array([0.14, 0.26, 0.58])
    sky = horizon + (zenith - horizon) * t[..., None]
    down = np.maximum(-y, 1e-4)
    gx, gz = d[..., 0] * 1.5 / down, d[..., 2] * 1.5 / down

    def square(x):
        return np.clip(4.0 * np.sin(2.0 * math.pi * x / 4.0), -1.0, 1.0)

    distance = np.sqrt(gx * gx + gz * gz)
    contrast = 1.0 - _smoothstep(6.0, 30.0, distance)
    tile = 1.0 + 0.22 * square(gx) * square(gz) * contrast
    ground = np.stack([0.15 * tile, 0.135 * tile, 0.12 * tile], axis=-1)
    w = _smoothstep(-0.012, 0.012, y)[..., None]
    c = ground + (sky - ground) * w
    if sun:
        s = np.array(_SUN) / np.linalg.norm(_SUN)
        gamma = np.arccos(np.clip(d @ s, -1.0, 1.0))
        radiance = 60.0 * np.exp(-((gamma / 0.035) ** 2)) + 1.5 * np.exp(-((gamma / 0.3) ** 2))
        c = c + radiance[..., None] * np.array([1.0, 0.93, 0.82])
    boxes = [
        (140.0, 162.0, 8.0, 48.0, (6.0, 5.8, 5.4)),
        (-165.0, -128.0, 22.0, 58.0, (3.2, 3.6, 4.2)),
        (-70.0, 70.0, 72.0, 84.0, (4.0, 4.0, 4.0)),
        (-52.0, -40.0, 2.0, 40.0, (3.0, 2.9, 2.7)),
        (-60.0, 60.0, 20.0, 62.0, (2.2, 2.2, 2.3)),
    ]
    azimuth = np.degrees(ph)
    elevation = 90.0 - np.degrees(th)
    for a0, a1, e0, e1, rad in boxes:
        edge = 3.0
        wa = _smoothstep(a0 - edge, a0 + edge, azimuth) * (1.0 - _smoothstep(a1 - edge, a1 + edge, azimuth))
        we = _smoothstep(e0 - edge, e0 + edge, elevation) * (1.0 - _smoothstep(e1 - edge, e1 + edge, elevation))
        c = c + (wa * we)[..., None] * np.array(rad)
    return np.clip(c, 0.0, 60000.0).astype(np.float32)


def mitsuba_environment(env: np.ndarray, oversample: int = 4) -> np.ndarray:
    """``env`` (nacre's layout) resampled for Mitsuba's ``envmap``, which places column i at
    u = (i + ½)/w (as nacre) but row j at v = j/(h − 1) (nacre: (j + ½)/h): rows at
    v = j'/(oversample·h), which holds every knot of nacre's bilinear lookup, so that
    Mitsuba's bilinear lookup (rotated 180° about y) reproduces nacre's exactly."""
    h = env.shape[0]
    rows = oversample * h + 1
    v = np.arange(rows) / (rows - 1)
    pos = np.clip(v * h - 0.5, 0.0, h - 1.0)
    j0 = np.floor(pos).astype(int)
    j1 = np.minimum(j0 + 1, h - 1)
    t = (pos - j0)[:, None, None]
    return ((1.0 - t) * env[j0] + t * env[j1]).astype(np.float32)


# ─── Thickness map (crates/runtime/src/thickness_map.rs) ────────────────────────────────


def swirls(size: int = 256, shift_rad: float = 0.0) -> np.ndarray:
    """One channel of ``procedural_thickness_map(size)``: g ∈ [0, 1], shape (size, size), top
    row first (three rounds of domain warping, four waves, normalised to [0, 1])."""
    tau = 2.0 * math.pi
    warps = [
        (0.12, (1.0, 2.0), 0.3, (2.0, -1.0), 1.7),
        (0.07, (3.0, -2.0), 2.1, (-1.0, 3.0), 0.4),
        (0.035, (4.0, 5.0), 4.0, (5.0, -3.0), 2.9),
    ]
    waves = [(0.55, (2.0, 1.0), 0.0), (0.35, (-1.0, 3.0), 1.0), (0.2, (4.0, -2.0), 2.2), (0.1, (5.0, 6.0), 0.7)]
    c = (np.arange(size) + 0.5) / size
    v, u = np.meshgrid(c, c, indexing="ij")
    for a, fu, pu, fv, pv in warps:
        du = a * np.sin(tau * (fu[0] * u + fu[1] * v) + (pu + shift_rad))
        dv = a * np.sin(tau * (fv[0] * u + fv[1] * v) + (pv + shift_rad))
        u, v = u + du, v + dv
    g = sum(a * np.sin(tau * (f[0] * u + f[1] * v) + (p + shift_rad)) for a, f, p in waves)
    lo, hi = g.min(), g.max()
    return ((g - lo) / max(hi - lo, 1e-12)).astype(np.float32)


# ─── Display (shaders/output.wgsl) ──────────────────────────────────────────────────────


def tone_map(linear: np.ndarray, kind: str, exposure_ev: float = 0.0) -> np.ndarray:
    """Linear RGB radiance → displayed sRGB-encoded values in [0, 1], as ``nacre render``:
    ``pbr_neutral`` (Khronos PBR Neutral, the film scenes) or ``max_channel``
    (c/(1 + max channel), the diffraction scenes), then the sRGB transfer function."""
    c = np.nan_to_num(np.maximum(np.asarray(linear, dtype=np.float64) * 2.0 ** exposure_ev, 0.0))
    if kind == "max_channel":
        mapped = c / (1.0 + c.max(axis=-1, keepdims=True))
    elif kind == "pbr_neutral":
        x = c.min(axis=-1, keepdims=True)
        offset = np.where(x < 0.08, x - 6.25 * x * x, 0.04)
        c = c - offset
        peak = c.max(axis=-1, keepdims=True)
        start, desat = 0.8 - 0.04, 0.15
        d = 1.0 - start
        new_peak = 1.0 - d * d / (peak + d - start)
        scaled = c * (new_peak / np.maximum(peak, 1e-30))
        g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0)
        compressed = scaled + (new_peak - scaled) * g
        mapped = np.where(peak < start, c, compressed)
    else:
        raise ValueError(f"tone map `{kind}`: expected pbr_neutral or max_channel")
    mapped = np.clip(mapped, 0.0, 1.0)
    return np.where(mapped <= 0.0031308, 12.92 * mapped, 1.055 * mapped ** (1.0 / 2.4) - 0.055)


def srgb_to_linear(encoded: np.ndarray) -> np.ndarray:
    """The sRGB EOTF (IEC 61966-2-1), encoded [0, 1] → linear."""
    e = np.asarray(encoded, dtype=np.float64)
    return np.where(e <= 0.04045, e / 12.92, ((e + 0.055) / 1.055) ** 2.4)
