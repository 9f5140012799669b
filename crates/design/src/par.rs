//! Work over many independent frequencies, split across the machine's
//! cores: each item is computed alone, so the result is the same, bit for
//! bit, whatever the split.

/// Below this many items one thread does them all.
const SERIAL_BELOW: usize = 512;

/// `f(0), ..., f(n - 1)` in order, computed on up to the machine's
/// available cores (at most 8) in contiguous chunks.
pub(crate) fn map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    map_from(n, SERIAL_BELOW, f)
}

/// [`map`] for items that each cost enough to split from `serial_below`
/// items up.
pub(crate) fn map_from<T: Send>(
    n: usize,
    serial_below: usize,
    f: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(8);
    if threads < 2 || n < serial_below {
        return (0..n).map(f).collect();
    }
    let chunk = n.div_ceil(threads);
    let f = &f;
    std::thread::scope(|s| {
        let parts: Vec<_> = (0..n)
            .step_by(chunk)
            .map(|lo| s.spawn(move || (lo..(lo + chunk).min(n)).map(f).collect::<Vec<T>>()))
            .collect();
        // A worker that panicked re-raises here (the items themselves do
        // not panic).
        parts
            .into_iter()
            .flat_map(|p| p.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    /// Every item once, in order, across any split.
    #[test]
    fn the_order_and_the_values_are_the_serial_ones() {
        for n in [0, 1, 511, 512, 513, 4097] {
            let v = super::map(n, |i| i * i);
            assert_eq!(v, (0..n).map(|i| i * i).collect::<Vec<_>>());
        }
    }
}
