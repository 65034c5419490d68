//! How sure a measured fact is: the probability that the quantity a
//! threshold test compares really lies on the asserted side, given the
//! measurement and its noise.
//!
//! Two kinds of evidence, two models:
//! - [`beyond`]: a Gaussian estimate (a smoothed speed, a gap's slope)
//!   with its standard error: `Φ((value − threshold − k·se) / se)`, where
//!   `k` is the significance margin the fact's test demands
//!   (`trend_significance`, `distance_significance`). The probability is
//!   centred on the test's decision (an asserted fact is above ½, a doubt
//!   below) because the margin stands for what a bare `Φ(margin / se)`
//!   ignores: noise biases a speed's magnitude upward (a parked car's
//!   estimated speed is never 0), and the standard errors are themselves
//!   estimates. An estimate with no error (`se == 0`, a noise-free source)
//!   is certain.
//! - [`majority`]: frames that vote (`LeftOf` in 7 of 10 frames): the
//!   posterior probability, under a uniform prior on the true fraction of
//!   frames, that the fraction exceeds the rule's `min_frame_fraction`.
//!
//! These are the probabilities of the base facts; logicrag combines them
//! through proofs (docs/probability.md).

/// The standard normal cumulative distribution function Φ(z).
///
/// Why an approximation of our own: no numerics crate is a dependency of
/// perception, and three printed decimals need far less than the
/// 1.2e-7 absolute error of this one (Numerical Recipes' `erfc`, a
/// Chebyshev fit).
pub fn normal_cdf(z: f64) -> f64 {
    if z.is_nan() {
        return 0.5;
    }
    0.5 * erfc(-z / std::f64::consts::SQRT_2)
}

/// The complementary error function, to 1.2e-7 everywhere.
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// `P(true value > threshold)` for an estimate `value` with standard error
/// `se`: `Φ((value − threshold) / se)`. With `se` zero or not finite the
/// estimate is taken as exact (1 or 0), which is what a noise-free source
/// means.
pub fn beyond(value: f64, threshold: f64, se: f64) -> f64 {
    let margin = value - threshold;
    if !(se.is_finite() && se > 0.0) {
        return if margin > 0.0 { 1.0 } else { 0.0 };
    }
    normal_cdf(margin / se)
}

/// The posterior probability that the true fraction of frames where a
/// relation holds exceeds `fraction`, after it held in `votes` of `frames`
/// frames, under a uniform prior: `P(θ > f | k of n) = P(Bin(n + 1, f) ≤ k)`
/// (the Beta–binomial identity for integer parameters).
pub fn majority(votes: usize, frames: usize, fraction: f64) -> f64 {
    let (k, n) = (votes.min(frames), frames);
    let f = fraction.clamp(0.0, 1.0);
    if f <= 0.0 {
        return 1.0;
    }
    if f >= 1.0 {
        return 0.0;
    }
    // Σ_{i ≤ k} C(n+1, i) f^i (1−f)^(n+1−i), in logs: n is at most a
    // window's frames, but f^n underflows long before n is large.
    let m = n + 1;
    let (lf, lg) = (f.ln(), (1.0 - f).ln());
    let mut log_c = 0.0f64; // ln C(m, 0)
    let mut sum = 0.0;
    for i in 0..=k {
        if i > 0 {
            log_c += ((m - i + 1) as f64).ln() - (i as f64).ln();
        }
        sum += (log_c + i as f64 * lf + (m - i) as f64 * lg).exp();
    }
    sum.min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_normal_cdf_matches_its_table() {
        for (z, want) in [
            (0.0, 0.5),
            (1.0, 0.841_344_7),
            (-1.0, 0.158_655_3),
            (1.5, 0.933_192_8),
            (2.0, 0.977_249_9),
            (-3.0, 0.001_349_9),
        ] {
            assert!(
                (normal_cdf(z) - want).abs() < 1e-6,
                "Φ({z}) = {}",
                normal_cdf(z)
            );
        }
        assert_eq!(normal_cdf(40.0), 1.0);
        assert_eq!(normal_cdf(-40.0), 0.0);
    }

    #[test]
    fn an_exact_estimate_is_certain() {
        assert_eq!(beyond(3.0, 1.0, 0.0), 1.0);
        assert_eq!(beyond(0.5, 1.0, 0.0), 0.0);
        assert!((beyond(2.0, 1.0, 1.0) - 0.841_344_7).abs() < 1e-6);
    }

    #[test]
    fn majority_agrees_with_the_beta_posterior() {
        // All of 10 frames vote: P(θ > 1/2) = 1 − 2^-11.
        assert!((majority(10, 10, 0.5) - (1.0 - 0.5f64.powi(11))).abs() < 1e-12);
        // Half the frames: the posterior is symmetric about 1/2.
        assert!((majority(5, 10, 0.5) - 0.5).abs() < 1e-12);
        // None: P(θ > 1/2) = 2^-11.
        assert!((majority(0, 10, 0.5) - 0.5f64.powi(11)).abs() < 1e-12);
        // More votes, more belief.
        assert!(majority(7, 10, 0.5) < majority(8, 10, 0.5));
        assert!(majority(700, 1000, 0.6) > 0.99);
    }
}
