//! Value statistics for `info`, and iso values to suggest from them.
//!
//! Two kinds of suggestion, because scans differ: Otsu's threshold (the split of the histogram
//! into two classes with the largest between-class variance) finds the object/background
//! boundary when there is one dominant contrast; histogram valleys (local minima between two
//! clear peaks) find boundaries between several tissues or materials.

use sc_io::volume::{Grid, Range, Sample};
use sc_io::with_samples;

/// Counts of finite values in equal bins over `[lo, hi]`, in real units.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// Lower edge of the first bin.
    pub lo: f64,
    /// Upper edge of the last bin.
    pub hi: f64,
    /// Samples per bin.
    pub counts: Vec<u64>,
    /// Mean of the finite values.
    pub mean: f64,
}

impl Histogram {
    /// Bins the grid's finite values; `range` is [`Grid::range`].
    pub fn of(grid: &Grid, range: &Range, bins: usize) -> Histogram {
        let bins = bins.max(1);
        let (lo, hi) = if range.finite > 0 {
            (range.min, range.max)
        } else {
            (0.0, 0.0)
        };
        let mut h = Histogram {
            lo,
            hi,
            counts: vec![0; bins],
            mean: f64::NAN,
        };
        let scale = grid.scale;
        let width = (hi - lo) / bins as f64;
        let mut sum = 0.0;
        with_samples!(&grid.samples, v => count(v, |x| {
            let x = scale.apply(x);
            if x.is_finite() {
                sum += x;
                let i = if width > 0.0 { ((x - lo) / width) as usize } else { 0 };
                h.counts[i.min(bins - 1)] += 1;
            }
        }));
        if range.finite > 0 {
            h.mean = sum / range.finite as f64;
        }
        h
    }

    /// Width of one bin.
    pub fn width(&self) -> f64 {
        (self.hi - self.lo) / self.counts.len() as f64
    }

    /// Lower edge of bin `i`.
    pub fn edge(&self, i: usize) -> f64 {
        self.lo + self.width() * i as f64
    }

    /// Otsu's threshold: the bin edge that best splits the values into two classes.
    pub fn otsu(&self) -> Option<f64> {
        let total: u64 = self.counts.iter().sum();
        let centre = |i: usize| self.edge(i) + self.width() / 2.0;
        let sum_all: f64 = self
            .counts
            .iter()
            .enumerate()
            .map(|(i, &c)| c as f64 * centre(i))
            .sum();
        let (mut w0, mut sum0) = (0.0, 0.0);
        let mut best = None;
        let mut best_var = 0.0;
        for (i, &c) in self.counts.iter().enumerate().take(self.counts.len() - 1) {
            w0 += c as f64;
            sum0 += c as f64 * centre(i);
            let w1 = total as f64 - w0;
            if w0 == 0.0 || w1 == 0.0 {
                continue;
            }
            let diff = sum0 / w0 - (sum_all - sum0) / w1;
            let var = w0 * w1 * diff * diff;
            if var > best_var {
                best_var = var;
                best = Some(self.edge(i + 1));
            }
        }
        best
    }

    /// Up to `max` valleys `(centre, left peak, right peak)`, deepest first: bins of the smoothed
    /// histogram that are lower than both neighbours and at most half the smaller of the highest
    /// peaks on each side. Smoothing over 7 bins bridges the empty bins of quantised data (CT
    /// values in steps of 62.5, say), which would otherwise look like valleys.
    pub fn valleys(&self, max: usize) -> Vec<(f64, f64, f64)> {
        let n = self.counts.len();
        let smooth: Vec<f64> = (0..n)
            .map(|i| {
                let window = i.saturating_sub(SMOOTH)..(i + SMOOTH + 1).min(n);
                let len = window.len() as f64;
                self.counts[window].iter().sum::<u64>() as f64 / len
            })
            .collect();
        let centre = |i: usize| self.edge(i) + self.width() / 2.0;
        let peak = |range: &mut dyn Iterator<Item = usize>| {
            range
                .map(|j| (smooth[j], j))
                .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
        };
        let mut found: Vec<(f64, f64, f64, f64)> = Vec::new();
        for i in 1..n.saturating_sub(1) {
            if !(smooth[i] < smooth[i - 1] && smooth[i] <= smooth[i + 1]) {
                continue;
            }
            let (left, l) = peak(&mut (0..i));
            let (right, r) = peak(&mut (i + 1..n));
            let floor = left.min(right);
            if floor > 0.0 && smooth[i] <= floor / 2.0 {
                found.push((floor - smooth[i], centre(i), centre(l), centre(r)));
            }
        }
        found.sort_by(|a, b| b.0.total_cmp(&a.0));
        // Neighbouring minima of one broad valley are one suggestion, not several.
        let mut kept: Vec<(f64, f64, f64)> = Vec::new();
        for (_, v, l, r) in found {
            if kept.len() < max
                && kept
                    .iter()
                    .all(|k| (k.0 - v).abs() > 4.0 * SMOOTH as f64 * self.width())
            {
                kept.push((v, l, r));
            }
        }
        kept
    }
}

/// Half-width of the smoothing window, in bins.
const SMOOTH: usize = 3;

fn count<T: Sample>(v: &[T], mut f: impl FnMut(f64)) {
    v.iter().for_each(|x| f(x.to_f64()));
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_io::volume::Samples;

    fn grid(values: Vec<u8>) -> Grid {
        let n = values.len();
        Grid::new(Samples::U8(values), [n, 1, 1], "test")
    }

    #[test]
    fn two_clusters_split_between_them() {
        let mut v = vec![10u8; 500];
        v.extend(vec![200u8; 300]);
        v.extend((0..50).map(|i| 100 + i as u8));
        let g = grid(v);
        let h = Histogram::of(&g, &g.range(), 64);
        assert_eq!(h.counts.iter().sum::<u64>(), 850);
        let t = h.otsu().unwrap();
        assert!(t > 10.0 && t < 200.0, "{t}");
        let valleys = h.valleys(3);
        assert!(!valleys.is_empty());
        assert!(
            valleys.iter().all(|(v, l, r)| l < v && v < r),
            "{valleys:?}"
        );
    }

    #[test]
    fn constant_volume_has_no_suggestion() {
        let g = grid(vec![7; 10]);
        let h = Histogram::of(&g, &g.range(), 16);
        assert_eq!(h.otsu(), None);
        assert!(h.valleys(3).is_empty());
        assert_eq!(h.mean, 7.0);
    }
}
