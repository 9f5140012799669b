//! The docs quote the probe's instruction counts and the benchmarks'
//! figures: each quote is marked `<!-- probe:NAME -->` or
//! `<!-- bench:NAME -->` after its number, and these tests hold it to the
//! one file its numbers live in, `firmware/probe/counts.txt` or
//! `benches/figures.txt`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A table's numbers by name: each line not a comment is a name and a
/// number, then whatever the file says of it.
fn table(path: &str) -> BTreeMap<String, f64> {
    let text = std::fs::read_to_string(root().join(path)).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let mut f = l.split_whitespace();
            let name = f.next().unwrap().to_string();
            let value = f.next().and_then(|c| c.parse().ok());
            (name, value.unwrap_or_else(|| panic!("{path}: {l:?}")))
        })
        .collect()
}

/// Every `(file, line, number as written, name)` a doc marks with
/// `<!-- KIND:NAME -->`.
fn quotes(kind: &str) -> Vec<(String, usize, String, String)> {
    let tag = format!("<!-- {kind}:");
    let mut files = vec![root().join("README.md")];
    for dir in ["docs", "crates"] {
        let mut stack = vec![root().join(dir)];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() && !p.ends_with("target") {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "md") {
                    files.push(p);
                }
            }
        }
    }
    let mut out = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let mut rest = line;
            while let Some(at) = rest.find(&tag) {
                let before = rest[..at].trim_end();
                let number: String = before
                    .chars()
                    .rev()
                    .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == ',')
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect();
                let after = &rest[at + tag.len()..];
                let end = after.find("-->").unwrap_or(after.len());
                let name = after[..end].trim().to_string();
                let shown = f.strip_prefix(root()).unwrap_or(&f).display().to_string();
                out.push((shown, i + 1, number, name));
                rest = &after[end..];
            }
        }
    }
    out
}

/// Each quote marked `kind` is its number in `values` (from `file`), to
/// the digits it shows.
fn check(kind: &str, file: &str, values: &BTreeMap<String, f64>) -> Vec<String> {
    let quotes = quotes(kind);
    for (doc, line, number, name) in &quotes {
        let value = values
            .get(name)
            .unwrap_or_else(|| panic!("{doc}:{line}: no {name:?} in {file}"));
        let shown: f64 = number
            .replace(',', "")
            .parse()
            .unwrap_or_else(|_| panic!("{doc}:{line}: no number before {kind}:{name}"));
        let digits = number.split('.').nth(1).map_or(0, str::len);
        let step = 10f64.powi(-(digits as i32));
        assert!(
            (shown - value).abs() <= 0.5 * step + 1e-9,
            "{doc}:{line}: quotes {number} for {name}; {file} has {value}"
        );
    }
    quotes.into_iter().map(|q| q.3).collect()
}

/// Each marked quote is the count `counts.txt` holds, to the digits it
/// shows; and the docs quote the counts the linkage and passivity pages
/// rest on.
#[test]
fn the_docs_quote_the_probes_counts() {
    let file = "firmware/probe/counts.txt";
    let quoted = check("probe", file, &table(file));
    for name in [
        "serial_arm_tick",
        "delta_tick",
        "energy_sum_f32",
        "empty_loop",
    ] {
        assert!(
            quoted.iter().any(|q| q == name),
            "no doc quotes {name} with its marker"
        );
    }
}

/// Each marked quote is the figure `benches/figures.txt` holds, to the
/// digits it shows; and every figure there is quoted, so that none is
/// left behind when the docs move on.
#[test]
fn the_docs_quote_the_benchmarks_figures() {
    let file = "benches/figures.txt";
    let figures = table(file);
    let quoted = check("bench", file, &figures);
    for name in figures.keys() {
        assert!(
            quoted.iter().any(|q| q == name),
            "{file}: no doc quotes {name} with its marker"
        );
    }
}
