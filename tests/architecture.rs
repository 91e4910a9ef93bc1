//! The layout ARCHITECTURE.md describes, checked on the sources: the crate's top-level modules
//! form the layers it lists (every import points to a lower layer, so there is no cycle), the
//! constants leaf imports nothing of the crate, no pass's CPU half (nor the twins, nor streaming)
//! reaches into a GPU half, every pass is found in one hop (`src/passes/X/`, `shaders/X.wgsl`),
//! and no source or test file is over 500 lines. Test code (`tests.rs`, `#[cfg(test)]`) may
//! import from anywhere.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            files(&path, ext, out);
        } else if path.extension().is_some_and(|e| e == ext) {
            out.push(path);
        }
    }
}

fn rust_files(dir: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    files(&root().join(dir), "rs", &mut out);
    out.sort();
    out.into_iter()
        .map(|p| {
            let rel = p.strip_prefix(root()).unwrap().to_string_lossy().replace('\\', "/");
            (rel, std::fs::read_to_string(&p).unwrap())
        })
        .collect()
}

/// The source without comments (a doc comment naming `crate::x` is not an import).
fn code(text: &str) -> String {
    text.lines().map(|l| l.split("//").next().unwrap_or_default()).collect::<Vec<_>>().join("\n")
}

/// Identifiers following `prefix` in `text`.
fn paths_after<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
    text.match_indices(prefix)
        .map(|(i, _)| {
            let rest = &text[i + prefix.len()..];
            let end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
            &rest[..end]
        })
        .collect()
}

/// The top-level module a file of `src/` belongs to (`None` for the crate root and binaries).
fn top_module(rel: &str) -> Option<String> {
    let first = rel.strip_prefix("src/")?.split('/').next()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (!["lib", "main", "bin"].contains(&name)).then(|| name.to_string())
}

/// Every `crate::m` a file names, with grouped imports `use crate::{a, b::c}` expanded.
fn crate_modules(text: &str) -> BTreeSet<String> {
    let text = code(text);
    let mut found: BTreeSet<String> = paths_after(&text, "crate::").into_iter().map(str::to_string).collect();
    for (i, _) in text.match_indices("crate::{") {
        let group = &text[i + 8..];
        let group = &group[..group.find('}').unwrap_or(group.len())];
        for item in group.split(',') {
            let head = item.trim().split("::").next().unwrap_or_default().trim();
            if !head.is_empty() {
                found.insert(head.to_string());
            }
        }
    }
    found.remove("");
    found
}

/// The imports between top-level modules, test code left out.
fn module_edges() -> BTreeMap<String, BTreeSet<String>> {
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (rel, text) in rust_files("src") {
        let Some(module) = top_module(&rel) else { continue };
        if rel.ends_with("/tests.rs") {
            continue;
        }
        let text = text.split("#[cfg(test)]").next().unwrap_or_default();
        let targets: Vec<String> = crate_modules(text)
            .into_iter()
            .filter(|t| *t != module && !t.chars().all(|c| c.is_uppercase()))
            .collect();
        edges.entry(module).or_default().extend(targets);
    }
    edges
}

/// ARCHITECTURE.md's layers, lowest first: a module may import only from lower layers.
const LAYERS: &[&[&str]] = &[
    &["gpu", "camera", "publish"],
    &["earth", "atmosphere"],
    &["config", "dataset", "path", "impostor"],
    &["classes", "streaming"],
    &["seeds", "synth", "tree"],
    &["texcell", "light"],
    &["passes", "bake", "sun"],
    &["reference"],
    &["frame"],
    &["profile", "truth", "photo", "host"],
    &["sweep"],
];

#[test]
fn every_import_points_to_a_lower_layer() {
    let layer_of = |m: &str| LAYERS.iter().position(|layer| layer.contains(&m));
    for (module, targets) in module_edges() {
        let Some(from) = layer_of(&module) else {
            panic!("src/{module} is in no layer: place it in ARCHITECTURE.md and in LAYERS here")
        };
        for target in targets {
            let to = layer_of(&target).unwrap_or(usize::MAX);
            assert!(to < from, "{module} (layer {from}) imports {target} (layer {to}): layers point down");
        }
    }
}

#[test]
fn no_import_cycle_between_top_level_modules() {
    let edges = module_edges();
    // A cycle exists when a module reaches itself.
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<(String, Vec<String>)> = vec![(start.clone(), vec![start.clone()])];
        while let Some((at, path)) = stack.pop() {
            for next in edges.get(&at).into_iter().flatten() {
                assert!(next != start, "import cycle: {} -> {start}", path.join(" -> "));
                if seen.insert(next.clone()) {
                    stack.push((next.clone(), [path.clone(), vec![next.clone()]].concat()));
                }
            }
        }
    }
    assert!(edges.len() > 10, "found only {} modules: is src/ there?", edges.len());
}

#[test]
fn the_constants_leaf_imports_nothing_of_the_crate() {
    let words = rust_files("src/gpu/layout").into_iter().filter(|(rel, _)| !rel.ends_with("tests.rs"));
    let files = [(
        "src/gpu/layout.rs".to_string(),
        std::fs::read_to_string(root().join("src/gpu/layout.rs")).unwrap(),
    )];
    let mut seen = 0;
    for (rel, text) in files.into_iter().chain(words) {
        // Its own unit tests may look at it (`use super::*`).
        let code = code(text.split("#[cfg(test)]").next().unwrap_or_default());
        assert!(!code.contains("crate::") && !code.contains("super::"), "{rel} imports from the crate");
        seen += 1;
    }
    assert!(seen >= 2, "found {seen} files of gpu::layout");
}

#[test]
fn cpu_halves_twins_and_streaming_never_reach_into_a_gpu_half() {
    for (rel, text) in rust_files("src") {
        let in_pass = rel.starts_with("src/passes/") && rel.matches('/').count() == 3;
        let cpu_half =
            in_pass && !rel.ends_with("/gpu.rs") && !rel.ends_with("/mod.rs") && !rel.ends_with("/tests.rs");
        let below_passes = rel.starts_with("src/reference/") || rel.starts_with("src/streaming/");
        if !(cpu_half || below_passes) {
            continue;
        }
        let code = code(&text);
        for (i, _) in code.match_indices("::gpu::") {
            let before = &code[..i];
            let owner = before.rsplit(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':')).next();
            let owner = owner.unwrap_or_default();
            assert!(
                !(owner.contains("passes::") || owner.ends_with("super")),
                "{rel} imports a pass's GPU half ({owner}::gpu::...)"
            );
        }
        assert!(!(below_passes && code.contains("crate::frame")), "{rel} depends on the renderer");
    }
}

#[test]
fn every_pass_is_found_in_one_hop() {
    let passes =
        std::fs::read_dir(root().join("src/passes")).unwrap().flatten().filter(|e| e.path().is_dir());
    let mut names: Vec<String> = passes.map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert!(names.len() >= 7, "{names:?}");
    for name in &names {
        let folder = root().join("src/passes").join(name);
        assert!(
            folder.join("mod.rs").is_file() && folder.join("gpu.rs").is_file(),
            "src/passes/{name}/ lacks mod.rs or gpu.rs"
        );
        assert!(root().join("shaders").join(format!("{name}.wgsl")).is_file(), "no shaders/{name}.wgsl");
        let gpu = std::fs::read_to_string(folder.join("gpu.rs")).unwrap();
        assert!(
            gpu.contains(&format!("name: \"{name}\"")),
            "src/passes/{name}/gpu.rs does not build shaders/{name}.wgsl"
        );
        // Passes whose output the CPU relies on have a twin of the same name.
        let twin = root().join("src/reference").join(format!("{name}.rs"));
        let drawn = ["terrain", "ground", "draw_seeds"].contains(&name.as_str());
        assert!(drawn || twin.is_file(), "no src/reference/{name}.rs");
    }
}

#[test]
fn no_source_or_test_file_is_over_500_lines() {
    let mut all = Vec::new();
    for dir in ["src", "tests", "benches", "shaders", "data-tools/src", "data-tools/tests", "testkit/src"] {
        let path = root().join(dir);
        if path.is_dir() {
            files(&path, "rs", &mut all);
            files(&path, "wgsl", &mut all);
        }
    }
    let long: Vec<String> = all
        .iter()
        .filter_map(|p| {
            let lines = std::fs::read_to_string(p).unwrap().lines().count();
            (lines > 500).then(|| format!("{} ({lines})", p.strip_prefix(root()).unwrap().display()))
        })
        .collect();
    assert!(long.is_empty(), "files over 500 lines: {long:?}");
}
