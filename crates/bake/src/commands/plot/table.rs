//! Pictures of baked tables: `film-lut` slices ([`FilmLutPlot`]) and `fourier` envelopes ([`FourierPlot`]).

use super::*;
use nacre_optics::elementary;

/// Slices of a `film-lut` table at fixed film indices: for each, an image over cos θ (x,
/// 0 = grazing to 1 = normal incidence) × optical path difference Δ (y, 0 to Δ_max) of
/// the colour the table gives — looked up exactly as a GPU samples it
/// ([`FilmLut::lookup`], at thickness Δ / (2 q(n, θ))) — as sRGB (module colour
/// conventions). A dashed line marks Δ = 2 d_max q(n, θ), the largest path difference of
/// the thickness range at that index; the table holds the whole Δ range for every index.
#[derive(Clone, Debug)]
pub struct FilmLutPlot {
    /// Title.
    pub title: String,
    /// The table's axes.
    pub axes: FilmLutAxes,
    /// The quantity's table (reflectance or transmittance).
    pub table: Table3,
    /// Film indices of the slices.
    pub film_iors: Vec<f64>,
    /// Table colours to linear sRGB.
    pub display: DisplayConverter,
    /// Factor applied to the linear colour before clipping.
    pub exposure: f64,
}

impl Figure for FilmLutPlot {
    fn size(&self) -> (u32, u32) {
        ((110 + 300 * self.film_iors.len() as u32).max(640), 960)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 16))?;
        let panels = area.split_evenly((1, self.film_iors.len()));
        let a = &self.axes;
        let opd_max = a.opd_max_nm();
        let (nx, ny) = if format.fine() {
            (120, (2 * a.opd_count).min(800))
        } else {
            (32, a.opd_count.min(150))
        };
        for (k, (panel, &n)) in panels.iter().zip(&self.film_iors).enumerate() {
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("film index n = {}", fmt_tick(&n)),
                    ("sans-serif", 16),
                )
                .margin(8)
                .x_label_area_size(44)
                .y_label_area_size(if k == 0 { 70 } else { 50 })
                .build_cartesian_2d(0.0..1.0, 0.0..opd_max)?;
            let mut mesh = chart.configure_mesh();
            mesh.disable_mesh()
                .x_desc("cos θ")
                .x_label_formatter(&fmt_tick)
                .y_label_formatter(&fmt_tick)
                .x_labels(6)
                .y_labels(12)
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 15));
            if k == 0 {
                mesh.y_desc("optical path difference Δ (nm)");
            }
            mesh.draw()?;
            let mut cells = Vec::with_capacity(nx * ny);
            for i in 0..nx {
                let (c0, c1) = (i as f64 / nx as f64, (i + 1) as f64 / nx as f64);
                let cos_theta = (0.5 * (c0 + c1)).max(MIN_COS_THETA);
                let q = a.film_q(cos_theta, n);
                for j in 0..ny {
                    let (o0, o1) = (
                        j as f64 / ny as f64 * opd_max,
                        (j + 1) as f64 / ny as f64 * opd_max,
                    );
                    let opd = 0.5 * (o0 + o1);
                    let d = if q > 0.0 { opd / (2.0 * q) } else { 0.0 };
                    let c = FilmLut::lookup(a, &self.table, cos_theta, d, n);
                    let rgb = self.display.linear_srgb(c).map(|v| v * self.exposure);
                    cells.push(Rectangle::new([(c0, o0), (c1, o1)], srgb8(rgb).filled()));
                }
            }
            chart.draw_series(cells)?;
            let limit: Vec<Option<(f64, f64)>> = (0..=100)
                .map(|i| {
                    let c = (f64::from(i) / 100.0).max(MIN_COS_THETA);
                    Some((c, 2.0 * a.thickness_max_nm * a.film_q(c, n)))
                })
                .collect();
            draw_line(
                &mut chart,
                &limit,
                [0.0, 1.0, 0.0, opd_max],
                Line {
                    colour: WHITE,
                    width: 2,
                    dash: Dashed,
                },
                (k == 0).then(|| format!("Δ at d = {} nm", a.thickness_max_nm)),
            )?;
            if k == 0 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(BLACK.mix(0.6))
                    .border_style(WHITE.mix(0.6))
                    .label_font(("sans-serif", 13).into_font().color(&WHITE))
                    .draw()?;
            }
        }
        Ok(())
    }
}

/// A `fourier` table: for each channel (rows) the real and imaginary parts (columns) of
/// the stored, demodulated envelope A_j,k(μ) = Ŝ_j,σk(μ) e^{+2πiμν̄_j} against the optical
/// path difference μ, one line per mip level (dark: level 0, unfiltered; light: the
/// coarsest), over 0 to `max_opd_nm`.
#[derive(Clone, Debug)]
pub struct FourierPlot {
    /// Title.
    pub title: String,
    /// The table.
    pub table: FourierTable,
    /// Channel names (R, G, B or X, Y, Z).
    pub channels: [&'static str; 3],
    /// The μ range drawn, nm.
    pub max_opd_nm: f64,
}

impl FourierPlot {
    /// The μ below which the envelopes hold everything above 3 % of their peak, plus a
    /// half, rounded up to a round value (at least 1 µm, at most the table's range).
    pub fn auto_range(table: &FourierTable) -> f64 {
        let peak = table
            .levels
            .iter()
            .flatten()
            .flat_map(|a| a.iter().map(|&c| elementary::norm(c)))
            .fold(0.0, f64::max);
        let mut last = 0.0f64;
        for (level, &n) in table.levels.iter().zip(&table.axes.level_samples) {
            for (i, a) in level.iter().enumerate() {
                if a.iter().any(|&c| elementary::norm(c) > 0.03 * peak) {
                    last = last.max((i as f64 + 0.5) * table.axes.max_opd_nm / n as f64);
                }
            }
        }
        nice_ceiling((1.5 * last).max(1000.0)).min(table.axes.max_opd_nm)
    }
}

impl Figure for FourierPlot {
    fn size(&self) -> (u32, u32) {
        (1300, 1080)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let panels = area.split_evenly((3, 2));
        let t = &self.table;
        let levels = t.levels.len();
        let mu_max_um = self.max_opd_nm / 1000.0;
        for j in 0..3 {
            let bound = t
                .levels
                .iter()
                .zip(&t.axes.level_samples)
                .flat_map(|(level, &n)| {
                    level.iter().enumerate().filter_map(move |(i, a)| {
                        let mu = (i as f64 + 0.5) * t.axes.max_opd_nm / n as f64;
                        (mu <= self.max_opd_nm).then(|| a[j].re.abs().max(a[j].im.abs()))
                    })
                })
                .fold(0.0f64, f64::max);
            let y = nice_ceiling((bound * 1.05).max(1e-6));
            for (part, name) in ["Re", "Im"].iter().enumerate() {
                let panel = &panels[2 * j + part];
                let mut chart = ChartBuilder::on(panel)
                    .caption(
                        format!(
                            "{name} A_{} (channel {})",
                            self.channels[j], self.channels[j]
                        ),
                        ("sans-serif", 15),
                    )
                    .margin(8)
                    .margin_right(20)
                    .x_label_area_size(40)
                    .y_label_area_size(64)
                    .build_cartesian_2d(0.0..mu_max_um, -y..y)?;
                chart
                    .configure_mesh()
                    .x_desc("optical path difference μ (µm)")
                    .x_label_formatter(&fmt_tick)
                    .y_label_formatter(&fmt_tick)
                    .label_style(("sans-serif", 13))
                    .axis_desc_style(("sans-serif", 14))
                    .bold_line_style(BLACK.mix(0.12))
                    .light_line_style(BLACK.mix(0.03))
                    .draw()?;
                for (k, (level, &n)) in t.levels.iter().zip(&t.axes.level_samples).enumerate() {
                    let points: Vec<Option<(f64, f64)>> = level
                        .iter()
                        .enumerate()
                        .map(|(i, a)| {
                            let mu = (i as f64 + 0.5) * t.axes.max_opd_nm / n as f64;
                            (mu <= self.max_opd_nm * 1.01)
                                .then(|| (mu / 1000.0, if part == 0 { a[j].re } else { a[j].im }))
                        })
                        .take_while(Option::is_some)
                        .collect();
                    let sigma = t.axes.level_sigma_nm[k];
                    let label = (j == 0 && part == 0).then(|| {
                        format!(
                            "level {k}: {n} texels, σ = {}",
                            if sigma == 0.0 {
                                "0".to_string()
                            } else {
                                format!("{sigma:.0} nm")
                            }
                        )
                    });
                    draw_line(
                        &mut chart,
                        &points,
                        [0.0, mu_max_um, -y, y],
                        Line {
                            colour: ramp(k as f64 / (levels.max(2) - 1) as f64),
                            width: if k == 0 { 2 } else { 1 },
                            dash: Solid,
                        },
                        label,
                    )?;
                }
                if j == 0 && part == 0 {
                    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 12)?;
                }
            }
        }
        Ok(())
    }
}

/// A baked table as a figure: [`FilmLutPlot`] or [`FourierPlot`] by its kind.
#[derive(Clone, Debug)]
pub enum TablePlot {
    /// A `film-lut` table.
    FilmLut(Box<FilmLutPlot>),
    /// A `fourier` table.
    Fourier(Box<FourierPlot>),
}

impl Figure for TablePlot {
    fn size(&self) -> (u32, u32) {
        match self {
            TablePlot::FilmLut(p) => p.size(),
            TablePlot::Fourier(p) => p.size(),
        }
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB> {
        match self {
            TablePlot::FilmLut(p) => p.draw(root, format),
            TablePlot::Fourier(p) => p.draw(root, format),
        }
    }
}

/// What to draw of a table: [`load_table_plot`]'s options.
#[derive(Clone, Debug)]
pub struct TableOptions {
    /// film-lut: reflectance or transmittance.
    pub quantity: Quantity,
    /// film-lut: film indices of the slices [default: n_min + (n_max − n_min) k/4 for
    /// k = 1…4, or the table's single index].
    pub film_iors: Option<Vec<f64>>,
    /// film-lut: factor applied to the linear colour before clipping.
    pub exposure: f64,
    /// fourier: the μ range, nm [default: [`FourierPlot::auto_range`]].
    pub max_opd_nm: Option<f64>,
}

/// The names of the default-set tables (manifests in the default `tables/baked/`).
pub fn default_table_names() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(default_baked_dir())
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Loads the table `name_or_path` (a default-set name or a manifest path) as a figure.
pub fn load_table_plot(name_or_path: &str, options: &TableOptions) -> Result<TablePlot> {
    let path = resolve_table(name_or_path);
    if !path.is_file() {
        return Err(Error::value(
            "TABLE",
            name_or_path,
            format!(
                "no such table ({} does not exist): expected a default-set table ({}) or the path to a table manifest (.json)",
                path.display(),
                default_table_names().join(", ")
            ),
        ));
    }
    let manifest = Manifest::read(&path)?;
    if manifest.fourier().is_some() {
        let table = manifest.load_fourier(&path)?;
        let colorimeter = manifest.colorimeter(&path)?;
        let max_opd_nm = match options.max_opd_nm {
            Some(v) if v > 0.0 && v.is_finite() => v.min(table.axes.max_opd_nm),
            Some(v) => {
                return Err(Error::value(
                    Param::MaxOpd,
                    format!("{v}"),
                    "must be a positive number of nanometres",
                ));
            }
            None => FourierPlot::auto_range(&table),
        };
        return Ok(TablePlot::Fourier(Box::new(FourierPlot {
            title: format!(
                "{}: demodulated envelopes of the {} sensitivities' Fourier transforms (observer {}, illuminant {})",
                manifest.name, manifest.space, manifest.observer, manifest.illuminant
            ),
            channels: colorimeter.space().channel_names(),
            table,
            max_opd_nm,
        })));
    }
    let lut = LoadedLut::load(&path)?;
    let axes = lut
        .manifest
        .film_lut()
        .cloned()
        .expect("checked by LoadedLut");
    let (table, what) = match options.quantity {
        Quantity::Reflectance => (lut.reflectance, "reflectance"),
        Quantity::Transmittance => (
            lut.transmittance.ok_or_else(|| {
                Error::value(
                    Param::Quantity,
                    "t",
                    format!("table `{}` holds no transmittance", manifest.name),
                )
            })?,
            "transmittance",
        ),
    };
    let film_iors = match &options.film_iors {
        Some(v) => {
            if let Some(n) = v
                .iter()
                .find(|n| !(**n >= axes.ior_min - 1e-9 && **n <= axes.ior_max + 1e-9))
            {
                return Err(Error::value(
                    Param::FilmIors,
                    format!("{n}"),
                    format!(
                        "outside the table's film index range {}–{}",
                        axes.ior_min, axes.ior_max
                    ),
                ));
            }
            v.clone()
        }
        None if axes.ior_count <= 1 || axes.ior_max <= axes.ior_min => vec![axes.ior_min],
        // n_min is often the ambient's index (no film at all): start a quarter in.
        None => (1..=4)
            .map(|k| axes.ior_min + (axes.ior_max - axes.ior_min) * f64::from(k) / 4.0)
            .collect(),
    };
    if film_iors.is_empty() || film_iors.len() > MAX_SLICES {
        return Err(Error::value(
            Param::FilmIors,
            summarise(&film_iors),
            format!("expected 1 to {MAX_SLICES} film indices"),
        ));
    }
    let under: String = manifest
        .under
        .iter()
        .enumerate()
        .map(|(j, (m, d))| {
            let slab = if manifest.under_incoherent.get(j) == Some(&true) {
                " (incoherent)"
            } else {
                ""
            };
            format!(" | {m} {d} nm{slab}")
        })
        .collect();
    let exposure = if options.exposure == 1.0 {
        String::new()
    } else {
        format!(", exposure ×{}", options.exposure)
    };
    Ok(TablePlot::FilmLut(Box::new(FilmLutPlot {
        title: format!(
            "{}: {what} colour of {} | film | {}{under} as the GPU samples it; sRGB, clipped{exposure}",
            manifest.name, manifest.ambient, manifest.base
        ),
        display: DisplayConverter::new(&lut.colorimeter),
        axes,
        table,
        film_iors,
        exposure: options.exposure,
    })))
}
