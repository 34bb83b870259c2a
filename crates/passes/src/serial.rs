//! §7 pass 4: what the parallel passes left, meshed serially on part 0,
//! with layers peeled off around faces that stay stuck; and the peeling of
//! the tets about stuck faces between passes.
use super::*;

/// Between passes (§7 needs room as much as pass 4 does): a face stuck in
/// pass j is a face of an older tet, which pass j+1's front cannot remove.
/// Every part removes its tets with three points or more among the stuck
/// faces' points (the ids go out by all-gather): the tets on the stuck
/// faces and those wedged between them. The faces of the removed tets and
/// the whole front go by an exact key to one part, where opposite pairs
/// cancel. Returns the tets removed.
pub(super) fn peel_stuck<C: Comm>(parts: &mut [Part], comm: &C) -> usize {
    let np = comm.parts();
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
    let key_part = |v: &[Rec; 3]| {
        let mut g = v.map(|r| r.gid as u64);
        g.sort_unstable();
        let h = g[0]
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(g[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_add(g[2].wrapping_mul(0x1656_67B1_9E37_79F9));
        ((h >> 32) % np as u64) as u32
    };
    type Out = (usize, Vec<(u32, [Rec; 3])>);
    let out: Vec<Out> = parts
        .par_iter_mut()
        .map(|part| {
            let (removed, faces) = remove_touching(part, &marked, PEEL_MARKED);
            let mut out: Vec<(u32, [Rec; 3])> =
                faces.into_iter().map(|v| (key_part(&v), v)).collect();
            for f in std::mem::take(&mut part.front) {
                let v = f.map(|i| part.rec(i));
                out.push((key_part(&v), v));
            }
            (removed, out)
        })
        .collect();
    let removed = comm.all_reduce(out.iter().map(|o| o.0).collect(), |a, b| a + b);
    let inboxes = comm.exchange(out.into_iter().map(|o| o.1).collect());
    parts.par_iter_mut().zip(inboxes).for_each(|(part, inbox)| {
        let mut hole: Vec<[Rec; 3]> = inbox.into_iter().map(|m| m.1).collect();
        cancel_pairs(&mut hole);
        part.front = hole.into_iter().map(|v| v.map(|r| part.local(r))).collect();
    });
    removed
}

/// A peel around stuck faces removes the tets with this many points among
/// theirs. Every tet touching one (a full layer) made pass 4 five times
/// larger (sphere_1e5, P = 8: 5.0 % against 0.7 %), most of it tets
/// peeled and made again.
pub(super) const PEEL_MARKED: usize = 3;

/// Removes the part's tets with at least `min_marked` points in `marked`
/// (global ids); returns how many and their faces, oriented into the hole.
pub(super) fn remove_touching(
    part: &mut Part,
    marked: &rustc_hash::FxHashSet<u32>,
    min_marked: usize,
) -> (usize, Vec<[Rec; 3]>) {
    // Faces of a positive tet, oriented into the tet (into the hole).
    const INWARD: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];
    let mut out = Vec::new();
    let mut keep_t = Vec::with_capacity(part.tets.len());
    let mut keep_p = Vec::with_capacity(part.tets.len());
    for (t, tv) in part.tets.iter().enumerate() {
        if tv
            .iter()
            .filter(|&&i| marked.contains(&part.gid[i as usize]))
            .count()
            >= min_marked
        {
            for f in INWARD {
                out.push(f.map(|c| part.rec(tv[c])));
            }
        } else {
            keep_t.push(*tv);
            keep_p.push(part.tet_pass[t]);
        }
    }
    let removed = part.tets.len() - keep_t.len();
    part.tets = keep_t;
    part.tet_pass = keep_p;
    (removed, out)
}

/// Cancels opposite pairs of faces (the hole on both sides): sort by the
/// unordered triple, then match the two orientations one for one.
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

pub(super) fn cancel_pairs(hole: &mut Vec<[Rec; 3]>) {
    let canon = |v: &[Rec; 3]| {
        let g = v.map(|r| r.gid);
        let r = (0..3).min_by_key(|&k| g[k]).unwrap();
        let (a, b, c) = (g[r], g[(r + 1) % 3], g[(r + 2) % 3]);
        if b < c {
            ((a, b, c), true)
        } else {
            ((a, c, b), false)
        }
    };
    let mut order: Vec<(u32, u32, u32, bool, usize)> = hole
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let (k, o) = canon(v);
            (k.0, k.1, k.2, o, i)
        })
        .collect();
    order.sort_unstable();
    let mut drop = vec![false; hole.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j < order.len()
            && (order[j].0, order[j].1, order[j].2) == (order[i].0, order[i].1, order[i].2)
        {
            j += 1;
        }
        let pos: Vec<usize> = order[i..j].iter().filter(|x| x.3).map(|x| x.4).collect();
        let neg: Vec<usize> = order[i..j].iter().filter(|x| !x.3).map(|x| x.4).collect();
        for (a, b) in pos.iter().zip(&neg) {
            drop[*a] = true;
            drop[*b] = true;
        }
        i = j;
    }
    let mut k = 0;
    hole.retain(|_| {
        k += 1;
        !drop[k - 1]
    });
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
            faces.into_iter().map(|v| (0u32, v)).collect()
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
