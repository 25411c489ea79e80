//! A fit template: a [`Stack`] some of whose film thicknesses and constant film indices are
//! free parameters, each between two bounds.
//!
//! The parameter vector `x` lists the free parameters in the order of [`Template::free`]
//! (films top first; within a film its index before its thickness). [`Template::stack_at`]
//! is the function from `x` to a stack: the template's stack with film j's thickness set to
//! `x_i` (nm) or its material replaced by the constant real index `x_i`.

use crate::error::{Error, Result};
use crate::material::Material;
use crate::stack::{Layer, Stack};
use num_complex::Complex64 as C64;

/// What a free parameter sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FreeKind {
    /// The film's physical thickness, nm.
    ThicknessNm,
    /// The film's constant real refractive index (κ = 0).
    Index,
}

/// A free parameter: which film, what, and its bounds `lo ≤ x ≤ hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Free {
    /// 1-based film number, top film first.
    pub layer: usize,
    /// What the parameter sets.
    pub kind: FreeKind,
    /// Lower bound (nm for a thickness).
    pub lo: f64,
    /// Upper bound (nm for a thickness).
    pub hi: f64,
}

impl Free {
    /// The middle of the bounds.
    pub fn mid(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }
}

/// A stack with free parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Template {
    stack: Stack,
    free: Vec<Free>,
}

impl Template {
    /// A template from `stack` (its values of the free parameters are placeholders) and the
    /// free parameters, put in the order films top first, index before thickness.
    ///
    /// Errors ([`Error::FitTemplate`]) when a parameter names no film of the stack, is given
    /// twice, has bounds that are not finite or are inverted (lo > hi), a negative thickness
    /// bound, an index bound ≤ 0, or frees a thickness of an incoherent film.
    pub fn new(stack: Stack, mut free: Vec<Free>) -> Result<Self> {
        let err = |f: &Free, message: String| Error::FitTemplate {
            layer: f.layer,
            message,
        };
        free.sort_by_key(|f| (f.layer, f.kind == FreeKind::ThicknessNm));
        for (i, f) in free.iter().enumerate() {
            if f.layer == 0 || f.layer > stack.layers().len() {
                return Err(err(
                    f,
                    format!("the stack has {} films", stack.layers().len()),
                ));
            }
            if i > 0 && free[i - 1].layer == f.layer && free[i - 1].kind == f.kind {
                return Err(err(f, "the same parameter is free twice".into()));
            }
            if !(f.lo.is_finite() && f.hi.is_finite()) {
                return Err(err(f, format!("bounds {}:{} must be finite", f.lo, f.hi)));
            }
            if f.lo > f.hi {
                return Err(err(
                    f,
                    format!(
                        "bounds {}:{} are inverted: the lower bound comes first",
                        f.lo, f.hi
                    ),
                ));
            }
            match f.kind {
                FreeKind::ThicknessNm if f.lo < 0.0 => {
                    return Err(err(f, format!("thickness bound {} nm is negative", f.lo)));
                }
                FreeKind::Index if f.lo <= 0.0 => {
                    return Err(err(f, format!("index bound {} must be positive", f.lo)));
                }
                _ => {}
            }
            if stack.is_incoherent(f.layer) {
                return Err(err(
                    f,
                    "an incoherent slab's parameters cannot be fitted (its spectrum has no fringes)"
                        .into(),
                ));
            }
        }
        Ok(Template { stack, free })
    }

    /// The stack with the placeholder values.
    pub fn stack(&self) -> &Stack {
        &self.stack
    }

    /// The free parameters, in the order of the parameter vector.
    pub fn free(&self) -> &[Free] {
        &self.free
    }

    /// Number of free parameters.
    pub fn dims(&self) -> usize {
        self.free.len()
    }

    /// The middle of every parameter's bounds.
    pub fn mid(&self) -> Vec<f64> {
        self.free.iter().map(Free::mid).collect()
    }

    /// The stack at parameter vector `x` (one value per [`Template::free`] entry).
    ///
    /// Errors when `x` has the wrong length or a value the stack refuses (a negative
    /// thickness, an index ≤ 0 or not finite).
    pub fn stack_at(&self, x: &[f64]) -> Result<Stack> {
        if x.len() != self.free.len() {
            return Err(Error::FitTemplate {
                layer: 0,
                message: format!(
                    "{} parameter values for {} free parameters",
                    x.len(),
                    self.free.len()
                ),
            });
        }
        let mut layers: Vec<Layer> = self.stack.layers().to_vec();
        for (f, &v) in self.free.iter().zip(x) {
            let layer = &mut layers[f.layer - 1];
            match f.kind {
                FreeKind::ThicknessNm => layer.thickness_nm = v,
                FreeKind::Index => {
                    layer.material = Material::constant(format!("{v}"), C64::new(v, 0.0))?;
                }
            }
        }
        let stack = Stack::new(
            self.stack.ambient().clone(),
            layers,
            self.stack.substrate().clone(),
        )?;
        if self.stack.is_coherent() {
            Ok(stack)
        } else {
            stack.with_incoherent(self.stack.incoherent_flags())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stack() -> Stack {
        let m = |n: f64| Material::constant(format!("{n}"), C64::new(n, 0.0)).unwrap();
        Stack::new(
            m(1.0),
            vec![
                Layer {
                    material: m(2.0),
                    thickness_nm: 100.0,
                },
                Layer {
                    material: m(1.46),
                    thickness_nm: 200.0,
                },
            ],
            m(1.52),
        )
        .unwrap()
    }

    #[test]
    fn parameters_map_to_the_stack() {
        let t = Template::new(
            stack(),
            vec![
                Free {
                    layer: 2,
                    kind: FreeKind::ThicknessNm,
                    lo: 50.0,
                    hi: 400.0,
                },
                Free {
                    layer: 1,
                    kind: FreeKind::ThicknessNm,
                    lo: 10.0,
                    hi: 20.0,
                },
                Free {
                    layer: 1,
                    kind: FreeKind::Index,
                    lo: 1.3,
                    hi: 1.7,
                },
            ],
        )
        .unwrap();
        // Sorted: film 1's index, film 1's thickness, film 2's thickness.
        assert_eq!(t.free()[0].kind, FreeKind::Index);
        assert_eq!(t.free()[1].lo, 10.0);
        assert_eq!(t.free()[2].layer, 2);
        assert_eq!(t.mid(), vec![1.5, 15.0, 225.0]);
        let s = t.stack_at(&[1.6, 12.0, 321.0]).unwrap();
        assert_eq!(s.thicknesses_nm(), vec![12.0, 321.0]);
        assert_eq!(
            s.layers()[0].material.index_at(500.0).unwrap(),
            C64::new(1.6, 0.0)
        );
        assert_eq!(
            s.layers()[1].material.index_at(500.0).unwrap(),
            C64::new(1.46, 0.0)
        );
        assert!(t.stack_at(&[1.6, 12.0]).is_err());
        assert!(t.stack_at(&[-1.0, 12.0, 3.0]).is_err());
    }

    #[test]
    fn bad_bounds_are_refused() {
        let free = |layer, kind, lo, hi| Free {
            layer,
            kind,
            lo,
            hi,
        };
        for (f, want) in [
            (
                free(3, FreeKind::ThicknessNm, 1.0, 2.0),
                "the stack has 2 films",
            ),
            (free(1, FreeKind::ThicknessNm, 400.0, 50.0), "inverted"),
            (free(1, FreeKind::ThicknessNm, -5.0, 50.0), "negative"),
            (free(1, FreeKind::Index, 0.0, 2.0), "positive"),
            (free(1, FreeKind::Index, 1.0, f64::NAN), "finite"),
        ] {
            let e = Template::new(stack(), vec![f]).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
        let twice = vec![
            free(1, FreeKind::ThicknessNm, 1.0, 2.0),
            free(1, FreeKind::ThicknessNm, 1.0, 3.0),
        ];
        assert!(Template::new(stack(), twice).is_err());
    }
}
