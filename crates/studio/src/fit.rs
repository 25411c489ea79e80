//! The fit panel's work, off the UI thread: the colour design (`nacre fit color`'s
//! [`design_watched`]) for target colours per angle, and the fit of a measured spectrum
//! (`nacre fit spectrum`'s [`fit_one`]), both over the free parameters the panel sets on the
//! current stack ([`template`]), each on its own thread ([`FitJob`]) with its progress
//! (steps done of steps) and a cancel flag ([`nacre_optics::fit::Watch`]). A cancelled fit
//! returns nothing; nothing here touches the stack: the panel applies a solution
//! ([`doc_at`]) as one undo step.
//!
//! Target colours are 8-bit sRGB (a colour picker, a hex code or a pixel of an image),
//! decoded to linear sRGB (IEC 61966-2-1) and read as `nacre fit color`'s `R,G,B` columns
//! ([`target_row`], CIE 1931 2°, D65, sRGB: the CLI's default colorimeter).

pub use crate::compare::{linear_to_srgb, srgb_to_linear};
use crate::doc::StackDoc;
use nacre_bake::commands::color_request::{ColourSettings as ColourFlags, colorimeter};
use nacre_bake::commands::fit_color::{Design, Given, TargetRow, design_watched, target_row};
use nacre_bake::commands::fit_spectrum::{Outcome, Request, Spectrum, fit_one, warnings};
use nacre_bake::commands::fit_template::FitTemplate;
use nacre_bake::commands::stack_spec::{FreeSpec, TemplateSpec};
use nacre_optics::colour::Colorimeter;
use nacre_optics::fit::{ColourSettings, Free, FreeKind, Quantity, Settings, Watch};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;
use std::time::Instant;

/// One film's free parameters: its thickness and its (constant, real) index, each free or
/// not, with bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeFilm {
    /// Whether the thickness is free.
    pub thickness_free: bool,
    /// The thickness bounds, nm.
    pub thickness_nm: [f64; 2],
    /// Whether the index is free (the film becomes a constant real index).
    pub index_free: bool,
    /// The index bounds.
    pub index: [f64; 2],
}

/// The thickness range of a film with no thickness yet, nm.
pub const DEFAULT_RANGE_NM: [f64; 2] = [10.0, 1000.0];

/// The index range offered when a film's index is set free.
pub const DEFAULT_INDEX_RANGE: [f64; 2] = [1.3, 2.5];

impl FreeFilm {
    /// The default of a film `thickness_nm` thick: its thickness free over ±50 %
    /// ([`DEFAULT_RANGE_NM`] when it is 0), its index fixed.
    pub fn for_film(thickness_nm: f64) -> FreeFilm {
        let range = if thickness_nm > 0.0 {
            [round2(0.5 * thickness_nm), round2(1.5 * thickness_nm)]
        } else {
            DEFAULT_RANGE_NM
        };
        FreeFilm {
            thickness_free: true,
            thickness_nm: range,
            index_free: false,
            index: DEFAULT_INDEX_RANGE,
        }
    }
}

fn round2(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

/// The fit template of `doc` with film j's parameters free as `free[j]` says. Errors name
/// the field: an inverted or negative range, free settings for another number of films,
/// nothing free, or what the stack refuses.
pub fn template(doc: &StackDoc, free: &[FreeFilm]) -> Result<FitTemplate, String> {
    if free.len() != doc.films.len() {
        return Err(format!(
            "free parameters for {} films, the stack has {}",
            free.len(),
            doc.films.len()
        ));
    }
    let mut specs = Vec::new();
    for (j, f) in free.iter().enumerate() {
        let n = j + 1;
        if f.index_free {
            let [lo, hi] = f.index;
            check_range(&format!("film {n} index range"), lo, hi, "")?;
            if lo <= 0.0 {
                return Err(format!(
                    "film {n} index range: the minimum {lo} must be positive"
                ));
            }
            specs.push(free_spec(n, FreeKind::Index, lo, hi, "index"));
        }
        if f.thickness_free {
            let [lo, hi] = f.thickness_nm;
            check_range(&format!("film {n} thickness range"), lo, hi, " nm")?;
            if lo < 0.0 {
                return Err(format!(
                    "film {n} thickness range: the minimum {lo} nm is negative"
                ));
            }
            specs.push(free_spec(n, FreeKind::ThicknessNm, lo, hi, "thickness"));
        }
    }
    if specs.is_empty() {
        return Err("nothing is free: tick a film's thickness or index".into());
    }
    doc.build().map_err(|e| e.to_string())?;
    FitTemplate::build(TemplateSpec {
        stack: doc.spec(),
        free: specs,
        angles: None,
        wavelengths: None,
    })
    .map_err(|e| e.to_string())
}

fn check_range(what: &str, lo: f64, hi: f64, unit: &str) -> Result<(), String> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(format!(
            "{what} {lo}–{hi}{unit}: both bounds must be numbers"
        ));
    }
    if lo > hi {
        return Err(format!(
            "{what} {lo}–{hi}{unit} is inverted: the minimum comes first"
        ));
    }
    Ok(())
}

fn free_spec(layer: usize, kind: FreeKind, lo: f64, hi: f64, what: &str) -> FreeSpec {
    FreeSpec {
        free: Free {
            layer,
            kind,
            lo,
            hi,
        },
        origin: format!("studio fit film {layer} {what} range").into(),
    }
}

/// `doc` with `template`'s free parameters at `x`: thicknesses in nm, a free index as the
/// film's material (a constant real index, as `nacre fit` writes it).
pub fn doc_at(doc: &StackDoc, template: &FitTemplate, x: &[f64]) -> StackDoc {
    let mut d = doc.clone();
    for (f, &v) in template.free().iter().zip(x) {
        let film = &mut d.films[f.layer - 1];
        match f.kind {
            FreeKind::ThicknessNm => film.thickness_nm = v,
            FreeKind::Index => film.material = format!("{v}"),
        }
    }
    d
}

/// A free parameter's name and value: `film 1 212.4 nm`, `film 2 n 1.4523`.
pub fn describe_value(free: &Free, v: f64) -> String {
    match free.kind {
        FreeKind::ThicknessNm => format!("film {} {v:.1} nm", free.layer),
        FreeKind::Index => format!("film {} n {v:.4}", free.layer),
    }
}

/// The colorimeter of the colour targets: the CLI's default (CIE 1931 2°, D65, sRGB).
pub fn studio_colorimeter() -> Colorimeter {
    colorimeter(&ColourFlags::default()).expect("the default colorimeter exists")
}

/// A colour target as the panel holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetEntry {
    /// Incidence angle, degrees.
    pub angle_deg: f64,
    /// The colour, 8-bit sRGB.
    pub srgb: [u8; 3],
    /// Weight (> 0).
    pub weight: f64,
}

/// The target rows of `entries` (row k is target k + 1 in messages).
pub fn target_rows(
    entries: &[TargetEntry],
    colorimeter: &Colorimeter,
) -> Result<Vec<TargetRow>, String> {
    if entries.is_empty() {
        return Err("no colour target: add a target row".into());
    }
    entries
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let linear = t.srgb.map(srgb_to_linear);
            target_row(
                k + 1,
                t.angle_deg,
                Given::Rgb,
                linear,
                t.weight,
                colorimeter,
            )
            .map_err(|bad| format!("target {}: {bad}", k + 1))
        })
        .collect()
}

/// A finished colour design.
#[derive(Clone, Debug)]
pub struct ColourResult {
    /// The stack it designed (its free values are placeholders).
    pub doc: StackDoc,
    /// The template.
    pub template: FitTemplate,
    /// The targets.
    pub rows: Vec<TargetRow>,
    /// The solutions, best first.
    pub design: Design,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl ColourResult {
    /// Solution `k`'s stack.
    pub fn doc(&self, k: usize) -> StackDoc {
        doc_at(&self.doc, &self.template, &self.design.solutions[k].x)
    }
}

/// A finished spectrum fit.
#[derive(Clone, Debug)]
pub struct SpectrumResult {
    /// The stack it fitted (its free values are placeholders).
    pub doc: StackDoc,
    /// The template.
    pub template: FitTemplate,
    /// The fit: the points, the fitted values, the parameters and their σ.
    pub outcome: Outcome,
    /// `nacre fit spectrum`'s warnings (a bound reached, too few fringes, ambiguity).
    pub warnings: Vec<String>,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl SpectrumResult {
    /// The fitted stack (thicknesses to 0.001 nm, indices to 10⁻⁵).
    pub fn fitted_doc(&self) -> StackDoc {
        let x: Vec<f64> = self
            .template
            .free()
            .iter()
            .zip(&self.outcome.fit.x)
            .map(|(f, &v)| match f.kind {
                FreeKind::ThicknessNm => (v * 1e3).round() / 1e3,
                FreeKind::Index => (v * 1e5).round() / 1e5,
            })
            .collect();
        doc_at(&self.doc, &self.template, &x)
    }
}

/// What a fit gives.
#[derive(Clone, Debug)]
pub enum FitResult {
    /// A colour design.
    Colour(Box<ColourResult>),
    /// A spectrum fit.
    Spectrum(Box<SpectrumResult>),
}

/// How a fit ended.
#[derive(Clone, Debug)]
pub enum FitOutcome {
    /// Finished.
    Done(FitResult),
    /// Cancelled: nothing to show.
    Cancelled,
    /// Failed: why.
    Failed(String),
}

/// A measured spectrum file's spectra (`nacre fit spectrum`'s reader: a CSV file with
/// `wavelength_nm` and `R` or `T`, optionally `angle_deg` and `sigma`, or a folder of them).
pub fn load_spectra(path: &Path) -> Result<Vec<Spectrum>, String> {
    if path.as_os_str().is_empty() {
        return Err("the spectrum file is empty: name a file".into());
    }
    nacre_bake::commands::fit_spectrum::read_spectra(path, None).map_err(|e| e.to_string())
}

/// A fit running on its own thread.
pub struct FitJob {
    done: Arc<AtomicUsize>,
    total: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<FitResult, String>>>,
    /// "colour design" or "spectrum fit".
    pub what: &'static str,
}

impl FitJob {
    /// Starts designing `doc`'s free parameters for `targets` (errors come back at once:
    /// the template's, the targets').
    pub fn colour(
        doc: &StackDoc,
        free: &[FreeFilm],
        targets: &[TargetEntry],
        quantity: Quantity,
        solutions: usize,
    ) -> Result<FitJob, String> {
        let template = template(doc, free)?;
        let colorimeter = studio_colorimeter();
        let rows = target_rows(targets, &colorimeter)?;
        let settings = ColourSettings {
            quantity,
            solutions: solutions.clamp(1, 100),
            ..ColourSettings::default()
        };
        let doc = doc.clone();
        Self::spawn("colour design", move |watch| {
            let start = Instant::now();
            let design = design_watched(&template, &rows, &colorimeter, &settings, watch)
                .map_err(|e| e.to_string())?;
            Ok(FitResult::Colour(Box::new(ColourResult {
                doc,
                template,
                rows,
                design,
                seconds: start.elapsed().as_secs_f64(),
            })))
        })
    }

    /// Starts fitting `doc`'s free parameters to `spectrum` (`nacre fit spectrum`'s
    /// defaults: scale 1, offset 0, the Cauchy loss, 64 starts).
    pub fn spectrum(
        doc: &StackDoc,
        free: &[FreeFilm],
        spectrum: Spectrum,
    ) -> Result<FitJob, String> {
        let template = template(doc, free)?;
        let request = Request {
            settings: Settings::default(),
            window: None,
        };
        let doc = doc.clone();
        Self::spawn("spectrum fit", move |watch| {
            let start = Instant::now();
            let outcome =
                fit_one(&template, &spectrum, &request, watch).map_err(|e| e.to_string())?;
            Ok(FitResult::Spectrum(Box::new(SpectrumResult {
                warnings: warnings(&template, &outcome.fit),
                doc,
                template,
                outcome,
                seconds: start.elapsed().as_secs_f64(),
            })))
        })
    }

    fn spawn(
        what: &'static str,
        work: impl FnOnce(Watch<'_>) -> Result<FitResult, String> + Send + 'static,
    ) -> Result<FitJob, String> {
        let done = Arc::new(AtomicUsize::new(0));
        let total = Arc::new(AtomicUsize::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        // As the bake: a pool one core short of the machine's, so that the plots' worker
        // and the view are never queued behind the fit. The results do not depend on the
        // pool's size.
        let threads = std::thread::available_parallelism()
            .map_or(1, |n| n.get().saturating_sub(1))
            .max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|k| format!("nacre-studio fit {k}"))
            .build()
            .map_err(|e| format!("the fit threads did not start: {e}"))?;
        let thread = {
            let (done, total, cancel) =
                (Arc::clone(&done), Arc::clone(&total), Arc::clone(&cancel));
            std::thread::Builder::new()
                .name("nacre-studio fit".into())
                .spawn(move || {
                    let progress = |d: usize, t: usize| {
                        done.fetch_max(d, Ordering::Relaxed);
                        total.store(t, Ordering::Relaxed);
                    };
                    let watch = Watch {
                        progress: &progress,
                        cancel: &cancel,
                    };
                    pool.install(|| work(watch))
                })
                .map_err(|e| format!("the fit thread did not start: {e}"))?
        };
        Ok(FitJob {
            done,
            total,
            cancel,
            thread: Some(thread),
            what,
        })
    }

    /// Steps done and steps in all (0 of 0 until the fit has counted its work).
    pub fn progress(&self) -> (usize, usize) {
        let total = self.total.load(Ordering::Relaxed);
        (self.done.load(Ordering::Relaxed).min(total), total)
    }

    /// Asks the fit to stop (steps already running finish; nothing is returned).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether a cancel was asked.
    pub fn cancelling(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The outcome once the thread has finished (None while it runs). A fit cancelled
    /// is [`FitOutcome::Cancelled`] even when it finished before it saw the flag.
    pub fn poll(&mut self) -> Option<FitOutcome> {
        if !self.thread.as_ref()?.is_finished() {
            return None;
        }
        let thread = self.thread.take()?;
        Some(match thread.join() {
            _ if self.cancelling() => FitOutcome::Cancelled,
            Ok(Ok(result)) => FitOutcome::Done(result),
            Ok(Err(e)) => FitOutcome::Failed(e),
            Err(_) => FitOutcome::Failed(format!("the {} thread stopped unexpectedly", self.what)),
        })
    }
}

impl Drop for FitJob {
    /// A studio closed mid-fit stops the fit.
    fn drop(&mut self) {
        self.cancel();
    }
}

/// The box a sampled colour averages over: (2 r + 1)² pixels around the one clicked.
pub const SAMPLE_RADIUS_PX: u32 = 2;

/// An image to pick target colours from.
#[derive(Clone, Debug)]
pub struct SampleImage {
    /// Where it was read from.
    pub path: PathBuf,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// 8-bit sRGB RGBA, rows top first.
    pub rgba: Vec<u8>,
}

impl SampleImage {
    /// Reads a PNG or JPEG file.
    pub fn load(path: &Path) -> Result<SampleImage, String> {
        if path.as_os_str().is_empty() {
            return Err("the image file is empty: name a PNG or JPEG file".into());
        }
        let image = image::ImageReader::open(path)
            .and_then(|r| r.with_guessed_format())
            .map_err(|e| format!("{}: {e}", path.display()))?
            .decode()
            .map_err(|e| format!("{}: {e}", path.display()))?
            .to_rgba8();
        let (width, height) = image.dimensions();
        if width == 0 || height == 0 {
            return Err(format!("{}: the image is empty", path.display()));
        }
        Ok(SampleImage {
            path: path.to_path_buf(),
            width,
            height,
            rgba: image.into_raw(),
        })
    }

    /// The colour around pixel (x, y): the mean of the linear sRGB values over the
    /// (2 [`SAMPLE_RADIUS_PX`] + 1)² box (clipped to the image), encoded back to 8 bits.
    pub fn sample(&self, x: u32, y: u32) -> [u8; 3] {
        let r = SAMPLE_RADIUS_PX;
        let (x, y) = (x.min(self.width - 1), y.min(self.height - 1));
        let mut sum = [0.0; 3];
        let mut count = 0.0;
        for py in y.saturating_sub(r)..=(y + r).min(self.height - 1) {
            for px in x.saturating_sub(r)..=(x + r).min(self.width - 1) {
                let at = ((py * self.width + px) * 4) as usize;
                for (s, &v) in sum.iter_mut().zip(&self.rgba[at..at + 3]) {
                    *s += srgb_to_linear(v);
                }
                count += 1.0;
            }
        }
        sum.map(|s| linear_to_srgb(s / count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::doc::Film;

    fn two_films() -> StackDoc {
        StackDoc {
            ambient: "1.0".into(),
            films: vec![Film::new("tio2", 100.0), Film::new("1.46", 0.0)],
            substrate: "bk7".into(),
            base_dir: None,
        }
    }

    #[test]
    fn free_films_make_the_template_and_its_stacks() {
        let doc = two_films();
        let mut free = vec![FreeFilm::for_film(100.0), FreeFilm::for_film(0.0)];
        assert_eq!(free[0].thickness_nm, [50.0, 150.0]);
        assert_eq!(free[1].thickness_nm, DEFAULT_RANGE_NM);
        free[1].index_free = true;
        let t = template(&doc, &free).unwrap();
        // Film 1's thickness, film 2's index, film 2's thickness.
        let kinds: Vec<(usize, FreeKind)> = t.free().iter().map(|f| (f.layer, f.kind)).collect();
        assert_eq!(
            kinds,
            [
                (1, FreeKind::ThicknessNm),
                (2, FreeKind::Index),
                (2, FreeKind::ThicknessNm)
            ]
        );
        let d = doc_at(&doc, &t, &[120.5, 1.52, 333.0]);
        assert_eq!(d.films[0].thickness_nm, 120.5);
        assert_eq!(d.films[0].material, "tio2");
        assert_eq!(d.films[1].material, "1.52");
        assert_eq!(d.films[1].thickness_nm, 333.0);
        assert_eq!(d.substrate, "bk7");
        d.build().unwrap();
    }

    #[test]
    fn bad_free_settings_name_the_field() {
        let doc = two_films();
        let ok = FreeFilm::for_film(100.0);
        let with = |j: usize, f: FreeFilm| {
            let mut v = vec![ok.clone(), ok.clone()];
            v[j] = f;
            template(&doc, &v).unwrap_err()
        };
        let e = with(
            1,
            FreeFilm {
                thickness_nm: [300.0, 20.0],
                ..ok.clone()
            },
        );
        assert_eq!(
            e,
            "film 2 thickness range 300–20 nm is inverted: the minimum comes first"
        );
        let e = with(
            0,
            FreeFilm {
                thickness_nm: [-5.0, 20.0],
                ..ok.clone()
            },
        );
        assert!(
            e.contains("film 1 thickness range: the minimum -5 nm is negative"),
            "{e}"
        );
        let e = with(
            0,
            FreeFilm {
                index_free: true,
                index: [0.0, 2.0],
                ..ok.clone()
            },
        );
        assert!(
            e.contains("film 1 index range: the minimum 0 must be positive"),
            "{e}"
        );
        let none = FreeFilm {
            thickness_free: false,
            ..ok.clone()
        };
        let e = template(&doc, &[none.clone(), none]).unwrap_err();
        assert!(e.starts_with("nothing is free"), "{e}");
        let e = template(&doc, std::slice::from_ref(&ok)).unwrap_err();
        assert!(
            e.contains("free parameters for 1 films, the stack has 2"),
            "{e}"
        );
        let mut bad = doc.clone();
        bad.films[0].material = "unobtainium".into();
        assert!(template(&bad, &[ok.clone(), ok]).is_err());
    }

    #[test]
    fn a_sample_is_the_mean_in_linear_light_over_its_box() {
        // Columns alternate black and white: the 5 × 5 box round (2, 2) holds 3 white
        // columns of 5, clipped boxes fewer.
        let (width, height) = (8u32, 6u32);
        let mut rgba = Vec::new();
        for _ in 0..height {
            for x in 0..width {
                let v = if x % 2 == 0 { 255 } else { 0 };
                rgba.extend([v, v, v, 255]);
            }
        }
        let image = SampleImage {
            path: PathBuf::from("checks.png"),
            width,
            height,
            rgba,
        };
        let mean = |white: f64, all: f64| linear_to_srgb(white / all);
        assert_eq!(image.sample(2, 2), [mean(3.0, 5.0); 3]);
        // At the corner the box holds columns 0–2: two white of three.
        assert_eq!(image.sample(0, 0), [mean(2.0, 3.0); 3]);
        // Beyond the image: its last pixel's box (columns 5–7, one white).
        assert_eq!(image.sample(99, 99), [mean(1.0, 3.0); 3]);
        // The mean of black and white is 50 % linear (188), not 128.
        assert_eq!(mean(1.0, 2.0), 188);
        for v in [0u8, 1, 10, 60, 128, 200, 255] {
            assert_eq!(linear_to_srgb(srgb_to_linear(v)), v);
        }
        assert!(SampleImage::load(Path::new("")).is_err());
    }

    #[test]
    fn targets_need_a_row_and_good_values() {
        let c = studio_colorimeter();
        assert_eq!(
            target_rows(&[], &c).unwrap_err(),
            "no colour target: add a target row"
        );
        let t = |angle_deg: f64, weight: f64| TargetEntry {
            angle_deg,
            srgb: [200, 100, 50],
            weight,
        };
        let rows = target_rows(&[t(0.0, 1.0), t(45.0, 2.0)], &c).unwrap();
        assert_eq!(rows[1].line, 2);
        assert_eq!(rows[1].weight, 2.0);
        for k in 0..3 {
            assert_eq!(rows[0].colour[k], srgb_to_linear([200, 100, 50][k]));
        }
        assert_eq!(
            target_rows(&[t(0.0, 1.0), t(0.0, 0.0)], &c).unwrap_err(),
            "target 2: weight 0 must be positive"
        );
    }
}
