//! A partitioned mesh improved and measured where it lies (§9 on the pieces
//! of §8, memory distributed): each piece is improved on its own, its cut
//! faces frozen like the boundary (§9.5's first pass; the shifted second
//! pass over the former cuts is still to do), then the points are numbered
//! again over all processes: the points on a piece's boundary (input and
//! shared points) keep their order, the pieces' own points follow piece by
//! piece. The quality report is the pieces' reports merged.
use super::*;
use parafront_comm::{Wire, WireError};
use parafront_improve::{ImproveOptions, ImproveStats};
use parafront_mesh::quality::{Histogram, Stat};
use parafront_passes::Piece;
use rustc_hash::FxHashMap;

type Key = [u64; 3];

fn key(p: parafront_geom::P3) -> Key {
    p.map(|x| (x + 0.0).to_bits())
}

/// One improved piece before its points are numbered again.
struct Improved {
    mesh: TetMesh,
    /// Per point of `mesh`: its id in the piece before (a boundary point,
    /// which improvement never moves), or none (the piece's own).
    was: Vec<Option<u32>>,
}

/// Improves the pieces this process holds (`pieces[r * held + i]`: region
/// `r`'s piece of part `owned().start + i`, region ids in `region`) and
/// numbers their points and tets again over all processes; the summed
/// statistics of this process and the point count of the whole mesh.
pub(crate) fn improve_pieces<C: Comm>(
    comm: &C,
    pieces: &mut Vec<Piece>,
    region: &[u32],
    n_input: usize,
    io: &ImproveOptions,
) -> Result<(ImproveStats, usize), MeshError> {
    let mut st = ImproveStats::default();
    improve_round(comm, pieces, region, n_input, io, None, &mut st)?;
    // §9.5: the tets at each cut go to the lower piece, and a second round
    // improves the former cuts: the points within a few layers of tets of
    // them move, the rest (improved in the first round) stay.
    let held = comm.owned().len();
    let mut cut: Vec<u32> = comm
        .all_gather(
            (0..held)
                .map(|i| {
                    let mut g: Vec<u32> = pieces
                        .iter()
                        .skip(i)
                        .step_by(held.max(1))
                        .flat_map(|pc| pc.shared.iter().flatten().map(|&j| pc.gid[j as usize]))
                        .collect();
                    g.sort_unstable();
                    g.dedup();
                    g
                })
                .collect(),
        )
        .concat();
    cut.sort_unstable();
    cut.dedup();
    let mut all = std::mem::take(pieces);
    for &r in region {
        let take = held.min(all.len());
        let chunk: Vec<Piece> = all.drain(..take).collect();
        let moved =
            parafront_passes::shift_pieces(comm, chunk).map_err(|source| MeshError::Parallel {
                region: r as usize,
                source,
            })?;
        pieces.extend(moved);
    }
    let n = improve_round(comm, pieces, region, n_input, io, Some(&cut), &mut st)?;
    Ok((st, n))
}

/// One round: every piece improved with its boundary and cuts frozen (and,
/// with `near`, every point farther than a few layers of tets from the
/// points whose global ids it lists), then the points and tets numbered
/// again; the whole mesh's point count.
fn improve_round<C: Comm>(
    comm: &C,
    pieces: &mut [Piece],
    region: &[u32],
    n_input: usize,
    io: &ImproveOptions,
    near: Option<&[u32]>,
    st: &mut ImproveStats,
) -> Result<usize, MeshError> {
    let held = comm.owned().len();
    let (start, np) = (comm.owned().start, comm.parts());
    let n_regions = region.len();
    let mut done = Vec::with_capacity(pieces.len());
    for (i, pc) in pieces.iter().enumerate() {
        let mut on_boundary = vec![false; pc.points.len()];
        for (j, &g) in pc.gid.iter().enumerate() {
            on_boundary[j] = (g as usize) < n_input;
        }
        for list in &pc.shared {
            for &j in list {
                on_boundary[j as usize] = true;
            }
        }
        let by_key: FxHashMap<Key, u32> = (0..pc.points.len())
            .filter(|&j| on_boundary[j])
            .map(|j| (key(pc.points[j]), j as u32))
            .collect();
        let mut mesh = TetMesh {
            points: pc.points.clone(),
            tets: pc.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
            region: vec![region[i / held.max(1)]; pc.tets.len()],
            ..Default::default()
        };
        // Faces in one tet of the piece (its boundary and its cuts) are
        // frozen by the improver itself.
        let frozen = match near {
            None => Vec::new(),
            Some(ids) => far_from(pc, ids),
        };
        let s = parafront_improve::improve(&mut mesh, &frozen, io)
            .map_err(|source| MeshError::Improve { source })?;
        add_stats(st, &s);
        let was = mesh
            .points
            .iter()
            .map(|&p| by_key.get(&key(p)).copied())
            .collect();
        done.push(Improved { mesh, was });
    }
    // The boundary points of every piece keep their order.
    let mut kept: Vec<u32> = comm
        .all_gather(
            (0..held)
                .map(|i| {
                    let mut g: Vec<u32> = (0..n_regions)
                        .flat_map(|r| {
                            let k = r * held + i;
                            let (pc, d) = (&pieces[k], &done[k]);
                            d.was.iter().flatten().map(|&j| pc.gid[j as usize])
                        })
                        .collect();
                    g.sort_unstable();
                    g.dedup();
                    g
                })
                .collect(),
        )
        .concat();
    kept.sort_unstable();
    kept.dedup();
    // Counts by (region, part): the pieces' own points, and the tets.
    let counts: Vec<Vec<(u32, u32)>> = comm.all_gather(
        (0..held)
            .map(|i| {
                (0..n_regions)
                    .map(|r| {
                        let d = &done[r * held + i];
                        let own = d.was.iter().filter(|w| w.is_none()).count() as u32;
                        (own, d.mesh.tets.len() as u32)
                    })
                    .collect()
            })
            .collect(),
    );
    let mut own_base = kept.len() as u32;
    let mut total = kept.len();
    for r in 0..n_regions {
        let mut tet_base = 0u32;
        for k in 0..np {
            let (own, tets) = counts[k][r];
            if let Some(i) = k.checked_sub(start).filter(|&i| i < held) {
                let at = r * held + i;
                renumber(
                    &mut pieces[at],
                    &done[at],
                    &kept,
                    own_base,
                    tet_base,
                    k as u32,
                );
            }
            own_base += own;
            tet_base += tets;
            total += own as usize;
        }
    }
    for (pc, d) in pieces.iter_mut().zip(done) {
        pc.points = d.mesh.points;
        pc.tets = d.mesh.tets.iter().map(|t| t.map(|p| p.raw())).collect();
        // Improvement made these tets; no pass did.
        pc.tet_pass = vec![0; pc.tets.len()];
    }
    Ok(total)
}

/// Per point of `pc`: farther than [`SHIFT_LAYERS`] layers of tets from
/// every point whose global id `ids` (sorted) holds.
///
/// [`SHIFT_LAYERS`]: parafront_improve::parallel::SHIFT_LAYERS
fn far_from(pc: &Piece, ids: &[u32]) -> Vec<bool> {
    let mut near: Vec<bool> = pc
        .gid
        .iter()
        .map(|g| ids.binary_search(g).is_ok())
        .collect();
    for _ in 0..parafront_improve::parallel::SHIFT_LAYERS {
        let now = near.clone();
        for t in &pc.tets {
            if t.iter().any(|&j| now[j as usize]) {
                for &j in t {
                    near[j as usize] = true;
                }
            }
        }
    }
    near.into_iter().map(|x| !x).collect()
}

/// The new ids of one improved piece: its boundary points by their rank in
/// `kept`, its own from `own_base`, its tets from `tet_base`; the owner and
/// the shared lists carried over (shared points are boundary points).
fn renumber(pc: &mut Piece, d: &Improved, kept: &[u32], own_base: u32, tet_base: u32, k: u32) {
    let mut own = own_base;
    let mut now_of = vec![u32::MAX; pc.points.len()];
    let mut gid = Vec::with_capacity(d.was.len());
    let mut owner = Vec::with_capacity(d.was.len());
    for (j, w) in d.was.iter().enumerate() {
        match *w {
            Some(old) => {
                let g = pc.gid[old as usize];
                gid.push(kept.binary_search(&g).map_or(u32::MAX, |x| x as u32));
                owner.push(pc.owner[old as usize]);
                now_of[old as usize] = j as u32;
            }
            None => {
                gid.push(own);
                owner.push(k);
                own += 1;
            }
        }
    }
    for list in &mut pc.shared {
        for j in list.iter_mut() {
            *j = now_of[*j as usize];
        }
    }
    pc.gid = gid;
    pc.owner = owner;
    pc.tet_gid = (tet_base..tet_base + d.mesh.tets.len() as u32).collect();
}

/// Adds one piece's run to `a` (separate runs: every count adds).
fn add_stats(a: &mut ImproveStats, b: &ImproveStats) {
    a.add_ops(b);
    a.points_removed += b.points_removed;
    a.points_inserted += b.points_inserted;
    a.tets_before += b.tets_before;
    a.tets_after += b.tets_after;
    a.seconds += b.seconds;
}

/// The quality of every process's pieces, merged (the same on all).
pub(crate) fn pieces_quality<C: Comm>(
    comm: &C,
    pieces: &[Piece],
    size: Option<&(dyn Fn(parafront_geom::P3) -> f64 + Sync)>,
) -> Option<QualityReport> {
    let held = comm.owned().len().max(1);
    let local: Vec<Option<QWire>> = (0..comm.owned().len())
        .map(|i| {
            pieces
                .iter()
                .skip(i)
                .step_by(held)
                .map(|pc| {
                    let m = TetMesh {
                        points: pc.points.clone(),
                        tets: pc.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
                        ..Default::default()
                    };
                    match size {
                        Some(h) => QualityReport::with_size(&m, h),
                        None => QualityReport::new(&m),
                    }
                })
                .reduce(|a, b| a.merge(&b))
                .map(QWire)
        })
        .collect();
    comm.all_reduce(local, |a, b| match (a, b) {
        (Some(a), Some(b)) => Some(QWire(a.0.merge(&b.0))),
        (a, b) => a.or(b),
    })
    .map(|q| q.0)
}

/// A quality report as it travels between processes.
#[derive(Clone)]
struct QWire(QualityReport);

fn put_stat(s: &Stat, buf: &mut Vec<u8>) {
    (s.min, s.mean, s.max, s.count).put(buf);
}

fn get_stat(buf: &mut &[u8]) -> Result<Stat, WireError> {
    let (min, mean, max, count) = Wire::get(buf)?;
    Ok(Stat {
        min,
        mean,
        max,
        count,
    })
}

fn put_hist(h: &Histogram, buf: &mut Vec<u8>) {
    (h.lo, h.hi).put(buf);
    h.counts.put(buf);
}

fn get_hist(buf: &mut &[u8]) -> Result<Histogram, WireError> {
    let (lo, hi) = Wire::get(buf)?;
    let counts = Wire::get(buf)?;
    Ok(Histogram { lo, hi, counts })
}

impl Wire for QWire {
    fn put(&self, buf: &mut Vec<u8>) {
        let q = &self.0;
        (
            q.n_tets,
            q.n_inverted,
            q.n_skipped,
            q.share_min_dihedral_below,
        )
            .put(buf);
        for s in [
            &q.min_dihedral,
            &q.max_dihedral,
            &q.radius_ratio,
            &q.mean_ratio,
        ] {
            put_stat(s, buf);
        }
        for h in [
            &q.dihedral_hist,
            &q.min_dihedral_hist,
            &q.max_dihedral_hist,
            &q.radius_ratio_hist,
            &q.mean_ratio_hist,
        ] {
            put_hist(h, buf);
        }
        match (&q.edge_ratio, &q.edge_ratio_hist) {
            (Some(s), Some(h)) => {
                true.put(buf);
                put_stat(s, buf);
                put_hist(h, buf);
            }
            _ => false.put(buf),
        }
    }

    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let (n_tets, n_inverted, n_skipped, share_min_dihedral_below) = Wire::get(buf)?;
        let [min_dihedral, max_dihedral, radius_ratio, mean_ratio] = [
            get_stat(buf)?,
            get_stat(buf)?,
            get_stat(buf)?,
            get_stat(buf)?,
        ];
        let [dihedral_hist, min_dihedral_hist, max_dihedral_hist, radius_ratio_hist, mean_ratio_hist] = [
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
        ];
        let (edge_ratio, edge_ratio_hist) = if bool::get(buf)? {
            (Some(get_stat(buf)?), Some(get_hist(buf)?))
        } else {
            (None, None)
        };
        Ok(QWire(QualityReport {
            n_tets,
            n_inverted,
            n_skipped,
            min_dihedral,
            max_dihedral,
            radius_ratio,
            mean_ratio,
            dihedral_hist,
            min_dihedral_hist,
            max_dihedral_hist,
            radius_ratio_hist,
            mean_ratio_hist,
            share_min_dihedral_below,
            edge_ratio,
            edge_ratio_hist,
        }))
    }
}
