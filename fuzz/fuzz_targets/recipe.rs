//! Table recipes (`nacre bake`, every kind) and stack recipes (`--recipe`): any text is
//! either parsed or refused with an error naming the file; never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // A name no test folder holds: relative material paths in the recipe resolve against
    // the current folder and are not found.
    let path = Path::new("fuzz-recipe.toml");
    if let Err(e) = nacre_bake::kinds::parse_recipe(path, text.to_string()) {
        let message = e.to_string();
        assert!(!message.is_empty());
    }
    let _ = nacre_bake::commands::stack_spec::StackRecipe::parse(path, text);
});
