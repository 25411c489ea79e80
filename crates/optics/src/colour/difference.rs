//! Colour difference: CIE 1976 L\*a\*b\* and CIEDE2000 (Sharma, Wu & Dalal 2005).

use crate::elementary;

/// CIE 1976 L\*a\*b\* (CIELAB) of `xyz` relative to the reference white `white_xyz` (the
/// same scale, e.g. both with the perfect reflector at Y = 1), per CIE 015:2018:
///
/// ```text
/// L* = 116 f(Y/Yₙ) − 16,   a* = 500 [f(X/Xₙ) − f(Y/Yₙ)],   b* = 200 [f(Y/Yₙ) − f(Z/Zₙ)]
/// f(t) = t^(1/3)                  if t > (24/116)³
///      = (841/108) t + 16/116     otherwise
/// ```
///
/// The white itself gives (100, 0, 0).
pub fn xyz_to_lab(xyz: [f64; 3], white_xyz: [f64; 3]) -> [f64; 3] {
    fn f(t: f64) -> f64 {
        const EPS: f64 = (24.0 / 116.0) * (24.0 / 116.0) * (24.0 / 116.0);
        if t > EPS {
            elementary::cbrt(t)
        } else {
            841.0 / 108.0 * t + 16.0 / 116.0
        }
    }
    let fx = f(xyz[0] / white_xyz[0]);
    let fy = f(xyz[1] / white_xyz[1]);
    let fz = f(xyz[2] / white_xyz[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The CIEDE2000 colour difference ΔE₀₀ between two CIELAB colours, with the
/// parametric factors k_L = k_C = k_H = 1 (CIE 142-2001), computed as in G. Sharma,
/// W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation notes,
/// supplementary test data, and mathematical observations", *Color Res. Appl.* **30**,
/// 21–30 (2005), doi:10.1002/col.20070 (their step-by-step implementation):
///
/// ```text
/// C*ᵢ = √(a*ᵢ² + b*ᵢ²),  C̄* = (C*₁ + C*₂)/2,  G = ½ (1 − √(C̄*⁷ / (C̄*⁷ + 25⁷)))
/// a′ᵢ = (1 + G) a*ᵢ,  C′ᵢ = √(a′ᵢ² + b*ᵢ²),  h′ᵢ = atan2(b*ᵢ, a′ᵢ) ∈ [0°, 360°)
/// ΔL′ = L*₂ − L*₁,  ΔC′ = C′₂ − C′₁,  ΔH′ = 2 √(C′₁C′₂) sin(Δh′/2)
/// Δh′ = h′₂ − h′₁ brought into [−180°, 180°] (0 if C′₁C′₂ = 0)
/// L̄′ = (L*₁ + L*₂)/2,  C̄′ = (C′₁ + C′₂)/2,  h̄′ = mean hue (h′₁ + h′₂ if C′₁C′₂ = 0)
/// T = 1 − 0.17 cos(h̄′ − 30°) + 0.24 cos(2h̄′) + 0.32 cos(3h̄′ + 6°) − 0.20 cos(4h̄′ − 63°)
/// Δθ = 30° exp(−((h̄′ − 275°)/25°)²),  R_C = 2 √(C̄′⁷ / (C̄′⁷ + 25⁷))
/// S_L = 1 + 0.015 (L̄′ − 50)² / √(20 + (L̄′ − 50)²),  S_C = 1 + 0.045 C̄′,  S_H = 1 + 0.015 C̄′ T
/// R_T = −sin(2Δθ) R_C
/// ΔE₀₀ = √((ΔL′/S_L)² + (ΔC′/S_C)² + (ΔH′/S_H)² + R_T (ΔC′/S_C)(ΔH′/S_H))
/// ```
///
/// The mean hue is (h′₁ + h′₂)/2 when |h′₁ − h′₂| ≤ 180°, and otherwise that ± 180°,
/// brought into [0°, 360°). Hue angles that are exactly opposite (such as pair 14 of
/// Sharma's Table 1) can come out of atan2 an ulp away from a 180° difference, which
/// would flip the mean hue by 180° depending on the platform's libm. So differences
/// within 10⁻⁹° of 180° count as exactly 180°, the ≤ branch of the paper.
pub fn delta_e_2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    const POW25_7: f64 = 6_103_515_625.0; // 25⁷
    const TIE_DEG: f64 = 180.0 + 1e-9;
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let c_bar = 0.5 * (elementary::hypot(a1, b1) + elementary::hypot(a2, b2));
    let c_bar7 = elementary::powi(c_bar, 7);
    let g = 0.5 * (1.0 - (c_bar7 / (c_bar7 + POW25_7)).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = (elementary::hypot(a1p, b1), elementary::hypot(a2p, b2));
    let hue = |b: f64, ap: f64| {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            let h = elementary::atan2(b, ap).to_degrees();
            if h < 0.0 { h + 360.0 } else { h }
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));
    let chroma_product = c1p * c2p;

    let dl = l2 - l1;
    let dc = c2p - c1p;
    let dh_deg = if chroma_product == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d.abs() <= TIE_DEG {
            d
        } else if d > 0.0 {
            d - 360.0
        } else {
            d + 360.0
        }
    };
    let dh_big = 2.0 * chroma_product.sqrt() * elementary::sin((0.5 * dh_deg).to_radians());

    let l_bar = 0.5 * (l1 + l2);
    let c_bar_p = 0.5 * (c1p + c2p);
    let h_bar = if chroma_product == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= TIE_DEG {
        0.5 * (h1p + h2p)
    } else if h1p + h2p < 360.0 {
        0.5 * (h1p + h2p + 360.0)
    } else {
        0.5 * (h1p + h2p - 360.0)
    };
    let cos_deg = |deg: f64| elementary::cos(deg.to_radians());
    let t = 1.0 - 0.17 * cos_deg(h_bar - 30.0)
        + 0.24 * cos_deg(2.0 * h_bar)
        + 0.32 * cos_deg(3.0 * h_bar + 6.0)
        - 0.20 * cos_deg(4.0 * h_bar - 63.0);
    let h_off = (h_bar - 275.0) / 25.0;
    let d_theta_deg = 30.0 * elementary::exp(-(h_off * h_off));
    let c_bar_p7 = elementary::powi(c_bar_p, 7);
    let r_c = 2.0 * (c_bar_p7 / (c_bar_p7 + POW25_7)).sqrt();
    let l50 = (l_bar - 50.0) * (l_bar - 50.0);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * c_bar_p;
    let s_h = 1.0 + 0.015 * c_bar_p * t;
    let r_t = -elementary::sin((2.0 * d_theta_deg).to_radians()) * r_c;
    let (ql, qc, qh) = (dl / s_l, dc / s_c, dh_big / s_h);
    (ql * ql + qc * qc + qh * qh + r_t * qc * qh).sqrt()
}
