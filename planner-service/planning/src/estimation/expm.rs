//! Matrix exponential by scaling and squaring with the degree-13 Padé approximant
//! (Higham, "The scaling and squaring method for the matrix exponential revisited",
//! SIAM J. Matrix Anal. Appl. 26(4), 2005, algorithm 2.3 with its `theta_13`).

use nalgebra::SMatrix;

/// Padé(13) numerator coefficients `b_0 .. b_13` (Higham 2005, table 2.3 and eq. 2.5).
const B13: [f64; 14] = [
    64764752532480000.0,
    32382376266240000.0,
    7771770303897600.0,
    1187353796428800.0,
    129060195264000.0,
    10559470521600.0,
    670442572800.0,
    33522128640.0,
    1323241920.0,
    40840800.0,
    960960.0,
    16380.0,
    182.0,
    1.0,
];

/// Largest 1-norm for which Padé(13) without scaling has backward error below the unit
/// roundoff (Higham 2005, table 2.3).
const THETA13: f64 = 5.371920351148152;

/// `exp(A)` for a static square matrix, allocation-free. `None` if `A` holds a non-finite
/// entry, its norm needs more than 1023 squarings, or the Padé denominator is singular
/// (which cannot happen for a finite `A` after scaling, `||A|| <= theta_13`).
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> Option<SMatrix<f64, N, N>> {
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let norm = (0..N)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > THETA13 {
        (norm / THETA13).log2().ceil() as i32
    } else {
        0
    };
    if squarings > 1023 {
        return None;
    }
    let a = a * 2f64.powi(-squarings);
    let ident = SMatrix::<f64, N, N>::identity();
    let a2 = a * a;
    let a4 = a2 * a2;
    let a6 = a4 * a2;
    let b = &B13;
    let u_inner = a6 * (a6 * b[13] + a4 * b[11] + a2 * b[9])
        + a6 * b[7]
        + a4 * b[5]
        + a2 * b[3]
        + ident * b[1];
    let u = a * u_inner;
    let v = a6 * (a6 * b[12] + a4 * b[10] + a2 * b[8])
        + a6 * b[6]
        + a4 * b[4]
        + a2 * b[2]
        + ident * b[0];
    let mut r = solve(v - u, v + u)?;
    for _ in 0..squarings {
        r = r * r;
    }
    if r.iter().all(|v| v.is_finite()) {
        Some(r)
    } else {
        None
    }
}

/// Solves `A X = B` by Gaussian elimination with partial pivoting (`None` if `A` is
/// singular to working precision).
fn solve<const N: usize>(
    mut a: SMatrix<f64, N, N>,
    mut b: SMatrix<f64, N, N>,
) -> Option<SMatrix<f64, N, N>> {
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..N {
        let (piv, pmax) = (col..N)
            .map(|r| (r, a[(r, col)].abs()))
            .fold((col, -1.0), |best, x| if x.1 > best.1 { x } else { best });
        if pmax.is_nan() || pmax <= scale * f64::EPSILON * N as f64 {
            return None;
        }
        a.swap_rows(col, piv);
        b.swap_rows(col, piv);
        for r in col + 1..N {
            let f = a[(r, col)] / a[(col, col)];
            if f != 0.0 {
                for c in col..N {
                    a[(r, c)] -= f * a[(col, c)];
                }
                for c in 0..N {
                    b[(r, c)] -= f * b[(col, c)];
                }
            }
        }
    }
    for col in (0..N).rev() {
        for c in 0..N {
            let mut v = b[(col, c)];
            for k in col + 1..N {
                v -= a[(col, k)] * b[(k, c)];
            }
            b[(col, c)] = v / a[(col, col)];
        }
    }
    Some(b)
}
