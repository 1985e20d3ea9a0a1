//! Every command-line example of the user guide (`docs/guide/src/*.md`) and
//! of `README.md` runs: each ```` ```sh ```` block whose commands are `msp`'s
//! is run by `bash -e` in a directory of its own (with the repository's
//! `examples/` beside it), the `msp` this package builds first on the
//! PATH. A block of other commands (the set-up's `cargo`, `pip`, `cc`) is
//! named in the test's output, never run and never passed over unnoticed:
//! the test fails if a block mixes the two.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The Markdown files with examples: the guide's chapters and the README.
fn pages() -> Vec<PathBuf> {
    let dir = root().join("docs/guide/src");
    let mut pages: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    pages.sort();
    pages.push(root().join("README.md"));
    pages
}

/// The ```` ```sh ```` blocks of a page: (first line number, text).
fn blocks(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut open: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        match open.as_mut() {
            None if line.trim_start() == "```sh" => open = Some((i + 2, String::new())),
            Some(_) if line.trim_start().starts_with("```") => out.extend(open.take()),
            Some((_, body)) => {
                body.push_str(line);
                body.push('\n');
            }
            None => {}
        }
    }
    out
}

/// The commands of a block: its lines joined where they end in `\`,
/// without blank lines and whole-line comments.
fn commands(block: &str) -> Vec<String> {
    let joined = block.replace("\\\n", " ");
    joined
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(String::from)
        .collect()
}

#[test]
fn every_cli_example_of_the_guide_runs() {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_msp"));
    let bin_dir = bin.parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (mut ran, mut setup) = (0, Vec::new());
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (line, block) in blocks(&text) {
            let where_ = format!("{}:{line}", page.display());
            let cmds = commands(&block);
            let ours = cmds.iter().filter(|c| c.starts_with("msp ")).count();
            if ours == 0 {
                setup.push(where_);
                continue;
            }
            assert_eq!(
                ours,
                cmds.len(),
                "{where_}: msp's examples and other commands in one block"
            );
            let dir = std::env::temp_dir().join(format!("msp-guide-{}-{ran}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let examples = dir.join("examples");
            if !examples.exists() {
                std::os::unix::fs::symlink(root().join("examples"), &examples).unwrap();
            }
            let out = Command::new("bash")
                .args(["-e", "-c", &block])
                .current_dir(&dir)
                .env("PATH", &path)
                .output()
                .unwrap();
            let _ = std::fs::remove_dir_all(&dir);
            assert!(
                out.status.success(),
                "{where_}: the example failed\n{block}\nstderr:\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    println!("ran {ran} example blocks; set-up blocks (not run): {setup:?}");
    assert!(ran >= 8, "only {ran} example blocks found");
}
