//! Every image the docs show is made by a committed command: `scripts/docs_images.sh` lists each
//! image with its maker, and this test holds the docs, the files and that list to each other.
//! - every image README.md and the pages under docs/ reference (a Markdown image, or a path
//!   `docs/….png` named in the text) exists and is listed in the script's table;
//! - every PNG under docs/ is listed there and referenced by some page (none left behind);
//! - every row's maker is a function of the script (`make_<maker>`), and every such function
//!   makes some row.
//!
//! No GPU: it reads files only.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `path` with `.` and `..` resolved lexically, relative to the repository root.
fn normalised(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// The Markdown pages whose images count: README.md and every page under docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![PathBuf::from("README.md")];
    let mut stack = vec![PathBuf::from("docs")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(root().join(&dir)).unwrap().map(Result::unwrap) {
            let path = dir.join(entry.file_name());
            if entry.file_type().unwrap().is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
    }
    pages.sort();
    pages
}

/// The images a page shows or names, relative to the repository root: Markdown images
/// (`![alt](file.png)`, relative to the page) and paths `docs/….png` in its text.
fn images_of(page: &Path, text: &str) -> BTreeSet<PathBuf> {
    let mut images = BTreeSet::new();
    let folder = page.parent().unwrap();
    for (at, _) in text.match_indices("](") {
        let target = &text[at + 2..];
        let Some(end) = target.find(')') else { continue };
        let link = target[..end].split_whitespace().next().unwrap_or("");
        let opened_by_image = text[..at].rfind("![").is_some_and(|open| !text[open..at].contains(']'));
        if opened_by_image && !link.contains("://") {
            images.insert(normalised(&folder.join(link)));
        }
    }
    let is_path_char = |c: char| c.is_ascii_alphanumeric() || "_-./".contains(c);
    for (at, _) in text.match_indices("docs/") {
        if text[..at].chars().next_back().is_some_and(is_path_char) {
            continue;
        }
        let rest = &text[at..];
        let end = rest.find(|c: char| !is_path_char(c)).unwrap_or(rest.len());
        if let Some(path) = rest[..end].strip_suffix(".png").map(|p| format!("{p}.png")) {
            images.insert(PathBuf::from(path));
        }
    }
    images
}

/// The script's table: image → maker.
fn listed() -> BTreeMap<PathBuf, String> {
    let script = std::fs::read_to_string(root().join("scripts/docs_images.sh")).unwrap();
    let start = script.find("\ntable=\"\n").expect("scripts/docs_images.sh has its table") + 9;
    let end = start + script[start..].find("\n\"").unwrap();
    let mut table = BTreeMap::new();
    for row in script[start..end].lines().filter(|l| !l.trim().is_empty()) {
        let fields: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(fields.len(), 4, "a row is `image maker needs cost`: {row:?}");
        assert!(["shared", "-"].contains(&fields[2]), "needs is `shared` or `-`: {row:?}");
        assert!(["short", "long"].contains(&fields[3]), "cost is `short` or `long`: {row:?}");
        let previous = table.insert(PathBuf::from(fields[0]), fields[1].to_owned());
        assert!(previous.is_none(), "{} is listed twice", fields[0]);
    }
    table
}

/// The makers the script defines (`make_NAME() {` or `make_NAME() { …`).
fn makers() -> BTreeSet<String> {
    let script = std::fs::read_to_string(root().join("scripts/docs_images.sh")).unwrap();
    script
        .lines()
        .filter_map(|l| l.strip_prefix("make_"))
        .filter_map(|l| l.split_once("()").map(|(name, _)| name.to_owned()))
        .collect()
}

fn pngs_under(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    for entry in std::fs::read_dir(root().join(dir)).unwrap().map(Result::unwrap) {
        let path = dir.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            out.extend(pngs_under(&path));
        } else if path.extension().is_some_and(|e| e == "png") {
            out.insert(path);
        }
    }
    out
}

#[test]
fn every_image_the_docs_show_exists_and_is_made_by_the_script() {
    let table = listed();
    let mut shown = BTreeSet::new();
    let mut problems = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(root().join(&page)).unwrap();
        for image in images_of(&page, &text) {
            if !root().join(&image).is_file() {
                problems.push(format!("{} shows {}, which does not exist", page.display(), image.display()));
            }
            if !table.contains_key(&image) {
                problems.push(format!(
                    "{} shows {}, which scripts/docs_images.sh does not make",
                    page.display(),
                    image.display()
                ));
            }
            shown.insert(image);
        }
    }
    for png in pngs_under(Path::new("docs")) {
        if !table.contains_key(&png) {
            problems
                .push(format!("{} is in docs/ but scripts/docs_images.sh does not make it", png.display()));
        }
        if !shown.contains(&png) {
            problems.push(format!("{} is in docs/ but no page shows it", png.display()));
        }
    }
    for image in table.keys() {
        if !root().join(image).is_file() {
            problems.push(format!("scripts/docs_images.sh lists {}, which does not exist", image.display()));
        }
    }
    let defined = makers();
    let used: BTreeSet<String> = table.values().cloned().collect();
    for maker in used.difference(&defined) {
        problems.push(format!("scripts/docs_images.sh names maker {maker} but defines no make_{maker}"));
    }
    for maker in defined.difference(&used) {
        problems.push(format!("scripts/docs_images.sh defines make_{maker}, which makes no listed image"));
    }
    println!("{} images shown, {} listed, {} makers", shown.len(), table.len(), defined.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(shown.len() >= 30, "only {} images found in the docs: is the reader broken?", shown.len());
}

#[test]
fn the_reader_finds_images_in_both_forms_and_nothing_else() {
    let page = Path::new("docs/light.md");
    let text = "![a](cloud_shadows.png) and ![b](../docs/trade/nc/trade.png 'title'), a [link](x.png), \
                see `docs/soak_nc.png`, not out/docs/x.png, nor docs/notes.md";
    let found: Vec<PathBuf> = images_of(page, text).into_iter().collect();
    let expected: Vec<PathBuf> = ["docs/cloud_shadows.png", "docs/soak_nc.png", "docs/trade/nc/trade.png"]
        .iter()
        .map(PathBuf::from)
        .collect();
    assert_eq!(found, expected);
}
