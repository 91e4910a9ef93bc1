//! How it works: the statistics of the profile table, kept pure so they can be checked on known
//! samples. The median is the usual one (the middle sample, or the mean of the two middle ones
//! for an even count). Percentiles use the nearest-rank method: the p-th percentile of n sorted
//! samples is the sample of rank ⌈p/100 · n⌉ (1-based), so it is always a measured value, and the
//! 95th of fewer than 20 samples is the largest. Non-finite samples are left out.

use serde::Serialize;

/// Summary statistics of one series of timings, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stat {
    /// Median (the mean of the two middle samples for an even count), ms.
    pub median_ms: f64,
    /// 95th percentile, nearest rank: always a measured sample, ms.
    pub p95_ms: f64,
    /// Arithmetic mean, ms.
    pub mean_ms: f64,
    /// Slowest sample, ms.
    pub max_ms: f64,
    /// Samples the figures are computed from.
    pub samples: usize,
}

impl Stat {
    /// The statistics of `samples`; `None` when none is finite.
    pub fn of(samples: &[f64]) -> Option<Self> {
        let sorted = sorted_finite(samples);
        let max_ms = *sorted.last()?;
        Some(Self {
            median_ms: median_sorted(&sorted)?,
            p95_ms: percentile_sorted(&sorted, 95.0)?,
            mean_ms: sorted.iter().sum::<f64>() / sorted.len() as f64,
            max_ms,
            samples: sorted.len(),
        })
    }
}

fn sorted_finite(samples: &[f64]) -> Vec<f64> {
    let mut sorted: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    sorted
}

/// The median of `samples` (mean of the two middle ones for an even count); `None` when empty.
pub fn median(samples: &[f64]) -> Option<f64> {
    median_sorted(&sorted_finite(samples))
}

/// The `p`-th percentile (0 < p ≤ 100) of `samples` by nearest rank; `None` when empty.
pub fn percentile(samples: &[f64], p: f64) -> Option<f64> {
    percentile_sorted(&sorted_finite(samples), p)
}

fn median_sorted(sorted: &[f64]) -> Option<f64> {
    let n = sorted.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(sorted[n / 2]),
        _ => Some(0.5 * (sorted[n / 2 - 1] + sorted[n / 2])),
    }
}

fn percentile_sorted(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let rank = (p.clamp(0.0, 100.0) / 100.0 * sorted.len() as f64).ceil() as usize;
    Some(sorted[rank.clamp(1, sorted.len()) - 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[7.0]), Some(7.0));
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[f64::NAN, 1.0, 3.0]), Some(2.0));
    }

    #[test]
    fn nearest_rank_percentiles() {
        let hundred: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&hundred, 95.0), Some(95.0));
        assert_eq!(percentile(&hundred, 50.0), Some(50.0));
        assert_eq!(percentile(&hundred, 100.0), Some(100.0));
        assert_eq!(percentile(&hundred, 0.0), Some(1.0));
        let twenty: Vec<f64> = (1..=20).rev().map(f64::from).collect();
        assert_eq!(percentile(&twenty, 95.0), Some(19.0));
        // Fewer than 20 samples: the 95th is the largest.
        assert_eq!(percentile(&[5.0, 1.0, 9.0, 2.0], 95.0), Some(9.0));
        assert_eq!(percentile(&[], 95.0), None);
    }

    #[test]
    fn stat_of_known_samples() {
        let stat = Stat::of(&[2.0, 4.0, 6.0, 8.0, 100.0]).unwrap();
        assert_eq!(stat.median_ms, 6.0);
        assert_eq!(stat.p95_ms, 100.0);
        assert_eq!(stat.mean_ms, 24.0);
        assert_eq!(stat.max_ms, 100.0);
        assert_eq!(stat.samples, 5);
        assert_eq!(Stat::of(&[f64::INFINITY]), None);
    }
}
