//! Support for the cross-crate and golden tests in `tests/tests/`: a deterministic random
//! source and summary statistics. No product code lives here.

/// SplitMix64 (Steele, Lea & Flood 2014): deterministic uniform numbers, the same on every
/// platform, so that accuracy tests sample the same points everywhere.
pub struct Rng(pub u64);

impl Rng {
    /// A uniform number in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// The `p`-quantile (0–1) of an ascending slice, by nearest rank.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// The worst reflectance and transmittance differences of a cross-check and where they
/// occurred (`tmm_golden`, `inc_tmm_golden`).
#[derive(Debug, Default)]
pub struct WorstRt {
    /// Worst |ΔR| and where.
    pub r: (f64, String),
    /// Worst |ΔT| and where.
    pub t: (f64, String),
}

impl WorstRt {
    /// Keeps `dr` and `dt` where they are the worst so far.
    pub fn record(&mut self, dr: f64, dt: f64, where_: String) {
        if dr > self.r.0 {
            self.r = (dr, where_.clone());
        }
        if dt > self.t.0 {
            self.t = (dt, where_);
        }
    }

    /// Fails when either worst difference exceeds `tolerance`.
    pub fn assert_within(&self, tolerance: f64) {
        assert!(
            self.r.0 <= tolerance,
            "worst |ΔR| {:.3e} at {}",
            self.r.0,
            self.r.1
        );
        assert!(
            self.t.0 <= tolerance,
            "worst |ΔT| {:.3e} at {}",
            self.t.0,
            self.t.1
        );
    }
}
