//! §7: the pockets a pass leaves inside its own part, closed by the front
//! with recovery on, and the tets they make taken into the part.
use super::*;

/// Largest pocket (faces) a pass closes itself.
pub(super) const MAX_POCKET: usize = 4000;
/// Recovery rounds a pocket gets (the serial front's default is 60): the
/// removal round and one of kernel cones. Most pockets that close at all
/// close there; the late rounds' patch cones cost 30 ms or more per pocket
/// that stays stuck, and with 8 rounds they took 70 % of pass 2's time
/// (sphere_1e6 at 0.036, P = 8: pockets 6.8 s, 0.16 s with 2 rounds). What
/// stays open goes to the next pass.
pub(super) const POCKET_ROUNDS: u32 = 2;

/// Recovery inside a pass (§7 needs it as much as the serial front does):
/// the faces a pass could not advance without relaxing its acceptance are
/// left behind, and many form small closed pockets inside the part's own
/// region. Each such pocket (an edge-connected set of faces the part owns,
/// closed on its own, facing in, small) is closed here by the front with
/// recovery on: a closed front bounds what it fills, so no filter is
/// needed. A pocket that stays stuck is left as it was for the next pass.
/// Returns the tets made.
pub(super) fn close_pockets(
    res: &mut parafront_front::FrontResult,
    ok: impl Fn(u32) -> bool,
    size: &(dyn Fn(P3) -> f64 + Sync),
) -> usize {
    let own: Vec<usize> = (0..res.front.len())
        .filter(|&f| res.front[f].iter().all(|&i| ok(i)))
        .collect();
    if own.is_empty() {
        return 0;
    }
    let comp = components(&res.front, &own);
    let mut done = vec![false; res.front.len()];
    let mut made = 0;
    let mut i = 0;
    while i < comp.len() {
        let mut j = i;
        while j < comp.len() && comp[j].0 == comp[i].0 {
            j += 1;
        }
        let faces: Vec<[u32; 3]> = comp[i..j].iter().map(|c| res.front[c.1]).collect();
        if is_pocket(res, &faces) && embedded(res, &faces) {
            if let Some(n) = fill_pocket(res, &faces, size) {
                made += n;
                for c in &comp[i..j] {
                    done[c.1] = true;
                }
            }
        }
        i = j;
    }
    retain_unflagged(&mut res.front, &done);
    made
}

/// The faces `own` of `front` in components through shared edges
/// (union-find): `(component, face)`, sorted by component.
fn components(front: &[[u32; 3]], own: &[usize]) -> Vec<(usize, usize)> {
    let mut up: Vec<usize> = (0..own.len()).collect();
    fn root(up: &mut [usize], mut x: usize) -> usize {
        while up[x] != x {
            up[x] = up[up[x]];
            x = up[x];
        }
        x
    }
    let mut edges: Vec<(u32, u32, usize)> = Vec::with_capacity(own.len() * 3);
    for (j, &f) in own.iter().enumerate() {
        let v = front[f];
        for c in 0..3 {
            let (a, b) = (v[c], v[(c + 1) % 3]);
            edges.push((a.min(b), a.max(b), j));
        }
    }
    edges.sort_unstable();
    for w in edges.windows(2) {
        if (w[0].0, w[0].1) == (w[1].0, w[1].1) {
            let (a, b) = (root(&mut up, w[0].2), root(&mut up, w[1].2));
            if a != b {
                up[a.max(b)] = a.min(b);
            }
        }
    }
    let mut comp: Vec<(usize, usize)> =
        (0..own.len()).map(|j| (root(&mut up, j), own[j])).collect();
    comp.sort_unstable();
    comp
}

/// A pocket: closed on its own (every directed edge as often as its
/// reverse), facing in (negative signed volume), small (about a tet per
/// face, and at most [`MAX_POCKET`] faces). A large closed set may wrap
/// another part's region, and one facing out bounds the rest of the
/// region: both wait for the next pass.
fn is_pocket(res: &parafront_front::FrontResult, faces: &[[u32; 3]]) -> bool {
    let mut e: Vec<(u32, u32)> = Vec::with_capacity(faces.len() * 3);
    for v in faces {
        for c in 0..3 {
            e.push((v[c], v[(c + 1) % 3]));
        }
    }
    e.sort_unstable();
    let closed = e.iter().all(|&(a, b)| {
        let n = |x: (u32, u32)| e.partition_point(|y| *y <= x) - e.partition_point(|y| *y < x);
        n((a, b)) == n((b, a))
    });
    let mut vol = 0.0;
    let mut hsum = 0.0;
    for f in faces {
        let [a, b, c] = f.map(|i| res.points[i as usize]);
        vol += parafront_geom::dot(a, parafront_geom::cross(b, c)) / 6.0;
        hsum += f.iter().map(|&i| res.point_size[i as usize]).sum::<f64>() / 3.0;
    }
    let hm = hsum / faces.len() as f64;
    let pocket = vol < 0.0 && -vol <= faces.len() as f64 * hm * hm * hm;
    if tracing::enabled!(tracing::Level::DEBUG) && closed {
        tracing::debug!(
            "pocket: {} faces, vol {vol:.3e}, h {hm:.3e}, taken {}",
            faces.len(),
            pocket && faces.len() <= MAX_POCKET
        );
    }
    closed && pocket && faces.len() <= MAX_POCKET
}

/// Pockets up to this many faces are checked for faces that cross (a
/// quadratic test).
const CHECKED_POCKET: usize = 256;

/// No two faces of a small pocket meet other than along the edges and
/// corners they share. A component of the part's faces can be closed and
/// still cross itself; no front or fill closes it, and trying cost pass 2
/// of sphere_1e6 at size 0.037, on 2 parts, 0.36 s of its 0.47.
fn embedded(res: &parafront_front::FrontResult, faces: &[[u32; 3]]) -> bool {
    use parafront_geom::intersect::faces_meet;
    if faces.len() > CHECKED_POCKET {
        return true;
    }
    let boxes: Vec<parafront_geom::Aabb> = faces
        .iter()
        .map(|f| parafront_geom::Aabb::from_points(f.iter().map(|&v| &res.points[v as usize])))
        .collect();
    for i in 0..faces.len() {
        for j in i + 1..faces.len() {
            if !boxes[i].overlaps(&boxes[j]) {
                continue;
            }
            let (a, b) = (faces[i], faces[j]);
            // A face twice (from either side) is no crossing.
            let twice = a.iter().all(|v| b.contains(v));
            if !twice && faces_meet(a, b, &res.points) {
                return false;
            }
        }
    }
    true
}

/// Close pocket `faces` by the front with recovery on, adding its points
/// and tets to `res`; the tets made, or `None` when it stays open.
fn fill_pocket(
    res: &mut parafront_front::FrontResult,
    faces: &[[u32; 3]],
    size: &(dyn Fn(P3) -> f64 + Sync),
) -> Option<usize> {
    let mut pts: Vec<u32> = faces.iter().flatten().copied().collect();
    pts.sort_unstable();
    pts.dedup();
    let local = |p: u32| pts.binary_search(&p).unwrap() as u32;
    let r = advance(
        FrontInput {
            points: pts.iter().map(|&p| res.points[p as usize]).collect(),
            point_size: pts.iter().map(|&p| res.point_size[p as usize]).collect(),
            faces: faces.iter().map(|f| f.map(local)).collect(),
        },
        SizeMode::Field(size),
        &Everywhere,
        &FrontOptions {
            recovery_rounds: POCKET_ROUNDS,
            max_points: 50 * faces.len() + pts.len(),
            ..FrontOptions::default()
        },
    )
    .ok()?;
    if !r.front.is_empty() {
        return None;
    }
    let base = res.points.len() as u32;
    let n = pts.len();
    res.points.extend_from_slice(&r.points[n..]);
    res.point_size.extend_from_slice(&r.point_size[n..]);
    let map = |q: u32| {
        if (q as usize) < n {
            pts[q as usize]
        } else {
            base + q - n as u32
        }
    };
    res.tets.extend(r.tets.iter().map(|t| t.map(map)));
    Some(r.tets.len())
}

/// Takes a front call's tets, new points (global ids from `base`) and the
/// remaining faces it owns into the part's store. Context faces come back
/// untouched and are dropped: their holder still has them.
pub(super) fn absorb(part: &mut Part, m: Made, base: u32, pass: u8) -> usize {
    let a = absorb_local(part, m, pass);
    absorb_finish(part, &a, base);
    a.tets
}

/// A front call taken into its part before its new points have global
/// ids (they come from every part's count): [`absorb_finish`] gives them.
pub(super) struct Absorbed {
    /// The part's local id of the first new point; the rest follow.
    first_new: u32,
    pub(super) new_points: u32,
    pub(super) tets: usize,
    /// Local ids of the stuck faces' points, to be given as global ids.
    stuck: Vec<u32>,
    pub(super) seconds: f64,
}

/// [`absorb`] up to the new points' global ids: the tets, the faces and
/// the points go into the part at once, so that a part's result is not
/// held beside the next part's front (its adjacency was a sixth of an MPI
/// rank's peak).
pub(super) fn absorb_local(part: &mut Part, m: Made, pass: u8) -> Absorbed {
    let Some(r) = m.res else {
        return Absorbed {
            first_new: 0,
            new_points: 0,
            tets: 0,
            stuck: Vec::new(),
            seconds: m.seconds,
        };
    };
    let n_in = m.input_gid.len();
    // Room made once: grown by doubling, the part's arrays were copied
    // while the pass's other results waited (a rank's peak under MPI).
    let n_new = r.points.len().saturating_sub(n_in);
    part.pts.reserve_exact(n_new);
    part.size.reserve_exact(n_new);
    part.gid.reserve_exact(n_new);
    let ok = |i: u32| (i as usize) >= n_in || m.input_ok[i as usize];
    let kept = |f: &[u32; 3]| f.iter().all(|&i| ok(i));
    // Only the input points a tet or a kept face names join the part: the
    // context faces' other points stay with their holders (at 64 parts,
    // the parts' copies of them were a third of sphere_1e6's peak).
    let mut named = vec![false; n_in];
    let kept_faces = r.front.iter().filter(|f| kept(f));
    for &i in r.tets.iter().flatten().chain(kept_faces.flatten()) {
        if let Some(x) = named.get_mut(i as usize) {
            *x = true;
        }
    }
    let mut map: Vec<u32> = (0..n_in)
        .map(|i| {
            if !named[i] {
                return u32::MAX;
            }
            part.local(Rec {
                gid: m.input_gid[i],
                p: r.points[i],
                h: r.point_size[i],
            })
        })
        .collect();
    drop(named);
    // The new points are new to the part: pushed in order, indexed later.
    let first_new = part.pts.len() as u32;
    for i in n_in..r.points.len() {
        map.push(part.pts.len() as u32);
        part.pts.push(r.points[i]);
        part.size.push(r.point_size[i]);
        part.gid.push(u32::MAX);
    }
    let mut stuck = Vec::new();
    for (j, f) in r.front.iter().enumerate() {
        if kept(f) {
            part.front.push(f.map(|i| map[i as usize]));
            if m.stuck.get(j) == Some(&true) {
                stuck.extend(f.map(|i| map[i as usize]));
            }
        }
    }
    let n = r.tets.len();
    part.tets
        .extend(r.tets.into_iter().map(|t| t.map(|i| map[i as usize])));
    part.tet_pass.push_n(pass, n);
    Absorbed {
        first_new,
        new_points: n_new as u32,
        tets: n,
        stuck,
        seconds: m.seconds,
    }
}

/// The new points of `a` get their global ids from `base`, and the stuck
/// faces' points theirs.
pub(super) fn absorb_finish(part: &mut Part, a: &Absorbed, base: u32) {
    for k in 0..a.new_points {
        part.gid[(a.first_new + k) as usize] = base + k;
    }
    part.index.insert_run(base, a.first_new, a.new_points);
    part.stuck
        .extend(a.stuck.iter().map(|&l| part.gid[l as usize]));
}

/// Whether face `f` of a pass's result got stuck: the region rules of §7
/// let the front try it (points and edges inside, the ideal point inside,
/// computed as the front does), but no tet was accepted.
pub(super) fn is_stuck(
    res: &parafront_front::FrontResult,
    f: [u32; 3],
    filter: &dyn RegionFilter,
) -> bool {
    use parafront_geom::{add, cross, dist, normalize, scale, sub};
    let p = f.map(|i| res.points[i as usize]);
    let inside = p.iter().all(|&q| filter.point_ok(q))
        && filter.edge_ok(p[0], p[1])
        && filter.edge_ok(p[1], p[2])
        && filter.edge_ok(p[2], p[0]);
    if !inside {
        return false;
    }
    let nrm = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    let m = [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
    let emax = dist(p[0], p[1]).max(dist(p[1], p[2])).max(dist(p[2], p[0]));
    let h = (f.iter().map(|&i| res.point_size[i as usize]).sum::<f64>() / 3.0).min(2.0 * emax);
    let dm = (dist(m, p[0]) + dist(m, p[1]) + dist(m, p[2])) / 3.0;
    let alpha = (h * h - dm * dm).max(0.25 * dm * dm).sqrt();
    filter.point_ok(add(m, scale(nrm, alpha)))
}

#[cfg(test)]
mod absorb_tests {
    use super::*;
    use parafront_front::{FrontResult, FrontStats};

    /// A front call's input points that no tet and no kept face names (its
    /// context faces' far corners) stay out of the part; the rest keep
    /// their order, and the new points follow them.
    #[test]
    fn only_the_points_a_tet_or_a_kept_face_names_join_the_part() {
        let p = |i: u32| [i as f64, (i * i) as f64, 1.0];
        // Inputs 0..6 (global ids 100..106), input 5 outside the part; new
        // point 6. Tet on 0, 2, 3, 6; kept face 3, 4, 6; face 1, 5, 6 is
        // dropped (5 is outside), so 1 and 5 are named by nothing kept.
        let res = FrontResult {
            points: (0..7).map(p).collect(),
            point_size: vec![0.5; 7],
            tets: vec![[0, 2, 3, 6]],
            neigh: Vec::new(),
            front: vec![[3, 4, 6], [1, 5, 6]],
            stats: FrontStats::default(),
        };
        let made = Made {
            res: Some(res),
            input_gid: (100..106).collect(),
            input_ok: vec![true, true, true, true, true, false],
            stuck: vec![true, false],
            seconds: 0.0,
        };
        let mut part = Part::default();
        let a = absorb_local(&mut part, made, 2);
        absorb_finish(&mut part, &a, 500);
        assert_eq!(part.gid, vec![100, 102, 103, 104, 500]);
        assert_eq!(part.pts, [0, 2, 3, 4, 6].map(p).to_vec());
        assert_eq!(part.tets.to_vec(), vec![[0, 1, 2, 4]]);
        assert_eq!(part.front, vec![[2, 3, 4]]);
        assert_eq!(part.stuck, vec![103, 104, 500]);
        assert_eq!(part.tet_pass.to_vec(), vec![2]);
        part.check().expect("a sound part");
    }
}
