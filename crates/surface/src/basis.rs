//! Cubic B-spline basis functions and their derivatives (Piegl & Tiller,
//! *The NURBS Book*, 2nd ed., algorithms A2.1 `FindSpan` and A2.3
//! `DersBasisFuns`, written here for degree 3).

/// The degree of every spline in this crate.
pub const DEGREE: usize = 3;

/// The knot span index `s` with `knots[s] ≤ u < knots[s + 1]` for a spline
/// with `n_ctrl` control points; `u` at or beyond the end of the domain
/// gives the last non-empty span, `u` before its start the first (A2.1).
pub fn find_span(knots: &[f64], n_ctrl: usize, u: f64) -> usize {
    let p = DEGREE;
    if u >= knots[n_ctrl] {
        // Last span with non-zero length.
        let mut s = n_ctrl - 1;
        while s > p && knots[s] >= knots[s + 1] {
            s -= 1;
        }
        return s;
    }
    if u <= knots[p] {
        let mut s = p;
        while s + 1 < n_ctrl && knots[s + 1] <= knots[p] {
            s += 1;
        }
        return s;
    }
    let (mut lo, mut hi) = (p, n_ctrl);
    // Invariant: knots[lo] <= u < knots[hi].
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if u < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// Values and derivatives up to order `D − 1` of the four basis functions
/// `N_{span−3} … N_{span}` at `u`, evaluated as the polynomials of span
/// `span` (also valid at the span's ends, and beyond them as the span's
/// polynomial continued): `ders[k][r]` is the k-th derivative of
/// `N_{span−3+r}` (A2.3).
pub fn basis_ders<const D: usize>(knots: &[f64], span: usize, u: f64) -> [[f64; 4]; D] {
    const P: usize = DEGREE;
    let mut ndu = [[0.0f64; 4]; 4];
    let mut left = [0.0f64; 4];
    let mut right = [0.0f64; 4];
    ndu[0][0] = 1.0;
    for j in 1..=P {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences; upper: basis functions.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [[0.0f64; 4]; D];
    for j in 0..=P {
        ders[0][j] = ndu[j][P];
    }
    let mut a = [[0.0f64; 4]; 2];
    for r in 0..=P {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..D.min(P + 1) {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = P - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize {
                k - 1
            } else {
                P - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = P as f64;
    for (k, row) in ders.iter_mut().enumerate().skip(1) {
        if k > P {
            *row = [0.0; 4];
            continue;
        }
        for v in row.iter_mut() {
            *v *= factor;
        }
        factor *= (P - k) as f64;
    }
    ders
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cox–de Boor recursion, the textbook definition, for comparison.
    fn cox_de_boor(knots: &[f64], i: usize, p: usize, u: f64) -> f64 {
        if p == 0 {
            return if knots[i] <= u && u < knots[i + 1] {
                1.0
            } else {
                0.0
            };
        }
        let mut v = 0.0;
        let d1 = knots[i + p] - knots[i];
        if d1 > 0.0 {
            v += (u - knots[i]) / d1 * cox_de_boor(knots, i, p - 1, u);
        }
        let d2 = knots[i + p + 1] - knots[i + 1];
        if d2 > 0.0 {
            v += (knots[i + p + 1] - u) / d2 * cox_de_boor(knots, i + 1, p - 1, u);
        }
        v
    }

    const KNOTS: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.2, 0.5, 0.55, 1.0, 1.0, 1.0, 1.0];

    #[test]
    fn values_match_cox_de_boor_and_sum_to_one() {
        let n = KNOTS.len() - 4;
        for k in 0..200 {
            let u = k as f64 / 200.0;
            let s = find_span(&KNOTS, n, u);
            assert!(KNOTS[s] <= u && u < KNOTS[s + 1]);
            let d = basis_ders::<1>(&KNOTS, s, u);
            for r in 0..4 {
                let want = cox_de_boor(&KNOTS, s - 3 + r, 3, u);
                assert!((d[0][r] - want).abs() < 1e-14, "u {u} r {r}");
            }
            assert!((d[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let n = KNOTS.len() - 4;
        for &u in &[0.05, 0.3, 0.52, 0.8, 0.97] {
            let s = find_span(&KNOTS, n, u);
            let d = basis_ders::<4>(&KNOTS, s, u);
            let h = 1e-5;
            let lo = basis_ders::<3>(&KNOTS, s, u - h);
            let hi = basis_ders::<3>(&KNOTS, s, u + h);
            for k in 1..4 {
                for r in 0..4 {
                    let fd = (hi[k - 1][r] - lo[k - 1][r]) / (2.0 * h);
                    let tol = 1e-5 * (1.0 + d[k][r].abs());
                    assert!((d[k][r] - fd).abs() < tol, "u {u} k {k} r {r}");
                }
            }
            // Derivatives of a partition of unity sum to zero.
            for row in &d[1..] {
                assert!(row.iter().sum::<f64>().abs() < 1e-9);
            }
        }
    }

    #[test]
    fn span_at_the_ends_of_the_domain() {
        let n = KNOTS.len() - 4;
        assert_eq!(find_span(&KNOTS, n, 0.0), 3);
        assert_eq!(find_span(&KNOTS, n, -1.0), 3);
        assert_eq!(find_span(&KNOTS, n, 1.0), n - 1);
        assert_eq!(find_span(&KNOTS, n, 2.0), n - 1);
        assert_eq!(find_span(&KNOTS, n, 0.5), 5);
    }
}
