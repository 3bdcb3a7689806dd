//! LU decomposition with partial pivoting of one 6x6 matrix, on plain arrays.
//!
//! nalgebra's `lu()` does the same arithmetic, but through its generic storage, permutation sequence and
//! column views: about 1,800 instructions a decomposition on the Cortex-M4F (measured under QEMU), where this
//! loop over fixed-size rows, which the compiler unrolls, takes a fraction of it. The control tick needs a
//! determinant (the singularity index) and forward kinematics a determinant and a solve, each every period.

// Elimination reads one row while it writes another of the same matrix: index loops say so more plainly than
// split borrows.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix6;

use crate::Real;

/// `P M = L U` of a 6x6 matrix `M`, decomposed in the caller's rows: `L` unit lower triangular below their
/// diagonal, `U` on and above it. In place, because moving 144-byte matrices in and out of calls costs more than
/// the elimination on the M4F (each move is a `memcpy` call; measured).
#[derive(Debug)]
pub(crate) struct Lu6<'a, T> {
    lu: &'a [[T; 6]; 6],
    /// Row `i` of `P M` is row `perm[i]` of `M`.
    perm: [u8; 6],
    /// An odd number of row swaps (the determinant changes sign).
    odd: bool,
    /// A pivot was zero or not finite: the matrix is singular (or its entries were not finite).
    singular: bool,
}

impl<'a, T: Real> Lu6<'a, T> {
    /// Decomposes the matrix given by its rows, which become the factors.
    #[inline]
    pub(crate) fn in_place(rows: &'a mut [[T; 6]; 6]) -> Self {
        let mut perm = [0, 1, 2, 3, 4, 5];
        let mut odd = false;
        // One column at a time, each a constant: every loop has a fixed trip count and unrolls (a loop over the
        // column stays rolled and costs three times as much on the M4F).
        let regular = eliminate::<T, 0>(rows, &mut perm, &mut odd)
            && eliminate::<T, 1>(rows, &mut perm, &mut odd)
            && eliminate::<T, 2>(rows, &mut perm, &mut odd)
            && eliminate::<T, 3>(rows, &mut perm, &mut odd)
            && eliminate::<T, 4>(rows, &mut perm, &mut odd)
            && eliminate::<T, 5>(rows, &mut perm, &mut odd);
        Self {
            lu: rows,
            perm,
            odd,
            singular: !regular,
        }
    }

    /// The determinant: 0 when a pivot was zero, NaN when an entry was not finite.
    pub(crate) fn determinant(&self) -> T {
        if self.singular {
            let finite = self.lu.iter().flatten().all(|v| v.finite());
            return if finite { T::zero() } else { T::zero() / T::zero() };
        }
        let product = (0..6).fold(T::one(), |d, k| d * self.lu[k][k]);
        if self.odd {
            -product
        } else {
            product
        }
    }

    /// Solves `M x = b`; `None` when the matrix is singular or the solution is not finite.
    pub(crate) fn solve(&self, b: &[T; 6]) -> Option<[T; 6]> {
        if self.singular {
            return None;
        }
        let mut x: [T; 6] = core::array::from_fn(|i| b[usize::from(self.perm[i])]);
        for i in 1..6 {
            for j in 0..i {
                let l = self.lu[i][j];
                x[i] -= l * x[j];
            }
        }
        for i in (0..6).rev() {
            for j in i + 1..6 {
                let u = self.lu[i][j];
                x[i] -= u * x[j];
            }
            x[i] /= self.lu[i][i];
        }
        x.iter().all(|v| v.finite()).then_some(x)
    }
}

/// Pivots on column `K` and eliminates it below the diagonal; false when the pivot is zero or not finite.
#[inline(always)]
fn eliminate<T: Real, const K: usize>(lu: &mut [[T; 6]; 6], perm: &mut [u8; 6], odd: &mut bool) -> bool {
    // The largest magnitude so far is kept, not reloaded through the index of its row.
    let mut p = K;
    let mut largest = lu[K][K].abs();
    for i in K + 1..6 {
        let magnitude = lu[i][K].abs();
        if magnitude > largest {
            largest = magnitude;
            p = i;
        }
    }
    let pivot = lu[p][K];
    // Zero, infinite or NaN, by two comparisons of the magnitude the search kept (a NaN fails both), where
    // `pivot == 0 || !pivot.finite()` took the absolute value again.
    if !(largest > T::zero() && largest <= T::max_value().unwrap_or(T::one())) {
        return false;
    }
    if p != K {
        // Element by element: `swap` of whole rows calls memmove.
        for j in 0..6 {
            let t = lu[p][j];
            lu[p][j] = lu[K][j];
            lu[K][j] = t;
        }
        perm.swap(p, K);
        *odd = !*odd;
    }
    let inv = T::one() / pivot;
    for i in K + 1..6 {
        let f = lu[i][K] * inv;
        lu[i][K] = f;
        for j in K + 1..6 {
            let u = lu[K][j];
            lu[i][j] -= f * u;
        }
    }
    true
}

/// The rows of a nalgebra matrix.
pub(crate) fn rows_of<T: Real>(m: &Matrix6<T>) -> [[T; 6]; 6] {
    core::array::from_fn(|r| core::array::from_fn(|c| m[(r, c)]))
}

#[cfg(test)]
#[allow(clippy::expect_used)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    #[test]
    fn determinant_and_solution_agree_with_nalgebra() {
        let mut state = 7;
        for _ in 0..2_000 {
            let m = Matrix6::<f64>::from_fn(|_, _| lcg(&mut state));
            let b: [f64; 6] = core::array::from_fn(|_| lcg(&mut state));
            let mut rows = rows_of(&m);
            let lu = Lu6::in_place(&mut rows);
            let det = m.lu().determinant();
            assert!((lu.determinant() - det).abs() <= 1e-12 * det.abs().max(1e-3), "{det}");
            // Partial pivoting: each pivot is its column's largest, so no multiplier exceeds 1 in magnitude.
            for i in 1..6 {
                for j in 0..i {
                    assert!(lu.lu[i][j].abs() <= 1.0, "multiplier {} at ({i}, {j})", lu.lu[i][j]);
                }
            }
            let x = lu.solve(&b).expect("a random matrix is regular");
            let residual = m * nalgebra::Vector6::from(x) - nalgebra::Vector6::from(b);
            assert!(residual.amax() < 1e-9, "{residual}");
        }
    }

    #[test]
    fn singular_and_non_finite_matrices() {
        let mut rows = [[0.0f64; 6]; 6];
        for (i, row) in rows.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        rows[4] = rows[2];
        let mut singular = rows;
        let lu = Lu6::in_place(&mut singular);
        assert_eq!(lu.determinant(), 0.0);
        assert_eq!(lu.solve(&[1.0; 6]), None);
        rows[4][4] = f64::NAN;
        assert!(Lu6::in_place(&mut rows).determinant().is_nan());
        // An infinite pivot (first in its column, or reached after others) is not a regular matrix's either.
        for at in [0, 3, 5] {
            for inf in [f64::INFINITY, f64::NEG_INFINITY] {
                let mut rows = [[0.0f64; 6]; 6];
                for (i, row) in rows.iter_mut().enumerate() {
                    row[i] = 1.0;
                }
                rows[at][at] = inf;
                let lu = Lu6::in_place(&mut rows);
                assert!(lu.determinant().is_nan(), "{at} {inf}");
                assert_eq!(lu.solve(&[1.0; 6]), None);
            }
        }
        // The smallest normal pivot is a pivot.
        let mut tiny = [[0.0f64; 6]; 6];
        for (i, row) in tiny.iter_mut().enumerate() {
            row[i] = if i == 2 { f64::MIN_POSITIVE } else { 1.0 };
        }
        assert_eq!(Lu6::in_place(&mut tiny).determinant(), f64::MIN_POSITIVE);
        let mut swapped = [
            [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 2.0],
        ];
        let swapped = Lu6::in_place(&mut swapped);
        assert_eq!(swapped.determinant(), -2.0);
        assert_eq!(
            swapped.solve(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
            Some([2.0, 1.0, 3.0, 4.0, 5.0, 3.0])
        );
    }
}
