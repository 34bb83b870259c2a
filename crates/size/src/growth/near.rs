//! The near leaves' candidate seeds, two bytes each: a leaf's seeds are
//! close in space, so close in the seeds' Morton order, and are kept as
//! offsets from the leaf's lowest id. A leaf whose ids span more than a
//! `u16` keeps each id as two halves. On sphere_5e6 the 780k candidates
//! were 3.1 MB of each MPI rank's peak, which the passes set.

/// One near leaf: `len` seed ids from `start` in [`NearLists::cand`].
#[derive(Clone, Copy, Debug)]
pub(super) struct NearLeaf {
    start: u32,
    len: u32,
    /// The lowest id, or [`WIDE`]: each id as (low, high) halves.
    base: u32,
}

const WIDE: u32 = u32::MAX;

/// Every near leaf's candidates, in leaf order.
#[derive(Clone, Debug, Default)]
pub(super) struct NearLists {
    pub(super) leaves: Vec<NearLeaf>,
    pub(super) cand: Vec<u16>,
    /// Ids over all leaves.
    pub(super) ids: usize,
}

impl NearLists {
    /// Appends a leaf with the seed ids `list`.
    pub(super) fn push(&mut self, list: &[u32]) {
        let lo = list.iter().copied().min().unwrap_or(0);
        let hi = list.iter().copied().max().unwrap_or(0);
        let start = self.cand.len() as u32;
        let base = if hi - lo <= u32::from(u16::MAX) {
            self.cand.extend(list.iter().map(|&j| (j - lo) as u16));
            lo
        } else {
            for &j in list {
                self.cand.extend([j as u16, (j >> 16) as u16]);
            }
            WIDE
        };
        self.leaves.push(NearLeaf {
            start,
            len: list.len() as u32,
            base,
        });
        self.ids += list.len();
    }

    /// Room for `leaves` more leaves of `ids` ids in all (at two bytes an
    /// id: the few wide leaves grow it).
    pub(super) fn reserve(&mut self, leaves: usize, ids: usize) {
        self.leaves.reserve_exact(leaves);
        self.cand.reserve_exact(ids);
    }

    /// `f(min)` over the seed ids of leaf `i`.
    #[inline(always)]
    pub(super) fn min_over(&self, i: usize, init: f64, f: impl Fn(u32) -> f64) -> f64 {
        let l = self.leaves[i];
        let (a, n) = (l.start as usize, l.len as usize);
        let mut best = init;
        if l.base != WIDE {
            for &o in &self.cand[a..a + n] {
                best = best.min(f(l.base + u32::from(o)));
            }
        } else {
            for w in self.cand[a..a + 2 * n].chunks_exact(2) {
                best = best.min(f(u32::from(w[0]) | (u32::from(w[1]) << 16)));
            }
        }
        best
    }

    /// Bytes held.
    pub(super) fn bytes(&self) -> usize {
        self.leaves.len() * std::mem::size_of::<NearLeaf>() + self.cand.len() * 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ids come back as given, narrow and wide leaves alike.
    #[test]
    fn each_leaf_gives_back_its_ids() {
        let lists: Vec<Vec<u32>> = vec![
            vec![5, 9, 70_000],
            vec![100_000, 100_000 + 65_535],
            vec![3, 200_000, u32::MAX - 1],
            vec![],
            vec![42],
        ];
        let mut n = NearLists::default();
        for l in &lists {
            n.push(l);
        }
        assert_eq!(n.ids, 9);
        for (i, l) in lists.iter().enumerate() {
            let got = std::cell::RefCell::new(Vec::new());
            n.min_over(i, 0.0, |j| {
                got.borrow_mut().push(j);
                0.0
            });
            assert_eq!(&got.into_inner(), l, "leaf {i}");
        }
        // The narrow leaves (2, 0 and 1 ids) take a slot an id, the two
        // wide ones (3 ids each) two.
        assert_eq!(n.cand.len(), 2 + 1 + 2 * (3 + 3));
    }
}
