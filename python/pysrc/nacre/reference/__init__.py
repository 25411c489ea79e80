"""Path-traced references of ``nacre render``'s scenes in Mitsuba 3 (``nacre[mitsuba]``).

``python -m nacre.reference SCENE --width W --height H --spp N -o FILE.png`` renders SCENE
(``sphere``, ``bubble``, ``plane``, ``cd-disc``, ``dvd-disc``, ``snake-skin``,
``grating-plane``) framed as ``nacre render --scene SCENE --width W --height H`` frames it — the same camera, lights,
environment (the bundled studio) and tone mapping — with nacre's BSDFs
(:mod:`nacre.mitsuba`), spectrally. Besides the PNG it writes the linear radiance
(``FILE.exr``) and the reference's own noise: the samples are rendered as two independent
halves (different seeds), and the noise is the ΔE2000 between the halves' pictures
halved: see :func:`nacre.reference.compare.noise`.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from ._scenes import SCENES, Scene, srgb_to_linear, studio_environment, swirls, tone_map

__all__ = ["SCENES", "Reference", "Scene", "render", "tone_map", "srgb_to_linear", "studio_environment", "swirls"]


@dataclass
class Reference:
    """A rendered reference: the linear RGB radiance of the whole render and of its two
    independent halves (shape (height, width, 3), float64), the scene and the time."""

    scene: Scene
    linear: np.ndarray
    half_a: np.ndarray
    half_b: np.ndarray
    spp: int
    seconds: float

    def display(self, linear: Optional[np.ndarray] = None) -> np.ndarray:
        """sRGB-encoded values in [0, 1] as ``nacre render`` shows them."""
        return tone_map(self.linear if linear is None else linear, self.scene.tone_map)


def _bar(done: int, total: int, started: float, out=sys.stderr) -> None:
    width = 30
    filled = int(width * done / max(total, 1))
    elapsed = time.perf_counter() - started
    eta = elapsed / done * (total - done) if done else 0.0
    out.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} passes, {elapsed:6.1f} s, ~{eta:5.1f} s left")
    if done == total:
        out.write("\n")
    out.flush()


def render(
    scene: str,
    width: int = 320,
    height: int = 320,
    spp: int = 64,
    seed: int = 0,
    variant: str = "llvm_ad_spectral",
    passes: int = 8,
    progress: Optional[Callable[[int, int, float], None]] = None,
    roughness: float = 0.0,
    lighting: str = "both",
) -> Reference:
    """Renders ``scene`` at ``width × height`` with ``spp`` samples per pixel in ``passes``
    passes (an even number; the first and second halves of the passes are the two
    independent halves), seeds from ``seed``. ``progress(done, total, started)`` is called
    after every pass (default: none). ``roughness``: the GGX α of a diffraction scene's
    grating (``nacre render --roughness``), 0 to 1. ``lighting``: ``both``, ``light`` (the
    directional light alone) or ``environment`` (the environment alone), as ``nacre render
    --lighting``; a scene's picture under both is the sum of the other two (rendering is
    linear in the sources)."""
    import mitsuba as mi

    import nacre.mitsuba

    if spp < 2 or passes < 2 or passes % 2:
        raise ValueError("render: spp ≥ 2 and an even number of passes ≥ 2")
    passes = min(passes, spp - spp % 2)
    nacre.mitsuba.register(variant)
    from ._build import build, scene_named

    definition = scene_named(scene)
    mi_scene, keep = build(definition, width, height, roughness=roughness, lighting=lighting)
    per_pass = [spp // passes + (1 if i < spp % passes else 0) for i in range(passes)]
    started = time.perf_counter()
    halves = [np.zeros((height, width, 3)), np.zeros((height, width, 3))]
    counts = [0, 0]
    for i, n in enumerate(per_pass):
        image = np.array(mi.render(mi_scene, spp=n, seed=seed * 7919 + i), dtype=np.float64)[..., :3]
        half = 0 if i < passes // 2 else 1
        halves[half] += image * n
        counts[half] += n
        if progress is not None:
            progress(i + 1, passes, started)
    seconds = time.perf_counter() - started
    del keep
    a, b = halves[0] / counts[0], halves[1] / counts[1]
    linear = (halves[0] + halves[1]) / (counts[0] + counts[1])
    return Reference(definition, linear, a, b, spp, seconds)
