//! The size field's octree shared out over processes (MPI ranks): part
//! `i % P` builds subtree `i`, and every process gets every subtree by an
//! all-gather, so each holds the field a single process builds. One
//! process (the threads backend) holds every part and builds them all.
use parafront_comm::Comm;
use parafront_size::{OctreeShare, Subtree, SubtreeParts};

/// The subtrees of the parts a process holds, by [`Comm`].
pub(crate) struct CommShare<'a, C: Comm>(pub(crate) &'a C);

impl<C: Comm> CommShare<'_, C> {
    /// The part that builds subtree `i`.
    fn part(&self, i: usize) -> usize {
        i % self.0.parts()
    }
}

impl<C: Comm> OctreeShare for CommShare<'_, C> {
    fn builds(&self, i: usize, _n: usize) -> bool {
        self.0.holds(self.part(i))
    }

    fn gather(&self, mine: Vec<(u32, Subtree)>, n: usize) -> Vec<Subtree> {
        let owned = self.0.owned();
        let mut local: Vec<Vec<(u32, SubtreeParts)>> = owned.clone().map(|_| Vec::new()).collect();
        for (i, t) in mine {
            local[self.part(i as usize) - owned.start].push((i, t.into_parts()));
        }
        let mut all: Vec<(u32, SubtreeParts)> =
            self.0.all_gather(local).into_iter().flatten().collect();
        all.sort_unstable_by_key(|x| x.0);
        assert_eq!(all.len(), n, "every subtree built once");
        all.into_iter()
            .map(|(_, t)| Subtree::from_parts(t))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_comm::{wire, Threads, Wire};
    use parafront_size::SurfaceGrowth;
    use parafront_surface::generate;
    use std::ops::Range;
    use std::sync::{Barrier, Mutex};

    /// Processes as threads: each holds `owned` of `parts` parts; the
    /// all-gather goes through bytes in shared slots, as between ranks.
    struct Proc<'a> {
        parts: usize,
        owned: Range<usize>,
        slots: &'a Mutex<Vec<Vec<u8>>>,
        barrier: &'a Barrier,
    }

    impl Comm for Proc<'_> {
        fn parts(&self) -> usize {
            self.parts
        }
        fn owned(&self) -> Range<usize> {
            self.owned.clone()
        }
        fn exchange<T: Wire + Send>(&self, _: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>> {
            unreachable!("the share only all-gathers")
        }
        fn all_gather<T: Wire + Clone + Send>(&self, local: Vec<T>) -> Vec<T> {
            for (k, x) in self.owned.clone().zip(local) {
                self.slots.lock().unwrap()[k] = wire::to_bytes(&x);
            }
            self.barrier.wait();
            let all = (0..self.parts)
                .map(|k| wire::from_bytes(&self.slots.lock().unwrap()[k]).unwrap())
                .collect();
            self.barrier.wait();
            all
        }
        fn all_reduce<T: Wire + Clone + Send>(&self, _: Vec<T>, _: impl Fn(T, T) -> T) -> T {
            unreachable!("the share only all-gathers")
        }
    }

    /// The octree built by three processes (parts 0-1, 2-4 and 5-6 of 7)
    /// has the nodes of the one built alone and answers every query with
    /// its bits.
    #[test]
    fn shared_octree_is_the_octree_built_alone() {
        let s = generate::torus([0.0; 3], 2.0, 0.5, 40, 16);
        let seeds: Vec<_> = s
            .points
            .iter()
            .enumerate()
            .map(|(i, &p)| (p, 0.02 + 0.01 * (i % 7) as f64))
            .collect();
        let build = |share: &dyn OctreeShare| {
            SurfaceGrowth::in_domain_shared(&seeds, 0.3, f64::INFINITY, &s.points, &s.tris, share)
        };
        let alone = build(&parafront_size::Alone);
        let threads = build(&CommShare(&Threads::new(7)));
        let stats = alone.stats().clone();
        assert!(stats.nodes > 1000, "a real octree: {stats:?}");
        let slots = Mutex::new(vec![Vec::new(); 7]);
        let barrier = Barrier::new(3);
        let shared: Vec<SurfaceGrowth> = std::thread::scope(|sc| {
            let hs: Vec<_> = [0..2, 2..5, 5..7]
                .into_iter()
                .map(|owned| {
                    let comm = Proc {
                        parts: 7,
                        owned,
                        slots: &slots,
                        barrier: &barrier,
                    };
                    let build = &build;
                    sc.spawn(move || build(&CommShare(&comm)))
                })
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for g in shared.iter().chain([&threads]) {
            assert_eq!(g.stats().nodes, stats.nodes);
            assert_eq!(g.stats().candidates, stats.candidates);
            for i in 0..4000 {
                let x = i as f64;
                let p = [
                    2.6 * (x * 0.37).sin(),
                    2.6 * (x * 0.71).cos(),
                    0.6 * (x * 0.13).sin(),
                ];
                assert_eq!(g.size(p).to_bits(), alone.size(p).to_bits(), "at {p:?}");
            }
        }
    }
}
