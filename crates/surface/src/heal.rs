//! Healing of dirty CAD surfaces: closes what a float rounding
//! opened, and nothing else.
//!
//! CAD exports sometimes write the same vertex twice with coordinates a
//! rounding apart (1e-16 where the other copy has 0). Exact welding then
//! leaves open edges and pinched vertices along those seams. [`heal`]
//! merges such vertices under strict rules:
//!
//! - only vertices on open edges are candidates, and they merge only with
//!   each other, never with a vertex of the closed part;
//! - two vertices merge when they are closer than `rel_tol` times the
//!   shortest edge at either of them (relative, since files come in mm, m
//!   or no unit), and never when an edge joins them: a real edge, however
//!   short, is never collapsed;
//! - a merge is kept only when it closes an open edge (two open edges then
//!   have the same ends); a pinch along a seam is an open edge's end, so
//!   it is removed by the same merges.
//!
//! The merged vertex keeps the coordinates of its lowest id, so no new
//! coordinates appear. Then the triangles the merge made degenerate
//! (repeated ids) are dropped, duplicates it made are dropped (a pair of
//! opposite copies cancels, a same-facing copy goes), and each shell it
//! touched is made consistently oriented, turning the fewest triangles.
//! Everything else is left for validation to report. With nothing to
//! merge the surface comes back unchanged, bit for bit.
//!
//! Candidates are found with a hash grid whose cells are the largest
//! tolerance wide: expected O(n) over the boundary vertices.

use crate::Surface;
use parafront_geom::{dist, P3};
use std::collections::HashMap;
use std::fmt;

/// Options of [`heal`]; `Default` gives the documented defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct HealOptions {
    /// Largest merge distance as a fraction of the shortest edge at either
    /// vertex (default 1e-3). The seams of the corpus's dirty files are
    /// 1e-12 of their edges or less; real features start near 1.
    pub rel_tol: f64,
}

impl Default for HealOptions {
    fn default() -> Self {
        HealOptions { rel_tol: 1e-3 }
    }
}

/// What [`heal`] changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HealReport {
    /// Open edges before healing.
    pub open_edges: usize,
    /// Vertices merged into another one (removed from the point list).
    pub vertices_merged: usize,
    /// Places where vertices merged (groups of merged vertices).
    pub groups: usize,
    /// Triangles dropped because the merge repeated a vertex in them.
    pub tris_degenerate: usize,
    /// Triangles dropped because the merge made them copies of others.
    pub tris_duplicate: usize,
    /// Shells whose orientation was made consistent, and triangles turned.
    pub shells_flipped: usize,
    /// Triangles turned in those shells.
    pub tris_flipped: usize,
    /// Largest distance a vertex moved, absolute and over the shortest
    /// edge at it.
    pub max_distance: f64,
    /// The largest ratio of a merge's distance to the shortest edge at its
    /// vertices (the largest ratio, not the ratio of the largest move).
    pub max_relative: f64,
}

impl HealReport {
    /// True when the surface was changed.
    pub fn changed(&self) -> bool {
        self.vertices_merged > 0
    }
    /// Triangles dropped in all: degenerate and duplicate.
    pub fn tris_dropped(&self) -> usize {
        self.tris_degenerate + self.tris_duplicate
    }
}

impl fmt::Display for HealReport {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        if !self.changed() {
            return write!(f, "heal: nothing to merge, surface unchanged");
        }
        write!(
            f,
            "heal: merged {} vertices in {} places (largest distance {:.3e}, {:.1e} of the shortest edge there), dropped {} triangles ({} degenerate, {} duplicate), turned {} triangles in {} shells",
            self.vertices_merged,
            self.groups,
            self.max_distance,
            self.max_relative,
            self.tris_dropped(),
            self.tris_degenerate,
            self.tris_duplicate,
            self.tris_flipped,
            self.shells_flipped
        )
    }
}

/// A healed surface, its report, and where each input point went.
#[derive(Clone, Debug, PartialEq)]
pub struct Healed {
    /// The healed surface, renumbered.
    pub surface: Surface,
    /// What the healing changed.
    pub report: HealReport,
    /// Input point id -> output point id.
    pub point_map: Vec<u32>,
}

fn ekey(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

/// Union-find over point ids, `find` with path halving.
struct Dsu(Vec<u32>);
impl Dsu {
    fn new(n: usize) -> Dsu {
        Dsu((0..n as u32).collect())
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            self.0[x as usize] = self.0[self.0[x as usize] as usize];
            x = self.0[x as usize];
        }
        x
    }
    /// Joins the two sets under the lower root (the merged point keeps the
    /// lowest id's coordinates).
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

/// Heals `s` (see the module doc). A surface with out-of-range ids or
/// non-finite points comes back unchanged: validation reports those.
pub fn heal(s: &Surface, opts: &HealOptions) -> Healed {
    let np = s.points.len();
    let unchanged = |open_edges| Healed {
        surface: s.clone(),
        report: HealReport {
            open_edges,
            ..Default::default()
        },
        point_map: (0..np as u32).collect(),
    };
    if s.tris.iter().flatten().any(|&v| v as usize >= np)
        || s.tris
            .iter()
            .flatten()
            .any(|&v| s.points[v as usize].iter().any(|x| !x.is_finite()))
    {
        return unchanged(0);
    }
    // Undirected edges with their use counts; self-loops left out.
    let mut keys: Vec<u64> = s
        .tris
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|(a, b)| a != b)
        .map(|(a, b)| ekey(a, b))
        .collect();
    keys.sort_unstable();
    let mut edges: Vec<u64> = Vec::with_capacity(keys.len() / 2);
    let mut open: Vec<[u32; 2]> = Vec::new();
    for g in keys.chunk_by(|a, b| a == b) {
        edges.push(g[0]);
        if g.len() == 1 {
            open.push([(g[0] >> 32) as u32, g[0] as u32]);
        }
    }
    if open.is_empty() {
        return unchanged(0);
    }
    let is_edge = |a: u32, b: u32| edges.binary_search(&ekey(a, b)).is_ok();

    // Shortest edge at each boundary vertex, and its tolerance.
    let mut boundary = vec![false; np];
    for e in &open {
        boundary[e[0] as usize] = true;
        boundary[e[1] as usize] = true;
    }
    let mut shortest = vec![f64::INFINITY; np];
    for &k in &edges {
        let (a, b) = ((k >> 32) as usize, (k as u32) as usize);
        if boundary[a] || boundary[b] {
            let l = dist(s.points[a], s.points[b]);
            shortest[a] = shortest[a].min(l);
            shortest[b] = shortest[b].min(l);
        }
    }
    let bverts: Vec<u32> = (0..np as u32).filter(|&v| boundary[v as usize]).collect();
    let tol = |v: u32| opts.rel_tol * shortest[v as usize];
    let pairs = candidate_pairs(&s.points, &bverts, &tol, &is_edge);

    // Merge the closest pairs first. Two groups join only when every two
    // of their vertices are within tolerance (no chains) and no edge joins
    // them (a real edge is never collapsed, directly or through a group).
    let mut dsu = Dsu::new(np);
    let mut members: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(_, a, b) in &pairs {
        let (ra, rb) = (dsu.find(a), dsu.find(b));
        if ra == rb {
            continue;
        }
        let ma = members.get(&ra).cloned().unwrap_or_else(|| vec![ra]);
        let mb = members.get(&rb).cloned().unwrap_or_else(|| vec![rb]);
        let far =
            |x: u32, y: u32| dist(s.points[x as usize], s.points[y as usize]) > tol(x).min(tol(y));
        if ma
            .iter()
            .any(|&x| mb.iter().any(|&y| is_edge(x, y) || far(x, y)))
        {
            continue;
        }
        dsu.union(ra, rb);
        let r = dsu.find(ra);
        members.remove(&ra.max(rb));
        let mut m = ma;
        m.extend(mb);
        members.insert(r, m);
    }
    let mut rep: Vec<u32> = (0..np as u32).map(|v| dsu.find(v)).collect();
    // Keep only the merges that close an open edge; dropping one may
    // unjustify another, so repeat until nothing changes.
    loop {
        let next = justified(&open, &rep, np);
        if next == rep {
            break;
        }
        rep = next;
    }
    if rep.iter().enumerate().all(|(v, &r)| v as u32 == r) {
        return unchanged(open.len());
    }
    apply(s, &rep, &shortest, open.len())
}

/// Pairs of boundary vertices (distance, a, b), a < b, closer than both
/// their tolerances and not joined by an edge; sorted by distance.
fn candidate_pairs(
    p: &[P3],
    bverts: &[u32],
    tol: &dyn Fn(u32) -> f64,
    is_edge: &dyn Fn(u32, u32) -> bool,
) -> Vec<(f64, u32, u32)> {
    let h = bverts.iter().map(|&v| tol(v)).fold(0.0f64, f64::max);
    // Cells `h` wide (or exact coordinates when every tolerance is 0).
    let cell = |q: P3| -> [i64; 3] {
        if h > 0.0 {
            q.map(|x| (x / h).floor() as i64)
        } else {
            q.map(|x| x.to_bits() as i64)
        }
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for &v in bverts {
        grid.entry(cell(p[v as usize])).or_default().push(v);
    }
    let mut out = Vec::new();
    for &a in bverts {
        let c = cell(p[a as usize]);
        let r = if h > 0.0 { 1 } else { 0 };
        for dx in -r..=r {
            for dy in -r..=r {
                for dz in -r..=r {
                    let k = [
                        c[0].saturating_add(dx),
                        c[1].saturating_add(dy),
                        c[2].saturating_add(dz),
                    ];
                    for &b in grid.get(&k).map_or(&[][..], |v| &v[..]) {
                        if b <= a {
                            continue;
                        }
                        let d = dist(p[a as usize], p[b as usize]);
                        if d <= tol(a).min(tol(b)) && !is_edge(a, b) {
                            out.push((d, a, b));
                        }
                    }
                }
            }
        }
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    out
}

/// The groups of `rep` cut down to the merges that close an open edge:
/// open edges whose ends map to the same pair are one edge closed, and the
/// distinct vertices at each end of such a set are merged.
fn justified(open: &[[u32; 2]], rep: &[u32], np: usize) -> Vec<u32> {
    let mut mapped: Vec<(u64, u32)> = open
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let (a, b) = (rep[e[0] as usize], rep[e[1] as usize]);
            (a != b).then(|| (ekey(a, b), i as u32))
        })
        .collect();
    mapped.sort_unstable();
    let mut dsu = Dsu::new(np);
    for g in mapped.chunk_by(|x, y| x.0 == y.0) {
        if g.len() < 2 {
            continue;
        }
        // Union the original ends that land on the same merged vertex.
        for w in g.windows(2) {
            let (e, f) = (open[w[0].1 as usize], open[w[1].1 as usize]);
            for &u in &e {
                for &x in &f {
                    if rep[u as usize] == rep[x as usize] {
                        dsu.union(u, x);
                    }
                }
            }
        }
    }
    (0..np as u32).map(|v| dsu.find(v)).collect()
}

/// Applies the merge `rep`, then drops, reorients and renumbers.
fn apply(s: &Surface, rep: &[u32], shortest: &[f64], open_edges: usize) -> Healed {
    let np = s.points.len();
    let mut report = HealReport {
        open_edges,
        ..Default::default()
    };
    let mut in_group = vec![false; np];
    for (v, &r) in rep.iter().enumerate() {
        if r as usize != v {
            in_group[v] = true;
            in_group[r as usize] = true;
            report.vertices_merged += 1;
            let d = dist(s.points[v], s.points[r as usize]);
            report.max_distance = report.max_distance.max(d);
            let l = shortest[v].min(shortest[r as usize]);
            if l > 0.0 {
                report.max_relative = report.max_relative.max(d / l);
            }
        }
    }
    report.groups = (0..np)
        .filter(|&v| rep[v] as usize == v && in_group[v])
        .count();

    // Remap; drop what the merge made degenerate.
    let mut keep: Vec<(usize, [u32; 3], bool)> = Vec::with_capacity(s.tris.len());
    for (i, t) in s.tris.iter().enumerate() {
        let m = t.map(|v| rep[v as usize]);
        let touched = t.iter().any(|&v| in_group[v as usize]);
        if touched && (m[0] == m[1] || m[1] == m[2] || m[2] == m[0]) {
            report.tris_degenerate += 1;
            continue;
        }
        keep.push((i, m, touched));
    }
    // Duplicates the merge made: same vertex set, at least one touched.
    let mut drop = vec![false; keep.len()];
    let mut sets: Vec<([u32; 3], usize)> = keep
        .iter()
        .enumerate()
        .map(|(j, (_, m, _))| {
            let mut k = *m;
            k.sort_unstable();
            (k, j)
        })
        .collect();
    sets.sort_unstable();
    for g in sets.chunk_by(|a, b| a.0 == b.0) {
        if g.len() < 2 || !g.iter().any(|&(_, j)| keep[j].2) {
            continue;
        }
        // Same-facing copies go; opposite copies cancel in pairs.
        let facing = |j: usize| {
            let m = keep[j].1;
            let k = m.iter().position(|&v| v == g[0].0[0]).unwrap_or(0);
            m[(k + 1) % 3] == g[0].0[1]
        };
        let (mut fwd, mut bwd): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
        for &(_, j) in g {
            if facing(j) {
                fwd.push(j)
            } else {
                bwd.push(j)
            }
        }
        let pairs = fwd.len().min(bwd.len());
        for &j in fwd[..pairs].iter().chain(&bwd[..pairs]) {
            drop[j] = true;
        }
        for side in [&fwd[pairs..], &bwd[pairs..]] {
            for &j in side.iter().skip(1) {
                drop[j] = true;
            }
        }
    }
    report.tris_duplicate = drop.iter().filter(|&&d| d).count();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut patch = Vec::new();
    let mut touched = Vec::new();
    for (j, (i, m, t)) in keep.into_iter().enumerate() {
        if !drop[j] {
            tris.push(m);
            patch.push(s.patch.get(i).copied().unwrap_or(0));
            touched.push(t);
        }
    }
    let (shells, flipped) = orient(&mut tris, &touched);
    report.shells_flipped = shells;
    report.tris_flipped = flipped;

    // Renumber: merged-away points go, the others keep their order.
    let mut new_id = vec![u32::MAX; np];
    let mut points = Vec::with_capacity(np - report.vertices_merged);
    for v in 0..np {
        if rep[v] as usize == v {
            new_id[v] = points.len() as u32;
            points.push(s.points[v]);
        }
    }
    let point_map: Vec<u32> = (0..np).map(|v| new_id[rep[v] as usize]).collect();
    for t in &mut tris {
        *t = t.map(|v| new_id[v as usize]);
    }
    Healed {
        surface: Surface {
            points,
            tris,
            patch,
            patch_names: s.patch_names.clone(),
        },
        report,
        point_map,
    }
}

/// Makes each edge-connected set of triangles that contains a touched one
/// consistently oriented across its two-triangle edges, turning the
/// smaller side. Sets that cannot be oriented (a Möbius band) are left for
/// validation. Returns (sets changed, triangles turned).
fn orient(tris: &mut [[u32; 3]], touched: &[bool]) -> (usize, usize) {
    let mut he: Vec<(u64, u32)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            he.push((ekey(tri[k], tri[(k + 1) % 3]), 3 * t as u32 + k as u32));
        }
    }
    he.sort_unstable();
    // Neighbour across each half-edge when its edge has exactly two uses.
    let mut nb = vec![u32::MAX; 3 * tris.len()];
    for g in he.chunk_by(|a, b| a.0 == b.0) {
        if g.len() == 2 {
            nb[g[0].1 as usize] = g[1].1;
            nb[g[1].1 as usize] = g[0].1;
        }
    }
    let start = |h: u32| tris[(h / 3) as usize][(h % 3) as usize];
    let mut seen = vec![false; tris.len()];
    let (mut shells, mut turned) = (0, 0);
    let mut turn: Vec<usize> = Vec::new();
    for seed in 0..tris.len() {
        if seen[seed] {
            continue;
        }
        // flip[t]: t must turn to agree with the seed.
        let mut comp: Vec<(usize, bool)> = vec![(seed, false)];
        let mut flip: HashMap<usize, bool> = HashMap::from([(seed, false)]);
        seen[seed] = true;
        let mut ok = true;
        let mut i = 0;
        while i < comp.len() {
            let (t, ft) = comp[i];
            i += 1;
            for k in 0..3 {
                let h = 3 * t as u32 + k;
                let o = nb[h as usize];
                if o == u32::MAX {
                    continue;
                }
                let u = (o / 3) as usize;
                // Consistent when the two traverse the edge in opposite
                // directions (taking each one's own flip into account).
                let same_dir = start(h) == start(o);
                let fu = ft ^ same_dir;
                match flip.get(&u) {
                    Some(&f) => ok &= f == fu,
                    None => {
                        flip.insert(u, fu);
                        seen[u] = true;
                        comp.push((u, fu));
                    }
                }
            }
        }
        if !ok || !comp.iter().any(|&(t, _)| touched[t]) {
            continue;
        }
        let n = comp.iter().filter(|c| c.1).count();
        if n == 0 || n == comp.len() {
            continue;
        }
        let turn_flagged = 2 * n <= comp.len();
        turn.extend(comp.iter().filter(|c| c.1 == turn_flagged).map(|c| c.0));
        shells += 1;
        turned += if turn_flagged { n } else { comp.len() - n };
    }
    for t in turn {
        tris[t].swap(1, 2);
    }
    (shells, turned)
}

/// Checks what [`heal`] promises between `input` and `h` (its result):
/// every output point is an input point bit for bit; a merged point moved
/// at most `rel_tol` times the shortest edge at it; no input edge had its
/// two ends merged; every output triangle is an input triangle mapped
/// (possibly turned), each input triangle used at most once; the counts
/// agree with the report. The tests run it after every heal.
pub fn check(input: &Surface, h: &Healed, opts: &HealOptions) -> Result<(), String> {
    let (s, r, map) = (&h.surface, &h.report, &h.point_map);
    if map.len() != input.points.len() {
        return Err(format!(
            "point map has {} entries for {} points",
            map.len(),
            input.points.len()
        ));
    }
    if input.points.len() - s.points.len() != r.vertices_merged {
        return Err(format!(
            "{} points became {}, report says {} merged",
            input.points.len(),
            s.points.len(),
            r.vertices_merged
        ));
    }
    if input
        .tris
        .iter()
        .flatten()
        .any(|&v| v as usize >= map.len())
    {
        return Err("an input triangle names a point out of range".into());
    }
    let mut shortest = vec![f64::INFINITY; input.points.len()];
    for t in &input.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if a == b {
                continue;
            }
            if map[a] == map[b] {
                return Err(format!("edge {a}-{b} collapsed"));
            }
            let l = dist(input.points[a], input.points[b]);
            shortest[a] = shortest[a].min(l);
            shortest[b] = shortest[b].min(l);
        }
    }
    let bits = |p: &P3| p.map(f64::to_bits);
    let known: std::collections::HashSet<[u64; 3]> = input.points.iter().map(bits).collect();
    for (v, &m) in map.iter().enumerate() {
        let q = *s
            .points
            .get(m as usize)
            .ok_or(format!("point {v} maps out of range"))?;
        let d = dist(q, input.points[v]);
        if d > opts.rel_tol * shortest[v] || d > r.max_distance {
            return Err(format!("point {v} moved {d}"));
        }
        if !known.contains(&bits(&q)) {
            return Err(format!("point {m} is not an input point"));
        }
    }
    if s.tris.len() + r.tris_dropped() != input.tris.len() {
        return Err(format!(
            "{} triangles became {}, report says {} dropped",
            input.tris.len(),
            s.tris.len(),
            r.tris_dropped()
        ));
    }
    let canon = |t: [u32; 3]| {
        let mut k = t;
        k.sort_unstable();
        k
    };
    let mut want: Vec<[u32; 3]> = input
        .tris
        .iter()
        .map(|t| canon(t.map(|v| map[v as usize])))
        .collect();
    want.sort_unstable();
    for t in &s.tris {
        match want.binary_search(&canon(*t)) {
            Ok(i) => {
                want.remove(i);
            }
            Err(_) => return Err(format!("triangle {t:?} is no input triangle")),
        }
    }
    if s.patch.len() != s.tris.len() {
        return Err("patch tags and triangles differ in number".into());
    }
    Ok(())
}
