//! The methods reference `docs/methods.md` holds every section the code cites.
//!
//! Help texts, errors, rustdoc, the Python package, the tests and the README point users to
//! sections of `docs/methods.md` ("docs/methods.md §4.2", or a bare "§4.2" beside such a
//! citation). These tests scan the workspace's sources (std only) and fail when
//! - a cited section has no heading `## §x Title` / `### §x.y Title` in `docs/methods.md` or
//!   the files under `docs/methods/`;
//! - a citation still names the team-internal spec instead of the repository's document
//!   (`tools/methods_refs.py` rewrites those).

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The section sign, written as an escape so that this file cites nothing itself.
const SECTION: char = '\u{a7}';

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("crates/gmwm lies two levels below the workspace root")
        .to_path_buf()
}

/// Text files that may cite the reference: the crates, the benches, CI and the README.
fn sources(root: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
        entries.sort();
        for path in entries {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if !matches!(
                    name,
                    "target" | ".git" | "__pycache__" | "node_modules" | ".venv"
                ) {
                    walk(&path, out);
                }
            } else {
                let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
                let ci = path
                    .parent()
                    .and_then(Path::file_name)
                    .is_some_and(|d| d == ".ci");
                if ci || matches!(ext, "rs" | "py" | "pyi" | "md" | "toml" | "txt" | "sh") {
                    out.push(path);
                }
            }
        }
    }
    let mut out = vec![root.join("README.md")];
    for dir in ["crates", "bench", ".ci"] {
        walk(&root.join(dir), &mut out);
    }
    out
}

/// A section number `x` or `x.y` as (x, y), y = None for a top-level section.
type Section = (u32, Option<u32>);

fn show(s: Section) -> String {
    match s.1 {
        Some(y) => format!("{SECTION}{}.{y}", s.0),
        None => format!("{SECTION}{}", s.0),
    }
}

/// Parses `12` or `12.3` at the start of `s`; returns the section and the bytes read.
fn parse_number(s: &str) -> Option<(Section, usize)> {
    let digits = |t: &str| t.bytes().take_while(u8::is_ascii_digit).count();
    let a = digits(s);
    if a == 0 {
        return None;
    }
    let x: u32 = s[..a].parse().ok()?;
    let rest = &s[a..];
    if let Some(after) = rest.strip_prefix('.') {
        let b = digits(after);
        if b > 0 {
            return Some(((x, Some(after[..b].parse().ok()?)), a + 1 + b));
        }
    }
    Some(((x, None), a))
}

/// Headings of the reference: `#... §x Title` or `#... §x.y Title`.
fn headings(root: &Path) -> BTreeSet<Section> {
    let mut files = vec![root.join("docs/methods.md")];
    if let Ok(dir) = fs::read_dir(root.join("docs/methods")) {
        let mut more: Vec<_> = dir.filter_map(Result::ok).map(|e| e.path()).collect();
        more.retain(|p| p.extension().is_some_and(|e| e == "md"));
        more.sort();
        files.extend(more);
    }
    let mut out = BTreeSet::new();
    for file in files {
        let text = fs::read_to_string(&file)
            .unwrap_or_else(|e| panic!("{}: {e} (the methods reference)", file.display()));
        for line in text.lines() {
            let Some(rest) = line.strip_prefix('#') else {
                continue;
            };
            let rest = rest.trim_start_matches('#').trim_start();
            let Some(number) = rest.strip_prefix(SECTION) else {
                continue;
            };
            if let Some((section, len)) = parse_number(number) {
                let title = number[len..].trim();
                assert!(
                    !title.is_empty(),
                    "{}: heading {line:?} has no title",
                    file.display()
                );
                assert!(
                    out.insert(section),
                    "{}: {} twice",
                    file.display(),
                    show(section)
                );
            }
        }
    }
    out
}

/// Every numbered section the text cites, with its line: `§x`, `§x.y`, and ranges
/// `§a.b–§a.d` / `§a.b–a.d` / `§a–§c` expanded to every section between. A section sign
/// right after `STYLE` cites the style guide, not the methods reference, and is skipped.
fn citations(text: &str) -> Vec<(usize, Section)> {
    let mut out = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        let mut from = 0;
        while let Some(pos) = line[from..].find(SECTION) {
            let at = from + pos;
            from = at + SECTION.len_utf8();
            if line[..at].trim_end().ends_with("STYLE") {
                continue;
            }
            let Some((first, len)) = parse_number(&line[from..]) else {
                continue;
            };
            let mut last = first;
            let after = &line[from + len..];
            for dash in ["\u{2013}", "-"] {
                if let Some(tail) = after.strip_prefix(dash) {
                    let tail = tail.strip_prefix(SECTION).unwrap_or(tail);
                    if let Some((end, _)) = parse_number(tail) {
                        last = end;
                    }
                }
            }
            out.push((line_no + 1, first));
            if last != first {
                match (first, last) {
                    ((a, Some(b)), (c, Some(d))) if a == c && b < d => {
                        out.extend((b + 1..=d).map(|y| (line_no + 1, (a, Some(y)))));
                    }
                    ((a, None), (c, None)) if a < c => {
                        out.extend((a + 1..=c).map(|x| (line_no + 1, (x, None))));
                    }
                    _ => out.push((line_no + 1, last)),
                }
            }
        }
    }
    out
}

#[test]
fn every_cited_section_is_a_heading_of_docs_methods() {
    let root = workspace_root();
    let have = headings(&root);
    assert!(
        have.len() > 50,
        "docs/methods.md: only {} section headings",
        have.len()
    );
    let mut missing = Vec::new();
    let mut cited = 0;
    for file in sources(&root) {
        let Ok(text) = fs::read_to_string(&file) else {
            continue;
        };
        for (line, section) in citations(&text) {
            cited += 1;
            if !have.contains(&section) {
                let rel = file.strip_prefix(&root).unwrap_or(&file);
                missing.push(format!("{}:{line}: {}", rel.display(), show(section)));
            }
        }
    }
    assert!(
        cited > 500,
        "only {cited} citations found: is the scan looking in the right place?"
    );
    assert!(
        missing.is_empty(),
        "{} citations name a section docs/methods.md does not have (add a heading \
         `### {SECTION}x.y Title`):\n{}",
        missing.len(),
        missing.join("\n")
    );
}

#[test]
fn no_citation_names_the_internal_spec() {
    let root = workspace_root();
    let old = concat!("METH", "ODS");
    let mut left = Vec::new();
    for file in sources(&root) {
        let Ok(text) = fs::read_to_string(&file) else {
            continue;
        };
        for (at, _) in text.match_indices(old) {
            // the word, then blanks or a comment break, then the section sign
            let after = text[at + old.len()..].trim_start_matches([' ', '\t', '\n', '/', '!', '#']);
            if after.starts_with(SECTION) || after.starts_with(".md") {
                let line = text[..at].matches('\n').count() + 1;
                let rel = file.strip_prefix(&root).unwrap_or(&file);
                left.push(format!("{}:{line}", rel.display()));
            }
        }
    }
    assert!(
        left.is_empty(),
        "{} citations still name the internal spec; run `python3 tools/methods_refs.py`:\n{}",
        left.len(),
        left.join("\n")
    );
}

#[test]
fn citation_scanner_reads_lists_and_ranges() {
    let s = SECTION;
    let text = format!(
        "(x {s}1.2, {s}1.4) {s}13.8\u{2013}13.10 {s}2.2-{s}2.3 STYLE {s}5 {s}1\u{2013}{s}3"
    );
    let got: Vec<Section> = citations(&text).into_iter().map(|c| c.1).collect();
    let want = [
        (1, Some(2)),
        (1, Some(4)),
        (13, Some(8)),
        (13, Some(9)),
        (13, Some(10)),
        (2, Some(2)),
        (2, Some(3)),
        (1, None),
        (2, None),
        (3, None),
    ];
    // the range's end is read twice (once as the range end, once on its own section sign)
    let got: BTreeSet<_> = got.into_iter().collect();
    assert_eq!(got, want.into_iter().collect());
}
