//! §7 pass 4: what the parallel passes left, meshed serially on part 0,
//! with layers peeled off around faces that stay stuck; and the peeling of
//! the tets about stuck faces between passes.
use super::*;

/// Between passes (§7 needs room as much as pass 4 does): a face stuck in
/// pass j is a face of an older tet, which pass j+1's front cannot remove.
/// Every part removes its tets with three points or more among the stuck
/// faces' points (the ids go out by all-gather): the tets on the stuck
/// faces and those wedged between them. Their faces join the part's front,
/// and opposite pairs over all fronts cancel ([`cancel_across`]). Returns
/// the tets removed.
pub(super) fn peel_stuck<C: Comm>(parts: &mut [Part], comm: &C) -> usize {
    let marked: Vec<Vec<u32>> = parts
        .iter_mut()
        .map(|p| std::mem::take(&mut p.stuck))
        .collect();
    let mut marked: Vec<u32> = comm.all_gather(marked).concat();
    if marked.is_empty() {
        return 0;
    }
    marked.sort_unstable();
    marked.dedup();
    let marked: rustc_hash::FxHashSet<u32> = marked.into_iter().collect();
    let removed: Vec<usize> = parts
        .par_iter_mut()
        .map(|part| {
            let (removed, mut faces) = remove_touching(part, &marked, PEEL_MARKED);
            faces.append(&mut part.front);
            part.front = faces;
            removed
        })
        .collect();
    let removed = comm.all_reduce(removed, |a, b| a + b);
    cancel_across(parts, comm);
    removed
}

/// Cancels the opposite pairs of faces over all parts' fronts, each face
/// staying with its part. Only the faces' global ids travel: each goes to
/// a part picked by its point set, which finds the pairs as
/// [`cancel_pairs`] does over the faces it got (by sender, then in each
/// sender's order) and answers which ones go. The faces themselves, as
/// located points, were 124 bytes each, and their messages raised a
/// process's peak by 17 MiB (an MPI rank's, sphere_5e6 at 4 ranks) to
/// 51 MiB (one process) after pass 1.
fn cancel_across<C: Comm>(parts: &mut [Part], comm: &C) {
    let np = comm.parts();
    let key_part = |g: [u32; 3]| {
        let mut g = g.map(u64::from);
        g.sort_unstable();
        let h = g[0]
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(g[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_add(g[2].wrapping_mul(0x1656_67B1_9E37_79F9));
        ((h >> 32) % np as u64) as u32
    };
    // Per part, its faces by key part (face order kept): the global ids
    // out, the face indices kept for the answer.
    type Sent = (Vec<(u32, Vec<[u32; 3]>)>, Vec<Vec<u32>>);
    let sent: Vec<Sent> = parts
        .par_iter()
        .map(|part| {
            let gids = |f: &[u32; 3]| f.map(|i| part.gid[i as usize]);
            let mut to: Vec<(u32, u32)> = part
                .front
                .iter()
                .enumerate()
                .map(|(i, f)| (key_part(gids(f)), i as u32))
                .collect();
            to.sort_by_key(|x| x.0);
            let mut out = Vec::new();
            let mut idx = Vec::new();
            for group in to.chunk_by(|a, b| a.0 == b.0) {
                let faces = group.iter().map(|&(_, i)| gids(&part.front[i as usize]));
                out.push((group[0].0, faces.collect()));
                idx.push(group.iter().map(|&(_, i)| i).collect());
            }
            (out, idx)
        })
        .collect();
    let (out, idx): (Vec<_>, Vec<_>) = sent.into_iter().unzip();
    let inboxes = comm.exchange(out);
    // Per key part, per sender, the positions of the faces that go.
    let answers: Vec<Vec<(u32, Vec<u32>)>> = inboxes
        .into_par_iter()
        .map(|inbox| {
            let all: Vec<[u32; 3]> = inbox.iter().flat_map(|m| m.1.iter().copied()).collect();
            let gone = cancelled(all.len(), |i| all[i]);
            let mut at = 0;
            inbox
                .iter()
                .map(|(src, faces)| {
                    let n = faces.len();
                    let out = (0..n).filter(|&j| gone[at + j]).map(|j| j as u32).collect();
                    at += n;
                    (*src, out)
                })
                .collect()
        })
        .collect();
    let answers = comm.exchange(answers);
    parts
        .par_iter_mut()
        .zip(answers)
        .zip(idx)
        .for_each(|((part, answer), idx)| {
            // The answers come by key part, as the faces went.
            let mut drop = vec![false; part.front.len()];
            for ((_, gone), sent) in answer.iter().zip(&idx) {
                for &j in gone {
                    drop[sent[j as usize] as usize] = true;
                }
            }
            retain_unflagged(&mut part.front, &drop);
        });
}

/// A peel around stuck faces removes the tets with this many points among
/// theirs. Every tet touching one (a full layer) made pass 4 five times
/// larger (sphere_1e5, P = 8: 5.0 % against 0.7 %), most of it tets
/// peeled and made again.
pub(super) const PEEL_MARKED: usize = 3;

/// Removes the part's tets with at least `min_marked` points in `marked`
/// (global ids); returns how many and their faces (local ids), oriented
/// into the hole. The kept tets stay where they are: no copy of the
/// part's tets.
pub(super) fn remove_touching(
    part: &mut Part,
    marked: &rustc_hash::FxHashSet<u32>,
    min_marked: usize,
) -> (usize, Vec<[u32; 3]>) {
    // Faces of a positive tet, oriented into the tet (into the hole).
    const INWARD: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];
    let mut out = Vec::new();
    let passes = std::mem::take(&mut part.tet_pass);
    let mut pass = passes.iter();
    let tets = std::mem::take(&mut part.tets);
    let gid = &part.gid;
    let tet_pass = &mut part.tet_pass;
    part.tets = tets
        .iter()
        .filter(|tv| {
            let p = pass.next().expect("a pass for every tet");
            let hits = tv
                .iter()
                .filter(|&&i| marked.contains(&gid[i as usize]))
                .count();
            if hits >= min_marked {
                out.extend(INWARD.map(|f| f.map(|c| tv[c])));
                false
            } else {
                tet_pass.push_n(p, 1);
                true
            }
        })
        .collect();
    (tets.len() - part.tets.len(), out)
}

/// A front over global points, numbered locally in the order the points
/// are first met, with the global id of each local point.
pub(super) fn local_front(faces: impl Iterator<Item = [Rec; 3]>) -> (FrontInput, Vec<u32>) {
    let mut index: FxHashMap<u32, u32> = FxHashMap::default();
    let (mut points, mut point_size, mut gids) = (Vec::new(), Vec::new(), Vec::new());
    let faces = faces
        .map(|v| {
            v.map(|r| {
                *index.entry(r.gid).or_insert_with(|| {
                    points.push(r.p);
                    point_size.push(r.h);
                    gids.push(r.gid);
                    points.len() as u32 - 1
                })
            })
        })
        .collect();
    (
        FrontInput {
            points,
            point_size,
            faces,
        },
        gids,
    )
}

/// Cancels opposite pairs of faces (the hole on both sides).
pub(super) fn cancel_pairs(hole: &mut Vec<[Rec; 3]>) {
    let gone = cancelled(hole.len(), |i| hole[i].map(|r| r.gid));
    retain_unflagged(hole, &gone);
}

/// Which of `n` faces (global ids of face `i`: `gids(i)`) cancel: sorted
/// by the unordered triple, the two orientations match one for one, in
/// face order.
fn cancelled(n: usize, gids: impl Fn(usize) -> [u32; 3]) -> Vec<bool> {
    let canon = |g: [u32; 3]| {
        let r = (0..3).min_by_key(|&k| g[k]).unwrap();
        let (a, b, c) = (g[r], g[(r + 1) % 3], g[(r + 2) % 3]);
        if b < c {
            ((a, b, c), true)
        } else {
            ((a, c, b), false)
        }
    };
    let mut order: Vec<(u32, u32, u32, bool, usize)> = (0..n)
        .map(|i| {
            let (k, o) = canon(gids(i));
            (k.0, k.1, k.2, o, i)
        })
        .collect();
    order.sort_unstable();
    let mut gone = vec![false; n];
    for group in order.chunk_by(|x, y| (x.0, x.1, x.2) == (y.0, y.1, y.2)) {
        let pos = group.iter().filter(|x| x.3).map(|x| x.4);
        let neg = group.iter().filter(|x| !x.3).map(|x| x.4);
        for (a, b) in pos.zip(neg) {
            gone[a] = true;
            gone[b] = true;
        }
    }
    gone
}

/// Recovery rounds of pass 4's tries; a layer is peeled before each try
/// after the first.
pub(super) const PASS4_ROUNDS: [u32; 5] = [1, 12, 12, 12, 60];

/// Pass 4: every part sends what is left of its front to part 0, which
/// closes it with the serial front (recovery on). What passes 1 to 3 left
/// are faces the front could not advance without recovery, and recovery
/// can only remove tets of its own call: so the parts first remove the
/// tets touching the left-over front (one layer, one more per try when the
/// serial front still gets stuck) and send their faces along.
/// `rounds`: the recovery rounds of each try. Returns the tets made and
/// the tets removed.
pub(super) fn serial_pass<C: Comm>(
    parts: &mut [Part],
    comm: &C,
    size: Sizes<'_>,
    next_gid: &mut u32,
    rounds: &[u32],
    fill_after: u32,
) -> Result<(usize, usize), PassError> {
    let last = rounds.len() - 1;
    // Part 0's process runs the front; the others follow its choices.
    let here = comm.holds(0);
    let out: Vec<Vec<(u32, [Rec; 3])>> = parts
        .iter_mut()
        .map(|p| {
            let faces = std::mem::take(&mut p.front);
            faces.iter().map(|f| (0u32, f.map(|i| p.rec(i)))).collect()
        })
        .collect();
    let mut inbox = comm.exchange(out);
    let mut hole: Vec<[Rec; 3]> = if here {
        inbox.swap_remove(0).into_iter().map(|m| m.1).collect()
    } else {
        Vec::new()
    };
    if comm.all_reduce(parts.iter().map(|_| hole.len()).collect(), usize::max) == 0 {
        return Ok((0, 0));
    }
    let mut removed = 0;
    // The front left over is what the passes could not advance: a first
    // try without room spends long in recovery, so peel from the start.
    // Room first only around the faces that got stuck in a pass (peeled
    // before pass 4 already); then, when the serial front still gets stuck,
    // around the faces it could not close.
    let mut peel = 0;
    let mut around: Option<Vec<u32>> = None;
    loop {
        if peel > 0 {
            // Around what the last try left, wider on each try (tets with
            // 3, then 2 points there, then all touching it), or a whole
            // layer.
            let m = if around.is_some() {
                PEEL_MARKED.saturating_sub(peel - 1).max(1)
            } else {
                1
            };
            removed += peel_layer(parts, comm, &mut hole, around.take(), m);
        }
        let step = if here {
            pass4_try(&hole, size, rounds[peel], peel < last, fill_after)
        } else {
            Try4::Elsewhere
        };
        // Part 0's choice, for every process: closed (its new points), stuck
        // again (the older points around what is left) or failed.
        let said: Vec<(u8, u32, Vec<u32>, String)> = comm.all_gather(
            (0..parts.len())
                .map(|i| match (&step, i) {
                    (Try4::Closed(m), 0) => (0, m.new_points(), Vec::new(), String::new()),
                    (Try4::Stuck(g), 0) => (1, 0, g.clone(), String::new()),
                    (Try4::Failed(e), 0) => (2, 0, Vec::new(), e.to_string()),
                    _ => (3, 0, Vec::new(), String::new()),
                })
                .collect(),
        );
        let (code, n_new, g, message) = said.into_iter().next().unwrap_or_default();
        match (code, step) {
            (0, step) => {
                let n = match step {
                    Try4::Closed(m) => absorb(&mut parts[0], *m, *next_gid, 4),
                    _ => 0,
                };
                *next_gid += n_new;
                return Ok((n, removed));
            }
            (1, _) => {
                around = (!g.is_empty()).then_some(g);
                peel += 1;
            }
            (_, Try4::Failed(source)) => {
                return Err(PassError::Pass {
                    pass: 4,
                    part: 0,
                    source,
                })
            }
            _ => {
                return Err(PassError::Remote {
                    part: 0,
                    message,
                    pass_failed: true,
                })
            }
        }
    }
}

/// One try of pass 4's front on part 0, and what came of it.
enum Try4 {
    Closed(Box<Made>),
    /// Stuck: the global ids of the older points around what it left.
    Stuck(Vec<u32>),
    Failed(FrontError),
    /// Part 0 is held by another process.
    Elsewhere,
}

/// Pass 4's front on `hole` with `rounds` of recovery; `retry`: a stuck
/// front gives back the points around what it left instead of an error.
fn pass4_try(
    hole: &[[Rec; 3]],
    size: Sizes<'_>,
    rounds: u32,
    retry: bool,
    fill_after: u32,
) -> Try4 {
    let (input, gids) = local_front(hole.iter().copied());
    let t0 = Instant::now();
    let res = advance(
        input,
        SizeMode::Field(size.field),
        &Everywhere,
        &FrontOptions {
            // Bounded: peeling a layer is the better next step. The first
            // try removes only its own tets once: recovery's pocket
            // filling (round 2 on) trips on some left-over fronts.
            recovery_rounds: rounds,
            keep_partial: retry,
            max_growth: size.max_growth,
            fill_after,
            ..FrontOptions::default()
        },
    );
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!(
            "pass 4: a try on {} faces: {}",
            hole.len(),
            if res.is_ok() { "closed" } else { "stuck" }
        );
    }
    match res {
        Ok(r) => Try4::Closed(Box::new(Made {
            stuck: Vec::new(),
            input_ok: vec![true; gids.len()],
            input_gid: gids,
            res: Some(r),
            seconds: t0.elapsed().as_secs_f64(),
        })),
        Err(FrontError::Stuck { partial, .. }) if retry => {
            // The older points of the faces left: recovery could not
            // remove the tets of the passes around them.
            let mut g: Vec<u32> = partial
                .iter()
                .flat_map(|p| p.front.iter().flatten())
                .filter(|&&i| (i as usize) < gids.len())
                .map(|&i| gids[i as usize])
                .collect();
            g.sort_unstable();
            g.dedup();
            if tracing::enabled!(tracing::Level::DEBUG) {
                tracing::debug!(
                    "pass 4: {} faces left, {} older points",
                    partial.as_ref().map_or(0, |p| p.front.len()),
                    g.len()
                );
            }
            Try4::Stuck(g)
        }
        Err(e) => Try4::Failed(e),
    }
}

/// Removes, in every part, the tets with `min_marked` points among
/// `around` (all points of `hole` if `None`; the ids go out by all-gather)
/// and adds their faces to `hole` (sent to part 0), cancelling the faces
/// that now have the hole on both sides. Returns the tets removed.
pub(super) fn peel_layer<C: Comm>(
    parts: &mut [Part],
    comm: &C,
    hole: &mut Vec<[Rec; 3]>,
    around: Option<Vec<u32>>,
    min_marked: usize,
) -> usize {
    let marked = around.unwrap_or_else(|| {
        let mut m: Vec<u32> = hole.iter().flatten().map(|r| r.gid).collect();
        m.sort_unstable();
        m.dedup();
        m
    });
    // Part 0 holds the hole; every part gets its points.
    let marked = comm.all_gather(vec![marked; parts.len()]).swap_remove(0);
    let marked: rustc_hash::FxHashSet<u32> = marked.into_iter().collect();
    let out: Vec<Vec<(u32, [Rec; 3])>> = parts
        .par_iter_mut()
        .map(|part| {
            let (_, faces) = remove_touching(part, &marked, min_marked);
            let rec = |f: [u32; 3]| f.map(|i| part.rec(i));
            faces.into_iter().map(|f| (0u32, rec(f))).collect()
        })
        .collect();
    let mut inbox = comm.exchange(out);
    let here = comm.holds(0);
    let inbox = if here {
        inbox.swap_remove(0)
    } else {
        Vec::new()
    };
    let removed = comm.all_reduce(parts.iter().map(|_| inbox.len() / 4).collect(), usize::max);
    hole.extend(inbox.into_iter().map(|m| m.1));
    cancel_pairs(hole);
    removed
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_comm::Threads;

    /// A part holding `tets` and `front` over the points `pts` (global id =
    /// index), with `stuck` as its last call's stuck points.
    fn part(pts: &[P3], tets: &[[u32; 4]], front: &[[u32; 3]], stuck: &[u32]) -> Part {
        let mut p = Part::default();
        let mut local = |g: u32| {
            p.local(Rec {
                gid: g,
                p: pts[g as usize],
                h: 1.0,
            })
        };
        let tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(&mut local)).collect();
        let front: Vec<[u32; 3]> = front.iter().map(|f| f.map(&mut local)).collect();
        p.tet_pass.push_n(1, tets.len());
        (p.tets, p.front, p.stuck) = (tets.into_iter().collect(), front, stuck.to_vec());
        p
    }

    fn front_gids(p: &Part) -> Vec<[u32; 3]> {
        p.front
            .iter()
            .map(|f| f.map(|i| p.gid[i as usize]))
            .collect()
    }

    #[test]
    fn a_peel_cancels_the_faces_of_removed_tets_against_other_parts_fronts() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        // Tet A (part 0) and tet B (part 1) share face 0 1 2. The front
        // over A's other faces, facing out of A, is held by the last part,
        // with a face of B's and the same face of A's twice more: once as
        // A's face into A (no pair left for it), once facing out again.
        let a = [0, 1, 2, 3];
        let b = [0, 2, 1, 4];
        let out_of_a = [[1, 2, 3], [0, 3, 2], [0, 1, 3]];
        for np in [2usize, 3, 5] {
            let mut held: Vec<[u32; 3]> = out_of_a.to_vec();
            held.extend([[0, 1, 4], [1, 3, 2]]);
            let mut parts: Vec<Part> = (0..np)
                .map(|k| match k {
                    0 => part(&pts, &[a], &[], &[0, 1, 3]),
                    1 => part(&pts, &[b], &[], &[]),
                    _ => Part::default(),
                })
                .collect();
            let last = parts.len() - 1;
            parts[last] = if last == 1 {
                part(&pts, &[b], &held, &[])
            } else {
                part(&pts, &[], &held, &[])
            };
            let removed = peel_stuck(&mut parts, &Threads::new(np));
            // A had three stuck points, B two.
            assert_eq!(removed, 1, "{np} parts");
            assert_eq!(parts[0].tets.len(), 0);
            assert_eq!(parts[1].tets.len(), 1);
            // A's faces into the hole: 0 1 2 stays (B is behind it); its
            // three others cancel the three faces out of A, one for one,
            // so that the held face 1 3 2 (into A, like A's own) stays.
            assert_eq!(front_gids(&parts[0]), vec![[0, 1, 2]], "{np} parts");
            assert_eq!(
                front_gids(&parts[last]),
                vec![[0, 1, 4], [1, 3, 2]],
                "{np} parts"
            );
            for p in &parts {
                assert_eq!(p.check(), Ok(()));
            }
        }
    }

    /// The kept tets keep their order and their passes.
    #[test]
    fn removing_tets_keeps_the_others_passes() {
        let pts: Vec<P3> = (0..8).map(|i| [i as f64, (i * i) as f64, 0.0]).collect();
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5], [4, 5, 6, 7]];
        let mut p = part(&pts, &tets, &[], &[]);
        p.tet_pass = TetPasses::default();
        for pass in [1, 2, 2, 3] {
            p.tet_pass.push_n(pass, 1);
        }
        // Points 0 and 1 mark the first tet; 6 and 7 the last.
        let marked: rustc_hash::FxHashSet<u32> = [0, 1, 6, 7].into_iter().collect();
        let (removed, faces) = remove_touching(&mut p, &marked, 2);
        assert_eq!((removed, faces.len()), (2, 8));
        let kept: Vec<[u32; 4]> = p
            .tets
            .iter()
            .map(|t| t.map(|i| p.gid[i as usize]))
            .collect();
        assert_eq!(kept, vec![[1, 2, 3, 4], [2, 3, 4, 5]]);
        assert_eq!(p.tet_pass.to_vec(), vec![2, 2]);
        assert_eq!(p.check(), Ok(()));
    }

    #[test]
    fn pairs_cancel_one_for_one_in_face_order() {
        // Two faces one way round, one the other: the first two cancel.
        let gone = cancelled(4, |i| [[1, 2, 3], [2, 3, 1], [3, 2, 1], [4, 5, 6]][i]);
        assert_eq!(gone, vec![true, false, true, false]);
    }
}
