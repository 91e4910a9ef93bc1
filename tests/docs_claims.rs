//! The numbers the docs quote from the tests, the settings and the code, checked against the
//! constants they quote, so that a page and a test cannot drift apart again:
//! - each claim (`docs_claims/claims.rs`) names a page, its words with `{}` where a number stands,
//!   and where each number is defined: a constant of a test or script read from its source
//!   (`const MIN_PSNR_DB: f64 = 60.0;`), a literal in a line of code, a key of
//!   `config/default.toml` under a preset, or a constant of the library by its Rust name; the
//!   words, with the numbers written as the page writes them, must be on the page;
//! - the presets table of `docs/PRESETS.md` equals what `config/presets/` gives, row by row;
//! - the ratios of `docs/PERFORMANCE.md`'s floor table follow from its own columns;
//! - every tolerance a page quotes ("tolerance 0.85", "the test asks ≥ 0.45", "≥ 60 dB") lies
//!   inside a claim, so a new quote without a claim fails;
//! - controls: every claim with its numbers changed is not on its page, and a constant changed in
//!   its source changes what the check reads.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

#[path = "docs_claims/atmosphere.rs"]
mod atmosphere;
#[path = "docs_claims/claims.rs"]
mod claims;
#[path = "docs_claims/host.rs"]
mod host;
#[path = "docs_claims/presets.rs"]
mod presets;

use std::path::PathBuf;

use atmosphere::ATMOSPHERE_CLAIMS;
use claims::{CLAIMS, Claim, Format, Source};
use host::HOST_CLAIMS;
use presets::PRESET_ROWS;

/// Every claim, of every page.
fn all_claims() -> impl Iterator<Item = &'static Claim> {
    CLAIMS.iter().chain(ATMOSPHERE_CLAIMS).chain(HOST_CLAIMS)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Any run of whitespace as one space: pages wrap their lines anywhere.
fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A number written in source: a literal (`_` separators allowed), or a product of them.
fn parse_number(text: &str) -> Option<f64> {
    text.split('*').map(|f| f.trim().replace('_', "").trim_end_matches("f64").parse::<f64>().ok()).product()
}

/// The value of `name` in `source`: `const NAME: T = V;` in Rust, `NAME = V` in Python, `NAME=V`
/// in shell.
fn constant(source: &str, name: &str) -> Option<f64> {
    source.lines().find_map(|line| {
        let rest = line.trim_start().trim_start_matches("pub ").trim_start_matches("const ");
        let rest = rest.strip_prefix(name)?;
        let rest =
            rest.split_once('=').filter(|(typed, _)| typed.trim().is_empty() || typed.starts_with(':'))?.1;
        parse_number(rest.trim().trim_end_matches(';'))
    })
}

/// The number that stands at `{}` of `pattern` in `source`.
fn literal(source: &str, pattern: &str) -> Option<f64> {
    let (before, after) = pattern.split_once("{}").unwrap();
    let at = source.find(before)? + before.len();
    let rest = &source[at..];
    let end = if after.is_empty() {
        rest.find(|c: char| !(c.is_ascii_digit() || "._e-".contains(c))).unwrap_or(rest.len())
    } else {
        rest.find(after)?
    };
    parse_number(&rest[..end])
}

/// A setting: the preset's value over config/default.toml's (booleans as 0 and 1).
fn setting(preset: Option<&str>, key: &str) -> Vec<f64> {
    let layers: Vec<toml::Table> = std::iter::once("config/default.toml".to_owned())
        .chain(preset.map(|p| format!("config/presets/{p}.toml")))
        .map(|file| read(&file).parse().unwrap())
        .collect();
    let (section, name) = key.split_once('.').unwrap();
    let value = layers
        .iter()
        .rev()
        .find_map(|t| t.get(section).and_then(|s| s.get(name)).cloned())
        .unwrap_or_else(|| panic!("no setting {key}"));
    let number = |v: &toml::Value| match v {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        toml::Value::Boolean(b) => f64::from(u8::from(*b)),
        other => panic!("{key} = {other}: not a number"),
    };
    match &value {
        toml::Value::Array(items) => items.iter().map(number).collect(),
        v => vec![number(v)],
    }
}

/// The numbers a source gives, `read` giving files by their path in the repository.
fn resolve(source: &Source, read: &dyn Fn(&str) -> String) -> Result<Vec<f64>, String> {
    match *source {
        Source::Const { file, name } => {
            constant(&read(file), name).map(|v| vec![v]).ok_or(format!("{file}: no constant {name}"))
        }
        Source::Code { file, from, pattern } => {
            let text = read(file);
            let after = text.find(from).map(|at| &text[at..]).ok_or(format!("{file}: no `{from}`"))?;
            literal(after, pattern).map(|v| vec![v]).ok_or(format!("{file}: no `{pattern}` after `{from}`"))
        }
        Source::Setting { preset, key } => Ok(setting(preset, key)),
        Source::SettingItem { preset, key, index } => {
            setting(preset, key).get(index).map(|v| vec![*v]).ok_or(format!("{key} has no item {index}"))
        }
        Source::Value(v) => Ok(vec![v]),
    }
}

/// `quote` with each `{}` filled by a number written in its format.
fn fill(quote: &str, parts: &[(f64, Format)]) -> Result<String, String> {
    let mut words = String::new();
    let mut rest = quote;
    let mut parts = parts.iter();
    while let Some((before, after)) = rest.split_once("{}") {
        let Some((v, format)) = parts.next() else {
            return Err(format!("more {{}} than numbers in `{quote}`"));
        };
        words.push_str(before);
        words.push_str(&format(*v));
        rest = after;
    }
    if parts.next().is_some() {
        return Err(format!("more numbers than {{}} in `{quote}`"));
    }
    words.push_str(rest);
    Ok(flat(&words))
}

/// The claim's numbers with their formats, source by source (a setting's array fills as many
/// `{}` as it holds).
fn numbers(claim: &Claim, read: &dyn Fn(&str) -> String) -> Result<Vec<(f64, Format)>, String> {
    let mut out = Vec::new();
    for (source, format) in claim.values {
        out.extend(resolve(source, read)?.into_iter().map(|v| (v, *format)));
    }
    Ok(out)
}

/// The claim's words as its page must hold them, or why not.
fn check(claim: &Claim, read: &dyn Fn(&str) -> String) -> Result<String, String> {
    let words = fill(claim.quote, &numbers(claim, read)?).map_err(|e| format!("{}: {e}", claim.doc))?;
    if flat(&read(claim.doc)).contains(&words) {
        Ok(words)
    } else {
        Err(format!("{}: not found: «{words}»", claim.doc))
    }
}

#[test]
fn every_quoted_number_is_the_constant_it_quotes() {
    let failures: Vec<String> = all_claims().filter_map(|c| check(c, &read).err()).collect();
    assert!(
        failures.is_empty(),
        "{} of {} claims fail:\n{}",
        failures.len(),
        all_claims().count(),
        failures.join("\n")
    );
}

#[test]
fn the_presets_table_is_what_the_presets_give() {
    let page = read("docs/PRESETS.md");
    let rows: Vec<&str> = page.lines().filter(|l| l.starts_with("| `")).collect();
    let mut failures = Vec::new();
    for row in &rows {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let Some(spec) = PRESET_ROWS.iter().find(|s| cells[1].starts_with(s.knob)) else {
            failures.push(format!("a row with no spec in PRESET_ROWS: {}", cells[1]));
            continue;
        };
        for (column, preset) in ["fast", "balanced", "accurate"].into_iter().enumerate() {
            let parts: Vec<(f64, Format)> = spec
                .keys
                .iter()
                .flat_map(|(key, format)| setting(Some(preset), key).into_iter().map(|v| (v, *format)))
                .collect();
            let expected = fill(spec.cell, &parts).unwrap();
            if cells[2 + column] != expected {
                failures.push(format!(
                    "{} under {preset}: the page says {}, the preset {expected}",
                    spec.knob,
                    cells[2 + column]
                ));
            }
        }
    }
    for spec in PRESET_ROWS {
        if !rows.iter().any(|r| r[1..].trim_start().starts_with(spec.knob)) {
            failures.push(format!("no row for {}", spec.knob));
        }
    }
    assert!(rows.len() >= 20 && failures.is_empty(), "{} rows:\n{}", rows.len(), failures.join("\n"));
}

/// Rows of the floor table: the pass's time, its floor's, and the ratio the page gives.
fn floor_rows(page: &str) -> Vec<(String, f64, f64, f64)> {
    let ms = |cell: &str| cell.trim().trim_end_matches(" ms").replace(',', "").parse::<f64>().ok();
    page.lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').collect();
            let [_, pass, size, time, floor, ratio, _] = cells[..] else { return None };
            Some((
                format!("{} {}", pass.trim(), size.trim()),
                ms(time)?,
                ms(floor)?,
                ratio.trim().parse().ok()?,
            ))
        })
        .collect()
}

#[test]
fn the_floor_ratios_follow_from_their_columns() {
    let rows = floor_rows(&read("docs/PERFORMANCE.md"));
    assert!(rows.len() >= 9, "the floor table has {} rows", rows.len());
    let wrong = |rows: &[(String, f64, f64, f64)]| -> Vec<String> {
        rows.iter()
            .filter(|(_, time, floor, ratio)| *floor <= 0.0 || (time / floor - ratio).abs() > 0.051)
            .map(|(what, time, floor, ratio)| {
                format!("{what}: {time} / {floor} = {:.2}, not {ratio}", time / floor)
            })
            .collect()
    };
    assert!(wrong(&rows).is_empty(), "{:#?}", wrong(&rows));
    // Control: a ratio one tenth off is caught.
    let mut off = rows.clone();
    off[0].3 += 0.1;
    assert_eq!(wrong(&off).len(), 1);
}

/// Where a page quotes a tolerance: "tolerance" before a number, "the test asks / asserts /
/// allows", a bound in parentheses, a least PSNR.
fn quoted_tolerances(page: &str) -> Vec<usize> {
    let starts_number = |s: &str| s.trim_start().starts_with(|c: char| c.is_ascii_digit());
    let mut at = Vec::new();
    for (i, _) in page.match_indices("tolerance ") {
        if starts_number(&page[i + "tolerance ".len()..]) {
            at.push(i);
        }
    }
    // A test's bound in words counts where its sentence holds a number ("the test asserts that
    // the slicings pop no more than the cloud" quotes none).
    let sentence_has_number = |i: usize| {
        let rest = &page[i..];
        rest[..rest.find(". ").unwrap_or(rest.len())].contains(|c: char| c.is_ascii_digit())
    };
    for key in ["test asks", "test asserts", "test allows"] {
        at.extend(page.match_indices(key).map(|(i, _)| i).filter(|&i| sentence_has_number(i)));
    }
    for key in ["(≥ ", "(≤ "] {
        at.extend(page.match_indices(key).map(|(i, _)| i));
    }
    for (i, _) in page.match_indices("≥ ") {
        let rest = &page[i + "≥ ".len()..];
        let number = rest.split(' ').next().unwrap_or_default();
        if starts_number(rest) && rest[number.len()..].trim_start().starts_with("dB") {
            at.push(i);
        }
    }
    at
}

#[test]
fn every_quoted_tolerance_is_a_claim() {
    let mut pages: Vec<String> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .flatten()
        .map(|e| format!("docs/{}", e.file_name().to_string_lossy()))
        .filter(|p| p.ends_with(".md"))
        .chain(["ARCHITECTURE.md".to_owned(), "README.md".to_owned()])
        .collect();
    pages.sort();
    let mut unclaimed = Vec::new();
    for page in &pages {
        let text = flat(&read(page));
        let spans: Vec<(usize, usize)> = all_claims()
            .filter(|c| c.doc == page)
            .filter_map(|c| check(c, &read).ok())
            .flat_map(|words| text.match_indices(&words).map(|(i, w)| (i, i + w.len())).collect::<Vec<_>>())
            .collect();
        for at in quoted_tolerances(&text) {
            if !spans.iter().any(|&(a, b)| a <= at && at < b) {
                let context: String = text[at..].chars().take(60).collect();
                unclaimed.push(format!("{page}: «{context}…»"));
            }
        }
    }
    assert!(
        unclaimed.is_empty(),
        "tolerances quoted with no claim in tests/docs_claims/claims.rs:\n{}",
        unclaimed.join("\n")
    );
    // Control: the scan finds each kind of quote.
    let sample = "IoU 0.93 (tolerance 0.85); the test asks ≥ 0.45 (≤ 1.35) (≥ 0.9), ≥ 60 dB; occlusion tolerance m. \
         The test asserts that it pops no more than the cloud. The test allows 3 pixels.";
    assert_eq!(quoted_tolerances(sample).len(), 6, "{:?}", quoted_tolerances(sample));
}

#[test]
fn a_claim_with_other_numbers_is_not_on_its_page() {
    for claim in all_claims() {
        // Each number off by a tenth and one: what a changed constant or a stale page would read.
        let other: Vec<(f64, Format)> =
            numbers(claim, &read).unwrap().into_iter().map(|(v, format)| (v * 1.1 + 1.0, format)).collect();
        let words = fill(claim.quote, &other).unwrap();
        assert!(
            !flat(&read(claim.doc)).contains(&words),
            "{}: «{words}» is on the page too: the claim does not pin its numbers",
            claim.doc
        );
    }
    // A constant changed in its source is read as changed, and the claim then fails.
    let truth = all_claims().find(|c| c.quote.contains("tolerance {})")).unwrap();
    let Source::Const { file, name } = truth.values[0].0 else {
        panic!("the control claim reads a constant")
    };
    let edited = |path: &str| {
        let text = read(path);
        if path == file {
            text.replace(&format!("{name}: f64 = "), &format!("{name}: f64 = 1.5 * "))
        } else {
            text
        }
    };
    assert!(check(truth, &read).is_ok() && check(truth, &edited).is_err());
}
