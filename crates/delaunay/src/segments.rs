//! The conforming fill in TetGen's order, in one triangulation: the
//! cavity's edges are recovered by flips and kept, an edge flips cannot
//! recover is split at a point inserted without breaking what is kept,
//! then the faces (cut at those points) are recovered by flips, a piece
//! they cannot recover split in turn; last the split points are moved off
//! the surface into the cavity (`conform::relocate`). Rebuilding the
//! triangulation after each round of splits instead (`conform_fill`) loses
//! what the flips had recovered, and on thin cracks does not converge.
use crate::conform::{split_point, Conforming};
use crate::fill::classify;
use crate::flips::{edge_key, key3};
use crate::predicates::is_flat;
use crate::recover::{recover_edge, recover_faces, DEPTH};
use crate::relocate::relocate;
use crate::tri::{Triangulation, NONE};
use parafront_geom::P3;
use rustc_hash::FxHashSet;

/// Rounds of flat-tet removal before relocation.
const UNFLATTEN_ROUNDS: usize = 4;
/// Rounds of face recovery and splits before it gives up.
const ROUNDS: usize = 24;
/// Whether a fill's rounds of splits still make headway: a fill gives up
/// after `limit` rounds (0: never) that leave more pieces missing than the
/// fewest so far, as diverging (a thin crack's face pieces went 78, 50,
/// 54, 71, ... while the splits passed 400; a first stall's 1,584-face
/// crack's edges 80, 53, 59, 72, 77, ... for 2 s). Rounds that leave as
/// many are the slow tail of a fill that closes (the plate's 1,560-face
/// cavity: 2, 2, 2, 2, 1, 0 edges; the whole plate: 17, 17, 0 faces).
struct Headway {
    fewest: usize,
    worse: u32,
    limit: u32,
    /// A round that leaves more than this many times the fewest ends it
    /// at once (0: never).
    blowup: usize,
}

impl Headway {
    fn new(limit: u32) -> Headway {
        Headway {
            fewest: usize::MAX,
            worse: 0,
            limit,
            blowup: 0,
        }
    }

    /// After a round that left `missing`.
    fn goes_on(&mut self, missing: usize) -> bool {
        if missing < self.fewest {
            self.fewest = missing;
        } else if missing > self.fewest {
            self.worse += 1;
            if self.blowup > 0 && missing > self.blowup * self.fewest {
                return false;
            }
        }
        self.limit == 0 || self.worse < self.limit
    }
}

/// [`Headway::blowup`] of the face rounds: each recovers every piece,
/// dearer with each round of splits, so a round that leaves more than
/// twice the fewest ends the fill (the plate at size 4: a 5,088-face
/// cavity's pieces went 169, 436 and 1,017 missing in 2.4, 8.6 and 30 s
/// before the limit ended it; at size 16 a 1,636-face one went 7, 8, 0).
const FACE_BLOWUP: usize = 2;

/// The cavity's points (`lp`, each face's corners index it) and faces; a
/// fill as Steiner points and tets over `lp` then the Steiner points, or
/// `None`.
pub(crate) fn conform_kept(
    lp: &[P3],
    faces: &[[u32; 3]],
    max_split: usize,
    per_face: usize,
    headway_rounds: u32,
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let n0 = lp.len();
    let mut c = Conforming::new(lp, faces);
    // Ids in the triangulation are 4 + ids in `c.pts`.
    let mut tri = Triangulation::new(lp).ok()?;
    let mut flips = 0;
    let mut edge_headway = Headway::new(headway_rounds);
    let mut face_headway = Headway {
        blowup: FACE_BLOWUP,
        ..Headway::new(headway_rounds)
    };
    for _ in 0..ROUNDS {
        // What is there to keep: the edges' pieces and the faces' pieces
        // the triangulation has.
        let mut protect: FxHashSet<[u32; 3]> = piece_keys(&c)
            .filter(|&k| {
                if k[2] == NONE {
                    tri.has_edge(k[0], k[1])
                } else {
                    tri.find_face(k).is_some()
                }
            })
            .collect();
        // Edges first.
        loop {
            let mut pieces: Vec<(u32, u32)> = c
                .chains
                .values()
                .flat_map(|ch| ch.windows(2).map(|w| (w[0], w[1])))
                .collect();
            pieces.sort_unstable();
            let mut missing = Vec::new();
            for (u, v) in pieces {
                let (a, b) = (u + 4, v + 4);
                if protect.contains(&edge_key(a, b))
                    || recover_edge(&mut tri, a, b, &protect, per_face, &mut flips, DEPTH)
                {
                    protect.insert(edge_key(a, b));
                } else {
                    missing.push((u, v));
                }
            }
            tracing::debug!(
                faces = faces.len(),
                splits = c.pts.len() - n0,
                missing = missing.len(),
                "conform_kept: edges"
            );
            if missing.is_empty() {
                break;
            }
            if !edge_headway.goes_on(missing.len()) {
                return None;
            }
            for (u, v) in missing {
                if c.pts.len() - n0 >= max_split {
                    return None;
                }
                let m = split_point(&c.pts, n0, u, v);
                let id = tri.insert_constrained(m, &protect)?;
                debug_assert_eq!(id as usize, c.pts.len() + 4);
                c.split_edge(u, v, m);
            }
        }
        // Then the faces, as the triangulation tiles them where it does.
        c.retile(&tri, true);
        let (sub, origin) = c.flat();
        let tf: Vec<[u32; 3]> = sub.iter().map(|f| f.map(|v| v + 4)).collect();
        let still = recover_faces(&mut tri, &tf, &mut protect, per_face, &mut flips, DEPTH);
        tracing::debug!(
            faces = faces.len(),
            splits = c.pts.len() - n0,
            missing = still.len(),
            "conform_kept: pieces"
        );
        if still.is_empty() {
            // A flip that fails can still have changed tets: classify
            // again after any was tried. A flip can leave a flat tet
            // beside (a strip of coplanar needles): a few rounds.
            let mut kept = classify(&tri, &tf)?;
            for _ in 0..UNFLATTEN_ROUNDS {
                if !unflatten(&mut tri, &kept, &protect) {
                    break;
                }
                kept = classify(&tri, &tf)?;
            }
            let tets: Vec<[u32; 4]> = kept.iter().map(|&t| tri.tet(t).map(|v| v - 4)).collect();
            return relocate(n0, c.pts, &c.chains, tets, sub, origin, faces);
        }
        if !face_headway.goes_on(still.len()) {
            return None;
        }
        let before = c.pts.len();
        for m in still {
            if c.pts.len() - n0 >= max_split {
                return None;
            }
            c.break_piece(&tri, sub[m], origin[m], false);
        }
        if c.pts.len() == before {
            return None;
        }
        // Pieces split above are not kept any more.
        let keep: FxHashSet<[u32; 3]> = piece_keys(&c).collect();
        protect.retain(|k| keep.contains(k));
        for k in before..c.pts.len() {
            let id = tri.insert_constrained(c.pts[k], &protect)?;
            debug_assert_eq!(id as usize, k + 4);
        }
    }
    None
}

/// The surface's pieces as they stand, in triangulation ids: each edge
/// piece as its [`edge_key`], each face piece as its [`key3`].
fn piece_keys(c: &Conforming) -> impl Iterator<Item = [u32; 3]> + '_ {
    let edges = c
        .chains
        .values()
        .flat_map(|ch| ch.windows(2).map(|w| edge_key(w[0] + 4, w[1] + 4)));
    let faces = c.pieces.iter().flatten().map(|p| key3(p.map(|v| v + 4)));
    edges.chain(faces)
}

/// Remove the flat tets among `kept` by edge removal where the edges
/// allow (a flat tet on two coplanar surface faces goes with a 3-2 flip
/// of the edge across them); whether there were any. The tets may change
/// even where none goes.
fn unflatten(tri: &mut Triangulation, kept: &[u32], protect: &FxHashSet<[u32; 3]>) -> bool {
    let flat: Vec<[u32; 4]> = kept
        .iter()
        .map(|&t| tri.tet(t))
        .filter(|tv| is_flat(tv.map(|v| tri.points()[v as usize])))
        .collect();
    let any = !flat.is_empty();
    for tv in flat {
        // Still there?
        let a = tv.iter().copied().find(|&x| x >= 4).unwrap_or(tv[0]);
        if !tri
            .star(a)
            .iter()
            .any(|&t| tv.iter().all(|x| tri.tet(t).contains(x)))
        {
            continue;
        }
        for (a, b) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let (u, v) = (tv[a], tv[b]);
            if protect.contains(&edge_key(u, v)) {
                continue;
            }
            if tri.remove_edge_deep(u, v, protect, DEPTH) == crate::Flip::Done {
                break;
            }
        }
    }
    any
}

#[cfg(test)]
mod tests {
    use super::Headway;

    /// Rounds that leave as many missing as the fewest are a closing
    /// fill's tail; rounds that leave more count, and the limit-th ends
    /// it; a limit of 0 never does.
    #[test]
    fn headway_counts_only_rounds_worse_than_the_best() {
        let run = |limit: u32, missing: &[usize]| {
            let mut h = Headway::new(limit);
            missing.iter().position(|&m| !h.goes_on(m))
        };
        // The plate's 1,560-face cavity, which closes.
        assert_eq!(run(3, &[67, 48, 43, 33, 17, 8, 4, 2, 2, 2, 2, 1]), None);
        // A first stall's crack that does not.
        assert_eq!(run(3, &[80, 53, 59, 72, 77, 44, 16]), Some(4));
        // Worse rounds need not follow each other.
        assert_eq!(run(3, &[50, 60, 40, 45, 30, 31]), Some(5));
        assert_eq!(run(0, &[80, 53, 59, 72, 77, 90, 100]), None);
    }

    /// With a blow-up factor, a round that leaves more than that many
    /// times the fewest ends it at once; a slightly worse round does not.
    #[test]
    fn a_face_round_that_doubles_the_fewest_ends_the_fill() {
        let run = |missing: &[usize]| {
            let mut h = Headway {
                blowup: super::FACE_BLOWUP,
                ..Headway::new(3)
            };
            missing.iter().position(|&m| !h.goes_on(m))
        };
        // The plate at size 4's 5,088-face cavity: 436 > 2 x 169.
        assert_eq!(run(&[169, 436, 1017]), Some(1));
        // At size 16, a 1,636-face cavity that closes.
        assert_eq!(run(&[7, 8, 0]), None);
        // Exactly twice is not more than twice.
        assert_eq!(run(&[10, 20, 5]), None);
        // The count of worse rounds still ends it.
        assert_eq!(run(&[10, 12, 14, 16]), Some(3));
    }
}
