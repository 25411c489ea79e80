// The film thickness range of a three.js physical material, on every release the package
// supports: `iridescenceThicknessRange` ([min, max] nm) before r187, `iridescenceThicknessMinimum`
// and `iridescenceThicknessMaximum` since (r187 keeps the range as a deprecated accessor that
// warns). Shared by NacreFilmMaterial (material.js) and NacreFilmNodeMaterial (webgpu.js).

/** [min, max] nm: what the thickness map's green channel spans (the maximum without a map). */
export function thicknessRange(material) {
  return 'iridescenceThicknessMinimum' in material
    ? [material.iridescenceThicknessMinimum, material.iridescenceThicknessMaximum]
    : [...material.iridescenceThicknessRange];
}

/** Sets the range to [min, max] nm through whichever properties the release has. */
export function setThicknessRange(material, [min, max]) {
  if ('iridescenceThicknessMinimum' in material) {
    material.iridescenceThicknessMinimum = min;
    material.iridescenceThicknessMaximum = max;
  } else {
    material.iridescenceThicknessRange = [min, max];
  }
}
