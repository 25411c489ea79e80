"""Mitsuba scenes of :data:`nacre.reference._scenes.SCENES` (needs ``nacre[mitsuba]``).

Geometry as the ray casters of ``nacre render``: the film scenes' sphere (centre (0, 1, 0),
radius 1) and plane y = 0 (to 1000 units), the CD's (and the DVD's) annulus 0.12 ≤ r ≤ 1 in
y = 0 (grating for 0.38 ≤ r ≤ 0.98, tracks circular, a plain mirror elsewhere), the snake's cylinder patch
y² + z² = 1, |x| ≤ 1.6, |φ| ≤ 1.31 with its domed diamond scales, per-scale ridge rotation and
fan, and matt scale edges, and grating-plane's 2 × 2 square (``shaders/diffraction_scene.wgsl``).
The curved surfaces are fine triangle meshes (the CD's circles with 1024 segments,
a sagitta of 5·10⁻⁶ units); the BSDFs take their normals and grating frames from the
analytic surfaces at each hit point.
"""

from __future__ import annotations

import math
import os
import tempfile
from typing import Any, Dict, List, Tuple

import drjit as dr
import mitsuba as mi
import numpy as np

import nacre
import nacre.mitsuba
from nacre.mitsuba import _film, _grating

from ._scenes import SCENES, Scene, mitsuba_environment, studio_environment, swirls

#: nacre's largest film thickness (THICKNESS_MAX_NM in shaders/material.wgsl).
THICKNESS_MAX_NM = 2000.0


def _unit(v) -> List[float]:
    a = np.asarray(v, dtype=np.float64)
    return list(a / np.linalg.norm(a))


def _mesh(name: str, vertices: np.ndarray, faces: np.ndarray) -> Dict[str, Any]:
    """A triangle mesh as a Mitsuba ``ply`` shape description (a binary PLY in a temporary
    folder, read when the scene loads)."""
    folder = tempfile.mkdtemp(prefix="nacre-reference-")
    path = os.path.join(folder, f"{name}.ply")
    v = np.ascontiguousarray(vertices, dtype="<f4")
    f = np.ascontiguousarray(faces, dtype="<u4")
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(f)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    face_rows = np.zeros(len(f), dtype=[("n", "u1"), ("i", "<u4", (3,))])
    face_rows["n"] = 3
    face_rows["i"] = f
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(v.tobytes())
        out.write(face_rows.tobytes())
    return {"type": "ply", "filename": path, "face_normals": True}


def _grid_faces(rows: int, cols: int) -> np.ndarray:
    """Two triangles per cell of a (rows + 1) × (cols + 1) vertex grid, counter-clockwise as
    seen from the side the grid's (row, col) → (r + 1, c + 1) orientation faces."""
    faces = []
    for r in range(rows):
        for c in range(cols):
            a = r * (cols + 1) + c
            b, d = a + 1, a + cols + 1
            faces += [(a, d, b), (b, d, d + 1)]
    return np.array(faces)


def _annulus(r0: float, r1: float, segments: int = 1024) -> Dict[str, Any]:
    phi = 2.0 * math.pi * np.arange(segments + 1) / segments
    rings = [np.stack([r * np.cos(phi), np.zeros_like(phi), -r * np.sin(phi)], axis=-1) for r in (r0, r1)]
    vertices = np.concatenate(rings)
    faces = []
    for i in range(segments):
        a, b = i, i + 1
        c, d = a + segments + 1, b + segments + 1
        faces += [(a, c, b), (b, c, d)]
    return _mesh("cd-disc", vertices, np.array(faces))


def _cylinder_patch(rows: int = 256, cols: int = 512) -> Dict[str, Any]:
    phi = np.linspace(-1.31, 1.31, rows + 1)
    x = np.linspace(-1.6, 1.6, cols + 1)
    pp, xx = np.meshgrid(phi, x, indexing="ij")
    vertices = np.stack([xx, np.cos(pp), np.sin(pp)], axis=-1).reshape(-1, 3)
    return _mesh("snake-skin", vertices, _grid_faces(rows, cols))


def _thickness_function(surface: Dict[str, Any]):
    """``si → thickness_nm`` of the film scenes: the built-in swirl map projected triplanarly
    (shaders/scene.wgsl), bilinear with wrap-around, mapped SVT d = a + b(2g − 1) or glTF
    d = mix(min, max, g), plus drain·½(1 − h)."""
    g = swirls(256)
    texture = mi.Texture2f(mi.TensorXf(g[:, :, None]), filter_mode=dr.FilterMode.Linear,
                           wrap_mode=dr.WrapMode.Repeat)
    s = 0.5 * surface["map_scale"]
    mode, a, b = surface["mapping"]
    drain = surface["drain_nm"]
    plane = surface["kind"] == "plane"

    def fn(si):
        if plane:
            p = mi.Vector3f(si.p.x, 0.0, si.p.z)
            n = mi.Vector3f(0.0, 1.0, 0.0)
            h = mi.Float(1.0)
        else:
            n = dr.normalize(si.p - mi.Vector3f(0.0, 1.0, 0.0))
            p = n
            h = n.y
        q = p * s + 0.5
        a4 = dr.square(dr.square(dr.abs(n)))
        w = a4 / dr.maximum(a4.x + a4.y + a4.z, 1e-30)
        total = mi.Float(0.0)
        mean = mi.Float(0.0)
        for axis, uv in ((0, (q.z, q.y)), (1, (q.x, q.z)), (2, (q.x, q.y))):
            wi = w[axis]
            keep = wi > 1e-3
            value = texture.eval(mi.Point2f(uv[0], uv[1]))[0]
            mean += dr.select(keep, wi * value, 0.0)
            total += dr.select(keep, wi, 0.0)
        gval = dr.clip(mean / dr.select(total > 0, total, 1.0), 0.0, 1.0)
        if mode == "gltf":
            d = a + (b - a) * gval
        else:
            d = a + b * (2.0 * gval - 1.0)
        d = d + drain * 0.5 * (1.0 - dr.clip(h, -1.0, 1.0))
        return dr.clip(d, 0.0, THICKNESS_MAX_NM)

    return fn


def _hash(cx, cy):
    """scene_hash of shaders/diffraction_scene.wgsl: a lattice cell → [0, 1)²."""
    ux = dr.reinterpret_array(mi.UInt32, cx)
    uy = dr.reinterpret_array(mi.UInt32, cy)
    h = (ux * 0x9E3779B9) ^ (uy * 0x85EBCA6B + 0x632BE5AB)
    h ^= h >> 16
    h *= 0x7FEB352D
    h ^= h >> 15
    h2 = h * 0x846CA68B
    return mi.Float(h >> 8) / 16777216.0, mi.Float((h2 ^ (h2 >> 16)) >> 8) / 16777216.0


def _smoothstep(e0, e1, x):
    t = dr.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _snake_scale(p):
    """The scale at point p of the snake: its position (fx, fy) ∈ [−0.5, 0.5)² in the rhombic
    lattice cell and the cell's two hashes (the shader's ``f`` and ``rnd``)."""
    phi = dr.atan2(p.z, p.y)
    qx, qy = p.x / 0.4, phi / 0.3
    gx, gy = qx + qy, qx - qy
    cx, cy = dr.floor(gx), dr.floor(gy)
    rx, ry = _hash(mi.Int32(cx), mi.Int32(cy))
    return gx - cx - 0.5, gy - cy - 0.5, rx, ry


def _snake_frame(si):
    """Normal, direction across the ridges and grating coverage of the snake's scales."""
    p = si.p
    n0 = mi.Vector3f(0.0, p.y, p.z)
    along = mi.Vector3f(1.0, 0.0, 0.0)
    around = dr.normalize(mi.Vector3f(0.0, -p.z, p.y))
    fx, fy, rx, _ = _snake_scale(p)
    la = 0.5 * (fx + fy)
    lb = 0.5 * (fx - fy)
    tilt = 0.55 * la * along + 0.9 * lb * around
    n = dr.normalize(n0 - tilt)
    angle = (rx - 0.5) * 0.52 + lb * 0.84
    ridge = dr.cos(angle) * along + dr.sin(angle) * around
    across = dr.cross(n, ridge)
    edge = dr.maximum(dr.abs(fx), dr.abs(fy))
    coverage = 1.0 - _smoothstep(0.42, 0.5, edge)
    return n, across, coverage


def _snake_tint(si):
    """The snake's skin tint per scale, 0.6 + 0.4 × the scale's second hash (the shader's
    ``tint``), on the base albedo."""
    return 0.6 + 0.4 * _snake_scale(si.p)[3]


def _cd_frame(si):
    p = si.p
    r = dr.sqrt(p.x * p.x + p.z * p.z)
    across = mi.Vector3f(p.x, 0.0, p.z) / dr.maximum(r, 1e-6)
    coverage = dr.select((r >= 0.38) & (r <= 0.98), 1.0, 0.0)
    return mi.Vector3f(0.0, 1.0, 0.0), across, mi.Float(coverage)


def _plane_frame(si):
    """grating-plane: lines along x, t = z (shaders/diffraction_scene.wgsl)."""
    return mi.Vector3f(0.0, 1.0, 0.0), mi.Vector3f(0.0, 0.0, 1.0), mi.Float(1.0)


def _props(plugin: str, values: Dict[str, Any]) -> "mi.Properties":
    props = mi.Properties(plugin)
    for k, v in values.items():
        props[k] = v
    return props


def cd_height_field() -> Tuple[np.ndarray, float]:
    """The CD's height field of ``tables/recipes/cd-tracks.toml``: ``synthetic = "cd"``
    (seed 1) at 256 × 256 samples 0.125 µm apart, pits 0.1 µm deep."""
    return _grating.cd_tracks(256, 256, 0.125, 0.1, 1), 0.125


def _grating_bsdf(surface: Dict[str, Any], roughness: float = 0.0) -> "_grating.NacreGrating":
    values: Dict[str, Any] = {"coherence_um": 32.0, "roughness": float(roughness)}
    if surface.get("fresnel_ior") is not None:
        values["fresnel_ior"] = float(surface["fresnel_ior"])
    if surface.get("base") is not None:
        values["base"] = mi.ScalarColor3f(*surface["base"])
    bsdf = _grating.NacreGrating(_props("nacre_grating", values))
    spec = surface["grating"]
    if spec == "cd":
        h, pitch = cd_height_field()
        bsdf.set_height_field(h, pitch)
    else:
        _, period, amplitude = spec.split(":")
        bsdf.set_sine(float(period), float(amplitude))
    return bsdf


#: ``nacre render --lighting``: which sources light a scene.
LIGHTINGS = ("both", "light", "environment")


def build(scene: Scene, width: int, height: int, max_depth: int = 8,
          roughness: float = 0.0, lighting: str = "both") -> Tuple["mi.Scene", List[Any]]:
    """The Mitsuba scene of ``scene`` at ``width × height`` (and the Python BSDFs it holds,
    which must outlive it); ``roughness``: the GGX α of a diffraction scene's grating
    (``nacre render --roughness``; film scenes take 0 only); ``lighting``: ``both`` (the
    directional light and the environment), ``light`` (the light alone, the environment
    black) or ``environment`` (the environment alone), as ``nacre render --lighting``."""
    if lighting not in LIGHTINGS:
        raise ValueError(f"lighting `{lighting}`: expected one of {', '.join(LIGHTINGS)}")
    if roughness and scene.surface["kind"] in ("sphere", "plane"):
        raise ValueError(f"roughness {roughness}: the diffraction scenes' gratings only, not {scene.name}")
    nacre.mitsuba.register(mi.variant() if mi.variant() and "spectral" in mi.variant() else None)
    s = scene.surface
    keep: List[Any] = []
    shapes: Dict[str, Any] = {}
    if s["kind"] in ("sphere", "plane"):
        values = {"film_ior": s["film_ior"], "substrate": s["substrate"], "alpha": s["alpha"],
                  "transmission": s["transmission"]}
        if s["base"] is not None:
            values["base"] = mi.ScalarColor3f(*s["base"])
        bsdf = _film.NacreFilm(_props("nacre_film", values))
        bsdf.set_thickness_function(_thickness_function(s))
        keep.append(bsdf)
        if s["kind"] == "sphere":
            shapes["object"] = {"type": "sphere", "center": [0.0, 1.0, 0.0], "radius": 1.0, "bsdf": bsdf}
        else:
            shapes["object"] = {
                "type": "rectangle",
                "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], -90).scale(1000.0),
                "bsdf": bsdf,
            }
    else:
        bsdf = _grating_bsdf(s, roughness)
        keep.append(bsdf)
        if s["kind"] == "cd-disc":
            bsdf.set_frame_function(_cd_frame)
            mesh = _annulus(0.12, 1.0)
        elif s["kind"] == "snake-skin":
            bsdf.set_frame_function(_snake_frame)
            bsdf.set_base_weight_function(_snake_tint)
            mesh = _cylinder_patch()
        else:
            bsdf.set_frame_function(_plane_frame)
            mesh = None
        if mesh is not None:
            shapes["object"] = dict(mesh, bsdf=bsdf)
        else:
            shapes["object"] = {
                "type": "rectangle",
                "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], -90),
                "bsdf": bsdf,
            }
    emitters: Dict[str, Any] = {}
    if lighting != "light":
        env = studio_environment(256, 128, scene.env_sun) * scene.env_intensity
        emitters["environment"] = {
            "type": "envmap",
            "bitmap": mi.Bitmap(mitsuba_environment(env)),
            "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], 180),
        }
    if scene.light_intensity > 0 and lighting != "environment":
        emitters["light"] = {
            "type": "directional",
            "direction": [-x for x in _unit(scene.light_direction)],
            "irradiance": {"type": "rgb", "value": [c * scene.light_intensity for c in scene.light_colour]},
        }
    description = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov": scene.fov_y_deg,
            "fov_axis": "y",
            "near_clip": 0.05,
            "far_clip": 2000.0,
            "to_world": mi.ScalarTransform4f().look_at(origin=list(scene.eye), target=list(scene.target),
                                                       up=[0.0, 1.0, 0.0]),
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": 1},
        },
        **emitters,
    }
    description.update(shapes)
    return mi.load_dict(description), keep


def scene_named(name: str) -> Scene:
    try:
        return SCENES[name]
    except KeyError:
        raise nacre.NacreError(f"scene `{name}`: expected one of {', '.join(SCENES)}") from None
