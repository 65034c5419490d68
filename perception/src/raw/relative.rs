//! Relative depth made metric: a depth model with `mode: relative` gives a
//! map that is monotonic in depth with an unknown scale (MiDaS-style inverse
//! depth by default, or depth up to scale, [`RelativeDepth`]). Its value is
//! sampled at each box exactly as a metric map is (median of the lower half
//! of the box), turned depth-like ([`depth_like`]: inverse depth is
//! inverted), and every frame's values are scaled onto that frame's
//! monocular estimates ([`super::mono`]) by one factor ([`align_scale`]).
//!
//! Why one scale per frame and a median: the monocular estimates are metric
//! but individually noisy (a wrong size prior, ground that is not one plane),
//! while the relative map has the right *ratios* between objects. A single
//! factor keeps those ratios; the median of the per-box ratios ignores the
//! few boxes whose monocular estimate is far off. The factor is per frame
//! because relative models are not consistent in scale from frame to frame.

use super::config::RelativeDepth;

/// A sampled relative value as a depth-like quantity (proportional to
/// depth), or `None` when it carries no depth (non-finite, or not positive:
/// zero inverse depth is infinitely far).
pub fn depth_like(value: f64, kind: RelativeDepth) -> Option<f64> {
    if !(value.is_finite() && value > 0.0) {
        return None;
    }
    let d = match kind {
        RelativeDepth::Depth => value,
        RelativeDepth::InverseDepth => value.recip(),
    };
    d.is_finite().then_some(d)
}

/// The scale that maps depth-like relative values onto metres: the median of
/// `mono_z / relative` over `pairs` of `(relative, mono_z)` (both positive
/// and finite; other pairs are skipped). `None` when no pair is usable — the
/// frame then keeps its monocular estimates. With an even count the median
/// is the mean of the two middle ratios.
pub fn align_scale(pairs: impl IntoIterator<Item = (f64, f64)>) -> Option<f64> {
    let mut ratios: Vec<f64> = pairs
        .into_iter()
        .filter(|(rel, z)| rel.is_finite() && *rel > 0.0 && z.is_finite() && *z > 0.0)
        .map(|(rel, z)| z / rel)
        .filter(|r| r.is_finite() && *r > 0.0)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let n = ratios.len();
    let upper = *ratios.get(n / 2)?;
    if n % 2 == 1 {
        return Some(upper);
    }
    let lower = *ratios.get(n / 2 - 1)?;
    Some(0.5 * (lower + upper))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Depths from 5 to 65 m.
    fn truth() -> Vec<f64> {
        (0..20).map(|i| 5.0 + 3.0 * f64::from(i)).collect()
    }

    /// Unbiased multiplicative noise of up to ±20%, symmetric as a set (each
    /// error appears once with each sign), assigned in a scrambled order so
    /// it is not correlated with depth.
    fn noisy(truth: &[f64]) -> Vec<f64> {
        let n = truth.len();
        (0..n)
            .map(|i| {
                let k = (i * 7) % n; // a permutation of 0..n (gcd(7, 20) = 1)
                let size = 0.02 * (k / 2 + 1) as f64;
                let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
                truth[i] * (1.0 + sign * size)
            })
            .collect()
    }

    #[test]
    fn a_relative_map_of_truth_over_seven_gives_truth_back_from_noisy_mono() {
        let truth = truth();
        let mono = noisy(&truth);
        // The monocular estimates alone are off by up to 20%.
        let worst = truth
            .iter()
            .zip(&mono)
            .map(|(t, m)| (m / t - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst > 0.19, "{worst}");
        for kind in [RelativeDepth::Depth, RelativeDepth::InverseDepth] {
            // The model's raw output: depth / 7, or its inverse 7 / depth.
            let raw: Vec<f64> = truth
                .iter()
                .map(|t| match kind {
                    RelativeDepth::Depth => t / 7.0,
                    RelativeDepth::InverseDepth => 7.0 / t,
                })
                .collect();
            let rel: Vec<f64> = raw.iter().filter_map(|v| depth_like(*v, kind)).collect();
            assert_eq!(rel.len(), truth.len());
            let scale =
                align_scale(rel.iter().copied().zip(mono.iter().copied())).unwrap_or(f64::NAN);
            assert!((scale - 7.0).abs() < 1e-9, "{kind:?}: scale {scale}");
            for (r, t) in rel.iter().zip(&truth) {
                assert!(
                    (scale * r - t).abs() < 1e-9 * t,
                    "{kind:?}: {} vs {t}",
                    scale * r
                );
            }
        }
    }

    #[test]
    fn the_median_ignores_a_few_gross_monocular_failures() {
        let truth = truth();
        let mut mono = noisy(&truth);
        // Three boxes with monocular estimates 3x too far (a cut box, a
        // wrong prior): a mean of ratios would move by 30%, the median by
        // one rank of the ±20% noise.
        for i in [2, 9, 15] {
            mono[i] *= 3.0;
        }
        let rel: Vec<f64> = truth.iter().map(|t| t / 7.0).collect();
        let scale = align_scale(rel.iter().copied().zip(mono.iter().copied())).unwrap_or(0.0);
        assert!((scale / 7.0 - 1.0).abs() < 0.07, "{scale}");
    }

    #[test]
    fn unusable_values_are_skipped_and_nothing_usable_is_none() {
        assert_eq!(depth_like(0.0, RelativeDepth::InverseDepth), None);
        assert_eq!(depth_like(-1.0, RelativeDepth::Depth), None);
        assert_eq!(depth_like(f64::NAN, RelativeDepth::Depth), None);
        assert_eq!(depth_like(0.5, RelativeDepth::InverseDepth), Some(2.0));
        assert_eq!(align_scale([]), None);
        assert_eq!(
            align_scale([(0.0, 10.0), (1.0, f64::NAN), (1.0, -2.0)]),
            None
        );
        assert_eq!(align_scale([(2.0, 10.0), (0.0, 4.0)]), Some(5.0));
        assert_eq!(align_scale([(1.0, 2.0), (1.0, 4.0)]), Some(3.0));
    }
}
