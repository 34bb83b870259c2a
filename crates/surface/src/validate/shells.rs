//! Shells (edge-connected components) and how the closed ones nest.
//!
//! Shell `i` is inside shell `j` when a vertex of `i` is inside `j`, decided
//! by the parity of exact transversal crossings along a ray; a ray that
//! grazes an edge, a vertex or a plane is dropped and another direction
//! drawn. Depth = number of closed shells containing the shell. Inside
//! material a shell with negative volume is a void (its triangles point into
//! it) and one with positive volume an embedded body (a region of its own);
//! inside a void only a body (positive) may float.
use super::bvh::Bvh;
use super::selfint::tri_boxes;
use super::topology::Edges;
use crate::Surface;
use parafront_geom::intersect::segment_triangle_parity;
use parafront_geom::{Aabb, P3};
use rayon::prelude::*;

/// What a shell is, from its nesting depth and the sign of its volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShellKind {
    /// Depth 0: bounds the domain from outside; must have positive volume.
    Outer,
    /// A cavity inside material: negative volume.
    Void,
    /// A body embedded in material or floating in a void: positive volume.
    Inner,
    /// Has an edge not used by exactly two triangles: nesting not computed.
    NotClosed,
}

impl ShellKind {
    /// A plain-words name of the kind, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            ShellKind::Outer => "outer shell",
            ShellKind::Void => "void",
            ShellKind::Inner => "inner body",
            ShellKind::NotClosed => "not closed",
        }
    }
}

/// An edge-connected component of a surface's triangles, and how it nests
/// among the closed shells.
#[derive(Clone, Debug, PartialEq)]
pub struct Shell {
    /// Triangle ids, ascending.
    pub tris: Vec<u32>,
    /// Signed enclosed volume (positive when the normals point outward).
    pub volume: f64,
    /// Number of closed shells containing this one.
    pub depth: u32,
    /// The innermost shell containing this one.
    pub parent: Option<u32>,
    /// What the shell is: outer shell, void, inner body, or not closed.
    pub kind: ShellKind,
}

impl Shell {
    /// The volume sign matches the kind (always true when not closed).
    pub fn orientation_ok(&self) -> bool {
        match self.kind {
            ShellKind::Outer | ShellKind::Inner => self.volume > 0.0,
            ShellKind::Void => self.volume < 0.0,
            ShellKind::NotClosed => true,
        }
    }
}

/// A material region: inside shell `outer` (an outer shell or an inner
/// body) and outside each of its `voids`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// The shell that bounds the region from outside (an index into the shells).
    pub outer: u32,
    /// The voids directly inside `outer` (their parent), as shell indices.
    pub voids: Vec<u32>,
}

/// The material regions described by nested shells.
pub fn regions(shells: &[Shell]) -> Vec<Region> {
    shells
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s.kind, ShellKind::Outer | ShellKind::Inner))
        .map(|(i, _)| Region {
            outer: i as u32,
            voids: shells
                .iter()
                .enumerate()
                .filter(|(_, v)| v.kind == ShellKind::Void && v.parent == Some(i as u32))
                .map(|(k, _)| k as u32)
                .collect(),
        })
        .collect()
}

/// The shells of a surface and their nesting. Empty when a triangle names a
/// vertex past the end of the point list.
pub fn shells(s: &Surface) -> Vec<Shell> {
    let np = s.points.len();
    if s.tris.iter().flatten().any(|&v| v as usize >= np) {
        return Vec::new();
    }
    shells_with(s, &Edges::build(s))
}

fn find(p: &mut [u32], mut x: u32) -> u32 {
    while p[x as usize] != x {
        p[x as usize] = p[p[x as usize] as usize];
        x = p[x as usize];
    }
    x
}

pub(super) fn shells_with(s: &Surface, edges: &Edges) -> Vec<Shell> {
    let n = s.tris.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for e in 0..edges.n_edges() {
        let r = edges.run(e);
        for w in r.windows(2) {
            let (a, b) = (find(&mut parent, w[0].1 / 3), find(&mut parent, w[1].1 / 3));
            if a != b {
                // Keep the smaller triangle as root: shells come out ordered.
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut label = vec![u32::MAX; n];
    let mut out: Vec<Shell> = Vec::new();
    for t in 0..n as u32 {
        let r = find(&mut parent, t) as usize;
        if label[r] == u32::MAX {
            label[r] = out.len() as u32;
            out.push(Shell {
                tris: Vec::new(),
                volume: 0.0,
                depth: 0,
                parent: None,
                kind: ShellKind::Outer,
            });
        }
        out[label[r] as usize].tris.push(t);
        label[t as usize] = label[r];
    }
    for e in 0..edges.n_edges() {
        let r = edges.run(e);
        if r.len() != 2 {
            out[label[(r[0].1 / 3) as usize] as usize].kind = ShellKind::NotClosed;
        }
    }
    let boxes: Vec<Aabb> = out
        .iter()
        .map(|sh| {
            Aabb::from_points(
                sh.tris
                    .iter()
                    .flat_map(|&t| s.tris[t as usize].iter().map(|&v| &s.points[v as usize])),
            )
        })
        .collect();
    for (sh, bb) in out.iter_mut().zip(&boxes) {
        sh.volume = volume(s, &sh.tris, bb.center());
    }
    nest(s, &mut out, &boxes);
    out
}

fn volume(s: &Surface, tris: &[u32], c: P3) -> f64 {
    use parafront_geom::{cross, dot, sub};
    let v: f64 = tris
        .iter()
        .map(|&t| {
            let [a, b, d] = s.tris[t as usize].map(|v| sub(s.points[v as usize], c));
            dot(a, cross(b, d))
        })
        .sum();
    v / 6.0
}

fn nest(s: &Surface, out: &mut [Shell], boxes: &[Aabb]) {
    let closed: Vec<u32> = (0..out.len() as u32)
        .filter(|&i| out[i as usize].kind != ShellKind::NotClosed)
        .collect();
    if closed.len() < 2 {
        return;
    }
    // Candidate containers: closed shells whose box holds this shell's box.
    let sbvh = Bvh::build(closed.clone(), boxes);
    let cand: Vec<Vec<u32>> = closed
        .par_iter()
        .map_init(Vec::new, |stack, &i| {
            let bi = &boxes[i as usize];
            let mut c = Vec::new();
            sbvh.query(bi, boxes, stack, |j| {
                let bj = &boxes[j as usize];
                if j != i && bj.contains(bi.min) && bj.contains(bi.max) {
                    c.push(j);
                }
            });
            c.sort_unstable();
            c
        })
        .collect();
    let mut need = vec![false; out.len()];
    for &j in cand.iter().flatten() {
        need[j as usize] = true;
    }
    let tboxes = tri_boxes(s);
    let tbvh: Vec<Option<Bvh>> = (0..out.len())
        .into_par_iter()
        .map(|j| need[j].then(|| Bvh::build(out[j].tris.clone(), &tboxes)))
        .collect();
    let contains: Vec<Vec<u32>> = closed
        .par_iter()
        .zip(&cand)
        .map(|(&i, c)| {
            c.iter()
                .copied()
                .filter(|&j| {
                    let inner = &out[i as usize].tris;
                    let b = tbvh[j as usize].as_ref().expect("built for candidates");
                    shell_inside(s, inner, b, &tboxes, &boxes[j as usize])
                })
                .collect()
        })
        .collect();
    for (k, &i) in closed.iter().enumerate() {
        out[i as usize].depth = contains[k].len() as u32;
    }
    for (k, &i) in closed.iter().enumerate() {
        out[i as usize].parent = contains[k]
            .iter()
            .copied()
            .max_by_key(|&j| out[j as usize].depth);
    }
    // Outside in, so a parent's kind is known first. Inside material, a
    // negative shell is a void and a positive one an embedded body (its
    // own region: an interface); inside a void only a body can float.
    let mut order: Vec<u32> = closed.clone();
    order.sort_by_key(|&i| out[i as usize].depth);
    for i in order {
        let kind = match out[i as usize].parent {
            None => ShellKind::Outer,
            Some(p) if out[p as usize].kind == ShellKind::Void => ShellKind::Inner,
            Some(_) if out[i as usize].volume < 0.0 => ShellKind::Void,
            Some(_) => ShellKind::Inner,
        };
        out[i as usize].kind = kind;
    }
}

/// A vertex of shell `a` is inside the closed shell whose triangles are in
/// `b`. Tries a few vertices, since one may lie on `b` (shells touching at
/// a point).
fn shell_inside(s: &Surface, a: &[u32], b: &Bvh, tboxes: &[Aabb], bb: &Aabb) -> bool {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64 ^ ((a[0] as u64) << 20) ^ b.order[0] as u64;
    let mut stack = Vec::new();
    for &t in a.iter().take(8) {
        for &v in &s.tris[t as usize] {
            let q = s.points[v as usize];
            if let Some(inside) = point_inside(s, q, b, tboxes, bb, &mut seed, &mut stack) {
                return inside;
            }
        }
    }
    false
}

fn next(seed: &mut u64) -> f64 {
    // xorshift64*: a fixed sequence keeps the answer reproducible.
    *seed ^= *seed >> 12;
    *seed ^= *seed << 25;
    *seed ^= *seed >> 27;
    let x = seed.wrapping_mul(0x2545_f491_4f6c_dd1d);
    (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Parity of exact crossings along a segment from `q` to beyond `bb`;
/// `None` when every direction tried grazes something (or `q` lies on the
/// shell). Directions are near an axis so the segment's box stays thin and
/// the tree prunes well; the small random tilt avoids grazing symmetric
/// meshes.
fn point_inside(
    s: &Surface,
    q: P3,
    tris: &Bvh,
    tboxes: &[Aabb],
    bb: &Aabb,
    seed: &mut u64,
    stack: &mut Vec<u32>,
) -> Option<bool> {
    if !bb.contains(q) {
        return Some(false);
    }
    let reach = 2.0 * (bb.diagonal() + parafront_geom::dist(q, bb.center()));
    let reach = if reach > 0.0 && reach.is_finite() {
        reach
    } else {
        1.0
    };
    for attempt in 0..12 {
        let mut d = [0.02 * next(seed), 0.02 * next(seed), 0.02 * next(seed)];
        d[attempt % 3] = if attempt % 2 == 0 { 1.0 } else { -1.0 };
        let r = parafront_geom::add(q, parafront_geom::scale(d, reach));
        if bb.contains(r) {
            continue;
        }
        let seg = Aabb::from_points([&q, &r]);
        let mut odd = false;
        let mut ok = true;
        tris.query(&seg, tboxes, stack, |t| {
            if !ok {
                return;
            }
            let [a, b, c] = s.tris[t as usize].map(|v| s.points[v as usize]);
            match segment_triangle_parity(q, r, a, b, c) {
                Some(x) => odd ^= x,
                None => ok = false,
            }
        });
        if ok {
            return Some(odd);
        }
    }
    None
}
