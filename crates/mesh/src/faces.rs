//! The face table: every tet face as a `u128` key (sorted vertex triple in
//! the high 96 bits, its `FaceRef` in the low 32), sorted so that the faces
//! with the same three vertices lie next to each other. Adjacency building
//! and `check()` both pair faces through it; it needs no coordinates.
use crate::ids::*;
use crate::slices::Slices;
use crate::tetmesh::TET_FACES;
use rayon::prelude::*;

/// The three vertex ids sorted ascending, and whether sorting took an odd
/// permutation. Two faces with the same triple are seen from opposite sides
/// exactly when their parities differ.
#[inline(always)]
pub(crate) fn sort3(v: [u32; 3]) -> ([u32; 3], bool) {
    let [mut a, mut b, mut c] = v;
    let mut odd = false;
    if a > b {
        std::mem::swap(&mut a, &mut b);
        odd = !odd;
    }
    if b > c {
        std::mem::swap(&mut b, &mut c);
        odd = !odd;
    }
    if a > b {
        std::mem::swap(&mut a, &mut b);
        odd = !odd;
    }
    ([a, b, c], odd)
}

#[inline(always)]
pub(crate) fn pack(t: [u32; 3], low: u32) -> u128 {
    ((t[0] as u128) << 96) | ((t[1] as u128) << 64) | ((t[2] as u128) << 32) | low as u128
}

/// The triple part of a key (the low 32 bits cleared).
#[inline(always)]
pub(crate) fn triple_bits(k: u128) -> u128 {
    k >> 32
}

#[inline(always)]
pub(crate) fn unpack_triple(k: u128) -> [u32; 3] {
    [(k >> 96) as u32, (k >> 64) as u32, (k >> 32) as u32]
}

#[inline(always)]
pub(crate) fn low(k: u128) -> u32 {
    k as u32
}

/// Vertex ids of face `f` of tet `t`, outward from `t`.
#[inline(always)]
pub(crate) fn face_verts(tet: &[PointId; 4], f: usize) -> [u32; 3] {
    let l = TET_FACES[f];
    [tet[l[0]].raw(), tet[l[1]].raw(), tet[l[2]].raw()]
}

/// True when the tet lists the same point twice; such a tet has no proper
/// faces and is left out of the face table.
#[inline(always)]
pub(crate) fn has_repeat(t: &[PointId; 4]) -> bool {
    t[0] == t[1] || t[0] == t[2] || t[0] == t[3] || t[1] == t[2] || t[1] == t[3] || t[2] == t[3]
}

/// The sorted face keys of all tets without repeated vertices, slice by
/// slice of the smallest vertex id: `f` gets each slice's keys, sorted,
/// with the range of smallest ids it covers (the first starts at 0, the
/// last ends at `u32::MAX`). In order, the slices are the whole sorted
/// table, and a group (one triple) never spans two.
pub(crate) fn for_each_key_slice(
    tets: &[[PointId; 4]],
    mut f: impl FnMut(&[u128], std::ops::Range<u32>),
) {
    // A face's smallest vertex is the tet's smallest (three faces) unless
    // the face is the one opposite it (its smallest is the tet's second).
    // Slices half the size of other tables': `sort_keys` holds two
    // buffers (an MPI rank's peak comes in its pieces' adjacency).
    use crate::slices::{MIN_SLICE, SLICES};
    let sl = Slices::new(tets, [3, 1, 0], false, (2 * SLICES, MIN_SLICE / 2));
    let mut keys: Vec<u128> = Vec::new();
    let mut scratch: Vec<u128> = Vec::new();
    for (k, r) in sl.ranges.iter().enumerate() {
        let k = k as u8;
        sl.gather(
            k,
            tets,
            &mut keys,
            u128::MAX,
            |t, tet, [a, b, _, c], out| {
                if c == u8::MAX {
                    return 0; // repeats a vertex: no proper faces
                }
                let m = (((a == k) as u8) * (0xf ^ (1 << c))) | (((b == k) as u8) << c);
                let mut n = 0;
                for f in 0..4 {
                    if m >> f & 1 == 1 {
                        out[n] = pack(sort3(face_verts(tet, f)).0, (4 * t + f) as u32);
                        n += 1;
                    }
                }
                n
            },
        );
        sort_keys(&mut keys, &mut scratch);
        keys.truncate(keys.partition_point(|&x| x != u128::MAX));
        f(&keys, r.clone());
    }
}

/// Sorts a slice's keys: a counting sort by the smallest vertex (the
/// slice's ids are a narrow range) into `scratch`, then each vertex's
/// run, about 20 keys, by `sort_unstable`; `keys` and `scratch` trade
/// places. One pdqsort over the slice made the check 15 % slower, and
/// a permutation in place by cycles as slow as that. The fill
/// `u128::MAX` go last; ids spread wider than twice the keys fall back to
/// `sort_unstable`.
fn sort_keys(keys: &mut Vec<u128>, scratch: &mut Vec<u128>) {
    let (mut lo, mut hi, mut fill) = (u32::MAX, 0u32, 0usize);
    for &k in keys.iter() {
        if k == u128::MAX {
            fill += 1;
        } else {
            lo = lo.min((k >> 96) as u32);
            hi = hi.max((k >> 96) as u32);
        }
    }
    let n = keys.len() - fill;
    if n < 2 || (hi - lo) as usize + 1 > 2 * n {
        sort_unstable(keys);
        return;
    }
    let nb = (hi - lo) as usize + 1;
    let run = |k: u128| ((k >> 96) as u32 - lo) as usize;
    // ends[b + 1]: the end of run b once the scatter is done.
    let mut ends = vec![0u32; nb + 1];
    for &k in keys.iter() {
        if k != u128::MAX {
            ends[run(k) + 1] += 1;
        }
    }
    for b in 1..=nb {
        ends[b] += ends[b - 1];
    }
    scratch.clear();
    scratch.resize(keys.len(), u128::MAX);
    let next = &mut ends[..nb];
    for &k in keys.iter() {
        if k != u128::MAX {
            let b = run(k);
            scratch[next[b] as usize] = k;
            next[b] += 1;
        }
    }
    // Now ends[b] is the end of run b, and run b starts at ends[b - 1].
    let runs = |out: &mut [u128], ends: &[u32], base: u32| {
        let mut s = base;
        for &e in ends {
            out[(s - base) as usize..(e - base) as usize].sort_unstable();
            s = e;
        }
    };
    let threads = rayon::current_num_threads();
    if threads > 1 && nb > 64 {
        // Groups of runs, cut at run ends, sorted in parallel.
        let groups = (8 * threads).min(nb);
        let mut work = Vec::with_capacity(groups);
        let mut rest: &mut [u128] = &mut scratch[..n];
        let (mut b0, mut start) = (0usize, 0u32);
        for g in 1..=groups {
            let b1 = nb * g / groups;
            let end = ends[b1 - 1];
            let (a, r) = std::mem::take(&mut rest).split_at_mut((end - start) as usize);
            work.push((a, &ends[b0..b1], start));
            rest = r;
            b0 = b1;
            start = end;
        }
        work.into_par_iter().for_each(|(a, e, s)| runs(a, e, s));
    } else {
        runs(&mut scratch[..n], &ends[..nb], 0);
    }
    std::mem::swap(keys, scratch);
}

/// `sort_unstable`, in parallel when the pool has threads to spare:
/// rayon's sort on one thread took a third longer than the standard
/// library's (a face table's slice: 8.6 ms against 6.5). Either gives the
/// one sorted order.
pub(crate) fn sort_unstable<T: Ord + Send>(v: &mut [T]) {
    if rayon::current_num_threads() > 1 {
        v.par_sort_unstable();
    } else {
        v.sort_unstable();
    }
}

/// Splits a sorted key array into about `8 * threads` chunks that start at
/// group boundaries (a group = the keys sharing one triple), so each chunk
/// can walk its groups alone.
pub(crate) fn group_chunks(keys: &[u128]) -> Vec<&[u128]> {
    let n = keys.len();
    if n == 0 {
        return Vec::new();
    }
    let parts = (rayon::current_num_threads() * 8).clamp(1, n);
    let mut cuts = Vec::with_capacity(parts + 1);
    cuts.push(0);
    for p in 1..parts {
        let mut c = (p * n / parts).max(*cuts.last().unwrap());
        while c > 0 && c < n && triple_bits(keys[c]) == triple_bits(keys[c - 1]) {
            c += 1;
        }
        if c < n && c > *cuts.last().unwrap() {
            cuts.push(c);
        }
    }
    cuts.push(n);
    cuts.windows(2).map(|w| &keys[w[0]..w[1]]).collect()
}

/// Calls `f` on each group (run of keys with equal triples) of a chunk.
#[inline]
pub(crate) fn for_each_group(chunk: &[u128], mut f: impl FnMut(&[u128])) {
    let mut s = 0;
    while s < chunk.len() {
        let tb = triple_bits(chunk[s]);
        let mut e = s + 1;
        while e < chunk.len() && triple_bits(chunk[e]) == tb {
            e += 1;
        }
        f(&chunk[s..e]);
        s = e;
    }
}

/// The range of keys in `keys` (sorted) whose triple equals `t`.
#[inline]
pub(crate) fn find_triple(keys: &[u128], t: [u32; 3]) -> &[u128] {
    let lo = pack(t, 0);
    let tb = triple_bits(lo);
    let s = keys.partition_point(|&k| k < lo);
    let e = s + keys[s..].partition_point(|&k| triple_bits(k) == tb);
    &keys[s..e]
}

/// Parity of face `fr` as listed (outward from its tet).
#[inline(always)]
pub(crate) fn face_parity(tets: &[[PointId; 4]], fr: u32) -> bool {
    let fr = FaceRef::from_raw(fr);
    sort3(face_verts(&tets[fr.tet().idx()], fr.local())).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sort3_parity() {
        assert_eq!(sort3([1, 2, 3]), ([1, 2, 3], false));
        assert_eq!(sort3([2, 3, 1]), ([1, 2, 3], false));
        assert_eq!(sort3([3, 1, 2]), ([1, 2, 3], false));
        assert_eq!(sort3([1, 3, 2]), ([1, 2, 3], true));
        assert_eq!(sort3([3, 2, 1]), ([1, 2, 3], true));
        assert_eq!(sort3([2, 1, 3]), ([1, 2, 3], true));
    }

    #[test]
    fn chunks_do_not_split_groups() {
        let mut keys = Vec::new();
        for i in 0..1000u32 {
            for j in 0..(i % 3 + 1) {
                keys.push(pack([i, i + 1, i + 2], j));
            }
        }
        let chunks = group_chunks(&keys);
        assert_eq!(chunks.iter().map(|c| c.len()).sum::<usize>(), keys.len());
        let mut groups = 0;
        for c in &chunks {
            for_each_group(c, |g| {
                assert_eq!(g.len() as u32, unpack_triple(g[0])[0] % 3 + 1);
                groups += 1;
            });
        }
        assert_eq!(groups, 1000);
        assert_eq!(find_triple(&keys, [5, 6, 7]).len(), 3);
        assert_eq!(find_triple(&keys, [5, 6, 8]).len(), 0);
    }

    fn xorshift(mut x: u64) -> impl FnMut() -> u64 {
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        }
    }

    /// `sort_keys` gives `sort_unstable`'s order, fill slots last: ids
    /// narrow (the counting sort, serial and in parallel runs) and spread
    /// (the fallback).
    #[test]
    fn sort_keys_is_a_sort() {
        let mut rng = xorshift(11);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for (n, span) in [
                (0usize, 1u64),
                (1, 1),
                (5000, 300),
                (50_000, 2000),
                (3000, 1 << 30),
            ] {
                let mut keys: Vec<u128> = (0..n)
                    .map(|i| {
                        if rng().is_multiple_of(7) {
                            return u128::MAX;
                        }
                        let a = 1000 + (rng() % span) as u32;
                        let b = a + 1 + (rng() % 50) as u32;
                        pack([a, b, b + 1 + (rng() % 50) as u32], i as u32)
                    })
                    .collect();
                let mut want = keys.clone();
                want.sort_unstable();
                let mut scratch = Vec::new();
                pool.install(|| sort_keys(&mut keys, &mut scratch));
                assert_eq!(keys, want, "{n} keys over {span} ids, {threads} threads");
            }
        }
    }

    /// The slices, in order, are the whole sorted table.
    #[test]
    fn slices_make_the_whole_table() {
        let mut bits = xorshift(7);
        let mut rng = move || (bits() >> 11) as f64 / (1u64 << 53) as f64;
        for n in [1usize, 100, 40_000, 90_000] {
            let np = (n / 3).max(4) as u32;
            let tets: Vec<[PointId; 4]> = (0..n)
                .map(|_| [0; 4].map(|_| PointId::from_raw((rng() * np as f64) as u32)))
                .collect();
            let mut whole: Vec<u128> = (0..n)
                .filter(|&t| !has_repeat(&tets[t]))
                .flat_map(|t| (0..4).map(move |f| (t, f)))
                .map(|(t, f)| pack(sort3(face_verts(&tets[t], f)).0, (4 * t + f) as u32))
                .collect();
            whole.sort_unstable();
            let mut got = Vec::new();
            let mut slices = 0;
            let mut next = 0;
            for_each_key_slice(&tets, |keys, r| {
                assert_eq!(r.start, next);
                next = r.end;
                assert!(keys.iter().all(|&k| r.contains(&unpack_triple(k)[0])));
                got.extend_from_slice(keys);
                slices += 1;
            });
            assert_eq!(next, u32::MAX);
            assert_eq!(got, whole, "{n} tets");
            assert!((1..=2 * crate::slices::SLICES + 1).contains(&slices));
            if 4 * n > 2 * (1 << 15) {
                assert!(slices > 1, "{n} tets in one slice");
            }
        }
    }
}
