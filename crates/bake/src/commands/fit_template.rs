//! A fit template with its materials loaded: the free parameters with their bounds, the
//! fixed rest, and the function from a parameter vector to a [`Stack`]
//! ([`nacre_optics::fit::Template`]), each parameter remembering the flag or recipe line
//! that set it free. The syntax is [`crate::commands::stack_spec`]'s (`sio2@50:400`,
//! `1.3:1.7@100:600`, `thickness_nm = [50, 400]`).

use crate::commands::stack_spec::{FreeSpec, TemplateSpec};
use crate::error::{Error, Origin, Result};
use nacre_format::materials::MaterialDb;
use nacre_optics::Stack;
use nacre_optics::fit::{Free, Template};

/// A template ready to fit.
#[derive(Clone, Debug)]
pub struct FitTemplate {
    /// The parsed template (material specs, where each value came from).
    pub spec: TemplateSpec,
    /// The stack and its free parameters.
    pub template: Template,
}

impl FitTemplate {
    /// Loads the materials of `spec` (the database of
    /// [`nacre_format::materials::set_database`]).
    pub fn build(spec: TemplateSpec) -> Result<Self> {
        Self::build_with(spec, nacre_format::materials::database().as_ref())
    }

    /// Loads the materials of `spec`, reading `shelf/book/page` materials from `db`.
    pub fn build_with(spec: TemplateSpec, db: Option<&MaterialDb>) -> Result<Self> {
        let stack = spec.stack.build_with(db)?;
        let free: Vec<Free> = spec.free.iter().map(|f| f.free).collect();
        let template = Template::new(stack, free).map_err(|e| {
            let origin = match &e {
                nacre_optics::Error::FitTemplate { layer, .. } => spec
                    .free
                    .iter()
                    .find(|f| f.free.layer == *layer)
                    .map(|f| f.origin.clone()),
                _ => None,
            };
            match origin {
                Some(o) => Error::optics_in(o, e),
                None => Error::Optics(e),
            }
        })?;
        Ok(FitTemplate { spec, template })
    }

    /// The free parameters, in the order of the parameter vector.
    pub fn free(&self) -> &[Free] {
        self.template.free()
    }

    /// Where free parameter `i` was set free (a flag or a recipe line).
    pub fn origin(&self, i: usize) -> &Origin {
        // `Template::new` sorts as `TemplateSpec` lists them: films top first, index first.
        &self.spec.free[i].origin
    }

    /// The free parameters with where they came from.
    pub fn free_specs(&self) -> &[FreeSpec] {
        &self.spec.free
    }

    /// The stack at parameter vector `x`.
    pub fn stack_at(&self, x: &[f64]) -> Result<Stack> {
        self.template.stack_at(x).map_err(Error::Optics)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::stack_spec::StackRecipe;
    use nacre_optics::fit::FreeKind;
    use std::path::Path;

    fn flags(layers: &[&str]) -> Result<FitTemplate> {
        let layers: Vec<String> = layers.iter().map(|s| s.to_string()).collect();
        FitTemplate::build(TemplateSpec::from_flags(None, &layers, Some("bk7"))?)
    }

    #[test]
    fn ranges_on_the_command_line() {
        let t = flags(&["sio2@50:400", "1.3:1.7@100:600", "tio2@30nm"]).unwrap();
        let f = t.free();
        assert_eq!(f.len(), 3);
        assert_eq!(
            (f[0].layer, f[0].kind, f[0].lo, f[0].hi),
            (1, FreeKind::ThicknessNm, 50.0, 400.0)
        );
        assert_eq!(
            (f[1].layer, f[1].kind, f[1].lo, f[1].hi),
            (2, FreeKind::Index, 1.3, 1.7)
        );
        assert_eq!(
            (f[2].layer, f[2].kind, f[2].lo, f[2].hi),
            (2, FreeKind::ThicknessNm, 100.0, 600.0)
        );
        assert_eq!(t.origin(1).to_string(), "layer = 1.3:1.7@100:600");
        let s = t.stack_at(&[75.0, 1.45, 200.0]).unwrap();
        assert_eq!(s.thicknesses_nm(), vec![75.0, 200.0, 30.0]);
        let n = s.layers()[1].material.index_at(600.0).unwrap();
        assert_eq!(n.re, 1.45);
        // Units on bounds; a fixed layer keeps its value.
        let t = flags(&["sio2@0.5um:1um"]).unwrap();
        assert_eq!((t.free()[0].lo, t.free()[0].hi), (500.0, 1000.0));
        // Nothing free is a template too.
        assert!(flags(&["sio2@100"]).unwrap().free().is_empty());
    }

    #[test]
    fn bad_ranges_name_the_flag() {
        for (bad, want) in [
            (
                "sio2@400:50",
                "layer `sio2@400:50`: thickness bounds 400:50 are inverted",
            ),
            (
                "1.7:1.3@100",
                "layer `1.7:1.3@100`: index bounds 1.7:1.3 are inverted",
            ),
            ("0:1.3@100", "an index must be positive"),
            ("sio2@50:x", "layer `sio2@50:x`: thickness must be a number"),
        ] {
            let e = flags(&[bad]).unwrap_err().to_string();
            assert!(e.contains(want), "{bad}: {e}");
        }
        // Not a template: the stack flags keep refusing ranges.
        let e =
            crate::commands::stack_spec::StackSpec::from_flags(None, &["sio2@50:400".into()], None)
                .unwrap_err()
                .to_string();
        assert!(e.contains("unknown suffix `:400`"), "{e}");
    }

    #[test]
    fn ranges_in_a_recipe() {
        let p = Path::new("t.toml");
        let text = "substrate = \"bk7\"\n[[layers]]\nmaterial = \"1.3:1.7\"\nthickness_nm = [100, 600]\n[[layers]]\nmaterial = \"sio2\"\nthickness_nm = 20\n";
        let t = FitTemplate::build(TemplateSpec::parse(p, text).unwrap()).unwrap();
        assert_eq!(t.free().len(), 2);
        assert_eq!(t.free()[0].kind, FreeKind::Index);
        assert_eq!(t.origin(1).to_string(), "t.toml:4");
        assert_eq!(t.template.mid(), vec![1.5, 350.0]);
        // A stack recipe refuses the range, naming the line.
        let e = StackRecipe::parse(p, text).unwrap_err().to_string();
        assert!(
            e.starts_with("t.toml:4: thickness_nm = [100, 600] is a range"),
            "{e}"
        );
        let bad = "[[layers]]\nmaterial = \"sio2\"\nthickness_nm = [600, 100]\n";
        let e = TemplateSpec::parse(p, bad).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "t.toml:3: thickness_nm = [600, 100]: thickness bounds 600:100 are inverted"
            ),
            "{e}"
        );
        let bad = "[[layers]]\nmaterial = \"2:1\"\nthickness_nm = 100\n";
        let e = TemplateSpec::parse(p, bad).unwrap_err().to_string();
        assert!(
            e.starts_with("t.toml:2: material = \"2:1\": index bounds 2:1 are inverted"),
            "{e}"
        );
        // What a fit writes reads back as a stack recipe.
        let fitted = "substrate = \"bk7\"\n[[layers]]\nmaterial = \"1.4523\"\nindex_sigma = 0.001\nthickness_nm = 123.4\nthickness_sigma_nm = 0.2\n[fit]\nrms = 0.002\n";
        let r = StackRecipe::parse(p, fitted).unwrap();
        assert_eq!(r.stack.layers[0].1, 123.4);
        r.stack.build().unwrap();
    }
}
