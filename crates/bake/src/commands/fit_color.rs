//! `fit color`: designs a template's free thicknesses and indices for target colours over
//! angles ([`nacre_optics::fit::color`]) and writes the designed stack as a recipe, the
//! achieved colour and ΔE2000 per target row, and optionally a picture of the designed
//! swatches beside the targets.
//!
//! # Targets CSV
//!
//! Columns by header name, in any order: `angle_deg` (required), the colour as `L,a,b`
//! (CIELAB under the illuminant), `R,G,B` (linear, in the output space, as `nacre color`
//! writes them) or `X,Y,Z` (under the illuminant, perfect reflector Y = 1), and optionally
//! `weight` (> 0, default 1). `nacre color`'s own output reads as targets: its
//! `thickness_nm` and `film_ior` columns are ignored (R, G, B are taken where both R, G, B
//! and X, Y, Z are given). `#` lines are comments.
//!
//! # Scoring
//!
//! The design runs on one spectral rule for the whole box; the achieved colours reported
//! (and written to the recipe's `[fit]` table) are recomputed by `nacre color`'s own
//! `spectral` method on the designed stack, so `nacre color --recipe FIT.toml` shows the
//! same numbers.

use crate::commands::color::{self, Method, Point};
use crate::commands::fit_template::FitTemplate;
use crate::csv_text::{self, line_text};
use crate::error::{Error, Param, Result};
use nacre_optics::colour::{Colorimeter, delta_e_2000, xyz_to_lab};
use nacre_optics::fit::{
    ColourSettings, ColourTarget, FreeKind, Quantity, Watch, fit_colour_watched,
};
use std::fmt::Write as _;
use std::path::Path;

/// One target row as read.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetRow {
    /// 1-based line in the file.
    pub line: usize,
    /// Incidence angle, degrees.
    pub angle_deg: f64,
    /// CIELAB under the illuminant.
    pub lab: [f64; 3],
    /// The colour in the output space (the given R, G, B, or converted).
    pub colour: [f64; 3],
    /// Weight.
    pub weight: f64,
}

/// How a target's colour is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Given {
    /// Linear R, G, B in the colorimeter's output space (as `nacre color` writes them).
    Rgb,
    /// CIE XYZ under the illuminant (perfect reflector Y = 1).
    Xyz,
    /// CIELAB under the illuminant.
    Lab,
}

/// A target row's value outside what it may hold: `{field} {value} {requirement}`
/// (`angle_deg 90 must lie strictly between -90 and 90`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadTarget {
    /// `angle_deg`, `weight` or `L`.
    pub field: &'static str,
    /// The value given.
    pub value: f64,
    /// What it must be.
    pub requirement: &'static str,
}

impl std::fmt::Display for BadTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {} {}", self.field, self.value, self.requirement)
    }
}

/// One target row from finite numbers: the angle (strictly inside ±90°), the colour `v` as
/// `given` (L of CIELAB in 0–100) and the weight (> 0), with its CIELAB and output-space
/// colour under `colorimeter`. The one conversion of the targets file and of Python's
/// `nacre.fit_color` arrays.
pub fn target_row(
    line: usize,
    angle_deg: f64,
    given: Given,
    v: [f64; 3],
    weight: f64,
    colorimeter: &Colorimeter,
) -> std::result::Result<TargetRow, BadTarget> {
    if !(angle_deg > -90.0 && angle_deg < 90.0) {
        return Err(BadTarget {
            field: "angle_deg",
            value: angle_deg,
            requirement: "must lie strictly between -90 and 90",
        });
    }
    if weight <= 0.0 {
        return Err(BadTarget {
            field: "weight",
            value: weight,
            requirement: "must be positive",
        });
    }
    let white = colorimeter.white_xyz();
    let (lab, colour) = match given {
        Given::Rgb => (xyz_to_lab(colorimeter.xyz_from_output(v), white), v),
        Given::Xyz => (xyz_to_lab(v, white), colorimeter.output_from_xyz(v)),
        Given::Lab => {
            if !(0.0..=100.0).contains(&v[0]) {
                return Err(BadTarget {
                    field: "L",
                    value: v[0],
                    requirement: "must lie in 0–100",
                });
            }
            (v, colorimeter.output_from_xyz(lab_to_xyz(v, white)))
        }
    };
    Ok(TargetRow {
        line,
        angle_deg,
        lab,
        colour,
        weight,
    })
}

/// Reads the targets of `path` for `colorimeter` (see the module docs).
pub fn read_targets(path: &Path, colorimeter: &Colorimeter) -> Result<Vec<TargetRow>> {
    let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_targets(path, &text, colorimeter)
}

/// [`read_targets`] of `text`, read from `path`.
pub fn parse_targets(path: &Path, text: &str, colorimeter: &Colorimeter) -> Result<Vec<TargetRow>> {
    let at = |line: usize, m: String| Error::recipe(path.to_path_buf(), line, m);
    let mut rows = csv_text::rows(path, text);
    let (header_line, names) = csv_text::header(
        path,
        &mut rows,
        "a header `angle_deg,R,G,B` (or L,a,b) and rows",
    )?;
    let find = |n: &str| names.iter().position(|h| h == n);
    let find_ci = |n: &str| names.iter().position(|h| h.eq_ignore_ascii_case(n));
    const KNOWN: [&str; 13] = [
        "angle_deg",
        "weight",
        "L",
        "a",
        "b",
        "R",
        "G",
        "B",
        "X",
        "Y",
        "Z",
        "thickness_nm",
        "film_ior",
    ];
    for n in &names {
        if !KNOWN.contains(&n.as_str()) {
            return Err(at(
                header_line,
                format!(
                    "unknown column `{n}` in header `{}`: expected angle_deg, the colour as L,a,b or R,G,B or X,Y,Z, and optionally weight",
                    line_text(text, header_line)
                ),
            ));
        }
    }
    let angle = find_ci("angle_deg").ok_or_else(|| {
        at(
            header_line,
            format!(
                "header `{}` has no `angle_deg` column",
                line_text(text, header_line)
            ),
        )
    })?;
    let weight = find_ci("weight");
    let triple = |a: &str, b: &str, c: &str| match (find(a), find(b), find(c)) {
        (Some(x), Some(y), Some(z)) => Some([x, y, z]),
        _ => None,
    };
    let (given, cols) = match (
        triple("R", "G", "B"),
        triple("X", "Y", "Z"),
        triple("L", "a", "b"),
    ) {
        (Some(c), _, _) => (Given::Rgb, c),
        (None, Some(c), _) => (Given::Xyz, c),
        (None, None, Some(c)) => (Given::Lab, c),
        _ => {
            return Err(at(
                header_line,
                format!(
                    "header `{}` has no complete colour: give R,G,B (linear, in the output space), X,Y,Z or L,a,b",
                    line_text(text, header_line)
                ),
            ));
        }
    };
    let mut out = Vec::new();
    for row in rows {
        let row = row?;
        if row.fields.len() != names.len() {
            return Err(at(
                row.line,
                format!(
                    "{} fields where the header has {}: `{}`",
                    row.fields.len(),
                    names.len(),
                    line_text(text, row.line)
                ),
            ));
        }
        let num = |i: usize| -> Result<f64> {
            let f = row.fields[i].trim();
            match f.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(at(
                    row.line,
                    format!("{} `{f}` is not a finite number", names[i]),
                )),
            }
        };
        let angle_deg = num(angle)?;
        let w = match weight {
            Some(i) => num(i)?,
            None => 1.0,
        };
        let v = [num(cols[0])?, num(cols[1])?, num(cols[2])?];
        let target = target_row(row.line, angle_deg, given, v, w, colorimeter)
            .map_err(|bad| at(row.line, bad.to_string()))?;
        out.push(target);
    }
    if out.is_empty() {
        return Err(at(header_line, "no target rows below the header".into()));
    }
    Ok(out)
}

/// XYZ of CIELAB `lab` against `white` (the inverse of CIE 015:2018 Eq. 8.1–8.3:
/// f⁻¹(t) = t³ above 24/116, else 108/841 (t − 16/116)).
pub fn lab_to_xyz(lab: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let fy = (lab[0] + 16.0) / 116.0;
    let fx = fy + lab[1] / 500.0;
    let fz = fy - lab[2] / 200.0;
    let inv = |t: f64| {
        if t > 24.0 / 116.0 {
            t * t * t
        } else {
            108.0 / 841.0 * (t - 16.0 / 116.0)
        }
    };
    [white[0] * inv(fx), white[1] * inv(fy), white[2] * inv(fz)]
}

/// What one designed stack achieves at each target row (by `nacre color`'s spectral
/// method).
#[derive(Clone, Debug, PartialEq)]
pub struct Achieved {
    /// The free parameters.
    pub x: Vec<f64>,
    /// Per row: the colour in the output space.
    pub colour: Vec<[f64; 3]>,
    /// Per row: CIELAB.
    pub lab: Vec<[f64; 3]>,
    /// Per row: ΔE2000 to the target.
    pub delta_e: Vec<f64>,
    /// LM iterations.
    pub iterations: usize,
}

impl Achieved {
    /// The largest ΔE2000.
    pub fn max(&self) -> f64 {
        self.delta_e.iter().copied().fold(0.0, f64::max)
    }

    /// The weighted mean ΔE2000.
    pub fn mean(&self, rows: &[TargetRow]) -> f64 {
        let w: f64 = rows.iter().map(|r| r.weight).sum();
        rows.iter()
            .zip(&self.delta_e)
            .map(|(r, e)| r.weight * e)
            .sum::<f64>()
            / w
    }
}

/// A design: its solutions, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// The distinct stacks, best first.
    pub solutions: Vec<Achieved>,
    /// Samples and polishes the search ran.
    pub samples: usize,
    /// Local polishes.
    pub starts: usize,
}

/// Designs `template` for `rows`.
pub fn design(
    template: &FitTemplate,
    rows: &[TargetRow],
    colorimeter: &Colorimeter,
    settings: &ColourSettings,
) -> Result<Design> {
    design_watched(template, rows, colorimeter, settings, Watch::none())
}

/// [`design`] reporting its progress to `watch` and stopping with
/// [`nacre_optics::Error::FitCancelled`] once its cancel flag is set
/// ([`fit_colour_watched`]; the studio's background design).
pub fn design_watched(
    template: &FitTemplate,
    rows: &[TargetRow],
    colorimeter: &Colorimeter,
    settings: &ColourSettings,
    watch: Watch<'_>,
) -> Result<Design> {
    let targets: Vec<ColourTarget> = rows
        .iter()
        .map(|r| ColourTarget {
            angle_deg: r.angle_deg,
            lab: r.lab,
            weight: r.weight,
        })
        .collect();
    let attribute = |e: nacre_optics::Error| {
        template
            .spec
            .stack
            .attribute(template.template.stack(), Error::Optics(e))
    };
    let fit = fit_colour_watched(&template.template, &targets, colorimeter, settings, watch)
        .map_err(attribute)?;
    let quantity = match settings.quantity {
        Quantity::Reflectance => color::Quantity::Reflectance,
        Quantity::Transmittance => color::Quantity::Transmittance,
    };
    let points: Vec<Point> = rows
        .iter()
        .map(|r| Point {
            angle_deg: r.angle_deg,
            thickness_nm: None,
            film_ior: None,
        })
        .collect();
    let solutions = fit
        .solutions
        .iter()
        .map(|s| {
            // As written: thicknesses to 0.001 nm, indices to 10⁻⁵.
            let x: Vec<f64> = template
                .free()
                .iter()
                .zip(&s.x)
                .map(|(f, &v)| match f.kind {
                    FreeKind::ThicknessNm => round(v, 3),
                    FreeKind::Index => round(v, 5),
                })
                .collect();
            let stack = template.stack_at(&x)?;
            let colour = color::evaluate(
                &stack,
                &points,
                &Method::Spectral,
                colorimeter,
                quantity,
                None,
            )?;
            let lab: Vec<[f64; 3]> = colour
                .iter()
                .map(|&c| xyz_to_lab(colorimeter.xyz_from_output(c), colorimeter.white_xyz()))
                .collect();
            let delta_e = rows
                .iter()
                .zip(&lab)
                .map(|(r, l)| delta_e_2000(r.lab, *l))
                .collect();
            Ok(Achieved {
                x,
                colour,
                lab,
                delta_e,
                iterations: s.iterations,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Design {
        solutions,
        samples: fit.samples,
        starts: fit.starts,
    })
}

/// Parses `--solutions K` (1–100).
pub fn parse_solutions(k: usize) -> Result<usize> {
    if (1..=100).contains(&k) {
        Ok(k)
    } else {
        Err(Error::value(
            Param::Solutions,
            k.to_string(),
            "expected 1 to 100 stacks",
        ))
    }
}

/// Checks `--distinct NM` (finite, ≥ 0).
pub fn check_distinct(nm: f64) -> Result<f64> {
    if nm.is_finite() && nm >= 0.0 {
        Ok(nm)
    } else {
        Err(Error::value(
            Param::Distinct,
            nm.to_string(),
            "expected a thickness tolerance of 0 nm or more",
        ))
    }
}

fn list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{}", round(*x, 4))).collect();
    format!("[{}]", items.join(", "))
}

/// `v` rounded to `digits` decimals (for the reports).
fn round(v: f64, digits: i32) -> f64 {
    let s = nacre_optics::elementary::powi(10.0, digits);
    (v * s).round() / s
}

/// Solution `k` (0-based) as a recipe that `--recipe` reads: the designed stack and a
/// `[fit]` table with the targets' file, the achieved colour and ΔE2000 per row.
pub fn recipe_toml(
    template: &FitTemplate,
    design: &Design,
    k: usize,
    rows: &[TargetRow],
    colorimeter: &Colorimeter,
    targets_name: &str,
) -> Result<String> {
    let sol = &design.solutions[k];
    let stack = template.stack_at(&sol.x)?;
    let spec = &template.spec.stack;
    let free = template.free();
    let q = |t: &str| format!("{t:?}");
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# A stack designed for the colours of {targets_name} (solution {} of {})",
        k + 1,
        design.solutions.len()
    );
    let _ = writeln!(s, "ambient = {}", q(&spec.ambient.spec));
    let _ = writeln!(s, "substrate = {}", q(&spec.substrate.spec));
    for (j, layer) in stack.layers().iter().enumerate() {
        let find = |kind| free.iter().position(|f| f.layer == j + 1 && f.kind == kind);
        let _ = writeln!(s, "\n[[layers]]");
        match find(FreeKind::Index) {
            Some(i) => {
                let _ = writeln!(s, "material = \"{}\"", sol.x[i]);
            }
            None => {
                let _ = writeln!(s, "material = {}", q(&spec.layers[j].0.spec));
            }
        }
        let _ = writeln!(s, "thickness_nm = {}", layer.thickness_nm);
    }
    let names = colorimeter.space().channel_names();
    let _ = writeln!(s, "\n[fit]");
    let _ = writeln!(s, "targets = {}", q(targets_name));
    let _ = writeln!(
        s,
        "colour = {}",
        q(&format!(
            "{} {} {}",
            colorimeter.observer().name(),
            colorimeter.illuminant().name(),
            colorimeter.space().name()
        ))
    );
    let angles: Vec<f64> = rows.iter().map(|r| r.angle_deg).collect();
    let _ = writeln!(s, "angles_deg = {}", list(&angles));
    for c in 0..3 {
        let v: Vec<f64> = sol.colour.iter().map(|x| x[c]).collect();
        let _ = writeln!(s, "{} = {}", names[c], list(&v));
    }
    let _ = writeln!(s, "delta_e_2000 = {}", list(&sol.delta_e));
    let _ = writeln!(s, "delta_e_2000_mean = {}", round(sol.mean(rows), 4));
    let _ = writeln!(s, "delta_e_2000_max = {}", round(sol.max(), 4));
    let _ = writeln!(
        s,
        "reached = {}",
        sol.max() <= nacre_optics::fit::color::REACHED_DELTA_E
    );
    let _ = writeln!(s, "iterations = {}", sol.iterations);
    Ok(s)
}

/// The per-row report CSV: `solution,angle_deg,weight,target_L,target_a,target_b,L,a,b,`
/// the three output channels, `delta_e_2000`.
pub fn report_csv(
    design: &Design,
    rows: &[TargetRow],
    colorimeter: &Colorimeter,
    w: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    let n = colorimeter.space().channel_names();
    writeln!(
        w,
        "solution,angle_deg,weight,target_L,target_a,target_b,L,a,b,{},{},{},delta_e_2000",
        n[0], n[1], n[2]
    )?;
    for (k, s) in design.solutions.iter().enumerate() {
        for (i, r) in rows.iter().enumerate() {
            let (t, l, c) = (r.lab, s.lab[i], s.colour[i]);
            writeln!(
                w,
                "{},{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{:.4}",
                k + 1,
                r.angle_deg,
                r.weight,
                t[0],
                t[1],
                t[2],
                l[0],
                l[1],
                l[2],
                c[0],
                c[1],
                c[2],
                s.delta_e[i]
            )?;
        }
    }
    Ok(())
}

/// One line per solution for standard error: its free values and ΔE2000, and whether it
/// reaches the look (if not, the worst row named by `place`: `line 4` for the targets
/// file, [`file_line`]).
pub fn describe(
    template: &FitTemplate,
    design: &Design,
    rows: &[TargetRow],
    place: &dyn Fn(&TargetRow) -> String,
) -> Vec<String> {
    design
        .solutions
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let values: Vec<String> = template
                .free()
                .iter()
                .zip(&s.x)
                .map(|(f, v)| match f.kind {
                    FreeKind::ThicknessNm => format!("layer {} {:.1} nm", f.layer, v),
                    FreeKind::Index => format!("layer {} n {:.4}", f.layer, v),
                })
                .collect();
            let worst = s
                .delta_e
                .iter()
                .enumerate()
                .fold((0, 0.0), |b, (i, &e)| if e > b.1 { (i, e) } else { b });
            let verdict = if s.max() <= nacre_optics::fit::color::REACHED_DELTA_E {
                "reached".to_string()
            } else {
                format!(
                    "not reached: the closest stack stays ΔE2000 {:.2} away at {}° ({})",
                    worst.1,
                    rows[worst.0].angle_deg,
                    place(&rows[worst.0])
                )
            };
            format!(
                "solution {}: {} — ΔE2000 mean {:.2}, max {:.2}; {verdict}",
                k + 1,
                values.join(", "),
                s.mean(rows),
                s.max()
            )
        })
        .collect()
}

/// A target row's place in its file: `line 4`.
pub fn file_line(row: &TargetRow) -> String {
    format!("line {}", row.line)
}

/// The picture of a design: per target row, the target swatch over each solution's, as
/// sRGB with one exposure for all (the brightest channel of any swatch at 0.95, never
/// darkened).
pub fn design_plot(
    design: &Design,
    rows: &[TargetRow],
    colorimeter: &Colorimeter,
    title: &str,
) -> crate::commands::plot::DesignPlot {
    let display = crate::commands::plot::DisplayConverter::new(colorimeter);
    use crate::commands::plot::SwatchRow;
    let mut swatches = vec![SwatchRow {
        label: "target".into(),
        colours: rows.iter().map(|r| display.linear_srgb(r.colour)).collect(),
        delta_e: None,
    }];
    for (k, s) in design.solutions.iter().enumerate() {
        swatches.push(SwatchRow {
            label: format!("design {}", k + 1),
            colours: s.colour.iter().map(|&c| display.linear_srgb(c)).collect(),
            delta_e: Some(s.delta_e.clone()),
        });
    }
    let brightest = swatches
        .iter()
        .flat_map(|r| r.colours.iter())
        .flat_map(|c| c.iter().copied())
        .fold(0.0f64, f64::max);
    let exposure = if brightest > 0.0 {
        (0.95 / brightest).max(1.0)
    } else {
        1.0
    };
    crate::commands::plot::DesignPlot {
        title: format!("{title} (exposure ×{})", round(exposure, 1)),
        angles_deg: rows.iter().map(|r| r.angle_deg).collect(),
        rows: swatches,
        exposure,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nacre_optics::colour::{Illuminant, Observer, OutputSpace, RgbSpace};

    fn srgb() -> Colorimeter {
        Colorimeter::new(
            Observer::Cie1931_2Deg,
            Illuminant::D65,
            OutputSpace::Rgb(RgbSpace::Srgb),
        )
    }

    #[test]
    fn targets_in_every_form_agree() {
        let c = srgb();
        let p = Path::new("t.csv");
        let rgb = parse_targets(p, "angle_deg,R,G,B\n0,0.2,0.1,0.05\n", &c).unwrap();
        let lab = rgb[0].lab;
        let xyz = c.xyz_from_output([0.2, 0.1, 0.05]);
        let text = format!(
            "# xyz\nangle_deg,X,Y,Z,weight\n0,{},{},{},2\n",
            xyz[0], xyz[1], xyz[2]
        );
        let from_xyz = parse_targets(p, &text, &c).unwrap();
        assert_eq!(from_xyz[0].line, 3);
        assert_eq!(from_xyz[0].weight, 2.0);
        let text = format!("L,a,b,angle_deg\n{},{},{},0\n", lab[0], lab[1], lab[2]);
        let from_lab = parse_targets(p, &text, &c).unwrap();
        for k in 0..3 {
            assert!((from_xyz[0].lab[k] - lab[k]).abs() < 1e-9);
            assert!((from_lab[0].colour[k] - [0.2, 0.1, 0.05][k]).abs() < 1e-9);
        }
        // nacre color's output reads as targets.
        let text =
            "angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B\n10,400,1.33,0.1,0.1,0.1,0.2,0.1,0.05\n";
        let t = parse_targets(p, text, &c).unwrap();
        assert_eq!(t[0].colour, [0.2, 0.1, 0.05]);
    }

    #[test]
    fn bad_targets_name_the_line() {
        let c = srgb();
        let p = Path::new("t.csv");
        for (text, want) in [
            ("", "t.csv:0: the file is empty"),
            (
                "angle_deg,R,G\n0,1,1\n",
                "t.csv:1: header `angle_deg,R,G` has no complete colour",
            ),
            ("angle_deg,R,G,B,hue\n", "t.csv:1: unknown column `hue`"),
            (
                "R,G,B\n1,1,1\n",
                "t.csv:1: header `R,G,B` has no `angle_deg`",
            ),
            ("angle_deg,R,G,B\n", "t.csv:1: no target rows"),
            (
                "angle_deg,R,G,B\n0,1,x,1\n",
                "t.csv:2: G `x` is not a finite number",
            ),
            (
                "angle_deg,R,G,B\n0,1,NaN,1\n",
                "t.csv:2: G `NaN` is not a finite number",
            ),
            (
                "angle_deg,R,G,B\n90,1,1,1\n",
                "t.csv:2: angle_deg 90 must lie",
            ),
            (
                "angle_deg,R,G,B,weight\n0,1,1,1,0\n",
                "t.csv:2: weight 0 must be positive",
            ),
            (
                "angle_deg,L,a,b\n0,120,0,0\n",
                "t.csv:2: L 120 must lie in 0–100",
            ),
            (
                "angle_deg,R,G,B\n0,1,1\n",
                "t.csv:2: 3 fields where the header has 4",
            ),
        ] {
            let e = parse_targets(p, text, &c).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
