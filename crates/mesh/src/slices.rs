//! Tables over all of a mesh's faces or edges, built slice by slice of
//! vertex id: the face table whole took 64 B per tet and the edge list
//! 48, and each set the peak of the stage that built it (the
//! improvement's adjacency, the final check, the quality report). In
//! slices a table takes a few bytes per tet, and the slices in order are
//! the whole table sorted.
use crate::ids::*;
use rayon::prelude::*;
use std::ops::Range;

/// Slices a table is built in, about.
pub(crate) const SLICES: usize = 8;
/// Fewer items than this are one slice.
pub(crate) const MIN_SLICE: usize = 1 << 16;
/// Tets per work item.
const CHUNK: usize = 4096;

/// A tet's ids sorted, and the corner of the smallest.
#[inline(always)]
pub(crate) fn ranked(t: &[PointId; 4]) -> ([u32; 4], u8) {
    let mut v = [0, 1, 2, 3].map(|i| (t[i].raw(), i as u8));
    // A sorting network: five compare-exchanges.
    for (i, j) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
        if v[j] < v[i] {
            v.swap(i, j);
        }
    }
    (v.map(|x| x.0), v[0].1)
}

/// How a table's items fall into slices: the id ranges, and per tet the
/// slice of its smallest, second and third smallest id with the corner
/// of the smallest (`u8::MAX` for a tet that repeats an id).
pub(crate) struct Slices {
    /// The first starts at 0, the last ends at `u32::MAX`.
    pub ranges: Vec<Range<u32>>,
    tag: Vec<[u8; 4]>,
    /// Items per chunk of tets and slice (at most: the caller may write
    /// fewer), `counts[chunk * ranges.len() + slice]`.
    counts: Vec<u32>,
}

impl Slices {
    /// A tet has `per_rank[i]` items at most whose slice is that of its
    /// i-th smallest id (faces by smallest vertex: 3 and 1; edges: 3, 2
    /// and 1); tets that repeat an id have none unless `repeats`. About
    /// `slices` slices of at least `min_slice` items.
    pub(crate) fn new(
        tets: &[[PointId; 4]],
        per_rank: [u32; 3],
        repeats: bool,
        (slices, min_slice): (usize, usize),
    ) -> Slices {
        let total = tets.len() * per_rank.iter().sum::<u32>() as usize;
        let ranges = id_ranges(tets, total, per_rank, (slices, min_slice));
        let ns = ranges.len();
        // The slice of each id below the last range's start, by table.
        let last = ranges.last().map_or(0, |r| r.start) as usize;
        let mut lut = vec![0u8; last];
        for (k, r) in ranges.iter().enumerate() {
            let (a, b) = (r.start as usize, (r.end as usize).min(last));
            if a < b {
                lut[a..b].fill(k as u8);
            }
        }
        // The last range runs to u32::MAX (itself in none).
        let slice_of = |v: u32| match lut.get(v as usize) {
            Some(&k) => k,
            None => (ns - usize::from(v < u32::MAX)) as u8,
        };
        let mut tag = vec![[0u8; 4]; tets.len()];
        let mut counts = vec![0u32; tets.len().div_ceil(CHUNK) * ns];
        tag.par_chunks_mut(CHUNK)
            .zip(tets.par_chunks(CHUNK))
            .zip(counts.par_chunks_mut(ns))
            .for_each(|((tg, ts), cnt)| {
                for (g, t) in tg.iter_mut().zip(ts) {
                    let (v, c) = ranked(t);
                    let rep = crate::faces::has_repeat(t);
                    *g = [
                        slice_of(v[0]),
                        slice_of(v[1]),
                        slice_of(v[2]),
                        if rep { u8::MAX } else { c },
                    ];
                    if !rep || repeats {
                        for r in 0..3 {
                            cnt[g[r] as usize] += per_rank[r];
                        }
                    }
                }
            });
        Slices {
            ranges,
            tag,
            counts,
        }
    }

    /// Fills `out` with slice `k`'s items, tet by tet: `emit(t, tet, tag,
    /// rest)` writes tet `t`'s at the start of `rest` and says how many
    /// (`tag`: the slices of its three smallest ids, and the corner of the
    /// smallest or `u8::MAX`). It is called only for tets with an id of
    /// rank 0 to 2 in the slice; the slots left are `fill`.
    pub(crate) fn gather<T: Copy + Send + Sync>(
        &self,
        k: u8,
        tets: &[[PointId; 4]],
        out: &mut Vec<T>,
        fill: T,
        emit: impl Fn(usize, &[PointId; 4], [u8; 4], &mut [T]) -> usize + Sync,
    ) {
        let ns = self.ranges.len();
        let sizes: Vec<usize> = self
            .counts
            .chunks(ns)
            .map(|c| c[k as usize] as usize)
            .collect();
        out.clear();
        out.resize(sizes.iter().sum(), fill);
        let mut rest: &mut [T] = out;
        let mut parts = Vec::with_capacity(sizes.len());
        for &n in &sizes {
            let (a, b) = rest.split_at_mut(n);
            parts.push(a);
            rest = b;
        }
        tets.par_chunks(CHUNK)
            .zip(self.tag.par_chunks(CHUNK))
            .zip(parts.into_par_iter())
            .enumerate()
            .for_each(|(c, ((ts, tg), part))| {
                let mut n = 0;
                for (i, (t, &g)) in ts.iter().zip(tg).enumerate() {
                    if g[0] == k || g[1] == k || g[2] == k {
                        n += emit(c * CHUNK + i, t, g, &mut part[n..]);
                    }
                }
            });
    }
}

/// The ranges of ids that split `total` items into about `slices`
/// slices of equal size, at least `min_slice` each; a tet has
/// `per_rank[i]` items by its i-th smallest id.
fn id_ranges(
    tets: &[[PointId; 4]],
    total: usize,
    per_rank: [u32; 3],
    (slices, min_slice): (usize, usize),
) -> Vec<Range<u32>> {
    if total <= min_slice {
        return std::iter::once(0..u32::MAX).collect();
    }
    // A valid mesh has fewer points than 4 ids per tet; ids past that (a
    // corrupt mesh under check) are counted with the last, so that the
    // histogram never grows with a bad id.
    let top = tets
        .par_iter()
        .map(|t| t.iter().map(|p| p.raw()).max().unwrap_or(0))
        .max()
        .unwrap_or(0)
        .min((4 * tets.len()).min(u32::MAX as usize) as u32) as usize;
    // A histogram per task, added up: atomic adds per tet were a tenth of
    // the final check. The tasks are few (4 B per id each).
    let tasks = rayon::current_num_threads().clamp(1, tets.len() / (1 << 16) + 1);
    let counts = tets
        .par_chunks(tets.len().div_ceil(tasks))
        .map(|ch| {
            let mut c = vec![0u32; top + 1];
            for t in ch {
                let (v, _) = ranked(t);
                for r in 0..3 {
                    c[(v[r] as usize).min(top)] += per_rank[r];
                }
            }
            c
        })
        .reduce_with(|mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
            a
        })
        .unwrap_or_default();
    let per = (total / slices.max(1)).max(min_slice.max(1));
    let mut out = Vec::with_capacity(slices + 1);
    let (mut lo, mut acc) = (0u32, 0usize);
    for (v, &c) in counts.iter().enumerate() {
        acc += c as usize;
        if acc >= per && v < top {
            out.push(lo..v as u32 + 1);
            lo = v as u32 + 1;
            acc = 0;
        }
    }
    out.push(lo..u32::MAX);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranked_sorts_and_finds_the_smallest_corner() {
        for p in [[3u32, 1, 2, 0], [0, 1, 2, 3], [9, 4, 4, 7], [5, 8, 2, 6]] {
            let t = p.map(PointId::from_raw);
            let (v, c) = ranked(&t);
            let mut s = p;
            s.sort();
            assert_eq!(v, s);
            assert_eq!(p[c as usize], s[0]);
        }
    }
}
