//! The `--points` file of `nacre color` and `nacre plot`: one [`Point`] per row (incidence
//! angle, film thickness and index), checked ([`Point::check`]) and read ([`parse_points`]).

use super::MAX_POINTS;
use crate::error::{Error, Result};
use std::path::Path;

/// One point: incidence angle, and optionally the first film's thickness and real index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Incidence angle in the ambient, degrees.
    pub angle_deg: f64,
    /// First film's thickness, nm (None: the stack's own).
    pub thickness_nm: Option<f64>,
    /// First film's real index (None: the stack's own material).
    pub film_ior: Option<f64>,
}

/// Which value of a [`Point`] is unacceptable, and why ([`Point::check`]); displays as
/// `COLUMN VALUE REQUIREMENT` (`film_ior -1 must be finite and positive`).
#[derive(Clone, Debug, PartialEq)]
pub struct PointProblem {
    /// The column that names the value: `angle_deg`, `thickness_nm` or `film_ior`.
    pub column: &'static str,
    /// The value.
    pub value: f64,
    /// What it must be.
    pub requirement: &'static str,
}

impl std::fmt::Display for PointProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {} {}", self.column, self.value, self.requirement)
    }
}

impl Point {
    /// Checks the values every method needs: the angle strictly between −90° and 90°, a
    /// given thickness finite and non-negative, a given film index finite and positive.
    pub fn check(&self) -> std::result::Result<(), PointProblem> {
        let a = self.angle_deg;
        if !(a.abs() < 90.0) {
            return Err(PointProblem {
                column: "angle_deg",
                value: a,
                requirement: "must lie strictly between -90 and 90",
            });
        }
        if let Some(d) = self.thickness_nm
            && !(d >= 0.0 && d.is_finite())
        {
            return Err(PointProblem {
                column: "thickness_nm",
                value: d,
                requirement: "must be finite and non-negative",
            });
        }
        if let Some(n) = self.film_ior
            && !(n > 0.0 && n.is_finite())
        {
            return Err(PointProblem {
                column: "film_ior",
                value: n,
                requirement: "must be finite and positive",
            });
        }
        Ok(())
    }
}

/// Reads `--points` CSV: header `angle_deg,thickness_nm,film_ior`, then rows. `#` comment
/// lines, blank lines, quoted fields, a UTF-8 BOM, CRLF and spaces around fields are
/// accepted (see [`nacre_optics::csv_rows`]).
pub fn parse_points(path: &Path, text: &str) -> Result<Vec<Point>> {
    let perr = |line: usize, message: String| Error::recipe(path.to_path_buf(), line, message);
    let mut out = Vec::new();
    let mut header = false;
    for row in crate::csv_text::rows(path, text) {
        let row = row?;
        let line = row.line;
        let f = &row.fields;
        if !header {
            if f != &["angle_deg", "thickness_nm", "film_ior"] {
                return Err(perr(
                    line,
                    format!(
                        "expected the header `angle_deg,thickness_nm,film_ior`, found `{}`",
                        crate::csv_text::line_text(text, line)
                    ),
                ));
            }
            header = true;
            continue;
        }
        if f.len() != 3 {
            return Err(perr(
                line,
                format!(
                    "expected 3 comma-separated numbers, found {} field(s)",
                    f.len()
                ),
            ));
        }
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| perr(line, format!("{what} `{s}` is not a finite number")))
        };
        let (a, d, n) = (
            num(&f[0], "angle_deg")?,
            num(&f[1], "thickness_nm")?,
            num(&f[2], "film_ior")?,
        );
        let point = Point {
            angle_deg: a,
            thickness_nm: Some(d),
            film_ior: Some(n),
        };
        point
            .check()
            .map_err(|problem| perr(line, problem.to_string()))?;
        out.push(point);
        if out.len() > MAX_POINTS {
            return Err(nacre_format::Error::TooLarge {
                what: format!("{}: points", path.display()).into(),
                count: out.len() as u64,
                limit: MAX_POINTS as u64,
            }
            .into());
        }
    }
    if !header {
        return Err(perr(
            0,
            "no header line `angle_deg,thickness_nm,film_ior` found".into(),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_files_accept_csv_conventions() {
        let path = Path::new("p.csv");
        // BOM, CRLF, comment and blank lines, quoted fields, spaces around fields.
        let text = "\u{feff}# points\r\n angle_deg , \"thickness_nm\",film_ior\r\n\r\n# a\r\n  10 , \"250.5\" , 1.33 \r\n\"20\",300,1.5";
        let points = parse_points(path, text).unwrap();
        assert_eq!(
            points,
            vec![
                Point {
                    angle_deg: 10.0,
                    thickness_nm: Some(250.5),
                    film_ior: Some(1.33)
                },
                Point {
                    angle_deg: 20.0,
                    thickness_nm: Some(300.0),
                    film_ior: Some(1.5)
                },
            ]
        );
    }

    #[test]
    fn points_errors_name_file_and_line() {
        let path = Path::new("p.csv");
        let header = "angle_deg,thickness_nm,film_ior";
        for (text, start) in [
            ("# c\n\nangle, d\n".to_string(), "p.csv:3: "),
            (
                format!("# c\r\n{header}\r\n# x\r\n\r\n10,x,1.5\r\n"),
                "p.csv:5: ",
            ),
            (format!("{header}\n\n10,200\n"), "p.csv:3: "),
            (format!("# a\n# b\n{header}\n95,200,1.5\n"), "p.csv:4: "),
            ("# only\n".to_string(), "p.csv:0: "),
        ] {
            let e = parse_points(path, &text).unwrap_err().to_string();
            assert!(e.starts_with(start), "{e}");
        }
        let e = parse_points(path, "# c\n\nangle, d\n")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("found `angle, d`"), "{e}");
    }
}
