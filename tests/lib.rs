//! Cross-crate and golden tests live in `tests/tests/`; this crate has no library code.
