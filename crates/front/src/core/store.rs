//! The front's faces by id, every face ever made (ids stay put and only
//! grow), in chunks that are freed once all their faces are dead.
//!
//! A face lives from the tet that opens it to the tet that closes it, so
//! most chunks empty soon after they fill: on sphere_1e6 the store held
//! 20 MB of faces at the end of the front (1M made), 4 MB of them in
//! chunks with a live face. A freed chunk reads as dead faces: code
//! that needs a face's corners after it may have died keeps them itself
//! (`fill_pockets`).
//!
//! A pass's front (§7) leaves its faces on the part's walls alive to the
//! end, a few in nearly every chunk: at sphere_5e6 `--size 0.021`, a part
//! of 640k tets kept 859 of its 1281 chunks (17 MB) for 31k live faces.
//! A chunk down to [`SPARSE_AT`] live faces gives them to a hash map and
//! goes.
use super::Face;
use rustc_hash::FxHashMap;
use std::ops::{Index, IndexMut};

/// Faces per chunk (20 KB).
const BITS: u32 = 10;
const MASK: usize = (1 << BITS) - 1;
/// Live faces at which a chunk (not the last) moves them to the map: a
/// face there takes about 30 bytes against the chunk's 20 KB.
const SPARSE_AT: u32 = 64;

/// What a face of a freed chunk reads as: dead, with corners and owner
/// out of any range, so that code using a dead face's corners (which
/// freed chunks no longer hold) fails loudly instead of using point 0.
const DEAD: Face = Face {
    v: [u32::MAX; 3],
    owner: u32::MAX - 1,
    tries: 0,
    alive: false,
};

#[derive(Default)]
pub(super) struct Faces {
    chunks: Vec<Option<Box<[Face]>>>,
    /// Live faces per chunk.
    live: Vec<u32>,
    /// The live faces of freed chunks that still have some, by id.
    sparse: FxHashMap<u32, Face>,
    len: usize,
}

impl Faces {
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Appends a live face; its id is the old `len()`.
    pub(super) fn push(&mut self, f: Face) {
        debug_assert!(f.alive);
        let (c, i) = (self.len >> BITS, self.len & MASK);
        if i == 0 {
            self.chunks
                .push(Some(vec![DEAD; MASK + 1].into_boxed_slice()));
            self.live.push(0);
        }
        self.chunks[c].as_mut().expect("the last chunk is kept")[i] = f;
        self.live[c] += 1;
        self.len += 1;
    }

    /// Marks live face `id` dead; frees its chunk when that was the
    /// chunk's last live face (the last chunk stays, faces go there next),
    /// and moves the live faces of a chunk down to [`SPARSE_AT`] to the map.
    pub(super) fn kill(&mut self, id: usize) {
        let c = id >> BITS;
        self.live[c] -= 1;
        match self.chunks[c].as_mut() {
            Some(ch) => {
                let f = &mut ch[id & MASK];
                debug_assert!(f.alive);
                f.alive = false;
            }
            None => {
                let f = self.sparse.remove(&(id as u32));
                debug_assert!(f.is_some_and(|f| f.alive));
                return;
            }
        }
        let n = self.live[c];
        if n <= SPARSE_AT && c + 1 < self.chunks.len() {
            if let Some(ch) = self.chunks[c].take() {
                let base = (c << BITS) as u32;
                for (i, f) in ch.iter().enumerate().filter(|x| x.1.alive) {
                    self.sparse.insert(base + i as u32, *f);
                }
            }
        }
    }

    /// Every face by id, the dead ones included.
    pub(super) fn iter(&self) -> impl Iterator<Item = &Face> + '_ {
        (0..self.len).map(move |i| &self[i])
    }
}

impl Index<usize> for Faces {
    type Output = Face;
    #[inline]
    fn index(&self, id: usize) -> &Face {
        assert!(id < self.len, "face {id} of {}", self.len);
        match &self.chunks[id >> BITS] {
            Some(c) => &c[id & MASK],
            None if self.live[id >> BITS] == 0 => &DEAD,
            None => self.sparse.get(&(id as u32)).unwrap_or(&DEAD),
        }
    }
}

impl IndexMut<usize> for Faces {
    /// Live faces only (a dead face's chunk may be gone).
    #[inline]
    fn index_mut(&mut self, id: usize) -> &mut Face {
        assert!(id < self.len, "face {id} of {}", self.len);
        match self.chunks[id >> BITS].as_mut() {
            Some(c) => &mut c[id & MASK],
            None => self.sparse.get_mut(&(id as u32)).expect("a live face"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face(k: u32) -> Face {
        Face {
            v: [k, k + 1, k + 2],
            owner: k,
            tries: 0,
            alive: true,
        }
    }

    /// Against a plain vector: the same faces by id, whatever dies in
    /// which order; no chunk kept with [`SPARSE_AT`] live faces or fewer
    /// but the last, and the map holds the live faces of the others.
    #[test]
    fn same_as_a_vector_and_frees_empty_chunks() {
        let mut x = 12345u64;
        let mut rng = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut s = Faces::default();
        let mut plain: Vec<Face> = Vec::new();
        let mut oldest = 0;
        for step in 0..20_000u32 {
            if rng() % 2 == 0 || oldest == plain.len() {
                s.push(face(step));
                plain.push(face(step));
            } else {
                // Mostly the oldest live face dies, as on a front; some at
                // random.
                let id = if rng() % 5 == 0 {
                    (rng() % plain.len() as u64) as usize
                } else {
                    oldest
                };
                // Every 40th face lives to the end, like a pass's faces on
                // its part's walls.
                if plain[id].alive && id % 40 != 0 {
                    s.kill(id);
                    plain[id].alive = false;
                }
                while oldest < plain.len() && (!plain[oldest].alive || oldest % 40 == 0) {
                    oldest += 1;
                }
            }
        }
        assert_eq!(s.len(), plain.len());
        for (i, (a, b)) in s.iter().zip(&plain).enumerate() {
            assert_eq!(a.alive, b.alive, "face {i}");
            if b.alive {
                assert_eq!((a.v, a.owner), (b.v, b.owner), "face {i}");
            }
        }
        for (c, (ch, &n)) in s.chunks.iter().zip(&s.live).enumerate() {
            let want = plain[c << BITS..]
                .iter()
                .take(MASK + 1)
                .filter(|f| f.alive)
                .count();
            assert_eq!(n as usize, want);
            let last = c + 1 == s.chunks.len();
            assert_eq!(ch.is_none(), n <= SPARSE_AT && !last, "chunk {c}");
        }
        // The map holds the live faces of the freed chunks, and no more.
        let in_freed = (0..plain.len())
            .filter(|&i| plain[i].alive && s.chunks[i >> BITS].is_none())
            .count();
        assert_eq!(s.sparse.len(), in_freed);
        assert!(in_freed > 0 && s.chunks.iter().any(|c| c.is_none()));
        s[plain.iter().position(|f| f.alive).unwrap()].tries += 1;
    }
}
