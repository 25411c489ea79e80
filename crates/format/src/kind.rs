//! The kinds of table nacre bakes, named as recipes and manifests name them, and the one
//! list of them ([`TableKind::ALL`]).
//!
//! A kind is data — its name — not an enum variant: no `match` over every kind exists
//! anywhere, so a kind the CPU alone reads is one line in [`TableKind::ALL`] here, its module
//! in `nacre-bake`'s `kinds/` and one line in that crate's registry. Its manifest record is
//! then the JSON object its module writes ([`crate::manifest::KindRecord::Data`]); the kinds
//! whose records other crates read (the runtime, engine integrations) have typed records.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// A kind of table nacre bakes: its name (`film-lut`, …), which recipes (`kind = "…"`) and
/// manifests (`"kind": "…"`) write. Two kinds are equal when their names are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TableKind {
    name: &'static str,
}

impl TableKind {
    /// Pre-integrated film colour over cos θ × optical path × film index
    /// ([`crate::film_lut`]).
    pub const FILM_LUT: TableKind = TableKind::new("film-lut");
    /// Fourier transforms of the colour sensitivities, mip-mapped ([`crate::fourier`]).
    pub const FOURIER: TableKind = TableKind::new("fourier");
    /// Directional albedo of the iridescent GGX lobe ([`crate::rough_film_lut`]).
    pub const ROUGH_FILM_LUT: TableKind = TableKind::new("rough-film-lut");
    /// Stam's diffraction terms or their wavelength-integrated colours
    /// ([`crate::diffraction`]).
    pub const DIFFRACTION: TableKind = TableKind::new("diffraction");

    /// Every kind a manifest may name, one line each.
    pub const ALL: &'static [TableKind] = &[
        TableKind::FILM_LUT,
        TableKind::FOURIER,
        TableKind::ROUGH_FILM_LUT,
        TableKind::DIFFRACTION,
    ];

    /// The kind called `name` (lower-case words joined by `-`). Only the kinds of
    /// [`TableKind::ALL`] are read from manifests.
    pub const fn new(name: &'static str) -> TableKind {
        TableKind { name }
    }

    /// The name recipes and manifests use (`film-lut`, …).
    pub fn name(self) -> &'static str {
        self.name
    }

    /// The JSON key of the kind's record in a manifest: its name with `_` for `-`
    /// (`film_lut`, …).
    pub fn record_key(self) -> String {
        self.name.replace('-', "_")
    }

    /// The kind of [`TableKind::ALL`] named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|k| k.name == name)
    }

    /// The kind of `kinds` whose record key is `key`, if any.
    pub(crate) fn from_record_key(kinds: &[TableKind], key: &str) -> Option<Self> {
        kinds.iter().copied().find(|k| k.record_key() == key)
    }
}

impl fmt::Display for TableKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl Serialize for TableKind {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name)
    }
}

impl<'de> Deserialize<'de> for TableKind {
    /// A name of [`TableKind::ALL`]; any other is refused with serde's message for an
    /// unknown variant.
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = std::borrow::Cow::<'de, str>::deserialize(deserializer)?;
        TableKind::from_name(&name).ok_or_else(|| {
            let names: Vec<String> = TableKind::ALL
                .iter()
                .map(|k| format!("`{}`", k.name))
                .collect();
            serde::de::Error::custom(format_args!(
                "unknown variant `{name}`, expected one of {}",
                names.join(", ")
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_record_keys() {
        // Every name is lower-case words joined by `-`, and no two kinds share a name.
        let mut names: Vec<&str> = TableKind::ALL.iter().map(|k| k.name()).collect();
        for name in &names {
            assert!(
                name.split('-')
                    .all(|w| !w.is_empty() && w.chars().all(|c| c.is_ascii_lowercase())),
                "{name}"
            );
        }
        names.sort();
        names.dedup();
        assert_eq!(names.len(), TableKind::ALL.len());
        for kind in [
            TableKind::FILM_LUT,
            TableKind::FOURIER,
            TableKind::ROUGH_FILM_LUT,
            TableKind::DIFFRACTION,
        ] {
            assert!(TableKind::ALL.contains(&kind), "{kind}");
        }
        assert_eq!(TableKind::ROUGH_FILM_LUT.record_key(), "rough_film_lut");
        assert_eq!(TableKind::from_name("fourier"), Some(TableKind::FOURIER));
        assert_eq!(TableKind::from_name("nope"), None);
        assert_eq!(
            TableKind::from_record_key(TableKind::ALL, "film_lut"),
            Some(TableKind::FILM_LUT)
        );
    }

    #[test]
    fn serde_writes_and_reads_the_name() {
        let json = serde_json::to_string(&TableKind::ROUGH_FILM_LUT).unwrap();
        assert_eq!(json, "\"rough-film-lut\"");
        let back: TableKind = serde_json::from_str(&json).unwrap();
        assert_eq!(back, TableKind::ROUGH_FILM_LUT);
        let err = serde_json::from_str::<TableKind>("\"nope\"")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(
                "unknown variant `nope`, expected one of `film-lut`, `fourier`, `rough-film-lut`, `diffraction`"
            ),
            "{err}"
        );
    }
}
