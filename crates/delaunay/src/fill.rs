//! The constrained fill of a closed cavity, in order: the
//! Delaunay tetrahedralization of its points with its faces recovered by
//! flips and the tets outside removed; the cone from its kernel's deepest
//! point (a star-shaped cavity); the search (`search.rs`); the conforming
//! fill (`conform.rs`: edges split, split points moved inside); Steiner
//! points strictly inside it in the triangulation, under other
//! perturbations.
//! Every result is verified exactly.
use crate::conform::conform_fill;
use crate::flips::{key3, same_cycle};
use crate::predicates::is_flat;
use crate::recover::{crossings, recover_all};
use crate::search::search_fill;
use crate::tri::{InsertError, Triangulation, NONE, TET_FACES};
use parafront_geom::{centroid3, kernel::deepest_point, orient3d, tri_normal, P3};
use rustc_hash::{FxHashMap, FxHashSet};

/// Bounds on the fill's work.
#[derive(Clone, Debug)]
pub struct FillOptions {
    /// Steiner points the recovery may add inside the cavity.
    pub max_steiner: usize,
    /// Flips tried on one missing face before it counts as stuck. 32
    /// closed nothing on the corpus that 8 does not, and a cavity that
    /// stays open cost four times as long (the slot at size 0.1: 20 s of
    /// failing fills against 14).
    pub flips_per_face: usize,
    /// Triangulations with Steiner points tried last, each under another
    /// symbolic perturbation. 0 by default: on the corpus, the hard
    /// surfaces and the dirty ones (serial and 8 parts) none of 14 tries
    /// closed a cavity, at 0.02-0.25 s each; the caller's growth round
    /// closed them all.
    pub attempts: usize,
    /// Cavities with more faces get no Steiner points (their search is
    /// slow, and growing them serves better).
    pub max_steiner_faces: usize,
    /// Steps the search (the fill's second method) may take per try.
    pub search_nodes: usize,
    /// Steiner points the search may add (it may add `max_steiner` and one
    /// per eight faces, up to this).
    pub max_search_steiner: usize,
    /// Cavities with more faces are not searched.
    pub max_search_faces: usize,
    /// Points the conforming fill may put on the cavity's edges (each
    /// moved into the cavity at the end); 0 turns it off.
    pub max_split: usize,
    /// The conforming fill runs where flips left at most this many faces
    /// missing. With nested flips the tray's cracks that it closes have
    /// 14, and the thin slot's slabs at size 0.1, where it fails, 24-28:
    /// at 32 it ran there, 2-5 s a slab, and the slot took 10 s, not 4.
    pub max_conform_missing: usize,
    /// Go straight to the conforming fill in TetGen's order, in one
    /// triangulation: edges recovered by flips and kept, the rest split
    /// (`max_split` points at most), then faces, then the split points
    /// moved inside. For a whole region (a front that stalls on most of its
    /// faces at once, or cannot close it). Off by default.
    pub segments_first: bool,
    /// With `segments_first`: rounds of splits that leave more edges, or
    /// more face pieces, missing than the fewest so far before the fill
    /// gives up as diverging; 0 (default): never, the split budget bounds
    /// it. For the front's cavities, where a failure has a next step
    /// (recovery, growth); a region's last resort has none (the whole
    /// plate at size 7.5 went 59, 50, 61, 71, 60, ... edges missing and
    /// closed).
    pub headway_rounds: u32,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            max_steiner: 16,
            flips_per_face: 8,
            attempts: 0,
            max_steiner_faces: 200,
            search_nodes: 4000,
            max_search_steiner: 20,
            max_search_faces: 400,
            max_split: 4096,
            max_conform_missing: 20,
            segments_first: false,
            headway_rounds: 0,
        }
    }
}

impl FillOptions {
    /// The fill of a whole region's surface (GDT's start, §2): straight to
    /// the conforming fill (`segments_first`), with the default split
    /// budget. The front's region fills and the pipeline's fallback use
    /// it, so that they make the same fill.
    pub fn whole_region() -> FillOptions {
        FillOptions {
            segments_first: true,
            ..FillOptions::default()
        }
    }
}

/// How a cavity was closed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FillMethod {
    /// Constrained Delaunay: the triangulation of its points (and of any
    /// Steiner points) with every face recovered.
    Delaunay,
    /// Cones from one interior point that sees every face.
    Cone,
    /// Tets found by a search over the cavity's points (and Steiner
    /// points), each verified in the cavity.
    Search,
    /// Constrained Delaunay with the cavity's edges split where flips
    /// stall, each split point then moved into the cavity.
    Conform,
}

/// A cavity's fill.
#[derive(Debug, Clone)]
pub struct Fill {
    /// Points added strictly inside the cavity.
    pub steiner: Vec<P3>,
    /// Positive tets. Ids below `points.len()` are the caller's points;
    /// id `points.len() + k` is `steiner[k]`.
    pub tets: Vec<[u32; 4]>,
    /// Which method made the tets.
    pub method: FillMethod,
    /// Flips the recovery made.
    pub flips: usize,
}

/// Why a cavity was not filled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FillError {
    /// `faces` is empty.
    #[error("the cavity has no faces")]
    Empty,
    /// Face `.0` names point `.1`, which is not in `points`.
    #[error("cavity face {0} names point {1}, which does not exist")]
    BadIndex(usize, u32),
    /// Face `.0` names a point twice.
    #[error("cavity face {0} repeats a corner")]
    Degenerate(usize),
    /// Edge `.0`-`.1` (lower id first) is not used as often in each direction,
    /// so the faces do not close a cavity.
    #[error("cavity edge {0}-{1} is not used as often in each direction")]
    NotClosed(u32, u32),
    /// The faces enclose no positive volume (their normals point out, or the
    /// cavity is flat).
    #[error("the cavity's faces enclose no positive volume")]
    NotPositive,
    /// A point could not be inserted into the triangulation.
    #[error(transparent)]
    Insert(#[from] InsertError),
    /// No method filled the cavity: flips left faces missing, no interior point
    /// sees every face, and the search and the Steiner points (where tried)
    /// failed.
    #[error(
        "{missing} of {faces} cavity faces could not be recovered, and no point sees them all"
    )]
    Unrecovered {
        /// Cavity faces still missing from the last triangulation tried.
        missing: usize,
        /// Cavity faces in all.
        faces: usize,
    },
}

/// Fill the cavity bounded by `faces` (triangles of `points`, each with its
/// right-hand normal pointing into the cavity, as a front's faces): tets
/// whose boundary is exactly `faces`, each positive, with new points only
/// strictly inside the cavity.
pub fn fill_cavity(
    points: &[P3],
    faces: &[[u32; 3]],
    opts: &FillOptions,
) -> Result<Fill, FillError> {
    validate(points, faces)?;
    let mut local: Vec<u32> = faces.iter().flatten().copied().collect();
    local.sort_unstable();
    local.dedup();
    let mut flips = 0;
    if opts.segments_first {
        return conform(points, faces, &local, opts).ok_or(FillError::Unrecovered {
            missing: faces.len(),
            faces: faces.len(),
        });
    }
    // The Delaunay triangulation of its points, faces recovered by flips.
    let mut missing = match delaunay_fill(points, faces, &local, opts, false, &mut flips)? {
        Ok(f) => return Ok(f),
        Err(m) => m,
    };
    // Flips are stuck: a star-shaped cavity takes the cone.
    if let Some(f) = cone(points, faces) {
        return Ok(f);
    }
    // Then the search, which tiles what no single point sees.
    if faces.len() <= opts.max_search_faces {
        // A face in eight: each Steiner point costs a selection and a
        // search, so half the faces made the slot's failing fills 3 s
        // longer and closed no more.
        // At most `max_search_steiner` in all: closed searches used up to
        // 17 (idler_riser's 54-face cavity), failing ones spent 26 (round's
        // 86 faces, 0.33 s).
        let steiner = (opts.max_steiner + faces.len() / 8).min(opts.max_search_steiner);
        let search = |lp: &[P3], lf: &[[u32; 3]]| search_fill(lp, lf, opts.search_nodes, steiner);
        if let Some((steiner, tets)) = in_local_ids(points, faces, &local, search) {
            return Ok(Fill {
                steiner,
                tets,
                method: FillMethod::Search,
                flips,
            });
        }
    }
    // Then split the edges flips cannot recover, and move the split
    // points into the cavity, where flips left few faces missing.
    if missing <= opts.max_conform_missing {
        if let Some(f) = conform(points, faces, &local, opts) {
            return Ok(f);
        }
    }
    // Last, Steiner points in the triangulation, under other symbolic
    // perturbations (on CAD's coplanar and cospherical points they pick
    // other diagonals).
    let attempts = if faces.len() > opts.max_steiner_faces {
        0
    } else {
        opts.attempts
    };
    for attempt in 0..attempts {
        if attempt > 0 {
            let key = |v: u32| {
                (v as u64 ^ (attempt as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
                    .wrapping_mul(0xff51_afd7_ed55_8ccd)
            };
            local.sort_unstable_by_key(|&v| key(v));
        }
        match delaunay_fill(points, faces, &local, opts, true, &mut flips)? {
            Ok(f) => return Ok(f),
            Err(m) => missing = m,
        }
    }
    Err(FillError::Unrecovered {
        missing,
        faces: faces.len(),
    })
}

/// One try: the triangulation of the points `local` (in that order of
/// ids), its faces recovered, Steiner points added while flips are stuck.
/// The fill, or how many faces stayed missing.
fn delaunay_fill(
    points: &[P3],
    faces: &[[u32; 3]],
    local: &[u32],
    opts: &FillOptions,
    with_steiner: bool,
    flips: &mut usize,
) -> Result<Result<Fill, usize>, FillError> {
    let lp: Vec<P3> = local.iter().map(|&i| points[i as usize]).collect();
    let to_tri: FxHashMap<u32, u32> = local
        .iter()
        .enumerate()
        .map(|(k, &i)| (i, 4 + k as u32))
        .collect();
    let cf: Vec<[u32; 3]> = faces.iter().map(|f| f.map(|v| to_tri[&v])).collect();
    let mut tri = Triangulation::new(&lp)?;
    let mut steiner = 0;
    loop {
        let missing = recover_all(&mut tri, &cf, opts.flips_per_face, flips);
        if missing.is_empty() {
            if let Some(kept) = classify(&tri, &cf) {
                return Ok(Ok(output(
                    &tri,
                    &kept,
                    local,
                    points.len(),
                    FillMethod::Delaunay,
                    *flips,
                )));
            }
            return Ok(Err(1));
        }
        // Large cavities are grown by the caller rather than searched.
        if !with_steiner || cf.len() > opts.max_steiner_faces {
            return Ok(Err(missing.len()));
        }
        // Steiner points near the stuck faces, strictly inside the cavity.
        let mut added = false;
        for &m in missing.iter().take(4) {
            if steiner >= opts.max_steiner {
                break;
            }
            if let Some(q) =
                steiner_at_crossing(&tri, &cf, m).or_else(|| steiner_near(&tri, &cf, m))
            {
                if tri.insert(q).is_ok() {
                    steiner += 1;
                    added = true;
                }
            }
        }
        if !added {
            return Ok(Err(missing.len()));
        }
    }
}

/// Closed, consistently oriented, non-degenerate, positive volume.
fn validate(points: &[P3], faces: &[[u32; 3]]) -> Result<(), FillError> {
    if faces.is_empty() {
        return Err(FillError::Empty);
    }
    for (i, f) in faces.iter().enumerate() {
        if let Some(&v) = f.iter().find(|&&v| v as usize >= points.len()) {
            return Err(FillError::BadIndex(i, v));
        }
        if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
            return Err(FillError::Degenerate(i));
        }
    }
    if let Some((a, b)) = open_edge(faces) {
        return Err(FillError::NotClosed(a, b));
    }
    let o = points[faces[0][0] as usize];
    let vol: f64 = faces
        .iter()
        .map(|f| {
            let p = f.map(|v| points[v as usize]);
            orient3d(p[0], p[1], p[2], o)
        })
        .sum();
    if !(vol > 0.0) {
        return Err(FillError::NotPositive);
    }
    Ok(())
}

/// An edge of `faces` used more often one way than the other (lower id
/// first), or `None` when the surface is closed. A pinched cavity (two
/// parts touching along an edge) uses the edge twice each way.
pub(crate) fn open_edge(faces: &[[u32; 3]]) -> Option<(u32, u32)> {
    let mut half: FxHashMap<(u32, u32), i32> = FxHashMap::default();
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *half.entry((a, b)).or_default() += 1;
        }
    }
    half.iter()
        .find(|&(&(a, b), &n)| half.get(&(b, a)) != Some(&n))
        .map(|(&(a, b), _)| (a.min(b), a.max(b)))
}

/// The tets inside the recovered faces, grown from each face's inner side
/// without crossing a face; `None` unless they are bounded by exactly the
/// faces, each once and from its inner side, and hold no bounding corner.
pub(crate) fn classify(tri: &Triangulation, cf: &[[u32; 3]]) -> Option<Vec<u32>> {
    let oriented: FxHashMap<[u32; 3], [u32; 3]> = cf.iter().map(|&f| (key3(f), f)).collect();
    let mut inside = vec![false; tri.tet_slots()];
    let mut queue = Vec::new();
    for &f in cf {
        let fr = tri.find_face(f)?;
        let (t, k) = (fr >> 2, (fr & 3) as usize);
        let p = f.map(|v| tri.pts[v as usize]);
        let apex = tri.tet(t)[k];
        let seed = if orient3d(p[0], p[1], p[2], tri.pts[apex as usize]) > 0.0 {
            t
        } else {
            let nb = tri.neighbour(t, k);
            if nb == NONE {
                return None;
            }
            nb >> 2
        };
        if !inside[seed as usize] {
            inside[seed as usize] = true;
            queue.push(seed);
        }
    }
    let mut i = 0;
    while i < queue.len() {
        let t = queue[i];
        i += 1;
        let tv = tri.tet(t);
        if tv.iter().any(|&v| tri.is_bounding(v)) {
            return None;
        }
        for k in 0..4 {
            let w = TET_FACES[k].map(|j| tv[j]);
            if oriented.contains_key(&key3(w)) {
                continue;
            }
            let nb = tri.neighbour(t, k);
            if nb == NONE {
                return None;
            }
            let u = nb >> 2;
            if !inside[u as usize] {
                inside[u as usize] = true;
                queue.push(u);
            }
        }
    }
    // Exactly the faces bound the kept tets, each seen from inside.
    let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
    for &t in &queue {
        let tv = tri.tet(t);
        for k in 0..4 {
            let nb = tri.neighbour(t, k);
            if nb != NONE && inside[(nb >> 2) as usize] {
                continue;
            }
            let w = TET_FACES[k].map(|j| tv[j]);
            let f = *oriented.get(&key3(w))?;
            // The tet's outward face is the cavity face reversed.
            if !same_cycle([f[0], f[2], f[1]], w) || !seen.insert(key3(w)) {
                return None;
            }
        }
    }
    (seen.len() == cf.len()).then_some(queue)
}

fn output(
    tri: &Triangulation,
    kept: &[u32],
    local: &[u32],
    n: usize,
    method: FillMethod,
    flips: usize,
) -> Fill {
    let nl = local.len() as u32;
    let mut steiner = Vec::new();
    let mut sid: FxHashMap<u32, u32> = FxHashMap::default();
    let mut sorted = kept.to_vec();
    sorted.sort_unstable();
    let tets = sorted
        .iter()
        .map(|&t| {
            tri.tet(t).map(|v| {
                let k = v - 4;
                if k < nl {
                    local[k as usize]
                } else {
                    *sid.entry(v).or_insert_with(|| {
                        steiner.push(tri.pts[v as usize]);
                        (n + steiner.len() - 1) as u32
                    })
                }
            })
        })
        .collect();
    Fill {
        steiner,
        tets,
        method,
        flips,
    }
}

/// The conforming fill ([`conform_fill`]) over the points `local`.
fn conform(points: &[P3], faces: &[[u32; 3]], local: &[u32], opts: &FillOptions) -> Option<Fill> {
    // Large cavities are grown by the caller instead: a failing
    // conforming fill of the tray's 1,426-face slab took 7 s.
    if opts.max_split == 0 || (faces.len() > opts.max_steiner_faces && !opts.segments_first) {
        return None;
    }
    // A point per face and a few more: the fills that converge on the
    // corpus use fewer (the tray's 158-face slab: 27).
    let max_split = opts.max_split.min(16 + faces.len());
    let fill = |lp: &[P3], lf: &[[u32; 3]]| {
        if !opts.segments_first {
            return conform_fill(lp, lf, max_split, opts.flips_per_face, false);
        }
        // TetGen's order first; where it fails, or leaves a tet flat in
        // floating point (a layer on the coplanar points of a CAD plane
        // that flips do not undo), edges split until Delaunay and the
        // triangulation rebuilt (round.stl's 1,120 needles: 1,574 tets with
        // one flat, against 4,464 with none).
        let kept = crate::segments::conform_kept(
            lp,
            lf,
            max_split,
            opts.flips_per_face,
            opts.headway_rounds,
        );
        let flat = |(st, tets): &(Vec<P3>, Vec<[u32; 4]>)| {
            tets.iter().any(|t| {
                is_flat(t.map(|v| {
                    let v = v as usize;
                    if v < lp.len() {
                        lp[v]
                    } else {
                        st[v - lp.len()]
                    }
                }))
            })
        };
        match kept {
            Some(k) if !flat(&k) => Some(k),
            other => conform_fill(lp, lf, max_split, opts.flips_per_face, true).or(other),
        }
    };
    let (steiner, tets) = in_local_ids(points, faces, local, fill)?;
    Some(Fill {
        steiner,
        tets,
        method: FillMethod::Conform,
        flips: 0,
    })
}

/// Runs `fill` on the cavity in local ids (`local`, the cavity's corners,
/// are ids `0..`) and maps its tets back: a local id past the corners is
/// the caller's `points.len() + k`, for the `k`-th Steiner point returned.
fn in_local_ids(
    points: &[P3],
    faces: &[[u32; 3]],
    local: &[u32],
    fill: impl FnOnce(&[P3], &[[u32; 3]]) -> Option<(Vec<P3>, Vec<[u32; 4]>)>,
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let lp: Vec<P3> = local.iter().map(|&i| points[i as usize]).collect();
    let to_local: FxHashMap<u32, u32> = local
        .iter()
        .enumerate()
        .map(|(k, &i)| (i, k as u32))
        .collect();
    let lf: Vec<[u32; 3]> = faces.iter().map(|f| f.map(|v| to_local[&v])).collect();
    let (steiner, tets) = fill(&lp, &lf)?;
    let nl = local.len() as u32;
    let n = points.len() as u32;
    let tets = tets
        .iter()
        .map(|t| {
            t.map(|v| {
                if v < nl {
                    local[v as usize]
                } else {
                    n + v - nl
                }
            })
        })
        .collect();
    Some((steiner, tets))
}

/// The cone from the kernel's deepest point, verified exactly.
fn cone(points: &[P3], faces: &[[u32; 3]]) -> Option<Fill> {
    let planes: Vec<(P3, P3)> = faces
        .iter()
        .map(|f| {
            let p = f.map(|v| points[v as usize]);
            (centroid3(p[0], p[1], p[2]), tri_normal(p[0], p[1], p[2]))
        })
        .collect();
    let (q, depth) = deepest_point(&planes)?;
    if !(depth > 0.0) || !q.iter().all(|x| x.is_finite()) {
        return None;
    }
    let sees = faces.iter().all(|f| {
        let p = f.map(|v| points[v as usize]);
        orient3d(p[0], p[1], p[2], q) > 0.0
    });
    if !sees {
        return None;
    }
    let id = points.len() as u32;
    Some(Fill {
        steiner: vec![q],
        tets: faces.iter().map(|f| [f[0], f[1], f[2], id]).collect(),
        method: FillMethod::Cone,
        flips: 0,
    })
}

/// A point strictly inside the cavity that sees the faces around stuck
/// face `m` (those sharing a corner with it): their kernel's deepest point
/// within a box about the face, accepted when it sees each of them and no
/// cavity face separates it from face `m`'s centroid.
fn steiner_near(tri: &Triangulation, cf: &[[u32; 3]], m: usize) -> Option<P3> {
    let f = cf[m];
    let near: Vec<usize> = (0..cf.len())
        .filter(|&i| cf[i].iter().any(|v| f.contains(v)))
        .collect();
    let pt = |v: u32| tri.pts[v as usize];
    let fp = f.map(pt);
    let c = centroid3(fp[0], fp[1], fp[2]);
    let mut size: f64 = 0.0;
    for &i in &near {
        for &v in &cf[i] {
            size = size.max(parafront_geom::dist(pt(v), c));
        }
    }
    let planes: Vec<(P3, P3)> = near
        .iter()
        .map(|&i| {
            let p = cf[i].map(pt);
            (centroid3(p[0], p[1], p[2]), tri_normal(p[0], p[1], p[2]))
        })
        .collect();
    let q = deepest_in_box(planes, c, size)?;
    let sees = near.iter().all(|&i| {
        let p = cf[i].map(pt);
        orient3d(p[0], p[1], p[2], q) > 0.0
    });
    (sees && inside(tri, cf, q)).then_some(q)
}

/// The deepest point of the half-spaces `planes` (point, inward normal)
/// within the box of half-width `half` about `c`, where it lies strictly
/// inside them all.
pub(crate) fn deepest_in_box(mut planes: Vec<(P3, P3)>, c: P3, half: f64) -> Option<P3> {
    for k in 0..3 {
        let mut n = [0.0; 3];
        n[k] = 1.0;
        let mut lo = c;
        lo[k] -= half;
        planes.push((lo, n));
        n[k] = -1.0;
        let mut hi = c;
        hi[k] += half;
        planes.push((hi, n));
    }
    let (q, depth) = deepest_point(&planes)?;
    (depth > 0.0 && q.iter().all(|x| x.is_finite())).then_some(q)
}

/// Whether `q` lies strictly inside the closed surface `cf`.
fn inside(tri: &Triangulation, cf: &[[u32; 3]], q: P3) -> bool {
    inside_surface(&tri.pts, cf, q)
}

/// Whether `q` lies strictly inside the closed surface `faces` of `pts`: a
/// ray's crossings, counted with the exact segment-triangle test, along the
/// first of a few directions that meets no edge or corner.
pub(crate) fn inside_surface(pts: &[P3], faces: &[[u32; 3]], q: P3) -> bool {
    use parafront_geom::intersect::segment_triangle_parity;
    let mut far: f64 = 1.0;
    for f in faces {
        for &v in f {
            for k in 0..3 {
                far = far.max((pts[v as usize][k] - q[k]).abs());
            }
        }
    }
    let far = 4.0 * far;
    let dirs = [
        [0.577, 0.0321, 0.816],
        [-0.31, 0.77, 0.2],
        [0.11, -0.43, -0.9],
        [0.7, 0.7, -0.14],
    ];
    'dir: for d in dirs {
        let e = [q[0] + far * d[0], q[1] + far * d[1], q[2] + far * d[2]];
        let mut odd = false;
        for f in faces {
            let p = f.map(|v| pts[v as usize]);
            match segment_triangle_parity(q, e, p[0], p[1], p[2]) {
                Some(true) => odd = !odd,
                Some(false) => {}
                None => continue 'dir,
            }
        }
        return odd;
    }
    false
}

/// A point just inside stuck face `m` where the triangulation crosses it:
/// an edge that pierces the face, or the face's edge where it pierces a
/// face, moved off the face into the cavity (Si's Steiner points near a
/// missing facet, kept off the surface). Inserted, it removes the crossing.
fn steiner_at_crossing(tri: &Triangulation, cf: &[[u32; 3]], m: usize) -> Option<P3> {
    use parafront_geom::{add, dist, normalize, scale, sub};
    let f = cf[m];
    let p = f.map(|v| tri.pts[v as usize]);
    let n = normalize(tri_normal(p[0], p[1], p[2]));
    let c = centroid3(p[0], p[1], p[2]);
    let (edges, faces) = crossings(tri, f);
    let mut hits: Vec<P3> = Vec::new();
    for (u, v) in edges {
        let (pu, pv) = (tri.pts[u as usize], tri.pts[v as usize]);
        let (ou, ov) = (
            orient3d(p[0], p[1], p[2], pu),
            orient3d(p[0], p[1], p[2], pv),
        );
        if ou == ov {
            continue;
        }
        let t = ou / (ou - ov);
        hits.push(add(pu, scale(sub(pv, pu), t)));
    }
    for fr in faces {
        let tv = tri.tet(fr >> 2);
        let w = crate::tri::TET_FACES[(fr & 3) as usize].map(|k| tri.pts[tv[k] as usize]);
        for e in 0..3 {
            let (a, b) = (p[e], p[(e + 1) % 3]);
            let (oa, ob) = (orient3d(w[0], w[1], w[2], a), orient3d(w[0], w[1], w[2], b));
            if (oa > 0.0) != (ob > 0.0) && oa != 0.0 && ob != 0.0 {
                let t = oa / (oa - ob);
                // On the face's edge: pulled towards its centroid.
                let x = add(a, scale(sub(b, a), t));
                hits.push(add(x, scale(sub(c, x), 0.1)));
            }
        }
    }
    let lmin = (0..3)
        .map(|e| dist(p[e], p[(e + 1) % 3]))
        .fold(f64::INFINITY, f64::min);
    for x in hits {
        for s in [0.2, 0.05, 0.01] {
            let q = add(x, scale(n, s * lmin));
            if orient3d(p[0], p[1], p[2], q) > 0.0 && inside(tri, cf, q) {
                return Some(q);
            }
        }
    }
    None
}
