//! Signal processing on irregularly sampled series (tracks may skip frames):
//! Savitzky–Golay smoothing and differentiation as local polynomial least
//! squares, ordinary least-squares slopes, and a Hampel outlier filter.

/// One constant-velocity Kalman track after the Rauch–Tung–Striebel
/// smoother: position, velocity and their variances at every sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CvSmoothed {
    /// Smoothed position per sample.
    pub position: Vec<f64>,
    /// Smoothed velocity per sample (units of `y` per unit of `t`).
    pub velocity: Vec<f64>,
    /// Posterior variance of the velocity per sample.
    pub velocity_var: Vec<f64>,
    /// Samples rejected as outliers by the innovation gate.
    pub rejected: usize,
}

/// Constant-velocity Kalman filter with an RTS smoother on samples `y` at
/// ascending times `t`, each with its own measurement variance `r`.
/// `accel_psd` is the spectral density of the white acceleration that
/// drives the model (units² / time³); a sample whose innovation exceeds
/// `gate` standard deviations is treated as missing (counted in
/// `rejected`), except the first two, which start the track. Times may
/// skip (missed frames): the prediction simply spans the gap.
pub fn cv_rts(t: &[f64], y: &[f64], r: &[f64], accel_psd: f64, gate: f64) -> CvSmoothed {
    use nalgebra::{Matrix2, Vector2};
    let n = t.len().min(y.len()).min(r.len());
    if n == 0 {
        return CvSmoothed::default();
    }
    let h_row = nalgebra::RowVector2::new(1.0, 0.0);
    // Unknown initial velocity: a prior far wider than any road user's speed.
    let mut x = Vector2::new(y[0], 0.0);
    let mut p = Matrix2::new(r[0].max(1e-12), 0.0, 0.0, 1.0e4);
    let (mut xp, mut pp, mut xf, mut pf, mut fs) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut rejected = 0;
    for i in 0..n {
        let f = if i == 0 {
            Matrix2::identity()
        } else {
            Matrix2::new(1.0, t[i] - t[i - 1], 0.0, 1.0)
        };
        if i > 0 {
            let h = (t[i] - t[i - 1]).max(0.0);
            let q = Matrix2::new(h * h * h / 3.0, h * h / 2.0, h * h / 2.0, h) * accel_psd;
            x = f * x;
            p = f * p * f.transpose() + q;
        }
        xp.push(x);
        pp.push(p);
        fs.push(f);
        let s = p[(0, 0)] + r[i].max(1e-12);
        let innovation = y[i] - x[0];
        if i >= 2 && innovation * innovation > gate * gate * s {
            rejected += 1;
        } else if i > 0 {
            let k = p * h_row.transpose() / s;
            x += k * innovation;
            p = (Matrix2::identity() - k * h_row) * p;
        }
        xf.push(x);
        pf.push(p);
    }
    let mut xs = xf.clone();
    let mut ps = pf.clone();
    for i in (0..n.saturating_sub(1)).rev() {
        let Some(inv) = pp[i + 1].try_inverse() else {
            continue;
        };
        let c = pf[i] * fs[i + 1].transpose() * inv;
        xs[i] = xf[i] + c * (xs[i + 1] - xp[i + 1]);
        ps[i] = pf[i] + c * (ps[i + 1] - pp[i + 1]) * c.transpose();
    }
    CvSmoothed {
        position: xs.iter().map(|v| v[0]).collect(),
        velocity: xs.iter().map(|v| v[1]).collect(),
        velocity_var: ps.iter().map(|m| m[(1, 1)].max(0.0)).collect(),
        rejected,
    }
}

/// Least-squares line through `(t, y)`: returns `(slope, intercept)`, or
/// `None` with fewer than two distinct `t`.
pub fn linear_fit(t: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = t.len().min(y.len());
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let mt = t[..n].iter().sum::<f64>() / nf;
    let my = y[..n].iter().sum::<f64>() / nf;
    let mut stt = 0.0;
    let mut sty = 0.0;
    for (a, b) in t[..n].iter().zip(&y[..n]) {
        stt += (a - mt) * (a - mt);
        sty += (a - mt) * (b - my);
    }
    if stt <= f64::EPSILON {
        return None;
    }
    let slope = sty / stt;
    Some((slope, my - slope * mt))
}

/// Least-squares slope with its standard error (from the residuals; 0 with
/// two points): `(slope, standard_error)`.
pub fn slope_with_error(t: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = t.len().min(y.len());
    let (slope, intercept) = linear_fit(t, y)?;
    if n < 3 {
        return Some((slope, 0.0));
    }
    let mt = t[..n].iter().sum::<f64>() / n as f64;
    let (mut rss, mut stt) = (0.0, 0.0);
    for (a, b) in t[..n].iter().zip(&y[..n]) {
        let r = b - (slope * a + intercept);
        rss += r * r;
        stt += (a - mt) * (a - mt);
    }
    Some((slope, (rss / (n as f64 - 2.0) / stt).sqrt()))
}

/// Variance of the least-squares slope through `(t, y)` when each `y[i]`
/// carries independent noise of variance `var[i]`:
/// `Σ (t_i − t̄)² var_i / (Σ (t_i − t̄)²)²`. `None` with fewer than two
/// distinct `t`.
pub fn slope_noise_var(t: &[f64], var: &[f64]) -> Option<f64> {
    let n = t.len().min(var.len());
    if n < 2 {
        return None;
    }
    let mt = t[..n].iter().sum::<f64>() / n as f64;
    let (mut stt, mut num) = (0.0, 0.0);
    for (a, v) in t[..n].iter().zip(&var[..n]) {
        let d = (a - mt) * (a - mt);
        stt += d;
        num += d * v;
    }
    if stt <= f64::EPSILON {
        return None;
    }
    Some(num / (stt * stt))
}

/// The Theil–Sen line through `(t, y)` evaluated at `at`: the slope is the
/// median of the pairwise slopes, the intercept the median of
/// `y − slope·t`. Unlike least squares, one wild point among three or more
/// does not move it. `None` without two distinct `t`; one point gives its
/// own value.
pub fn theil_sen_at(t: &[f64], y: &[f64], at: f64) -> Option<f64> {
    let n = t.len().min(y.len());
    match n {
        0 => return None,
        1 => return Some(y[0]),
        _ => {}
    }
    let mut slopes = Vec::with_capacity(n * (n - 1) / 2);
    for i in 0..n {
        for j in i + 1..n {
            let dt = t[j] - t[i];
            if dt.abs() > f64::EPSILON {
                slopes.push((y[j] - y[i]) / dt);
            }
        }
    }
    let slope = median_in_place(&mut slopes)?;
    let mut icpt: Vec<f64> = t[..n]
        .iter()
        .zip(&y[..n])
        .map(|(a, b)| b - slope * a)
        .collect();
    let intercept = median_in_place(&mut icpt)?;
    Some(slope * at + intercept)
}

/// Regression slope of `y` over `t`; `None` as for [`linear_fit`].
pub fn slope(t: &[f64], y: &[f64]) -> Option<f64> {
    linear_fit(t, y).map(|(s, _)| s)
}

/// Savitzky–Golay filter on samples at times `t` (ascending): each output is
/// the value (`deriv = 0`) or first derivative (`deriv = 1`) at `t[i]` of the
/// polynomial of degree `order` fitted to the samples within `half_window`
/// time units of `t[i]`. Near the ends and across gaps the window is simply
/// the samples available, and the degree drops to what they support, so no
/// sample is discarded or invented.
pub fn savgol(t: &[f64], y: &[f64], half_window: f64, order: usize, deriv: usize) -> Vec<f64> {
    let n = t.len().min(y.len());
    let mut out = Vec::with_capacity(n);
    let mut lo = 0usize;
    let mut hi = 0usize;
    for i in 0..n {
        while lo < i && t[i] - t[lo] > half_window {
            lo += 1;
        }
        if hi < i {
            hi = i;
        }
        while hi + 1 < n && t[hi + 1] - t[i] <= half_window {
            hi += 1;
        }
        let m = hi - lo + 1;
        let deg = order.min(m.saturating_sub(1)).min(3);
        out.push(local_poly(&t[lo..=hi], &y[lo..=hi], t[i], deg, deriv));
    }
    out
}

/// Value or first derivative at `t0` of the degree-`deg` least-squares
/// polynomial in `(t - t0)`.
fn local_poly(t: &[f64], y: &[f64], t0: f64, deg: usize, deriv: usize) -> f64 {
    if deriv > deg {
        return 0.0;
    }
    let k = deg + 1;
    // Normal equations, at most 4x4.
    let mut a = [[0.0f64; 5]; 4];
    for (ti, yi) in t.iter().zip(y) {
        let d = ti - t0;
        let mut pw = [1.0f64; 7];
        for p in 1..7 {
            pw[p] = pw[p - 1] * d;
        }
        for r in 0..k {
            for c in 0..k {
                a[r][c] += pw[r + c];
            }
            a[r][k] += pw[r] * yi;
        }
    }
    match solve(&mut a, k) {
        Some(coef) => coef[deriv],
        None => {
            // Degenerate (repeated times): fall back to the mean / zero slope.
            if deriv == 0 {
                y.iter().sum::<f64>() / y.len().max(1) as f64
            } else {
                0.0
            }
        }
    }
}

/// Gaussian elimination with partial pivoting on a `k x (k+1)` augmented matrix.
fn solve(a: &mut [[f64; 5]; 4], k: usize) -> Option<[f64; 4]> {
    #[allow(clippy::needless_range_loop)] // row operations index two rows at once
    for col in 0..k {
        let mut piv = col;
        for r in col + 1..k {
            if a[r][col].abs() > a[piv][col].abs() {
                piv = r;
            }
        }
        if a[piv][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, piv);
        for r in 0..k {
            if r != col {
                let f = a[r][col] / a[col][col];
                for c in col..=k {
                    a[r][c] -= f * a[col][c];
                }
            }
        }
    }
    let mut x = [0.0; 4];
    for r in 0..k {
        x[r] = a[r][k] / a[r][r];
    }
    Some(x)
}

/// Median of a slice (NaN-free input); `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    median_in_place(&mut values.to_vec())
}

/// Median that reorders its buffer instead of copying it.
pub(crate) fn median_in_place(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(|a, b| a.total_cmp(b));
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// Hampel filter: a sample farther than `k` scaled MADs (plus `floor`) from
/// the median of its `±half` neighbours is replaced by that median. Returns
/// how many samples were replaced.
pub fn hampel(y: &mut [f64], half: usize, k: f64, floor: f64) -> usize {
    let n = y.len();
    if n < 3 {
        return 0;
    }
    let orig = y.to_vec();
    let mut replaced = 0;
    let mut buf = Vec::with_capacity(2 * half + 1);
    for i in 0..n {
        let lo = i.saturating_sub(half);
        let hi = (i + half).min(n - 1);
        buf.clear();
        buf.extend_from_slice(&orig[lo..=hi]);
        let Some(med) = median_in_place(&mut buf) else {
            continue;
        };
        for v in buf.iter_mut() {
            *v = (*v - med).abs();
        }
        let mad = median_in_place(&mut buf).unwrap_or(0.0) * 1.4826;
        if (orig[i] - med).abs() > k * mad + floor {
            y[i] = med;
            replaced += 1;
        }
    }
    replaced
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn slope_of_a_line() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let y = [1.0, 3.0, 5.0, 7.0];
        assert!((slope(&t, &y).unwrap() - 2.0).abs() < 1e-12);
        assert!(slope(&[1.0], &[1.0]).is_none());
        assert!(slope(&[1.0, 1.0], &[1.0, 2.0]).is_none());
    }

    #[test]
    fn theil_sen_ignores_one_wild_point_and_extrapolates_a_line() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        // y = 0.1 + 0.02 t, with the first point thrown across the image.
        let y = [0.9, 0.12, 0.14, 0.16, 0.18];
        let at0 = theil_sen_at(&t, &y, 0.0).unwrap();
        assert!((at0 - 0.1).abs() < 1e-12, "{at0}");
        assert_eq!(theil_sen_at(&[2.0], &[5.0], 0.0), Some(5.0));
        assert_eq!(theil_sen_at(&[1.0, 1.0], &[1.0, 2.0], 0.0), None);
        assert_eq!(theil_sen_at(&[], &[], 0.0), None);
    }

    #[test]
    fn slope_noise_variance_of_equal_noise_is_sigma2_over_stt() {
        let t = [0.0, 1.0, 2.0, 3.0];
        // Stt = 5.
        let v = slope_noise_var(&t, &[0.04; 4]).unwrap();
        assert!((v - 0.04 / 5.0).abs() < 1e-15, "{v}");
        assert!(slope_noise_var(&[1.0, 1.0], &[1.0, 1.0]).is_none());
    }

    /// Deterministic pseudo-normal noise (sum of 12 uniforms − 6).
    fn noise(seed: &mut u64) -> f64 {
        let mut acc = 0.0;
        for _ in 0..12 {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            acc += (*seed >> 11) as f64 / (1u64 << 53) as f64;
        }
        acc - 6.0
    }

    #[test]
    fn cv_rts_recovers_a_constant_velocity_track_with_outliers_and_misses() {
        // 4 m/s, σ 0.3 m, 10 fps, frames 3 and 11 missed, 3 gross outliers.
        let mut seed = 7;
        let (mut t, mut y) = (Vec::new(), Vec::new());
        for f in 0..30 {
            if f == 3 || f == 11 {
                continue;
            }
            let ts = f64::from(f) / 10.0;
            let mut v = 2.0 + 4.0 * ts + 0.3 * noise(&mut seed);
            if [8, 17, 25].contains(&f) {
                v += 6.0;
            }
            t.push(ts);
            y.push(v);
        }
        let r = vec![0.09; t.len()];
        let s = cv_rts(&t, &y, &r, 4.0, 3.5);
        assert_eq!(s.rejected, 3, "{s:?}");
        let inner = 3..t.len() - 3;
        for ((ti, v), p) in t[inner.clone()]
            .iter()
            .zip(&s.velocity[inner.clone()])
            .zip(&s.position[inner])
        {
            assert!((v - 4.0).abs() < 1.0, "v({ti}) = {v}");
            assert!((p - (2.0 + 4.0 * ti)).abs() < 0.35, "p({ti}) = {p}");
        }
        // The posterior knows it is sure: well under the raw slope noise.
        assert!(s.velocity_var[15].sqrt() < 1.0, "{}", s.velocity_var[15]);
    }

    #[test]
    fn cv_rts_of_a_jittering_stopped_object_has_a_small_velocity() {
        let mut seed = 3;
        let t: Vec<f64> = (0..20).map(|f| f64::from(f) / 10.0).collect();
        let y: Vec<f64> = t.iter().map(|_| 20.0 + 0.5 * noise(&mut seed)).collect();
        let s = cv_rts(&t, &y, &vec![0.25; t.len()], 4.0, 3.5);
        for (v, var) in s.velocity.iter().zip(&s.velocity_var) {
            // Within two posterior standard deviations of zero, every frame.
            assert!(v.abs() < 2.0 * var.sqrt(), "{v} ± {}", var.sqrt());
        }
        // Noise-free input is reproduced.
        let exact: Vec<f64> = t.iter().map(|x| 1.0 + 3.0 * x).collect();
        let e = cv_rts(&t, &exact, &vec![1e-6; t.len()], 4.0, 3.5);
        assert!(e.velocity.iter().all(|v| (v - 3.0).abs() < 1e-3), "{e:?}");
    }

    #[test]
    fn hampel_removes_a_spike() {
        let mut y = vec![1.0, 1.1, 0.9, 25.0, 1.0, 1.05, 0.95];
        assert_eq!(hampel(&mut y, 3, 3.0, 0.1), 1);
        assert!(y[3] < 2.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]
        // A quadratic is reproduced exactly (value and derivative) by an
        // order-2 Savitzky–Golay filter, even with gaps in time.
        #[test]
        fn savgol_reproduces_quadratics(a in -5.0f64..5.0, b in -5.0f64..5.0, c in -1.0f64..1.0,
                                        gaps in proptest::collection::vec(1u32..3, 4..20)) {
            let mut t = vec![0.0];
            for g in &gaps { let last = *t.last().unwrap(); t.push(last + f64::from(*g)); }
            let y: Vec<f64> = t.iter().map(|x| a + b * x + c * x * x).collect();
            let s = savgol(&t, &y, 3.0, 2, 0);
            let d = savgol(&t, &y, 3.0, 2, 1);
            for i in 0..t.len() {
                // Isolated samples (gap larger than the window) cannot carry a derivative.
                let neighbours = t.iter().filter(|x| (*x - t[i]).abs() <= 3.0).count();
                prop_assert!((s[i] - y[i]).abs() < 1e-6);
                if neighbours >= 3 {
                    prop_assert!((d[i] - (b + 2.0 * c * t[i])).abs() < 1e-6);
                }
            }
        }
    }
}
