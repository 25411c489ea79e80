//! Forward-mode dual numbers with three derivative components, and CIEDE2000 through them:
//! the gradient of ΔE2000(target, lab) with respect to `lab` ([`super::delta_e_2000_gradient`]).
//!
//! A [`Dual`] carries a value v and its gradient ∂v/∂(L*, a*, b*); every operation applies
//! its derivative rule (∂(uw) = u ∂w + w ∂u, ∂√u = ∂u/(2√u), ∂ atan2(y, x) =
//! (x ∂y − y ∂x)/(x² + y²), ∂ sin u = cos u ∂u, ∂ e^u = e^u ∂u), so the gradient is exact
//! up to rounding. Values go through [`crate::elementary`] as [`crate::colour::delta_e_2000`]
//! does, and its branches (hue wrap, mean hue) are taken on the values, so the value
//! matches it.

use crate::elementary;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value and its gradient with respect to three inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f64,
    /// ∂v/∂x_k, k = 0, 1, 2.
    pub d: [f64; 3],
}

impl Dual {
    /// A constant (zero gradient).
    pub fn constant(v: f64) -> Self {
        Dual { v, d: [0.0; 3] }
    }
    /// Input k with value `v`.
    pub fn input(v: f64, k: usize) -> Self {
        let mut d = [0.0; 3];
        d[k] = 1.0;
        Dual { v, d }
    }
    fn chain(self, v: f64, slope: f64) -> Self {
        Dual {
            v,
            d: self.d.map(|d| d * slope),
        }
    }
    /// √u.
    pub fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, if r == 0.0 { 0.0 } else { 0.5 / r })
    }
    /// √(u² + w²).
    pub fn magnitude(self, w: Self) -> Self {
        let h = elementary::hypot(self.v, w.v);
        let inv = if h == 0.0 { 0.0 } else { 1.0 / h };
        Dual {
            v: h,
            d: std::array::from_fn(|k| (self.v * self.d[k] + w.v * w.d[k]) * inv),
        }
    }
    /// atan2(self, x) in radians.
    pub fn arctan2(self, x: Self) -> Self {
        let r2 = self.v * self.v + x.v * x.v;
        let inv = if r2 == 0.0 { 0.0 } else { 1.0 / r2 };
        Dual {
            v: elementary::atan2(self.v, x.v),
            d: std::array::from_fn(|k| (x.v * self.d[k] - self.v * x.d[k]) * inv),
        }
    }
    /// sin u (radians).
    pub fn sine(self) -> Self {
        self.chain(elementary::sin(self.v), elementary::cos(self.v))
    }
    /// cos u (radians).
    pub fn cosine(self) -> Self {
        self.chain(elementary::cos(self.v), -elementary::sin(self.v))
    }
    /// e^u.
    pub fn exponential(self) -> Self {
        let e = elementary::exp(self.v);
        self.chain(e, e)
    }
    /// u^n.
    pub fn pow_int(self, n: i32) -> Self {
        self.chain(
            elementary::powi(self.v, n),
            n as f64 * elementary::powi(self.v, n - 1),
        )
    }
    /// Degrees to radians.
    pub fn to_radians(self) -> Self {
        self * (std::f64::consts::PI / 180.0)
    }
    /// Radians to degrees.
    pub fn to_degrees(self) -> Self {
        self * (180.0 / std::f64::consts::PI)
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual {
            v: self.v + o.v,
            d: std::array::from_fn(|k| self.d[k] + o.d[k]),
        }
    }
}
impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual {
            v: self.v - o.v,
            d: std::array::from_fn(|k| self.d[k] - o.d[k]),
        }
    }
}
// The product and quotient rules add and subtract.
#[allow(clippy::suspicious_arithmetic_impl)]
impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self.v * o.v,
            d: std::array::from_fn(|k| self.d[k] * o.v + self.v * o.d[k]),
        }
    }
}
#[allow(clippy::suspicious_arithmetic_impl)]
impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let inv = 1.0 / o.v;
        let v = self.v * inv;
        Dual {
            v,
            d: std::array::from_fn(|k| (self.d[k] - v * o.d[k]) * inv),
        }
    }
}
impl Add<f64> for Dual {
    type Output = Dual;
    fn add(self, o: f64) -> Dual {
        Dual {
            v: self.v + o,
            ..self
        }
    }
}
impl Sub<f64> for Dual {
    type Output = Dual;
    fn sub(self, o: f64) -> Dual {
        Dual {
            v: self.v - o,
            ..self
        }
    }
}
impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, o: f64) -> Dual {
        Dual {
            v: self.v * o,
            d: self.d.map(|d| d * o),
        }
    }
}
impl Mul<Dual> for f64 {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        o * self
    }
}
impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        self * -1.0
    }
}

/// [`crate::colour::delta_e_2000`] with `lab2` as the three dual inputs: the value and its
/// gradient with respect to (L*₂, a*₂, b*₂). Same steps and branches (Sharma, Wu & Dalal
/// 2005), taken on the values.
pub fn delta_e_2000(lab1: [f64; 3], lab2: [f64; 3]) -> Dual {
    const POW25_7: f64 = 6_103_515_625.0;
    const TIE_DEG: f64 = 180.0 + 1e-9;
    let c = Dual::constant;
    let [l1, a1, b1] = lab1.map(c);
    let l2 = Dual::input(lab2[0], 0);
    let a2 = Dual::input(lab2[1], 1);
    let b2 = Dual::input(lab2[2], 2);
    let c_bar = (a1.magnitude(b1) + a2.magnitude(b2)) * 0.5;
    let c_bar7 = c_bar.pow_int(7);
    let g = (c(1.0) - (c_bar7 / (c_bar7 + POW25_7)).sqrt()) * 0.5;
    let (a1p, a2p) = ((g + 1.0) * a1, (g + 1.0) * a2);
    let (c1p, c2p) = (a1p.magnitude(b1), a2p.magnitude(b2));
    let hue = |b: Dual, ap: Dual| {
        if b.v == 0.0 && ap.v == 0.0 {
            c(0.0)
        } else {
            let h = b.arctan2(ap).to_degrees();
            if h.v < 0.0 { h + 360.0 } else { h }
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));
    let chroma_product = c1p * c2p;
    let dl = l2 - l1;
    let dc = c2p - c1p;
    let dh_deg = if chroma_product.v == 0.0 {
        c(0.0)
    } else {
        let d = h2p - h1p;
        if d.v.abs() <= TIE_DEG {
            d
        } else if d.v > 0.0 {
            d - 360.0
        } else {
            d + 360.0
        }
    };
    let dh_big = 2.0 * chroma_product.sqrt() * (dh_deg * 0.5).to_radians().sine();
    let l_bar = (l1 + l2) * 0.5;
    let c_bar_p = (c1p + c2p) * 0.5;
    let h_bar = if chroma_product.v == 0.0 {
        h1p + h2p
    } else if (h1p.v - h2p.v).abs() <= TIE_DEG {
        (h1p + h2p) * 0.5
    } else if h1p.v + h2p.v < 360.0 {
        (h1p + h2p + 360.0) * 0.5
    } else {
        (h1p + h2p - 360.0) * 0.5
    };
    let cos_deg = |deg: Dual| deg.to_radians().cosine();
    let t = c(1.0) - 0.17 * cos_deg(h_bar - 30.0)
        + 0.24 * cos_deg(2.0 * h_bar)
        + 0.32 * cos_deg(3.0 * h_bar + 6.0)
        - 0.20 * cos_deg(4.0 * h_bar - 63.0);
    let h_off = (h_bar - 275.0) * (1.0 / 25.0);
    let d_theta_deg = 30.0 * (-(h_off * h_off)).exponential();
    let c_bar_p7 = c_bar_p.pow_int(7);
    let r_c = 2.0 * (c_bar_p7 / (c_bar_p7 + POW25_7)).sqrt();
    let l50 = (l_bar - 50.0) * (l_bar - 50.0);
    let s_l = c(1.0) + 0.015 * l50 / (l50 + 20.0).sqrt();
    let s_c = c(1.0) + 0.045 * c_bar_p;
    let s_h = c(1.0) + 0.015 * c_bar_p * t;
    let r_t = -((2.0 * d_theta_deg).to_radians().sine()) * r_c;
    let (ql, qc, qh) = (dl / s_l, dc / s_c, dh_big / s_h);
    (ql * ql + qc * qc + qh * qh + r_t * qc * qh).sqrt()
}
