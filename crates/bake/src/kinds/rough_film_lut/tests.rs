//! Tests of the `rough-film-lut` table kind.

use super::*;

fn axes() -> RoughLutAxes {
    RoughLutAxes {
        cos_theta_count: 9,
        opd_count: 17,
        ior_count: 5,
        alpha_count: 4,
        thickness_min_nm: 0.0,
        thickness_max_nm: 1200.0,
        ior_min: 1.0,
        ior_max: 2.5,
        alpha_min: 0.02,
        alpha_max: 1.0,
        ambient_index: 1.0,
        base_eta: Some(1.5),
    }
}

#[test]
fn forward_and_inverse_round_trip() {
    let a = axes();
    for &(c, al, d, n) in &[
        (1.0, 0.02, 0.0, 1.0),
        (0.5, 0.3, 300.0, 1.7),
        (0.01, 1.0, 1200.0, 2.5),
        (0.9, 0.05, 17.0, 1.2),
    ] {
        let t = a.forward(c, al, d, n);
        let (c2, opd, n2, al2) = a.inverse(t);
        assert!((c2 - c).abs() < 1e-12 && (n2 - n).abs() < 1e-12, "{t:?}");
        assert!((al2 - al).abs() < 1e-12 * al, "{al} {al2}");
        assert!((opd - a.opd_nm(c, al, d, n)).abs() < 1e-9);
    }
    // Texel parameters map back to their own t.
    for (x, y, k, al) in [(1, 0, 0, 0), (8, 16, 4, 3), (3, 7, 2, 1)] {
        let (c, n, alpha) = (a.texel_cos_theta(x), a.texel_ior(k), a.texel_alpha(al));
        let d = a.texel_thickness_nm(x, y, k, al);
        let t = a.forward(c, alpha, d, n);
        let want = [
            RoughLutAxes::texel_t(x, 9),
            RoughLutAxes::texel_t(y, 17),
            RoughLutAxes::texel_t(k, 5),
            RoughLutAxes::texel_t(al, 4),
        ];
        for i in 0..4 {
            assert!((t[i] - want[i]).abs() < 1e-12, "{t:?} vs {want:?}");
        }
    }
    // Out of range and non-finite inputs clamp.
    assert_eq!(a.forward(f64::NAN, 0.001, -1.0, 0.5), [0.0; 4]);
    assert_eq!(a.forward(2.0, 5.0, 1e9, 9.0), [1.0; 4]);
}

#[test]
fn lookup_is_exact_at_texels_and_linear_between_alpha_blocks() {
    let a = axes();
    let mut table = Table3::new(9, 17, a.depth());
    for z in 0..a.depth() {
        for y in 0..17 {
            for x in 0..9 {
                let v = (x + 100 * y + 10_000 * z) as f32;
                table.set(x, y, z, [v, 2.0 * v, -v]);
            }
        }
    }
    // Texel (4, 8, k = 2, α block 1): z = 1 * 5 + 2.
    let (c, n, al) = (a.texel_cos_theta(4), a.texel_ior(2), a.texel_alpha(1));
    let d = a.texel_thickness_nm(4, 8, 2, 1);
    let v = RoughFilmLut::lookup(&a, &table, c, al, d, n);
    assert!((v[0] - (4.0 + 800.0 + 70_000.0)).abs() < 1e-6, "{v:?}");
    // Half-way (in t) between α blocks 1 and 2: the mean of the two blocks' values.
    let (_, _, _, al_mid) = a.inverse([0.0, 0.0, 0.0, 1.5 / 3.0]);
    let v = RoughFilmLut::lookup(&a, &table, c, al_mid, d, n);
    // Each block reads Δ referred to its own α: y is 8 in block 1, y₂ in block 2.
    let y2 = a.forward(c, a.texel_alpha(2), d, n)[1] * 16.0;
    assert!((y2 - 8.0).abs() > 0.01 && y2 < 16.0, "{y2}");
    let want = 0.5 * (4.0 + 800.0 + 70_000.0) + 0.5 * (4.0 + 100.0 * y2 + 120_000.0);
    assert!((v[0] - want).abs() < 1e-6, "{v:?} vs {want}");
}

fn srgb() -> Colorimeter {
    use nacre_optics::colour::{Illuminant, Observer, OutputSpace, RgbSpace};
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

fn tiny_job(base: &str) -> RoughLutJob {
    let m = |s: &str| Material::parse_index(s).unwrap();
    let axes = RoughLutAxes {
        cos_theta_count: 5,
        opd_count: 9,
        ior_count: 3,
        alpha_count: 3,
        thickness_min_nm: 0.0,
        thickness_max_nm: 600.0,
        ior_min: 1.0,
        ior_max: 2.0,
        alpha_min: 0.05,
        alpha_max: 1.0,
        ambient_index: 1.0,
        base_eta: Some(1.5),
    };
    RoughLutJob {
        axes,
        ambient: m("1.0"),
        under: vec![],
        base: m(base),
        colorimeter: srgb(),
        transmittance: true,
    }
}

/// (b) White furnace on every entry of a lossless stack's table, and the bake at a
/// texel against the kernel product with the exact film colour at that thickness.
#[test]
fn lossless_bake_passes_the_white_furnace_and_matches_the_exact_product() {
    let job = tiny_job("1.5");
    let lut = job.bake(&|| {}).unwrap();
    let t = lut.transmittance.as_ref().unwrap();
    for (x, y, k, al) in [(3, 6, 1, 2), (4, 3, 1, 0)] {
        check_texel(&lut, x, y, k, al);
    }
    // Linear sRGB channels of saturated film colours may be negative (a violet
    // residual reflection), so the law is on the sum, channel by channel: R + T ≤ 1.
    let (half_r, half_t) = rounded_to_half(&lut);
    let half_t = half_t.unwrap();
    for (r_table, t_table) in [(&lut.reflectance, t), (&half_r, &half_t)] {
        for (i, (r, t)) in r_table.data.iter().zip(&t_table.data).enumerate() {
            assert!(f64::from(*r) + f64::from(*t) <= 1.0, "value {i}: {r} + {t}");
        }
    }
    for (h, f) in half_r.data.iter().zip(&lut.reflectance.data) {
        assert_eq!(half::f16::from_f32(*h).to_f32(), *h);
        assert!((h - f).abs() <= 4.9e-4, "{h} vs {f}");
    }
}

/// (e) Storage rounding keeps E_r + E_t ≤ 1 where rounding to the nearest would not,
/// errs by less than one ulp, and leaves pairs that fit untouched.
#[test]
fn stored_pairs_keep_the_white_furnace_law() {
    use half::f16;
    let sum = |(a, b): (f32, f32)| f64::from(a) + f64::from(b);
    // The first two round up to a sum of 1 + 2⁻¹² and 1 + 3.3·10⁻⁴ at the nearest
    // halves (the second: a negative channel and one above 1, where the ulp is 2⁻¹⁰).
    for &(r, t) in &[
        (0.449_95, 0.550_05),
        (-0.000_65, 1.000_63),
        (0.04, 0.959_9),
        (0.5, 0.5),
        (0.123_456, 0.876_543_9),
    ] {
        assert!(r + t <= 1.0);
        let nearest = f64::from(f16::from_f64(r).to_f32()) + f64::from(f16::from_f64(t).to_f32());
        let (qr, qt) = store_albedo_pair(r, t, Precision::Half);
        assert!(
            sum((qr, qt)) <= 1.0,
            "{r} {t}: {qr} {qt} (nearest {nearest})"
        );
        assert_eq!(f16::from_f32(qr).to_f32(), qr);
        assert_eq!(f16::from_f32(qt).to_f32(), qt);
        for (q, v) in [(qr, r), (qt, t)] {
            let ulp = f16::from_f64(v.abs()).to_f64() * 2f64.powi(-10) + 1e-7;
            assert!((f64::from(q) - v).abs() <= ulp, "{q} vs {v}");
        }
        if nearest <= 1.0 {
            assert_eq!(
                (qr, qt),
                (f16::from_f64(r).to_f32(), f16::from_f64(t).to_f32())
            );
        }
        let (fr, ft) = store_albedo_pair(r, t, Precision::Float);
        assert!(sum((fr, ft)) <= 1.0);
        assert!((f64::from(fr) - r).abs() < 1e-7 && (f64::from(ft) - t).abs() < 1e-7);
    }
    // At least one of the cases needed the rounding down.
    let needs = |(r, t): (f64, f64)| {
        f64::from(f16::from_f64(r).to_f32()) + f64::from(f16::from_f64(t).to_f32()) > 1.0
    };
    assert!(needs((0.449_95, 0.550_05)) && needs((-0.000_65, 1.000_63)));
    // A quadrature sum above 1 is renormalised, keeping the split.
    let (qr, qt) = store_albedo_pair(0.25, 0.7503, Precision::Float);
    assert!(sum((qr, qt)) <= 1.0 && (f64::from(qr) - 0.25 / 1.0003).abs() < 1e-7);
}

fn check_texel(lut: &RoughFilmLut, x: usize, y: usize, k: usize, al: usize) {
    let a = &lut.axes;
    let (cos_o, n, alpha) = (a.texel_cos_theta(x), a.texel_ior(k), a.texel_alpha(al));
    let d = a.texel_thickness_nm(x, y, k, al);
    let m = |s: &str| Material::parse_index(s).unwrap();
    let stack = Stack::new(
        m("1.0"),
        vec![Layer {
            material: m(&format!("{n}")),
            thickness_nm: d,
        }],
        m("1.5"),
    )
    .unwrap();
    let kern = kernels(cos_o, alpha, Some(1.5), KERNEL_COS_NODES);
    let rule = SpectralRule::new(&srgb(), stack.max_opd_nm(None));
    let mut e = [0.0; 6];
    for j in 0..KERNEL_COS_NODES {
        let c = kernel_cos(j, KERNEL_COS_NODES).max(MIN_COS_THETA);
        let f = stack
            .colours_over_thickness(1, c.acos().to_degrees(), &rule, &[d])
            .unwrap();
        for ch in 0..3 {
            e[ch] += kern.reflection[j] * f.reflectance[0][ch];
            e[3 + ch] += kern.transmission[j] * f.transmittance[0][ch];
        }
    }
    let got = lut.reflectance.texel(x, y, al * a.ior_count + k);
    for ch in 0..3 {
        assert!(
            (f64::from(got[ch]) - e[ch]).abs() < 1e-5,
            "{got:?} vs {e:?}"
        );
    }
}

/// (d) Bad recipes: errors name the file and the line.
/// A re-bake without PNGs removes the PNGs of an earlier bake from the output folder
/// (they were left behind, no longer listed by the manifest).
#[test]
fn rebake_without_png_removes_the_earlier_pngs() {
    let dir = tempfile::tempdir().unwrap();
    let recipe = dir.path().join("tiny.toml");
    let text = "kind = \"rough-film-lut\"\n[stack]\nambient = \"1.0\"\nbase = \"1.5\"\n[axes]\ncos_theta_count = 3\nthickness_nm = [0.0, 300.0]\nopd_count = 4\nfilm_ior = [1.0, 2.0]\nfilm_ior_count = 2\nalpha = [0.1, 1.0]\nalpha_count = 2\n[output]\ntransmittance = false\n";
    let out = dir.path().join("out");
    std::fs::write(&recipe, format!("{text}png = true\n")).unwrap();
    crate::kinds::read_recipe(&recipe)
        .unwrap()
        .bake(&out, &|| {})
        .unwrap();
    let png = out.join("tiny.reflectance.png");
    assert!(png.exists());
    std::fs::write(&recipe, text).unwrap();
    crate::kinds::read_recipe(&recipe)
        .unwrap()
        .bake(&out, &|| {})
        .unwrap();
    assert!(!png.exists(), "the earlier bake's PNG is left behind");
}

#[test]
fn bad_recipes_name_file_and_line() {
    let good = "kind = \"rough-film-lut\"\n[stack]\nambient = \"1.0\"\nbase = \"1.5\"\n[axes]\ncos_theta_count = 4\nthickness_nm = [0.0, 500.0]\nopd_count = 8\nfilm_ior = [1.0, 2.0]\nfilm_ior_count = 3\nalpha = [0.05, 1.0]\nalpha_count = 3\n";
    let path = Path::new("dir/rough.toml");
    let parsed = RoughRecipe::parse(path, good.to_string()).unwrap();
    assert_eq!(parsed.name, "rough");
    assert_eq!(parsed.job.axes.base_eta, Some(1.5));
    for (from, to, want) in [
        (
            "alpha = [0.05, 1.0]",
            "alpha = [0.0, 1.0]",
            "dir/rough.toml:5",
        ),
        ("alpha_count = 3", "alpha_count = 1", "dir/rough.toml:5"),
        ("opd_count = 8", "opd_count = 1", "dir/rough.toml:5"),
        (
            "film_ior = [1.0, 2.0]",
            "film_ior = [0.5, 2.0]",
            "dir/rough.toml:5",
        ),
        (
            "alpha_count = 3",
            "alpha_count = 3\nbogus = 1",
            "dir/rough.toml:13",
        ),
        (
            "base = \"1.5\"",
            "base = \"unobtainium\"",
            "dir/rough.toml:4",
        ),
        ("ambient = \"1.0\"", "ambient = \"au\"", "dir/rough.toml:3"),
        (
            "alpha_count = 3",
            "alpha_count = 100000000",
            "dir/rough.toml:5",
        ),
    ] {
        let text = good.replace(from, to);
        let e = RoughRecipe::parse(path, text).err().expect(to).to_string();
        assert!(e.contains(want), "{to}: {e}");
    }
    // Transmittance through an absorbing base is refused at the base's line.
    let text =
        good.replace("base = \"1.5\"", "base = \"0.2+3i\"") + "[output]\ntransmittance = true\n";
    let e = RoughRecipe::parse(path, text).err().unwrap().to_string();
    assert!(
        e.contains("dir/rough.toml:4") && e.contains("non-absorbing"),
        "{e}"
    );
    // The kind dispatch reaches this parser.
    let any = crate::kinds::parse_recipe(path, good.to_string()).unwrap();
    assert_eq!(any.name(), "rough");
}
