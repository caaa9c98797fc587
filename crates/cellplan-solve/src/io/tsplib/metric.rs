//! The TSPLIB95 distance rules: the full matrix from EDGE_WEIGHT_SECTION in each format, and
//! from coordinates by EUC_2D, CEIL_2D, ATT and GEO (nearest-integer rounding as TSPLIB95 §2).
use crate::error::CostMatrixError;
use crate::problem::CostMatrix;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum WeightType {
    Euc2d,
    Ceil2d,
    Att,
    Geo,
    Explicit,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Format {
    Full,
    UpperRow,
    LowerRow,
    UpperDiagRow,
    LowerDiagRow,
}

/// The symmetric matrix of `n` nodes from EDGE_WEIGHT_SECTION's values in format `f`.
pub(super) fn explicit_matrix(n: usize, f: Format, vals: &[f64]) -> Result<CostMatrix, CostMatrixError> {
    let mut m = vec![0.0; n * n];
    let mut it = vals.iter().copied();
    let mut set = |i: usize, j: usize, v: f64| {
        m[i * n + j] = v;
        m[j * n + i] = v;
    };
    match f {
        Format::Full => {
            return CostMatrix::new(n, vals.to_vec());
        }
        Format::UpperRow => (0..n).for_each(|i| (i + 1..n).for_each(|j| set(i, j, it.next().unwrap_or(0.0)))),
        Format::LowerRow => (0..n).for_each(|i| (0..i).for_each(|j| set(i, j, it.next().unwrap_or(0.0)))),
        Format::UpperDiagRow => (0..n).for_each(|i| (i..n).for_each(|j| set(i, j, it.next().unwrap_or(0.0)))),
        Format::LowerDiagRow => {
            (0..n).for_each(|i| (0..=i).for_each(|j| set(i, j, it.next().unwrap_or(0.0))))
        }
    }
    CostMatrix::new(n, m)
}

/// TSPLIB's `nint`: `(int)(x + 0.5)`.
fn nint(x: f64) -> f64 {
    (x + 0.5).floor()
}

/// Latitude or longitude in radians from TSPLIB's DDD.MM notation.
fn geo_rad(x: f64) -> f64 {
    // TSPLIB95 fixes PI to 3.141592; the published optima depend on it.
    #[allow(clippy::approx_constant)]
    const PI: f64 = 3.141592;
    let deg = x.trunc();
    let min = x - deg;
    PI * (deg + 5.0 * min / 3.0) / 180.0
}

/// The matrix of TSPLIB distances of type `wt` between the coordinates `c`.
pub(super) fn coord_matrix(wt: WeightType, c: &[(f64, f64)]) -> Result<CostMatrix, CostMatrixError> {
    let n = c.len();
    let geo: Vec<(f64, f64)> = if wt == WeightType::Geo {
        c.iter().map(|&(x, y)| (geo_rad(x), geo_rad(y))).collect()
    } else {
        Vec::new()
    };
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        for j in i + 1..n {
            let (dx, dy) = (c[i].0 - c[j].0, c[i].1 - c[j].1);
            let d = match wt {
                WeightType::Euc2d => nint((dx * dx + dy * dy).sqrt()),
                WeightType::Ceil2d => (dx * dx + dy * dy).sqrt().ceil(),
                WeightType::Att => {
                    let r = ((dx * dx + dy * dy) / 10.0).sqrt();
                    let t = nint(r);
                    if t < r { t + 1.0 } else { t }
                }
                WeightType::Geo => {
                    const RRR: f64 = 6378.388;
                    let ((lat_i, lon_i), (lat_j, lon_j)) = (geo[i], geo[j]);
                    let q1 = (lon_i - lon_j).cos();
                    let q2 = (lat_i - lat_j).cos();
                    let q3 = (lat_i + lat_j).cos();
                    let a = (0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)).clamp(-1.0, 1.0);
                    (RRR * a.acos() + 1.0).trunc()
                }
                WeightType::Explicit => 0.0,
            };
            m[i * n + j] = d;
            m[j * n + i] = d;
        }
    }
    CostMatrix::new(n, m)
}
