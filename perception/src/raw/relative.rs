//! Relative depth made metric: a depth model with `mode: relative` gives a
//! map that is monotonic in depth with unknown parameters (MiDaS-style
//! inverse depth by default, or depth up to scale, [`RelativeDepth`]). Its
//! value is sampled at each box exactly as a metric map is (median of the
//! lower half of the box, i.e. the object's visible near face), and every
//! frame's samples are fitted ([`align`]) onto that frame's *anchors*: boxes
//! whose monocular estimate ([`super::mono`]) is trustworthy enough
//! ([`is_anchor`]), compared by their near-face depth
//! ([`super::mono::DepthEstimate::near_z`]), since that is the surface the
//! map sees.
//!
//! What is fitted ([`Alignment`]):
//! - `relative: depth`: one scale, `Z_near = s · sample`, `s` the median of
//!   the anchors' `Z_near / sample`.
//! - `relative: inverse_depth`: MiDaS, DPT and Depth Anything output
//!   disparity up to scale *and shift*, so `1 / Z_near = a · sample + b` is
//!   fitted in disparity space by Theil–Sen (`a` the median of the pairwise
//!   slopes, `b` the median of `1/Z_near − a·sample`), but only when the
//!   line is well determined: at least [`MIN_LINE_ANCHORS`] anchors whose
//!   near-face depths span at least [`MIN_LINE_DEPTH_SPREAD`]. Otherwise
//!   (fewer anchors, anchors at similar depths, or a line that is not
//!   increasing) scale only, `b = 0`, `a` the median of `(1/Z_near) /
//!   sample`.
//!
//! Why robust fits per frame: the monocular estimates are metric but
//! individually noisy (a wrong size prior, ground that is not one plane),
//! while the relative map has the right *order and spacing* between
//! objects. Medians ignore the few anchors whose monocular estimate is far
//! off. The fit is per frame because relative models are not consistent in
//! scale (or shift) from frame to frame.

use super::config::RelativeDepth;
use super::mono::DepthEstimate;

/// The fewest anchors for a line (scale and shift) instead of a scale.
/// Theil–Sen's median slope ignores a gross monocular failure only when
/// most pairwise slopes avoid it: with 3 anchors two of the three slopes
/// involve the bad one (a car at 6 m estimated at 18 m put an 18 m car at
/// 33 m), with 5 six of ten slopes are clean. A choice, not a measurement.
pub const MIN_LINE_ANCHORS: usize = 5;

/// The smallest ratio between the farthest and the nearest anchor's
/// near-face depth for a line to be fitted. Anchors at similar depths
/// leave the slope to their monocular noise (cars at 10, 11 and 12 m with
/// ±5% errors put a 20 m box at 13.8 m or 36.3 m), while a scale stays
/// within the noise. Measured on depths, not raw samples, since an unknown
/// shift compresses the samples' ratio. A choice, not a measurement.
pub const MIN_LINE_DEPTH_SPREAD: f64 = 2.0;

/// How a frame's relative samples map to near-face depth in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Alignment {
    /// `Z_near = scale · sample` (`relative: depth`).
    Scale(f64),
    /// `1 / Z_near = a · sample + b` (`relative: inverse_depth`; `b = 0`
    /// when only a scale was fitted).
    Disparity {
        /// Slope, positive.
        a: f64,
        /// Shift in disparity, 1/metres.
        b: f64,
    },
}

impl Alignment {
    /// The near-face depth of a raw sample, metres, or `None` when it carries
    /// no depth: a non-finite or non-positive sample, or a fitted disparity
    /// that is not positive (the box then keeps its monocular estimate).
    pub fn depth(&self, sample: f64) -> Option<f64> {
        if !(sample.is_finite() && sample > 0.0) {
            return None;
        }
        let z = match *self {
            Alignment::Scale(s) => s * sample,
            Alignment::Disparity { a, b } => {
                let disparity = a * sample + b;
                // A shift can push a far (small) sample to zero or below:
                // beyond infinity, not a depth.
                if disparity <= 0.0 {
                    return None;
                }
                disparity.recip()
            }
        };
        (z.is_finite() && z > 0.0).then_some(z)
    }
}

/// Whether a box's monocular estimate may anchor the alignment: its depth
/// rests on a visible ground contact of a type with a size prior, or on the
/// size prior itself. Left out: boxes cut by the image's bottom edge (their
/// flat-ground depth is a known overestimate) and flat ground of a type
/// without a size prior (`std_m` is `None` exactly then): for a traffic
/// light or sign the box bottom is not where the object meets the ground.
pub fn is_anchor(e: &DepthEstimate) -> bool {
    !e.cut_by_image && e.std_m.is_some()
}

/// The median of `v` (mean of the middle two for an even count); `None`
/// when empty. Sorts `v`.
fn median(v: &mut [f64]) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let upper = *v.get(n / 2)?;
    if n % 2 == 1 {
        return Some(upper);
    }
    let lower = *v.get(n / 2 - 1)?;
    Some(0.5 * (lower + upper))
}

/// Fits the frame's [`Alignment`] on `anchors`, pairs of `(raw sample,
/// near-face depth in metres)` (both positive and finite; other pairs are
/// skipped). `None` when no pair is usable: the frame then keeps its
/// monocular estimates.
pub fn align(
    kind: RelativeDepth,
    anchors: impl IntoIterator<Item = (f64, f64)>,
) -> Option<Alignment> {
    let pairs: Vec<(f64, f64)> = anchors
        .into_iter()
        .filter(|(s, z)| s.is_finite() && *s > 0.0 && z.is_finite() && *z > 0.0)
        .collect();
    match kind {
        RelativeDepth::Depth => {
            let mut ratios: Vec<f64> = pairs.iter().map(|(s, z)| z / s).collect();
            median(&mut ratios)
                .filter(|s| s.is_finite() && *s > 0.0)
                .map(Alignment::Scale)
        }
        RelativeDepth::InverseDepth => {
            let points: Vec<(f64, f64)> = pairs.iter().map(|(s, z)| (*s, z.recip())).collect();
            let (near, far) = pairs
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), (_, z)| {
                    (lo.min(*z), hi.max(*z))
                });
            let line = if points.len() >= MIN_LINE_ANCHORS && far >= MIN_LINE_DEPTH_SPREAD * near {
                theil_sen(&points)
            } else {
                None
            };
            // The map is monotonic (larger is nearer): a line that is not
            // increasing is noise, not the model.
            if let Some((a, b)) = line.filter(|(a, b)| a.is_finite() && *a > 0.0 && b.is_finite()) {
                return Some(Alignment::Disparity { a, b });
            }
            let mut ratios: Vec<f64> = points.iter().map(|(x, y)| y / x).collect();
            median(&mut ratios)
                .filter(|a| a.is_finite() && *a > 0.0)
                .map(|a| Alignment::Disparity { a, b: 0.0 })
        }
    }
}

/// Theil–Sen line `y = a·x + b`: `a` the median of the slopes over all
/// pairs with different `x`, `b` the median of `y − a·x`. `None` when every
/// `x` is the same.
fn theil_sen(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let mut slopes = Vec::with_capacity(points.len() * (points.len() - 1) / 2);
    for (i, (x1, y1)) in points.iter().enumerate() {
        for (x2, y2) in &points[i + 1..] {
            if x1 != x2 {
                slopes.push((y2 - y1) / (x2 - x1));
            }
        }
    }
    let a = median(&mut slopes)?;
    let mut intercepts: Vec<f64> = points.iter().map(|(x, y)| y - a * x).collect();
    Some((a, median(&mut intercepts)?))
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

    fn depths(al: &Alignment, samples: &[f64]) -> Vec<f64> {
        samples
            .iter()
            .map(|s| al.depth(*s).unwrap_or(f64::NAN))
            .collect()
    }

    #[test]
    fn a_relative_depth_map_of_truth_over_seven_gives_truth_back_from_noisy_mono() {
        let truth = truth();
        let mono = noisy(&truth);
        // The monocular estimates alone are off by up to 20%.
        let worst = truth
            .iter()
            .zip(&mono)
            .map(|(t, m)| (m / t - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst > 0.19, "{worst}");
        let raw: Vec<f64> = truth.iter().map(|t| t / 7.0).collect();
        let al = align(
            RelativeDepth::Depth,
            raw.iter().copied().zip(mono.iter().copied()),
        );
        assert_eq!(al, Some(Alignment::Scale(7.0)), "{al:?}");
        let Some(al) = al else { return };
        for (z, t) in depths(&al, &raw).iter().zip(&truth) {
            assert!((z - t).abs() < 1e-9 * t, "{z} vs {t}");
        }
    }

    #[test]
    fn an_inverse_depth_map_of_seven_over_truth_gives_truth_back_from_noisy_mono() {
        let truth = truth();
        let mono = noisy(&truth);
        let raw: Vec<f64> = truth.iter().map(|t| 7.0 / t).collect();
        let al = align(
            RelativeDepth::InverseDepth,
            raw.iter().copied().zip(mono.iter().copied()),
        )
        .unwrap_or(Alignment::Scale(f64::NAN));
        // Noise moves a robust line a little, not by the ±20% of one box.
        for (z, t) in depths(&al, &raw).iter().zip(&truth) {
            assert!((z / t - 1.0).abs() < 0.06, "{al:?}: {z} vs {t}");
        }
    }

    /// Five boxes from 6 to 45 m, an inverse-depth map `7/z + shift`, exact
    /// monocular estimates except those in `outliers` (3× too far).
    fn shifted_case(shift: f64, outliers: &[usize]) -> (Vec<f64>, Vec<f64>, Option<Alignment>) {
        let truth = vec![6.0, 11.0, 18.0, 30.0, 45.0];
        let raw: Vec<f64> = truth.iter().map(|z| 7.0 / z + shift).collect();
        let mono: Vec<f64> = truth
            .iter()
            .enumerate()
            .map(|(i, z)| if outliers.contains(&i) { 3.0 * z } else { *z })
            .collect();
        let al = align(
            RelativeDepth::InverseDepth,
            raw.iter().copied().zip(mono.iter().copied()),
        );
        (truth, raw, al)
    }

    #[test]
    fn a_shifted_inverse_depth_map_is_recovered_by_the_affine_fit() {
        for shift in [0.05, 0.2] {
            for outliers in [&[][..], &[2], &[4], &[0]] {
                let (truth, raw, al) = shifted_case(shift, outliers);
                let al = al.unwrap_or(Alignment::Scale(f64::NAN));
                for (z, t) in depths(&al, &raw).iter().zip(&truth) {
                    assert!(
                        (z / t - 1.0).abs() < 0.01,
                        "shift {shift}, outliers {outliers:?}: {al:?}: {z} vs {t}"
                    );
                }
            }
        }
        // Scale alone cannot absorb the shift: the far box lands a third short.
        let (truth, raw, _) = shifted_case(0.2, &[]);
        let pairs = raw.iter().copied().zip(truth.iter().copied());
        let mut ratios: Vec<f64> = pairs.map(|(s, z)| z.recip() / s).collect();
        let a = median(&mut ratios).unwrap_or(f64::NAN);
        let far = Alignment::Disparity { a, b: 0.0 }.depth(raw[4]);
        assert!(far.is_some_and(|z| z < 0.7 * truth[4]), "{far:?}");
    }

    #[test]
    fn a_line_needs_five_anchors_spread_over_depth_else_a_scale() {
        let s = |z: f64| 7.0 / z + 0.1;
        let is_scale =
            |al: Option<Alignment>| matches!(al, Some(Alignment::Disparity { b, .. }) if b == 0.0);
        // Five anchors from 8 to 30 m: the line, exactly.
        let five: Vec<(f64, f64)> = [8.0, 11.0, 15.0, 21.0, 30.0]
            .iter()
            .map(|z| (s(*z), *z))
            .collect();
        let al = align(RelativeDepth::InverseDepth, five.iter().copied());
        let Some(Alignment::Disparity { a, b }) = al else {
            panic!("{al:?}")
        };
        assert!((a - 1.0 / 7.0).abs() < 1e-12 && (b + 0.1 / 7.0).abs() < 1e-12);
        // Regression: two or three anchors fitted a line. With three, one
        // gross monocular failure (6 m read as 18 m) took the median slope:
        // the 18 m car came out at 33 m. Now a scale, which keeps it close.
        let t = |z: f64| 7.0 / z;
        let three = [(t(6.0), 18.0), (t(18.0), 18.0), (t(45.0), 45.0)];
        let al = align(RelativeDepth::InverseDepth, three);
        assert!(is_scale(al), "{al:?}");
        let z18 = al.and_then(|al| al.depth(t(18.0))).unwrap_or(0.0);
        assert!((z18 / 18.0 - 1.0).abs() < 0.01, "{z18}");
        // Regression: anchors at similar depths (10, 11, 12 m, ±5% noise,
        // five of them) tilted the line; a 20 m box landed at 13.8 m.
        let close = [
            (t(10.0), 10.5),
            (t(10.5), 10.5),
            (t(11.0), 11.0),
            (t(11.5), 11.5),
            (t(12.0), 11.4),
        ];
        let al = align(RelativeDepth::InverseDepth, close);
        assert!(is_scale(al), "{al:?}");
        let z20 = al.and_then(|al| al.depth(t(20.0))).unwrap_or(0.0);
        assert!((z20 / 20.0 - 1.0).abs() < 0.06, "{z20}");
        // A decreasing line (monocular estimates in the wrong order) is
        // noise: scale only.
        let reversed: Vec<(f64, f64)> = five
            .iter()
            .zip(five.iter().rev())
            .map(|((s, _), (_, z))| (*s, *z))
            .collect();
        assert!(is_scale(align(RelativeDepth::InverseDepth, reversed)));
        // One anchor: scale only, through it.
        let al = align(RelativeDepth::InverseDepth, [(0.5, 10.0)]);
        assert_eq!(al, Some(Alignment::Disparity { a: 0.2, b: 0.0 }));
    }

    #[test]
    fn a_non_positive_fitted_disparity_is_no_depth() {
        let al = Alignment::Disparity { a: 0.1, b: -0.05 };
        assert_eq!(al.depth(0.5), None);
        assert_eq!(al.depth(0.2), None);
        assert!(al.depth(1.0).is_some_and(|z| (z - 20.0).abs() < 1e-9));
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
        let al = align(
            RelativeDepth::Depth,
            rel.iter().copied().zip(mono.iter().copied()),
        );
        let Some(Alignment::Scale(scale)) = al else {
            panic!("{al:?}")
        };
        assert!((scale / 7.0 - 1.0).abs() < 0.07, "{scale}");
    }

    #[test]
    fn unusable_values_are_skipped_and_nothing_usable_is_none() {
        for kind in [RelativeDepth::Depth, RelativeDepth::InverseDepth] {
            assert_eq!(align(kind, []), None);
            assert_eq!(
                align(kind, [(0.0, 10.0), (1.0, f64::NAN), (1.0, -2.0)]),
                None
            );
        }
        assert_eq!(
            align(RelativeDepth::Depth, [(2.0, 10.0), (0.0, 4.0)]),
            Some(Alignment::Scale(5.0))
        );
        assert_eq!(
            align(RelativeDepth::Depth, [(1.0, 2.0), (1.0, 4.0)]),
            Some(Alignment::Scale(3.0))
        );
        let al = Alignment::Scale(2.0);
        assert_eq!(
            [0.0, -1.0, f64::NAN, f64::INFINITY].map(|s| al.depth(s)),
            [None; 4]
        );
    }
}
