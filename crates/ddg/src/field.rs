//! The DDG's size field (§5 as a field): the surface sizes grown by
//! `c - 1` per unit distance, `f(x) = min_i h_i + (c - 1) |x - x_i|`.
//!
//! The fine mesher's size field (`parafront_size`) builds an octree that
//! answers millions of queries; the DDG's front asks once per new point,
//! a few hundred thousand times, so a k-d tree over the surface points
//! with a branch-and-bound query costs far less to build (milliseconds
//! against seconds on a 59k-point surface) and answers within 1 % of the
//! exact minimum (never below it).
use parafront_geom::{dist, P3};

/// Seeds per leaf.
const LEAF: usize = 8;
/// A subtree is skipped when its lower bound is within this fraction of
/// the best value found: the answer is at most this much too large.
const TOL: f64 = 0.01;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: P3,
    hi: P3,
    hmin: f64,
    /// Seeds `start..end` (a leaf) or the two children (`left`, `left + 1`
    /// are not adjacent: both indices are kept).
    start: u32,
    end: u32,
    left: u32,
    right: u32,
}

/// See the module doc.
#[derive(Clone, Debug)]
pub struct GradedField {
    slope: f64,
    seeds: Vec<(P3, f64)>,
    nodes: Vec<Node>,
}

impl GradedField {
    /// `seeds`: (point, size) pairs; `slope` = `c - 1` >= 0.
    pub fn new(mut seeds: Vec<(P3, f64)>, slope: f64) -> GradedField {
        let mut nodes = Vec::new();
        if !seeds.is_empty() {
            let n = seeds.len();
            build(&mut seeds, 0, n, &mut nodes);
        }
        GradedField {
            slope,
            seeds,
            nodes,
        }
    }

    /// The seeds of a closed front: its points, each with the mean length
    /// of its edges ([`parafront_surface::mean_edge_lengths`], what the fine size field gives a
    /// surface point).
    pub fn of_front(points: &[P3], faces: &[[u32; 3]], slope: f64) -> GradedField {
        let h = parafront_surface::mean_edge_lengths(points, faces);
        GradedField::of_sizes(points, &h, slope)
    }

    /// Seeded by the points with a positive size `h[i]`.
    pub fn of_sizes(points: &[P3], h: &[f64], slope: f64) -> GradedField {
        let seeds = (0..points.len())
            .filter(|&i| h[i] > 0.0)
            .map(|i| (points[i], h[i]))
            .collect();
        GradedField::new(seeds, slope)
    }

    /// The size at `x`: the least seed size grown to it (+inf without
    /// seeds).
    pub fn size(&self, x: P3) -> f64 {
        if self.nodes.is_empty() {
            return f64::INFINITY;
        }
        let mut best = f64::INFINITY;
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let nd = &self.nodes[stack[top] as usize];
            if self.bound(nd, x) * (1.0 + TOL) >= best {
                continue;
            }
            if nd.left == u32::MAX {
                for &(p, h) in &self.seeds[nd.start as usize..nd.end as usize] {
                    best = best.min(h + self.slope * dist(x, p));
                }
                continue;
            }
            // The nearer child last, so it is visited first.
            let (a, b) = (nd.left, nd.right);
            let (ba, bb) = (
                self.bound(&self.nodes[a as usize], x),
                self.bound(&self.nodes[b as usize], x),
            );
            let (first, second) = if ba <= bb { (a, b) } else { (b, a) };
            stack[top] = second;
            stack[top + 1] = first;
            top += 2;
        }
        best
    }

    #[inline]
    fn bound(&self, nd: &Node, x: P3) -> f64 {
        let mut d2 = 0.0;
        for (k, &xk) in x.iter().enumerate() {
            let e = (nd.lo[k] - xk).max(xk - nd.hi[k]).max(0.0);
            d2 += e * e;
        }
        nd.hmin + self.slope * d2.sqrt()
    }
}

/// Median split across the longest axis; deterministic (ties by the
/// seeds' order, which the caller fixes).
fn build(seeds: &mut [(P3, f64)], start: usize, end: usize, nodes: &mut Vec<Node>) -> u32 {
    let me = nodes.len() as u32;
    let s = &mut seeds[start..end];
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut hmin = f64::INFINITY;
    for (p, h) in s.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        hmin = hmin.min(*h);
    }
    nodes.push(Node {
        lo,
        hi,
        hmin,
        start: start as u32,
        end: end as u32,
        left: u32::MAX,
        right: u32::MAX,
    });
    // 64-deep stack in `size`: leaves of 8 give depth ~log2(n / 8) < 30.
    if s.len() <= LEAF {
        return me;
    }
    let ax = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap();
    let mid = s.len() / 2;
    s.select_nth_unstable_by(mid, |a, b| {
        a.0[ax]
            .total_cmp(&b.0[ax])
            .then(a.0[(ax + 1) % 3].total_cmp(&b.0[(ax + 1) % 3]))
            .then(a.0[(ax + 2) % 3].total_cmp(&b.0[(ax + 2) % 3]))
            .then(a.1.total_cmp(&b.1))
    });
    let left = build(seeds, start, start + mid, nodes);
    let right = build(seeds, start + mid, end, nodes);
    nodes[me as usize].left = left;
    nodes[me as usize].right = right;
    me
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tree_matches_the_brute_force_minimum_within_its_tolerance() {
        let seeds: Vec<(P3, f64)> = (0..3000)
            .map(|i| {
                let t = i as f64;
                let p = [(t * 0.37).sin(), (t * 0.71).cos(), (t * 0.13).sin()];
                (p, 0.01 + 0.02 * (t * 0.05).sin().abs())
            })
            .collect();
        let f = GradedField::new(seeds.clone(), 0.6);
        for i in 0..500 {
            let t = i as f64;
            let x = [
                (t * 1.7).sin() * 1.3,
                (t * 0.3).cos(),
                (t * 2.9).sin() * 0.5,
            ];
            let exact = seeds
                .iter()
                .map(|&(p, h)| h + 0.6 * dist(x, p))
                .fold(f64::INFINITY, f64::min);
            let got = f.size(x);
            assert!(
                got >= exact && got <= exact * (1.0 + TOL) + 1e-15,
                "{got} vs {exact}"
            );
        }
    }
}
