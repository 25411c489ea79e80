//! Spectra: R, T, A (and their s/p parts) against wavelength, one colour per angle ([`SpectrumPlot`]), from a stack or a `nacre spectrum` CSV.

use super::*;

/// One column of a `nacre spectrum` table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumQuantity {
    /// Reflectance, s polarisation (dashed).
    Rs,
    /// Reflectance, p polarisation (dotted).
    Rp,
    /// Unpolarised reflectance (solid).
    R,
    /// Transmittance into the substrate, s polarisation (dashed).
    Ts,
    /// Transmittance, p polarisation (dotted).
    Tp,
    /// Unpolarised transmittance (solid).
    T,
    /// Absorptance A = 1 − R − T (solid).
    A,
}

impl SpectrumQuantity {
    /// In the column order of [`crate::commands::spectrum::HEADER`] (after the angle and wavelength).
    pub const ALL: [SpectrumQuantity; 7] = [
        SpectrumQuantity::Rs,
        SpectrumQuantity::Rp,
        SpectrumQuantity::R,
        SpectrumQuantity::Ts,
        SpectrumQuantity::Tp,
        SpectrumQuantity::T,
        SpectrumQuantity::A,
    ];

    /// The column name: `R_s`, `R_p`, `R`, `T_s`, `T_p`, `T`, `A`.
    pub fn name(self) -> &'static str {
        ["R_s", "R_p", "R", "T_s", "T_p", "T", "A"][self.column()]
    }

    /// Index into [`SpectrumCurve::values`].
    pub fn column(self) -> usize {
        Self::ALL
            .iter()
            .position(|q| *q == self)
            .expect("listed in ALL")
    }

    /// 0: reflectance, 1: transmittance, 2: absorptance (one panel each).
    fn family(self) -> usize {
        match self {
            SpectrumQuantity::Rs | SpectrumQuantity::Rp | SpectrumQuantity::R => 0,
            SpectrumQuantity::Ts | SpectrumQuantity::Tp | SpectrumQuantity::T => 1,
            SpectrumQuantity::A => 2,
        }
    }

    fn dash(self) -> Dash {
        match self {
            SpectrumQuantity::Rs | SpectrumQuantity::Ts => Dashed,
            SpectrumQuantity::Rp | SpectrumQuantity::Tp => Dotted,
            _ => Solid,
        }
    }

    /// Parses `R,T,R_s,…` (any case, underscore optional: `rs` = `R_s`), without repeats.
    pub fn parse_list(text: &str) -> Result<Vec<Self>> {
        let mut out = Vec::new();
        for item in text.split(',') {
            let key = item.trim().to_ascii_lowercase().replace('_', "");
            let q = Self::ALL
                .iter()
                .find(|q| q.name().to_ascii_lowercase().replace('_', "") == key)
                .ok_or_else(|| Error::value(Param::Quantities, text, format!(
                        "unknown quantity `{}`: expected any of R, T, A, R_s, R_p, T_s, T_p, separated by commas",
                        item.trim()
                    )))?;
            if !out.contains(q) {
                out.push(*q);
            }
        }
        Ok(out)
    }
}

/// The spectra of one angle.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumCurve {
    /// Incidence angle in the ambient, degrees.
    pub angle_deg: f64,
    /// Vacuum wavelengths, nm, increasing.
    pub wavelengths_nm: Vec<f64>,
    /// Per wavelength: R_s, R_p, R, T_s, T_p, T, A (the order of [`SpectrumQuantity::ALL`]).
    pub values: Vec<[f64; 7]>,
}

/// Computes the curves of `stack` at `angles_deg` over `wavelengths_nm` (exact, as
/// `nacre spectrum`).
pub fn spectrum_curves(
    stack: &Stack,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
) -> Result<Vec<SpectrumCurve>> {
    let powers = crate::commands::spectrum::compute(stack, angles_deg, wavelengths_nm)?;
    Ok(angles_deg
        .iter()
        .zip(powers.chunks(wavelengths_nm.len().max(1)))
        .map(|(&angle_deg, p)| SpectrumCurve {
            angle_deg,
            wavelengths_nm: wavelengths_nm.to_vec(),
            values: p
                .iter()
                .map(|p| [p.R_s, p.R_p, p.R(), p.T_s, p.T_p, p.T(), p.A()])
                .collect(),
        })
        .collect())
}

/// Reads a `nacre spectrum` CSV (header [`crate::commands::spectrum::HEADER`], then 9 numbers a
/// row; blank lines and `#` comments skipped) into one curve per angle, in the order the
/// angles first appear, each sorted by wavelength. Errors name `path` and the line.
pub fn read_spectrum_csv(path: &Path, text: &str) -> Result<Vec<SpectrumCurve>> {
    let perr = |line: usize, message: String| Error::recipe(path.to_path_buf(), line, message);
    let names: Vec<&str> = crate::commands::spectrum::HEADER.split(',').collect();
    let mut header = false;
    let mut curves: Vec<SpectrumCurve> = Vec::new();
    for row in crate::csv_text::rows(path, text) {
        let row = row?;
        let line = row.line;
        let fields = &row.fields;
        if !header {
            if fields != &names {
                return Err(perr(
                    line,
                    format!(
                        "expected the `nacre spectrum` header `{}`, found `{}`",
                        crate::commands::spectrum::HEADER,
                        crate::csv_text::line_text(text, line)
                    ),
                ));
            }
            header = true;
            continue;
        }
        if fields.len() != names.len() {
            return Err(perr(
                line,
                format!(
                    "expected {} comma-separated numbers, found {} field(s)",
                    names.len(),
                    fields.len()
                ),
            ));
        }
        let mut v = [0.0; 9];
        for (k, (f, name)) in fields.iter().zip(&names).enumerate() {
            v[k] = f
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| perr(line, format!("{name} `{f}` is not a finite number")))?;
        }
        if !(v[0].abs() < 90.0) {
            return Err(perr(
                line,
                format!("angle_deg {} must lie strictly between -90 and 90", v[0]),
            ));
        }
        if !(v[1] > 0.0) {
            return Err(perr(
                line,
                format!("wavelength_nm {} must be positive", v[1]),
            ));
        }
        let k = match curves.iter().rposition(|c| c.angle_deg == v[0]) {
            Some(k) => k,
            None => {
                curves.push(SpectrumCurve {
                    angle_deg: v[0],
                    wavelengths_nm: Vec::new(),
                    values: Vec::new(),
                });
                curves.len() - 1
            }
        };
        curves[k].wavelengths_nm.push(v[1]);
        curves[k].values.push(std::array::from_fn(|j| v[2 + j]));
    }
    if !header {
        return Err(perr(
            1,
            format!(
                "empty: expected the `nacre spectrum` header `{}`",
                crate::commands::spectrum::HEADER
            ),
        ));
    }
    if curves.is_empty() {
        return Err(perr(
            text.lines().count(),
            "no data rows after the header".into(),
        ));
    }
    for c in &mut curves {
        let mut order: Vec<usize> = (0..c.wavelengths_nm.len()).collect();
        order.sort_by(|&a, &b| c.wavelengths_nm[a].total_cmp(&c.wavelengths_nm[b]));
        c.wavelengths_nm = order.iter().map(|&k| c.wavelengths_nm[k]).collect();
        c.values = order.iter().map(|&k| c.values[k]).collect();
    }
    Ok(curves)
}

/// The curves of a CSV to draw: those at `angles_deg` (each must be in the file, within
/// 10⁻⁹°), or by default every curve — or, when there are more than [`MAX_CURVES`], six
/// evenly spread ones, the first and last included. `path` names the file in messages.
pub fn select_curves(
    curves: Vec<SpectrumCurve>,
    angles_deg: Option<(&str, &[f64])>,
    path: &Path,
) -> Result<Vec<SpectrumCurve>> {
    match angles_deg {
        Some((text, wanted)) => wanted
            .iter()
            .map(|&a| {
                curves
                    .iter()
                    .find(|c| (c.angle_deg - a).abs() < 1e-9)
                    .cloned()
                    .ok_or_else(|| {
                        Error::value(
                            Param::Angles,
                            text,
                            format!(
                                "angle {a} is not in {} (it has {} angle(s): {})",
                                path.display(),
                                curves.len(),
                                summarise(&curves.iter().map(|c| c.angle_deg).collect::<Vec<_>>())
                            ),
                        )
                    })
            })
            .collect(),
        None if curves.len() <= MAX_CURVES => Ok(curves),
        None => {
            let n = curves.len();
            Ok((0..6)
                .map(|k| curves[(k * (n - 1) + 2) / 5].clone())
                .collect())
        }
    }
}

/// "0, 1, 2, …, 89" for long lists.
pub(super) fn summarise(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    if s.len() <= 8 {
        s.join(", ")
    } else {
        format!("{}, …, {}", s[..3].join(", "), s[s.len() - 1])
    }
}

/// Reflectance/transmittance spectra against vacuum wavelength: one panel per family
/// present in `quantities` (reflectance, transmittance, absorptance; y from 0 to a round
/// value above the largest), one colour per angle (Tableau 10), solid for unpolarised,
/// dashed for s and dotted for p polarisation.
#[derive(Clone, Debug)]
pub struct SpectrumPlot {
    /// Title (the stack or the CSV file).
    pub title: String,
    /// The curves, one per angle (at most [`MAX_CURVES`]).
    pub curves: Vec<SpectrumCurve>,
    /// What to draw of each curve.
    pub quantities: Vec<SpectrumQuantity>,
}

impl SpectrumPlot {
    /// Checks the number of curves and that there is something to draw.
    pub fn new(
        title: String,
        curves: Vec<SpectrumCurve>,
        quantities: Vec<SpectrumQuantity>,
    ) -> Result<Self> {
        if curves.len() > MAX_CURVES {
            return Err(Error::value(
                Param::Angles,
                summarise(&curves.iter().map(|c| c.angle_deg).collect::<Vec<_>>()),
                format!(
                    "{} angles: a spectrum plot shows at most {MAX_CURVES}",
                    curves.len()
                ),
            ));
        }
        if curves.is_empty() || quantities.is_empty() {
            return Err(Error::invalid("nacre plot spectrum", "nothing to draw"));
        }
        Ok(SpectrumPlot {
            title,
            curves,
            quantities,
        })
    }

    fn families(&self) -> Vec<usize> {
        (0..3)
            .filter(|f| self.quantities.iter().any(|q| q.family() == *f))
            .collect()
    }
}

impl Figure for SpectrumPlot {
    fn size(&self) -> (u32, u32) {
        (1200, 80 + 400 * self.families().len() as u32)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        const NAMES: [&str; 3] = ["reflectance", "transmittance", "absorptance"];
        let area = root.titled(&self.title, ("sans-serif", 20))?;
        let families = self.families();
        let panels = area.split_evenly((families.len(), 1));
        let all_wl = self.curves.iter().flat_map(|c| c.wavelengths_nm.iter());
        let (mut wl0, mut wl1) = all_wl.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
        if !(wl1 > wl0) {
            (wl0, wl1) = (wl0 - 1.0, wl1 + 1.0);
        }
        for (panel, &family) in panels.iter().zip(&families) {
            let quantities: Vec<SpectrumQuantity> = self
                .quantities
                .iter()
                .copied()
                .filter(|q| q.family() == family)
                .collect();
            let max = self
                .curves
                .iter()
                .flat_map(|c| {
                    c.values
                        .iter()
                        .flat_map(|v| quantities.iter().map(move |q| v[q.column()]))
                })
                .filter(|v| v.is_finite())
                .fold(0.0f64, f64::max);
            // Powers stay within [0, 1] without gain: keep that frame when the data does.
            let mut y1 = nice_ceiling((max * 1.02).max(1e-3));
            if max <= 1.0 + 1e-9 {
                y1 = y1.min(1.0);
            }
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .margin_right(170)
                .x_label_area_size(46)
                .y_label_area_size(70)
                .build_cartesian_2d(wl0..wl1, 0.0..y1)?;
            chart
                .configure_mesh()
                .x_desc("vacuum wavelength λ (nm)")
                .y_desc(NAMES[family])
                .x_label_formatter(&fmt_tick)
                .y_label_formatter(&fmt_tick)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .bold_line_style(BLACK.mix(0.15))
                .light_line_style(BLACK.mix(0.04))
                .draw()?;
            let mut entries = Vec::new();
            for (i, c) in self.curves.iter().enumerate() {
                for q in &quantities {
                    let points: Vec<Option<(f64, f64)>> = c
                        .wavelengths_nm
                        .iter()
                        .zip(&c.values)
                        .map(|(&w, v)| Some((w, v[q.column()])))
                        .collect();
                    let line = Line {
                        colour: palette(i),
                        width: 2,
                        dash: q.dash(),
                    };
                    entries.push((format!("{} at {}°", q.name(), c.angle_deg), line));
                    draw_line(&mut chart, &points, [wl0, wl1, 0.0, y1], line, None)?;
                }
            }
            // The legend goes in the right margin, never over the curves.
            let (w, _) = panel.dim_in_pixel();
            draw_side_legend(panel, (w as i32 - 160, 14), &entries)?;
        }
        Ok(())
    }
}
