//! The MPI backend (feature `mpi`, on rsmpi): rank `r` of `R` owns a
//! contiguous block of the `P` parts, `r*P/R .. (r+1)*P/R`. Messages
//! between parts of one rank are moved, as in [`Threads`](crate::Threads);
//! what leaves the rank is encoded ([`Wire`]) and goes by one
//! all-to-all (exchange) or all-gather per call. Blocks are contiguous and
//! ascending, so a receiver that reads the ranks' buffers in rank order
//! reads the messages ordered by source part, then send order: the
//! threads backend's order.
//!
//! A panic on any rank after [`Mpi::init`] ends every rank (MPI_Abort)
//! with that rank's message, instead of leaving the others waiting in
//! their next collective.

use crate::{Comm, Wire};
use mpi::collective::CommunicatorCollectives;
use mpi::datatype::{Partition, PartitionMut};
use mpi::environment::Universe;
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::Threading;
use std::fmt;
use std::ops::Range;
use std::sync::Mutex;

/// Why [`Mpi::init`] failed.
#[derive(Debug)]
pub enum MpiInitError {
    /// MPI was initialized before (by an earlier `Mpi` or other code): it
    /// can be initialized once per process.
    AlreadyInitialized,
    /// The library gives less thread support than the collectives need
    /// (calls from any one thread at a time).
    Threading(Threading),
}

impl fmt::Display for MpiInitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MpiInitError::AlreadyInitialized => write!(f, "MPI was initialized already"),
            MpiInitError::Threading(t) => write!(
                f,
                "the MPI library gives thread support {t:?}; parafront needs Serialized"
            ),
        }
    }
}

impl std::error::Error for MpiInitError {}

/// The MPI backend: this rank's view of the `parts()` parts. Dropping it
/// finalizes MPI.
pub struct Mpi {
    universe: Universe,
    rank: usize,
    ranks: usize,
    parts: usize,
    /// Rank `r` owns `starts[r]..starts[r + 1]`.
    starts: Vec<usize>,
    /// One collective at a time in this process (MPI is initialized for
    /// serialized calls).
    lock: Mutex<()>,
}

impl Mpi {
    /// Initializes MPI (once per process) for `parts` parts over the ranks
    /// of `MPI_COMM_WORLD`, and installs the panic hook that aborts every
    /// rank when one panics.
    pub fn init(parts: usize) -> Result<Mpi, MpiInitError> {
        assert!(parts > 0, "at least one part");
        let (universe, threading) = mpi::initialize_with_threading(Threading::Serialized)
            .ok_or(MpiInitError::AlreadyInitialized)?;
        if threading < Threading::Serialized {
            return Err(MpiInitError::Threading(threading));
        }
        let world = universe.world();
        let (rank, ranks) = (world.rank() as usize, world.size() as usize);
        let starts = (0..=ranks).map(|r| r * parts / ranks).collect();
        abort_on_panic(rank, ranks);
        Ok(Mpi {
            universe,
            rank,
            ranks,
            parts,
            starts,
            lock: Mutex::new(()),
        })
    }

    /// Spreads `parts` parts over the ranks instead (every rank calls it
    /// with the same count, between collectives).
    pub fn set_parts(&mut self, parts: usize) {
        assert!(parts > 0, "at least one part");
        self.parts = parts;
        self.starts = (0..=self.ranks).map(|r| r * parts / self.ranks).collect();
    }

    /// This process's rank.
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The number of ranks.
    pub fn ranks(&self) -> usize {
        self.ranks
    }

    /// The parts rank `r` owns (empty when there are more ranks than
    /// parts).
    pub fn block(&self, r: usize) -> Range<usize> {
        self.starts[r]..self.starts[r + 1]
    }

    /// The rank that owns part `p`.
    pub fn rank_of(&self, p: usize) -> usize {
        assert!(p < self.parts, "part {p} of {}", self.parts);
        // The last rank starting at or before p: its block is not empty.
        self.starts.partition_point(|&s| s <= p) - 1
    }

    /// Waits for every rank.
    pub fn barrier(&self) {
        let _g = self.serial();
        self.universe.world().barrier();
    }

    /// Ends every rank, after printing `msg` with this rank's number: for
    /// an error this rank cannot recover from, which the others would
    /// otherwise wait on in their next collective.
    pub fn abort(&self, msg: &str) -> ! {
        eprintln!("parafront: rank {} of {}: {msg}", self.rank, self.ranks);
        self.universe.world().abort(1)
    }

    fn serial(&self) -> std::sync::MutexGuard<'_, ()> {
        self.lock.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// `bufs[q]` goes to rank `q`; the answer's `[q]` came from rank `q`.
    fn all_to_all_bytes(&self, bufs: Vec<Vec<u8>>) -> Received {
        let world = self.universe.world();
        let lens: Vec<u64> = bufs.iter().map(|b| b.len() as u64).collect();
        let mut rlens = vec![0u64; self.ranks];
        world.all_to_all_into(&lens[..], &mut rlens[..]);
        let (send, scounts, sdispls) = pack_words(bufs);
        let (rcounts, rdispls) = layout(rlens.iter().map(|&n| words(n)));
        let mut recv = vec![0u64; rcounts.iter().map(|&c| c as usize).sum()];
        {
            let sp = Partition::new(&send[..], &scounts[..], &sdispls[..]);
            let mut rp = PartitionMut::new(&mut recv[..], &rcounts[..], &rdispls[..]);
            world.all_to_all_varcount_into(&sp, &mut rp);
        }
        Received::new(recv, &rdispls, &rlens)
    }

    /// Every rank's `buf`, indexed by rank.
    fn all_gather_bytes(&self, buf: Vec<u8>) -> Received {
        let world = self.universe.world();
        let mut rlens = vec![0u64; self.ranks];
        world.all_gather_into(&(buf.len() as u64), &mut rlens[..]);
        let (send, _, _) = pack_words(vec![buf]);
        let (rcounts, rdispls) = layout(rlens.iter().map(|&n| words(n)));
        let mut recv = vec![0u64; rcounts.iter().map(|&c| c as usize).sum()];
        {
            let mut rp = PartitionMut::new(&mut recv[..], &rcounts[..], &rdispls[..]);
            world.all_gather_varcount_into(&send[..], &mut rp);
        }
        Received::new(recv, &rdispls, &rlens)
    }
}

/// Installs the hook: the message, then MPI_Abort on every rank (unless
/// MPI is finalized already, when there is no one left to wait).
fn abort_on_panic(rank: usize, ranks: usize) {
    let prev = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !mpi::environment::is_initialized() || mpi::environment::is_finalized() {
            prev(info);
            return;
        }
        eprintln!("parafront: rank {rank} of {ranks}: {info}");
        eprintln!("parafront: rank {rank} aborts all {ranks} ranks");
        SimpleCommunicator::world().abort(101)
    }));
}

/// Bytes are sent as 8-byte words: MPI's counts are C ints, and in words
/// one call carries up to 16 GiB per rank instead of 2.
fn words(bytes: u64) -> usize {
    bytes.div_ceil(8) as usize
}

/// Counts and displacements (in words) of consecutive blocks.
fn layout(counts: impl Iterator<Item = usize>) -> (Vec<i32>, Vec<i32>) {
    let mut c = Vec::new();
    let mut d = Vec::new();
    let mut at = 0usize;
    for n in counts {
        let fits = |x: usize| i32::try_from(x).expect("more than 16 GiB in one collective call");
        c.push(fits(n));
        d.push(fits(at));
        at += n;
    }
    (c, d)
}

/// The buffers as consecutive blocks of words (zero-padded), with their
/// counts and displacements; each buffer is freed once copied, so that a
/// large message is held about once, not twice.
fn pack_words(bufs: Vec<Vec<u8>>) -> (Vec<u64>, Vec<i32>, Vec<i32>) {
    let (counts, displs) = layout(bufs.iter().map(|b| words(b.len() as u64)));
    // Zeroed pages are only touched as they are written.
    let mut out = vec![0u64; counts.iter().map(|&c| c as usize).sum()];
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut out);
    for (b, &d) in bufs.into_iter().zip(&displs) {
        let at = 8 * d as usize;
        bytes[at..at + b.len()].copy_from_slice(&b);
    }
    (out, counts, displs)
}

/// What a collective call received: each rank's bytes, read in place
/// from the words they came in (no second copy of a large message).
struct Received {
    words: Vec<u64>,
    /// Per rank, its first byte and its length.
    at: Vec<(usize, usize)>,
}

impl Received {
    /// `lens[q]` bytes from rank `q`, at word `displs[q]` of `words`.
    fn new(words: Vec<u64>, displs: &[i32], lens: &[u64]) -> Received {
        let at = displs
            .iter()
            .zip(lens)
            .map(|(&d, &n)| (8 * d as usize, n as usize))
            .collect();
        Received { words, at }
    }

    fn bytes(&self, q: usize) -> &[u8] {
        let (a, n) = self.at[q];
        &bytemuck::cast_slice::<u64, u8>(&self.words)[a..a + n]
    }
}

/// A message that does not decode is a bug on some rank: end them all.
fn decode<T: Wire>(buf: &mut &[u8], from: usize) -> T {
    T::get(buf).unwrap_or_else(|e| panic!("from rank {from}: {e}"))
}

impl Comm for Mpi {
    fn parts(&self) -> usize {
        self.parts
    }

    fn owned(&self) -> Range<usize> {
        self.block(self.rank)
    }

    fn exchange<T: Wire + Send>(&self, out: Vec<Vec<(u32, T)>>) -> Vec<Vec<(u32, T)>> {
        let own = self.owned();
        assert_eq!(out.len(), own.len(), "one outbox per owned part");
        let _g = self.serial();
        // Per rank, (src, dst, message) in source order, then send order.
        let mut bufs: Vec<Vec<u8>> = vec![Vec::new(); self.ranks];
        let mut here: Vec<(u32, u32, T)> = Vec::new();
        for (i, msgs) in out.into_iter().enumerate() {
            let src = (own.start + i) as u32;
            for (dst, m) in msgs {
                assert!(
                    (dst as usize) < self.parts,
                    "message to part {dst} of {}",
                    self.parts
                );
                let q = self.rank_of(dst as usize);
                if q == self.rank {
                    here.push((src, dst, m));
                } else {
                    let b = &mut bufs[q];
                    src.put(b);
                    dst.put(b);
                    m.put(b);
                }
            }
        }
        let recv = self.all_to_all_bytes(bufs);
        let mut inbox: Vec<Vec<(u32, T)>> = own.clone().map(|_| Vec::new()).collect();
        let mut here = Some(here);
        for q in 0..self.ranks {
            if q == self.rank {
                for (src, dst, m) in here.take().expect("once") {
                    inbox[dst as usize - own.start].push((src, m));
                }
                continue;
            }
            let from = self.block(q);
            let mut b = recv.bytes(q);
            while !b.is_empty() {
                let src: u32 = decode(&mut b, q);
                let dst: u32 = decode(&mut b, q);
                assert!(
                    from.contains(&(src as usize)) && own.contains(&(dst as usize)),
                    "rank {q} sent a message from part {src} to part {dst}"
                );
                let m: T = decode(&mut b, q);
                inbox[dst as usize - own.start].push((src, m));
            }
        }
        inbox
    }

    fn all_gather<T: Wire + Clone + Send>(&self, local: Vec<T>) -> Vec<T> {
        assert_eq!(local.len(), self.owned().len(), "one value per owned part");
        let _g = self.serial();
        let mut buf = Vec::new();
        for x in &local {
            x.put(&mut buf);
        }
        let all = self.all_gather_bytes(buf);
        let mut res = Vec::with_capacity(self.parts);
        let mut local = Some(local);
        for q in 0..self.ranks {
            if q == self.rank {
                res.extend(local.take().expect("once"));
                continue;
            }
            let mut b = all.bytes(q);
            for _ in self.block(q) {
                res.push(decode(&mut b, q));
            }
            assert!(b.is_empty(), "rank {q} sent more values than it has parts");
        }
        res
    }

    fn all_reduce<T: Wire + Clone + Send>(&self, local: Vec<T>, op: impl Fn(T, T) -> T) -> T {
        // The fold in part order, as the threads backend: a user-defined
        // MPI operation would fold in the library's order.
        let mut it = self.all_gather(local).into_iter();
        let first = it.next().expect("at least one part");
        it.fold(first, op)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_round_trip() {
        let bufs = vec![vec![], vec![1u8, 2, 3], (0..16).collect(), vec![9; 9]];
        let lens: Vec<u64> = bufs.iter().map(|b| b.len() as u64).collect();
        let (w, c, d) = pack_words(bufs.clone());
        assert_eq!(c, vec![0, 1, 2, 2]);
        assert_eq!(d, vec![0, 0, 1, 3]);
        let r = Received::new(w, &d, &lens);
        for (q, b) in bufs.iter().enumerate() {
            assert_eq!(r.bytes(q), &b[..]);
        }
    }
}
