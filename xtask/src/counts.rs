//! The on-target probe's instruction counts against the committed ones:
//! the probe prints `COUNT <name> <instructions> <what>`, and
//! `firmware/probe/counts.txt` holds each count with its tolerance. A
//! count outside its tolerance fails the run until the code goes back or
//! the file changes with it, so the file is the one home of these numbers.

use std::collections::BTreeMap;
use std::path::Path;

/// One committed count: instructions and the tolerance either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Expected {
    pub instructions: f64,
    pub tolerance: f64,
}

/// The counts in the probe's output, by name; a malformed `COUNT` line is
/// an error naming it.
pub fn measured(output: &str) -> Result<BTreeMap<String, f64>, String> {
    let mut out = BTreeMap::new();
    for (i, line) in output.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("COUNT") {
            continue;
        }
        let (Some(name), Some(value)) = (words.next(), words.next()) else {
            return Err(format!(
                "probe output line {}: `{line}`: want COUNT <name> <instructions>",
                i + 1
            ));
        };
        let v: f64 = value
            .parse()
            .map_err(|e| format!("probe output line {}: count `{value}`: {e}", i + 1))?;
        out.insert(name.to_string(), v);
    }
    Ok(out)
}

/// The committed counts in `text` (the file `path`): one
/// `<name> <instructions> <tolerance>` a line, `#` comments.
pub fn expected(text: &str, path: &Path) -> Result<BTreeMap<String, Expected>, String> {
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = || format!("{}:{}", path.display(), i + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        let [name, value, tol] = words[..] else {
            return Err(format!(
                "{}: want `<name> <instructions> <tolerance>`, got `{line}`",
                at()
            ));
        };
        let num = |w: &str, what: &str| -> Result<f64, String> {
            match w.parse::<f64>() {
                Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
                _ => Err(format!(
                    "{}: {what} `{w}` is not a non-negative number",
                    at()
                )),
            }
        };
        let e = Expected {
            instructions: num(value, "instructions")?,
            tolerance: num(tol, "tolerance")?,
        };
        if out.insert(name.to_string(), e).is_some() {
            return Err(format!("{}: `{name}` is listed twice", at()));
        }
    }
    Ok(out)
}

/// Every way `measured` disagrees with `expected`: a count past its
/// tolerance, a committed count the probe did not print, or a printed
/// count the file does not hold.
pub fn compare(
    measured: &BTreeMap<String, f64>,
    expected: &BTreeMap<String, Expected>,
) -> Vec<String> {
    let mut problems = Vec::new();
    for (name, e) in expected {
        match measured.get(name) {
            None => problems.push(format!("{name}: committed but not measured")),
            Some(&m) if (m - e.instructions).abs() > e.tolerance => problems.push(format!(
                "{name}: measured {m:.1} instructions, committed {} ± {}",
                e.instructions, e.tolerance
            )),
            Some(_) => {}
        }
    }
    for (name, m) in measured {
        if !expected.contains_key(name) {
            problems.push(format!(
                "{name}: measured {m:.1} instructions, not committed"
            ));
        }
    }
    problems
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str =
        "# name instructions tolerance\nimpedance_tick 227.7 1\nxyz 457.7 2 # three axes\n";

    #[test]
    fn a_count_inside_its_tolerance_passes_and_outside_fails() {
        let e = expected(FILE, Path::new("counts.txt")).unwrap();
        let ok = measured("PASS x\nCOUNT impedance_tick 228.5 what\nCOUNT xyz 456.0 w\n").unwrap();
        assert!(compare(&ok, &e).is_empty());
        let bad = measured("COUNT impedance_tick 228.8 what\nCOUNT xyz 456.0 w\n").unwrap();
        let p = compare(&bad, &e);
        assert_eq!(p.len(), 1);
        assert!(p[0].starts_with("impedance_tick: measured 228.8"), "{p:?}");
    }

    #[test]
    fn missing_and_unlisted_counts_are_named() {
        let e = expected(FILE, Path::new("counts.txt")).unwrap();
        let m = measured("COUNT impedance_tick 227.7 a\nCOUNT new_one 10 b\n").unwrap();
        let p = compare(&m, &e);
        assert!(p
            .iter()
            .any(|l| l.starts_with("xyz: committed but not measured")));
        assert!(p.iter().any(|l| l.starts_with("new_one: measured 10.0")));
    }

    #[test]
    fn bad_lines_name_the_file_and_line() {
        let e = expected("a 1 1\nb x 1\n", Path::new("counts.txt")).unwrap_err();
        assert!(e.starts_with("counts.txt:2: instructions `x`"), "{e}");
        let e = expected("a 1\n", Path::new("counts.txt")).unwrap_err();
        assert!(e.starts_with("counts.txt:1: want"), "{e}");
        let e = expected("a 1 1\na 2 1\n", Path::new("c")).unwrap_err();
        assert!(e.contains("listed twice"), "{e}");
        assert!(measured("COUNT a nope\n").is_err());
    }
}
