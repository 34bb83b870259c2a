//! A partitioned mesh improved and measured where it lies (§9 on the pieces
//! of §8, memory distributed), in three rounds, the pieces of each process
//! in parallel:
//! 1. each piece is improved on its own, its cut faces frozen like the
//!    boundary (§9.5's first pass);
//! 2. the tets at each cut go to the lower piece, and the balls of the
//!    points near the former cuts are improved again (§9.5's second pass);
//! 3. where a tet under the lift's floor is left near a cut, it goes with
//!    the tets around it into one piece, and their balls are improved once
//!    more (the whole mesh's last lift, §9.4, as the gathered path has it).
//!
//! After each round the points are numbered again over all processes: the
//! points on a piece's boundary (input and shared points) keep their
//! order, the pieces' own points follow piece by piece. The quality report
//! is the pieces' reports merged.
use super::*;
use parafront_improve::{ImproveOptions, ImproveStats};
use parafront_passes::Piece;

mod clusters;
mod curve;
mod report;

use clusters::{move_clusters, near_points, CLUSTER_LAYERS};
pub(crate) use curve::curve_parts;
use rayon::prelude::*;
pub(crate) use report::pieces_quality;
use rustc_hash::FxHashMap;

type Key = [u64; 3];

fn key(p: parafront_geom::P3) -> Key {
    p.map(|x| (x + 0.0).to_bits())
}

/// One improved piece before its points are numbered again: its points
/// and tets only. The improver's mesh also has each tet's neighbours and
/// region, and room to grow; a process holds every piece it improved until
/// the round ends (sphere_5e6 at `--size 0.021 --parts 8`: 14 MB a piece).
struct Improved {
    points: Vec<parafront_geom::P3>,
    tets: Vec<[u32; 4]>,
    /// Per point of `points`: its id in the piece before (a boundary point,
    /// which improvement never moves), or none (the piece's own).
    was: Vec<Option<u32>>,
}

/// Improves the pieces this process holds (`pieces[r * held + i]`: region
/// `r`'s piece of part `owned().start + i`, region ids in `region`) and
/// numbers their points and tets again over all processes; the summed
/// statistics of this process and the point count of the whole mesh.
/// `lattice_inner`: the global ids (sorted) of the lattice's inner points,
/// frozen in the first round, their tets set aside (they are ideal).
/// `release` hands freed memory back after each round and each move: the
/// improvers' and the moves' leave the heap full of holes (sphere_5e6 at
/// `--parts 32`: 28 MB more resident after the first round than before).
pub(crate) fn improve_pieces<C: Comm>(
    comm: &C,
    pieces: &mut Vec<Piece>,
    region: &[u32],
    (n_input, lattice_inner): (usize, &[u32]),
    io: &ImproveOptions,
    release: &dyn Fn(),
) -> Result<(ImproveStats, usize), MeshError> {
    let mut st = ImproveStats::default();
    let first = Round::First { lattice_inner };
    improve_round(comm, pieces, region, n_input, io, first, &mut st)?;
    release();
    // §9.5: the tets at each cut go to the lower piece, and a second round
    // improves the former cuts: the points within a few layers of tets of
    // them move, the rest (improved in the first round) stay.
    let cut = gather_ids(comm, pieces, |pc| {
        pc.shared
            .iter()
            .flatten()
            .map(|&j| pc.gid[j as usize])
            .collect()
    });
    shift_all(comm, pieces, region)?;
    release();
    let n = improve_round(
        comm,
        pieces,
        region,
        n_input,
        io,
        Round::Near(&cut),
        &mut st,
    )?;
    release();
    // §9.4's last lift, across the cuts: a tet under the lift's floor near
    // a cut of the second round had points frozen there. Such a tet and
    // the tets around it go to one piece, and a third round frees only the
    // points near it (sphere_5e6 at `--parts 8`: 16.2° -> 20°+).
    let tan = parafront_improve::LIFT_SWAP_DEG.to_radians().tan();
    let bad = gather_ids(comm, pieces, |pc| {
        let under: Vec<&[u32; 4]> = pc
            .tets
            .iter()
            .filter(|t| {
                let p = t.map(|j| pc.points[j as usize]);
                parafront_improve::quality::has_dihedral_under(p, tan)
            })
            .collect();
        // The layers around the cuts only where some tet is under.
        if under.is_empty() {
            return Vec::new();
        }
        let near_cut = near_points(pc, pc.shared.iter().flatten().copied(), CLUSTER_LAYERS);
        under
            .into_iter()
            .filter(|t| t.iter().any(|&j| near_cut[j as usize]))
            .flat_map(|t| t.map(|j| pc.gid[j as usize]))
            .collect()
    });
    if bad.is_empty() {
        return Ok((st, n));
    }
    move_clusters(comm, pieces, region, &bad)?;
    release();
    let n = improve_round(
        comm,
        pieces,
        region,
        n_input,
        io,
        Round::Near(&bad),
        &mut st,
    )?;
    Ok((st, n))
}

/// The global ids `of` gives for each piece of every process, sorted and
/// without repeats (the same on all processes).
fn gather_ids<C: Comm>(comm: &C, pieces: &[Piece], of: impl Fn(&Piece) -> Vec<u32>) -> Vec<u32> {
    let held = comm.owned().len();
    let mut ids: Vec<u32> = comm
        .all_gather(
            (0..held)
                .map(|i| {
                    let mut g: Vec<u32> = pieces
                        .iter()
                        .skip(i)
                        .step_by(held.max(1))
                        .flat_map(&of)
                        .collect();
                    g.sort_unstable();
                    g.dedup();
                    g
                })
                .collect(),
        )
        .concat();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// §9.5's shift of every region's pieces: the tets at each cut go to the
/// lower piece.
fn shift_all<C: Comm>(comm: &C, pieces: &mut Vec<Piece>, region: &[u32]) -> Result<(), MeshError> {
    per_region(comm, pieces, region, |chunk| {
        parafront_passes::shift_pieces(comm, chunk)
    })
}

/// The pieces of the regions `which` picks (by index), split again along
/// the Morton curve ([`curve::resplit`]): those of the regions the serial
/// front meshed, after their improvement.
pub(crate) fn resplit_regions<C: Comm>(
    comm: &C,
    pieces: &mut Vec<Piece>,
    region: &[u32],
    which: &[bool],
) -> Result<(), MeshError> {
    let mut which = which.iter();
    per_region(comm, pieces, region, |chunk| {
        if which.next() == Some(&true) {
            curve::resplit(comm, chunk)
        } else {
            Ok(chunk)
        }
    })
}

/// The pieces this process holds, region by region (`held` of each), each
/// region's given to `f` and replaced by what it makes of them.
fn per_region<C: Comm>(
    comm: &C,
    pieces: &mut Vec<Piece>,
    region: &[u32],
    mut f: impl FnMut(Vec<Piece>) -> Result<Vec<Piece>, parafront_passes::PassError>,
) -> Result<(), MeshError> {
    let held = comm.owned().len();
    let mut all = std::mem::take(pieces);
    for &r in region {
        let take = held.min(all.len());
        let chunk: Vec<Piece> = all.drain(..take).collect();
        let moved = f(chunk).map_err(|source| MeshError::Parallel {
            region: r as usize,
            source,
        })?;
        pieces.extend(moved);
    }
    Ok(())
}

/// Which points a round frees besides the pieces' boundaries and cuts.
#[derive(Clone, Copy)]
enum Round<'a> {
    /// Every point but the lattice's inner ones (global ids, sorted).
    First { lattice_inner: &'a [u32] },
    /// The points within a few layers of tets of those listed (global
    /// ids, sorted).
    Near(&'a [u32]),
}

/// One round: every piece improved with its boundary and cuts frozen (and
/// the points `round` keeps), then the points and tets numbered again; the
/// whole mesh's point count.
fn improve_round<C: Comm>(
    comm: &C,
    pieces: &mut [Piece],
    region: &[u32],
    n_input: usize,
    io: &ImproveOptions,
    round: Round<'_>,
    st: &mut ImproveStats,
) -> Result<usize, MeshError> {
    let held = comm.owned().len();
    let (start, np) = (comm.owned().start, comm.parts());
    let n_regions = region.len();
    // One piece per task: pieces differ in cost; the stats add in order.
    let done: Vec<(Improved, Option<ImproveStats>)> = pieces
        .par_iter_mut()
        .enumerate()
        .with_max_len(1)
        .map(|(i, pc)| improve_piece(pc, region[i / held.max(1)], n_input, io, round))
        .collect::<Result<_, _>>()?;
    let done: Vec<Improved> = done
        .into_iter()
        .map(|(d, s)| {
            if let Some(s) = s {
                add_stats(st, &s);
            }
            d
        })
        .collect();
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
                        (own, d.tets.len() as u32)
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
        pc.points = d.points;
        pc.tets = d.tets;
        // Improvement made these tets; no pass did.
        pc.tet_pass = vec![0; pc.tets.len()];
    }
    Ok(total)
}

/// One piece improved with its boundary and cuts frozen, and its run's
/// statistics. In the first round the lattice's inner points are frozen
/// too and their tets set aside. With `Round::Near`, only the points within
/// [`SHIFT_LAYERS`] layers of tets of those it lists are free, and only
/// their balls are improved, cut out as a mesh of their own (§9.5's second
/// pass works on the tets near the former cuts alone); none when no point
/// is free.
///
/// [`SHIFT_LAYERS`]: parafront_improve::parallel::SHIFT_LAYERS
fn improve_piece(
    pc: &mut Piece,
    region: u32,
    n_input: usize,
    io: &ImproveOptions,
    round: Round<'_>,
) -> Result<(Improved, Option<ImproveStats>), MeshError> {
    let (near, lattice_inner) = match round {
        Round::First { lattice_inner } => (None, lattice_inner),
        Round::Near(ids) => (Some(ids), &[][..]),
    };
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
    let free = near.map(|ids| {
        let from =
            (0..pc.points.len() as u32).filter(|&j| ids.binary_search(&pc.gid[j as usize]).is_ok());
        near_points(pc, from, parafront_improve::parallel::SHIFT_LAYERS)
    });
    // The piece's points and tets move into the mesh (a copy would be a
    // second piece at the rank's peak); the round puts them back.
    let mut whole = || TetMesh {
        region: vec![region; pc.tets.len()],
        points: std::mem::take(&mut pc.points),
        tets: std::mem::take(&mut pc.tets)
            .into_iter()
            .map(|t| t.map(PointId::from_raw))
            .collect(),
        ..Default::default()
    };
    let (mesh, st) = match free {
        None => {
            // Faces in one tet of the piece (its boundary and its cuts) are
            // frozen by the improver itself.
            let inner: Vec<u32> = (0..pc.gid.len() as u32)
                .filter(|&j| lattice_inner.binary_search(&pc.gid[j as usize]).is_ok())
                .collect();
            let mut mesh = whole();
            let done = crate::lattice::improve_around_lattice(&mut mesh, 0, &inner, io, false)
                .map_err(|source| MeshError::Improve { source })?;
            (mesh, Some(done.stats))
        }
        Some(free) if free.contains(&true) => {
            let (mesh, st) = improve_balls(pc, region, &free, io)?;
            pc.points = Vec::new();
            (mesh, Some(st))
        }
        Some(_) => (whole(), None),
    };
    let was = mesh
        .points
        .iter()
        .map(|&p| by_key.get(&key(p)).copied())
        .collect();
    let TetMesh {
        mut points, tets, ..
    } = mesh;
    points.shrink_to_fit();
    // In place (the same layout), then cut to its length.
    let mut tets: Vec<[u32; 4]> = tets.into_iter().map(|t| t.map(|p| p.raw())).collect();
    tets.shrink_to_fit();
    Ok((Improved { points, tets, was }, st))
}

/// The piece with the balls of its `free` points improved: those tets cut
/// out as a mesh whose other points are frozen (on its own boundary, by
/// the improver), improved, and the piece's other tets put back after
/// them (their points matched by exact key: frozen points do not move).
/// The piece's tets move into the mesh: the balls' are not held twice
/// while they are improved (sphere_5e6 at `--parts 32`, 4 MPI ranks: half
/// of a piece, 3.5 MB of the highest rank's peak with the lists that
/// split them).
fn improve_balls(
    pc: &mut Piece,
    region: u32,
    free: &[bool],
    io: &ImproveOptions,
) -> Result<(TetMesh, ImproveStats), MeshError> {
    let inside = |t: &[u32; 4]| t.iter().any(|&j| free[j as usize]);
    let mut sub_of = vec![u32::MAX; pc.points.len()];
    let mut points = Vec::new();
    let n_inside = pc.tets.iter().filter(|t| inside(t)).count();
    let mut tets = Vec::with_capacity(n_inside);
    for t in pc.tets.iter().filter(|t| inside(t)) {
        tets.push(t.map(|j| {
            if sub_of[j as usize] == u32::MAX {
                sub_of[j as usize] = points.len() as u32;
                points.push(j);
            }
            PointId::from_raw(sub_of[j as usize])
        }));
    }
    // The rest, in order.
    pc.tets.retain(|t| !inside(t));
    pc.tets.shrink_to_fit();
    let frozen: Vec<bool> = points.iter().map(|&j| !free[j as usize]).collect();
    let mut mesh = TetMesh {
        points: points.iter().map(|&j| pc.points[j as usize]).collect(),
        region: vec![region; tets.len()],
        tets,
        ..Default::default()
    };
    drop(points);
    let st = parafront_improve::improve(&mut mesh, &frozen, io)
        .map_err(|source| MeshError::Improve { source })?;
    // The sub-mesh's frozen points keep their coordinates, and the rest of
    // the piece reaches only those.
    let at: FxHashMap<Key, u32> = mesh
        .points
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i as u32))
        .collect();
    let mut now = vec![u32::MAX; pc.points.len()];
    let mut rest = std::mem::take(&mut pc.tets);
    for t in &mut rest {
        *t = t.map(|j| {
            let j = j as usize;
            if now[j] == u32::MAX {
                // A frozen point that moved (a bug) would come back as a
                // point of its own, and the pieces' check would say so.
                let found = (sub_of[j] != u32::MAX)
                    .then(|| at.get(&key(pc.points[j])).copied())
                    .flatten();
                now[j] = found.unwrap_or_else(|| {
                    mesh.points.push(pc.points[j]);
                    mesh.points.len() as u32 - 1
                });
            }
            now[j]
        });
    }
    mesh.neigh = Vec::new();
    rest.splice(0..0, mesh.tets.iter().map(|t| t.map(|p| p.raw())));
    // In place (the same layout).
    mesh.tets = rest.into_iter().map(|t| t.map(PointId::from_raw)).collect();
    mesh.region.resize(mesh.tets.len(), region);
    Ok((mesh, st))
}

/// The new ids of one improved piece: its boundary points by their rank in
/// `kept`, its own from `own_base`, its tets from `tet_base`; the owner and
/// the shared lists carried over (shared points are boundary points).
fn renumber(pc: &mut Piece, d: &Improved, kept: &[u32], own_base: u32, tet_base: u32, k: u32) {
    let mut own = own_base;
    // The piece's points are in `d` now; its ids still number them.
    let mut now_of = vec![u32::MAX; pc.gid.len()];
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
    pc.tet_gid = (tet_base..tet_base + d.tets.len() as u32).collect();
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

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_geom::P3;
    use parafront_mesh::quality::tet_quality;

    /// Improving the balls of some points changes only those balls: the
    /// other tets and every frozen point are as they were, the piece stays
    /// a valid mesh of the same volume, and its worst tet is no worse.
    #[test]
    fn improving_balls_leaves_the_rest_alone() {
        let s = parafront_surface::generate::icosphere([0.0; 3], 1.0, 4);
        let opts = MeshOptions {
            optimize: 0,
            ..MeshOptions::default()
        };
        let (m, _) = crate::mesh_surface(&s, &opts).unwrap();
        let pc = Piece {
            points: m.points.clone(),
            gid: (0..m.points.len() as u32).collect(),
            tets: m.tets.iter().map(|t| t.map(|p| p.raw())).collect(),
            ..Default::default()
        };
        // The points within two layers of a few inner points.
        let seeds = (s.points.len() as u32..pc.points.len() as u32).step_by(301);
        let free = near_points(&pc, seeds, 2);
        let (inside, rest): (Vec<&[u32; 4]>, Vec<&[u32; 4]>) = pc
            .tets
            .iter()
            .partition(|t| t.iter().any(|&j| free[j as usize]));
        assert!(!inside.is_empty() && !rest.is_empty());
        let io = ImproveOptions { level: 2, parts: 1 };
        let (out, st) = improve_balls(&mut pc.clone(), 1, &free, &io).unwrap();
        assert!(
            st.ops().iter().map(|o| o.1.done).sum::<usize>() > 0,
            "{st:?}"
        );
        // Numbered again with the surface's points first, by coordinates.
        let mut id: FxHashMap<Key, u32> = s
            .points
            .iter()
            .enumerate()
            .map(|(i, &p)| (key(p), i as u32))
            .collect();
        let mut whole = TetMesh {
            points: s.points.clone(),
            region: out.region.clone(),
            ..Default::default()
        };
        let local: Vec<u32> = out
            .points
            .iter()
            .map(|&p| {
                *id.entry(key(p)).or_insert_with(|| {
                    whole.points.push(p);
                    whole.points.len() as u32 - 1
                })
            })
            .collect();
        whole.tets = out
            .tets
            .iter()
            .map(|t| t.map(|p| PointId::from_raw(local[p.idx()])))
            .collect();
        assert_eq!(whole.points.len(), out.points.len());
        whole.build_adjacency().unwrap();
        whole.check_against_surface(&s.tris).unwrap();
        let v = whole.volume();
        assert!((v - m.volume()).abs() < 1e-9 * v, "{v}");
        // The rest, tet for tet, by coordinates, after the balls.
        let coords = |m: &[P3], t: [u32; 4]| t.map(|j| m[j as usize].map(f64::to_bits));
        let tail = &out.tets[out.tets.len() - rest.len()..];
        for (a, b) in rest.iter().zip(tail) {
            assert_eq!(
                coords(&pc.points, **a),
                coords(&out.points, b.map(|p| p.raw()))
            );
        }
        // Frozen points stay; the free ones may move or go.
        let at: std::collections::HashSet<[u64; 3]> =
            out.points.iter().map(|p| p.map(f64::to_bits)).collect();
        for (j, p) in pc.points.iter().enumerate() {
            if !free[j] {
                assert!(at.contains(&p.map(f64::to_bits)), "point {j} moved");
            }
        }
        let worst = |pts: &[P3], tets: &mut dyn Iterator<Item = [u32; 4]>| {
            tets.map(|t| tet_quality(t.map(|j| pts[j as usize])).min_dihedral)
                .fold(f64::INFINITY, f64::min)
        };
        let before = worst(&pc.points, &mut pc.tets.iter().copied());
        let after = worst(
            &out.points,
            &mut out.tets.iter().map(|t| t.map(|p| p.raw())),
        );
        assert!(after >= before, "{before} -> {after}");
    }
}
