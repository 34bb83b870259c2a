//! The relocation of boundary Steiner points that ends the conforming
//! fills (Si and Gärtner): each split point's star gives way to the cone
//! from a point just inside (or from a corner of the hole, or a small fill)
//! over the star's link and the faces it had cut made whole again. The
//! patch takes the link's own triangles where it can and other tilings
//! where the hole cannot be filled, and the hole takes in the tets beyond
//! it when no tiling does. Each hole's fill is checked against it, and the
//! whole at the end.
use crate::conform::{ear_clip_preferring, polygon_fans, tri_normal_of, Chains};
use crate::fill::open_edge;
use crate::flips::key3;
use crate::predicates::is_flat;
use crate::tri::TET_FACES;
use parafront_geom::{
    add, dist, kernel::deepest_point, normalize, orient3d, scale, tri_normal, P3,
};
use rustc_hash::{FxHashMap, FxHashSet};

/// Halvings of the step off the surface tried for a relocated point.
const STEP_HALVINGS: usize = 40;

/// Move each split point off the surface: its star's tets give way to the
/// cone from a point just inside over the star's link and the faces it
/// split, made whole without it (`sub` are the current surface pieces,
/// `origin` their cavity faces). Checked: every tet positive, the surface
/// exactly `faces`, the volume the cavity's.
pub(crate) fn relocate(
    n: usize,
    mut pts: Vec<P3>,
    chains: &Chains,
    mut tets: Vec<[u32; 4]>,
    mut sub: Vec<[u32; 3]>,
    mut origin: Vec<usize>,
    faces: &[[u32; 3]],
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    // A point whose hole cannot be filled yet may be after its
    // neighbours have moved.
    let mut pending: Vec<u32> = (n as u32..pts.len() as u32).collect();
    while !pending.is_empty() {
        let before = pending.len();
        pending.retain(|&s| {
            relocate_one(s, &mut pts, chains, &mut tets, &mut sub, &mut origin, faces).is_none()
        });
        if pending.len() == before {
            tracing::debug!(left = before, "conform: split points not relocated");
            return None;
        }
    }
    if verify(&pts, &tets, faces).is_none() {
        tracing::debug!("conform: verify failed");
        return None;
    }
    // Renumber: the cavity's points, then the relocated points in order.
    let mut used: Vec<u32> = tets
        .iter()
        .flatten()
        .copied()
        .filter(|&v| v as usize >= n)
        .collect();
    used.sort_unstable();
    used.dedup();
    let id: FxHashMap<u32, u32> = used
        .iter()
        .enumerate()
        .map(|(k, &v)| (v, (n + k) as u32))
        .collect();
    let steiner = used.iter().map(|&v| pts[v as usize]).collect();
    let tets = tets
        .iter()
        .map(|t| t.map(|v| if (v as usize) < n { v } else { id[&v] }))
        .collect();
    Some((steiner, tets))
}

/// Tilings of a split point's faces tried for its hole, at most.
const RELOCATE_TRIES: usize = 12;
/// Layers of tets a split point's hole may take in.
const RELOCATE_GROWTH: usize = 2;

/// Tets `tets` over `pts` then `extra` fill `hole` exactly.
fn fills(pts: &[P3], extra: &[P3], tets: &[[u32; 4]], hole: &[[u32; 3]], how: &str) -> bool {
    let all: Vec<P3> = pts.iter().chain(extra).copied().collect();
    let ok = verify(&all, tets, hole).is_some();
    if !ok {
        tracing::debug!(
            how,
            hole = hole.len(),
            "conform: a hole's fill does not match it"
        );
    }
    ok
}

/// Drop each pair of faces that are one triangle seen from both sides
/// (the region between them is empty).
fn cancel_opposite(hole: &mut Vec<[u32; 3]>) {
    let mut by_key: FxHashMap<[u32; 3], Vec<usize>> = FxHashMap::default();
    for (i, &w) in hole.iter().enumerate() {
        by_key.entry(key3(w)).or_default().push(i);
    }
    let mut gone = vec![false; hole.len()];
    for list in by_key.values() {
        for (x, &i) in list.iter().enumerate() {
            if gone[i] {
                continue;
            }
            let pair = list[x + 1..]
                .iter()
                .copied()
                .find(|&j| !gone[j] && !crate::flips::same_cycle(hole[i], hole[j]));
            if let Some(j) = pair {
                gone[i] = true;
                gone[j] = true;
            }
        }
    }
    let mut k = 0;
    hole.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
}

/// The faces around the tets `region` other than those on `s` (its
/// surface pieces), each seen from inside.
fn region_hole(tets: &[[u32; 4]], region: &[usize], s: u32) -> Vec<[u32; 3]> {
    let mut count: FxHashMap<[u32; 3], usize> = FxHashMap::default();
    for &t in region {
        let tv = tets[t];
        for fv in TET_FACES {
            *count.entry(key3(fv.map(|j| tv[j]))).or_default() += 1;
        }
    }
    let mut hole = Vec::new();
    for &t in region {
        let tv = tets[t];
        for fv in TET_FACES {
            let w = fv.map(|j| tv[j]);
            if count[&key3(w)] == 1 && !w.contains(&s) {
                hole.push([w[0], w[2], w[1]]);
            }
        }
    }
    hole
}

/// Move split point `s` off the surface ([`relocate`]'s step); `None`,
/// with nothing changed, when its hole cannot be filled.
fn relocate_one(
    s: u32,
    pts: &mut Vec<P3>,
    chains: &Chains,
    tets: &mut Vec<[u32; 4]>,
    sub: &mut Vec<[u32; 3]>,
    origin: &mut Vec<usize>,
    faces: &[[u32; 3]],
) -> Option<()> {
    let mut star: Vec<usize> = (0..tets.len()).filter(|&t| tets[t].contains(&s)).collect();
    // The surface pieces on `s`, by cavity face, made whole without it.
    let mut by_face: Vec<(usize, Vec<usize>)> = Vec::new();
    for (i, f) in sub.iter().enumerate() {
        if f.contains(&s) {
            match by_face.iter_mut().find(|(o, _)| *o == origin[i]) {
                Some((_, l)) => l.push(i),
                None => by_face.push((origin[i], vec![i])),
            }
        }
    }
    // The patch takes the link's triangles where it can: on a layer of
    // flat tets (split points lie off their face's plane by rounding)
    // the link holds the face's other tiling, and each such triangle
    // then bounds the hole twice and goes. Where the hole still cannot be
    // filled, other tilings of the faces are tried.
    let link: FxHashSet<[u32; 3]> = region_hole(tets, &star, s)
        .iter()
        .map(|&w| key3(w))
        .collect();
    let mut normals: Vec<P3> = Vec::new();
    let mut tilings: Vec<Vec<Vec<[u32; 3]>>> = Vec::new();
    for (o, list) in &by_face {
        let nrm = tri_normal_of(pts, faces[*o]);
        normals.push(normalize(nrm));
        let poly = fan_polygon(sub, list, s)?;
        let mut alts = vec![ear_clip_preferring(pts, chains, &poly, nrm, &link)?];
        for t in polygon_fans(pts, chains, &poly, nrm) {
            if !alts.contains(&t) {
                alts.push(t);
            }
        }
        tilings.push(alts);
    }
    // All first choices, then one face at a time on another.
    let mut choices: Vec<Vec<usize>> = vec![vec![0; tilings.len()]];
    for (f, alts) in tilings.iter().enumerate() {
        for k in 1..alts.len() {
            let mut c = vec![0; tilings.len()];
            c[f] = k;
            choices.push(c);
        }
    }
    let mut found = None;
    // A hole that no tiling lets fill (two coplanar faces whose quad the
    // link tiles the other way: a flat hole) takes in the tets beyond it.
    for grow in 0..=RELOCATE_GROWTH {
        if grow > 0 {
            let around = region_hole(tets, &star, s);
            let keys: FxHashSet<[u32; 3]> = around.iter().map(|&w| key3(w)).collect();
            let inside: FxHashSet<usize> = star.iter().copied().collect();
            for t in 0..tets.len() {
                if inside.contains(&t) {
                    continue;
                }
                let tv = tets[t];
                if TET_FACES
                    .iter()
                    .any(|fv| keys.contains(&key3(fv.map(|j| tv[j]))))
                {
                    star.push(t);
                }
            }
        }
        let link_faces = region_hole(tets, &star, s);
        for choice in choices.iter().take(RELOCATE_TRIES) {
            let patch: Vec<([u32; 3], usize)> = choice
                .iter()
                .enumerate()
                .flat_map(|(f, &k)| {
                    let o = by_face[f].0;
                    tilings[f][k].iter().map(move |&p| (p, o))
                })
                .collect();
            let mut hole = link_faces.clone();
            hole.extend(patch.iter().map(|(p, _)| *p));
            cancel_opposite(&mut hole);
            if open_edge(&hole).is_some() {
                tracing::debug!(hole = hole.len(), point = s, "conform: hole not closed");
                continue;
            }
            if hole.is_empty() {
                found = Some((patch, Vec::new(), Vec::new()));
                break;
            }
            // A corner of the hole that sees every face not on it (two
            // coplanar faces that the link tiled the other way: the cone from
            // the corner beyond them is a 2-2 flip).
            if let Some(x) = corner_cone(pts, &hole) {
                let cone: Vec<[u32; 4]> = hole
                    .iter()
                    .filter(|w| !w.contains(&x))
                    .map(|w| [w[0], w[1], w[2], x])
                    .collect();
                if fills(pts, &[], &cone, &hole, "corner cone") {
                    found = Some((patch, Vec::new(), cone));
                    break;
                }
            }
            if let Some(q) = cone_point(pts, &hole, s, &normals) {
                let qid = pts.len() as u32;
                let cone: Vec<[u32; 4]> = hole.iter().map(|w| [w[0], w[1], w[2], qid]).collect();
                if fills(pts, &[q], &cone, &hole, "cone") {
                    found = Some((patch, vec![q], cone));
                    break;
                }
            }
            // No point sees the whole hole: it is a cavity of its own, filled
            // without splits.
            let opts = crate::fill::FillOptions {
                max_split: 0,
                ..Default::default()
            };
            match crate::fill::fill_cavity(pts, &hole, &opts) {
                Ok(f) if fills(pts, &f.steiner, &f.tets, &hole, "fill") => {
                    found = Some((patch, f.steiner, f.tets));
                    break;
                }
                Ok(_) => {}
                Err(e) => {
                    tracing::debug!(hole = hole.len(), error = %e, point = s, "conform: hole not filled");
                }
            }
        }
        if found.is_some() {
            break;
        }
    }
    let (patch, new_pts, new_tets) = found?;
    pts.extend_from_slice(&new_pts);
    let mut dead = vec![false; tets.len()];
    for &t in &star {
        dead[t] = true;
    }
    let mut next: Vec<[u32; 4]> = (0..tets.len())
        .filter(|&t| !dead[t])
        .map(|t| tets[t])
        .collect();
    next.extend(new_tets);
    *tets = next;
    let keep: Vec<usize> = (0..sub.len()).filter(|&i| !sub[i].contains(&s)).collect();
    *sub = keep.iter().map(|&i| sub[i]).collect();
    *origin = keep.iter().map(|&i| origin[i]).collect();
    for (p, o) in patch {
        sub.push(p);
        origin.push(o);
    }
    Some(())
}

/// The outer chain of the fan of pieces `list` around `s`: from the
/// corner after `s` on its edge round to the one before it, or the whole
/// ring when `s` is inside the face.
fn fan_polygon(sub: &[[u32; 3]], list: &[usize], s: u32) -> Option<Vec<u32>> {
    // Each piece (s, x, y) in its cyclic order gives the chain step x -> y.
    let mut next: FxHashMap<u32, u32> = FxHashMap::default();
    let mut has_in: FxHashSet<u32> = FxHashSet::default();
    for &i in list {
        let f = sub[i];
        let k = f.iter().position(|&v| v == s)?;
        let (x, y) = (f[(k + 1) % 3], f[(k + 2) % 3]);
        if next.insert(x, y).is_some() {
            return None;
        }
        has_in.insert(y);
    }
    // A point on an edge has a path of pieces on each face; one inside a
    // face has a closed fan.
    let open = next.keys().filter(|x| !has_in.contains(x)).min().copied();
    let start = match open {
        Some(v) => v,
        None => *next.keys().min()?,
    };
    let mut chain = vec![start];
    let mut v = start;
    while let Some(&w) = next.get(&v) {
        if w == start {
            break;
        }
        chain.push(w);
        v = w;
        if chain.len() > list.len() + 1 {
            return None;
        }
    }
    let want = if open.is_some() {
        list.len() + 1
    } else {
        list.len()
    };
    (chain.len() == want).then_some(chain)
}

/// A corner of `hole` (faces seen from inside) that every face not on it
/// makes a positive tet with, when one does.
fn corner_cone(pts: &[P3], hole: &[[u32; 3]]) -> Option<u32> {
    let mut corners: Vec<u32> = hole.iter().flatten().copied().collect();
    corners.sort_unstable();
    corners.dedup();
    let pt = |v: u32| pts[v as usize];
    corners.into_iter().find(|&x| {
        hole.iter().filter(|w| !w.contains(&x)).count() > 0
            && hole.iter().filter(|w| !w.contains(&x)).all(|w| {
                let p = [pt(w[0]), pt(w[1]), pt(w[2]), pt(x)];
                orient3d(p[0], p[1], p[2], p[3]) > 0.0 && !is_flat(p)
            })
    })
}

/// A point that sees every face of `hole` from inside: the kernel's deepest
/// point, else `s` moved into the cavity along the faces' `normals`, a step
/// halved until it sees them all.
fn cone_point(pts: &[P3], hole: &[[u32; 3]], s: u32, normals: &[P3]) -> Option<P3> {
    // Positive, and not flat in floating point either.
    let sees = |q: P3| {
        hole.iter().all(|w| {
            let p = w.map(|v| pts[v as usize]);
            orient3d(p[0], p[1], p[2], q) > 0.0 && !is_flat([p[0], p[1], p[2], q])
        })
    };
    let planes: Vec<(P3, P3)> = hole
        .iter()
        .map(|w| {
            let p = w.map(|v| pts[v as usize]);
            (p[0], tri_normal(p[0], p[1], p[2]))
        })
        .collect();
    if let Some((q, depth)) = deepest_point(&planes) {
        if depth > 0.0 && q.iter().all(|x| x.is_finite()) && sees(q) {
            return Some(q);
        }
    }
    let ps = pts[s as usize];
    let d = normalize(normals.iter().fold([0.0; 3], |a, &b| add(a, b)));
    let mut step = hole
        .iter()
        .flatten()
        .map(|&v| dist(pts[v as usize], ps))
        .fold(f64::INFINITY, f64::min)
        * 0.25;
    for _ in 0..STEP_HALVINGS {
        let q = add(ps, scale(d, step));
        if sees(q) {
            return Some(q);
        }
        step *= 0.5;
    }
    None
}

/// Every tet positive, every inner face in two tets from either side, the
/// outer faces exactly the cavity's faces, and the tets' volume the
/// cavity's.
pub(crate) fn verify(pts: &[P3], tets: &[[u32; 4]], faces: &[[u32; 3]]) -> Option<()> {
    let mut open: FxHashMap<[u32; 3], [u32; 3]> = FxHashMap::default();
    let mut vol = 0.0;
    for t in tets {
        let p = t.map(|v| pts[v as usize]);
        let o = orient3d(p[0], p[1], p[2], p[3]);
        if !(o > 0.0) {
            tracing::debug!(?t, "verify: a tet is not positive");
            return None;
        }
        vol += o;
        for fv in TET_FACES {
            let w = fv.map(|j| t[j]);
            let k = key3(w);
            match open.remove(&k) {
                Some(o) if !crate::flips::same_cycle(o, w) => {}
                Some(_) => {
                    tracing::debug!(?w, "verify: a face twice from one side");
                    return None;
                }
                None => {
                    open.insert(k, w);
                }
            }
        }
    }
    if open.len() != faces.len() {
        tracing::debug!(open = open.len(), faces = faces.len(), "verify: open faces");
        return None;
    }
    let o = pts[faces[0][0] as usize];
    let mut cav = 0.0;
    for f in faces {
        // A cavity face's outward tet face is the face reversed.
        let w = *open.get(&key3(*f))?;
        if !crate::flips::same_cycle([f[0], f[2], f[1]], w) {
            return None;
        }
        let p = f.map(|v| pts[v as usize]);
        cav += orient3d(p[0], p[1], p[2], o);
    }
    tracing::debug!(vol, cav, "verify: volumes");
    let ok = tets.iter().flatten().all(|&v| (v as usize) < pts.len())
        && (vol - cav).abs() <= 1e-9 * cav.abs().max(f64::MIN_POSITIVE);
    ok.then_some(())
}
