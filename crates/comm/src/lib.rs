//! Communication between parts (paper §7: "all data is kept local").
//!
//! Parts own their points, tets and front; they see each other's data
//! only through the collectives of [`Comm`]. The calls are written in the
//! bulk-synchronous form that a driver of its parts issues between two
//! parallel phases, with a rank-local view: a process holds the parts
//! [`Comm::owned`] gives, passes one entry per owned part and receives one
//! per owned part. [`Threads`] owns every part and moves the buffers
//! between parts that live in one address space; the MPI backend
//! (`Mpi`, feature `mpi`) gives each rank a contiguous block of parts and
//! sends what leaves the rank as bytes ([`Wire`]).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use std::ops::Range;

pub mod wire;
pub use wire::{Wire, WireError};

#[cfg(feature = "mpi")]
mod mpi_backend;
#[cfg(feature = "mpi")]
pub use mpi_backend::{Mpi, MpiInitError};

/// Collectives over `parts()` parts, of which this process holds
/// `owned()`.
///
/// Every process makes the same calls in the same order (from one thread:
/// the driver between its parallel phases). Results do not depend on the
/// backend, on the number of processes or on timing.
pub trait Comm: Sync {
    /// All parts, over all processes.
    fn parts(&self) -> usize;
    /// The parts this process holds, ascending: the `out` and `local`
    /// arguments and the inboxes of [`exchange`](Comm::exchange) have one
    /// entry per owned part, in this order. The threads backend owns all.
    fn owned(&self) -> Range<usize>;
    /// Whether this process holds part `part` (part 0 is where a run's
    /// serial steps and gathered results live).
    fn holds(&self, part: usize) -> bool {
        self.owned().contains(&part)
    }
    /// Point-to-point messages: `out[i]` lists `(dst, message)` sent by
    /// part `owned().start + i`. The answer's `[i]` is what part
    /// `owned().start + i` receives: `(src, message)` ordered by `src`,
    /// then by send order (the order is part of the contract: results must
    /// not depend on timing or on where the parts live).
    fn exchange<T: Wire + Send>(&self, out: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>>;
    /// Every owned part contributes one value (`local[i]` for part
    /// `owned().start + i`); every process receives all parts' values,
    /// indexed by part.
    fn all_gather<T: Wire + Clone + Send>(&self, local: Vec<T>) -> Vec<T>;
    /// Every owned part contributes one value; every process receives the
    /// fold of all parts' values in part order (so a float sum is the same
    /// on every backend).
    fn all_reduce<T: Wire + Clone + Send>(&self, local: Vec<T>, op: impl Fn(T, T) -> T) -> T;
}

/// The threads backend: parts share one address space, so a message is a
/// moved buffer (no copy, no serialisation).
#[derive(Clone, Copy, Debug)]
pub struct Threads {
    parts: usize,
}

impl Threads {
    /// `parts` parts in this process.
    pub fn new(parts: usize) -> Self {
        assert!(parts > 0, "at least one part");
        Threads { parts }
    }
}

impl Comm for Threads {
    fn parts(&self) -> usize {
        self.parts
    }

    fn owned(&self) -> Range<usize> {
        0..self.parts
    }

    fn exchange<T: Wire + Send>(&self, out: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>> {
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

    fn all_gather<T: Wire + Clone + Send>(&self, local: Vec<T>) -> Vec<T> {
        assert_eq!(local.len(), self.parts, "one value per part");
        local
    }

    fn all_reduce<T: Wire + Clone + Send>(&self, local: Vec<T>, op: impl Fn(T, T) -> T) -> T {
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
