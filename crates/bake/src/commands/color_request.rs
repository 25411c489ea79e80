//! `nacre color` (and the methods of `nacre plot`) from the command line's values: the
//! method checked against the stack, its roughness and the tables it reads, the colour
//! settings (the table's where a table fixes them), the points, and the evaluation. The
//! methods themselves are [`crate::commands::color`].

use crate::commands::color::{self, LoadedLut, Method, Point, Quantity};
use crate::commands::grid::parse_range;
use crate::error::{Error, Param, Result};
use nacre_format::fourier::FourierTable;
use nacre_format::msg;
use nacre_format::{Manifest, set};
use nacre_optics::colour::Colorimeter;
use nacre_optics::{Stack, Undersampled};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Default incidence angles of `nacre color`, degrees.
pub const DEFAULT_ANGLES: &str = "0:89:1";

/// True when `text` (a `--method`) asks for the baked `fourier` table (`fourier`,
/// `fourier:…`; not `fourier-exact…`).
pub fn wants_baked_fourier(text: &str) -> bool {
    let t = text.trim();
    t == "fourier" || t.starts_with("fourier:")
}

/// The colour settings as given (`--observer`, `--illuminant`, `--space`); `None` takes the
/// table's, else 1931, d65, srgb.
#[derive(Clone, Copy, Debug, Default)]
pub struct ColourSettings<'a> {
    /// CIE observer.
    pub observer: Option<&'a str>,
    /// Illuminant.
    pub illuminant: Option<&'a str>,
    /// Output space.
    pub space: Option<&'a str>,
}

/// The colorimeter of `settings` (1931, d65 and srgb where `None`). Errors: an unknown
/// observer, illuminant or space, naming its parameter.
pub fn colorimeter(settings: &ColourSettings) -> Result<Colorimeter> {
    fn flag_err(flag: Param, v: &str) -> impl FnOnce(nacre_optics::Error) -> Error {
        let v = v.to_string();
        move |e| Error::value(flag, v, e.to_string())
    }
    let o = settings.observer.unwrap_or("1931");
    let i = settings.illuminant.unwrap_or("d65");
    let s = settings.space.unwrap_or("srgb");
    Ok(Colorimeter::new(
        o.parse().map_err(flag_err(Param::Observer, o))?,
        i.parse().map_err(flag_err(Param::Illuminant, i))?,
        s.parse().map_err(flag_err(Param::Space, s))?,
    ))
}

/// A `nacre color` method with everything it needs, as given on the command line.
#[derive(Clone, Copy, Debug)]
pub struct ColorRequest<'a> {
    /// `--method`.
    pub method: &'a str,
    /// `--roughness`.
    pub roughness: Option<f64>,
    /// `--observer`, `--illuminant`, `--space`.
    pub colour: ColourSettings<'a>,
    /// `--fourier-table`.
    pub fourier_table: Option<&'a str>,
}

/// A method ready to evaluate: tables loaded and checked, roughness set, colour settings
/// resolved.
pub struct Prepared {
    /// The method.
    pub method: Method,
    /// The `lut:` table.
    pub lut: Option<LoadedLut>,
    /// The colour settings.
    pub colorimeter: Colorimeter,
}

/// The incidence angles `text` (a range, [`DEFAULT_ANGLES`] when `None`) as points that keep
/// the stack's film.
pub fn angle_points(text: Option<String>) -> Result<Vec<Point>> {
    let text = text.unwrap_or_else(|| DEFAULT_ANGLES.into());
    let angles = parse_range(Param::Angles, &text)?;
    if let Some(a) = angles.iter().find(|a| !(a.abs() < 90.0)) {
        return Err(Error::Angle {
            origin: Param::Angles.into(),
            value: text,
            angle: *a,
        });
    }
    Ok(angles
        .into_iter()
        .map(|angle_deg| Point {
            angle_deg,
            thickness_nm: None,
            film_ior: None,
        })
        .collect())
}

/// Reads a points CSV ([`color::parse_points`]).
pub fn read_points(path: &Path) -> Result<Vec<Point>> {
    let text = std::fs::read_to_string(path).map_err(|source| nacre_format::Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    color::parse_points(path, &text)
}

/// Prepares `method` (parsed from `req.method` by [`Method::parse`]) for `stack`:
/// `lut:`/`rough-lut:` tables loaded and checked against the stack and the colour settings,
/// the roughness checked, the `fourier:` table found.
pub fn prepare(stack: &Stack, method: Method, req: &ColorRequest) -> Result<Prepared> {
    let mut method = method;
    let given = [
        req.colour.observer.map(str::to_string),
        req.colour.illuminant.map(str::to_string),
        req.colour.space.map(str::to_string),
    ];
    match (method.is_rough(), req.roughness) {
        (true, Some(alpha)) => {
            if !(alpha > 0.0 && alpha <= 1.0) {
                return Err(Error::value(
                    Param::Roughness,
                    alpha.to_string(),
                    "GGX roughness α must lie in (0, 1]",
                ));
            }
            method = method.with_roughness(alpha);
        }
        (true, None) => {
            return Err(Error::value(
                Param::Method,
                req.method.to_string(),
                msg!["needs ", Param::Roughness.arg(), " (GGX α, 0 < α ≤ 1)"],
            ));
        }
        (false, Some(alpha)) => {
            return Err(Error::value(
                Param::Roughness,
                alpha.to_string(),
                msg![
                    "applies only to ",
                    Param::Method.given("rough-lut:NAME"),
                    " and rough-mc"
                ],
            ));
        }
        (false, None) => {}
    }
    // A method without slab physics says so before its table is checked against the stack.
    color::refuse_incoherent(stack, &method)?;
    let (lut, colorimeter) = match &method {
        Method::RoughLut { path, alpha, .. } => {
            let table = nacre_format::load::LoadedRoughLut::load(path)?;
            color::check_stack_matches(&table.manifest, path, stack, "rough-lut")?;
            let m = &table.manifest;
            for (flag, given, baked) in [
                (Param::Observer, &given[0], &m.observer),
                (Param::Illuminant, &given[1], &m.illuminant),
                (Param::Space, &given[2], &m.space),
            ] {
                if let Some(g) = given
                    && !g.eq_ignore_ascii_case(baked)
                {
                    return Err(Error::value(
                        flag,
                        g.clone(),
                        format!("table `{}` was baked for `{baked}`", m.name),
                    ));
                }
            }
            let a = &table.lut.axes;
            if !(*alpha >= a.alpha_min && *alpha <= a.alpha_max) {
                return Err(Error::value(
                    Param::Roughness,
                    alpha.to_string(),
                    format!(
                        "table `{}` covers GGX α {} to {}",
                        m.name, a.alpha_min, a.alpha_max
                    ),
                ));
            }
            let c = table.colorimeter.clone();
            method = Method::RoughLut {
                path: path.clone(),
                alpha: *alpha,
                table: Some(Arc::new(table)),
            };
            (None, c)
        }
        Method::Lut(path) => {
            let lut = LoadedLut::load(path)?;
            lut.check_stack(path, stack)?;
            let m = &lut.manifest;
            for (flag, given, table) in [
                (Param::Observer, &given[0], &m.observer),
                (Param::Illuminant, &given[1], &m.illuminant),
                (Param::Space, &given[2], &m.space),
            ] {
                if let Some(g) = given
                    && !g.eq_ignore_ascii_case(table)
                {
                    return Err(Error::value(
                        flag,
                        g.clone(),
                        format!("table `{}` was baked for `{table}`", m.name),
                    ));
                }
            }
            let c = lut.colorimeter.clone();
            (Some(lut), c)
        }
        _ => {
            let c = colorimeter(&req.colour)?;
            let s = req.colour.space.unwrap_or("srgb");
            if method == Method::Rgb3 && s == "xyz" {
                return Err(Error::value(
                    Param::Method,
                    "rgb3",
                    msg!["rgb3 gives RGB directly: choose an RGB ", Param::Space],
                ));
            }
            if let Method::Fourier(h, sigma, None) = &method
                && wants_baked_fourier(req.method)
            {
                let table = load_fourier_table(req.fourier_table, &c)?;
                method = Method::Fourier(*h, *sigma, Some(Arc::new(table)));
            }
            (None, c)
        }
    };
    Ok(Prepared {
        method,
        lut,
        colorimeter,
    })
}

/// The colours of a prepared method.
pub struct Colours {
    /// Output-space colour per point.
    pub colours: Vec<[f64; 3]>,
    /// The Monte Carlo reference's samples per point and largest standard error per
    /// channel (`rough-mc` only).
    pub monte_carlo: Option<(usize, f64)>,
    /// The coherent films whose fringes the method's wavelength sampling cannot follow
    /// ([`color::undersampled`]): warnings for the user, one per film.
    pub undersampled: Vec<Undersampled>,
}

/// Evaluates `prepared` at every point.
pub fn compute(
    stack: &Stack,
    points: &[Point],
    prepared: &Prepared,
    quantity: Quantity,
) -> Result<Colours> {
    let undersampled = color::undersampled(stack, points, &prepared.method, &prepared.colorimeter);
    Ok(match &prepared.method {
        // The Monte Carlo reference reports its noise: the largest standard error.
        Method::RoughMonteCarlo { alpha, samples } => {
            let estimates = color::rough_monte_carlo(
                stack,
                points,
                *alpha,
                *samples,
                &prepared.colorimeter,
                quantity,
            )?;
            let worst = estimates
                .iter()
                .flat_map(|e| e.standard_error)
                .fold(0.0f64, f64::max);
            Colours {
                colours: estimates.iter().map(|e| e.colour).collect(),
                monte_carlo: Some((*samples, worst)),
                undersampled,
            }
        }
        _ => Colours {
            colours: color::evaluate(
                stack,
                points,
                &prepared.method,
                &prepared.colorimeter,
                quantity,
                prepared.lut.as_ref(),
            )?,
            monte_carlo: None,
            undersampled,
        },
    })
}

/// A method of `nacre plot` ready to evaluate: `lut:` tables loaded and checked against the
/// stack, `fourier:` with the baked table (as `nacre color`).
pub fn prepare_method(
    text: &str,
    stack: &Stack,
    colorimeter: &Colorimeter,
    fourier_table: Option<&str>,
) -> Result<(Method, Option<LoadedLut>)> {
    let method = Method::parse(text)?;
    match method {
        Method::Lut(ref path) => {
            let lut = LoadedLut::load(path)?;
            lut.check_stack(path, stack)?;
            Ok((method, Some(lut)))
        }
        Method::Fourier(h, sigma, None) if wants_baked_fourier(text) => {
            let table = load_fourier_table(fourier_table, colorimeter)?;
            Ok((Method::Fourier(h, sigma, Some(Arc::new(table))), None))
        }
        m => Ok((m, None)),
    }
}

/// The `fourier` table named by `--fourier-table`, or the default-set one baked for the same
/// observer, illuminant and space as `colorimeter`.
pub fn load_fourier_table(given: Option<&str>, colorimeter: &Colorimeter) -> Result<FourierTable> {
    let settings = (
        colorimeter.observer().to_string(),
        colorimeter.illuminant().to_string(),
        colorimeter.space().to_string(),
    );
    let path = match given {
        Some(name) => set::resolve_table(name),
        None => {
            let dir = set::default_baked_dir();
            let mut found = None;
            if let Ok(entries) = std::fs::read_dir(&dir) {
                let mut paths: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "json"))
                    .collect();
                paths.sort();
                for p in paths {
                    if let Ok(m) = Manifest::read(&p)
                        && m.kind == nacre_format::TableKind::FOURIER
                        && (m.observer.clone(), m.illuminant.clone(), m.space.clone()) == settings
                    {
                        found = Some(p);
                        break;
                    }
                }
            }
            found.ok_or_else(|| Error::invalid(Param::Method.given("fourier"), msg![format!(
                    "no fourier table for observer {}, illuminant {}, space {} in {}: bake one (kind = \"fourier\") and pass ",
                    settings.0,
                    settings.1,
                    settings.2,
                    dir.display()
                ), Param::FourierTable, ", or use fourier-exact:"]))?
        }
    };
    let manifest = Manifest::read(&path)?;
    if (
        manifest.observer.clone(),
        manifest.illuminant.clone(),
        manifest.space.clone(),
    ) != settings
    {
        return Err(Error::invalid(
            Param::FourierTable.given(path.display().to_string()),
            format!(
                "the table was baked for observer {}, illuminant {}, space {}; this run uses {}, {}, {}",
                manifest.observer,
                manifest.illuminant,
                manifest.space,
                settings.0,
                settings.1,
                settings.2
            ),
        ));
    }
    Ok(manifest.load_fourier(&path)?)
}
