//! Every KTX2 file of the committed default set (`tables/baked/`), read with an independent
//! parser (the `ktx2` crate, not nacre's own reader): format, data format descriptor,
//! dimensions, levels, layers, key/value metadata, checksum, and texels equal to the EXR
//! files' (half floats bit for bit, full floats bit for bit).

use half::f16;
use nacre_format::Manifest;
use nacre_format::ktx2::{MANIFEST_KEY, WRITER_KEY};
use nacre_format::manifest::FOURIER_KTX2_QUANTITY;
use nacre_format::set::default_baked_dir;
use nacre_format::table_io::{read_exr_table, sha256_hex};

fn manifests() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(default_baked_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    v.sort();
    assert!(v.len() >= 5, "{v:?}");
    v
}

/// Parses with the `ktx2` crate and checks what every nacre KTX2 file shares; returns the
/// reader.
fn open<'a>(
    bytes: &'a [u8],
    manifest: &Manifest,
    format: ktx2::Format,
    what: &str,
) -> ktx2::Reader<&'a [u8]> {
    let reader = ktx2::Reader::new(bytes).unwrap_or_else(|e| panic!("{what}: {e:?}"));
    let header = reader.header();
    assert_eq!(header.format, Some(format), "{what}");
    assert_eq!(header.face_count, 1, "{what}");
    assert_eq!(header.supercompression_scheme, None, "{what}");
    let (expected_dfd, type_size) = ktx2::dfd::Basic::from_format(format).unwrap();
    assert_eq!(header.type_size, type_size, "{what}");
    assert_eq!(reader.basic_dfd(), Some(&expected_dfd), "{what}");
    assert_eq!(reader.dfd_blocks().len(), 1, "{what}");
    assert_eq!(
        reader.transfer_function(),
        Some(ktx2::TransferFunction::Linear),
        "{what}"
    );
    let kv: Vec<(&str, &[u8])> = reader.key_value_data().collect();
    let keys: Vec<&str> = kv.iter().map(|(k, _)| *k).collect();
    assert_eq!(keys, [WRITER_KEY, MANIFEST_KEY], "{what}: keys sorted");
    assert_eq!(
        reader.writer(),
        Some(concat!("nacre ", env!("CARGO_PKG_VERSION"), "\0")),
        "{what}"
    );
    let embedded = kv[1].1.strip_suffix(&[0]).expect("NUL-terminated manifest");
    let embedded: serde_json::Value = serde_json::from_slice(embedded).unwrap();
    let mut expected = serde_json::to_value(manifest).unwrap();
    expected.as_object_mut().unwrap().remove("files");
    assert_eq!(embedded, expected, "{what}: embedded manifest");
    for level in reader.levels() {
        assert_eq!(level.uncompressed_byte_length, level.data.len() as u64);
    }
    reader
}

#[test]
fn every_baked_ktx2_parses_with_the_ktx2_crate_and_matches_its_exr() {
    let mut seen = 0;
    for path in manifests() {
        let m = Manifest::read(&path).unwrap();
        let dir = path.parent().unwrap();
        let ktx2_files: Vec<_> = m
            .files
            .iter()
            .filter(|f| f.format == nacre_format::FileFormat::Ktx2)
            .collect();
        assert!(!ktx2_files.is_empty(), "{}: no KTX2 file", m.name);
        for f in ktx2_files {
            let file = dir.join(&f.path);
            let what = f.path.as_str();
            assert_eq!(sha256_hex(&file).unwrap(), f.sha256, "{what}");
            let bytes = std::fs::read(&file).unwrap();
            match m.kind.name() {
                // A rough-film-lut is laid out like a film-lut with depth = α blocks × indices.
                "film-lut" | "rough-film-lut" => {
                    let (nx, ny, nz) = match (&m.film_lut(), &m.rough_film_lut()) {
                        (Some(a), _) => (a.cos_theta_count, a.opd_count, a.ior_count),
                        (None, Some(a)) => (a.cos_theta_count, a.opd_count, a.depth()),
                        _ => panic!("{what}: no axes"),
                    };
                    let reader = open(&bytes, &m, ktx2::Format::R16G16B16A16_SFLOAT, what);
                    let h = reader.header();
                    assert_eq!(
                        (h.pixel_width, h.pixel_height, h.pixel_depth),
                        (nx as u32, ny as u32, nz as u32),
                        "{what}"
                    );
                    assert_eq!((h.layer_count, h.level_count), (0, 1), "{what}");
                    assert_eq!(
                        (f.width, f.height, f.encoding),
                        (nx, ny, nacre_format::Encoding::Half)
                    );
                    let exr = m
                        .files
                        .iter()
                        .find(|e| {
                            e.format == nacre_format::FileFormat::Exr && e.quantity == f.quantity
                        })
                        .unwrap();
                    let (table, _) = read_exr_table(&dir.join(&exr.path), nx, ny, nz).unwrap();
                    let level = reader.levels().next().unwrap().data;
                    assert_eq!(level.len(), nx * ny * nz * 8, "{what}");
                    for (i, texel) in level.chunks_exact(8).enumerate() {
                        let c = |j: usize| u16::from_le_bytes([texel[2 * j], texel[2 * j + 1]]);
                        let expect = [0, 1, 2].map(|j| f16::from_f32(table.data[3 * i + j]));
                        assert_eq!(
                            [c(0), c(1), c(2), c(3)],
                            [
                                expect[0].to_bits(),
                                expect[1].to_bits(),
                                expect[2].to_bits(),
                                f16::ONE.to_bits()
                            ],
                            "{what}: texel {i}"
                        );
                        // The EXR holds half floats: the KTX2 value is exactly the EXR value.
                        assert_eq!(f16::from_bits(c(0)).to_f32(), table.data[3 * i]);
                    }
                }
                "fourier" => {
                    let a = m.fourier().unwrap();
                    let reader = open(&bytes, &m, ktx2::Format::R32G32B32A32_SFLOAT, what);
                    let h = reader.header();
                    assert_eq!(
                        (h.pixel_width, h.pixel_height, h.pixel_depth),
                        (a.samples as u32, 1, 0),
                        "{what}"
                    );
                    assert_eq!(h.layer_count, 2, "{what}");
                    assert_eq!(h.level_count as usize, a.level_samples.len(), "{what}");
                    assert_eq!(f.quantity, FOURIER_KTX2_QUANTITY);
                    assert_eq!((f.width, f.height), (a.samples, 1));
                    let exr = m.load_fourier(&path).unwrap(); // all EXR levels listed
                    for (k, level) in reader.levels().enumerate() {
                        let n = a.level_samples[k];
                        assert_eq!(n, (a.samples >> k).max(1));
                        assert_eq!(level.data.len(), n * 2 * 16, "{what}: level {k}");
                        let v: Vec<f32> = level
                            .data
                            .chunks_exact(4)
                            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                            .collect();
                        for i in 0..n {
                            for j in 0..3 {
                                let z = exr.levels[k][i][j];
                                assert_eq!(v[4 * i + j].to_bits(), (z.re as f32).to_bits());
                                assert_eq!(v[4 * (n + i) + j].to_bits(), (z.im as f32).to_bits());
                            }
                            assert_eq!((v[4 * i + 3], v[4 * (n + i) + 3]), (0.0, 0.0));
                        }
                    }
                }
                "diffraction" if m.diffraction().unwrap().layout == "integrated" => {
                    // 2-D array RGBA32F n/2 × n, layer p = (I_p, 0), the EXR atlas's values.
                    let d = m.diffraction().unwrap();
                    let s = d.integrated.as_ref().unwrap();
                    let reader = open(&bytes, &m, ktx2::Format::R32G32B32A32_SFLOAT, what);
                    let h = reader.header();
                    assert_eq!(
                        (h.pixel_width, h.pixel_height, h.pixel_depth, h.layer_count),
                        (s.samples_u as u32, s.samples_v as u32, 0, s.layers as u32),
                        "{what}"
                    );
                    assert_eq!(h.level_count, 1, "{what}");
                    let mut ktx2_only = m.clone();
                    ktx2_only
                        .files
                        .retain(|f| f.format == nacre_format::FileFormat::Ktx2);
                    let copy = tempfile::tempdir().unwrap();
                    let json = copy.path().join("m.json");
                    std::fs::write(&json, serde_json::to_string(&ktx2_only).unwrap()).unwrap();
                    std::fs::copy(&file, copy.path().join(&f.path)).unwrap();
                    assert_eq!(
                        ktx2_only.load_diffraction_integrated(&json).unwrap(),
                        m.load_diffraction_integrated(&path).unwrap(),
                        "{what}"
                    );
                    let level = reader.levels().next().unwrap().data;
                    assert!(
                        level.chunks_exact(16).all(|t| t[12..] == [0; 4]),
                        "{what}: A = 0"
                    );
                }
                "diffraction" => {
                    // 2-D array RGBA32F: layer l = (Re T_2l, Im T_2l, Re T_2l+1, Im T_2l+1).
                    let d = m.diffraction().unwrap();
                    let terms = d.taylor_order + 1;
                    let reader = open(&bytes, &m, ktx2::Format::R32G32B32A32_SFLOAT, what);
                    let h = reader.header();
                    assert_eq!(
                        (h.pixel_width, h.pixel_height, h.pixel_depth),
                        (d.nx as u32, d.ny as u32, 0),
                        "{what}"
                    );
                    assert_eq!(h.layer_count as usize, terms.div_ceil(2), "{what}");
                    assert_eq!(h.level_count, 1, "{what}");
                    assert_eq!((f.width, f.height), (d.nx, d.ny));
                    let exr = m
                        .files
                        .iter()
                        .find(|e| {
                            e.format == nacre_format::FileFormat::Exr && e.quantity == "terms"
                        })
                        .unwrap();
                    let (table, _) =
                        read_exr_table(&dir.join(&exr.path), d.nx, d.ny, terms).unwrap();
                    let level = reader.levels().next().unwrap().data;
                    let v: Vec<f32> = level
                        .chunks_exact(4)
                        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                        .collect();
                    let bins = d.nx * d.ny;
                    assert_eq!(v.len(), terms.div_ceil(2) * bins * 4, "{what}");
                    for n in 0..terms.div_ceil(2) * 2 {
                        for i in 0..bins {
                            let at = ((n / 2) * bins + i) * 4 + 2 * (n % 2);
                            let expect = if n < terms {
                                let t = table.texel(i % d.nx, i / d.nx, n);
                                assert_eq!(t[2], 0.0);
                                [t[0], t[1]]
                            } else {
                                [0.0, 0.0]
                            };
                            assert_eq!(
                                [v[at].to_bits(), v[at + 1].to_bits()],
                                expect.map(f32::to_bits),
                                "{what}: term {n}, bin {i}"
                            );
                        }
                    }
                }
                other => panic!("{}: unexpected kind {other}", m.name),
            }
            seen += 1;
        }
    }
    // Every KTX2 file in the default set was checked (tables are added over time).
    let on_disk = std::fs::read_dir(default_baked_dir())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "ktx2")
        })
        .count();
    assert!(seen >= 12, "{seen} KTX2 files in the default set");
    assert_eq!(seen, on_disk, "KTX2 files in the default set");
}

/// nacre's own reader agrees with the EXR path through the manifest (EXR entries removed).
#[test]
fn manifest_loads_tables_from_ktx2_when_no_exr_is_listed() {
    let out = tempfile::tempdir().unwrap();
    for path in manifests() {
        let mut m = Manifest::read(&path).unwrap();
        let dir = path.parent().unwrap();
        let copy = out.path().join(path.file_name().unwrap());
        let full = m.clone();
        m.files
            .retain(|f| f.format == nacre_format::FileFormat::Ktx2);
        for f in &m.files {
            std::fs::copy(dir.join(&f.path), out.path().join(&f.path)).unwrap();
        }
        std::fs::write(&copy, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        match m.kind.name() {
            "film-lut" => {
                for q in ["reflectance", "transmittance"] {
                    assert_eq!(
                        m.load_table(&copy, q).unwrap(),
                        full.load_table(&path, q).unwrap(),
                        "{} {q}",
                        m.name
                    );
                }
            }
            "diffraction" if m.diffraction().unwrap().layout == "integrated" => assert_eq!(
                m.load_diffraction_integrated(&copy).unwrap(),
                full.load_diffraction_integrated(&path).unwrap()
            ),
            "diffraction" => assert_eq!(
                m.load_diffraction(&copy).unwrap(),
                full.load_diffraction(&path).unwrap()
            ),
            "rough-film-lut" => {
                use nacre_format::load::LoadedRoughLut;
                assert_eq!(
                    LoadedRoughLut::load(&copy).unwrap().lut,
                    LoadedRoughLut::load(&path).unwrap().lut,
                    "{}",
                    m.name
                );
            }
            _ => assert_eq!(
                m.load_fourier(&copy).unwrap(),
                full.load_fourier(&path).unwrap()
            ),
        }
    }
}

/// A `precision = "float"` recipe writes its KTX2 files as `RGBA32F` holding the EXR's
/// full floats bit for bit, and the manifest loads the same table from either file.
#[test]
fn float_precision_recipes_write_rgba32f_ktx2() {
    let out = tempfile::tempdir().unwrap();
    let recipe_path = out.path().join("small-float.toml");
    let text = r#"kind = "film-lut"
[stack]
ambient = "1.0"
film = "thin film"
base = "1.5"
[axes]
cos_theta_count = 5
thickness_nm = [0.0, 800.0]
opd_count = 7
film_ior = [1.2, 1.6]
film_ior_count = 3
[output]
precision = "float"
png = false
transmittance = "auto"
"#;
    std::fs::write(&recipe_path, text).unwrap();
    let recipe = nacre_bake::kinds::film_lut::FilmLutRecipe::read(&recipe_path).unwrap();
    let manifest_path =
        nacre_bake::kinds::film_lut::bake_recipe(&recipe, out.path(), &|| {}).unwrap();
    let manifest = Manifest::read(&manifest_path).unwrap();
    let mut seen = 0;
    for f in manifest
        .files
        .iter()
        .filter(|f| f.format == nacre_format::FileFormat::Ktx2)
    {
        assert_eq!(f.encoding, nacre_format::Encoding::Float, "{}", f.path);
        let bytes = std::fs::read(out.path().join(&f.path)).unwrap();
        let reader = open(
            &bytes,
            &manifest,
            ktx2::Format::R32G32B32A32_SFLOAT,
            &f.path,
        );
        let header = reader.header();
        assert_eq!(
            (header.pixel_width, header.pixel_height, header.pixel_depth),
            (5, 7, 3)
        );
        let texels: Vec<f32> = reader
            .levels()
            .next()
            .unwrap()
            .data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        let exr = manifest
            .files
            .iter()
            .find(|e| e.format == nacre_format::FileFormat::Exr && e.quantity == f.quantity)
            .unwrap();
        let (table, _) = read_exr_table(&out.path().join(&exr.path), 5, 7, 3).unwrap();
        assert_eq!(texels.len(), table.data.len() / 3 * 4);
        for (i, t) in texels.chunks_exact(4).enumerate() {
            let rgb = &table.data[3 * i..3 * i + 3];
            assert_eq!(
                [t[0].to_bits(), t[1].to_bits(), t[2].to_bits()],
                [rgb[0].to_bits(), rgb[1].to_bits(), rgb[2].to_bits()],
                "{} texel {i}",
                f.path
            );
            assert_eq!(t[3], 1.0);
        }
        let mut only_ktx2 = manifest.clone();
        only_ktx2
            .files
            .retain(|g| g.format == nacre_format::FileFormat::Ktx2);
        assert_eq!(
            only_ktx2.load_table(&manifest_path, &f.quantity).unwrap(),
            Some(table)
        );
        seen += 1;
    }
    assert_eq!(seen, 2, "reflectance and transmittance");
}
