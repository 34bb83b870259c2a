//! Pieces along a space-filling curve, for the regions whose passes gave
//! way: the serial front's mesh is split into equal runs of its tets in
//! the Morton order of their centroids, and split again so after the
//! pieces' improvement (§9.5's shifts move whole cuts to the lower piece,
//! and on a thin part nearly every tet is at a cut: round.stl's eight
//! pieces had become one).
use super::*;
use parafront_geom::{morton_key, Aabb, P3};
use parafront_passes::{move_pieces, piece_boxes, PassError};

/// Each tet's part of `np`: equal runs of the tets in the Morton order of
/// their centroids (ties by index).
pub(crate) fn curve_parts(points: &[P3], tets: &[[u32; 4]], np: usize) -> Vec<u32> {
    let (lo, ext) = cube(Aabb::from_points(points.iter()));
    let mut order: Vec<(u64, u32)> = tets
        .iter()
        .enumerate()
        .map(|(t, tv)| (morton_key(centroid(points, tv), lo, ext), t as u32))
        .collect();
    order.sort_unstable();
    let n = order.len().max(1);
    let mut part = vec![0u32; tets.len()];
    for (i, &(_, t)) in order.iter().enumerate() {
        part[t as usize] = (i * np / n) as u32;
    }
    part
}

/// Key buckets of [`resplit`]: the top 12 bits of the 60-bit key.
const BUCKET_SHIFT: u32 = 48;
const BUCKETS: usize = 1 << 12;

/// One region's pieces (those this process holds) split again into
/// runs along the Morton curve, over all processes: the tets are counted
/// per bucket of keys (summed over the parts, so the same on any number
/// of processes) and each bucket goes whole to the part its first tet
/// falls in. Global point ids stay.
pub(crate) fn resplit<C: Comm>(comm: &C, pieces: Vec<Piece>) -> Result<Vec<Piece>, PassError> {
    let np = comm.parts();
    let bb = piece_boxes(comm, pieces.iter())
        .into_iter()
        .filter(|b| !b.is_empty())
        .fold(Aabb::EMPTY, |a, b| a.union(&b));
    // Each axis over its own extent: in the cube of the longest one, a
    // needle's tets fell in a few buckets (needle_frustum at 8 parts: 3
    // pieces).
    let ext = [0, 1, 2].map(|k| (bb.max[k] - bb.min[k]).max(1e-300));
    let unit = |c: P3| [0, 1, 2].map(|k| (c[k] - bb.min[k]) / ext[k]);
    let buckets = |pc: &Piece| -> Vec<u32> {
        pc.tets
            .iter()
            .map(|tv| {
                let c = unit(centroid(&pc.points, tv));
                (morton_key(c, [0.0; 3], 1.0) >> BUCKET_SHIFT) as u32
            })
            .collect()
    };
    // The keys are made again as the tets are sent: held for every piece,
    // they were a second copy of its tets' count.
    let counts = comm.all_reduce(
        pieces
            .iter()
            .map(|pc| {
                let mut c = vec![0u32; BUCKETS];
                for k in buckets(pc) {
                    c[k as usize] += 1;
                }
                c
            })
            .collect(),
        |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect(),
    );
    let total: u64 = counts.iter().map(|&c| c as u64).sum();
    if total == 0 {
        return Ok(pieces);
    }
    let mut before = 0u64;
    let part: Vec<u32> = counts
        .iter()
        .map(|&c| {
            let k = (before * np as u64 / total) as u32;
            before += c as u64;
            k
        })
        .collect();
    move_pieces(comm, pieces, |_, pc| {
        buckets(pc).into_iter().map(|k| part[k as usize]).collect()
    })
}

/// The corner and edge of the cube from `b`'s corner with its longest
/// side.
fn cube(b: Aabb) -> (P3, f64) {
    if b.is_empty() {
        return ([0.0; 3], 1.0);
    }
    let a = b.longest_axis();
    (b.min, (b.max[a] - b.min[a]).max(1e-300))
}

fn centroid(points: &[P3], t: &[u32; 4]) -> P3 {
    let c = t.map(|v| points[v as usize]);
    [0, 1, 2].map(|k| 0.25 * (c[0][k] + c[1][k] + c[2][k] + c[3][k]))
}
