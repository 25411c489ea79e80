//! Command-line value parsers: `START:END:STEP` ranges, thicknesses and `--layer M@D`
//! stacks. Each input line is tried as every kind of value.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nacre_bake::commands::grid::{MAX_AXIS_SAMPLES, parse_range, parse_thickness_nm};
use nacre_bake::commands::stack_spec::StackSpec;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let lines: Vec<String> = text.lines().map(str::to_string).collect();
    for line in &lines {
        if let Ok(values) = parse_range("--angles", line) {
            assert!(!values.is_empty() && values.len() <= MAX_AXIS_SAMPLES);
            assert!(values.iter().all(|v| v.is_finite()), "{line}: {values:?}");
        }
        if let Ok(d) = parse_thickness_nm("--layer", line) {
            assert!(d.is_finite() && d >= 0.0, "{line}: {d}");
        }
    }
    // Only the flag syntax: building the stack would read material files named by the input.
    if let Ok(spec) = StackSpec::from_flags(
        lines.first().map(String::as_str),
        lines.get(1..).unwrap_or_default(),
        None,
    ) {
        assert!(spec.layers.iter().all(|(_, d)| d.is_finite() && *d >= 0.0));
    }
});
