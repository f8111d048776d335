//! Banded linear systems: LU factorisation with partial pivoting in band
//! storage (the scheme of LAPACK's `dgbtrf`/`dgbtrs`), O(n·kl·(kl+ku)) work
//! and O(n·(2kl+ku+1)) memory. The collocation systems of spline
//! interpolation are tridiagonal-like (kl = 1, ku ≤ 3) and the normal
//! equations of least-squares fitting have kl = ku = degree, so a 200-point
//! direction costs a few thousand operations instead of dense LU's millions.

/// A square band matrix: entries (i, j) with `i − kl ≤ j ≤ i + ku` may be
/// non-zero. Row interchanges during factorisation widen the upper band to
/// `ku + kl`, for which room is kept.
#[derive(Debug, Clone)]
pub struct BandMatrix {
    n: usize,
    kl: usize,
    ku: usize,
    /// Row `i` holds columns `i − kl ..= i + kl + ku`, at offset `j + kl − i`.
    data: Vec<f64>,
}

/// The matrix is singular (to working precision): a zero pivot in `column`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singular {
    /// 0-based column of the zero pivot.
    pub column: usize,
}

impl BandMatrix {
    /// An `n × n` zero matrix with `kl` sub- and `ku` super-diagonals.
    pub fn zeros(n: usize, kl: usize, ku: usize) -> BandMatrix {
        BandMatrix {
            n,
            kl,
            ku,
            data: vec![0.0; n * (2 * kl + ku + 1)],
        }
    }

    /// The order of the matrix.
    pub fn order(&self) -> usize {
        self.n
    }

    fn width(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        debug_assert!(j + self.kl >= i && j + self.kl - i < self.width());
        i * self.width() + (j + self.kl - i)
    }

    /// Entry (i, j); zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i >= self.n || j >= self.n || j + self.kl < i || j > i + self.ku + self.kl {
            return 0.0;
        }
        self.data[self.at(i, j)]
    }

    /// Sets entry (i, j).
    ///
    /// # Panics
    /// If (i, j) lies outside the declared band (a programming error).
    pub fn set(&mut self, i: usize, j: usize, value: f64) {
        assert!(
            i < self.n && j < self.n && j + self.kl >= i && j <= i + self.ku,
            "entry ({i}, {j}) outside the band (kl {}, ku {})",
            self.kl,
            self.ku
        );
        let k = self.at(i, j);
        self.data[k] = value;
    }

    /// Adds to entry (i, j) (same band rule as [`set`](Self::set)).
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        let v = self.get(i, j);
        self.set(i, j, v + value);
    }

    /// `self · x` (for residual checks).
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|i| {
                let lo = i.saturating_sub(self.kl);
                let hi = (i + self.ku).min(self.n - 1);
                (lo..=hi).map(|j| self.get(i, j) * x[j]).sum()
            })
            .collect()
    }

    /// LU factorisation with partial pivoting (row interchanges within the
    /// `kl` rows below the diagonal). A pivot smaller than `1e-14` times the
    /// largest entry of the matrix counts as zero.
    pub fn factor(mut self) -> Result<BandLu, Singular> {
        let n = self.n;
        let (kl, ku) = (self.kl, self.ku);
        let scale = self.data.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tiny = scale * 1e-14;
        let mut pivots = Vec::with_capacity(n);
        for k in 0..n {
            let last_row = (k + kl).min(n - 1);
            let last_col = (k + kl + ku).min(n - 1);
            let mut p = k;
            let mut best = self.data[self.at(k, k)].abs();
            for i in k + 1..=last_row {
                let v = self.data[self.at(i, k)].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best > tiny) {
                return Err(Singular { column: k });
            }
            pivots.push(p);
            if p != k {
                for j in k..=last_col {
                    let (a, b) = (self.at(k, j), self.at(p, j));
                    self.data.swap(a, b);
                }
            }
            let pivot = self.data[self.at(k, k)];
            for i in k + 1..=last_row {
                let ik = self.at(i, k);
                let l = self.data[ik] / pivot;
                self.data[ik] = l;
                if l != 0.0 {
                    for j in k + 1..=last_col {
                        let (ij, kj) = (self.at(i, j), self.at(k, j));
                        self.data[ij] -= l * self.data[kj];
                    }
                }
            }
        }
        Ok(BandLu { m: self, pivots })
    }
}

/// A factorised band matrix, ready to solve any number of right-hand sides.
#[derive(Debug, Clone)]
pub struct BandLu {
    m: BandMatrix,
    pivots: Vec<usize>,
}

impl BandLu {
    /// The order of the matrix.
    pub fn order(&self) -> usize {
        self.m.n
    }

    /// Solves `A x = b` in place for a right-hand side of `N`-vectors (one
    /// solve per coordinate, sharing the elimination).
    ///
    /// # Panics
    /// If `b.len()` is not the order of the matrix.
    pub fn solve_in_place<const N: usize>(&self, b: &mut [[f64; N]]) {
        let m = &self.m;
        let n = m.n;
        assert_eq!(b.len(), n, "right-hand side of the wrong length");
        for k in 0..n {
            let p = self.pivots[k];
            if p != k {
                b.swap(k, p);
            }
            let bk = b[k];
            for i in k + 1..=(k + m.kl).min(n - 1) {
                let l = m.data[m.at(i, k)];
                if l != 0.0 {
                    for c in 0..N {
                        b[i][c] -= l * bk[c];
                    }
                }
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..=(i + m.kl + m.ku).min(n - 1) {
                let a = m.data[m.at(i, j)];
                for c in 0..N {
                    s[c] -= a * b[j][c];
                }
            }
            let d = m.data[m.at(i, i)];
            for c in 0..N {
                s[c] /= d;
            }
            b[i] = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn dense_solve(a: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
        let n = b.len();
        let m = nalgebra::DMatrix::from_fn(n, n, |i, j| a[i][j]);
        let v = nalgebra::DVector::from_column_slice(b);
        let x = m.lu().solve(&v).expect("test matrices are regular");
        x.iter().copied().collect()
    }

    proptest! {
        /// Band LU agrees with nalgebra's dense LU on random diagonally
        /// weighted band matrices, including ones that need pivoting.
        #[test]
        fn agrees_with_dense_lu(
            n in 1usize..30,
            kl in 0usize..4,
            ku in 0usize..4,
            seed in proptest::collection::vec(-1.0f64..1.0, 30 * 30 + 30),
            swap_weight in 0.0f64..3.0,
        ) {
            let mut band = BandMatrix::zeros(n, kl, ku);
            let mut dense = vec![vec![0.0; n]; n];
            for i in 0..n {
                for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                    let mut v = seed[i * 30 + j];
                    // A weak diagonal makes pivoting necessary; keep the
                    // matrix regular by a sub-diagonal weight instead.
                    if i == j { v += 0.5; }
                    if i == j + 1 { v += swap_weight; }
                    band.set(i, j, v);
                    dense[i][j] = v;
                }
            }
            // Well-conditioned only (a determinant says nothing about that).
            let sv = nalgebra::DMatrix::from_fn(n, n, |i, j| dense[i][j]).singular_values();
            prop_assume!(sv.min() > 1e-6 * sv.max());
            let b: Vec<f64> = (0..n).map(|i| seed[900 + i]).collect();
            let want = dense_solve(&dense, &b);
            let lu = band.factor().unwrap();
            let mut x: Vec<[f64; 1]> = b.iter().map(|&v| [v]).collect();
            lu.solve_in_place(&mut x);
            for i in 0..n {
                prop_assert!((x[i][0] - want[i]).abs() < 1e-7 * (1.0 + want[i].abs()),
                    "x[{i}] = {} vs {}", x[i][0], want[i]);
            }
        }
    }

    #[test]
    fn singular_matrix_is_reported() {
        let mut a = BandMatrix::zeros(3, 1, 1);
        a.set(0, 0, 1.0);
        a.set(0, 1, 2.0);
        a.set(1, 0, 2.0);
        a.set(1, 1, 4.0);
        a.set(2, 2, 1.0);
        assert_eq!(a.factor().unwrap_err(), Singular { column: 1 });
    }

    #[test]
    fn solves_a_tridiagonal_system_with_three_right_hand_sides() {
        let n = 50;
        let mut a = BandMatrix::zeros(n, 1, 1);
        for i in 0..n {
            a.set(i, i, 4.0);
            if i > 0 {
                a.set(i, i - 1, 1.0);
            }
            if i + 1 < n {
                a.set(i, i + 1, 1.0);
            }
        }
        let x: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, (i as f64).sin(), 1.0]).collect();
        let cols: Vec<Vec<f64>> = (0..3)
            .map(|c| a.mul_vec(&x.iter().map(|v| v[c]).collect::<Vec<_>>()))
            .collect();
        let b: Vec<[f64; 3]> = (0..n)
            .map(|i| [cols[0][i], cols[1][i], cols[2][i]])
            .collect();
        let mut y = b.clone();
        a.factor().unwrap().solve_in_place(&mut y);
        for (g, w) in y.iter().zip(&x) {
            for c in 0..3 {
                assert!((g[c] - w[c]).abs() < 1e-12);
            }
        }
    }
}
