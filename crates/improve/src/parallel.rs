//! §9.5: improvement in parallel. The tets are split into parts; each part
//! is cut out as a mesh of its own, whose faces on the cut have no
//! neighbour and so are constraints like the boundary (§9.1-9.4 leave
//! interface points and faces alone), and the parts are improved at the
//! same time. Then each part takes two layers of tets from the parts of
//! higher index next to it, and a second pass improves the former
//! interfaces. Parts are processed independently and put back in part
//! order, so the result depends on the number of parts, not on threads.
//!
//! The partition is coordinate bisection of tet centroids behind
//! [`partition`]; the domain-defining grid's partition can replace it.
use crate::{run, ImproveStats};
use parafront_geom::{Aabb, P3};
use parafront_mesh::{PointId, TetMesh, TopoError};
use rayon::prelude::*;

/// Tets per part when the number of parts is automatic.
pub const TETS_PER_PART: usize = 100_000;

/// Layers of tets a part takes from its higher-index neighbours before the
/// second pass (§9.5: "1-2 extra layers").
pub const SHIFT_LAYERS: usize = 2;

/// The number of parts for `requested` (0: automatic) and `n_tets`.
pub fn part_count(requested: usize, n_tets: usize) -> usize {
    let p = if requested == 0 {
        n_tets.div_ceil(TETS_PER_PART).min(64)
    } else {
        requested
    };
    p.clamp(1, n_tets.max(1))
}

/// Part of each tet: recursive coordinate bisection of the centroids at
/// the median of the longest axis (ties by tet id), `parts` parts of
/// nearly equal size.
pub fn partition(mesh: &TetMesh, parts: usize) -> Vec<u32> {
    let cent: Vec<P3> = mesh
        .tets
        .par_iter()
        .map(|t| {
            let mut c = [0.0; 3];
            for p in t {
                let x = mesh.points[p.idx()];
                for k in 0..3 {
                    c[k] += 0.25 * x[k];
                }
            }
            c
        })
        .collect();
    let mut ids: Vec<u32> = (0..mesh.tets.len() as u32).collect();
    let mut part = vec![0u32; mesh.tets.len()];
    bisect(&mut ids, &cent, parts.max(1), 0, &mut part);
    part
}

fn bisect(ids: &mut [u32], cent: &[P3], parts: usize, first: u32, out: &mut [u32]) {
    if parts <= 1 || ids.len() < 2 {
        for &t in ids.iter() {
            out[t as usize] = first;
        }
        return;
    }
    let ax = Aabb::from_points(ids.iter().map(|&t| &cent[t as usize])).longest_axis();
    let left = parts / 2;
    let k = ids.len() * left / parts;
    ids.select_nth_unstable_by(k, |&a, &b| {
        cent[a as usize][ax]
            .total_cmp(&cent[b as usize][ax])
            .then(a.cmp(&b))
    });
    let (l, r) = ids.split_at_mut(k);
    bisect(l, cent, left, first, out);
    bisect(r, cent, parts - left, first + left as u32, out);
}

/// §9.5 shift: `layers` times, every tet that shares a point with a tet
/// of a lower part moves to the lowest such part.
pub fn shift_partition(mesh: &TetMesh, part: &mut [u32], layers: usize) {
    let mut pmin = vec![u32::MAX; mesh.points.len()];
    for _ in 0..layers {
        pmin.iter_mut().for_each(|x| *x = u32::MAX);
        for (t, v) in mesh.tets.iter().enumerate() {
            for p in v {
                pmin[p.idx()] = pmin[p.idx()].min(part[t]);
            }
        }
        for (t, v) in mesh.tets.iter().enumerate() {
            for p in v {
                part[t] = part[t].min(pmin[p.idx()]);
            }
        }
    }
}

/// One part cut out as a mesh: its points (global ids, sorted) and tets.
struct Piece {
    global: Vec<u32>,
    mesh: TetMesh,
    dead: Vec<bool>,
    st: ImproveStats,
}

fn cut(mesh: &TetMesh, tets: &[u32], frozen: &[bool], level: u8) -> Result<Piece, TopoError> {
    let mut global: Vec<u32> = tets
        .iter()
        .flat_map(|&t| mesh.tets[t as usize].map(|p| p.raw()))
        .collect();
    global.sort_unstable();
    global.dedup();
    let local = |p: PointId| PointId::from_raw(global.binary_search(&p.raw()).unwrap_or(0) as u32);
    let mut sub = TetMesh {
        points: global.iter().map(|&p| mesh.points[p as usize]).collect(),
        tets: tets
            .iter()
            .map(|&t| mesh.tets[t as usize].map(local))
            .collect(),
        region: tets.iter().map(|&t| mesh.region[t as usize]).collect(),
        ..Default::default()
    };
    let fr: Vec<bool> = global
        .iter()
        .map(|&p| frozen.get(p as usize).copied().unwrap_or(false))
        .collect();
    let mut st = ImproveStats::default();
    let dead = run(&mut sub, &fr, level, &mut st, false, false)?;
    // Every part is held until all are done: the merge needs no adjacency.
    sub.neigh = Vec::new();
    Ok(Piece {
        global,
        mesh: sub,
        dead,
        st,
    })
}

/// One parallel pass over the parts given by `part`; returns the part of
/// each tet of the new mesh.
fn pass(
    mesh: &mut TetMesh,
    frozen: &[bool],
    level: u8,
    part: &[u32],
    parts: usize,
    dead: &mut [bool],
    st: &mut ImproveStats,
) -> Result<Vec<u32>, TopoError> {
    // Rebuilt after the passes.
    mesh.neigh = Vec::new();
    let mut groups: Vec<Vec<u32>> = vec![Vec::new(); parts];
    let mut keep: Vec<u32> = Vec::new();
    for (t, &p) in part.iter().enumerate() {
        if p == LEAVE {
            keep.push(t as u32);
        } else {
            groups[p as usize].push(t as u32);
        }
    }
    let kept: Vec<[PointId; 4]> = keep.iter().map(|&t| mesh.tets[t as usize]).collect();
    let kept_region: Vec<u32> = keep.iter().map(|&t| mesh.region[t as usize]).collect();
    // One part per task (as the fills' cavities): parts differ in cost.
    let pieces: Vec<Piece> = groups
        .par_iter()
        .with_max_len(1)
        .map(|g| cut(mesh, g, frozen, level))
        .collect::<Result<_, _>>()?;
    mesh.tets.clear();
    mesh.region.clear();
    mesh.neigh.clear();
    let mut new_part = Vec::new();
    for (k, pc) in pieces.iter().enumerate() {
        for (l, &g) in pc.global.iter().enumerate() {
            if pc.dead[l] {
                dead[g as usize] = true;
            } else {
                mesh.points[g as usize] = pc.mesh.points[l];
            }
        }
        mesh.tets.extend(
            pc.mesh
                .tets
                .iter()
                .map(|t| t.map(|p| PointId::from_raw(pc.global[p.idx()]))),
        );
        mesh.region.extend_from_slice(&pc.mesh.region);
        new_part.extend(std::iter::repeat_n(k as u32, pc.mesh.tets.len()));
        st.add_ops(&pc.st);
    }
    mesh.tets.extend_from_slice(&kept);
    mesh.region.extend_from_slice(&kept_region);
    new_part.extend(std::iter::repeat_n(LEAVE, kept.len()));
    Ok(new_part)
}

/// Part id of tets a pass leaves alone.
const LEAVE: u32 = u32::MAX;

/// Keeps the parts only of the tets within `layers` point-layers of a
/// point that tets of two parts share (the interfaces of the pass that
/// used `part`); the others are marked [`LEAVE`].
fn near_interfaces(mesh: &TetMesh, part: &mut [u32], first: &[u32], layers: usize) {
    let np = mesh.points.len();
    let mut seen = vec![u32::MAX; np];
    let mut near = vec![false; np];
    for (t, v) in mesh.tets.iter().enumerate() {
        for p in v {
            let s = &mut seen[p.idx()];
            if *s == u32::MAX {
                *s = first[t];
            } else if *s != first[t] {
                near[p.idx()] = true;
            }
        }
    }
    let mut active: Vec<bool> = mesh
        .tets
        .iter()
        .map(|v| v.iter().any(|p| near[p.idx()]))
        .collect();
    for _ in 0..layers {
        for (t, v) in mesh.tets.iter().enumerate() {
            if active[t] {
                for p in v {
                    near[p.idx()] = true;
                }
            }
        }
        for (t, v) in mesh.tets.iter().enumerate() {
            active[t] |= v.iter().any(|p| near[p.idx()]);
        }
    }
    for (t, a) in active.iter().enumerate() {
        if !a {
            part[t] = LEAVE;
        }
    }
}

/// §9.5: a parallel pass on `parts` parts, a shift by [`SHIFT_LAYERS`],
/// a second pass over the tets near the first pass's interfaces (the rest
/// was improved already); then the dead points go and the adjacency is
/// rebuilt.
pub(crate) fn improve_parts(
    mesh: &mut TetMesh,
    frozen: &[bool],
    level: u8,
    parts: usize,
    st: &mut ImproveStats,
) -> Result<(), TopoError> {
    let mut dead = vec![false; mesh.points.len()];
    let part = partition(mesh, parts);
    let first = pass(mesh, frozen, level, &part, parts, &mut dead, st)?;
    let mut part = first.clone();
    shift_partition(mesh, &mut part, SHIFT_LAYERS);
    near_interfaces(mesh, &mut part, &first, SHIFT_LAYERS + 1);
    pass(mesh, frozen, level, &part, parts, &mut dead, st)?;
    st.points_removed = dead.iter().filter(|&&d| d).count();
    crate::work::compact_arrays(mesh, &dead);
    mesh.build_adjacency()
}
