//! Tables load from their KTX2 files alone: manifests of `film-dielectric` and
//! `fourier-srgb` whose `files` list only the KTX2 files upload textures that give exactly
//! the probe results of the OpenEXR path, for every technique; a truncated or mislabelled
//! KTX2 file is an error, never a panic.
//!
//! A missing adapter fails these tests: they never skip.

use nacre_format::Manifest;
use nacre_format::set::default_baked_dir;
use nacre_optics::C64;
use nacre_runtime::bindings::{TechniqueBinding, TechniqueOptions};
use nacre_runtime::probe::run_probe;
use nacre_runtime::{FilmInput, TableSet, Technique};
use std::path::{Path, PathBuf};

mod support;
use support::{ctx, manifest};

/// Copies table `name` into `dir` with only its KTX2 files listed (and copied); returns
/// the new manifest's path.
fn ktx2_only(name: &str, dir: &Path) -> PathBuf {
    let path = manifest(name);
    let mut m = Manifest::read(&path).unwrap();
    m.files
        .retain(|f| f.format == nacre_format::FileFormat::Ktx2);
    assert!(!m.files.is_empty(), "{name} lists no KTX2 file");
    for f in &m.files {
        std::fs::copy(default_baked_dir().join(&f.path), dir.join(&f.path)).unwrap();
    }
    let copy = dir.join(format!("{name}.json"));
    std::fs::write(&copy, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    copy
}

/// Deterministic uniform numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn inputs() -> Vec<FilmInput> {
    let mut rng = Lcg(5);
    let bases = [C64::new(1.5, 0.0), C64::new(0.27, 2.9)];
    (0..2000)
        .map(|i| {
            let base = bases[i % 2];
            FilmInput {
                cos_theta_i: rng.next() as f32,
                thickness_nm: (rng.next() * 1300.0) as f32,
                film_ior: (1.0 + rng.next() * 1.6) as f32,
                sigma_thickness_nm: if i % 3 == 0 {
                    (rng.next() * 60.0) as f32
                } else {
                    0.0
                },
                ambient_ior: 1.0,
                base_ior: [base.re as f32; 3],
                base_kappa: [base.im as f32; 3],
                ..Default::default()
            }
        })
        .collect()
}

#[test]
fn ktx2_only_manifests_give_the_same_probe_results_as_exr() {
    let ctx = ctx();
    let dir = tempfile::tempdir().unwrap();
    let mut exr = TableSet::load(ctx, &manifest("film-dielectric")).unwrap();
    exr.add(ctx, &manifest("fourier-srgb")).unwrap();
    let mut ktx2 = TableSet::load(ctx, &ktx2_only("film-dielectric", dir.path())).unwrap();
    ktx2.add(ctx, &ktx2_only("fourier-srgb", dir.path()))
        .unwrap();
    for t in [
        &ktx2.film_lut.as_ref().unwrap().manifest,
        &ktx2.fourier.as_ref().unwrap().manifest,
    ] {
        assert!(
            t.files
                .iter()
                .all(|f| f.format == nacre_format::FileFormat::Ktx2),
            "{}",
            t.name
        );
    }
    assert!(ktx2.film_lut.as_ref().unwrap().has_transmittance);
    let colorimeter = exr.colorimeter().unwrap();
    assert_eq!(ktx2.colorimeter().unwrap(), colorimeter);
    let inputs = inputs();
    for technique in Technique::ALL {
        for harmonics in [0u32, 3] {
            let options = TechniqueOptions {
                harmonics,
                ..Default::default()
            };
            let run = |tables: &TableSet| {
                let binding =
                    TechniqueBinding::new(ctx, tables, technique, &options, &colorimeter).unwrap();
                run_probe(ctx, &binding, &inputs).unwrap()
            };
            let (a, b) = (run(&exr), run(&ktx2));
            assert_eq!(a.len(), inputs.len());
            for (i, (a, b)) in a.iter().zip(&b).enumerate() {
                let bits = |o: &nacre_runtime::FilmOutput| {
                    [o.reflectance, o.transmittance].map(|c| c.map(f32::to_bits))
                };
                assert_eq!(
                    bits(a),
                    bits(b),
                    "{} (M = {harmonics}), input {i}: EXR {a:?}, KTX2 {b:?}",
                    technique.name()
                );
            }
            eprintln!(
                "{} (M = {harmonics}): {} probes identical",
                technique.name(),
                a.len()
            );
        }
    }
}

#[test]
fn broken_ktx2_files_are_errors() {
    let ctx = ctx();
    let dir = tempfile::tempdir().unwrap();
    for name in ["film-dielectric", "fourier-srgb"] {
        let path = ktx2_only(name, dir.path());
        let good = Manifest::read(&path).unwrap();
        let file = dir.path().join(&good.files[0].path);
        let bytes = std::fs::read(&file).unwrap();
        // Truncated (the checksum updated so that the KTX2 reader itself sees it), then a
        // wrong vkFormat (R32G32B32A32 ↔ R16G16B16A16 swapped).
        let mut wrong_format = bytes.clone();
        let swapped: u32 = if name == "fourier-srgb" { 97 } else { 109 };
        wrong_format[12..16].copy_from_slice(&swapped.to_le_bytes());
        for (what, broken) in [
            ("truncated", bytes[..bytes.len() / 2].to_vec()),
            ("wrong format", wrong_format),
        ] {
            std::fs::write(&file, &broken).unwrap();
            let mut m = good.clone();
            m.files[0].sha256 = nacre_format::table_io::sha256_hex(&file).unwrap();
            std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
            let err = match TableSet::load(ctx, &path) {
                Ok(_) => panic!("{name} {what}: loaded"),
                Err(e) => e.to_string(),
            };
            assert!(err.contains(&good.files[0].path), "{name} {what}: {err}");
        }
        // The original checksum no longer matches: refused before decoding.
        std::fs::write(&path, serde_json::to_string_pretty(&good).unwrap()).unwrap();
        let err = TableSet::load(ctx, &path).err().unwrap().to_string();
        assert!(err.contains("does not match its manifest"), "{name}: {err}");
    }
}
