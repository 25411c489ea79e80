//! `nacre bake`: lookup tables from recipes, concurrently, the largest first.

use crate::error::Result;
use clap::Args;
use nacre_bake::kinds;
use nacre_format::set;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  # the default set: every recipe in tables/recipes/ into tables/baked/
  nacre bake
  # one recipe into another folder
  nacre bake tables/recipes/film-gold.toml --out /tmp/tables
The recipe format is documented in the user guide (docs/guide/src/bake.md, \"Table recipes\").";

#[derive(Args)]
pub struct BakeArgs {
    /// Recipe files (TOML) [default: every tables/recipes/*.toml].
    #[arg(value_name = "RECIPE.toml")]
    recipes: Vec<PathBuf>,
    /// Output folder [default: tables/baked].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

pub fn run(args: &BakeArgs) -> Result<()> {
    use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
    let paths = if args.recipes.is_empty() {
        set::default_recipes()?
    } else {
        args.recipes.clone()
    };
    let out = args.out.clone().unwrap_or_else(set::default_baked_dir);
    // Parse and validate every recipe before baking any.
    let recipes = paths
        .iter()
        .map(|p| kinds::read_recipe(p))
        .collect::<nacre_bake::Result<Vec<_>>>()?;
    // The tables bake concurrently, the largest first, each with its own parallel loops
    // inside: rayon's work stealing keeps every core busy through one table's serial
    // stretches (set-up, compression, file writing) with the others' work. Each table
    // writes only its own files and sums in a fixed order, so the bytes do not depend on
    // the schedule.
    let mut order: Vec<usize> = (0..recipes.len()).collect();
    order.sort_by_key(|&i| kinds::entry(recipes[i].kind()).map_or(u8::MAX, |e| e.start_rank));
    let bars = MultiProgress::new();
    let failure = std::sync::Mutex::new(None);
    rayon::scope_fifo(|scope| {
        for &i in &order {
            let (recipe, bars, out, failure) = (&recipes[i], &bars, &out, &failure);
            scope.spawn_fifo(move |_| {
                let bar = bars.add(
                    ProgressBar::new(recipe.work()).with_style(
                        ProgressStyle::with_template(
                            "{prefix:>22} [{bar:30}] {pos}/{len} {elapsed}",
                        )
                        .expect("valid template")
                        .progress_chars("=> "),
                    ),
                );
                bar.set_prefix(recipe.name().to_string());
                let start = std::time::Instant::now();
                match recipe.bake(out, &|| bar.inc(1)) {
                    Ok(manifest) => {
                        bar.finish_and_clear();
                        bars.suspend(|| {
                            eprintln!(
                                "baked {} in {:.2} s -> {}",
                                recipe.name(),
                                start.elapsed().as_secs_f64(),
                                manifest.display()
                            )
                        });
                    }
                    Err(e) => {
                        bar.abandon();
                        failure.lock().expect("not poisoned").get_or_insert(e);
                    }
                }
            });
        }
    });
    match failure.into_inner().expect("not poisoned") {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}
