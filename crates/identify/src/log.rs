//! An experiment's record, one row a tick, as CSV.
//!
//! ```text
//! # twoport experiment: period_ticks = 1000, first = 1, last = 450
//! t_s,force_n,position_m,load_cell_n
//! 0.000,-0.0312,0.000000,0.0041
//! 0.001,1.8807,0.000001,-0.0213
//! ```
//!
//! - `t_s`: the tick's time (s), evenly spaced: the spacing is the
//!   sample period.
//! - `force_n`: the actuator's force on the device (N), positive toward
//!   `+x` (the push; the paper's `f_a` with its sign turned).
//! - `position_m`: the encoder's reading (m).
//! - `load_cell_n` (optional): the load cell's reading (N).
//!
//! A comment line `# twoport experiment: ...` names the excitation, so
//! that the record says what was played:
//!
//! - a periodic one (twoport's multisine, another program's with random
//!   phases, a chirp repeated every period): `period_ticks = P, first = a,
//!   last = b`, the harmonics `a..=b` of a period of `P` samples;
//! - a stepped sine: `stepped, step_ticks = L`, one frequency held for
//!   each `L` samples, in any order.
//!
//! A record made elsewhere can say the same with `twoport identify
//! --excitation`, in the same words. One file holds one axis's
//! experiment.

use crate::IdentifyError;
use std::fmt::Write as _;

/// What an experiment played.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Excitation {
    /// A force that repeats every `period_ticks` samples (a multisine, a
    /// chirp swept once a period, random phases), with the harmonics
    /// `first..=last` of that period in it.
    Periodic {
        /// The period (samples).
        period_ticks: usize,
        /// The lowest harmonic.
        first: usize,
        /// The highest.
        last: usize,
    },
    /// A stepped sine: one frequency held for each `step_ticks` samples,
    /// the steps in any order, each read from its own force.
    Stepped {
        /// Samples a step.
        step_ticks: usize,
    },
}

impl Excitation {
    /// A periodic excitation's period (samples) and its first and last
    /// harmonics; `None` for a stepped sine.
    pub fn periodic(&self) -> Option<(usize, usize, usize)> {
        match *self {
            Excitation::Periodic {
                period_ticks,
                first,
                last,
            } => Some((period_ticks, first, last)),
            Excitation::Stepped { .. } => None,
        }
    }

    /// The words of the record's comment line after its mark, as
    /// [`Excitation::parse`] reads them.
    pub fn words(&self) -> String {
        match self {
            Excitation::Periodic {
                period_ticks,
                first,
                last,
            } => format!("period_ticks = {period_ticks}, first = {first}, last = {last}"),
            Excitation::Stepped { step_ticks } => format!("stepped, step_ticks = {step_ticks}"),
        }
    }

    /// Read `period_ticks = P, first = a, last = b` or `stepped,
    /// step_ticks = L`; the error says what is wrong.
    pub fn parse(words: &str) -> Result<Excitation, String> {
        let mut parts: Vec<&str> = words.split(',').map(str::trim).collect();
        let stepped = parts.first() == Some(&"stepped");
        if stepped {
            parts.remove(0);
        }
        let mut v = [None; 4];
        for part in parts {
            let (k, x) = part
                .split_once('=')
                .ok_or_else(|| format!("`{part}` is not `name = value`"))?;
            let x: usize = x
                .trim()
                .parse()
                .map_err(|_| format!("{} = `{}` is not a whole number", k.trim(), x.trim()))?;
            let slot = match (stepped, k.trim()) {
                (false, "period_ticks") => 0,
                (false, "first") => 1,
                (false, "last") => 2,
                (true, "step_ticks") => 3,
                (_, other) => {
                    return Err(format!(
                        "`{other}`: the excitation names period_ticks, first and last, or is `stepped, step_ticks = L`"
                    ))
                }
            };
            v[slot] = Some(x);
        }
        match v {
            [Some(period_ticks), Some(first), Some(last), None] if period_ticks > 0 => {
                Ok(Excitation::Periodic {
                    period_ticks,
                    first,
                    last,
                })
            }
            [None, None, None, Some(step_ticks)] if step_ticks > 0 => {
                Ok(Excitation::Stepped { step_ticks })
            }
            _ => Err(
                "the excitation must name period_ticks, first and last (a period above zero), or be `stepped, step_ticks = L` (L above zero)"
                    .into(),
            ),
        }
    }
}

/// An experiment's record.
#[derive(Clone, Debug, PartialEq)]
pub struct Log {
    /// The sample period (s).
    pub period_s: f64,
    /// The actuator's push on the device (N, toward `+x`).
    pub force_n: Vec<f64>,
    /// The encoder (m).
    pub position_m: Vec<f64>,
    /// The load cell (N), if the device has one.
    pub load_cell_n: Option<Vec<f64>>,
    /// The excitation, if the record names it.
    pub excitation: Option<Excitation>,
}

const COLUMNS: [&str; 4] = ["t_s", "force_n", "position_m", "load_cell_n"];
const MARK: &str = "# twoport experiment:";

impl Log {
    /// The record as CSV, with its excitation's comment line.
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        if let Some(e) = self.excitation {
            let _ = writeln!(s, "{MARK} {}", e.words());
        }
        let cols = if self.load_cell_n.is_some() { 4 } else { 3 };
        let _ = writeln!(s, "{}", COLUMNS[..cols].join(","));
        for i in 0..self.force_n.len() {
            let _ = write!(
                s,
                "{},{:e},{:e}",
                i as f64 * self.period_s,
                self.force_n[i],
                self.position_m[i]
            );
            if let Some(lc) = &self.load_cell_n {
                let _ = write!(s, ",{:e}", lc[i]);
            }
            s.push('\n');
        }
        s
    }

    /// Read a record; `source` names it in errors, each of which says the
    /// line and what is wrong there.
    pub fn from_csv(text: &str, source: &str) -> Result<Log, IdentifyError> {
        // (Line 0: the record as a whole.)
        let bad = |line: usize, why: String| IdentifyError::Log {
            place: if line > 0 {
                format!("{source}, line {line}")
            } else {
                source.to_string()
            },
            why,
        };
        let mut excitation = None;
        let mut header: Option<usize> = None;
        let mut rows: Vec<[f64; 4]> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let l = raw.trim();
            if let Some(rest) = l.strip_prefix(MARK) {
                excitation = Some(Excitation::parse(rest).map_err(|w| bad(line, w))?);
                continue;
            }
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let cells: Vec<&str> = l.split(',').map(str::trim).collect();
            let Some(cols) = header else {
                let want3 = &COLUMNS[..3];
                if cells == want3 || cells == COLUMNS {
                    header = Some(cells.len());
                    continue;
                }
                return Err(bad(
                    line,
                    format!(
                        "the header must be `{}` or `{}`, not `{l}`",
                        want3.join(","),
                        COLUMNS.join(",")
                    ),
                ));
            };
            if cells.len() != cols {
                return Err(bad(
                    line,
                    format!("{} columns, but the header has {cols}", cells.len()),
                ));
            }
            let mut row = [0.0; 4];
            for (c, cell) in cells.iter().enumerate() {
                row[c] = cell
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(
                            line,
                            format!("{} = `{cell}` is not a finite number", COLUMNS[c]),
                        )
                    })?;
            }
            rows.push(row);
        }
        let Some(cols) = header else {
            return Err(bad(
                0,
                "no header line (t_s,force_n,position_m[,load_cell_n])".into(),
            ));
        };
        if rows.len() < 4 {
            return Err(bad(
                0,
                format!("{} samples: far too short to identify", rows.len()),
            ));
        }
        // Evenly spaced: the first step is the period, and every step is
        // within a thousandth of it (a dropped frame is a doubled step).
        let first_line = |k: usize| {
            // (Rows are counted after the header; a line number is nearer
            // the user's file, but rows are what a gap is measured in.)
            k + 1
        };
        let period_s = rows[1][0] - rows[0][0];
        // (t_s values are finite, so the difference is too.)
        if period_s <= 0.0 {
            return Err(bad(
                0,
                format!("t_s does not increase from the first sample to the second ({period_s} s)"),
            ));
        }
        for k in 1..rows.len() {
            let dt = rows[k][0] - rows[k - 1][0];
            if (dt - period_s).abs() > 1e-3 * period_s {
                return Err(bad(
                    0,
                    format!(
                        "t_s steps by {dt} s at sample {} (t = {} s), against {period_s} s before: samples are missing or repeated",
                        first_line(k),
                        rows[k][0]
                    ),
                ));
            }
        }
        let col = |c: usize| rows.iter().map(|r| r[c]).collect::<Vec<f64>>();
        Ok(Log {
            period_s,
            force_n: col(1),
            position_m: col(2),
            load_cell_n: (cols == 4).then(|| col(3)),
            excitation,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log() -> Log {
        Log {
            period_s: 1e-3,
            force_n: vec![0.5, -1.25, 2.0, 0.0, 3.5],
            position_m: vec![1e-6, 2e-6, -3e-6, 0.0, 1.5e-5],
            load_cell_n: Some(vec![0.1, 0.2, 0.3, 0.4, 0.5]),
            excitation: Some(Excitation::Periodic {
                period_ticks: 5,
                first: 1,
                last: 2,
            }),
        }
    }

    #[test]
    fn a_record_round_trips() {
        let l = log();
        let back = Log::from_csv(&l.to_csv(), "t.csv").unwrap();
        assert_eq!(back.force_n, l.force_n);
        assert_eq!(back.position_m, l.position_m);
        assert_eq!(back.load_cell_n, l.load_cell_n);
        assert_eq!(back.excitation, l.excitation);
        assert!((back.period_s - 1e-3).abs() < 1e-15);
        let plain = Log {
            load_cell_n: None,
            excitation: None,
            ..l
        };
        assert_eq!(
            Log::from_csv(&plain.to_csv(), "t.csv").unwrap(),
            Log {
                period_s: back.period_s,
                ..plain
            }
        );
    }

    /// Each bad record is refused with the line and the reason.
    #[test]
    fn bad_records_name_the_line_and_the_reason() {
        let good = log().to_csv();
        let cases = [
            (
                good.replace("t_s,force_n", "time,force_n"),
                "line 2: the header must be",
            ),
            (
                good.replacen("2e0", "x", 1),
                "force_n = `x` is not a finite number",
            ),
            (
                good.replacen("1.5e-5", "NaN", 1),
                "position_m = `NaN` is not a finite number",
            ),
            (
                good.replacen(",1e-1", "", 1),
                "line 3: 3 columns, but the header has 4",
            ),
            (
                good.replacen("0.003,", "0.0035,", 1),
                "samples are missing or repeated",
            ),
            (
                good.replacen("first = 1", "first = one", 1),
                "line 1: first = `one` is not a whole number",
            ),
            (
                "t_s,force_n,position_m\n0,1,2\n".to_string(),
                "far too short",
            ),
            ("# nothing\n".to_string(), "no header line"),
        ];
        for (text, want) in cases {
            let e = Log::from_csv(&text, "bench.csv").unwrap_err().to_string();
            assert!(
                e.contains("bench.csv") && e.contains(want),
                "{e}\nwanted: {want}\n{text}"
            );
        }
    }

    /// A stepped sine's line round-trips; lines that mix the two kinds,
    /// or leave one out, are refused with the reason.
    #[test]
    fn a_stepped_sine_is_named_and_read_back() {
        let stepped = Excitation::Stepped { step_ticks: 2000 };
        assert_eq!(stepped.words(), "stepped, step_ticks = 2000");
        assert_eq!(Excitation::parse(&stepped.words()), Ok(stepped));
        let l = Log {
            excitation: Some(stepped),
            ..log()
        };
        let back = Log::from_csv(&l.to_csv(), "t.csv").unwrap();
        assert_eq!(back.excitation, Some(stepped));
        for (words, want) in [
            ("stepped, period_ticks = 5", "`period_ticks`"),
            ("period_ticks = 5, first = 1", "must name period_ticks"),
            ("stepped", "must name period_ticks"),
            ("stepped, step_ticks = 0", "above zero"),
            ("period_ticks = 0, first = 1, last = 2", "above zero"),
        ] {
            let e = Excitation::parse(words).unwrap_err();
            assert!(e.contains(want), "{words}: {e}");
        }
    }
}
