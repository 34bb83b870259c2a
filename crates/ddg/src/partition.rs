//! Weights and the balanced split of the DDG (§6, step 2), and the shifted
//! partitions of passes 2 and 3 (§7).
use crate::Ddg;
use parafront_geom::{tet_volume6, Aabb, P3};

/// Fine tets each DDG tet will hold (§6): its volume over the volume of a
/// regular tet at the size `h` at its centroid.
pub fn tet_weights(d: &Ddg, h: &(dyn Fn(P3) -> f64 + Sync)) -> Vec<f64> {
    (0..d.tets.len())
        .map(|t| {
            let p = d.tet_points(t);
            let v = tet_volume6(p[0], p[1], p[2], p[3]) / 6.0;
            let s = h(d.centroid(t));
            let reg = s * s * s / (6.0 * std::f64::consts::SQRT_2);
            (v / reg).max(0.0)
        })
        .collect()
}

/// Max over mean of the parts' summed weights.
pub fn imbalance(part: &[u32], w: &[f64], parts: usize) -> f64 {
    let mut sum = vec![0.0; parts];
    for (&k, &x) in part.iter().zip(w) {
        sum[k as usize] += x;
    }
    let mean = sum.iter().sum::<f64>() / parts as f64;
    if mean <= 0.0 {
        return 1.0;
    }
    sum.iter().cloned().fold(0.0, f64::max) / mean
}

/// Recursive coordinate bisection by weight (§6): split the tets' centroids
/// across the longest axis of their box so that each side gets weight in
/// proportion to its number of parts. Deterministic: ties go by tet id.
pub fn rcb(d: &Ddg, w: &[f64], parts: usize) -> Vec<u32> {
    let mut part = vec![0u32; d.tets.len()];
    let cen: Vec<P3> = (0..d.tets.len()).map(|t| d.centroid(t)).collect();
    let mut ids: Vec<u32> = (0..d.tets.len() as u32).collect();
    split(&cen, w, &mut ids, 0, parts as u32, &mut part);
    part
}

fn split(cen: &[P3], w: &[f64], ids: &mut [u32], first: u32, parts: u32, part: &mut [u32]) {
    if parts <= 1 || ids.len() <= 1 {
        for &t in ids.iter() {
            part[t as usize] = first;
        }
        return;
    }
    let ax = Aabb::from_points(ids.iter().map(|&t| &cen[t as usize])).longest_axis();
    ids.sort_unstable_by(|&a, &b| {
        cen[a as usize][ax]
            .total_cmp(&cen[b as usize][ax])
            .then(a.cmp(&b))
    });
    let left = parts / 2;
    let total: f64 = ids.iter().map(|&t| w[t as usize]).sum();
    let target = total * left as f64 / parts as f64;
    let mut acc = 0.0;
    let mut cut = ids.len();
    for (i, &t) in ids.iter().enumerate() {
        if acc + 0.5 * w[t as usize] > target {
            cut = i;
            break;
        }
        acc += w[t as usize];
    }
    let cut = cut.clamp(1, ids.len() - 1);
    let (a, b) = ids.split_at_mut(cut);
    split(cen, w, a, first, left, part);
    split(cen, w, b, first + left, parts - left, part);
}

/// Which way passes 2 and 3 move the walls (§7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shift {
    /// Pass 2: each part takes layers from its neighbours of higher index.
    FromHigher,
    /// Pass 3: from its neighbours of lower index.
    FromLower,
}

/// The partition with `layers` layers of DDG tets (tets sharing a point)
/// moved across each wall, every layer from the partition before it.
pub fn shifted(d: &Ddg, part: &[u32], shift: Shift, layers: usize) -> Vec<u32> {
    let (start, list) = d.point_tets();
    let mut cur = part.to_vec();
    for _ in 0..layers {
        // Per point, the lowest (highest) part around it.
        let pick = |a: u32, b: u32| match shift {
            Shift::FromHigher => a.min(b),
            Shift::FromLower => a.max(b),
        };
        let around: Vec<u32> = (0..d.points.len())
            .map(|p| {
                let ts = &list[start[p] as usize..start[p + 1] as usize];
                ts.iter()
                    .map(|&t| cur[t as usize])
                    .reduce(pick)
                    .unwrap_or(0)
            })
            .collect();
        cur = (0..d.tets.len())
            .map(|t| {
                d.tets[t]
                    .iter()
                    .map(|&p| around[p as usize])
                    .fold(cur[t], pick)
            })
            .collect();
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    fn sphere_ddg() -> Ddg {
        let s = generate::icosphere([0.0; 3], 1.0, 3);
        let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        crate::build(
            s.points.clone(),
            s.mean_edge_lengths(),
            faces,
            crate::DEFAULT_GROWTH,
            crate::DdgMode::default(),
        )
        .unwrap()
    }

    #[test]
    fn rcb_balances_the_predicted_weights() {
        let d = sphere_ddg();
        let w = tet_weights(&d, &|_p| 0.05);
        for parts in [2usize, 3, 8] {
            let part = rcb(&d, &w, parts);
            assert!(part.iter().all(|&k| (k as usize) < parts));
            for k in 0..parts as u32 {
                assert!(part.contains(&k), "part {k} of {parts} is empty");
            }
            let imb = imbalance(&part, &w, parts);
            assert!(imb < 1.15, "{parts} parts: imbalance {imb}");
        }
    }

    #[test]
    fn a_shift_moves_tets_toward_the_lower_part_only() {
        let d = sphere_ddg();
        let w = tet_weights(&d, &|_p| 0.05);
        let part = rcb(&d, &w, 4);
        let up = shifted(&d, &part, Shift::FromHigher, 2);
        let down = shifted(&d, &part, Shift::FromLower, 2);
        let moved = up.iter().zip(&part).filter(|(a, b)| a != b).count();
        assert!(moved > 0);
        assert!(up.iter().zip(&part).all(|(a, b)| a <= b));
        assert!(down.iter().zip(&part).all(|(a, b)| a >= b));
    }
}
