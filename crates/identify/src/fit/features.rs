//! What the encoder's response shows of the modes: its peaks, the most
//! prominent resonances with their antiresonances (a fit's start), and
//! the band below the lowest, where the device moves as one body.

use crate::frf::Frf;

/// Every peak of `ln(|H| ω²)`: its prominence over the deeper of the
/// dips either side before a higher point, and its index.
fn peaks(data: &Frf) -> (Vec<f64>, Vec<(f64, usize)>) {
    let g: Vec<f64> = data
        .response
        .iter()
        .zip(&data.freq_hz)
        .map(|(h, f)| (h.norm() * f * f).ln())
        .collect();
    let n = g.len();
    let peaks = (1..n.saturating_sub(1))
        .filter(|&i| g[i] > g[i - 1] && g[i] >= g[i + 1])
        .map(|i| {
            let side = |range: &mut dyn Iterator<Item = usize>| {
                let mut low = g[i];
                for j in range {
                    if g[j] > g[i] {
                        break;
                    }
                    low = low.min(g[j]);
                }
                low
            };
            let left = side(&mut (0..i).rev());
            let right = side(&mut (i + 1..n));
            (g[i] - left.max(right), i)
        })
        .collect();
    (g, peaks)
}

/// The `modes` most prominent resonances of `|H| ω²` (indices into the
/// harmonics), in order, each with the deepest dip before it.
pub(super) fn features(data: &Frf, modes: usize) -> Option<(Vec<usize>, Vec<usize>)> {
    let (g, mut peaks) = peaks(data);
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    if peaks.len() < modes {
        return None;
    }
    let mut res: Vec<usize> = peaks[..modes].iter().map(|p| p.1).collect();
    res.sort_unstable();
    let mut anti = Vec::with_capacity(modes);
    let mut from = 0;
    for &r in &res {
        let a = (from..r).min_by(|&a, &b| g[a].total_cmp(&g[b]))?;
        anti.push(a);
        from = r + 1;
    }
    Some((anti, res))
}

/// Below where the device moves as one body (Hz): a quarter of the way to
/// its lowest resonance, or of the band where it shows none.
pub(super) fn rigid_band_hz(x: &Frf) -> f64 {
    lowest_resonance_hz(x)
        .or(x.freq_hz.last().copied())
        .unwrap_or(0.0)
        / 4.0
}

/// The lowest resonance seen at the encoder (Hz): a peak of `|H| ω²` at
/// least twice the lower of the least values either side within a factor
/// of 1.5 in frequency. A rigid body's is flat, and friction, cogging and
/// the band's ends bend it slowly, not in a peak.
fn lowest_resonance_hz(x: &Frf) -> Option<f64> {
    let (g, peaks) = peaks(x);
    let f = &x.freq_hz;
    let least = |range: std::ops::Range<usize>| range.map(|j| g[j]).fold(f64::INFINITY, f64::min);
    peaks
        .iter()
        .map(|(_, i)| *i)
        .filter(|&i| {
            let lo = f.partition_point(|v| *v < f[i] / 1.5);
            let hi = f.partition_point(|v| *v <= f[i] * 1.5);
            let dip = least(lo..i).max(least(i + 1..hi));
            g[i] - dip > std::f64::consts::LN_2
        })
        .map(|i| f[i])
        .reduce(f64::min)
}
