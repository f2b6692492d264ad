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
        // Halved, so that values near ±1.7e308 do not overflow `hi − lo` to infinity.
        let width = (hi / 2.0 - lo / 2.0) / bins as f64;
        let mut sum = 0.0;
        with_samples!(&grid.samples, v => count(v, |x| {
            let x = scale.apply(x);
            if x.is_finite() {
                sum += x;
                let i = if width > 0.0 { ((x / 2.0 - lo / 2.0) / width) as usize } else { 0 };
                h.counts[i.min(bins - 1)] += 1;
            }
        }));
        if range.finite > 0 {
            let n = range.finite as f64;
            h.mean = if sum.is_finite() {
                sum / n
            } else {
                running_mean(grid)
            };
        }
        h
    }

    /// Width of one bin (infinite when the range spans more than `f64` holds).
    pub fn width(&self) -> f64 {
        (self.hi - self.lo) / self.counts.len() as f64
    }

    /// Lower edge of bin `i`, computed so that it stays finite for any finite range.
    pub fn edge(&self, i: usize) -> f64 {
        let half = (self.hi / 2.0 - self.lo / 2.0) / self.counts.len() as f64;
        (self.lo / 2.0 + half * i as f64) * 2.0
    }

    /// Centre of bin `i`, finite for any finite range.
    fn centre(&self, i: usize) -> f64 {
        self.edge(i) / 2.0 + self.edge(i + 1) / 2.0
    }

    /// Otsu's threshold: the bin edge that best splits the values into two classes. Empty bins
    /// between two clusters all split them equally well; the middle of that run is returned,
    /// not its first edge, which would sit at the very top of the lower cluster.
    pub fn otsu(&self) -> Option<f64> {
        let total: u64 = self.counts.iter().sum();
        let centre = |i: usize| self.centre(i);
        let sum_all: f64 = self
            .counts
            .iter()
            .enumerate()
            .map(|(i, &c)| c as f64 * centre(i))
            .sum();
        let (mut w0, mut sum0) = (0.0, 0.0);
        let mut best: Option<(usize, usize)> = None;
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
            let tie = (var - best_var).abs() <= best_var * 1e-12;
            match best {
                Some((first, last)) if tie && last + 1 == i && c == 0 => best = Some((first, i)),
                _ if var > best_var && !tie => {
                    best_var = var;
                    best = Some((i, i));
                }
                _ => {}
            }
        }
        best.map(|(first, last)| self.edge(first + 1) / 2.0 + self.edge(last + 1) / 2.0)
    }

    /// Up to `max` valleys `(centre, left peak, right peak)`, deepest first: bins of the smoothed
    /// histogram that are lower than both neighbours and at most half the smaller of the highest
    /// peaks on each side. Smoothing over 7 bins bridges the empty bins of quantised data (CT
    /// values in steps of 62.5, say), which would otherwise look like valleys. A peak must hold
    /// `PEAK_SHARE` of the samples, so that a few saturated values at the top of the range do
    /// not make a "tissue"; one valley is kept per pair of peaks, since two minima between the
    /// same peaks separate the same two things.
    pub fn valleys(&self, max: usize) -> Vec<(f64, f64, f64)> {
        let n = self.counts.len();
        let total: u64 = self.counts.iter().sum();
        let window = 2 * SMOOTH + 1;
        let smooth: Vec<f64> = (0..n)
            .map(|i| {
                let bins = i.saturating_sub(SMOOTH)..(i + SMOOTH + 1).min(n);
                let len = bins.len() as f64;
                self.counts[bins].iter().sum::<u64>() as f64 / len
            })
            .collect();
        let least_peak = total as f64 * PEAK_SHARE / window as f64;
        let centre = |i: usize| self.centre(i);
        let peak = |range: &mut dyn Iterator<Item = usize>| {
            range
                .map(|j| (smooth[j], j))
                .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
        };
        let mut found: Vec<(f64, f64, usize, usize)> = Vec::new();
        for i in 1..n.saturating_sub(1) {
            if !(smooth[i] < smooth[i - 1] && smooth[i] <= smooth[i + 1]) {
                continue;
            }
            let (left, l) = peak(&mut (0..i));
            let (right, r) = peak(&mut (i + 1..n));
            let floor = left.min(right);
            if floor >= least_peak && floor > 0.0 && smooth[i] <= floor / 2.0 {
                found.push((floor - smooth[i], centre(i), l, r));
            }
        }
        found.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut kept: Vec<(f64, usize, usize)> = Vec::new();
        for (_, v, l, r) in found {
            if kept.len() < max && kept.iter().all(|k| (k.1, k.2) != (l, r)) {
                kept.push((v, l, r));
            }
        }
        kept.into_iter()
            .map(|(v, l, r)| (v, centre(l), centre(r)))
            .collect()
    }
}

/// The share of all samples a histogram peak must hold (within the smoothing window) to count.
const PEAK_SHARE: f64 = 1e-3;

/// Half-width of the smoothing window, in bins.
const SMOOTH: usize = 3;

/// The mean of the grid's finite values where their sum overflows (values near ±1e308): a
/// running mean cannot overflow, but its two divisions per sample, one waiting on the other,
/// are many times slower than summing, so it runs only when the sum overflows.
fn running_mean(grid: &Grid) -> f64 {
    let scale = grid.scale;
    let (mut mean, mut n) = (0.0, 0.0);
    with_samples!(&grid.samples, v => count(v, |x| {
        let x = scale.apply(x);
        if x.is_finite() {
            n += 1.0;
            mean += x / n - mean / n;
        }
    }));
    mean
}

fn count<T: Sample>(v: &[T], mut f: impl FnMut(f64)) {
    v.iter().for_each(|x| f(x.to_f64()));
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_io::volume::Samples;

    fn grid(values: Vec<u8>) -> Grid {
        let n = values.len();
        Grid::new(Samples::U8(values.into()), [n, 1, 1], "test")
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

    /// Two minima between the same two peaks are one suggestion, and a peak of a few saturated
    /// samples at the top is no peak.
    #[test]
    fn one_valley_per_pair_of_peaks_and_no_tiny_peaks() {
        let mut v = vec![0u8; 4000];
        v.extend(vec![60u8; 2000]);
        // A shallow bump between the two minima on either side of it.
        v.extend(vec![30u8; 100]);
        v.extend(vec![255u8; 3]);
        let g = grid(v);
        let h = Histogram::of(&g, &g.range(), 128);
        let valleys = h.valleys(3);
        assert_eq!(valleys.len(), 1, "{valleys:?}");
        let (valley, left, right) = valleys[0];
        assert!(left < 5.0 && right > 50.0 && right < 65.0, "{valleys:?}");
        assert!(valley > left && valley < right);
    }

    /// With nothing between two clusters, the threshold is halfway, not at the lower cluster.
    #[test]
    fn otsu_takes_the_middle_of_an_empty_gap() {
        let mut v = vec![10u8; 500];
        v.extend(vec![200u8; 300]);
        let g = grid(v);
        let h = Histogram::of(&g, &g.range(), 64);
        let t = h.otsu().unwrap();
        assert!((t - 105.0).abs() <= h.width(), "{t}");
    }

    /// Values near the ends of `f64` give finite bins and mean, not NaN or infinity.
    #[test]
    fn extreme_values_stay_finite() {
        let v = vec![-1.7e308, 1.7e308, 0.0, 1.0];
        let g = Grid::new(Samples::F64(v.into()), [4, 1, 1], "test");
        let h = Histogram::of(&g, &g.range(), 16);
        assert_eq!(h.counts.iter().sum::<u64>(), 4);
        assert!(h.mean.is_finite());
        assert!((h.mean - 0.25).abs() < 1e-9, "{}", h.mean);
        assert!((0..=16).all(|i| h.edge(i).is_finite()));
        assert_eq!(h.counts[0], 1);
        assert_eq!(h.counts[15], 1);
    }

    /// Where the values' sum overflows, the mean is still theirs.
    #[test]
    fn mean_of_values_whose_sum_overflows() {
        let v = vec![1.7e308, 1.7e308, 1.5e308, 1.5e308];
        let g = Grid::new(Samples::F64(v.into()), [4, 1, 1], "test");
        let h = Histogram::of(&g, &g.range(), 16);
        assert!((h.mean / 1.6e308 - 1.0).abs() < 1e-12, "{}", h.mean);
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
