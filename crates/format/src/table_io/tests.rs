//! Tests of the table files: round trips, determinism, malformed and hostile files.

use super::exr::*;
use super::png16::*;
use super::table::*;
use crate::checksum::sha256_hex;
use crate::error::Error;
use half::f16;
use std::path::Path;
use std::path::PathBuf;

/// A table with distinct, awkward values (negative, tiny, huge, non-representable).
fn sample_table(nx: usize, ny: usize, nz: usize) -> Table3 {
    let mut t = Table3::new(nx, ny, nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let i = (((z * ny) + y) * nx + x) as f32;
                t.set(
                    x,
                    y,
                    z,
                    [0.1 + i / 7.0, -(i * 1.000_1).sqrt() / 3.0, 1e-7 * (i + 1.0)],
                );
            }
        }
    }
    t
}

/// A table whose values all lie in [0, 1].
fn unit_table(nx: usize, ny: usize, nz: usize) -> Table3 {
    let mut t = Table3::new(nx, ny, nz);
    let n = t.data.len();
    for (i, v) in t.data.iter_mut().enumerate() {
        *v = ((i * 7919) % n) as f32 / (n - 1) as f32;
    }
    t.data[0] = 0.0;
    t.data[1] = 1.0;
    t.data[2] = 1.0 / 65535.0;
    t
}

fn names_file(err: &Error, path: &Path) -> bool {
    let name = path.file_name().unwrap().to_str().unwrap();
    err.to_string().contains(name)
}

fn dir_entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn table_indexing_is_x_fastest() {
    let mut t = Table3::new(3, 4, 5);
    t.set(2, 1, 3, [1.0, 2.0, 3.0]);
    let i = ((3 * 4) + 1) * 3 + 2;
    assert_eq!(&t.data[i * 3..i * 3 + 3], &[1.0, 2.0, 3.0]);
    assert_eq!(t.texel(2, 1, 3), [1.0, 2.0, 3.0]);
    assert_eq!(t.texel(0, 0, 0), [0.0; 3]);
}

#[test]
fn precision_serde_names_are_lowercase() {
    #[derive(serde::Deserialize)]
    struct W {
        p: Precision,
    }
    let w: W = serde_json::from_str(r#"{"p": "float"}"#).unwrap();
    assert_eq!(w.p, Precision::Float);
    let w: W = serde_json::from_str(r#"{"p": "half"}"#).unwrap();
    assert_eq!(w.p, Precision::Half);
    assert!(serde_json::from_str::<W>(r#"{"p": "Half"}"#).is_err());
}

#[test]
fn exr_float_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.exr");
    let mut t = sample_table(5, 3, 4);
    t.data[7] = -0.0;
    t.data[8] = f32::MAX;
    t.data[9] = f32::from_bits(1); // smallest subnormal
    write_exr(&path, &t, Precision::Float).unwrap();
    let (back, precision) = read_exr_table(&path, 5, 3, 4).unwrap();
    assert_eq!(precision, Precision::Float);
    assert_eq!((back.nx, back.ny, back.nz), (5, 3, 4));
    let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.data), bits(&t.data));

    let (atlas, precision) = read_exr(&path).unwrap();
    assert_eq!(precision, Precision::Float);
    assert_eq!((atlas.width, atlas.height), (5, 12));
    assert_eq!(bits(&atlas.data), bits(&t.data));
}

#[test]
fn exr_half_round_trip_rounds_to_nearest_even() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("h.exr");
    let mut t = sample_table(4, 2, 3);
    let one_ulp = 2f32.powi(-10); // f16 spacing just above 1
    t.data[0] = 1.0 + one_ulp / 2.0; // tie: rounds down to 1 (even)
    t.data[1] = 1.0 + 1.5 * one_ulp; // tie: rounds up to 1 + 2 ulp (even)
    t.data[2] = 65504.0; // f16::MAX
    t.data[3] = -65519.0; // rounds to -65504
    t.data[4] = 1e-7; // f16 subnormal
    write_exr(&path, &t, Precision::Half).unwrap();
    let (back, precision) = read_exr_table(&path, 4, 2, 3).unwrap();
    assert_eq!(precision, Precision::Half);
    for (a, b) in t.data.iter().zip(&back.data) {
        assert_eq!(f16::from_f32(*a).to_f32().to_bits(), b.to_bits(), "{a}");
    }
    assert_eq!(back.data[0], 1.0);
    assert_eq!(back.data[1], 1.0 + 2.0 * one_ulp);
    assert_eq!(back.data[3], -65504.0);
}

#[test]
fn exr_half_refuses_values_beyond_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.exr");
    let mut t = sample_table(2, 2, 2);
    t.set(1, 0, 1, [0.0, 70000.0, 0.0]);
    let err = write_exr(&path, &t, Precision::Half).unwrap_err();
    let msg = err.to_string();
    assert!(
        names_file(&err, &path) && msg.contains("half-float range"),
        "{msg}"
    );
    assert!(
        msg.contains("x=1, y=0, z=1") && msg.contains("channel G"),
        "{msg}"
    );
    assert!(!path.exists());
    write_exr(&path, &t, Precision::Float).unwrap();
}

#[test]
fn atlas_layout_matches_docs() {
    // Verified with exr's own position-based reader and the raw PNG rows, independent
    // of this module's readers.
    let dir = tempfile::tempdir().unwrap();
    let (nx, ny, nz) = (3, 2, 4);
    let mut t = Table3::new(nx, ny, nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                t.set(x, y, z, [x as f32 / 4.0, y as f32 / 4.0, z as f32 / 4.0]);
            }
        }
    }
    let exr_path = dir.path().join("layout.exr");
    write_exr(&exr_path, &t, Precision::Float).unwrap();
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &exr_path,
        |res, _| vec![[f32::NAN; 3]; res.0 * res.1],
        move |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.1 * nx + pos.0] = [r, g, b];
        },
    )
    .unwrap();
    assert_eq!(
        (image.layer_data.size.0, image.layer_data.size.1),
        (nx, ny * nz)
    );
    let px = &image.layer_data.channel_data.pixels;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                assert_eq!(px[(z * ny + y) * nx + x], t.texel(x, y, z));
            }
        }
    }

    let png_path = dir.path().join("layout.png");
    assert!(write_png16(&png_path, &t).unwrap());
    let file = std::io::BufReader::new(std::fs::File::open(&png_path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0u8; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (nx as u32, (ny * nz) as u32));
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let row = &buf[(z * ny + y) * info.line_size..];
                let at =
                    |c: usize| u16::from_be_bytes([row[x * 6 + 2 * c], row[x * 6 + 2 * c + 1]]);
                let expect = t.texel(x, y, z).map(|v| (v * 65535.0).round() as u16);
                assert_eq!([at(0), at(1), at(2)], expect);
            }
        }
    }
}

#[test]
fn exr_dimension_mismatch_names_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dims.exr");
    write_exr(&path, &sample_table(4, 3, 2), Precision::Float).unwrap();
    for (nx, ny, nz) in [
        (5, 3, 2),
        (4, 3, 3),
        (4, 2, 2),
        (0, 3, 2),
        (usize::MAX, 2, 2),
    ] {
        let err = read_exr_table(&path, nx, ny, nz).unwrap_err();
        assert!(names_file(&err, &path), "{err}");
    }
    let err = read_exr_table(&path, 4, 2, 4).unwrap_err(); // same texel count, 4x8 ≠ 4x6
    assert!(
        err.to_string().contains("4x6") && err.to_string().contains("4x8"),
        "{err}"
    );
    // A reshaped read of the same atlas is fine.
    assert!(read_exr_table(&path, 4, 6, 1).is_ok());
}

#[test]
fn exr_truncated_or_corrupt_files_give_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.exr");
    write_exr(&full, &sample_table(6, 5, 4), Precision::Float).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    let cut = dir.path().join("cut.exr");
    for len in [
        0,
        3,
        4,
        20,
        bytes.len() / 3,
        bytes.len() / 2,
        bytes.len() - 1,
    ] {
        std::fs::write(&cut, &bytes[..len]).unwrap();
        let err = read_exr_table(&cut, 6, 5, 4).unwrap_err();
        assert!(names_file(&err, &cut), "{len}: {err}");
        let err = read_exr(&cut).unwrap_err();
        assert!(names_file(&err, &cut), "{len}: {err}");
    }
    // Arbitrary single-byte corruption never panics (errors or, rarely, still decodes).
    let bad = dir.path().join("bad.exr");
    for i in (0..bytes.len()).step_by(3) {
        let mut b = bytes.clone();
        b[i] ^= 0xa5;
        std::fs::write(&bad, &b).unwrap();
        if let Err(err) = read_exr_table(&bad, 6, 5, 4) {
            assert!(names_file(&err, &bad), "{i}: {err}");
        }
    }
    let err = read_exr(&dir.path().join("missing.exr")).unwrap_err();
    assert!(matches!(err, Error::Io { .. }) && err.to_string().contains("missing.exr"));
}

#[test]
fn exr_without_rgb_or_with_non_finite_values_is_refused() {
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Image, SmallVec, WritableImage,
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("y.exr");
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
        "Y",
        FlatSamples::F32(vec![0.5; 4]),
    )]));
    Image::from_encoded_channels((2, 2), Encoding::UNCOMPRESSED, channels)
        .write()
        .to_file(&path)
        .unwrap();
    let err = read_exr_table(&path, 2, 2, 1).unwrap_err();
    assert!(
        names_file(&err, &path) && err.to_string().contains("no channel R"),
        "{err}"
    );

    let path = dir.path().join("nan.exr");
    let mut r = vec![0.5f32; 4];
    r[3] = f32::INFINITY;
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        AnyChannel::new("R", FlatSamples::F32(r)),
        AnyChannel::new("G", FlatSamples::F32(vec![0.5; 4])),
        AnyChannel::new("B", FlatSamples::F32(vec![0.5; 4])),
    ]));
    Image::from_encoded_channels((2, 2), Encoding::UNCOMPRESSED, channels)
        .write()
        .to_file(&path)
        .unwrap();
    let err = read_exr_table(&path, 2, 1, 2).unwrap_err();
    let msg = err.to_string();
    assert!(
        names_file(&err, &path) && msg.contains("non-finite"),
        "{msg}"
    );
    assert!(msg.contains("column 1, row 1, channel R"), "{msg}");
}

#[test]
fn writes_are_byte_identical_across_runs_and_thread_counts() {
    let dir = tempfile::tempdir().unwrap();
    let t = sample_table(37, 9, 11); // several 16-line ZIP blocks
    let u = unit_table(37, 9, 11);
    let write_all = |tag: &str| {
        let a = dir.path().join(format!("{tag}-f.exr"));
        let b = dir.path().join(format!("{tag}-h.exr"));
        let c = dir.path().join(format!("{tag}.png"));
        write_exr(&a, &t, Precision::Float).unwrap();
        write_exr(&b, &t, Precision::Half).unwrap();
        assert!(write_png16(&c, &u).unwrap());
        [a, b, c].map(|p| std::fs::read(p).unwrap())
    };
    let first = write_all("1");
    assert_eq!(write_all("2"), first);
    for threads in [1, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        assert_eq!(pool.install(|| write_all(&format!("pool{threads}"))), first);
    }
    assert_eq!(
        sha256_hex(&dir.path().join("1-f.exr")).unwrap(),
        sha256_hex(&dir.path().join("2-f.exr")).unwrap()
    );
}

#[test]
fn failed_writes_leave_existing_files_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let exr_path = dir.path().join("keep.exr");
    let png_path = dir.path().join("keep.png");
    write_exr(&exr_path, &sample_table(3, 2, 2), Precision::Float).unwrap();
    assert!(write_png16(&png_path, &unit_table(3, 2, 2)).unwrap());
    let before = [&exr_path, &png_path].map(|p| std::fs::read(p).unwrap());
    let entries = dir_entries(dir.path());

    let mut bad = unit_table(3, 2, 2);
    bad.set(2, 1, 0, [0.5, f32::NAN, 0.5]);
    for precision in [Precision::Float, Precision::Half] {
        let err = write_exr(&exr_path, &bad, precision).unwrap_err();
        assert!(names_file(&err, &exr_path) && err.to_string().contains("non-finite"));
    }
    let err = write_png16(&png_path, &bad).unwrap_err();
    assert!(names_file(&err, &png_path) && err.to_string().contains("x=2, y=1, z=0"));
    bad.data[4] = f32::NEG_INFINITY;
    assert!(write_exr(&exr_path, &bad, Precision::Float).is_err());

    // Inconsistent and empty tables are refused as well.
    let mut short = unit_table(3, 2, 2);
    short.data.pop();
    assert!(write_exr(&exr_path, &short, Precision::Float).is_err());
    assert!(write_png16(&png_path, &short).is_err());
    assert!(write_exr(&exr_path, &Table3::new(0, 2, 2), Precision::Float).is_err());
    assert!(write_png16(&png_path, &Table3::new(3, 0, 2)).is_err());

    // Out-of-range values: PNG is skipped, nothing written.
    let mut over = unit_table(3, 2, 2);
    over.data[5] = 1.000_001;
    assert!(!write_png16(&png_path, &over).unwrap());

    assert_eq!(
        [&exr_path, &png_path].map(|p| std::fs::read(p).unwrap()),
        before
    );
    assert_eq!(
        dir_entries(dir.path()),
        entries,
        "no temporary files left behind"
    );
}

#[test]
fn png_is_skipped_for_values_outside_unit_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("skip.png");
    for v in [-1e-9f32, -0.5, 1.0 + f32::EPSILON, 2.0] {
        let mut t = unit_table(2, 2, 2);
        t.set(1, 1, 1, [0.5, v, 0.5]);
        assert!(!write_png16(&path, &t).unwrap(), "{v}");
        assert!(!path.exists());
    }
    let mut t = unit_table(2, 2, 2);
    t.data[0] = -0.0; // within [0, 1]
    assert!(write_png16(&path, &t).unwrap());
}

#[test]
fn png_round_trip_within_one_step() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rt.png");
    let t = unit_table(7, 5, 3);
    assert!(write_png16(&path, &t).unwrap());
    let back = read_png16_table(&path, 7, 5, 3).unwrap();
    assert_eq!((back.nx, back.ny, back.nz), (7, 5, 3));
    assert_eq!(back.data.len(), t.data.len());
    for (a, b) in t.data.iter().zip(&back.data) {
        assert!((a - b).abs() <= 1.0 / 65535.0, "{a} vs {b}");
        // Exactly the documented quantisation.
        assert_eq!(*b, ((f64::from(*a) * 65535.0).round() / 65535.0) as f32);
    }
    assert_eq!(back.data[0], 0.0);
    assert_eq!(back.data[1], 1.0);
    assert_eq!(back.data[2], 1.0 / 65535.0);
}

#[test]
fn png_reader_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.png");
    assert!(write_png16(&path, &unit_table(4, 3, 2)).unwrap());
    for (nx, ny, nz) in [(5, 3, 2), (4, 3, 3), (4, 2, 2), (0, 1, 1)] {
        let err = read_png16_table(&path, nx, ny, nz).unwrap_err();
        assert!(names_file(&err, &path), "{err}");
    }
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.path().join("cut.png");
    for len in [0, 8, 20, 40, bytes.len() / 2, bytes.len() - 1] {
        std::fs::write(&cut, &bytes[..len]).unwrap();
        let err = read_png16_table(&cut, 4, 3, 2).unwrap_err();
        assert!(names_file(&err, &cut), "{len}: {err}");
    }
    let bad = dir.path().join("bad.png");
    for i in 0..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        std::fs::write(&bad, &b).unwrap();
        if let Err(err) = read_png16_table(&bad, 4, 3, 2) {
            assert!(names_file(&err, &bad), "{i}: {err}");
        }
    }

    // An 8-bit PNG is refused.
    let eight = dir.path().join("eight.png");
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, 4, 6);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[0u8; 4 * 6 * 3]).unwrap();
        w.finish().unwrap();
    }
    std::fs::write(&eight, &out).unwrap();
    let err = read_png16_table(&eight, 4, 3, 2).unwrap_err();
    assert!(
        names_file(&err, &eight) && err.to_string().contains("16 bits"),
        "{err}"
    );
    // An EXR is not a PNG and vice versa.
    let exr_path = dir.path().join("x.exr");
    write_exr(&exr_path, &unit_table(4, 3, 2), Precision::Half).unwrap();
    assert!(names_file(
        &read_png16_table(&exr_path, 4, 3, 2).unwrap_err(),
        &exr_path
    ));
    assert!(names_file(&read_exr(&path).unwrap_err(), &path));
}

#[test]
fn sha256_of_known_content() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("abc.txt");
    std::fs::write(&path, b"abc").unwrap();
    assert_eq!(
        sha256_hex(&path).unwrap(),
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    );
    std::fs::write(&path, b"").unwrap();
    assert_eq!(
        sha256_hex(&path).unwrap(),
        "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
    );
    let big = vec![0x61u8; 200_000]; // spans several read buffers
    std::fs::write(&path, &big).unwrap();
    assert_eq!(sha256_hex(&path).unwrap().len(), 64);
    let err = sha256_hex(&dir.path().join("nope")).unwrap_err();
    assert!(matches!(err, Error::Io { .. }) && err.to_string().contains("nope"));
}
