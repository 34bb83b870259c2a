//! The front's faces by id, every face ever made (ids stay put and only
//! grow), in chunks that are freed once all their faces are dead.
//!
//! A face lives from the tet that opens it to the tet that closes it, so
//! most chunks empty soon after they fill: on sphere_1e6 the store held
//! 20 MB of faces at the end of the front (1M made), 4 MB of them in
//! chunks with a live face. A freed chunk reads as dead faces: code
//! that needs a face's corners after it may have died keeps them itself
//! (`fill_pockets`).
use super::Face;
use std::ops::{Index, IndexMut};

/// Faces per chunk (20 KB).
const BITS: u32 = 10;
const MASK: usize = (1 << BITS) - 1;

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
    /// chunk's last live face (the last chunk stays, faces go there next).
    pub(super) fn kill(&mut self, id: usize) {
        let c = id >> BITS;
        let f = &mut self.chunks[c].as_mut().expect("a live face")[id & MASK];
        debug_assert!(f.alive);
        f.alive = false;
        self.live[c] -= 1;
        if self.live[c] == 0 && c + 1 < self.chunks.len() {
            self.chunks[c] = None;
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
            None => &DEAD,
        }
    }
}

impl IndexMut<usize> for Faces {
    /// Live faces only (a dead face's chunk may be gone).
    #[inline]
    fn index_mut(&mut self, id: usize) -> &mut Face {
        assert!(id < self.len, "face {id} of {}", self.len);
        &mut self.chunks[id >> BITS].as_mut().expect("a live face")[id & MASK]
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
    /// which order, and no chunk kept without a live face but the last.
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
                if plain[id].alive {
                    s.kill(id);
                    plain[id].alive = false;
                }
                while oldest < plain.len() && !plain[oldest].alive {
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
            assert_eq!(ch.is_none(), n == 0 && c + 1 < s.chunks.len(), "chunk {c}");
        }
        assert!(s.chunks.iter().any(|c| c.is_none()));
        s[plain.iter().position(|f| f.alive).unwrap()].tries += 1;
    }
}
