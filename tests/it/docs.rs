//! The README and the guide stay true to the project: every relative link resolves, and every
//! `simlod` command quoted in a shell block still parses.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every Markdown page under docs/.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut pages = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut pages);
    walk(&root().join("anchors"), &mut pages);
    pages.sort();
    pages
}

/// The targets of a page's Markdown links and images, `[text](target)`, outside code.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut in_code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        // Inline code spans may hold brackets that are not links.
        let prose: String = line.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        let mut rest = prose.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push(after[..end].split_whitespace().next().unwrap_or("").to_owned());
            rest = &after[end..];
        }
    }
    targets
}

fn is_relative(target: &str) -> bool {
    !(target.is_empty() || target.starts_with('#') || target.contains("://") || target.starts_with("mailto:"))
}

#[test]
fn every_relative_link_in_the_readme_and_the_guide_resolves() {
    let mut broken = Vec::new();
    let pages = pages();
    assert!(pages.len() > 5, "the guide's pages are found: {pages:?}");
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        for target in link_targets(&text).into_iter().filter(|t| is_relative(t)) {
            let file = target.split('#').next().unwrap();
            if !page.parent().unwrap().join(file).exists() {
                broken.push(format!("{}: {target}", page.strip_prefix(root()).unwrap().display()));
            }
        }
    }
    assert!(broken.is_empty(), "links that lead nowhere:\n{}", broken.join("\n"));
}

#[test]
fn a_link_inside_code_is_not_a_link_and_one_in_prose_is() {
    let text = "See [the guide](docs/guide/README.md) and `a[i](j)`.\n```sh\nx[0](y)\n```\n";
    assert_eq!(link_targets(text), ["docs/guide/README.md"]);
    assert!(!is_relative("https://bevyengine.org") && !is_relative("#layout") && is_relative("docs/x.md"));
}

/// Every line of a ```sh block that starts with `simlod `, its comment cut off, as arguments.
fn quoted_commands(text: &str) -> Vec<Vec<String>> {
    let mut commands = Vec::new();
    let mut in_sh = false;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if let Some(fence) = trimmed.strip_prefix("```") {
            in_sh = !in_sh && matches!(fence.trim(), "sh" | "bash" | "shell" | "console");
            continue;
        }
        if let Some(args) = trimmed.strip_prefix("simlod ").filter(|_| in_sh) {
            let args = args.split(" #").next().unwrap();
            commands.push(args.split_whitespace().map(str::to_owned).collect());
        }
    }
    commands
}

#[test]
fn every_simlod_command_quoted_in_the_readme_and_the_guide_parses() {
    let mut failed = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for args in quoted_commands(&text) {
            // `--help` after the arguments: clap checks every flag and value before it, then
            // prints the help instead of running the command.
            let out = Command::new(crate::support::simlod_bin())
                .args(&args)
                .arg("--help")
                .current_dir(root())
                .output()
                .unwrap();
            checked += 1;
            if !out.status.success() {
                failed.push(format!(
                    "{}: simlod {}\n  {}",
                    page.strip_prefix(root()).unwrap().display(),
                    args.join(" "),
                    String::from_utf8_lossy(&out.stderr).trim()
                ));
            }
        }
    }
    assert!(checked > 10, "the pages quote simlod's commands ({checked} found)");
    assert!(
        failed.is_empty(),
        "commands that no longer parse:\n{}",
        failed.join("\n")
    );
}

#[test]
fn a_quoted_command_is_read_from_shell_blocks_only_without_its_comment() {
    let text = "simlod run --seconds 1\n```sh\nsimlod run --seconds 2   # two seconds\ncargo t\n```\n```text\nsimlod run FILE\n```\n";
    assert_eq!(quoted_commands(text), [["run", "--seconds", "2"]]);
}
