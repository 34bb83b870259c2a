//! One inside-out pass (§7): every front face goes to the part that owns
//! its points, the parts advance their fronts in parallel on their cells,
//! and new points get global ids; the seeds of the parts inside the domain,
//! and the front each DDG tet is left with.
use super::*;

/// Parts per thread in one round of a pass's messages, on one process.
const ROUND_PER_THREAD: usize = 4;

/// The same over several processes (MPI), where memory per process is
/// the point: a rank then holds one part's inbox per thread. sphere_5e6 at
/// `--size 0.021 --parts 32`, 4 ranks of 1 thread: rank peaks 166-176 ->
/// 132-137 MiB, in the same time (the ranks wait for each other at every
/// exchange anyway).
const ROUND_PER_THREAD_MPI: usize = 1;

/// A part's front call taken into it, or its failure.
type Taken = Result<Absorbed, (usize, FrontError)>;

/// One parallel pass on partition `part_of`: send each front face to the
/// part that owns its three points, and a copy to every part whose region
/// box it meets (so that each part knows every face bounding its region);
/// every part advances its faces; new points get global ids. Returns the
/// tets and the front seconds of every part (`parts` are the owned ones).
/// `release` runs after each part's front (a process's parts run one after
/// another on one thread, and each front's memory is freed in pieces).
pub(crate) fn parallel_pass<C: Comm>(
    parts: &mut [Part],
    comm: &C,
    regions: &dyn Regions,
    size: Sizes<'_>,
    (pass, release): (u8, Option<fn()>),
    next_gid: &mut u32,
) -> Result<(Vec<usize>, Vec<f64>), PassError> {
    let np = comm.parts();
    let start = comm.owned().start;
    let mut boxes = regions.bounds();
    boxes.resize(np, Aabb::EMPTY);
    let boxes: Vec<Aabb> = boxes
        .iter()
        .map(|b| {
            if b.is_empty() {
                *b
            } else {
                b.inflated(1e-9 * b.diagonal())
            }
        })
        .collect();

    // Each holder routes its faces once: (destination, face, owned
    // there), by destination, each in face order (a stable sort). The
    // faces it keeps (no one part owns them) stay its front; the routed
    // ones wait in `olds` until every round has sent them. A route is 8
    // bytes ([`Route`]): they wait too.
    let olds: Vec<Vec<[u32; 3]>> = parts
        .iter_mut()
        .map(|part| std::mem::take(&mut part.front))
        .collect();
    let mut routes: Vec<Vec<Route>> = parts
        .par_iter_mut()
        .zip(&olds)
        .map(|(part, old)| {
            let mut to = Vec::new();
            let mut owner: Vec<Option<Option<u32>>> = vec![None; part.pts.len()];
            for (fi, &f) in old.iter().enumerate() {
                let o = f.map(|i| {
                    *owner[i as usize].get_or_insert_with(|| regions.owner(part.pts[i as usize]))
                });
                let own = if o[0].is_some() && o[0] == o[1] && o[1] == o[2] {
                    o[0]
                } else {
                    None
                };
                let fb = Aabb::from_points(f.iter().map(|&i| &part.pts[i as usize]));
                for (q, b) in boxes.iter().enumerate() {
                    if Some(q as u32) != own && b.overlaps(&fb) && regions.near(q as u32, &fb) {
                        to.push(Route::new(q as u32, fi as u32, false));
                    }
                }
                match own {
                    Some(k) => to.push(Route::new(k, fi as u32, true)),
                    None => part.front.push(f),
                }
            }
            to.sort_by_key(|x| x.to);
            to
        })
        .collect();

    // The messages go in rounds, each to the parts that then advance
    // together: a process holds one round's inboxes, not every part's. At
    // 32 parts on one process, pass 2's inboxes took sphere_5e6 from 124
    // to 168 MiB. A part's inbox is the same in any round, so is its mesh.
    // Rounds of one part per thread were 3-7 % slower on 2 threads
    // (sphere_1e6, torus_1e6: the threads wait at each round's end).
    let per_thread = if comm.owned().len() < np {
        ROUND_PER_THREAD_MPI
    } else {
        ROUND_PER_THREAD
    };
    let width = per_thread * rayon::current_num_threads().max(1);
    // The parts with the most faces to advance go first, while the parts
    // hold the fewest new tets: a process's peak is its largest front call
    // on top of what the calls before it added (sphere_5e6 at 32 parts, 4
    // ranks: rank 0 peaked in pass 2's fifth call at 96.5 MiB, 93.7 in
    // this order). Each process counts its faces for every part once.
    let mut sent = vec![0u64; np];
    for r in routes.iter().flatten() {
        sent[r.to as usize] += 1;
    }
    let mut local: Vec<Vec<u64>> = vec![Vec::new(); parts.len()];
    if let Some(first) = local.first_mut() {
        *first = sent;
    }
    // Every list is `np` long or empty: the longer one takes the sum.
    let inputs = comm.all_reduce(local, |a, b| {
        let (mut long, short) = if a.len() >= b.len() { (a, b) } else { (b, a) };
        long.iter_mut().zip(&short).for_each(|(x, y)| *x += y);
        long
    });
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(inputs[start + i]), i));
    let mut local_round = vec![0u32; parts.len()];
    for (j, &i) in order.iter().enumerate() {
        local_round[i] = (j / width) as u32;
    }
    let round_of: Vec<u32> = comm.all_gather(local_round);
    let rounds = round_of.iter().max().map_or(0, |&r| r as usize + 1);
    let mut made: Vec<(usize, Taken)> = Vec::with_capacity(parts.len());
    for r in 0..rounds as u32 {
        let outboxes: Vec<Vec<(u32, FaceBatch)>> = parts
            .par_iter()
            .zip(&olds)
            .zip(&routes)
            .map(|((part, old), to)| batches(part, old, to, |q| round_of[q as usize] == r))
            .collect();
        // The routes sent are done with: the last rounds' calls, on top of
        // the most new tets, run beside the fewest.
        routes.par_iter_mut().for_each(|to| {
            to.retain(|x| round_of[x.to as usize] != r);
            to.shrink_to_fit();
        });
        let inboxes = comm.exchange(outboxes);
        made.par_extend(
            parts
                .par_iter_mut()
                .zip(inboxes)
                .enumerate()
                .filter(|(i, _)| round_of[start + i] == r)
                .map(|(i, (part, inbox))| {
                    let m = front_call(inbox, (start + i) as u32, regions, size, release)
                        .map(|m| absorb_local(part, m, pass));
                    crate::release(release);
                    (i, m)
                }),
        );
    }
    drop((olds, routes));
    // In part order (each part was in exactly one round).
    made.sort_unstable_by_key(|&(i, _)| i);
    let made: Vec<Taken> = made.into_iter().map(|(_, m)| m).collect();
    let made = crate::agree(comm, pass, made)?;

    // Global ids for the new points: an all-gather of the counts.
    let counts = comm.all_gather(made.iter().map(|a| a.new_points).collect());
    let mut base = Vec::with_capacity(np);
    let mut acc = *next_gid;
    for c in &counts {
        base.push(acc);
        acc += c;
    }
    *next_gid = acc;
    let secs = comm.all_gather(made.iter().map(|a| a.seconds).collect());
    parts
        .par_iter_mut()
        .zip(&made)
        .zip(&base[start..])
        .for_each(|((part, a), &b)| absorb_finish(part, a, b));
    let tets: Vec<usize> = made.iter().map(|a| a.tets).collect();
    Ok((comm.all_gather(tets), secs))
}

/// A face of a holder going to part `to`: its index in the holder's front,
/// with the top bit set where it is owned there.
#[derive(Clone, Copy)]
struct Route {
    to: u32,
    face: u32,
}

impl Route {
    const OWNED: u32 = 1 << 31;

    fn new(to: u32, face: u32, owned: bool) -> Route {
        debug_assert!(face < Route::OWNED);
        Route {
            to,
            face: face | if owned { Route::OWNED } else { 0 },
        }
    }

    fn face(self) -> u32 {
        self.face & !Route::OWNED
    }

    fn owned(self) -> bool {
        self.face & Route::OWNED != 0
    }
}

/// A holder's batches for the destinations `to_round` picks: one per
/// destination, its points once each, then its owned and context faces
/// (indices into them), each list in the holder's face order.
fn batches(
    part: &Part,
    old: &[[u32; 3]],
    to: &[Route],
    to_round: impl Fn(u32) -> bool,
) -> Vec<(u32, FaceBatch)> {
    // Per point, its index in the batch being built.
    let mut at: Vec<u32> = Vec::new();
    let mut ids: Vec<u32> = Vec::new();
    let mut out = Vec::new();
    for group in to.chunk_by(|a, b| a.to == b.to) {
        if !to_round(group[0].to) {
            continue;
        }
        if at.is_empty() {
            at = vec![u32::MAX; part.pts.len()];
        }
        let mut b = FaceBatch::default();
        for r in group {
            let (fi, owned) = (r.face(), r.owned());
            let v = old[fi as usize].map(|i| {
                if at[i as usize] == u32::MAX {
                    at[i as usize] = ids.len() as u32;
                    ids.push(i);
                }
                at[i as usize]
            });
            if owned {
                b.owned.push(v);
            } else {
                b.context.push(v);
            }
        }
        b.points = ids.iter().map(|&i| part.rec(i)).collect();
        for i in ids.drain(..) {
            at[i as usize] = u32::MAX;
        }
        out.push((group[0].to, b));
    }
    out
}

/// Builds one part's front from its inbox (owned faces first, then the
/// context) and advances it in pass mode under its region filter.
pub(crate) fn front_call(
    inbox: Vec<(u32, FaceBatch)>,
    k: u32,
    regions: &dyn Regions,
    size: Sizes<'_>,
    release: Option<fn()>,
) -> Result<Made, (usize, FrontError)> {
    let t0 = Instant::now();
    let n_owned: usize = inbox.iter().map(|(_, b)| b.owned.len()).sum();
    if n_owned == 0 {
        return Ok(Made {
            res: None,
            input_gid: Vec::new(),
            input_ok: Vec::new(),
            stuck: Vec::new(),
            seconds: 0.0,
        });
    }
    // Owned faces first: their points get the low local ids.
    let (input, gids) = local_front(
        inbox
            .iter()
            .flat_map(|(_, b)| b.faces(&b.owned))
            .chain(inbox.iter().flat_map(|(_, b)| b.faces(&b.context))),
    );
    // The messages are copied into `input`: not held while the front
    // runs, and their memory goes back first (sphere_5e6 at 32 parts, 4
    // ranks: the highest rank 90.5 -> 89.7 MiB).
    drop(inbox);
    crate::release(release);
    let filter = regions.filter(k);
    let input_ok: Vec<bool> = input
        .points
        .iter()
        .map(|&p| regions.owner(p) == Some(k))
        .collect();
    let res = advance(
        input,
        SizeMode::Field(size.field),
        &*filter,
        &FrontOptions {
            pass: true,
            max_growth: size.max_growth,
            release,
            ..FrontOptions::default()
        },
    )
    .map_err(|e| (k as usize, e))?;
    let t_front = t0.elapsed().as_secs_f64();
    let mut res = res;
    let n_in = gids.len();
    let pocket_tets = close_pockets(
        &mut res,
        |i| i as usize >= n_in || input_ok[i as usize],
        size.field,
    );
    let t_pockets = t0.elapsed().as_secs_f64() - t_front;
    // The parts' results wait for each other: no growth slack kept, and
    // no adjacency (a part keeps none).
    res.points.shrink_to_fit();
    res.point_size.shrink_to_fit();
    res.tets.shrink_to_fit();
    res.neigh = Vec::new();
    let stuck: Vec<bool> = res
        .front
        .iter()
        .map(|f| is_stuck(&res, *f, &*filter))
        .collect();
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!(
            "part {k}: {} points in, {} owned faces, {} tets, front {t_front:.3} s, pockets {t_pockets:.3} s ({pocket_tets} tets), stuck check {:.3} s",
            gids.len(),
            n_owned,
            res.tets.len(),
            t0.elapsed().as_secs_f64() - t_front - t_pockets
        );
    }
    Ok(Made {
        res: Some(res),
        input_gid: gids,
        input_ok,
        stuck,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Pass 1 for the parts that own no face of the input front (those off
/// the surface, P >= 32 on a ball): their whole region would wait for
/// pass 2, on one part. Each gets one fine regular tet, inside-out: at the
/// middle of its DDG tet farthest (in face steps) from its walls, with its
/// faces facing out as its front. Returns how many parts got one.
/// Every process decides every part's seed alike (the input is
/// replicated), so that global ids agree; `parts` are the `owned` ones.
#[allow(clippy::too_many_arguments)]
pub(crate) fn seed_inner_parts(
    parts: &mut [Part],
    owned: std::ops::Range<usize>,
    (points, faces): (&[P3], &[[u32; 3]]),
    d: &Ddg,
    loc: &Locator,
    part0: &[u32],
    size: &(dyn Fn(P3) -> f64 + Sync),
    next_gid: &mut u32,
) -> usize {
    let np = part0.iter().map(|&k| k as usize + 1).max().unwrap_or(0);
    let nt = d.tets.len();
    // Face steps from a wall or the surface.
    let mut depth = vec![u32::MAX; nt];
    let mut queue = std::collections::VecDeque::new();
    // Parts that own a face of the input front.
    let mut owns = vec![false; np];
    let owner: Vec<Option<u32>> = points.par_iter().map(|&p| loc.owner(p, part0)).collect();
    let neigh = d.neigh();
    for f in faces {
        let o = f.map(|i| owner[i as usize]);
        if let Some(k) = o[0] {
            if o[1] == o[0] && o[2] == o[0] {
                owns[k as usize] = true;
            }
        }
    }
    for t in 0..nt {
        let wall = (0..4).any(|f| {
            let n = neigh[4 * t + f];
            n.is_none() || part0[n.tet().idx()] != part0[t]
        });
        if wall {
            depth[t] = 0;
            queue.push_back(t);
        }
    }
    while let Some(t) = queue.pop_front() {
        for f in 0..4 {
            let n = neigh[4 * t + f];
            if !n.is_none() && depth[n.tet().idx()] == u32::MAX {
                depth[n.tet().idx()] = depth[t] + 1;
                queue.push_back(n.tet().idx());
            }
        }
    }
    // Per part without a face, its tets, deepest first.
    let mut cands: Vec<Vec<usize>> = vec![Vec::new(); np];
    for t in 0..nt {
        if !owns[part0[t] as usize] {
            cands[part0[t] as usize].push(t);
        }
    }
    // Corners of a regular tet of unit edge about the origin.
    let s = 1.0 / 8f64.sqrt();
    let corners = [[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]];
    // Its faces, facing out of it (the front's faces face the space left).
    const OUTWARD: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let seed_in = |t: usize| -> Option<[P3; 4]> {
        let c = d.centroid(t);
        let h = size(c);
        let mut v = corners.map(|q| [c[0] + h * q[0], c[1] + h * q[1], c[2] + h * q[2]]);
        if orient3d(v[0], v[1], v[2], v[3]) < 0.0 {
            v.swap(2, 3);
        }
        (v.iter().all(|&p| loc.strictly_holds(t as u32, p))
            && orient3d(v[0], v[1], v[2], v[3]) > 0.0)
            .then_some(v)
    };
    let mut seeded = 0;
    for (k, mut ts) in cands.into_iter().enumerate() {
        ts.sort_by_key(|&t| (std::cmp::Reverse(depth[t]), t));
        let Some(v) = ts.iter().find_map(|&t| seed_in(t)) else {
            continue;
        };
        let gids = v.map(|_| {
            *next_gid += 1;
            *next_gid - 1
        });
        seeded += 1;
        if !owned.contains(&k) {
            continue;
        }
        let part = &mut parts[k - owned.start];
        let ids = [0, 1, 2, 3].map(|i| {
            part.local(Rec {
                gid: gids[i],
                p: v[i],
                h: size(v[i]),
            })
        });
        part.tets.extend([ids]);
        part.tet_pass.push_n(1, 1);
        for f in OUTWARD {
            part.front.push(f.map(|i| ids[i]));
        }
    }
    seeded
}

/// Per DDG tet, the front faces left in it (the first tet holding each
/// face's centroid), summed over the parts.
pub(crate) fn front_left_per_tet<C: Comm>(
    parts: &[Part],
    comm: &C,
    loc: &Locator,
    n_tets: usize,
) -> Vec<u32> {
    let local: Vec<Vec<u32>> = parts
        .par_iter()
        .map(|part| {
            let mut ts = Vec::with_capacity(part.front.len());
            for f in &part.front {
                let [a, b, c] = f.map(|i| part.pts[i as usize]);
                loc.hosts(centroid3(a, b, c), |t| {
                    ts.push(t);
                    false
                });
            }
            ts
        })
        .collect();
    let mut left = vec![0u32; n_tets];
    for ts in comm.all_gather(local) {
        for t in ts {
            left[t as usize] += 1;
        }
    }
    left
}
