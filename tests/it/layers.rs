//! The core library's layers import one way: each module only from those below it (the
//! architecture page of the guide draws them). The game, the lab tools and the command line
//! are crates of their own, so the compiler keeps them above the core.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Bottom to top. A module may import any module of a lower layer, and of its own layer only
/// those listed before it.
type Layers = &'static [(&'static str, &'static [&'static str])];

/// The core library's layers.
const LAYERS: Layers = &[
    ("the level contract", &["contract"]),
    ("kinds and their files", &["config", "kind", "third_party"]),
    ("sense", &["sense"]),
    ("the models of each level", &["models"]),
    ("level selection and switching", &["lod"]),
    ("the paper's world", &["arena", "creature", "outcome"]),
    ("the plugin that puts the layers together", &["plugin"]),
    ("the headless harness", &["headless"]),
];

/// The lab's: the tools build on the scenes they run, and the experiments on the bench.
const LAB_LAYERS: Layers = &[
    ("the scenes", &["scene", "error"]),
    ("the bench and the recorder", &["bench", "record"]),
    ("the experiments", &["experiments"]),
];

/// Where `module` stands in `layers`: its place in the order, and its layer's name.
fn rank(layers: Layers, module: &str) -> Option<(usize, &'static str)> {
    layers
        .iter()
        .flat_map(|(layer, modules)| modules.iter().map(move |m| (*m, *layer)))
        .enumerate()
        .find(|(_, (m, _))| *m == module)
        .map(|(i, (_, layer))| (i, layer))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`lod` for `src/lod/select.rs`), or
/// `None` for `lib.rs`, the top, which puts the layers together.
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).unwrap();
    let first = relative.components().next()?.as_os_str().to_str()?;
    (first != "lib.rs").then(|| first.trim_end_matches(".rs").to_owned())
}

/// The modules a line of code names through `crate::` (in a path or a `use` group), and
/// whether it names an item of the crate root itself.
fn named_modules(layers: Layers, code: &str) -> (BTreeSet<String>, bool) {
    let (mut modules, mut root) = (BTreeSet::new(), false);
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        // `crate::{a::X, Y}`: each item of the group, up to its closing brace.
        let group = rest.strip_prefix('{').map(|g| &g[..g.find('}').unwrap_or(g.len())]);
        let heads: Vec<&str> = match group {
            Some(g) => g.split(',').map(str::trim).collect(),
            None => vec![rest],
        };
        for head in heads {
            let name: String = head.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if rank(layers, &name).is_some() || head[name.len()..].starts_with("::") {
                modules.insert(name);
            } else if !name.is_empty() {
                root = true;
            }
        }
    }
    (modules, root)
}

/// Every import of the crate at `src` against `layers`: what goes against them.
fn imports_against(src: &Path, layers: Layers) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut wrong = Vec::new();
    let mut edges = BTreeSet::new();
    for file in &files {
        let Some(module) = module_of(src, file) else { continue };
        let Some((own, own_layer)) = rank(layers, &module) else {
            wrong.push(format!(
                "{}: module `{module}` is in no layer of tests/it/layers.rs",
                file.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let (modules, root) = named_modules(layers, code);
            let at = format!("{}:{}: `{}`", file.display(), n + 1, line.trim());
            if root {
                wrong.push(format!(
                    "{at}: names the crate root (the top); import from the module that defines it"
                ));
            }
            for other in modules.into_iter().filter(|m| *m != module) {
                edges.insert((module.clone(), other.clone()));
                match rank(layers, &other) {
                    Some((r, layer)) if r > own => wrong.push(format!(
                        "{at}: `{module}` ({own_layer}) imports `{other}` ({layer}), above it"
                    )),
                    None => wrong.push(format!("{at}: `{other}` is in no layer")),
                    _ => {}
                }
            }
        }
    }
    for (a, b) in &edges {
        if edges.contains(&(b.clone(), a.clone())) && a < b {
            wrong.push(format!("`{a}` and `{b}` import each other"));
        }
    }
    assert!(edges.len() >= layers.len(), "the check saw the imports: {edges:?}");
    wrong
}

#[test]
fn each_core_module_imports_only_the_layers_below_it() {
    let wrong = imports_against(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), LAYERS);
    assert!(wrong.is_empty(), "imports against the layers:\n{}", wrong.join("\n"));
}

#[test]
fn each_module_of_the_lab_imports_only_those_below_it() {
    let lab = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/lab/src");
    let wrong = imports_against(&lab, LAB_LAYERS);
    assert!(
        wrong.is_empty(),
        "imports against the lab's layers:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_layer_check_reads_paths_and_groups() {
    assert_eq!(
        named_modules(LAYERS, "use crate::{contract::Lod, config::SimConfig};").0,
        BTreeSet::from(["config".to_owned(), "contract".to_owned()])
    );
    assert!(named_modules(LAYERS, "use crate::{SimClock, lod::Lod};").1);
    assert_eq!(
        named_modules(LAYERS, ".after(crate::outcome::advance_clock)").0,
        BTreeSet::from(["outcome".to_owned()])
    );
}
