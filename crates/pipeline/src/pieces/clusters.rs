//! §9.4's last lift across the cuts of the pieces: the tets under the
//! lift's floor near a cut, with the tets around them, gathered into one
//! piece, so that a third round of improvement finds them inside it.
use super::{gather_ids, per_region, MeshError};
use parafront_comm::Comm;
use parafront_passes::Piece;

/// Layers of tets around the points of a bad tet that go with it into one
/// piece: the third round frees the points within
/// [`SHIFT_LAYERS`](parafront_improve::parallel::SHIFT_LAYERS) layers, so
/// their balls, and the tets beyond those balls' faces, must be inside it.
pub(super) const CLUSTER_LAYERS: usize = parafront_improve::parallel::SHIFT_LAYERS + 1;

/// Per point of `pc`: within `layers` layers of tets of a point `from`
/// gives (local ids).
pub(super) fn near_points(pc: &Piece, from: impl Iterator<Item = u32>, layers: usize) -> Vec<bool> {
    let mut near = vec![false; pc.points.len()];
    for j in from {
        near[j as usize] = true;
    }
    for _ in 0..layers {
        let now = near.clone();
        for t in &pc.tets {
            if t.iter().any(|&j| now[j as usize]) {
                for &j in t {
                    near[j as usize] = true;
                }
            }
        }
    }
    near
}

/// Moves, region by region, every tet within [`CLUSTER_LAYERS`] layers of
/// a point `bad` lists (global ids, sorted) into one piece: the tets so
/// found that touch are one cluster, and it goes to the lowest part that
/// holds a tet of it. The other tets stay.
pub(super) fn move_clusters<C: Comm>(
    comm: &C,
    pieces: &mut Vec<Piece>,
    region: &[u32],
    bad: &[u32],
) -> Result<(), MeshError> {
    let start = comm.owned().start as u32;
    let touches = |pc: &Piece, t: &[u32; 4], m: &[u32]| {
        t.iter()
            .any(|&j| m.binary_search(&pc.gid[j as usize]).is_ok())
    };
    per_region(comm, pieces, region, |chunk| {
        let mut m = bad.to_vec();
        for _ in 0..CLUSTER_LAYERS {
            m = gather_ids(comm, &chunk, |pc| {
                pc.tets
                    .iter()
                    .filter(|t| touches(pc, t, &m))
                    .flat_map(|t| t.map(|j| pc.gid[j as usize]))
                    .chain(m.iter().copied())
                    .collect()
            });
        }
        // The moved tets of every piece, on every process: a few layers
        // around a few tets.
        let moved: Vec<(u32, [u32; 4])> = comm
            .all_gather(
                (0..chunk.len())
                    .map(|i| {
                        let pc = &chunk[i];
                        pc.tets
                            .iter()
                            .filter(|t| touches(pc, t, &m))
                            .map(|t| (start + i as u32, t.map(|j| pc.gid[j as usize])))
                            .collect::<Vec<_>>()
                    })
                    .collect(),
            )
            .concat();
        let label = cluster_parts(&moved);
        parafront_passes::move_pieces(comm, chunk, |i, pc| {
            pc.tets
                .iter()
                .map(
                    |t| match label.binary_search_by_key(&pc.gid[t[0] as usize], |x| x.0) {
                        Ok(x) if touches(pc, t, &m) => label[x].1,
                        _ => start + i as u32,
                    },
                )
                .collect()
        })
    })
}

/// Per global point of `tets` (part, points), sorted: the lowest part
/// holding a tet of its cluster (the tets joined through shared points).
fn cluster_parts(tets: &[(u32, [u32; 4])]) -> Vec<(u32, u32)> {
    let mut ids: Vec<u32> = tets.iter().flat_map(|t| t.1).collect();
    ids.sort_unstable();
    ids.dedup();
    let at = |g: u32| ids.binary_search(&g).unwrap_or(0);
    let mut up: Vec<usize> = (0..ids.len()).collect();
    fn root(up: &mut [usize], mut a: usize) -> usize {
        while up[a] != a {
            up[a] = up[up[a]];
            a = up[a];
        }
        a
    }
    for (_, t) in tets {
        for &g in &t[1..] {
            let (a, b) = (root(&mut up, at(t[0])), root(&mut up, at(g)));
            up[a.max(b)] = a.min(b);
        }
    }
    let mut part = vec![u32::MAX; ids.len()];
    for &(k, t) in tets {
        let a = root(&mut up, at(t[0]));
        part[a] = part[a].min(k);
    }
    (0..ids.len())
        .map(|i| {
            let a = root(&mut up, i);
            (ids[i], part[a])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each point's label is the lowest part of its cluster, found by
    /// propagating the minimum over shared points until nothing changes.
    #[test]
    fn clusters_take_their_lowest_part() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u32| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % n as u64) as u32
        };
        for n_points in [8, 40, 300] {
            let tets: Vec<(u32, [u32; 4])> = (0..120)
                .map(|_| (next(9), [0; 4].map(|_| 5 * next(n_points))))
                .collect();
            let got = cluster_parts(&tets);
            let mut want: std::collections::BTreeMap<u32, u32> = std::collections::BTreeMap::new();
            for (k, t) in &tets {
                for g in t {
                    let e = want.entry(*g).or_insert(u32::MAX);
                    *e = (*e).min(*k);
                }
            }
            loop {
                let mut changed = false;
                for (_, t) in &tets {
                    let m = t.iter().map(|g| want[g]).min().unwrap();
                    for g in t {
                        if want[g] > m {
                            want.insert(*g, m);
                            changed = true;
                        }
                    }
                }
                if !changed {
                    break;
                }
            }
            assert_eq!(got, want.into_iter().collect::<Vec<_>>(), "{n_points}");
        }
    }
}
