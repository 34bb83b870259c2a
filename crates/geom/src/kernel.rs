//! The deepest point of an intersection of half-spaces (a polyhedron's
//! kernel): the point that sees every face of a pocket from furthest away,
//! for recovery's cones (step 5.3).
//!
//! It is a small linear program, max t subject to n_i.x - t >= n_i.p_i,
//! solved through its dual (4 equality rows, one column per plane) by a
//! dense two-phase simplex with Bland's rule, so it cannot cycle.
use crate::{dot, normalize, sub, P3};

/// The point `x` that maximises its smallest signed distance to the planes
/// (point `p`, normal `n` pointing inside), and that distance. `None` when
/// the planes bound no finite region (the LP is unbounded or degenerate).
/// A negative distance means the half-spaces have no common point.
pub fn deepest_point(planes: &[(P3, P3)]) -> Option<(P3, f64)> {
    let m = planes.len();
    if m < 4 {
        return None;
    }
    // Work about the planes' mean point, with unit normals.
    let mut c = [0.0; 3];
    for (p, _) in planes {
        for k in 0..3 {
            c[k] += p[k] / m as f64;
        }
    }
    let mut a = vec![[0.0f64; 4]; m];
    let mut d = vec![0.0f64; m];
    for (i, (p, n)) in planes.iter().enumerate() {
        let n = normalize(*n);
        if !n.iter().all(|x| x.is_finite()) {
            return None;
        }
        a[i] = [n[0], n[1], n[2], 1.0];
        d[i] = dot(n, sub(*p, c));
    }
    // Dual: min sum_i l_i (-d_i) s.t. sum_i l_i a_i = (0, 0, 0, 1), l >= 0.
    // Columns: m duals, then 4 artificials. Rows: 4, plus the cost row.
    let cols = m + 4;
    let mut tab = vec![vec![0.0f64; cols + 1]; 4];
    for r in 0..4 {
        for i in 0..m {
            tab[r][i] = a[i][r];
        }
        tab[r][m + r] = 1.0;
    }
    tab[3][cols] = 1.0;
    let mut basis: [usize; 4] = [m, m + 1, m + 2, m + 3];
    // Phase 1: drive the artificials out (cost 1 each).
    let mut cost1 = vec![0.0; cols];
    for c1 in cost1.iter_mut().skip(m) {
        *c1 = 1.0;
    }
    simplex(&mut tab, &mut basis, &cost1, cols)?;
    let infeas: f64 = (0..4)
        .filter(|&r| basis[r] >= m)
        .map(|r| tab[r][cols])
        .sum();
    if infeas > 1e-9 {
        return None; // the normals do not surround any point
    }
    // Phase 2 on the real cost; artificials may not re-enter.
    let mut cost2 = vec![0.0; cols];
    for i in 0..m {
        cost2[i] = -d[i];
    }
    for c2 in cost2.iter_mut().skip(m) {
        *c2 = 1e300;
    }
    simplex(&mut tab, &mut basis, &cost2, m)?;
    // Primal values y = c_B B^-1; B^-1 sits under the artificial columns.
    let mut y = [0.0; 4];
    for r in 0..4 {
        let cb = if basis[r] < m { cost2[basis[r]] } else { 0.0 };
        for (k, yk) in y.iter_mut().enumerate() {
            *yk += cb * tab[r][m + k];
        }
    }
    // The dual of the dual: max y4 s.t. a_i.y <= -d_i, so x = -y[..3].
    let x = [c[0] - y[0], c[1] - y[1], c[2] - y[2]];
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    // The depth, measured rather than read off the tableau.
    let depth = planes
        .iter()
        .map(|(p, n)| dot(normalize(*n), sub(x, *p)))
        .fold(f64::INFINITY, f64::min);
    Some((x, depth))
}

/// Minimise `cost` over the tableau (4 rows, RHS in the last column) with
/// Bland's rule; only the first `enter` columns may enter the basis.
fn simplex(tab: &mut [Vec<f64>], basis: &mut [usize; 4], cost: &[f64], enter: usize) -> Option<()> {
    let cols = cost.len();
    const EPS: f64 = 1e-12;
    for _ in 0..50 * (cols + 4) {
        // Reduced costs: c_j - c_B B^-1 A_j (the tableau holds B^-1 A).
        let mut e = None;
        for j in 0..enter {
            if basis.contains(&j) {
                continue;
            }
            let mut rc = cost[j];
            for r in 0..4 {
                let cb = cost[basis[r]];
                if cb != 0.0 {
                    rc -= cb * tab[r][j];
                }
            }
            if rc < -EPS {
                e = Some(j);
                break; // Bland: the lowest index that improves
            }
        }
        let Some(e) = e else {
            return Some(());
        };
        // Ratio test, ties to the lowest basic index.
        let mut leave: Option<(f64, usize)> = None;
        for r in 0..4 {
            let v = tab[r][e];
            if v > EPS {
                let ratio = tab[r][cols] / v;
                let better = match leave {
                    None => true,
                    Some((best, lr)) => {
                        ratio < best - EPS || (ratio <= best + EPS && basis[r] < basis[lr])
                    }
                };
                if better {
                    leave = Some((ratio, r));
                }
            }
        }
        let (_, r) = leave?; // unbounded
        let piv = tab[r][e];
        for v in tab[r].iter_mut() {
            *v /= piv;
        }
        let row = tab[r].clone();
        for (rr, tr) in tab.iter_mut().enumerate() {
            if rr == r {
                continue;
            }
            let f = tr[e];
            if f != 0.0 {
                for (v, w) in tr.iter_mut().zip(&row) {
                    *v -= f * w;
                }
            }
        }
        basis[r] = e;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_planes(lo: f64, hi: f64) -> Vec<(P3, P3)> {
        let mut v = Vec::new();
        for k in 0..3 {
            let mut n = [0.0; 3];
            n[k] = 1.0;
            v.push(([lo; 3], n));
            n[k] = -1.0;
            v.push(([hi; 3], n));
        }
        v
    }

    #[test]
    fn a_cube_has_its_centre_at_half_the_side() {
        let (x, t) = deepest_point(&cube_planes(1.0, 3.0)).unwrap();
        for v in x {
            assert!((v - 2.0).abs() < 1e-9, "{x:?}");
        }
        assert!((t - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_tet_has_its_incentre() {
        // Corner tet x, y, z >= 0, x + y + z <= 1: inradius 1 / (3 + sqrt 3).
        let s = 1.0 / 3f64.sqrt();
        let planes = vec![
            ([0.0; 3], [1.0, 0.0, 0.0]),
            ([0.0; 3], [0.0, 1.0, 0.0]),
            ([0.0; 3], [0.0, 0.0, 1.0]),
            ([1.0, 0.0, 0.0], [-s, -s, -s]),
        ];
        let (x, t) = deepest_point(&planes).unwrap();
        let r = 1.0 / (3.0 + 3f64.sqrt());
        assert!((t - r).abs() < 1e-9, "{t}");
        for v in x {
            assert!((v - r).abs() < 1e-9, "{x:?}");
        }
    }

    #[test]
    fn an_open_set_has_no_deepest_point() {
        // Every normal in one octant: the depth grows without bound.
        let s = 1.0 / 3f64.sqrt();
        let p = vec![
            ([0.0; 3], [1.0, 0.0, 0.0]),
            ([0.0; 3], [0.0, 1.0, 0.0]),
            ([0.0; 3], [0.0, 0.0, 1.0]),
            ([0.0; 3], [s, s, s]),
        ];
        assert!(deepest_point(&p).is_none());
    }

    #[test]
    fn disjoint_half_spaces_give_a_negative_depth() {
        // x >= 2 and x <= 1 (and a box in y, z): no common point; the
        // least violation is 0.5.
        let mut p = cube_planes(0.0, 1.0);
        p[0] = ([2.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let (_, t) = deepest_point(&p).unwrap();
        assert!((t + 0.5).abs() < 1e-9, "{t}");
    }
}
