//! Combinatorial checks on flat sorted arrays: edges, vertex fans,
//! duplicates, zero-area and unreferenced vertices.
use super::{Item, MAX_EXAMPLES};
use crate::Surface;
use parafront_geom::intersect::is_collinear;
use rayon::prelude::*;

/// Directed half-edge `k` of triangle `t` (from corner `k` to `k+1`) has id
/// `3t + k`.
#[inline]
pub(super) fn he_ends(s: &Surface, h: u32) -> (u32, u32) {
    let t = s.tris[(h / 3) as usize];
    let k = (h % 3) as usize;
    (t[k], t[(k + 1) % 3])
}

/// Undirected edges as runs of half-edges sorted by the key `(min, max)`.
pub(super) struct Edges {
    /// (key, half-edge id), sorted; self-loops (repeated ids) left out.
    pub he: Vec<(u64, u32)>,
    /// Start of each run in `he`, with a final sentinel `he.len()`.
    pub start: Vec<usize>,
}

impl Edges {
    pub fn build(s: &Surface) -> Edges {
        let mut he: Vec<(u64, u32)> = s
            .tris
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, tri)| {
                (0..3).filter_map(move |k| {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    (a != b).then(|| {
                        let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
                        (key, 3 * t as u32 + k as u32)
                    })
                })
            })
            .collect();
        he.par_sort_unstable();
        let mut start: Vec<usize> = (0..he.len())
            .filter(|&i| i == 0 || he[i].0 != he[i - 1].0)
            .collect();
        start.push(he.len());
        Edges { he, start }
    }

    pub fn n_edges(&self) -> usize {
        self.start.len() - 1
    }

    /// Half-edges of edge `e`.
    pub fn run(&self, e: usize) -> &[(u64, u32)] {
        &self.he[self.start[e]..self.start[e + 1]]
    }

    /// (open, non-manifold, inconsistently oriented) edge indices.
    pub fn classify(&self, s: &Surface) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let (mut open, mut nonman, mut incons) = (Vec::new(), Vec::new(), Vec::new());
        for e in 0..self.n_edges() {
            let r = self.run(e);
            match r.len() {
                1 => open.push(e as u32),
                2 => {
                    if he_ends(s, r[0].1).0 == he_ends(s, r[1].1).0 {
                        incons.push(e as u32);
                    }
                }
                _ => nonman.push(e as u32),
            }
        }
        (open, nonman, incons)
    }

    /// Report items for the first edges of a list.
    pub fn items(&self, s: &Surface, es: &[u32]) -> Vec<Item> {
        es.iter()
            .take(MAX_EXAMPLES)
            .map(|&e| {
                let r = self.run(e as usize);
                let key = r[0].0;
                let v = [(key >> 32) as u32, key as u32];
                Item::Edge {
                    v,
                    p: v.map(|i| s.points[i as usize]),
                    tris: r.iter().take(6).map(|&(_, h)| h / 3).collect(),
                }
            })
            .collect()
    }
}

/// Which points some triangle uses (indices already checked).
pub(super) fn referenced(s: &Surface) -> Vec<bool> {
    let mut used = vec![false; s.points.len()];
    for t in &s.tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    used
}

fn proper(t: &[u32; 3]) -> bool {
    t[0] != t[1] && t[1] != t[2] && t[2] != t[0]
}

/// Vertices with more than one fan of triangles, with their fan count.
/// A fan is a connected component of the vertex's link (each triangle at
/// `v` links its two other vertices), so an edge-manifold vertex where two
/// cones touch (the "cow" case) is found too. Triangles with repeated ids
/// are left out (reported as zero-area).
pub(super) fn pinched_vertices(s: &Surface) -> Vec<(u32, u32)> {
    let np = s.points.len();
    let mut start = vec![0usize; np + 1];
    for t in s.tris.iter().filter(|t| proper(t)) {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..np {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut inc = vec![0u32; start[np]];
    for (i, t) in s.tris.iter().enumerate().filter(|(_, t)| proper(t)) {
        for &v in t {
            inc[fill[v as usize]] = i as u32;
            fill[v as usize] += 1;
        }
    }
    (0..np as u32)
        .into_par_iter()
        .map_init(
            || (Vec::<u32>::new(), Vec::<u32>::new()),
            |(nb, parent), v| {
                let ts = &inc[start[v as usize]..start[v as usize + 1]];
                if ts.len() < 2 {
                    return None;
                }
                let other = |t: u32| {
                    let tri = s.tris[t as usize];
                    let k = tri.iter().position(|&x| x == v).unwrap_or(0);
                    (tri[(k + 1) % 3], tri[(k + 2) % 3])
                };
                nb.clear();
                for &t in ts {
                    let (a, b) = other(t);
                    nb.push(a);
                    nb.push(b);
                }
                nb.sort_unstable();
                nb.dedup();
                parent.clear();
                parent.extend(0..nb.len() as u32);
                fn find(p: &mut [u32], mut x: u32) -> u32 {
                    while p[x as usize] != x {
                        p[x as usize] = p[p[x as usize] as usize];
                        x = p[x as usize];
                    }
                    x
                }
                let mut comps = nb.len() as u32;
                for &t in ts {
                    let (a, b) = other(t);
                    let ia = nb.binary_search(&a).unwrap_or(0) as u32;
                    let ib = nb.binary_search(&b).unwrap_or(0) as u32;
                    let (ra, rb) = (find(parent, ia), find(parent, ib));
                    if ra != rb {
                        parent[ra as usize] = rb;
                        comps -= 1;
                    }
                }
                (comps > 1).then_some((v, comps))
            },
        )
        .flatten()
        .collect()
}

/// Triangles whose three points are collinear (exact), repeated ids included.
pub(super) fn zero_area(s: &Surface) -> Vec<u32> {
    (0..s.tris.len() as u32)
        .into_par_iter()
        .filter(|&t| {
            let [a, b, c] = s.tris[t as usize].map(|v| s.points[v as usize]);
            is_collinear(a, b, c)
        })
        .collect()
}

/// (earliest triangle, later copy) for every triangle whose vertex set
/// equals an earlier one's, ordered by the later id.
pub(super) fn duplicates(s: &Surface) -> Vec<(u32, u32)> {
    let mut keys: Vec<([u32; 3], u32)> = s
        .tris
        .par_iter()
        .enumerate()
        .map(|(i, t)| {
            let mut k = *t;
            k.sort_unstable();
            (k, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j].0 == keys[i].0 {
            out.push((keys[i].1, keys[j].1));
            j += 1;
        }
        i = j;
    }
    out.sort_unstable_by_key(|&(_, b)| b);
    out
}
