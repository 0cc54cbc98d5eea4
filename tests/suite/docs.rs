//! The documentation is self-contained: every citation of docs/model.md and docs/validation.md
//! by section resolves to a heading there, every equation number cited resolves to an
//! equation labelled in those files, every benchmarks/RESULTS.md section cited by name exists,
//! every docs/ file named exists, and nothing points outside the repository or carries
//! development history.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every text file of the product: sources, tests, docs, benchmarks, scenes, the README.
fn product_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p
                .extension()
                .is_some_and(|x| ["rs", "md", "toml", "sh", "py"].contains(&x.to_str().unwrap()))
            {
                out.push(p);
            }
        }
    }
    let mut out = vec![root().join("README.md")];
    for d in ["src", "tests", "docs", "benchmarks", "lattices"] {
        walk(&root().join(d), &mut out);
    }
    out
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn rel(p: &Path) -> String {
    p.strip_prefix(root()).unwrap().display().to_string()
}

/// The section labels of a doc: "1" for "## 1. Title", "B" for "## B. Title".
fn sections(doc: &str) -> Vec<String> {
    doc.lines()
        .filter_map(|l| l.strip_prefix("## "))
        .filter_map(|h| h.split_once(". ").map(|(n, _)| n.to_string()))
        .collect()
}

/// The section labels cited after `prefix` ("docs/model.md §"): "§3", "§1, §3", "§6–9",
/// "§B.", each label or range end.
fn cited_sections(text: &str, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (at, _) in text.match_indices(prefix) {
        let mut rest = &text[at + prefix.len() - "§".len()..];
        while let Some(r) = rest.strip_prefix('§') {
            let label: String = r
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric())
                .collect();
            out.push(label.clone());
            rest = &r[label.len()..];
            // a range "§6–9", "§B–C" or "§A–§C": its end is a label too
            if let Some(r) = rest.strip_prefix('–') {
                let r = r.strip_prefix('§').unwrap_or(r);
                let end: String = r
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric())
                    .collect();
                out.push(end.clone());
                rest = &r[end.len()..];
            }
            rest = rest.strip_prefix(", ").unwrap_or(rest);
        }
    }
    out
}

#[test]
fn section_citations_resolve_to_headings() {
    let model = sections(&read(&root().join("docs/model.md")));
    let validation = sections(&read(&root().join("docs/validation.md")));
    assert!(
        model.len() >= 13 && validation.len() >= 6,
        "{model:?} {validation:?}"
    );
    let mut missing = Vec::new();
    let mut count = 0;
    for f in product_files() {
        if f.ends_with("tests/suite/docs.rs") {
            // this file names the prefixes it looks for
            continue;
        }
        let text = read(&f);
        for (prefix, known) in [
            ("docs/model.md §", &model),
            ("docs/validation.md §", &validation),
        ] {
            for label in cited_sections(&text, prefix) {
                count += 1;
                if !known.contains(&label) {
                    missing.push(format!("{}: {prefix}{label}", rel(&f)));
                }
            }
        }
    }
    assert!(
        count > 100,
        "only {count} citations found: the scan is broken"
    );
    assert!(
        missing.is_empty(),
        "citations without a heading: {missing:#?}"
    );
}

/// Equation numbers cited in prose and comments, "(3.36)" or "(S.4)": the thesis's chapters
/// 3 to 5 and sppm's own equations.
fn cited_equations(text: &str, rust: bool) -> Vec<String> {
    let mut out = Vec::new();
    for line in text.lines() {
        let prose = if rust {
            match line.find("//") {
                Some(at) => &line[at..],
                None => continue,
            }
        } else {
            line
        };
        let b = prose.as_bytes();
        for (at, _) in prose.match_indices('(') {
            let tail = &prose[at + 1..];
            let close = match tail.find(')') {
                Some(c) => c,
                None => continue,
            };
            let label = &tail[..close];
            let is_eq = match label.split_once('.') {
                Some((ch, n)) => {
                    (["3", "4", "5"].contains(&ch) || ch == "S")
                        && !n.is_empty()
                        && n.len() <= 2
                        && n.chars().all(|c| c.is_ascii_digit())
                }
                None => false,
            };
            // not a call or an index: "(3.5)" after an identifier is code
            let after_ident = at > 0 && (b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_');
            if is_eq && !after_ident {
                out.push(format!("({label})"));
            }
        }
    }
    out
}

#[test]
fn equation_citations_resolve_to_labelled_equations() {
    let docs = read(&root().join("docs/model.md")) + &read(&root().join("docs/validation.md"));
    let mut missing = Vec::new();
    let mut count = 0;
    for f in product_files() {
        if f.ends_with("RESULTS.md") {
            // measured tables: numbers in parentheses are figures, not citations
            continue;
        }
        let rust = f.extension().is_some_and(|x| x == "rs");
        for label in cited_equations(&read(&f), rust) {
            count += 1;
            if !docs.contains(&label) {
                missing.push(format!("{}: {label}", rel(&f)));
            }
        }
    }
    assert!(
        count > 100,
        "only {count} equation citations found: the scan is broken"
    );
    assert!(
        missing.is_empty(),
        "equations cited but not labelled in docs/: {missing:#?}"
    );
}

#[test]
fn results_sections_cited_by_name_exist() {
    let results = read(&root().join("benchmarks/RESULTS.md"));
    let headings: Vec<&str> = results
        .lines()
        .filter(|l| l.starts_with("##"))
        .map(|l| l.trim_start_matches('#').trim_start())
        .collect();
    let mut missing = Vec::new();
    let mut count = 0;
    for f in product_files() {
        // names wrap across lines of prose and comments: the words without comment markers
        let text = read(&f)
            .split_whitespace()
            .filter(|w| !["//", "///", "//!", "#"].contains(w))
            .collect::<Vec<_>>()
            .join(" ");
        for marker in ["RESULTS.md, \"", "RESULTS.md (\""] {
            for (at, _) in text.match_indices(marker) {
                let tail = &text[at + marker.len()..];
                let Some(end) = tail.find('"') else { continue };
                let name = &tail[..end];
                count += 1;
                if !headings.iter().any(|h| h.starts_with(name)) {
                    missing.push(format!("{}: \"{name}\"", rel(&f)));
                }
            }
        }
    }
    assert!(
        count > 20,
        "only {count} citations found: the scan is broken"
    );
    assert!(
        missing.is_empty(),
        "RESULTS.md sections cited but absent: {missing:#?}"
    );
}

#[test]
fn docs_named_exist_and_nothing_points_outside_the_repository() {
    let mut problems = Vec::new();
    for f in product_files() {
        let text = read(&f);
        for (at, _) in text.match_indices("docs/") {
            let name: String = text[at..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || "/_.-".contains(*c))
                .collect();
            let name = name.trim_end_matches('.');
            if name.ends_with(".md") || name.ends_with(".svg") {
                // relative links inside docs/ name their siblings without the folder
                if !root().join(name).exists() {
                    problems.push(format!("{}: {name} does not exist", rel(&f)));
                }
            }
        }
        let lower = text.to_lowercase();
        // (the patterns are assembled so that this file does not match itself)
        for bad in [
            ["..", "/shared"].concat(),
            ["shared", "/spec"].concat(),
            ["/wo", "rk/"].concat(),
        ] {
            if lower.contains(&bad) {
                problems.push(format!(
                    "{}: points outside the repository ({bad})",
                    rel(&f)
                ));
            }
        }
        for word in ["issue ", "stop "] {
            for (at, _) in lower.match_indices(word) {
                let next = lower[at + word.len()..].chars().next();
                if next.is_some_and(|c| c.is_ascii_digit()) {
                    problems.push(format!("{}: development history ({word}N)", rel(&f)));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{problems:#?}");
}
