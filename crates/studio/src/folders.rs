//! The user's folders the studio keeps its files in (the XDG base directories).

use std::path::PathBuf;

/// The XDG base directory `var` (e.g. `XDG_STATE_HOME`) when set and not empty, else
/// `$HOME/home_relative` (e.g. `.local/state`); None when neither is known.
pub fn user_folder(var: &str, home_relative: &str) -> Option<PathBuf> {
    std::env::var_os(var)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|v| !v.is_empty())
                .map(|h| PathBuf::from(h).join(home_relative))
        })
}
