//! The `diffraction` technique for layout "integrated" (`nacre_runtime::diffraction_integrated`,
//! `shaders/diffraction_integrated.wgsl`):
//!
//! * GPU = CPU: the compute probe against `IntegratedTable::colour` of the table the loader
//!   read (the shader-style CPU evaluation of `nacre_optics::diffraction::integrated`), for
//!   the default set's `cd-tracks-fast`: in-plane sweeps across the first orders of the
//!   1.6 µm tracks, the baker's own check directions (off-plane views and views 0.02°–1°
//!   from the specular direction), directions beyond the table's 45°, and two Fresnel
//!   indices;
//! * the terms technique's consumers (`diffraction_scene.wgsl`'s probe entry point) run on
//!   the integrated table through the adapter, with the uniform's F²;
//! * the GPU colours stay within the baker's tolerance of the exact terms-layout colours of
//!   the same surface (`cd-tracks`) weighted by Stam's (555 nm/λ)² (the table's k²), and the
//!   specular colour (the unweighted zeroth-order layers) within 10⁻³ of the white of the
//!   zeroth order's |P_DC|²;
//! * a table baked before the k² (a manifest without `k_squared_reference_nm`) still loads,
//!   renders as before (its own peak as the mirror image) and is marked as lacking it;
//! * bad directions and Fresnel inputs (NaN, ±∞, huge, zero, below the horizon) give finite
//!   colours;
//! * the loader checks kind, layout and SHA-256;
//! * naga validates and translates the module, its probe, and the module + adapter + the
//!   terms technique's scene consumer (no GPU needed).
//!
//! A missing adapter fails the GPU tests: they never skip.

use nacre_format::set::default_baked_dir;
use nacre_optics::C64;
use nacre_optics::diffraction::integrated::check_directions;
use nacre_optics::diffraction::{
    DiffractionSurface, FresnelTerm, SpectralGrid, in_plane_directions,
};
use nacre_runtime::diffraction::LOBE_REFERENCE_NM;
use nacre_runtime::diffraction_integrated::{
    DiffractionIntegrated, DiffractionIntegratedUniform, ProbeCase, WGSL, compose_probe,
    compose_scene, run_probe, run_scene_probe,
};
use rayon::prelude::*;
use std::sync::OnceLock;

mod support;
use support::{ctx, translate, validate};

/// Largest GPU − CPU difference allowed, in units of the specular white per channel, scaled
/// by (1 + |CPU value| / white) so that the large values of grazing directions are compared
/// relatively. Both sides read the same f32 texels with the same bilinear weights and the
/// same f32 Horner order; what differs is f32 (GPU) against f64 (CPU) in the directions,
/// the warped coordinates (pow in f32) and G/w², and fused multiply-adds. Measured on Mesa
/// lavapipe (llvmpipe 15, x86-64): 2.7 · 10⁻⁶.
const TOLERANCE: f64 = 1e-4;

fn technique() -> &'static DiffractionIntegrated {
    static T: OnceLock<DiffractionIntegrated> = OnceLock::new();
    T.get_or_init(|| {
        DiffractionIntegrated::load(
            ctx(),
            &default_baked_dir().join("cd-tracks-fast.json"),
            FresnelTerm::Unity,
        )
        .unwrap()
    })
}

/// The table's wavelength grid (the one summed into it).
fn grid(t: &DiffractionIntegrated) -> SpectralGrid {
    let r = &t.record;
    let count = ((r.wavelength_max_nm - r.wavelength_min_nm) / r.wavelength_step_nm).round();
    let wavelengths: Vec<f64> = (0..=count as usize)
        .map(|i| r.wavelength_min_nm + i as f64 * r.wavelength_step_nm)
        .collect();
    SpectralGrid::new(&t.colorimeter().unwrap(), &wavelengths).unwrap()
}

/// The colour of ρ ≡ 1 (a flat perfect mirror in its specular direction) per output channel.
fn white(t: &DiffractionIntegrated) -> [f64; 3] {
    let grid = grid(t);
    let ones = vec![1.0; grid.wavelengths_nm().len()];
    t.colorimeter().unwrap().output_from_xyz(grid.xyz(&ones))
}

fn unit(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    [st * cp, st * sp, ct]
}

fn f32s(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// The Fresnel term as the shader receives it (f32 index).
fn rounded(f: FresnelTerm) -> FresnelTerm {
    match f {
        FresnelTerm::Unity => FresnelTerm::Unity,
        FresnelTerm::Index(n) => {
            FresnelTerm::Index(C64::new(f64::from(n.re as f32), f64::from(n.im as f32)))
        }
    }
}

/// The CPU twin of one probe case's filtered colour
/// (`IntegratedLevels::colour_filtered` of the loaded levels).
fn cpu_filtered(t: &DiffractionIntegrated, c: &ProbeCase) -> [f64; 3] {
    t.levels.colour_filtered(
        c.omega_i.map(f64::from),
        c.omega_r.map(f64::from),
        rounded(c.fresnel),
        c.sigma_uv,
        c.slope_variance,
    )
}

/// The CPU twin of one probe case: (colour, specular colour).
fn cpu(t: &DiffractionIntegrated, c: &ProbeCase) -> ([f64; 3], [f64; 3]) {
    let f = rounded(c.fresnel);
    let colour = t
        .table
        .colour(c.omega_i.map(f64::from), c.omega_r.map(f64::from), f);
    let cos = f64::from(c.cos_theta);
    let s = f.reflectance(cos);
    let specular = t.table.specular_sum(-2.0 * cos).map(|x| s * x);
    (colour, specular)
}

#[test]
fn gpu_matches_the_cpu_evaluation() {
    let t = technique();
    assert_eq!(
        t.texel_loads_per_call(),
        4 * (2 * t.record.taylor_order + 1)
    );
    let white = white(t);
    // The filtered call of every case at one of a cycle of spreads: no filter, σ_uv from
    // below level 1 (σ₁ = u_max/256 = 0.0055) to beyond the last level (u_max), alone and
    // with the facets of GGX α = 0.05 and 0.3 (σ_m² = α²/2).
    let mut counter = 0usize;
    let mut case = |wi: [f64; 3], wr: [f64; 3], fresnel: FresnelTerm| {
        const SIGMA: [f32; 7] = [0.0, 0.002, 0.0055, 0.013, 0.05, 0.2, 2.0];
        const SLOPES: [f32; 3] = [0.0, 0.00125, 0.045];
        counter += 1;
        ProbeCase {
            omega_i: f32s(wi),
            omega_r: f32s(wr),
            fresnel,
            cos_theta: wr[2] as f32,
            sigma_uv: SIGMA[counter % SIGMA.len()],
            slope_variance: SLOPES[(counter / SIGMA.len()) % SLOPES.len()],
        }
    };
    let mut cases = Vec::new();
    // In-plane sweeps across the lines, −45° … 45° every 0.25°.
    for incidence in [0.0, 20.0, 40.0] {
        for i in 0..=360 {
            let (wi, wr) = in_plane_directions(incidence, -45.0 + 0.25 * f64::from(i));
            cases.push(case(wi, wr, FresnelTerm::Unity));
        }
    }
    // The peaks of orders m = ±1, ±2 (sin θ_r = sin θ_i − mλ/d, d = 1.6 µm).
    let first_orders = cases.len();
    for incidence in [0.0f64, 20.0] {
        for wavelength_um in [0.45, 0.55, 0.65] {
            for m in [-2.0, -1.0, 1.0, 2.0] {
                let s = incidence.to_radians().sin() - m * wavelength_um / 1.6;
                if s.abs() < 45f64.to_radians().sin() {
                    let (wi, wr) = in_plane_directions(incidence, s.asin().to_degrees());
                    cases.push(case(wi, wr, FresnelTerm::Unity));
                }
            }
        }
    }
    let orders = first_orders..cases.len();
    // The baker's check directions: off-plane grid, the specular view and views 0.02°–1°
    // from it, in-plane sweeps along and across the lines.
    let checks = check_directions(t.record.max_angle_deg);
    for &(wi, wr) in &checks {
        cases.push(case(wi, wr, FresnelTerm::Unity));
    }
    // Beyond θ_max = 45° (clamp to edge on both sides): views up to 85°, a light at 60°.
    for view in (46..=85).step_by(3) {
        for phi in [0.0, 40.0, 90.0, 180.0] {
            cases.push(case(
                unit(30.0, 180.0),
                unit(f64::from(view), phi),
                FresnelTerm::Unity,
            ));
            cases.push(case(
                unit(60.0, 200.0),
                unit(f64::from(view) - 40.0, phi),
                FresnelTerm::Unity,
            ));
        }
    }
    // Fresnel: keratin (n = 1.56) and an aluminium-like metal (0.96 + 6.69i at 550 nm).
    for fresnel in [
        FresnelTerm::Index(C64::new(1.56, 0.0)),
        FresnelTerm::Index(C64::new(0.96, 6.69)),
    ] {
        for &(wi, wr) in checks.iter().step_by(7) {
            cases.push(case(wi, wr, fresnel));
        }
    }
    let gpu = run_probe(ctx(), t, &cases).unwrap();
    assert_eq!(gpu.len(), cases.len());
    let mut worst = (0.0f64, 0usize, "");
    let mut largest = 0.0f64;
    let mut order_peak = 0.0f64;
    for (i, (c, g)) in cases.iter().zip(&gpu).enumerate() {
        let (colour, specular) = cpu(t, c);
        for (what, expected, got) in [
            ("colour", colour, g.colour),
            ("specular", specular, g.specular),
            ("filtered", cpu_filtered(t, c), g.filtered),
        ] {
            for ch in 0..3 {
                let e = expected[ch] / white[ch];
                let d = (f64::from(got[ch]) / white[ch] - e).abs() / (1.0 + e.abs());
                assert!(
                    d.is_finite(),
                    "case {i} {c:?}: GPU {got:?}, CPU {expected:?}"
                );
                if d > worst.0 {
                    worst = (d, i, what);
                }
                largest = largest.max(e.abs());
                if what == "colour" && orders.contains(&i) {
                    order_peak = order_peak.max(e.abs());
                }
            }
        }
    }
    let (d, i, what) = worst;
    eprintln!(
        "{} cases: worst GPU − CPU {d:.3e} of the white ({what}, case {i}: {:?}); largest value {largest:.3} white; brightest order peak {order_peak:.3e} white",
        cases.len(),
        cases[i]
    );
    assert!(
        d <= TOLERANCE,
        "GPU − CPU {d:.3e} > {TOLERANCE} at case {i} ({what}): {:?}, GPU {:?}, CPU {:?}",
        cases[i],
        gpu[i],
        cpu(t, &cases[i])
    );
    // The comparison covers bright values: the mirror lobe and the diffraction orders.
    assert!(largest > 0.5, "largest value {largest}");
    assert!(order_peak > 1e-3, "brightest order peak {order_peak}");
}

/// The terms technique's consumers (`diffraction_scene.wgsl`'s probe entry point, through
/// the adapter) run on the integrated table and give the same colours, with the uniform's F².
#[test]
fn the_terms_consumers_run_on_the_integrated_table() {
    let keratin = FresnelTerm::Index(C64::new(1.56, 0.0));
    let t = DiffractionIntegrated::load(
        ctx(),
        &default_baked_dir().join("cd-tracks-fast.json"),
        keratin,
    )
    .unwrap();
    assert_eq!(
        (t.uniform.fresnel_kind, t.uniform.fresnel_ior),
        (1, [1.56, 0.0])
    );
    let white = white(&t);
    let mut pairs = Vec::new();
    for i in 0..=180 {
        let (wi, wr) = in_plane_directions(30.0, -45.0 + 0.5 * f64::from(i));
        pairs.push((f32s(wi), f32s(wr)));
        pairs.push((
            f32s(unit(25.0, 150.0)),
            f32s(unit(0.25 * f64::from(i), 2.0 * f64::from(i))),
        ));
    }
    let out = run_scene_probe(ctx(), &t, &pairs).unwrap();
    let mut worst = 0.0f64;
    for (&(wi, wr), o) in pairs.iter().zip(&out) {
        let (colour, specular) = cpu(
            &t,
            &ProbeCase {
                omega_i: wi,
                omega_r: wr,
                fresnel: keratin,
                cos_theta: wr[2],
                sigma_uv: 0.0,
                slope_variance: 0.0,
            },
        );
        for ch in 0..3 {
            for (e, g) in [(colour[ch], o.colour[ch]), (specular[ch], o.specular[ch])] {
                let e = e / white[ch];
                worst = worst.max((f64::from(g) / white[ch] - e).abs() / (1.0 + e.abs()));
            }
        }
    }
    eprintln!("scene probe through the adapter: worst GPU − CPU {worst:.3e} of the white");
    assert!(worst <= TOLERANCE, "{worst:.3e}");
}

/// The GPU colours of the integrated table against the exact colours of the terms layout of
/// the same surface (`cd-tracks`, f64 CPU evaluation at the same N and wavelength grid): the
/// fast path's whole error (interpolation, f32 storage and sum, f32 on the GPU) stays within
/// the tolerance the baker held the table to.
#[test]
fn gpu_matches_the_terms_layout_within_the_baked_tolerance() {
    let t = technique();
    let terms_path = default_baked_dir().join("cd-tracks.json");
    let m = nacre_format::Manifest::read(&terms_path).unwrap();
    let (record, terms) = m.load_diffraction(&terms_path).unwrap();
    for (a, b) in [
        (record.sigma_s_um, t.record.sigma_s_um),
        (record.pitch_um, t.record.pitch_um),
        (record.wavelength_step_nm, t.record.wavelength_step_nm),
        (record.max_angle_deg, t.record.max_angle_deg),
    ] {
        assert_eq!(
            a, b,
            "cd-tracks and cd-tracks-fast describe the same surface"
        );
    }
    assert_eq!(
        (record.nx, record.taylor_order),
        (t.record.nx, t.record.taylor_order)
    );
    // The table holds Stam's k² relative to 555 nm (issue 37): the exact colour weighs each
    // wavelength by (555 nm/λ)², as the terms technique's scenes do.
    assert_eq!(
        t.integrated.k_squared_reference_nm,
        Some(LOBE_REFERENCE_NM),
        "cd-tracks-fast is baked with Stam's k²"
    );
    assert_eq!(t.table.k_squared_reference_nm(), Some(LOBE_REFERENCE_NM));
    let surface = DiffractionSurface::new(terms, record.sigma_s_um).unwrap();
    let grid = grid(t);
    let colorimeter = t.colorimeter().unwrap();
    let white = white(t);
    // The baker's units: the white with the table's k² weight (like with like).
    let weighted_white = t.table.white(&grid, &colorimeter);
    let mut pairs = Vec::new();
    for incidence in [0.0, 20.0, 40.0] {
        for i in 0..=180 {
            pairs.push(in_plane_directions(incidence, -45.0 + 0.5 * f64::from(i)));
        }
    }
    for i in 0..120 {
        let a = f64::from(i);
        pairs.push((
            unit(35.0 * (a / 120.0), 170.0 + a),
            unit((a * 7.3) % 44.0, a * 37.0),
        ));
    }
    let cases: Vec<ProbeCase> = pairs
        .iter()
        .map(|&(wi, wr)| ProbeCase {
            omega_i: f32s(wi),
            omega_r: f32s(wr),
            fresnel: FresnelTerm::Unity,
            cos_theta: 1.0,
            sigma_uv: 0.0,
            slope_variance: 0.0,
        })
        .collect();
    let gpu = run_probe(ctx(), t, &cases).unwrap();
    let exact: Vec<[f64; 3]> = cases
        .par_iter()
        .map(|c| {
            let (wi, wr) = (c.omega_i.map(f64::from), c.omega_r.map(f64::from));
            let rho: Vec<f64> = grid
                .wavelengths_nm()
                .iter()
                .map(|&l| {
                    (LOBE_REFERENCE_NM / l).powi(2)
                        * surface.relative_reflectance(wi, wr, l, FresnelTerm::Unity)
                })
                .collect();
            colorimeter.output_from_xyz(grid.xyz(&rho))
        })
        .collect();
    let (mut worst, mut at, mut sum) = (0.0f64, 0, 0.0);
    for (i, (g, e)) in gpu.iter().zip(&exact).enumerate() {
        let d = (0..3)
            .map(|ch| (f64::from(g.colour[ch]) - e[ch]).abs() / weighted_white[ch])
            .fold(0.0, f64::max);
        sum += d;
        if d > worst {
            (worst, at) = (d, i);
        }
    }
    let s = t.integrated.clone();
    eprintln!(
        "GPU integrated vs exact terms layout over {} pairs: worst {worst:.3e} of the white at {:?} (GPU {:?}, exact {:?}), mean {:.3e}; the baker measured {:.3e} (tolerance {})",
        cases.len(),
        cases[at],
        gpu[at].colour,
        exact[at],
        sum / cases.len() as f64,
        s.reconstruction_error,
        s.tolerance
    );
    assert!(worst <= s.tolerance, "{worst:.3e} > {}", s.tolerance);
    // The specular colour (mirror-lobe peak, the colour of |P̃(0, 0)|²) against the zeroth
    // order's efficiency |P_DC|² that the terms technique's
    // `diffraction_specular_order_colour` gives: they differ by the window-weighted bins
    // next to DC, which the adapter's substitute must keep below 10⁻³ of the white for the CD
    // (measured 1.4 · 10⁻⁴ for cos θ = 0.7 … 1).
    let (nx, ny) = surface.terms().size();
    let dc = (ny / 2) * nx + nx / 2;
    let dc_terms: Vec<C64> = (0..=surface.terms().order())
        .map(|n| surface.terms().layer(n)[dc])
        .collect();
    let mut worst_specular = 0.0f64;
    for i in 0..=20 {
        let cos = 0.7 + 0.015 * f64::from(i);
        let p2: Vec<f64> = grid
            .wavelengths_nm()
            .iter()
            .map(|&l| {
                let kw = -2.0 * cos * 2.0 * std::f64::consts::PI / (l * 1e-3);
                let (mut p, mut term) = (C64::new(0.0, 0.0), 1.0);
                for (n, t) in dc_terms.iter().enumerate() {
                    if n > 0 {
                        term *= kw / n as f64;
                    }
                    p += t * term;
                }
                p.norm_sqr()
            })
            .collect();
        let order = colorimeter.output_from_xyz(grid.xyz(&p2));
        // The zeroth order's layers, unweighted: the mirror image has no k².
        let lobe = t.table.specular_sum(-2.0 * cos);
        for ch in 0..3 {
            worst_specular = worst_specular.max((lobe[ch] - order[ch]).abs() / white[ch]);
        }
    }
    eprintln!("specular colour vs |P_DC|² colour: worst {worst_specular:.3e} of the white");
    assert!(worst_specular <= 1e-3, "{worst_specular:.3e}");
}

#[test]
fn bad_inputs_give_finite_colours() {
    let t = technique();
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let good_i = [-0.3f32, 0.1, 0.9];
    let good_r = [0.4f32, 0.0, 0.8];
    let bad_dirs: [[f32; 3]; 10] = [
        [nan, 0.0, 1.0],
        [0.0, nan, 1.0],
        [0.0, 0.0, nan],
        [inf, 0.0, 1.0],
        [0.0, 0.0, -inf],
        [0.0, 0.0, 0.0],
        [0.3, 0.0, -0.9],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [-inf, inf, inf],
    ];
    let mut cases = Vec::new();
    for d in bad_dirs {
        for (wi, wr) in [(d, good_r), (good_i, d), (d, d)] {
            cases.push(ProbeCase {
                omega_i: wi,
                omega_r: wr,
                fresnel: FresnelTerm::Unity,
                cos_theta: d[2],
                sigma_uv: 0.0,
                slope_variance: 0.0,
            });
        }
    }
    let zero_count = cases.len();
    // Bad Fresnel inputs and cos θ outside (0, 1]: finite, not necessarily zero.
    for (ior, cos) in [
        ([nan, 0.0], 0.5),
        ([1.5, nan], nan),
        ([-1.0, -2.0], -0.5),
        ([0.0, 0.0], 2.0),
        ([1e30, 1e30], 1e-30),
        ([inf, 0.0], inf),
    ] {
        cases.push(ProbeCase {
            omega_i: good_i,
            omega_r: good_r,
            fresnel: FresnelTerm::Index(C64::new(f64::from(ior[0]), f64::from(ior[1]))),
            cos_theta: cos,
            sigma_uv: 0.0,
            slope_variance: 0.0,
        });
    }
    // Bad spreads for the filtered call (NaN, negative, infinite): finite.
    for (sigma_uv, slope_variance) in [
        (nan, 0.0),
        (0.0, nan),
        (-1.0, -1.0),
        (inf, 0.0),
        (0.0, inf),
        (-inf, nan),
        (3e38, 3e38),
    ] {
        cases.push(ProbeCase {
            omega_i: good_i,
            omega_r: good_r,
            fresnel: FresnelTerm::Unity,
            cos_theta: 0.8,
            sigma_uv,
            slope_variance,
        });
    }
    // Huge and tiny but valid directions: the unit vector's colour.
    let scaled = cases.len();
    for s in [1e30f32, 1e-30, 3e38] {
        cases.push(ProbeCase {
            omega_i: good_i.map(|x| x * s),
            omega_r: good_r.map(|x| x * s),
            fresnel: FresnelTerm::Unity,
            cos_theta: 0.8,
            sigma_uv: 0.0,
            slope_variance: 0.0,
        });
    }
    let out = run_probe(ctx(), t, &cases).unwrap();
    for (c, o) in cases.iter().zip(&out) {
        for v in o.colour.iter().chain(&o.specular).chain(&o.filtered) {
            assert!(v.is_finite(), "{c:?} gave {o:?}");
        }
    }
    for (c, o) in cases[..zero_count].iter().zip(&out) {
        assert_eq!(
            o.colour, [0.0; 3],
            "{c:?} is at or below the horizon or not finite"
        );
    }
    let reference = t.table.colour(
        good_i.map(f64::from),
        good_r.map(f64::from),
        FresnelTerm::Unity,
    );
    let norm = |v: [f32; 3]| {
        let l = v.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>().sqrt();
        v.map(|x| f64::from(x) / l)
    };
    let unit_reference = t
        .table
        .colour(norm(good_i), norm(good_r), FresnelTerm::Unity);
    assert!(reference.iter().any(|x| x.abs() > 1e-6), "{reference:?}");
    for (c, o) in cases[scaled..].iter().zip(&out[scaled..]) {
        for ch in 0..3 {
            let d = (f64::from(o.colour[ch]) - unit_reference[ch]).abs();
            assert!(
                d <= 1e-4 * (1.0 + unit_reference[ch].abs()),
                "{c:?}: {o:?} vs {unit_reference:?}"
            );
        }
    }
}

#[test]
fn the_loader_checks_kind_layout_and_sha256() {
    let dir = default_baked_dir();
    let terms = DiffractionIntegrated::load(ctx(), &dir.join("cd-tracks.json"), FresnelTerm::Unity)
        .err()
        .expect("a terms table is refused")
        .to_string();
    assert!(
        terms.contains("\"terms\"") && terms.contains("\"integrated\""),
        "{terms}"
    );
    let other = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.extension().is_some_and(|e| e == "json")
                && std::fs::read_to_string(p).is_ok_and(|s| s.contains("\"kind\": \"film-lut\""))
        })
        .expect("the default set has a film-lut table");
    let e = DiffractionIntegrated::load(ctx(), &other, FresnelTerm::Unity)
        .err()
        .expect("a film-lut table is refused")
        .to_string();
    assert!(e.contains("not a `diffraction` table"), "{e}");
    let e = DiffractionIntegrated::load(
        ctx(),
        &dir.join("cd-tracks-fast.json"),
        FresnelTerm::Index(C64::new(f64::NAN, 0.0)),
    )
    .err()
    .expect("a NaN index is refused")
    .to_string();
    assert!(e.contains("Fresnel"), "{e}");
    // A tampered file.
    let tmp = tempfile::tempdir().unwrap();
    for name in [
        "cd-tracks-fast.json",
        "cd-tracks-fast.integrated.exr",
        "cd-tracks-fast.integrated.ktx2",
    ] {
        std::fs::copy(dir.join(name), tmp.path().join(name)).unwrap();
    }
    let ktx2 = tmp.path().join("cd-tracks-fast.integrated.ktx2");
    let mut bytes = std::fs::read(&ktx2).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&ktx2, bytes).unwrap();
    let e = DiffractionIntegrated::load(
        ctx(),
        &tmp.path().join("cd-tracks-fast.json"),
        FresnelTerm::Unity,
    )
    .err()
    .expect("a tampered file is refused")
    .to_string();
    assert!(
        e.contains("SHA-256") && e.contains("cd-tracks-fast.integrated.ktx2"),
        "{e}"
    );
}

/// A table baked before Stam's k² (a manifest without `k_squared_reference_nm` and
/// `zeroth_order_layers`: here the default table's manifest with both removed) still loads
/// and renders as it did: marked as lacking the k², the light's gain at 555 nm, and the
/// mirror image its own layers' peak (GPU = CPU).
#[test]
fn a_table_baked_without_k_squared_still_loads_and_renders() {
    let dir = default_baked_dir();
    let tmp = tempfile::tempdir().unwrap();
    for name in [
        "cd-tracks-fast.integrated.exr",
        "cd-tracks-fast.integrated.ktx2",
    ] {
        std::fs::copy(dir.join(name), tmp.path().join(name)).unwrap();
    }
    let text = std::fs::read_to_string(dir.join("cd-tracks-fast.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let integrated = json["diffraction"]["integrated"].as_object_mut().unwrap();
    assert!(integrated.remove("k_squared_reference_nm").is_some());
    assert!(integrated.remove("zeroth_order_layers").is_some());
    let path = tmp.path().join("cd-tracks-fast.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    let old = DiffractionIntegrated::load(ctx(), &path, FresnelTerm::Unity).unwrap();
    let new = technique();
    assert_eq!(old.integrated.k_squared_reference_nm, None);
    assert_eq!(old.table.k_squared_reference_nm(), None);
    assert_eq!(old.table.values(), new.table.values());
    assert_eq!(
        nacre_runtime::diffraction::lobe_gain(&old.record),
        nacre_runtime::diffraction::lobe_gain(&new.record),
        "555 nm either way"
    );
    // Its mirror image is its own layers' peak, as before the k²; the new table's differs
    // (unweighted Jₚ against the weighted layers).
    let cases: Vec<ProbeCase> = (0..=10)
        .map(|i| ProbeCase {
            omega_i: [0.0, 0.0, 1.0],
            omega_r: [0.0, 0.0, 1.0],
            fresnel: FresnelTerm::Unity,
            cos_theta: 0.5 + 0.05 * i as f32,
            sigma_uv: 0.0,
            slope_variance: 0.0,
        })
        .collect();
    let out = run_probe(ctx(), &old, &cases).unwrap();
    let white = white(&old);
    let (mut worst, mut apart) = (0.0f64, 0.0f64);
    for (c, o) in cases.iter().zip(&out) {
        let w = -2.0 * f64::from(c.cos_theta);
        let peak = old.table.sum_at(0.0, 0.0, w);
        let unweighted = new.table.specular_sum(w);
        for ch in 0..3 {
            let e = (f64::from(o.specular[ch]) - peak[ch]).abs() / white[ch];
            worst = worst.max(e / (1.0 + (peak[ch] / white[ch]).abs()));
            apart = apart.max((peak[ch] - unweighted[ch]).abs() / white[ch]);
        }
    }
    eprintln!(
        "table without k²: mirror image GPU − CPU peak {worst:.2e} of the white; the k² layers' peak is {apart:.3} of the white from the unweighted zeroth order"
    );
    assert!(worst <= TOLERANCE, "{worst:.3e}");
    assert!(apart > 0.05, "{apart}");
}

#[test]
fn the_shaders_validate_and_translate() {
    // The probe.
    let (module, info) = validate("diffraction_integrated + probe", &compose_probe(), "");
    translate("diffraction_integrated + probe", &module, &info);
    assert!(
        module
            .entry_points
            .iter()
            .any(|e| e.name == "diffraction_integrated_probe")
    );
    // The uniform's documented layout, which the #[repr(C)] mirror reproduces.
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("DiffractionIntegratedParams"))
        .expect("DiffractionIntegratedParams declared");
    let naga::TypeInner::Struct { ref members, span } = ty.inner else {
        panic!("DiffractionIntegratedParams is not a struct");
    };
    assert_eq!(
        span as usize,
        std::mem::size_of::<DiffractionIntegratedUniform>()
    );
    let offsets: Vec<u32> = members.iter().map(|m| m.offset).collect();
    assert_eq!(offsets, [0, 8, 12, 16, 20, 24, 32, 36, 40, 44]);
    // The terms technique's consumers (scenes, bench, probe) through the adapter.
    let (module, info) = validate(
        "diffraction_integrated + adapter + scene",
        &compose_scene(),
        "",
    );
    translate("diffraction_integrated + adapter + scene", &module, &info);
    for entry in [
        "diffraction_vs",
        "diffraction_scene_fs",
        "diffraction_probe",
    ] {
        assert!(
            module.entry_points.iter().any(|e| e.name == entry),
            "{entry} missing"
        );
    }
    // The module alone, with a consumer that binds nothing: group 1 only.
    let consumer = "
@fragment
fn fs_bindingless(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let frame = diffraction_frame(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0));
    let c = diffraction_integrated_colour(frame * vec3<f32>(-0.3, 0.0, 0.9), vec3<f32>(p.x, 0.0, 1.0), 1u, vec2<f32>(1.5, 0.0));
    return vec4<f32>(c + diffraction_integrated_specular_colour(p.y, 0u, vec2<f32>(1.0, 0.0)), 1.0);
}
";
    let source = format!("{WGSL}\n{consumer}\n");
    let (module, info) = validate("diffraction_integrated", &source, "");
    translate("diffraction_integrated", &module, &info);
    let mut bound = 0;
    for (_, g) in module.global_variables.iter() {
        if let Some(b) = &g.binding {
            assert_eq!(b.group, 1, "`{:?}` is in group {}", g.name, b.group);
            bound += 1;
        }
    }
    // The uniform, the table and the zeroth order's layers.
    assert_eq!(bound, 3);
}

/// The prefiltered levels the loader adds (issue 37: the footprint filter and rough
/// gratings): how many, their σ ladder, the texture's size against the unfiltered table's,
/// and the time to make them (printed, not asserted: speed is the benchmarks' business).
#[test]
fn the_loader_prefilters_ten_levels_up_to_u_max() {
    use nacre_optics::diffraction::integrated::{INTEGRATED_FILTER_LEVELS, IntegratedLevels};
    let t = technique();
    let count = t.levels.levels().len();
    assert_eq!(count, INTEGRATED_FILTER_LEVELS);
    assert_eq!(t.uniform.levels as usize, count);
    let max_uv = t.table.axis().max_uv;
    assert!((t.levels.sigma(count - 1) - max_uv).abs() < 1e-12);
    assert_eq!(t.uniform.sigma_base_sq, t.levels.sigma_base_sq_f32());
    let (cols, rows) = t.table.size();
    let unfiltered = (cols * rows * t.table.layers() * 16) as u64;
    assert_eq!(t.texture_bytes(), count as u64 * unfiltered);
    let start = std::time::Instant::now();
    let again = IntegratedLevels::new(&t.table, count).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(&again, &t.levels, "the same levels on every load");
    eprintln!(
        "{count} levels, σ₁ = {:.5} … σ_{} = {:.4} (u_max); texture {:.1} MB against {:.1} MB unfiltered; made in {seconds:.2} s",
        t.levels.sigma(1),
        count - 1,
        t.levels.sigma(count - 1),
        t.texture_bytes() as f64 / 1e6,
        unfiltered as f64 / 1e6
    );
}
