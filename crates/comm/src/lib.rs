//! Communication between parts (paper §7: "all data is kept local").
//!
//! Parts own their points, tets and front; they see each other's data
//! only through the collectives of [`Comm`]. The calls are written in the
//! bulk-synchronous form that a driver of all parts issues between two
//! parallel phases: `out[src]` is what part `src` sends, the answer's
//! `[dst]` is what part `dst` receives. An MPI backend implements the same
//! trait with each rank holding only its own entry; [`Threads`] moves the
//! buffers between parts that live in one address space.
#![forbid(unsafe_code)]

/// Collectives over `parts()` parts.
pub trait Comm: Sync {
    fn parts(&self) -> usize;
    /// Point-to-point messages: `out[src]` lists `(dst, message)`. Part
    /// `dst` receives `(src, message)` ordered by `src`, then by send order
    /// (the order is part of the contract: results must not depend on
    /// timing).
    fn exchange<T: Send>(&self, out: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>>;
    /// Every part contributes one value; every part receives all of them,
    /// indexed by part.
    fn all_gather<T: Clone + Send>(&self, local: Vec<T>) -> Vec<T>;
    /// Every part contributes one value; every part receives the fold of
    /// all of them in part order.
    fn all_reduce<T: Clone + Send>(&self, local: Vec<T>, op: impl Fn(T, T) -> T) -> T;
}

/// The threads backend: parts share one address space, so a message is a
/// moved buffer (no copy, no serialisation).
#[derive(Clone, Copy, Debug)]
pub struct Threads {
    parts: usize,
}

impl Threads {
    pub fn new(parts: usize) -> Self {
        assert!(parts > 0, "at least one part");
        Threads { parts }
    }
}

impl Comm for Threads {
    fn parts(&self) -> usize {
        self.parts
    }

    fn exchange<T: Send>(&self, out: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>> {
        assert_eq!(out.len(), self.parts, "one outbox per part");
        let mut inbox: Vec<Vec<(u32, T)>> = (0..self.parts).map(|_| Vec::new()).collect();
        for (src, msgs) in out.into_iter().enumerate() {
            for (dst, m) in msgs {
                assert!(
                    (dst as usize) < self.parts,
                    "message to part {dst} of {}",
                    self.parts
                );
                inbox[dst as usize].push((src as u32, m));
            }
        }
        inbox
    }

    fn all_gather<T: Clone + Send>(&self, local: Vec<T>) -> Vec<T> {
        assert_eq!(local.len(), self.parts, "one value per part");
        local
    }

    fn all_reduce<T: Clone + Send>(&self, local: Vec<T>, op: impl Fn(T, T) -> T) -> T {
        assert_eq!(local.len(), self.parts, "one value per part");
        let mut it = local.into_iter();
        let first = it.next().expect("at least one part");
        it.fold(first, op)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exchange_delivers_every_message_in_source_order() {
        let c = Threads::new(4);
        // Part s sends s*10+d to every part d != s.
        let out: Vec<Vec<(u32, u32)>> = (0..4u32)
            .map(|s| {
                (0..4u32)
                    .filter(|&d| d != s)
                    .map(|d| (d, s * 10 + d))
                    .collect()
            })
            .collect();
        let inbox = c.exchange(out);
        for (d, msgs) in inbox.iter().enumerate() {
            let want: Vec<(u32, u32)> = (0..4u32)
                .filter(|&s| s != d as u32)
                .map(|s| (s, s * 10 + d as u32))
                .collect();
            assert_eq!(msgs, &want);
        }
    }

    #[test]
    fn all_gather_and_all_reduce() {
        let c = Threads::new(3);
        assert_eq!(c.all_gather(vec![5, 7, 9]), vec![5, 7, 9]);
        assert_eq!(c.all_reduce(vec![5u64, 7, 9], |a, b| a + b), 21);
        assert_eq!(c.all_reduce(vec![5.0f64, 7.0, 2.0], f64::max), 7.0);
    }
}
