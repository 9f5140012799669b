//! The docs quote the probe's instruction counts: each quote is marked
//! `<!-- probe:NAME -->` after its number, and this test holds it to
//! `firmware/probe/counts.txt`, the one file the numbers live in.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `counts.txt`'s counts by name.
fn counts() -> BTreeMap<String, f64> {
    let text = std::fs::read_to_string(root().join("firmware/probe/counts.txt")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let mut f = l.split_whitespace();
            let name = f.next().unwrap().to_string();
            let count = f.next().and_then(|c| c.parse().ok());
            (name, count.unwrap_or_else(|| panic!("counts.txt: {l:?}")))
        })
        .collect()
}

/// Every `(file, line, number as written, name)` a doc marks.
fn quotes() -> Vec<(String, usize, String, String)> {
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
            while let Some(at) = rest.find("<!-- probe:") {
                let before = rest[..at].trim_end();
                let number: String = before
                    .chars()
                    .rev()
                    .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == ',')
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect();
                let after = &rest[at + "<!-- probe:".len()..];
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

/// Each marked quote is the count `counts.txt` holds, to the digits it
/// shows; and the docs quote the counts the linkage and passivity pages
/// rest on.
#[test]
fn the_docs_quote_the_probes_counts() {
    let counts = counts();
    let quotes = quotes();
    for (file, line, number, name) in &quotes {
        let count = counts
            .get(name)
            .unwrap_or_else(|| panic!("{file}:{line}: no count {name:?} in counts.txt"));
        let shown: f64 = number
            .replace(',', "")
            .parse()
            .unwrap_or_else(|_| panic!("{file}:{line}: no number before probe:{name}"));
        let digits = number.split('.').nth(1).map_or(0, str::len);
        let step = 10f64.powi(-(digits as i32));
        assert!(
            (shown - count).abs() <= 0.5 * step + 1e-9,
            "{file}:{line}: quotes {number} for {name}; counts.txt has {count}"
        );
    }
    for name in [
        "serial_arm_tick",
        "delta_tick",
        "energy_sum_f32",
        "empty_loop",
    ] {
        assert!(
            quotes.iter().any(|q| q.3 == name),
            "no doc quotes {name} with its marker"
        );
    }
}
