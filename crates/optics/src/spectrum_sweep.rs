//! A stack's (angle, wavelength) sweep prepared once and evaluated many times: the path of
//! [`Stack::sweep`], of `nacre spectrum` and `nacre color`'s spectral integration, and of a
//! fitting loop that sweeps the same stack again and again with new film thicknesses or
//! film indices.
//!
//! ```
//! use nacre_optics::{Layer, Material, Power, SpectrumSweep, Stack};
//! let air = Material::parse_index("1.0")?;
//! let film = Material::parse_index("1.38")?;
//! let glass = Material::parse_index("1.52")?;
//! let stack = Stack::new(air, vec![Layer { material: film, thickness_nm: 100.0 }], glass)?;
//! let wavelengths: Vec<f64> = (0..401).map(|i| 380.0 + i as f64).collect();
//! // Once: the angles, the index table and the kernel's arrays.
//! let mut sweep = SpectrumSweep::new(&stack, &[0.0, 45.0], &wavelengths)?;
//! let mut powers = vec![Power::default(); sweep.len()];
//! for d in [90.0, 100.0, 110.0] {
//!     // Per evaluation: the new thicknesses, then the kernel straight into `powers`.
//!     sweep.set_thicknesses_nm(&[d])?;
//!     sweep.powers_into(&mut powers)?;
//! }
//! // The same bits as the stack's own sweep at the last thickness.
//! let last = Stack::new(
//!     Material::parse_index("1.0")?,
//!     vec![Layer { material: Material::parse_index("1.38")?, thickness_nm: 110.0 }],
//!     Material::parse_index("1.52")?,
//! )?;
//! assert_eq!(powers, last.sweep(&[0.0, 45.0], &wavelengths)?);
//! # Ok::<(), nacre_optics::Error>(())
//! ```
//!
//! # What is done once, and what per evaluation
//!
//! [`SpectrumSweep::new`] validates the angles (sin θ₀ each) and resolves every medium's
//! index over the wavelengths once: a constant material once in all (checked over the
//! wavelengths by [`Material::constant_over`], no per-wavelength lookup), a dispersive one
//! by one walk of its table ([`Material::indices_at`]). It lays the indices out for the
//! vectorised multilayer kernel of the `multilayer` module (structure of arrays; a constant
//! medium as one block of [`BLOCK`](crate::multilayer) copies that every block of a row
//! reads, so its set-up costs nothing per wavelength).
//!
//! Per evaluation, [`SpectrumSweep::powers_into`] runs that kernel, one angle's row per
//! rayon task, straight into the caller's buffer: no allocation, no index lookup. New
//! thicknesses ([`SpectrumSweep::set_thicknesses_nm`]) re-check the kernel's phase range and
//! which films repeat (O(films²), plus O(wavelengths) per dispersive film) and keep
//! everything else (k₀ and the index arrays are not rebuilt); a new constant
//! film index ([`SpectrumSweep::set_film_index`]) rebuilds the kernel's arrays of the
//! constant media (O(films × 64)) and re-walks the dispersive ones.
//!
//! Results are bit-identical to [`Stack::sweep`] of the stack with the same thicknesses and
//! indices (which is this type, made and run once), whatever the thread count: every
//! element is a pure function of its (angle, wavelength). Stacks or values outside the
//! kernel's ranges (|ñ| beyond [10⁻⁶, 10⁶], film phases beyond 5×10⁵ rad) take the scalar
//! recurrence of [`crate::Prepared`], and stacks with incoherent slabs the intensity
//! recurrence of [`crate::incoherent`], as [`Stack::sweep`] always has.

use crate::error::{Error, Result};
use crate::material::{Material, WavelengthSpan};
use crate::multilayer::{Column, Media, stack_powers};
use crate::power::{Power, PowerSlot};
use crate::stack::{Stack, scalar_powers, sin_of_angle, sweep_recurrence};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// One medium's indices over the sweep's wavelengths, owned.
#[derive(Clone, Debug)]
enum Indices {
    /// The same index at every wavelength.
    Constant(C64),
    /// One index per wavelength.
    Varying(Vec<C64>),
}

impl Indices {
    fn column(&self) -> Column<'_> {
        match self {
            Indices::Constant(n) => Column::Constant(*n),
            Indices::Varying(c) => Column::Varying(c),
        }
    }

    fn at(&self, w: usize) -> C64 {
        self.column().at(w)
    }

    /// One index per wavelength.
    fn expand(&self, wavelengths: usize) -> Vec<C64> {
        match self {
            Indices::Constant(n) => vec![*n; wavelengths],
            Indices::Varying(c) => c.clone(),
        }
    }
}

/// How the sweep evaluates.
enum Path {
    /// The vectorised multilayer kernel over the prepared arrays.
    Kernel(Box<Media>),
    /// The scalar recurrence of [`crate::Prepared`] (indices per wavelength: ambient, films,
    /// substrate): indices or phases outside the kernel's ranges.
    Scalar(Vec<Vec<C64>>),
    /// Incoherent slabs: [`crate::incoherent::sweep`] over full columns.
    Incoherent(Vec<Vec<C64>>),
}

/// A stack's (angle, wavelength) sweep, prepared for repeated evaluation (module docs).
/// Powers are angle-major: element `a * wavelengths + w`, as [`Stack::sweep`].
pub struct SpectrumSweep {
    sines: Vec<f64>,
    wavelengths_nm: Vec<f64>,
    /// Per medium (ambient, films top first, substrate): its indices.
    indices: Vec<Indices>,
    thickness_nm: Vec<f64>,
    /// Per film: incoherent (empty when every film is coherent).
    incoherent: Vec<bool>,
    /// The films' materials' names, for errors.
    names: Vec<String>,
    path: Path,
}

impl SpectrumSweep {
    /// Prepares `stack`'s sweep over `angles_deg` (incidence in the ambient) × `wavelengths_nm`
    /// (vacuum): the errors of [`Stack::sweep`] (an angle not strictly between −90° and 90°,
    /// a wavelength that is not positive, outside a material's data or where the ambient
    /// absorbs), the same one first.
    pub fn new(stack: &Stack, angles_deg: &[f64], wavelengths_nm: &[f64]) -> Result<Self> {
        let media = std::iter::once(stack.ambient())
            .chain(stack.layers().iter().map(|l| &l.material))
            .chain([stack.substrate()]);
        // One pass over the wavelengths for every constant medium.
        let span = WavelengthSpan::of(wavelengths_nm);
        let resolved: Result<Vec<Indices>> =
            media.map(|m| resolve(m, &span, wavelengths_nm)).collect();
        let lossless_ambient = |ambient: &Indices| match ambient {
            Indices::Constant(n) => n.im == 0.0,
            Indices::Varying(c) => c.iter().all(|n| n.im == 0.0),
        };
        let indices = match resolved {
            Ok(indices) if wavelengths_nm.is_empty() || lossless_ambient(&indices[0]) => indices,
            // An error: the one the per-wavelength order meets first.
            _ => {
                let (_, per_wavelength) = stack.resolve(angles_deg, wavelengths_nm)?;
                (0..stack.layers().len() + 2)
                    .map(|j| Indices::Varying(per_wavelength.iter().map(|idx| idx[j]).collect()))
                    .collect()
            }
        };
        let sines = angles_deg
            .iter()
            .map(|&a| sin_of_angle(a))
            .collect::<Result<Vec<_>>>()?;
        let mut sweep = SpectrumSweep {
            sines,
            wavelengths_nm: wavelengths_nm.to_vec(),
            indices,
            thickness_nm: stack.thicknesses_nm(),
            incoherent: stack.incoherent_flags(),
            names: stack
                .layers()
                .iter()
                .map(|l| l.material.name().to_string())
                .collect(),
            path: Path::Scalar(Vec::new()),
        };
        if !sweep.incoherent.iter().any(|&i| i) {
            sweep.incoherent.clear();
        }
        sweep.prepare();
        Ok(sweep)
    }

    /// Number of powers a sweep gives: angles × wavelengths.
    pub fn len(&self) -> usize {
        self.sines.len() * self.wavelengths_nm.len()
    }

    /// Whether a sweep gives no power (no angle or no wavelength).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The wavelengths, nm.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// The film thicknesses, nm, top first.
    pub fn thicknesses_nm(&self) -> &[f64] {
        &self.thickness_nm
    }

    /// Sets every film's thickness (nm, top first; one per film, each finite and ≥ 0, else
    /// [`Error::InvalidThickness`] naming the first bad one, or [`Error::ThicknessCount`] for a
    /// count that is not the number of films). Keeps the index table.
    pub fn set_thicknesses_nm(&mut self, thickness_nm: &[f64]) -> Result<()> {
        if thickness_nm.len() != self.thickness_nm.len() {
            return Err(Error::ThicknessCount {
                given: thickness_nm.len(),
                count: self.thickness_nm.len(),
            });
        }
        for (i, &d) in thickness_nm.iter().enumerate() {
            if !(d >= 0.0 && d.is_finite()) {
                return Err(Error::InvalidThickness {
                    layer: i + 1,
                    material: self.names[i].clone(),
                    thickness_nm: d,
                });
            }
        }
        if thickness_nm
            .iter()
            .zip(&self.thickness_nm)
            .all(|(a, b)| a.to_bits() == b.to_bits())
        {
            return Ok(());
        }
        // The kernel's index arrays and k₀ stay: only the phase check and which films
        // repeat are redone (`Media::set_thicknesses`, the same bits as a fresh
        // `prepare`). Otherwise (another path, or a phase leaving the kernel's range) all
        // of it.
        if let Path::Kernel(media) = &mut self.path {
            let columns: Vec<Column> = self.indices.iter().map(Indices::column).collect();
            if media.set_thicknesses(&columns, thickness_nm) {
                self.thickness_nm.copy_from_slice(thickness_nm);
                return Ok(());
            }
        }
        self.thickness_nm.copy_from_slice(thickness_nm);
        self.prepare();
        Ok(())
    }

    /// Sets film `layer`'s (1-based, top film = 1) index to the constant `index` (n > 0,
    /// κ ≥ 0, both finite, else [`Error::InvalidIndex`]); the other media keep theirs.
    pub fn set_film_index(&mut self, layer: usize, index: C64) -> Result<()> {
        if layer == 0 || layer > self.thickness_nm.len() {
            return Err(Error::NoSuchLayer {
                layer,
                count: self.thickness_nm.len(),
            });
        }
        Material::constant(self.names[layer - 1].clone(), index)?;
        self.indices[layer] = Indices::Constant(index);
        self.prepare();
        Ok(())
    }

    /// Lays the indices and thicknesses out for the path that evaluates them.
    fn prepare(&mut self) {
        let wavelengths = self.wavelengths_nm.len();
        if !self.incoherent.is_empty() {
            self.path =
                Path::Incoherent(self.indices.iter().map(|c| c.expand(wavelengths)).collect());
            return;
        }
        let columns: Vec<Column> = self.indices.iter().map(Indices::column).collect();
        self.path =
            match Media::from_compact(&columns, None, &self.wavelengths_nm, &self.thickness_nm) {
                Some(media) => Path::Kernel(Box::new(media)),
                None => Path::Scalar(
                    (0..wavelengths)
                        .map(|w| self.indices.iter().map(|c| c.at(w)).collect())
                        .collect(),
                ),
            };
    }

    /// The powers, angle-major (element `a * wavelengths + w`).
    pub fn powers(&self) -> Result<Vec<Power>> {
        let total = self.len();
        let mut out: Vec<Power> = Vec::with_capacity(total);
        if self.fill_kernel(&mut out.spare_capacity_mut()[..total]) {
            // SAFETY: `fill_kernel` wrote every one of the first `total` slots (its rows
            // partition them and the kernel writes every slot of a row).
            unsafe { out.set_len(total) };
            return Ok(out);
        }
        self.other_paths()
    }

    /// [`SpectrumSweep::powers`] written into `out` (length [`SpectrumSweep::len`]): no
    /// allocation on the kernel's path.
    pub fn powers_into(&self, out: &mut [Power]) -> Result<()> {
        assert_eq!(out.len(), self.len(), "one slot per (angle, wavelength)");
        if self.fill_kernel(out) {
            return Ok(());
        }
        out.copy_from_slice(&self.other_paths()?);
        Ok(())
    }

    /// Fills `out` by the kernel, one angle's row per rayon task; `false` (nothing written)
    /// when the sweep takes another path.
    fn fill_kernel<T: PowerSlot + Send>(&self, out: &mut [T]) -> bool {
        let Path::Kernel(media) = &self.path else {
            return false;
        };
        let per_angle = self.wavelengths_nm.len();
        if per_angle > 0 {
            out.par_chunks_mut(per_angle)
                .zip(&self.sines)
                .for_each(|(row, &sin_theta)| stack_powers(media, sin_theta, row, true));
        }
        true
    }

    /// The kernel's media and each angle's sin θ₀, when the sweep takes the kernel's path
    /// (the vectorised Jacobian of [`crate::jacobian`] runs on the same arrays).
    pub(crate) fn kernel(&self) -> Option<(&Media, &[f64])> {
        match &self.path {
            Path::Kernel(media) => Some((media, &self.sines)),
            _ => None,
        }
    }

    /// The powers by the scalar or the incoherent recurrence.
    fn other_paths(&self) -> Result<Vec<Power>> {
        match &self.path {
            Path::Kernel(_) => unreachable!("the kernel's path is filled in place"),
            Path::Scalar(indices) => Ok(sweep_recurrence(
                &self.sines,
                indices,
                &self.wavelengths_nm,
                &self.thickness_nm,
            )),
            Path::Incoherent(columns) => crate::incoherent::sweep(
                &crate::incoherent::Groups::new(&self.incoherent),
                &self.sines,
                columns,
                &self.wavelengths_nm,
                &self.thickness_nm,
                &self.names,
                scalar_powers,
            ),
        }
    }

    /// The first (wavelength, film) pair, in wavelength-major order, whose phase bound
    /// 2π (|ñ_j| + |ñ₀|) d_j / λ is not finite (a film too thick for f64 at that
    /// wavelength, where the sweep would give NaN): `(film, wavelength_nm, thickness_nm)`,
    /// film 1-based. `swept` replaces one film's thickness `(film, d)` (the thickest of a
    /// thickness sweep). |·| by [`crate::elementary::norm`]; evaluated left to right as
    /// written.
    pub fn overflowing_phase(&self, swept: Option<(usize, f64)>) -> Option<(usize, f64, f64)> {
        let thickness = |j: usize| match swept {
            Some((k, d)) if k == j + 1 => d,
            _ => self.thickness_nm[j],
        };
        let norm = crate::elementary::norm;
        let phase = |j: usize, w: usize| {
            let wl = self.wavelengths_nm[w];
            2.0 * std::f64::consts::PI
                * (norm(self.indices[j + 1].at(w)) + norm(self.indices[0].at(w)))
                * thickness(j)
                / wl
        };
        // Constant media: 2π(|ñ_j| + |ñ₀|) d is the same at every wavelength and its
        // quotient by λ > 0 largest at the shortest one (a correctly rounded division is
        // monotonic), so one check there stands for every wavelength.
        let shortest = (0..self.wavelengths_nm.len())
            .min_by(|&a, &b| self.wavelengths_nm[a].total_cmp(&self.wavelengths_nm[b]));
        let all_constant = self
            .indices
            .iter()
            .all(|c| matches!(c, Indices::Constant(_)));
        if all_constant
            && let Some(w) = shortest
            && self.wavelengths_nm[w] > 0.0
            && (0..self.thickness_nm.len()).all(|j| phase(j, w).is_finite())
        {
            return None;
        }
        for w in 0..self.wavelengths_nm.len() {
            for j in 0..self.thickness_nm.len() {
                if !phase(j, w).is_finite() {
                    return Some((j + 1, self.wavelengths_nm[w], thickness(j)));
                }
            }
        }
        None
    }
}

/// A medium's indices over `wavelengths_nm`: constant when it is constant and valid there.
fn resolve(material: &Material, span: &WavelengthSpan, wavelengths_nm: &[f64]) -> Result<Indices> {
    Ok(match material.constant_over_span(span) {
        Some(n) => Indices::Constant(n),
        None => Indices::Varying(material.indices_at(wavelengths_nm)?),
    })
}

/// The one-shot sweep, defined here so that `stack.rs` needs nothing of this module (no
/// import circle): [`Stack`]'s powers through a [`SpectrumSweep`].
impl Stack {
    /// Powers over every (angle, wavelength) pair, angle-major: element
    /// `a * wavelengths_nm.len() + w`.
    ///
    /// A [`SpectrumSweep`] made and run once. Indices are resolved once (a constant
    /// material once in all, a dispersive one per wavelength); each angle's row then runs
    /// through the vectorised kernel of the `multilayer` module (wavelengths as SIMD lanes, IEEE basic
    /// operations only: the same bits on every CPU, vector width and thread count), or,
    /// for indices or phases outside the kernel's range (|ñ| beyond [10⁻⁶, 10⁶], film phases
    /// beyond 10⁶ rad), through the scalar recurrence of [`crate::Prepared`].
    pub fn sweep(&self, angles_deg: &[f64], wavelengths_nm: &[f64]) -> Result<Vec<Power>> {
        SpectrumSweep::new(self, angles_deg, wavelengths_nm)?.powers()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Layer;

    fn constant(n: f64, k: f64) -> Material {
        Material::constant(format!("{n}+{k}i"), C64::new(n, k)).unwrap()
    }

    fn dispersive() -> Material {
        let csv = "wavelength_nm,n,k\n300,2.9,0.3\n500,2.5,0.01\n900,2.3,0\n";
        Material::from_nk_csv("tio2-like", "test.csv", csv).unwrap()
    }

    /// Stacks of constant media (repeats, absorbers, total internal reflection, a metal),
    /// and one with a dispersive film.
    fn stacks() -> Vec<Stack> {
        let s = |amb: Material, films: Vec<(Material, f64)>, sub: Material| {
            let layers = films
                .into_iter()
                .map(|(material, thickness_nm)| Layer {
                    material,
                    thickness_nm,
                })
                .collect();
            Stack::new(amb, layers, sub).unwrap()
        };
        let (h, l) = (constant(2.35, 0.0), constant(1.38, 0.0));
        vec![
            s(
                constant(1.0, 0.0),
                vec![(constant(1.33, 0.0), 400.0)],
                constant(1.5, 0.0),
            ),
            s(
                constant(1.0, 0.0),
                (0..8)
                    .map(|i| {
                        if i % 2 == 0 {
                            (h.clone(), 58.5)
                        } else {
                            (l.clone(), 99.6)
                        }
                    })
                    .collect(),
                constant(1.52, 0.0),
            ),
            s(
                constant(1.0, 0.0),
                vec![
                    (constant(2.1, 0.0), 71.0),
                    (constant(1.46, 0.0), 120.0),
                    (constant(1.9, 0.02), 33.0),
                    (constant(1.6, 0.0), 250.0),
                    (constant(2.4, 0.0), 0.0),
                ],
                constant(0.27, 2.9),
            ),
            s(
                constant(1.7, 0.0),
                vec![(constant(1.38, 0.0), 80.0)],
                constant(1.0, 0.0),
            ),
            s(
                constant(1.0, 0.0),
                vec![(dispersive(), 150.0), (l.clone(), 90.0)],
                constant(1.52, 0.0),
            ),
            s(constant(1.0, 0.0), vec![], constant(1.5, 0.0)),
        ]
    }

    /// The powers of the kernel over full columns (one index per wavelength for every
    /// medium, as before constant media were kept as one block).
    fn full_columns(stack: &Stack, angles: &[f64], wl: &[f64]) -> Vec<Power> {
        let (sines, indices) = stack.resolve(angles, wl).unwrap();
        let columns: Vec<Vec<C64>> = (0..stack.layers().len() + 2)
            .map(|j| indices.iter().map(|idx| idx[j]).collect())
            .collect();
        let media = Media::from_columns(&columns, wl, &stack.thicknesses_nm()).unwrap();
        let mut out = vec![Power::default(); sines.len() * wl.len()];
        for (row, &sin_theta) in out.chunks_mut(wl.len()).zip(&sines) {
            stack_powers(&media, sin_theta, row, true);
        }
        out
    }

    fn bits(p: &[Power]) -> Vec<[u64; 4]> {
        p.iter()
            .map(|p| [p.R_s, p.R_p, p.T_s, p.T_p].map(f64::to_bits))
            .collect()
    }

    #[test]
    fn constant_media_give_the_bits_of_full_columns() {
        let angles = [0.0, 17.0, 45.0, 70.0, 89.0];
        // Odd counts: a row's last block and last vector partial.
        for count in [1, 7, 64, 65, 203] {
            let wl: Vec<f64> = (0..count)
                .map(|i| 380.0 + 400.0 * i as f64 / count as f64)
                .collect();
            for stack in stacks() {
                let sweep = SpectrumSweep::new(&stack, &angles, &wl).unwrap();
                assert!(matches!(sweep.path, Path::Kernel(_)));
                assert_eq!(
                    bits(&sweep.powers().unwrap()),
                    bits(&full_columns(&stack, &angles, &wl)),
                    "{count} wavelengths, {:?}",
                    stack.thicknesses_nm()
                );
            }
        }
    }

    #[test]
    fn new_thicknesses_and_indices_give_the_bits_of_a_new_stack() {
        let angles = [0.0, 60.0];
        let wl: Vec<f64> = (0..301).map(|i| 380.0 + 1.3 * i as f64).collect();
        for stack in stacks() {
            let mut sweep = SpectrumSweep::new(&stack, &angles, &wl).unwrap();
            let mut out = vec![Power::default(); sweep.len()];
            let films = stack.layers().len();
            // Thicknesses that make films repeat, and part with them; one beyond the
            // kernel's phase range (the scalar path) and back.
            let steps = [40.0, 40.0 + 7.0, 1e3, 1e8, 0.0, 35.0];
            for (step, &d_step) in steps.iter().enumerate() {
                let d: Vec<f64> = (0..films)
                    .map(|j| match step {
                        1 => 40.0 + 7.0 * j as f64,
                        _ => d_step,
                    })
                    .collect();
                let n = C64::new(1.4 + 0.1 * step as f64, 0.01 * step as f64);
                sweep.set_thicknesses_nm(&d).unwrap();
                let mut layers = stack.layers().to_vec();
                for (layer, &d) in layers.iter_mut().zip(&d) {
                    layer.thickness_nm = d;
                }
                if films > 0 {
                    sweep.set_film_index(1, n).unwrap();
                    layers[0].material = Material::constant(layers[0].material.name(), n).unwrap();
                }
                let fresh =
                    Stack::new(stack.ambient().clone(), layers, stack.substrate().clone()).unwrap();
                sweep.powers_into(&mut out).unwrap();
                assert_eq!(bits(&out), bits(&fresh.sweep(&angles, &wl).unwrap()));
                let kernel = matches!(sweep.path, Path::Kernel(_));
                assert_eq!(kernel, films == 0 || step != 3, "step {step}");
                if kernel {
                    assert_eq!(bits(&out), bits(&full_columns(&fresh, &angles, &wl)));
                }
            }
        }
    }

    #[test]
    fn the_span_of_the_wavelengths_decides_as_a_walk_over_them() {
        let m = Material::from_nk_csv("c", "c.csv", "wavelength_nm,n,k\n300,1.5,0\n900,1.5,0\n")
            .unwrap();
        let k = constant(1.5, 0.0);
        let grids: [&[f64]; 8] = [
            &[],
            &[500.0],
            &[300.0, 900.0, 400.0, 450.0, 500.0],
            &[299.0, 500.0, 600.0, 700.0, 800.0, 850.0],
            &[500.0, 600.0, 700.0, 800.0, 901.0],
            &[500.0, f64::NAN, 600.0],
            &[500.0, 600.0, 700.0, 800.0, -1.0, 400.0, f64::INFINITY],
            &[0.0],
        ];
        for wl in grids {
            for material in [&m, &k] {
                let walk =
                    (!wl.is_empty() && material.indices_at(wl).is_ok() && material.is_constant())
                        .then(|| material.index_at(wl[0]).unwrap());
                assert_eq!(
                    material.constant_over_span(&WavelengthSpan::of(wl)),
                    walk,
                    "{wl:?}"
                );
            }
        }
    }

    #[test]
    fn bad_updates_are_refused() {
        let stack = &stacks()[0];
        let mut sweep = SpectrumSweep::new(stack, &[0.0], &[500.0]).unwrap();
        assert!(matches!(
            sweep.set_thicknesses_nm(&[1.0, 2.0]),
            Err(Error::ThicknessCount { given: 2, count: 1 })
        ));
        assert!(matches!(
            sweep.set_thicknesses_nm(&[f64::NAN]),
            Err(Error::InvalidThickness { layer: 1, .. })
        ));
        assert!(matches!(
            sweep.set_film_index(2, C64::new(1.5, 0.0)),
            Err(Error::NoSuchLayer { layer: 2, count: 1 })
        ));
        assert!(sweep.set_film_index(1, C64::new(-1.5, 0.0)).is_err());
    }

    #[test]
    fn out_of_range_stacks_take_the_scalar_recurrence() {
        // A film phase beyond the kernel's range.
        let stack = Stack::new(
            constant(1.0, 0.0),
            vec![Layer {
                material: constant(1.5, 0.0),
                thickness_nm: 1e8,
            }],
            constant(1.5, 0.0),
        )
        .unwrap();
        let wl = [400.0, 500.0, 600.0];
        let sweep = SpectrumSweep::new(&stack, &[0.0, 30.0], &wl).unwrap();
        assert!(matches!(sweep.path, Path::Scalar(_)));
        let (sines, indices) = stack.resolve(&[0.0, 30.0], &wl).unwrap();
        let reference = sweep_recurrence(&sines, &indices, &wl, &stack.thicknesses_nm());
        assert_eq!(bits(&sweep.powers().unwrap()), bits(&reference));
    }

    #[test]
    fn the_phase_check_of_constant_media_is_the_full_one() {
        let stack = |d: f64| {
            Stack::new(
                constant(1.0, 0.0),
                vec![
                    Layer {
                        material: constant(1.5, 0.0),
                        thickness_nm: 100.0,
                    },
                    Layer {
                        material: constant(2.0, 0.0),
                        thickness_nm: d,
                    },
                ],
                constant(1.5, 0.0),
            )
            .unwrap()
        };
        // Every (wavelength, film) in order, by the stack's per-wavelength indices.
        let reference = |stack: &Stack, wl: &[f64], swept: Option<(usize, f64)>| {
            for &w in wl {
                let idx = stack.indices_at(w).unwrap();
                for j in 0..stack.layers().len() {
                    let d = match swept {
                        Some((k, d)) if k == j + 1 => d,
                        _ => stack.layers()[j].thickness_nm,
                    };
                    let norm = crate::elementary::norm;
                    let phase =
                        2.0 * std::f64::consts::PI * (norm(idx[j + 1]) + norm(idx[0])) * d / w;
                    if !phase.is_finite() {
                        return Some((j + 1, w, d));
                    }
                }
            }
            None
        };
        let grids: [&[f64]; 4] = [
            &[600.0, 1e-300, 500.0, 1e-310],
            &[600.0, 1e-305, 500.0],
            &[1e-306, 600.0],
            &[380.0, 780.0],
        ];
        let mut found = 0;
        for wl in grids {
            for d in [0.0, 1e-20, 1.0, 100.0, 1e300] {
                let s = stack(d);
                let sweep = SpectrumSweep::new(&s, &[0.0], wl).unwrap();
                for swept in [None, Some((1, 1e306)), Some((2, 0.0))] {
                    let expected = reference(&s, wl, swept);
                    found += usize::from(expected.is_some());
                    assert_eq!(
                        sweep.overflowing_phase(swept),
                        expected,
                        "{wl:?} {d} {swept:?}"
                    );
                }
            }
        }
        assert!(found > 10, "the grids overflow somewhere");
    }
}
