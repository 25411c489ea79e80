//! Every command of the CLI is documented in the user guide (`docs/guide/`): each subcommand
//! that `nacre --help` lists has a chapter `docs/guide/src/COMMAND.md`, listed in the guide's
//! `SUMMARY.md`, whose title names the command and which shows it in use in a code block.
//! A new command cannot land without its chapter. (The guide's links are checked by
//! `tests/tests/doc_links.rs`, its build by `scripts/test_guide.sh`.)

use std::path::{Path, PathBuf};
use std::process::Command;

fn guide_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/guide/src")
}

/// The subcommands of `nacre --help`'s "Commands:" section (clap's layout: two spaces, the
/// name, then its description; continuation lines are indented further), without `help`.
fn subcommands(help: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut in_commands = false;
    for line in help.lines() {
        if line.trim_end() == "Commands:" {
            in_commands = true;
            continue;
        }
        if !in_commands {
            continue;
        }
        if line.trim().is_empty() || !line.starts_with(' ') {
            break;
        }
        // A command line starts with exactly two spaces; description continuations with more.
        if line.starts_with("  ") && !line.starts_with("   ") {
            let name = line.split_whitespace().next().unwrap_or("");
            if name != "help" {
                names.push(name.to_string());
            }
        }
    }
    names
}

#[test]
fn every_command_has_a_chapter_in_the_guide() {
    let out = Command::new(env!("CARGO_BIN_EXE_nacre"))
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success(), "nacre --help failed");
    let help = String::from_utf8(out.stdout).unwrap();
    let commands = subcommands(&help);
    // The schema has a dozen commands: fewer means the help's layout changed under the parser.
    assert!(
        commands.len() >= 10 && commands.iter().any(|c| c == "bench-gpu"),
        "found only {commands:?} in nacre --help:\n{help}"
    );
    let summary = std::fs::read_to_string(guide_src().join("SUMMARY.md"))
        .expect("docs/guide/src/SUMMARY.md (the user guide's table of contents)");
    let mut missing = Vec::new();
    for command in &commands {
        let file = format!("{command}.md");
        let path = guide_src().join(&file);
        let Ok(chapter) = std::fs::read_to_string(&path) else {
            missing.push(format!(
                "`nacre {command}`: no chapter docs/guide/src/{file}"
            ));
            continue;
        };
        if !summary.contains(&format!("]({file})")) {
            missing.push(format!(
                "`nacre {command}`: docs/guide/src/{file} is not listed in SUMMARY.md"
            ));
        }
        let title = chapter.lines().next().unwrap_or("");
        if !(title.starts_with("# ") && title.contains(&format!("nacre {command}"))) {
            missing.push(format!(
                "`nacre {command}`: docs/guide/src/{file}'s title `{title}` does not name the command"
            ));
        }
        if !shows_in_use(&chapter, command) {
            missing.push(format!(
                "`nacre {command}`: docs/guide/src/{file} has no code block running `nacre {command}`"
            ));
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// Whether a fenced code block of `chapter` runs `nacre COMMAND` (possibly after global flags
/// such as `--material-db DIR`).
fn shows_in_use(chapter: &str, command: &str) -> bool {
    let mut fence = false;
    for line in chapter.lines() {
        if line.trim_start().starts_with("```") {
            fence = !fence;
            continue;
        }
        if !fence {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        for (i, w) in words.iter().enumerate() {
            if *w == "nacre" {
                let rest = &words[i + 1..];
                // Skip global flags and their values.
                let mut j = 0;
                while j < rest.len() && rest[j].starts_with("--") {
                    j += if rest[j].contains('=') { 1 } else { 2 };
                }
                if rest.get(j) == Some(&command) {
                    return true;
                }
            }
        }
    }
    false
}

#[test]
fn the_parser_reads_clap_help() {
    let help = "Usage: nacre [OPTIONS] <COMMAND>\n\nCommands:\n  spectrum     Exact\n  bake         \
                Bake lookup tables from recipes (default: every recipe in tables/recipes/ into\n               \
                tables/baked/)\n  bench-gpu    Time\n  help         Print this message\n\nOptions:\n  -h, --help  Print help\n";
    assert_eq!(subcommands(help), ["spectrum", "bake", "bench-gpu"]);
    assert!(shows_in_use(
        "```sh\nnacre spectrum -o x.csv\n```\n",
        "spectrum"
    ));
    assert!(shows_in_use(
        "```sh\nnacre --material-db ~/db spectrum\n```\n",
        "spectrum"
    ));
    assert!(!shows_in_use(
        "`nacre spectrum` in prose only\n",
        "spectrum"
    ));
    assert!(!shows_in_use("```sh\nnacre color\n```\n", "spectrum"));
}
