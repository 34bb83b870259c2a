//! The DDG built by the passes themselves: §5's coarse mesh made with
//! §7's scheme. No DDG exists yet to cut the domain into regions, so each
//! parallel pass takes convex cells instead: a recursive bisection of the
//! front's face centroids into `parts` cells (pass 1 in the coordinate
//! frame, the later ones in rotated frames, so that their walls cross the
//! earlier walls instead of lying on them). A cell is convex, so an edge
//! whose two ends lie inside it stays inside. What the parallel passes
//! leave is closed by the serial pass of the fine mesher (pass 4).
//!
//! The cells follow from the front and `parts` alone, and the passes'
//! messages are ordered by part: the DDG depends on `parts`, never on the
//! threads.
use crate::{parallel_pass, peel_stuck, seed_parts, serial_pass, Part, PassError, Regions, Sizes};
use parafront_comm::Comm;
use parafront_ddg::{self as ddg, Ddg};
use parafront_front::RegionFilter;
use parafront_geom::{cross, dist, dot, norm, sub, Aabb, P3};
use parafront_mesh::PointId;
use std::time::Instant;

/// What building the DDG did, pass by pass.
#[derive(Clone, Debug, Default)]
pub struct DdgBuildStats {
    /// Tets made in each parallel pass, then in the serial pass (tets
    /// peeled later are still counted where they were made).
    pub pass_tets: Vec<usize>,
    /// Wall seconds of each pass, in the same order.
    pub pass_seconds: Vec<f64>,
    /// The size field (the surface sizes grown by `c - 1` per unit length).
    pub field_seconds: f64,
    /// Merging the parts into one mesh and its face neighbours.
    pub merge_seconds: f64,
}

#[derive(Clone, Copy, Debug)]
enum Node {
    Leaf(u32),
    Cut {
        axis: usize,
        at: f64,
        lo: u32,
        hi: u32,
    },
}

/// `parts` convex cells: the leaves of a bisection tree in the frame
/// `rot` (rows: the frame's axes). A point within `margin` of a cut
/// belongs to no cell.
pub(crate) struct Cells {
    rot: [P3; 3],
    nodes: Vec<Node>,
    margin: f64,
    bounds: Vec<Aabb>,
}

impl Cells {
    /// Bisects `pts` (equal weights) into `parts` cells, each cut across
    /// the longest extent of its points in the frame `rot`, halfway
    /// between the two points on either side of the cut. Deterministic:
    /// ties go by index. `domain` bounds every point the cells will be
    /// asked about (for the cells' boxes).
    pub(crate) fn new(pts: &[P3], parts: usize, rot: [P3; 3], domain: &Aabb) -> Cells {
        let q: Vec<P3> = pts.iter().map(|&p| rotate(&rot, p)).collect();
        let mut ids: Vec<u32> = (0..q.len() as u32).collect();
        // The domain's box in the rotated frame: the box of its corners.
        let mut rbox = Aabb::EMPTY;
        for c in corners(domain) {
            rbox.grow(rotate(&rot, c));
        }
        let mut c = Cells {
            rot,
            nodes: Vec::new(),
            margin: 1e-9 * domain.diagonal().max(1e-300),
            bounds: vec![Aabb::EMPTY; parts],
        };
        c.split(&q, &mut ids, 0, parts.max(1) as u32, rbox, domain);
        c
    }

    fn split(
        &mut self,
        q: &[P3],
        ids: &mut [u32],
        first: u32,
        parts: u32,
        rbox: Aabb,
        domain: &Aabb,
    ) -> u32 {
        let me = self.nodes.len() as u32;
        if parts <= 1 || ids.len() < 2 {
            self.nodes.push(Node::Leaf(first));
            // The cell's box in the original frame: the rotated box's
            // corners turned back, clipped to the domain.
            let mut b = Aabb::EMPTY;
            for c in corners(&rbox) {
                b.grow(unrotate(&self.rot, c));
            }
            let b = b.inflated(self.margin);
            self.bounds[first as usize] = Aabb {
                min: [0, 1, 2].map(|k| b.min[k].max(domain.min[k])),
                max: [0, 1, 2].map(|k| b.max[k].min(domain.max[k])),
            };
            return me;
        }
        self.nodes.push(Node::Leaf(first)); // replaced below
        let ax = Aabb::from_points(ids.iter().map(|&i| &q[i as usize])).longest_axis();
        ids.sort_unstable_by(|&a, &b| {
            q[a as usize][ax]
                .total_cmp(&q[b as usize][ax])
                .then(a.cmp(&b))
        });
        let left = parts / 2;
        let cut = (ids.len() * left as usize / parts as usize).clamp(1, ids.len() - 1);
        let at = 0.5 * (q[ids[cut - 1] as usize][ax] + q[ids[cut] as usize][ax]);
        let (mut lo_box, mut hi_box) = (rbox, rbox);
        lo_box.max[ax] = at;
        hi_box.min[ax] = at;
        let (a, b) = ids.split_at_mut(cut);
        let lo = self.split(q, a, first, left, lo_box, domain);
        let hi = self.split(q, b, first + left, parts - left, hi_box, domain);
        self.nodes[me as usize] = Node::Cut {
            axis: ax,
            at,
            lo,
            hi,
        };
        me
    }
}

impl Regions for Cells {
    fn owner(&self, p: P3) -> Option<u32> {
        let q = rotate(&self.rot, p);
        let mut n = 0usize;
        loop {
            match self.nodes[n] {
                Node::Leaf(k) => return Some(k),
                Node::Cut { axis, at, lo, hi } => {
                    let d = q[axis] - at;
                    if d.abs() <= self.margin || d.is_nan() {
                        return None;
                    }
                    n = if d < 0.0 { lo } else { hi } as usize;
                }
            }
        }
    }
    fn bounds(&self) -> Vec<Aabb> {
        self.bounds.clone()
    }
    fn filter(&self, k: u32) -> Box<dyn RegionFilter + '_> {
        Box::new(CellFilter { cells: self, k })
    }
}

/// Region filter of one cell: points inside it, off its walls; a cell is
/// convex, so an edge with both ends inside is inside.
struct CellFilter<'a> {
    cells: &'a Cells,
    k: u32,
}

impl RegionFilter for CellFilter<'_> {
    fn point_ok(&self, p: P3) -> bool {
        self.cells.owner(p) == Some(self.k)
    }
    fn edge_ok(&self, a: P3, b: P3) -> bool {
        self.point_ok(a) && self.point_ok(b)
    }
}

fn rotate(r: &[P3; 3], p: P3) -> P3 {
    [dot(r[0], p), dot(r[1], p), dot(r[2], p)]
}

fn unrotate(r: &[P3; 3], q: P3) -> P3 {
    [0, 1, 2].map(|k| r[0][k] * q[0] + r[1][k] * q[1] + r[2][k] * q[2])
}

fn corners(b: &Aabb) -> [P3; 8] {
    let mut c = [[0.0; 3]; 8];
    for (i, x) in c.iter_mut().enumerate() {
        for (k, xk) in x.iter_mut().enumerate() {
            *xk = if i >> k & 1 == 0 { b.min[k] } else { b.max[k] };
        }
    }
    c
}

/// The frame of parallel pass `j`: the coordinate axes for the first, then
/// rotations about fixed, unrelated axes (Rodrigues), so that no wall of
/// one pass lies along a wall of another.
fn frame(j: usize) -> [P3; 3] {
    const AXES: [(P3, f64); 3] = [
        ([0.0, 0.0, 1.0], 0.0),
        ([1.0, 2.0, 3.0], 0.9),
        ([3.0, -1.0, 2.0], 1.3),
    ];
    let (a, angle) = AXES[j % AXES.len()];
    let n = parafront_geom::normalize(a);
    let (s, c) = angle.sin_cos();
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (k, x) in row.iter_mut().enumerate() {
            let delta = if i == k { 1.0 } else { 0.0 };
            // Levi-Civita term of the cross-product matrix.
            let cross = match (i, k) {
                (0, 1) => -n[2],
                (0, 2) => n[1],
                (1, 0) => n[2],
                (1, 2) => -n[0],
                (2, 0) => -n[1],
                (2, 1) => n[0],
                _ => 0.0,
            };
            *x = c * delta + s * cross + (1.0 - c) * n[i] * n[k];
        }
    }
    r
}

/// The DDG's surface points get this many times their mean edge length
/// as their size, and its fronts let a tet grow that tall over a face
/// (`FrontOptions::max_growth`, the fine mesh's 2). §5 multiplies the
/// initial sizes by `c`; tall tets on neighbouring surface triangles share
/// their apexes. sphere_1e6: 131k tets at 2 instead of 213k at 1.6, in half
/// the time.
pub const FIRST_LAYER: f64 = 2.0;

/// The first layer of a deep domain ([`DEEP`]). sphere_5e6 (P = 8, one
/// thread): 362k tets in 5.0 s at 2, 299k in 4.8 s at 2.5, 250k in 4.7 s
/// at 3, 200k in 3.7 s at 4, 177k in 4.3 s at 5, 162k in 5.0 s at 6 (each
/// front query then holds more surface faces).
pub const DEEP_FIRST_LAYER: f64 = 4.0;

/// A domain this many mean surface edges deep (volume over area) takes
/// the taller first layer: only there is the DDG's cost a share worth
/// cutting (tets per surface triangle grow with the depth). Elsewhere tall
/// tets wedge in thin walls and narrow gaps: at 4 the DDG fails on the tray
/// after 133 s instead of 15 s, and on fertility at P = 32 (depth 1.7).
/// Depths: the CAD plates 0.1-0.4, the other corpus parts 1.7-9.6 (the
/// skull), the 1e5 bench surfaces 3.2-5.8, sphere_1e6 12.5, box2holes_5e6
/// 11.4 (no faster at 4: 4.7 s against 4.9), sphere_5e6 21.3.
pub const DEEP: f64 = 10.0;

/// Volume over area of the closed front `faces`, in mean edge lengths.
pub(crate) fn depth(points: &[P3], faces: &[[u32; 3]]) -> f64 {
    let (mut area, mut edges) = (0.0, 0.0);
    for f in faces {
        let [a, b, c] = f.map(|i| points[i as usize]);
        area += 0.5 * norm(cross(sub(b, a), sub(c, a)));
        edges += dist(a, b) + dist(b, c) + dist(c, a);
    }
    let h = edges / (3 * faces.len()).max(1) as f64;
    enclosed_volume(points, faces) / (area * h).max(1e-300)
}

/// The DDG's largest size on `parts` parts, as a share of a part's
/// width (the cube root of its volume). The shifts of passes 2 and 3
/// move each wall by two layers of DDG tets; where a DDG tet is as wide
/// as a part, two layers reach every part, and the front that pass 1
/// leaves there all goes to one part in pass 2 (sphere_5e6 on 16 parts:
/// 30 % of pass 2 on one). `ParOptions::ddg_cap`.
pub const DDG_CAP: f64 = 0.2;

/// `cap` times a part's width: no cap on one part.
fn size_cap(points: &[P3], faces: &[[u32; 3]], parts: usize, cap: f64) -> f64 {
    if parts <= 1 {
        return f64::INFINITY;
    }
    cap * (enclosed_volume(points, faces) / parts as f64).cbrt()
}

/// The volume the closed front `faces` encloses.
fn enclosed_volume(points: &[P3], faces: &[[u32; 3]]) -> f64 {
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| points[i as usize]);
            dot(a, cross(b, c)) / 6.0
        })
        .sum::<f64>()
        .abs()
}

/// Recovery rounds of the serial pass's tries. Every smooth surface closes
/// by the second try (the corpus and the 1e5 bench surfaces, P = 8 to
/// 128); what does not is a thin CAD part, where more tries cost minutes
/// (the tray: 115 s) before the serial front builds the DDG anyway.
const DDG_SERIAL_ROUNDS: [u32; 2] = [1, 12];

/// Builds the DDG of the closed front `faces` (normals inward) with
/// growth `c` (the graded sizes of [`ddg::build`]): `passes` parallel
/// passes on `comm.parts()` convex cells each, then the serial pass on
/// what they left. The sizes are the DDG's own, from the front's edges
/// (the fine mesh's sizes do not enter). Under MPI each process runs the
/// passes of its own parts, and every process gets the whole DDG.
pub fn build_ddg<C: Comm>(
    points: &[P3],
    faces: &[[u32; 3]],
    c: f64,
    passes: usize,
    comm: &C,
) -> Result<(Ddg, DdgBuildStats), PassError> {
    build_ddg_at(
        points,
        faces,
        depth(points, faces),
        c,
        passes,
        DDG_CAP,
        comm,
    )
}

/// [`build_ddg`] for a front `depth` mean edges deep ([`depth`]): the
/// passes have it already, from their thin-part test.
pub(crate) fn build_ddg_at<C: Comm>(
    points: &[P3],
    faces: &[[u32; 3]],
    depth: f64,
    c: f64,
    passes: usize,
    cap: f64,
    comm: &C,
) -> Result<(Ddg, DdgBuildStats), PassError> {
    let t_all = Instant::now();
    let np = comm.parts();
    let mut st = DdgBuildStats::default();
    let t0 = Instant::now();
    let first = if depth >= DEEP {
        DEEP_FIRST_LAYER
    } else {
        FIRST_LAYER
    };
    let point_size: Vec<f64> = parafront_surface::mean_edge_lengths(points, faces)
        .iter()
        .map(|h| first * h)
        .collect();
    // The field grows from the same surface sizes (§5: the initial sizes
    // times the growth), not from the fine ones: from the fine ones, the
    // layer over the first one gets it the first one's size again, and the
    // DDG of sphere_5e6 has 429k tets instead of 362k.
    let field = ddg::GradedField::of_sizes(points, &point_size, (c - 1.0).max(0.0));
    // Only deep fronts grow DDG tets as wide as a part; on shallow ones a
    // cap at the first layer's size costs tets (spot on 32 parts: +4.2 %
    // against P = 1 instead of +2.9 %).
    let cap = if depth >= DEEP {
        size_cap(points, faces, np, cap).max(point_size.iter().cloned().fold(0.0, f64::max))
    } else {
        f64::INFINITY
    };
    let field = move |p: P3| field.size(p).min(cap);
    let sizes = Sizes {
        field: &field,
        max_growth: first,
    };
    st.field_seconds = t0.elapsed().as_secs_f64();
    let domain = Aabb::from_points(points.iter());
    let domain = domain.inflated(1e-6 * domain.diagonal().max(1e-300));

    let mut parts = seed_parts(comm.owned(), 1, points, &point_size, faces);
    let mut next_gid = points.len() as u32;
    let debug = tracing::enabled!(tracing::Level::DEBUG);
    for j in 0..passes {
        let t0 = Instant::now();
        // The cells split the faces still to advance (an all-gather of
        // their centroids, in part order).
        let cen = front_centroids(&parts, comm);
        if cen.is_empty() {
            break;
        }
        let cells = Cells::new(&cen, np, frame(j), &domain);
        let (tets, _) = parallel_pass(
            &mut parts,
            comm,
            &cells,
            sizes,
            (j as u8 + 1, None),
            &mut next_gid,
        )?;
        let peeled = peel_stuck(&mut parts, comm);
        crate::debug_check_parts(&parts, "a DDG pass");
        if debug {
            let fr: usize = parts.iter().map(|p| p.front.len()).sum();
            tracing::debug!(
                "ddg pass {}: tets {:?}, front left {fr}, {peeled} peeled, {:.3} s",
                j + 1,
                tets,
                t0.elapsed().as_secs_f64()
            );
        }
        st.pass_tets.push(tets.iter().sum());
        st.pass_seconds.push(t0.elapsed().as_secs_f64());
    }
    let t0 = Instant::now();
    // What the passes left is closed with the fine mesh's growth: the tall
    // tets that fill a smooth region can wedge a left-over pocket shut
    // (fertility at P = 32, the tray).
    let (made, _) = serial_pass(
        &mut parts,
        comm,
        Sizes::fine(&field),
        &mut next_gid,
        &DDG_SERIAL_ROUNDS,
        parafront_front::DEFAULT_FILL_AFTER,
    )?;
    if debug {
        tracing::debug!(
            "ddg serial pass: {made} tets, {:.3} s",
            t0.elapsed().as_secs_f64()
        );
    }
    st.pass_tets.push(made);
    st.pass_seconds.push(t0.elapsed().as_secs_f64());

    let t0 = Instant::now();
    // Every process gets every part's tets (the DDG is replicated: each
    // locates points in all of it), in part order, so the merge is the
    // same bytes everywhere.
    let all = comm.all_gather(
        parts
            .into_iter()
            .map(|p| (p.gid, p.pts, p.tets.to_vec()))
            .collect(),
    );
    let (pts, tets, neigh) = merge_parts(all, points.len(), next_gid as usize)?;
    st.merge_seconds = t0.elapsed().as_secs_f64();
    Ok((
        Ddg {
            points: pts,
            tets,
            adjacency: neigh.into(),
            n_input: points.len(),
            growth: c,
            seconds: t_all.elapsed().as_secs_f64(),
        },
        st,
    ))
}

/// The centroids of the faces the parts still have to advance, in part
/// order (an all-gather): what the next pass's cells split.
fn front_centroids<C: Comm>(parts: &[Part], comm: &C) -> Vec<P3> {
    comm.all_gather(
        parts
            .iter()
            .map(|p| {
                p.front
                    .iter()
                    .map(|f| {
                        let [a, b, c] = f.map(|i| p.pts[i as usize]);
                        parafront_geom::centroid3(a, b, c)
                    })
                    .collect::<Vec<P3>>()
            })
            .collect(),
    )
    .concat()
}

/// A part's points (global ids, positions) and tets (local ids), as the
/// merge takes them from every process.
type PartMesh = (Vec<u32>, Vec<P3>, Vec<[u32; 4]>);

/// One mesh of the parts (every part, in part order): the `n_input` input
/// points first (their ids), then the new points (global ids below `n`) in
/// order, those no tet uses left out; tets by part; and its adjacency.
#[allow(clippy::type_complexity)]
fn merge_parts(
    parts: Vec<PartMesh>,
    n_input: usize,
    n: usize,
) -> Result<(Vec<P3>, Vec<[u32; 4]>, Vec<parafront_mesh::FaceRef>), PassError> {
    let mut at: Vec<P3> = vec![[0.0; 3]; n];
    let mut used = vec![false; n];
    used[..n_input].iter_mut().for_each(|u| *u = true);
    let mut tets: Vec<[u32; 4]> = Vec::new();
    for (gid, ppts, ptets) in &parts {
        for (i, &g) in gid.iter().enumerate() {
            at[g as usize] = ppts[i];
        }
        for t in ptets {
            let tv = t.map(|i| gid[i as usize]);
            for &g in &tv {
                used[g as usize] = true;
            }
            tets.push(tv);
        }
    }
    drop(parts);
    let mut map = vec![u32::MAX; n];
    let mut pts = Vec::with_capacity(n);
    for g in 0..n {
        if used[g] {
            map[g] = pts.len() as u32;
            pts.push(at[g]);
        }
    }
    for t in &mut tets {
        *t = t.map(|g| map[g as usize]);
    }
    let typed: &[[PointId; 4]] = bytemuck::cast_slice(&tets);
    let neigh = parafront_mesh::face_neighbours(typed).map_err(PassError::DdgMerge)?;
    Ok((pts, tets, neigh))
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    /// A ball of radius r is r / 3 deep; halving its edges doubles the
    /// depth in edges; a plate is about half its thickness deep. The
    /// front's normals point in, as `build_ddg` takes them.
    #[test]
    fn depth_is_volume_over_area_in_edges() {
        let inward = |s: &parafront_surface::Surface| -> Vec<[u32; 3]> {
            s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect()
        };
        let h = |s: &parafront_surface::Surface| {
            let m = parafront_surface::mean_edge_lengths(&s.points, &s.tris);
            m.iter().sum::<f64>() / m.len() as f64
        };
        let a = generate::icosphere([0.0; 3], 2.0, 3);
        let b = generate::icosphere([0.0; 3], 2.0, 4);
        let (da, db) = (depth(&a.points, &inward(&a)), depth(&b.points, &inward(&b)));
        // The area and volume of the polyhedron are a little under the
        // ball's, the mean edge is per point rather than per edge.
        assert!((da * h(&a) - 2.0 / 3.0).abs() < 0.05, "{da}");
        assert!((db / da - 2.0).abs() < 0.05, "{da} {db}");
        let p = generate::needle_plate(1.0, 8);
        assert!(depth(&p.points, &inward(&p)) < 1.0);
        assert!(db < DEEP, "a 1e3-triangle ball keeps the usual first layer");
    }

    #[test]
    fn frames_are_rotations() {
        for j in 0..3 {
            let r = frame(j);
            for a in 0..3 {
                for b in 0..3 {
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((dot(r[a], r[b]) - want).abs() < 1e-12);
                }
            }
            let p = [0.3, -1.2, 2.5];
            let back = unrotate(&r, rotate(&r, p));
            assert!((0..3).all(|k| (back[k] - p[k]).abs() < 1e-12));
        }
    }

    #[test]
    fn cells_split_points_evenly_and_keep_off_their_walls() {
        let pts: Vec<P3> = (0..1000)
            .map(|i| {
                let x = i as f64;
                [(x * 0.37).sin(), (x * 0.71).cos(), (x * 0.13).sin()]
            })
            .collect();
        let dom = Aabb::from_points(pts.iter()).inflated(0.01);
        for j in 0..3 {
            let c = Cells::new(&pts, 8, frame(j), &dom);
            let mut count = [0usize; 8];
            for &p in &pts {
                if let Some(k) = c.owner(p) {
                    count[k as usize] += 1;
                    assert!(c.bounds[k as usize].contains(p));
                }
            }
            assert!(count.iter().all(|&n| (110..=126).contains(&n)), "{count:?}");
        }
    }
}
