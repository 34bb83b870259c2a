//! Redistribution (paper §8, step 4): each tet goes to the lowest part its
//! points' DDG hosts give, doubly defined points are merged by exact
//! coordinate keys, points and tets get global numbers, and each part
//! learns its neighbours and the points it shares with each (bounding-box
//! overlap first, then an exact match).
use crate::{PackedTets, ParOutput, Part, PassError};
use parafront_comm::{Comm, Wire, WireError};
use parafront_ddg::Locator;
use parafront_geom::{Aabb, P3};
use parafront_mesh::{FaceRef, TET_FACES};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// One part of the partitioned mesh.
#[derive(Clone, Debug, Default)]
pub struct Piece {
    /// The points its tets use.
    pub points: Vec<P3>,
    /// Global point id (the merged mesh's numbering).
    pub gid: Vec<u32>,
    /// The part that owns each point: the lowest part holding it. Points
    /// owned elsewhere are this part's ghosts.
    pub owner: Vec<u32>,
    /// Local point ids.
    pub tets: Vec<[u32; 4]>,
    /// Global tet id (by part, then local order).
    pub tet_gid: Vec<u32>,
    /// Pass (1 to 4) that made each tet.
    pub tet_pass: Vec<u8>,
    /// Parts sharing points with this one, ascending.
    pub neighbours: Vec<u32>,
    /// Per neighbour, the local ids of the shared points in ascending
    /// global id: the send/receive list.
    pub shared: Vec<Vec<u32>>,
}

type Key = [u64; 3];

fn key(p: P3) -> Key {
    // -0.0 and 0.0 are one point.
    p.map(|x| (x + 0.0).to_bits())
}

/// A piece with its points' local ids in the order of their exact keys
/// (for the shared lists; a hash map by key was 8.7 MB a piece of 120k
/// points, held over a process's peak).
type Keyed = (Piece, Vec<u32>);

/// The tets one part sends another: their points once each (global id,
/// where it is), then the tets by global ids, packed, and the pass that
/// made each. A tet as four located points was 113 bytes, most of the
/// peak memory of a run on parts; as four ids, 16 bytes (the batches of a
/// process's parts are all made before they are sent: 14 MB of an MPI
/// rank's peak on sphere_5e6 at 32 parts, 4 ranks).
#[derive(Default)]
struct Batch {
    points: Vec<(u32, P3)>,
    tets: PackedTets,
    pass: Vec<u8>,
}

impl Wire for Batch {
    fn put(&self, buf: &mut Vec<u8>) {
        self.points.put(buf);
        self.tets.put(buf);
        self.pass.put(buf);
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let (points, tets, pass) = Wire::get(buf)?;
        Ok(Batch { points, tets, pass })
    }
}

/// Redistribution's first step: each part's tets to their destinations
/// (from [`destinations`]).
pub(crate) fn send<C: Comm>(parts: Vec<Part>, dests: Vec<Dests>, comm: &C) -> Sent {
    let out = parts
        .into_par_iter()
        .zip(dests)
        .map(|(part, dests)| {
            let dst = dests.expand(part.tets.len());
            let pass = part.tet_pass.to_vec();
            let tets = part.tets.to_vec();
            batches(&part.pts, &part.gid, &tets, &pass, (&dst, None))
        })
        .collect();
    Sent(comm.exchange(out))
}

/// The tets each held part received by [`send`]: the DDG is no longer
/// needed for the rest of redistribution.
pub(crate) struct Sent(Vec<Vec<(u32, Batch)>>);

/// Redistribution after [`send`]: the pieces, their shared points, the
/// global numbers, and the merged mesh when `opts.gather`.
pub(crate) fn finish<C: Comm>(
    Sent(inbox): Sent,
    comm: &C,
    input: &[P3],
    n_gid: u32,
    opts: &crate::ParOptions,
) -> Result<ParOutput, PassError> {
    let fail_part = opts.fail_part;
    // Each part: its points once, by exact key.
    let received = receive_tets(inbox).and_then(|p| match fail_part {
        Some(part) if comm.holds(part) => Err(PassError::Injected { part }),
        _ => Ok(p),
    });
    let mut pieces = agreed(comm, received)?;
    // Only for pieces that outlive the merge: a tenth of sphere_1e6's
    // redistribution went to lists that a merged run dropped.
    if !opts.gather || opts.keep_pieces {
        number_tets(comm, &mut pieces);
        // Send/receive lists: box overlap, then exact keys.
        share_points(comm, &mut pieces);
    }
    let mut pieces: Vec<Piece> = pieces.into_iter().map(|p| p.0).collect();
    // Global point numbers: the ids still in use, densely (tets removed
    // for pass 4 may have left points behind), input points first.
    let n = number_points(comm, &mut pieces, input.len(), n_gid);
    // The merged mesh, on part 0's process (the others send their pieces).
    let (points, tets, tet_pass) = if !opts.gather {
        (Vec::new(), Vec::new(), Vec::new())
    } else if comm.owned() == (0..comm.parts()) {
        merge(&pieces, input, n)?
    } else {
        let out = pieces
            .iter()
            .map(|pc| {
                let m = (
                    pc.gid.clone(),
                    pc.points.clone(),
                    pc.tets.clone(),
                    pc.tet_pass.clone(),
                );
                vec![(0u32, m)]
            })
            .collect();
        let inbox = comm.exchange(out);
        if comm.holds(0) {
            let got: Vec<Piece> = inbox
                .into_iter()
                .next()
                .unwrap_or_default()
                .into_iter()
                .map(|(_, (gid, points, tets, tet_pass))| Piece {
                    tets,
                    points,
                    gid,
                    tet_pass,
                    ..Piece::default()
                })
                .collect();
            agreed(comm, merge(&got, input, n))?
        } else {
            agreed(comm, Ok((Vec::new(), Vec::new(), Vec::new())))?
        }
    };
    Ok(ParOutput {
        points,
        tets,
        tet_pass,
        pieces,
        n_points: n,
        stats: Default::default(),
    })
}

/// §9.5's shift between two improvement passes on the pieces: every tet
/// with a point that a lower piece shares goes to the lowest such piece,
/// so that the former cuts lie inside a piece; the pieces are rebuilt
/// (points once by exact key, in order of use), their tets numbered again
/// and their shared lists found again. Global point ids stay.
pub fn shift_pieces<C: Comm>(comm: &C, pieces: Vec<Piece>) -> Result<Vec<Piece>, PassError> {
    let start = comm.owned().start;
    move_pieces(comm, pieces, |i, pc| {
        let k = (start + i) as u32;
        let mut low = vec![k; pc.points.len()];
        for (&q, list) in pc.neighbours.iter().zip(&pc.shared) {
            for &j in list {
                low[j as usize] = low[j as usize].min(q);
            }
        }
        pc.tets
            .iter()
            .map(|t| t.iter().map(|&j| low[j as usize]).min().unwrap_or(k))
            .collect()
    })
}

/// Every tet of the pieces this process holds goes to the part
/// `dst(i, piece)` gives it (for `pieces[i]`, per tet; empty for a piece
/// with none); the pieces are rebuilt as in [`shift_pieces`]. Global point
/// ids stay. Each piece's destinations are made as it is sent: all of them
/// at once were 21 MB of a single process's peak (sphere_5e6 at `--parts
/// 32`, its largest moment). Only the tets that leave a piece are sent;
/// those that stay keep their place (a piece's tets sent to itself were a
/// copy of it, 5 MB of an MPI rank's peak on sphere_5e6).
pub fn move_pieces<C: Comm>(
    comm: &C,
    pieces: Vec<Piece>,
    dst: impl Fn(usize, &Piece) -> Vec<u32> + Sync,
) -> Result<Vec<Piece>, PassError> {
    let start = comm.owned().start;
    let (out, kept): (Vec<Vec<(u32, Batch)>>, Vec<Piece>) = pieces
        .into_par_iter()
        .enumerate()
        .map(|(i, mut pc)| {
            let k = (start + i) as u32;
            let dst = dst(i, &pc);
            debug_assert!(dst.len() == pc.tets.len() || pc.tets.is_empty());
            let out = batches(&pc.points, &pc.gid, &pc.tets, &pc.tet_pass, (&dst, Some(k)));
            // The tets that stay, in order, with their passes.
            let mut kept = 0;
            for (t, &d) in dst.iter().enumerate() {
                if d == k {
                    pc.tets[kept] = pc.tets[t];
                    pc.tet_pass[kept] = pc.tet_pass[t];
                    kept += 1;
                }
            }
            pc.tets.truncate(kept);
            pc.tet_pass.truncate(kept);
            (out, pc)
        })
        .unzip();
    let inbox = comm.exchange(out);
    let joined = kept
        .into_par_iter()
        .zip(inbox)
        .enumerate()
        .map(|(i, (pc, msgs))| join(pc, msgs, (start + i) as u32))
        .collect::<Result<Vec<Keyed>, PassError>>();
    let mut pieces = agreed(comm, joined)?;
    number_tets(comm, &mut pieces);
    share_points(comm, &mut pieces);
    Ok(pieces.into_iter().map(|p| p.0).collect())
}

/// Piece `k` from the tets it kept and those it received (`msgs`, by
/// sending part ascending): the lower parts' tets, its own, the higher
/// parts', with the points once each in the order the tets first use them
/// (as [`receive_tets`] would make it from batches of all of them). Its own
/// tets are renumbered in place.
fn join(pc: Piece, msgs: Vec<(u32, Batch)>, k: u32) -> Result<Keyed, PassError> {
    let Piece {
        points,
        gid,
        tets: mut own,
        tet_pass: own_pass,
        ..
    } = pc;
    let mut out = Piece::default();
    let mut local: FxHashMap<u32, u32> = FxHashMap::default();
    let (lower, higher): (Vec<_>, Vec<_>) = msgs.into_iter().partition(|m| m.0 < k);
    add_batches(&mut out, &mut local, lower);
    for t in &mut own {
        *t = t.map(|j| {
            let g = gid[j as usize];
            *local.entry(g).or_insert_with(|| {
                out.points.push(points[j as usize]);
                out.gid.push(g);
                out.points.len() as u32 - 1
            })
        });
    }
    drop((points, gid));
    if out.tets.is_empty() {
        (out.tets, out.tet_pass) = (own, own_pass);
    } else {
        out.tets.reserve_exact(own.len());
        out.tets.extend(own);
        out.tet_pass.extend(own_pass);
    }
    add_batches(&mut out, &mut local, higher);
    keyed(out)
}

/// `r` once every process knows whether each succeeded: an error here
/// is returned as it is, one elsewhere as [`PassError::Remote`] (a run
/// stopper: these are no front failures).
fn agreed<C: Comm, T>(comm: &C, r: Result<T, PassError>) -> Result<T, PassError> {
    let mine = r.as_ref().err().map(|e| e.to_string());
    match (
        r,
        crate::first_failure(comm, vec![mine; comm.owned().len()]),
    ) {
        (Err(e), _) => Err(e),
        (Ok(x), None) => Ok(x),
        (Ok(_), Some((part, message))) => Err(PassError::Remote {
            part,
            message,
            pass_failed: false,
        }),
    }
}

/// Where each held part's tets go (§8): the lowest part among their
/// points' DDG hosts in `part0`. The DDG and its locator are not needed
/// after this.
pub(crate) fn destinations(
    parts: &[Part],
    start: usize,
    (loc, neigh): (&Locator, &[FaceRef]),
    part0: &[u32],
) -> Vec<Dests> {
    let at_inputs = loc.lowest_at_inputs(part0);
    parts
        .par_iter()
        .enumerate()
        .map(|(i, part)| {
            let k = start + i;
            // Each point's lowest part, and the DDG tet that holds it
            // strictly where one does: a walk for a tet's next corner
            // starts there (the points' own order jumps about).
            let mut host: Vec<Option<u32>> = vec![None; part.pts.len()];
            let mut place = vec![u32::MAX; part.pts.len()];
            let dst: Vec<u32> = part
                .tets
                .iter()
                .map(|tv| {
                    let mut hint = tv
                        .iter()
                        .map(|&i| place[i as usize])
                        .find(|&t| t != u32::MAX)
                        .unwrap_or(u32::MAX);
                    tv.iter()
                        .map(|&i| {
                            let i = i as usize;
                            if let Some(low) = host[i] {
                                return low;
                            }
                            let p = part.pts[i];
                            let low = match at_inputs.get(part.gid[i] as usize) {
                                Some(&low) if low != u32::MAX => {
                                    debug_assert_eq!(
                                        Some(low),
                                        loc.lowest_host(neigh, p, part0, &mut u32::MAX.clone())
                                    );
                                    low
                                }
                                _ => {
                                    let mut at = hint;
                                    let low = loc.lowest_host(neigh, p, part0, &mut at);
                                    if at != u32::MAX {
                                        (place[i], hint) = (at, at);
                                    }
                                    low.unwrap_or(k as u32)
                                }
                            };
                            host[i] = Some(low);
                            low
                        })
                        .min()
                        .unwrap()
                })
                .collect();
            Dests::new(&dst)
        })
        .collect()
}

/// The destinations of one part's tets: the most frequent one, and the
/// tets that go elsewhere, as (tet, part) ascending. Most of a part's tets
/// go to one part; a destination for every tet was 5 MB of each MPI rank's
/// peak (sphere_5e6 at 32 parts).
#[derive(Debug, PartialEq)]
pub(crate) struct Dests {
    most: u32,
    other: Vec<(u32, u32)>,
}

impl Dests {
    fn new(dst: &[u32]) -> Dests {
        let mut count: FxHashMap<u32, usize> = FxHashMap::default();
        for &d in dst {
            *count.entry(d).or_default() += 1;
        }
        // The most frequent, the lowest among equals.
        let most = count
            .iter()
            .max_by_key(|&(&d, &n)| (n, std::cmp::Reverse(d)))
            .map_or(0, |(&d, _)| d);
        let other = (0u32..)
            .zip(dst)
            .filter(|&(_, &d)| d != most)
            .map(|(t, &d)| (t, d))
            .collect();
        Dests { most, other }
    }

    /// The destination of each of `n` tets.
    fn expand(&self, n: usize) -> Vec<u32> {
        let mut dst = vec![self.most; n];
        for &(t, d) in &self.other {
            dst[t as usize] = d;
        }
        dst
    }
}

/// The tets (local ids into `pts` and `gid`) as one batch per destination
/// `dst[t]`, ascending, each in tet order with its points once; none for
/// the destination `skip`.
fn batches(
    pts: &[P3],
    gid: &[u32],
    tets: &[[u32; 4]],
    pass: &[u8],
    (dst, skip): (&[u32], Option<u32>),
) -> Vec<(u32, Batch)> {
    // By destination, each in tet order (a stable sort).
    let mut order: Vec<u32> = (0..dst.len() as u32)
        .filter(|&t| Some(dst[t as usize]) != skip)
        .collect();
    order.sort_by_key(|&t| dst[t as usize]);
    let mut stamp = vec![u32::MAX; pts.len()];
    let mut out = Vec::new();
    for group in order.chunk_by(|&a, &b| dst[a as usize] == dst[b as usize]) {
        let d = dst[group[0] as usize];
        let mut b = Batch::default();
        let mut by_gid = Vec::with_capacity(group.len());
        for &t in group {
            let tv = tets[t as usize];
            for &p in &tv {
                if stamp[p as usize] != d {
                    stamp[p as usize] = d;
                    b.points.push((gid[p as usize], pts[p as usize]));
                }
            }
            by_gid.push(tv.map(|p| gid[p as usize]));
            b.pass.push(pass[t as usize]);
        }
        b.tets = by_gid.into_iter().collect();
        out.push((d, b));
    }
    out
}

/// Each part's received tets as a piece, its points once (by global id,
/// then checked by exact key), with their order by key.
fn receive_tets(inbox: Vec<Vec<(u32, Batch)>>) -> Result<Vec<Keyed>, PassError> {
    inbox
        .into_par_iter()
        .map(|msgs| {
            let mut pc = Piece::default();
            add_batches(&mut pc, &mut FxHashMap::default(), msgs);
            keyed(pc)
        })
        .collect::<Result<_, PassError>>()
}

/// The batches' tets added to `pc` (room made once), their points once
/// each (`local`: the piece's local id of each global id it has).
fn add_batches(pc: &mut Piece, local: &mut FxHashMap<u32, u32>, msgs: Vec<(u32, Batch)>) {
    let n: usize = msgs.iter().map(|(_, b)| b.tets.len()).sum();
    pc.tets.reserve_exact(n);
    pc.tet_pass.reserve_exact(n);
    for (_, b) in msgs {
        let at: FxHashMap<u32, u32> = (b.points.iter().enumerate())
            .map(|(i, p)| (p.0, i as u32))
            .collect();
        for (tv, pass) in b.tets.iter().zip(b.pass) {
            let t = tv.map(|g| {
                *local.entry(g).or_insert_with(|| {
                    pc.points.push(b.points[at[&g] as usize].1);
                    pc.gid.push(g);
                    pc.points.len() as u32 - 1
                })
            });
            pc.tets.push(t);
            pc.tet_pass.push(pass);
        }
    }
}

/// A piece made, with its points' order by key.
fn keyed(mut pc: Piece) -> Result<Keyed, PassError> {
    pc.points.shrink_to_fit();
    pc.gid.shrink_to_fit();
    let by_key = by_key(&pc)?;
    Ok((pc, by_key))
}

/// The piece's points in the order of their exact keys, or the first two
/// global ids at one place.
fn by_key(pc: &Piece) -> Result<Vec<u32>, PassError> {
    let mut order: Vec<u32> = (0..pc.points.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (key(pc.points[i as usize]), i));
    for w in order.windows(2) {
        let (a, b) = (w[0] as usize, w[1] as usize);
        if key(pc.points[a]) == key(pc.points[b]) {
            return Err(PassError::Coincident {
                a: pc.gid[a],
                b: pc.gid[b],
                at: pc.points[a],
            });
        }
    }
    Ok(order)
}

/// Global tet numbers: by part, then local order.
fn number_tets<C: Comm>(comm: &C, pieces: &mut [Keyed]) {
    let counts = comm.all_gather(pieces.iter().map(|p| p.0.tets.len() as u32).collect());
    let start = comm.owned().start;
    let mut base: u32 = counts[..start].iter().sum();
    for (i, (pc, _)) in pieces.iter_mut().enumerate() {
        pc.tet_gid = (base..base + counts[start + i]).collect();
        base += counts[start + i];
    }
}

/// The box of every part's piece (empty for none), from every process:
/// `pieces` are those this process holds, in order.
pub fn piece_boxes<'a, C: Comm>(comm: &C, pieces: impl Iterator<Item = &'a Piece>) -> Vec<Aabb> {
    comm.all_gather(
        pieces
            .map(|pc| {
                let b = Aabb::from_points(pc.points.iter());
                [b.min, b.max]
            })
            .collect(),
    )
    .into_iter()
    .map(|[min, max]| Aabb { min, max })
    .collect()
}

/// Cells per axis of a piece's [`Occupancy`].
const CELLS: usize = 32;

/// The cells of a piece's box (`CELLS` per axis) that hold a point of its
/// boundary, a bit each: a point it shares with another piece is on both
/// boundaries, so in a cell of both.
type Occupancy = Vec<u64>;

/// The cell of `b` (`CELLS` per axis) that holds `p`, a point of `b`:
/// the same for the same coordinates on every process.
fn cell(b: &Aabb, p: P3) -> usize {
    let mut c = 0;
    for k in 0..3 {
        let e = b.max[k] - b.min[k];
        let t = if e > 0.0 {
            ((p[k] - b.min[k]) / e * CELLS as f64) as usize
        } else {
            0
        };
        c = c * CELLS + t.min(CELLS - 1);
    }
    c
}

/// Each piece's neighbours and shared points (the send/receive lists),
/// and each point's owner: the lowest part that holds it. A piece sends
/// another the keys of its boundary points in a cell of the other's
/// boundary (every point of its boundary in the other's box was 16 MB of
/// an MPI rank's peak, sent and received, on sphere_5e6 at 32 parts).
fn share_points<C: Comm>(comm: &C, pieces: &mut [Keyed]) {
    let boxes = piece_boxes(comm, pieces.iter().map(|p| &p.0));
    let start = comm.owned().start;
    let outer: Vec<Vec<u32>> = pieces.par_iter().map(|(pc, _)| on_boundary(pc)).collect();
    let occupied: Vec<Occupancy> = comm.all_gather(
        pieces
            .iter()
            .zip(&outer)
            .enumerate()
            .map(|(i, ((pc, _), outer))| {
                let mut bits = vec![0u64; (CELLS * CELLS * CELLS).div_ceil(64)];
                for &j in outer {
                    let c = cell(&boxes[start + i], pc.points[j as usize]);
                    bits[c >> 6] |= 1 << (c & 63);
                }
                bits
            })
            .collect(),
    );
    let out: Vec<Vec<(u32, Vec<Key>)>> = pieces
        .par_iter()
        .zip(&outer)
        .enumerate()
        .map(|(i, ((pc, _), outer))| {
            let k = start + i;
            let mut out = Vec::new();
            for (q, b) in boxes.iter().enumerate() {
                if q == k || b.is_empty() || !b.overlaps(&boxes[k]) {
                    continue;
                }
                let near = |p: P3| {
                    let c = cell(b, p);
                    occupied[q][c >> 6] >> (c & 63) & 1 == 1
                };
                let keys: Vec<Key> = outer
                    .iter()
                    .map(|&j| pc.points[j as usize])
                    .filter(|&p| b.contains(p) && near(p))
                    .map(key)
                    .collect();
                if !keys.is_empty() {
                    out.push((q as u32, keys));
                }
            }
            out
        })
        .collect();
    let inbox = comm.exchange(out);
    pieces
        .par_iter_mut()
        .zip(inbox)
        .enumerate()
        .for_each(|(i, ((pc, by_key), msgs))| {
            pc.owner = vec![(start + i) as u32; pc.points.len()];
            let find = |x: &Key| {
                by_key
                    .binary_search_by(|&j| key(pc.points[j as usize]).cmp(x))
                    .ok()
                    .map(|at| by_key[at])
            };
            for (q, keys) in msgs {
                let mut sh: Vec<u32> = keys.iter().filter_map(find).collect();
                if sh.is_empty() {
                    continue;
                }
                sh.sort_unstable_by_key(|&i| pc.gid[i as usize]);
                for &i in &sh {
                    pc.owner[i as usize] = pc.owner[i as usize].min(q);
                }
                pc.neighbours.push(q);
                pc.shared.push(sh);
            }
        });
}

/// The points of `pc` on a face of only one of its tets, ascending: the
/// only ones another piece can share, since a point inside the piece has
/// all its tets there. Sending every point in a neighbour's box instead
/// was 30 MB of each MPI rank's peak (sphere_5e6, 4 ranks, 32 parts).
fn on_boundary(pc: &Piece) -> Vec<u32> {
    let faces = 4 * pc.tets.len();
    on_boundary_in(
        pc,
        BOUNDARY_BAND.max(faces.div_ceil(crate::check::MAX_BANDS)),
    )
}

/// [`on_boundary`] sorting about `band` faces at once.
fn on_boundary_in(pc: &Piece, band: usize) -> Vec<u32> {
    let mut outer = vec![false; pc.points.len()];
    let mut mark = |f: [u32; 3]| f.iter().for_each(|&i| outer[i as usize] = true);
    // In bands of their smallest id, as the check sorts them: all of a
    // piece's at once were 5 MB of an MPI rank's peak (sphere_5e6 at 32
    // parts, 4 ranks). A face's smallest id is two compares; only the
    // faces of the band are sorted and kept.
    let max_id = (pc.points.len() as u32).saturating_sub(1);
    let (ranges, most) = crate::check::face_bands(4 * pc.tets.len(), max_id, band, |f| {
        for t in &pc.tets {
            for c in TET_FACES {
                f(t[c[0]].min(t[c[1]]).min(t[c[2]]));
            }
        }
    });
    if pc.points.len() < 1 << 21 {
        // Three 21-bit ids in a word: two thirds of the sort's memory.
        let pack = |v: [u32; 3]| u64::from(v[0]) | u64::from(v[1]) << 21 | u64::from(v[2]) << 42;
        let unpack = |w: u64| [0, 21, 42].map(|s| ((w >> s) & 0x1f_ffff) as u32);
        let mut keys = Vec::with_capacity(most);
        for (lo, hi) in ranges {
            keys.clear();
            band_faces(pc, (lo, hi), |v| keys.push(pack(v)));
            each_once(&mut keys, |w| mark(unpack(w)));
        }
    } else {
        let mut keys = Vec::with_capacity(most);
        for (lo, hi) in ranges {
            keys.clear();
            band_faces(pc, (lo, hi), |v| keys.push(v));
            each_once(&mut keys, &mut mark);
        }
    }
    (0..pc.points.len() as u32)
        .filter(|&i| outer[i as usize])
        .collect()
}

/// Each face of `pc`'s tets whose smallest id is in `[lo, hi)`, its ids
/// ascending.
fn band_faces(pc: &Piece, (lo, hi): (u64, u64), mut f: impl FnMut([u32; 3])) {
    for t in &pc.tets {
        for c in TET_FACES {
            let [a, b, d] = c.map(|k| t[k]);
            let m = a.min(b).min(d);
            if (lo..hi).contains(&u64::from(m)) {
                let top = a.max(b).max(d);
                // The middle one: the sum less the ends (no overflow in u64).
                let mid = (u64::from(a) + u64::from(b) + u64::from(d)
                    - u64::from(m)
                    - u64::from(top)) as u32;
                f([m, mid, top]);
            }
        }
    }
}

/// Faces [`on_boundary`] sorts at once.
const BOUNDARY_BAND: usize = 1 << 18;

/// Calls `f` with each key that occurs only once in `keys` (sorted here).
fn each_once<K: Ord + Copy>(keys: &mut [K], mut f: impl FnMut(K)) {
    keys.sort_unstable();
    for run in keys.chunk_by(|a, b| a == b) {
        if let [k] = run {
            f(*k);
        }
    }
}

/// Renumber the pieces' global point ids densely (in their order, input
/// points first); the count. The ids in use are a bit each, OR-ed over the
/// processes: every piece's ids gathered on every process, and a new id
/// for every old one, were 9 MB of each MPI rank's peak on sphere_5e6.
fn number_points<C: Comm>(comm: &C, pieces: &mut [Piece], n_input: usize, n_gid: u32) -> u32 {
    let mut mine = vec![0u64; (n_gid as usize).div_ceil(64)];
    let set = |w: &mut [u64], g: usize| w[g >> 6] |= 1 << (g & 63);
    (0..n_input).for_each(|g| set(&mut mine, g));
    for g in pieces.iter().flat_map(|pc| pc.gid.iter()) {
        set(&mut mine, *g as usize);
    }
    // The process's bits in its first part's slot, none in the others.
    let mut local = vec![Vec::new(); pieces.len()];
    if let Some(first) = local.first_mut() {
        *first = mine;
    }
    let used = comm.all_reduce(local, |a: Vec<u64>, b| {
        let (mut long, short) = if a.len() >= b.len() { (a, b) } else { (b, a) };
        long.iter_mut().zip(&short).for_each(|(x, y)| *x |= y);
        long
    });
    // Ids in use before each word.
    let mut before = Vec::with_capacity(used.len());
    let mut n = 0u32;
    for w in &used {
        before.push(n);
        n += w.count_ones();
    }
    for pc in pieces.iter_mut() {
        for g in &mut pc.gid {
            let (w, b) = (*g as usize >> 6, *g & 63);
            *g = before[w] + (used[w] & ((1u64 << b) - 1)).count_ones();
        }
    }
    n
}

/// The merged mesh: every point, every tet, and the pass that made it.
#[allow(clippy::type_complexity)]
fn merge(
    pieces: &[Piece],
    input: &[P3],
    n: u32,
) -> Result<(Vec<P3>, Vec<[u32; 4]>, Vec<u8>), PassError> {
    let mut points = vec![[f64::NAN; 3]; n as usize];
    points[..input.len()].copy_from_slice(input);
    let mut seen = vec![false; n as usize];
    seen[..input.len()].fill(true);
    let mut tets = Vec::new();
    let mut tet_pass = Vec::new();
    for pc in pieces {
        for (i, &g) in pc.gid.iter().enumerate() {
            points[g as usize] = pc.points[i];
            seen[g as usize] = true;
        }
        tets.extend(pc.tets.iter().map(|t| t.map(|i| pc.gid[i as usize])));
        tet_pass.extend_from_slice(&pc.tet_pass);
    }
    if let Some(g) = seen.iter().position(|&s| !s) {
        return Err(PassError::Unused { point: g as u32 });
    }
    Ok((points, tets, tet_pass))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(points: Vec<P3>) -> Piece {
        Piece {
            gid: (0..points.len() as u32).map(|i| 10 + i).collect(),
            points,
            ..Piece::default()
        }
    }

    /// The destinations kept as the most frequent one and the others give
    /// back every tet's; ties go to the lowest part.
    #[test]
    fn destinations_keep_the_most_frequent_and_list_the_rest() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for n in [0usize, 1, 7, 1000] {
            let dst: Vec<u32> = (0..n)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    // Mostly part 5, else one of 0..8.
                    if x % 10 < 7 {
                        5
                    } else {
                        (x >> 8) as u32 % 8
                    }
                })
                .collect();
            let d = Dests::new(&dst);
            assert_eq!(d.expand(n), dst, "{n} tets");
            if n == 1000 {
                assert_eq!(d.most, 5);
                assert!(d.other.len() < 400, "{}", d.other.len());
                assert!(d.other.windows(2).all(|w| w[0].0 < w[1].0));
            }
        }
        assert_eq!(Dests::new(&[3, 1, 3, 1, 2]).most, 1);
    }

    /// An octahedron of 8 tets about its centre (point 0): every point but
    /// the centre is on the boundary, also when the ids need the wide
    /// keys.
    #[test]
    fn the_boundary_points_of_a_piece_leave_out_the_inner_one() {
        let mut pc = piece(vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ]);
        for x in [1, 2] {
            for y in [3, 4] {
                for z in [5, 6] {
                    pc.tets.push([0, x, y, z]);
                }
            }
        }
        assert_eq!(on_boundary(&pc), vec![1, 2, 3, 4, 5, 6]);
        // One tet removed: the centre is on its hole.
        pc.tets.pop();
        assert_eq!(on_boundary(&pc), vec![0, 1, 2, 3, 4, 5, 6]);
        // Ids past 21 bits: the same answer from the wide keys.
        let n = 1 << 21;
        let shift = |t: [u32; 4]| t.map(|i| if i == 0 { 0 } else { n - 7 + i });
        pc.tets = pc.tets.iter().map(|&t| shift(t)).collect();
        pc.tets.push(shift([0, 2, 4, 6]));
        pc.points.resize(n as usize, [0.0; 3]);
        let want: Vec<u32> = (1..7).map(|i| n - 7 + i).collect();
        assert_eq!(on_boundary(&pc), want);
    }

    /// A block of `n`^3 cubes of six tets each (`generate::box_mesh`), in
    /// `np` slabs along x, one piece a slab, its points numbered in the
    /// order its tets use them (global ids: the block's), each tet's pass
    /// from its cube's x.
    fn slabs(n: usize, np: usize) -> Vec<Piece> {
        let m = parafront_mesh::generate::box_mesh(n, n, n, [0.0; 3], [n as f64; 3]);
        // A tet's cube: its lowest corner's x (integral, up to rounding).
        let cube_x = |t: &[parafront_mesh::PointId; 4]| {
            t.iter()
                .map(|p| m.points[p.idx()][0])
                .fold(f64::INFINITY, f64::min)
                .round() as usize
        };
        (0..np)
            .map(|k| {
                let mut pc = Piece::default();
                let mut local: FxHashMap<u32, u32> = FxHashMap::default();
                for t in m
                    .tets
                    .iter()
                    .filter(|t| (k * n / np..(k + 1) * n / np).contains(&cube_x(t)))
                {
                    pc.tets.push(t.map(|p| {
                        *local.entry(p.raw()).or_insert_with(|| {
                            pc.points.push(m.points[p.idx()]);
                            pc.gid.push(p.raw());
                            pc.points.len() as u32 - 1
                        })
                    }));
                    pc.tet_pass.push((cube_x(t) % 4 + 1) as u8);
                }
                pc
            })
            .collect()
    }

    /// The boundary points found a band at a time are those found at once,
    /// and those a count of every face finds.
    #[test]
    fn the_boundary_found_in_bands_is_the_boundary() {
        let pc = &slabs(5, 2)[0];
        let mut count: FxHashMap<[u32; 3], usize> = FxHashMap::default();
        for t in &pc.tets {
            for f in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
                let mut v = f.map(|c| t[c]);
                v.sort_unstable();
                *count.entry(v).or_default() += 1;
            }
        }
        let mut want: Vec<u32> = count
            .iter()
            .filter(|e| *e.1 == 1)
            .flat_map(|e| *e.0)
            .collect();
        want.sort_unstable();
        want.dedup();
        assert!(!want.is_empty() && want.len() < pc.points.len());
        for band in [1 << 20, 64, 7, 1] {
            assert_eq!(on_boundary_in(pc, band), want, "band {band}");
        }
    }

    /// Tets moved between pieces, those that stay kept in place, give the
    /// pieces that sending every tet (its own piece's too) and building
    /// the pieces from the batches gives: the same points, ids, tets,
    /// passes and shared lists, for moves up, down and both.
    #[test]
    fn moving_only_the_leaving_tets_gives_the_rebuilt_pieces() {
        let np = 4;
        let comm = parafront_comm::Threads::new(np);
        let pieces = slabs(6, np);
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for way in 0..3 {
            let dst: Vec<Vec<u32>> = pieces
                .iter()
                .enumerate()
                .map(|(k, pc)| {
                    (0..pc.tets.len())
                        .map(|_| {
                            x ^= x << 13;
                            x ^= x >> 7;
                            x ^= x << 17;
                            let to = (x >> 8) as usize % np;
                            let moves = x % 10 < 3
                                && match way {
                                    0 => to < k,
                                    1 => to > k,
                                    _ => true,
                                };
                            if moves {
                                to as u32
                            } else {
                                k as u32
                            }
                        })
                        .collect()
                })
                .collect();
            let out = pieces
                .iter()
                .zip(&dst)
                .map(|(pc, d)| batches(&pc.points, &pc.gid, &pc.tets, &pc.tet_pass, (d, None)))
                .collect();
            let mut want = receive_tets(comm.exchange(out)).unwrap();
            number_tets(&comm, &mut want);
            share_points(&comm, &mut want);
            let got = move_pieces(&comm, pieces.clone(), |i, _| dst[i].clone()).unwrap();
            let moved: usize = dst
                .iter()
                .enumerate()
                .map(|(k, d)| d.iter().filter(|&&q| q as usize != k).count())
                .sum();
            assert!(moved > 0, "way {way}");
            for (k, (a, (b, _))) in got.iter().zip(&want).enumerate() {
                let at = format!("way {way}, piece {k}");
                assert_eq!(a.points, b.points, "{at}");
                assert_eq!(a.gid, b.gid, "{at}");
                assert_eq!(a.tets, b.tets, "{at}");
                assert_eq!(a.tet_pass, b.tet_pass, "{at}");
                assert_eq!(a.tet_gid, b.tet_gid, "{at}");
                assert_eq!(a.owner, b.owner, "{at}");
                assert_eq!(a.neighbours, b.neighbours, "{at}");
                assert_eq!(a.shared, b.shared, "{at}");
            }
            let total: usize = got.iter().map(|p| p.tets.len()).sum();
            assert_eq!(total, 6 * 6 * 6 * 6);
        }
    }

    /// Each piece's neighbours and shared lists are the pieces and points
    /// (ascending global id) it has in common with the others, its points'
    /// owners the lowest pieces holding them: as a comparison of the ids
    /// of every pair finds them, for slabs side by side and a block split
    /// unevenly (boxes that overlap without a shared point).
    #[test]
    fn shared_points_are_those_two_pieces_hold() {
        for (n, np) in [(6, 4), (7, 3), (5, 5)] {
            let mut pieces: Vec<Keyed> = slabs(n, np)
                .into_iter()
                .map(|pc| {
                    let k = by_key(&pc).unwrap();
                    (pc, k)
                })
                .collect();
            // Move a corner column of the last slab to the first piece:
            // its box then spans the block.
            if np > 2 {
                let (a, b) = pieces.split_at_mut(np - 1);
                let last = &mut b[0].0;
                let first = &mut a[0].0;
                let far = |t: &[u32; 4], pc: &Piece| {
                    t.iter().all(|&j| {
                        pc.points[j as usize][1] <= 1.0 && pc.points[j as usize][2] <= 1.0
                    })
                };
                let mut moved = Vec::new();
                let mut keep = Vec::new();
                for (t, p) in last.tets.iter().zip(&last.tet_pass) {
                    if far(t, last) {
                        moved.push((
                            t.map(|j| (last.gid[j as usize], last.points[j as usize])),
                            *p,
                        ));
                    } else {
                        keep.push((*t, *p));
                    }
                }
                assert!(!moved.is_empty());
                (last.tets, last.tet_pass) = keep.into_iter().unzip();
                for (t, p) in moved {
                    let v = t.map(|(g, x)| match first.gid.iter().position(|&h| h == g) {
                        Some(j) => j as u32,
                        None => {
                            first.points.push(x);
                            first.gid.push(g);
                            first.points.len() as u32 - 1
                        }
                    });
                    first.tets.push(v);
                    first.tet_pass.push(p);
                }
                pieces[0].1 = by_key(&pieces[0].0).unwrap();
            }
            let comm = parafront_comm::Threads::new(np);
            share_points(&comm, &mut pieces);
            let used = |pc: &Piece| -> std::collections::BTreeSet<u32> {
                pc.tets
                    .iter()
                    .flatten()
                    .map(|&j| pc.gid[j as usize])
                    .collect()
            };
            for (k, (pc, _)) in pieces.iter().enumerate() {
                let mine = used(pc);
                let mut want_n = Vec::new();
                let mut want_s = Vec::new();
                for (q, (other, _)) in pieces.iter().enumerate() {
                    let both: Vec<u32> = used(other).intersection(&mine).copied().collect();
                    if q == k || both.is_empty() {
                        continue;
                    }
                    want_n.push(q as u32);
                    want_s.push(both);
                }
                assert_eq!(pc.neighbours, want_n, "{n} {np}: piece {k}");
                let got: Vec<Vec<u32>> = pc
                    .shared
                    .iter()
                    .map(|l| l.iter().map(|&j| pc.gid[j as usize]).collect())
                    .collect();
                assert_eq!(got, want_s, "{n} {np}: piece {k}");
                for (j, &g) in pc.gid.iter().enumerate() {
                    let low = (0..np)
                        .find(|&q| used(&pieces[q].0).contains(&g))
                        .unwrap_or(k);
                    if mine.contains(&g) {
                        assert_eq!(pc.owner[j], low as u32, "{n} {np}: point {g}");
                    }
                }
            }
        }
    }

    /// The ids in use, input ids first, numbered densely in their order,
    /// whichever piece uses them and across the words of the bitmap.
    #[test]
    fn point_ids_in_use_are_numbered_densely_in_order() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for (n_gid, n_input) in [(1u32, 0usize), (64, 3), (1000, 130), (4097, 0)] {
            let np = 3;
            let pieces: Vec<Piece> = (0..np)
                .map(|_| {
                    let gid = (0..n_gid)
                        .filter(|_| {
                            x ^= x << 13;
                            x ^= x >> 7;
                            x ^= x << 17;
                            x.is_multiple_of(7)
                        })
                        .collect();
                    Piece {
                        gid,
                        ..Piece::default()
                    }
                })
                .collect();
            let mut used: Vec<u32> = (0..n_input as u32)
                .chain(pieces.iter().flat_map(|p| p.gid.iter().copied()))
                .collect();
            used.sort_unstable();
            used.dedup();
            let mut got = pieces.clone();
            let n = number_points(&parafront_comm::Threads::new(np), &mut got, n_input, n_gid);
            assert_eq!(n as usize, used.len(), "{n_gid} ids");
            for (a, b) in pieces.iter().zip(&got) {
                for (g, h) in a.gid.iter().zip(&b.gid) {
                    assert_eq!(used[*h as usize], *g);
                }
            }
        }
    }

    /// The points in the order of their exact keys (-0.0 is 0.0), and two
    /// global ids at one place named, the first-met first.
    #[test]
    fn points_by_key_and_coincident_ones() {
        let pc = piece(vec![
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.5, 0.0, 0.0],
            [-0.0, 1.0, 0.0],
        ]);
        let order = by_key(&pc).unwrap();
        let keys: Vec<Key> = order.iter().map(|&i| key(pc.points[i as usize])).collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, vec![0, 1, 2, 3]);
        let pc = piece(vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 2.0, 0.0],
            [-0.0, 1.0, 0.0],
        ]);
        match by_key(&pc) {
            Err(PassError::Coincident { a, b, at }) => {
                assert_eq!((a, b), (11, 13));
                assert_eq!(key(at), key([0.0, 1.0, 0.0]));
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
    }
}
