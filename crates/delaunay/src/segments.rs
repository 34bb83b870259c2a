//! The conforming fill in TetGen's order, in one triangulation: the
//! cavity's edges are recovered by flips and kept, an edge flips cannot
//! recover is split at a point inserted without breaking what is kept,
//! then the faces (cut at those points) are recovered by flips, a piece
//! they cannot recover split in turn; last the split points are moved off
//! the surface into the cavity (`conform::relocate`). Rebuilding the
//! triangulation after each round of splits instead (`conform_fill`) loses
//! what the flips had recovered, and on thin cracks does not converge.
use crate::conform::{one_chain, split_point, Conforming};
use crate::fill::classify;
use crate::flips::{edge_key, key3};
use crate::predicates::is_flat;
use crate::recover::{recover_edge, recover_faces, DEPTH};
use crate::relocate::relocate;
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::{dot, tri_normal, P3};
use rustc_hash::FxHashSet;

/// Rounds of flat-tet removal before relocation.
const UNFLATTEN_ROUNDS: usize = 4;
/// Rounds of face recovery and splits before it gives up.
const ROUNDS: usize = 24;

/// The cavity's points (`lp`, each face's corners index it) and faces; a
/// fill as Steiner points and tets over `lp` then the Steiner points, or
/// `None`.
pub(crate) fn conform_kept(
    lp: &[P3],
    faces: &[[u32; 3]],
    max_split: usize,
    per_face: usize,
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let n0 = lp.len();
    let mut c = Conforming::new(lp, faces);
    // Ids in the triangulation are 4 + ids in `c.pts`.
    let mut tri = Triangulation::new(lp).ok()?;
    let mut flips = 0;
    for _ in 0..ROUNDS {
        // What is there to keep: the edges' pieces and the faces' pieces
        // the triangulation has.
        let mut protect: FxHashSet<[u32; 3]> = FxHashSet::default();
        for ch in c.chains.values() {
            for w in ch.windows(2) {
                if tri.has_edge(w[0] + 4, w[1] + 4) {
                    protect.insert(edge_key(w[0] + 4, w[1] + 4));
                }
            }
        }
        for ps in &c.pieces {
            for p in ps {
                let w = p.map(|v| v + 4);
                if tri.find_face(w).is_some() {
                    protect.insert(key3(w));
                }
            }
        }
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
                    || tri.has_edge(a, b)
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
        for i in 0..faces.len() {
            if c.pieces[i].len() > 1 {
                if let Some(t) = outer_tiling(&tri, &c, i) {
                    c.pieces[i] = t;
                }
            }
        }
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
            let kept = classify(&tri, &tf)?;
            // A flip that fails can still have changed tets: classify
            // again. A flip can leave a flat tet beside (a strip of
            // coplanar needles): a few rounds.
            let mut kept = kept;
            for _ in 0..UNFLATTEN_ROUNDS {
                if !unflatten(&mut tri, &kept, &protect) {
                    break;
                }
                kept = classify(&tri, &tf)?;
            }
            let kept = classify(&tri, &tf)?;
            let tets: Vec<[u32; 4]> = kept.iter().map(|&t| tri.tet(t).map(|v| v - 4)).collect();
            return relocate(n0, c.pts, &c.chains, tets, sub, origin, faces);
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
        let mut keep: FxHashSet<[u32; 3]> = FxHashSet::default();
        for ch in c.chains.values() {
            for w in ch.windows(2) {
                keep.insert(edge_key(w[0] + 4, w[1] + 4));
            }
        }
        for ps in &c.pieces {
            for p in ps {
                keep.insert(key3(p.map(|v| v + 4)));
            }
        }
        protect.retain(|k| keep.contains(k));
        for k in before..c.pts.len() {
            let id = tri.insert_constrained(c.pts[k], &protect)?;
            debug_assert_eq!(id as usize, k + 4);
        }
    }
    None
}

/// The triangulation's own triangles on face `i`'s points, when they tile
/// it, seen from outside the cavity: split points lie off the face's plane
/// by rounding, so the triangulation may hold flat tets on a face's points,
/// and of such a layer the outer faces are taken. The flat tets are then
/// inside, and go when the split points move off the surface.
fn outer_tiling(tri: &Triangulation, c: &Conforming, i: usize) -> Option<Vec<[u32; 3]>> {
    let set: FxHashSet<u32> = c.pieces[i].iter().flatten().map(|&v| v + 4).collect();
    let pt = |v: u32| tri.points()[v as usize];
    let f = c.faces[i].map(|v| v + 4);
    let n = tri_normal(pt(f[0]), pt(f[1]), pt(f[2]));
    let flat = |t: u32| tri.tet(t).iter().all(|v| set.contains(v));
    let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
    let mut out = Vec::new();
    let mut area = 0.0;
    for &v in &set {
        for t in tri.star(v) {
            let tv = tri.tet(t);
            for (k, fv) in TET_FACES.iter().enumerate() {
                let w = fv.map(|j| tv[j]);
                if !w.iter().all(|x| set.contains(x)) || !seen.insert(key3(w)) {
                    continue;
                }
                // Face k of t points away from t.
                let d = dot(tri_normal(pt(w[0]), pt(w[1]), pt(w[2])), n);
                let outer = if d > 0.0 {
                    t
                } else {
                    let nb = tri.neighbour(t, k);
                    if nb == NONE {
                        return None;
                    }
                    nb >> 2
                };
                if flat(outer) {
                    continue;
                }
                let w = w.map(|x| x - 4);
                if one_chain(&c.chains, w) {
                    return None;
                }
                area += d.abs();
                out.push(if d > 0.0 { w } else { [w[0], w[2], w[1]] });
            }
        }
    }
    out.sort_unstable();
    let whole = dot(n, n);
    (out.len() == c.pieces[i].len() && (area - whole).abs() <= 1e-9 * whole).then_some(out)
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
