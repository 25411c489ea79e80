"""The README's Python example: spectra of a soap film at three angles, and a film's colour
over thickness. Writes docs/images/python-soap-film.png:

    python python/examples/soap_film.py [OUT.png]
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nacre  # noqa: E402

soap = nacre.Stack("air", [("water", 400.0)], "air")  # a 400 nm water film in air
wavelengths = np.arange(380.0, 781.0, 1.0)
s = nacre.spectrum(soap, [0.0, 45.0, 70.0], wavelengths)  # R has shape (3, 401)

thickness = np.linspace(0.0, 1500.0, 751)
c = nacre.color(soap, 0.0, thickness_nm=thickness)  # linear sRGB, D65, CIE 1931
rgb = np.clip(4.0 * c.rgb, 0.0, 1.0)  # two stops brighter: a film reflects ~10 %
srgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(6.4, 4.8), height_ratios=[3, 1])
for angle, r in zip([0, 45, 70], s.R):
    ax1.plot(wavelengths, r, label=f"{angle}°")
ax1.set(xlabel="wavelength (nm)", ylabel="reflectance R", title="400 nm soap film in air")
ax1.legend(title="incidence")
ax2.imshow(srgb[None, :, :] * np.ones((40, 1, 1)), aspect="auto",
           extent=(thickness[0], thickness[-1], 0, 1))
ax2.set(xlabel="film thickness (nm): its colour at normal incidence (+2 EV)", yticks=[])
fig.tight_layout()
fig.savefig(sys.argv[1] if len(sys.argv) > 1 else "docs/images/python-soap-film.png", dpi=80)
