//! `fit spectrum`: fits a template's free parameters to measured spectra and writes the
//! fitted stack as a recipe (with 1σ uncertainties and a `[fit]` table), the residuals,
//! and, for many spectra, a thickness map.
//!
//! # Input CSV
//!
//! Columns by header name, in any order: `wavelength_nm` (required), optionally `angle_deg`
//! (several angles in one file; 0 when absent) and `sigma` (each point's standard
//! deviation), and the measured values: one column `R` or `T`, or several columns (a wide
//! file: every other column is a spectrum of the quantity asked for). `#` comment lines
//! are skipped. Within an angle the wavelengths must increase. A folder fits every `.csv`
//! file in it, in name order.

use crate::commands::fit_template::FitTemplate;
use crate::csv_text::{self, line_text};
use crate::error::{Error, Param, Result};
use nacre_optics::fit::{
    Baseline, FreeKind, Loss, Measurement, Quantity, Settings, SpectrumFit, Watch,
    fit_spectrum_watched,
};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One measured spectrum: its name (file, or file and column) and points.
#[derive(Clone, Debug)]
pub struct Spectrum {
    /// File name, and the column for a wide file.
    pub name: String,
    /// R or T.
    pub quantity: Quantity,
    /// The points, in file order.
    pub points: Vec<Measurement>,
}

/// Parses a scale or offset model: a number, `free` or `poly:N`.
pub fn parse_baseline(param: Param, text: &str) -> Result<Baseline> {
    let t = text.trim();
    if t == "free" {
        return Ok(Baseline::Poly(0));
    }
    if let Some(n) = t.strip_prefix("poly:") {
        return match n.trim().parse::<usize>() {
            Ok(n) if n <= 8 => Ok(Baseline::Poly(n)),
            _ => Err(Error::value(
                param,
                text,
                "poly:N takes a degree N from 0 to 8, e.g. `poly:2`",
            )),
        };
    }
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(Baseline::Fixed(v)),
        _ => Err(Error::value(
            param,
            text,
            "expected a number, `free` or `poly:N` (a polynomial of degree N in wavenumber)",
        )),
    }
}

/// Parses `--range START:END` (nm).
pub fn parse_window(text: &str) -> Result<(f64, f64)> {
    let bad = |m: &str| Error::value(Param::FitRange, text, m.to_string());
    let (a, b) = text
        .split_once(':')
        .ok_or_else(|| bad("expected START:END in nm, e.g. 450:750"))?;
    let (a, b): (f64, f64) = match (a.trim().parse(), b.trim().parse()) {
        (Ok(a), Ok(b)) => (a, b),
        _ => return Err(bad("expected START:END in nm, e.g. 450:750")),
    };
    if !(a.is_finite() && b.is_finite() && a < b) {
        return Err(bad("START must be below END, both finite"));
    }
    Ok((a, b))
}

/// Reads the spectra of `path`: a CSV file, or every `.csv` file of a folder in name
/// order. `quantity` names the values of a wide file's columns (and must agree with an
/// `R`/`T` column).
pub fn read_spectra(path: &Path, quantity: Option<Quantity>) -> Result<Vec<Spectrum>> {
    let io = |source| {
        Error::from(nacre_format::Error::Io {
            path: path.to_path_buf(),
            source,
        })
    };
    if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::invalid(
                Param::Measured.given(path.display().to_string()),
                "the folder holds no .csv file",
            ));
        }
        let mut out = Vec::new();
        for f in files {
            out.extend(read_csv(&f, quantity)?);
        }
        return Ok(out);
    }
    read_csv(path, quantity)
}

fn read_csv(path: &Path, quantity: Option<Quantity>) -> Result<Vec<Spectrum>> {
    let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let at = |line: usize, m: String| Error::recipe(path.to_path_buf(), line, m);
    let mut rows = csv_text::rows(path, &text);
    let (header_line, names) = csv_text::header(
        path,
        &mut rows,
        "a header `wavelength_nm,R` (or T) and rows",
    )?;
    let find = |n: &str| names.iter().position(|h| h.eq_ignore_ascii_case(n));
    let wl = find("wavelength_nm").ok_or_else(|| {
        at(
            header_line,
            format!(
                "header `{}` has no `wavelength_nm` column",
                line_text(&text, header_line)
            ),
        )
    })?;
    let angle = find("angle_deg");
    let sigma = find("sigma");
    let values: Vec<usize> = (0..names.len())
        .filter(|&i| i != wl && Some(i) != angle && Some(i) != sigma)
        .collect();
    if values.is_empty() {
        return Err(at(
            header_line,
            "no measured column: add `R` or `T` beside `wavelength_nm`".into(),
        ));
    }
    let named = |i: usize| match names[i].to_ascii_uppercase().as_str() {
        "R" => Some(Quantity::Reflectance),
        "T" => Some(Quantity::Transmittance),
        _ => None,
    };
    let file_name = path.display().to_string();
    let mut spectra: Vec<Spectrum> = values
        .iter()
        .map(|&i| {
            let q = match (named(i), quantity) {
                (Some(q), Some(asked)) if q != asked => Err(at(
                    header_line,
                    format!(
                        "column `{}` is {}, but the fit was asked for {}",
                        names[i],
                        label(q),
                        label(asked)
                    ),
                )),
                (Some(q), _) => Ok(q),
                (None, Some(q)) => Ok(q),
                (None, None) if values.len() > 1 => Ok(Quantity::Reflectance),
                (None, None) => Err(at(
                    header_line,
                    format!(
                        "column `{}` is neither `R` nor `T`: name it so, or say which with the quantity",
                        names[i]
                    ),
                )),
            }?;
            Ok(Spectrum {
                name: if values.len() > 1 {
                    format!("{file_name}:{}", names[i])
                } else {
                    file_name.clone()
                },
                quantity: q,
                points: Vec::new(),
            })
        })
        .collect::<Result<_>>()?;
    let mut last: Option<(f64, f64)> = None;
    for row in rows {
        let row = row?;
        if row.fields.len() != names.len() {
            return Err(at(
                row.line,
                format!(
                    "{} fields where the header has {}: `{}`",
                    row.fields.len(),
                    names.len(),
                    line_text(&text, row.line)
                ),
            ));
        }
        let num = |i: usize| -> Result<f64> {
            match row.fields[i].trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(at(
                    row.line,
                    format!(
                        "{} `{}` is not a finite number",
                        names[i],
                        row.fields[i].trim()
                    ),
                )),
            }
        };
        let w = num(wl)?;
        if w <= 0.0 {
            return Err(at(row.line, format!("wavelength_nm {w} must be positive")));
        }
        let a = match angle {
            Some(i) => num(i)?,
            None => 0.0,
        };
        if !(a.abs() < 90.0) {
            return Err(at(
                row.line,
                format!("angle_deg {a} is outside (−90°, 90°)"),
            ));
        }
        let s = match sigma {
            Some(i) => {
                let s = num(i)?;
                if s <= 0.0 {
                    return Err(at(row.line, format!("sigma {s} must be positive")));
                }
                Some(s)
            }
            None => None,
        };
        if let Some((pa, pw)) = last
            && pa == a
            && w <= pw
        {
            return Err(at(
                row.line,
                format!(
                    "wavelength {w} nm {} the row before's {pw} nm: within an angle the wavelengths must increase",
                    if w == pw { "repeats" } else { "comes after" }
                ),
            ));
        }
        last = Some((a, w));
        for (sp, &i) in spectra.iter_mut().zip(&values) {
            sp.points.push(Measurement {
                angle_deg: a,
                wavelength_nm: w,
                value: num(i)?,
                sigma: s,
            });
        }
    }
    if spectra[0].points.is_empty() {
        return Err(at(header_line, "the file has a header but no rows".into()));
    }
    Ok(spectra)
}

fn label(q: Quantity) -> &'static str {
    match q {
        Quantity::Reflectance => "reflectance (R)",
        Quantity::Transmittance => "transmittance (T)",
    }
}

/// A fit's request.
#[derive(Clone, Debug)]
pub struct Request {
    /// The fit settings (the quantity is each spectrum's own).
    pub settings: Settings,
    /// The wavelength window, nm.
    pub window: Option<(f64, f64)>,
}

/// One spectrum's fit.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The spectrum's name.
    pub name: String,
    /// R or T.
    pub quantity: Quantity,
    /// The points fitted (inside the window).
    pub points: Vec<Measurement>,
    /// The result.
    pub fit: SpectrumFit,
}

/// Fits every spectrum (in parallel; each fit runs alone, so the results are the same
/// whatever the thread count).
pub fn fit_all(
    template: &FitTemplate,
    spectra: &[Spectrum],
    request: &Request,
) -> Result<Vec<Outcome>> {
    spectra
        .par_iter()
        .map(|s| fit_one(template, s, request, Watch::none()))
        .collect()
}

/// Fits one spectrum (what [`fit_all`] does for each), reporting its progress to `watch`
/// and stopping with [`nacre_optics::Error::FitCancelled`] once its cancel flag is set
/// ([`fit_spectrum_watched`]; the studio's background fit).
pub fn fit_one(
    template: &FitTemplate,
    s: &Spectrum,
    request: &Request,
    watch: Watch<'_>,
) -> Result<Outcome> {
    let points: Vec<Measurement> = s
        .points
        .iter()
        .filter(|p| {
            request
                .window
                .is_none_or(|(a, b)| p.wavelength_nm >= a && p.wavelength_nm <= b)
        })
        .copied()
        .collect();
    let settings = Settings {
        quantity: s.quantity,
        ..request.settings
    };
    let fit = fit_spectrum_watched(&template.template, &points, &settings, watch).map_err(|e| {
        let e = template
            .spec
            .stack
            .attribute(template.template.stack(), Error::Optics(e));
        match e {
            Error::Optics(source) => {
                Error::optics_in(Param::Measured.given(s.name.clone()), source)
            }
            other => other,
        }
    })?;
    Ok(Outcome {
        name: s.name.clone(),
        quantity: s.quantity,
        points,
        fit,
    })
}

/// The warnings of a fit: parameters on a bound, too few fringes, an ambiguous fit.
pub fn warnings(template: &FitTemplate, fit: &SpectrumFit) -> Vec<String> {
    let mut out = Vec::new();
    for (k, f) in template.free().iter().enumerate() {
        let what = match f.kind {
            FreeKind::ThicknessNm => format!("layer {} thickness", f.layer),
            FreeKind::Index => format!("layer {} index", f.layer),
        };
        if fit.on_bound[k] {
            out.push(format!(
                "{what} {} sits on its bound {}:{}: widen the range",
                fit.x[k], f.lo, f.hi
            ));
        }
        if fit.fringes[k] < 0.5 {
            out.push(format!(
                "{what}: the data hold {:.2} fringes of this film, too few to fix its thickness independently of its index",
                fit.fringes[k]
            ));
        }
    }
    if let Some(alt) = &fit.ambiguous {
        out.push(format!(
            "ambiguous: parameters {alt:?} fit the data about as well (another fringe order); widen the wavelength range or narrow the bounds"
        ));
    }
    out
}

/// The fitted stack as a recipe that `recipe` flags read back: every value with its 1σ
/// uncertainty beside it and a `[fit]` table.
pub fn recipe_toml(template: &FitTemplate, outcome: &Outcome) -> Result<String> {
    let fit = &outcome.fit;
    let stack = template.stack_at(&fit.x)?;
    let spec = &template.spec.stack;
    let free = template.free();
    let mut s = String::new();
    let q = |t: &str| format!("{:?}", t);
    let _ = writeln!(s, "# A stack fitted to {}", outcome.name);
    let _ = writeln!(s, "ambient = {}", q(&spec.ambient.spec));
    let _ = writeln!(s, "substrate = {}", q(&spec.substrate.spec));
    for (j, layer) in stack.layers().iter().enumerate() {
        let find = |kind| free.iter().position(|f| f.layer == j + 1 && f.kind == kind);
        let _ = writeln!(s, "\n[[layers]]");
        match find(FreeKind::Index) {
            Some(k) => {
                let _ = writeln!(s, "material = \"{}\"", fit.x[k]);
                let _ = writeln!(s, "index_sigma = {}", finite(fit.sigma[k]));
            }
            None => {
                let _ = writeln!(s, "material = {}", q(&spec.layers[j].0.spec));
            }
        }
        let _ = writeln!(s, "thickness_nm = {}", layer.thickness_nm);
        if let Some(k) = find(FreeKind::ThicknessNm) {
            let _ = writeln!(s, "thickness_sigma_nm = {}", finite(fit.sigma[k]));
        }
        if stack.is_incoherent(j + 1) {
            let _ = writeln!(s, "incoherent = true");
        }
    }
    let list = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
        format!("[{}]", items.join(", "))
    };
    let _ = writeln!(s, "\n[fit]");
    let _ = writeln!(s, "points = {}", fit.points);
    let _ = writeln!(s, "rms = {}", fit.rms);
    let _ = writeln!(s, "chi2 = {}", fit.chi2);
    let _ = writeln!(s, "scale = {}", list(&fit.scale));
    let _ = writeln!(s, "offset = {}", list(&fit.offset));
    let _ = writeln!(s, "iterations = {}", fit.iterations);
    let _ = writeln!(s, "starts = {}", fit.starts);
    let w: Vec<String> = warnings(template, fit).iter().map(|w| q(w)).collect();
    let _ = writeln!(s, "warnings = [{}]", w.join(", "));
    Ok(s)
}

/// TOML has no NaN literal in every reader: an undetermined σ is written as `nan`, which
/// TOML 1.0 accepts.
fn finite(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "nan".into()
    }
}

/// The picture of a fit (`--plot`): the measured values against the fitted ones per angle,
/// residuals below, titled with the spectrum's name, the fitted values and the rms.
pub fn fit_plot(
    template: &FitTemplate,
    outcome: &Outcome,
) -> Result<crate::commands::plot::FitPlot> {
    let mut title = outcome.name.clone();
    let values: Vec<String> = template
        .free()
        .iter()
        .zip(outcome.fit.x.iter().zip(&outcome.fit.sigma))
        .map(|(f, (x, s))| {
            // Two significant digits of σ, and x to the same place.
            let places = [1.0, 0.1, 0.01, 0.001]
                .iter()
                .position(|&p| *s >= p)
                .unwrap_or(4)
                + 1;
            match f.kind {
                FreeKind::ThicknessNm => {
                    format!("d{} = {x:.places$} ± {s:.places$} nm", f.layer)
                }
                FreeKind::Index => format!("n{} = {x:.places$} ± {s:.places$}", f.layer),
            }
        })
        .collect();
    if !values.is_empty() {
        title = format!("{title}: {}", values.join(", "));
    }
    title = format!("{title}; rms {:.2e}", outcome.fit.rms);
    let quantity = match outcome.quantity {
        Quantity::Reflectance => "reflectance",
        Quantity::Transmittance => "transmittance",
    };
    let points: Vec<(f64, f64, f64, f64)> = outcome
        .points
        .iter()
        .zip(&outcome.fit.fitted)
        .map(|(p, &f)| (p.angle_deg, p.wavelength_nm, p.value, f))
        .collect();
    crate::commands::plot::FitPlot::new(title, quantity, &points)
}

/// The residuals CSV: `spectrum,angle_deg,wavelength_nm,measured,fitted,residual`.
pub fn residuals_csv(outcomes: &[Outcome], w: &mut dyn std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "spectrum,angle_deg,wavelength_nm,measured,fitted,residual"
    )?;
    let mut csv = csv_text::writer(w);
    for o in outcomes {
        for (p, f) in o.points.iter().zip(&o.fit.fitted) {
            csv.write_record([
                o.name.clone(),
                format!("{}", p.angle_deg),
                format!("{}", p.wavelength_nm),
                format!("{}", p.value),
                format!("{f}"),
                format!("{}", p.value - f),
            ])?;
        }
    }
    csv.flush()
}

/// The thickness map of many spectra: one row per spectrum, each free parameter and its σ,
/// the rms residual and the number of warnings.
pub fn map_csv(
    template: &FitTemplate,
    outcomes: &[Outcome],
    w: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    let mut header = vec!["spectrum".to_string()];
    for f in template.free() {
        let (name, unit) = match f.kind {
            FreeKind::ThicknessNm => ("thickness", "_nm"),
            FreeKind::Index => ("index", ""),
        };
        header.push(format!("layer{}_{name}{unit}", f.layer));
        header.push(format!("layer{}_{name}_sigma{unit}", f.layer));
    }
    header.extend(["rms".into(), "warnings".into()]);
    let mut csv = csv_text::writer(w);
    csv.write_record(&header)?;
    for o in outcomes {
        let mut row = vec![o.name.clone()];
        for (x, s) in o.fit.x.iter().zip(&o.fit.sigma) {
            row.push(format!("{x}"));
            row.push(format!("{s}"));
        }
        row.push(format!("{}", o.fit.rms));
        row.push(format!("{}", warnings(template, &o.fit).len()));
        csv.write_record(&row)?;
    }
    csv.flush()
}

/// Parses `--loss`.
pub fn parse_loss(text: &str) -> Result<Loss> {
    match text.trim() {
        "linear" => Ok(Loss::Linear),
        "cauchy" => Ok(Loss::Cauchy),
        _ => Err(Error::value(
            Param::Loss,
            text,
            "expected `linear` (least squares) or `cauchy` (robust to outliers)",
        )),
    }
}
