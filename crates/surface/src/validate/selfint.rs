//! Self-intersecting triangle pairs: a bounding-volume hierarchy over the
//! triangle boxes finds candidate pairs, the exact test in
//! `parafront_geom::intersect` decides them. Boxes are exact min/max of the
//! coordinates, so touching triangles are always candidates.
use super::bvh::Bvh;
use crate::Surface;
use parafront_geom::intersect::triangles_intersect;
use parafront_geom::{Aabb, P3};
use rayon::prelude::*;

pub(super) fn tri_boxes(s: &Surface) -> Vec<Aabb> {
    s.tris
        .par_iter()
        .map(|t| Aabb::from_points(t.iter().map(|&v| &s.points[v as usize])))
        .collect()
}

/// Number of pairs `(i, j)`, `i < j`, of triangles (both not in `skip`)
/// that meet in more than their common vertices, and the first `keep` of
/// them in order. Memory stays O(`keep` n) however many pairs there are.
pub(super) fn self_intersections(
    s: &Surface,
    skip: &[bool],
    keep: usize,
) -> (usize, Vec<(u32, u32)>) {
    let boxes = tri_boxes(s);
    let ids: Vec<u32> = (0..s.tris.len() as u32)
        .filter(|&t| !skip[t as usize])
        .collect();
    let bvh = Bvh::build(ids, &boxes);
    // Query in tree order: neighbours in space reuse the same nodes.
    let (count, mut first) = bvh
        .order
        .par_iter()
        .map_init(Vec::new, |stack, &i| {
            let mut hits = Vec::new();
            bvh.query(&boxes[i as usize], &boxes, stack, |j| {
                if j > i && pair_intersects(s, i, j) {
                    hits.push((i, j));
                }
            });
            let n = hits.len();
            if n > keep {
                hits.select_nth_unstable(keep);
                hits.truncate(keep);
            }
            (n, hits)
        })
        .reduce(
            || (0, Vec::new()),
            |(n1, mut h1), (n2, h2)| {
                h1.extend(h2);
                if h1.len() > keep {
                    h1.select_nth_unstable(keep);
                    h1.truncate(keep);
                }
                (n1 + n2, h1)
            },
        );
    first.sort_unstable();
    (count, first)
}

/// Rotates the shared vertices to the front, in the same order in both, and
/// runs the exact test. Both triangles have three distinct ids.
pub(super) fn pair_intersects(s: &Surface, i: u32, j: u32) -> bool {
    let (ti, tj) = (s.tris[i as usize], s.tris[j as usize]);
    let p = |t: [u32; 3]| -> [P3; 3] { t.map(|v| s.points[v as usize]) };
    let mut common = [(0usize, 0usize); 3];
    let mut n = 0;
    for (a, va) in ti.iter().enumerate() {
        for (b, vb) in tj.iter().enumerate() {
            if va == vb && n < 3 {
                common[n] = (a, b);
                n += 1;
            }
        }
    }
    match n {
        0 => triangles_intersect(p(ti), p(tj), 0),
        1 => {
            let (a, b) = common[0];
            let t1 = [ti[a], ti[(a + 1) % 3], ti[(a + 2) % 3]];
            let t2 = [tj[b], tj[(b + 1) % 3], tj[(b + 2) % 3]];
            triangles_intersect(p(t1), p(t2), 1)
        }
        2 => {
            let (a0, b0) = common[0];
            let (a1, b1) = common[1];
            let (ka, kb) = (3 - a0 - a1, 3 - b0 - b1);
            let t1 = [ti[a0], ti[a1], ti[ka]];
            let t2 = [tj[b0], tj[b1], tj[kb]];
            triangles_intersect(p(t1), p(t2), 2)
        }
        _ => true,
    }
}
