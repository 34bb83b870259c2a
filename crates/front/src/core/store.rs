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
//! end, a few in nearly every chunk, and a front that grows ragged keeps
//! old faces alive everywhere: at sphere_5e6 `--size 0.021`, a part of
//! 640k tets held up to 970 chunks (19 MB) for at most 180k live faces.
//! A chunk (not the last) down to [`PACK_AT`] live faces keeps them alone,
//! with a bit mask of which they are, and is packed again each time half
//! of them have died: the store holds at most about twice its live faces.
use super::Face;
use std::ops::{Index, IndexMut};

/// Faces per chunk (20 KB).
const BITS: u32 = 10;
const MASK: usize = (1 << BITS) - 1;
const WORDS: usize = (MASK + 1) / 64;
/// Live faces at which a chunk (not the last) is packed: its live faces
/// alone, with a mask of which they are (20 bytes a face and 160 a chunk,
/// against the full chunk's 20 KB).
const PACK_AT: u32 = 384;

/// What a face of a freed chunk reads as: dead, with corners and owner
/// out of any range, so that code using a dead face's corners (which
/// freed chunks no longer hold) fails loudly instead of using point 0.
const DEAD: Face = Face {
    v: [u32::MAX; 3],
    owner: u32::MAX - 1,
    tries: 0,
    alive: false,
};

/// A chunk's faces: every slot, only the live ones, or none.
enum Chunk {
    Full(Box<[Face]>),
    Packed(Box<Packed>),
    Gone,
}

/// The faces of a chunk's set bits in `mask`, in id order; a face that
/// dies keeps its slot (dead) until the chunk is packed again.
struct Packed {
    mask: [u64; WORDS],
    /// Set bits in the words before each word.
    before: [u16; WORDS],
    faces: Box<[Face]>,
}

impl Packed {
    /// A chunk's live faces, each with its offset in the chunk, in order.
    fn new<'a>(live: impl Iterator<Item = (usize, &'a Face)>, n: u32) -> Packed {
        let mut mask = [0u64; WORDS];
        let mut faces = Vec::with_capacity(n as usize);
        for (i, f) in live.filter(|x| x.1.alive) {
            mask[i >> 6] |= 1 << (i & 63);
            faces.push(*f);
        }
        let mut before = [0u16; WORDS];
        for w in 1..WORDS {
            before[w] = before[w - 1] + mask[w - 1].count_ones() as u16;
        }
        Packed {
            mask,
            before,
            faces: faces.into_boxed_slice(),
        }
    }

    /// Slot of chunk offset `i` in `faces`, if it has one.
    #[inline]
    fn slot(&self, i: usize) -> Option<usize> {
        let (w, b) = (i >> 6, i & 63);
        let m = self.mask[w];
        ((m >> b) & 1 == 1)
            .then(|| self.before[w] as usize + (m & ((1u64 << b) - 1)).count_ones() as usize)
    }

    /// Chunk offset of each slot, in order.
    fn offsets(&self) -> impl Iterator<Item = usize> + '_ {
        (0..MASK + 1).filter(|&i| (self.mask[i >> 6] >> (i & 63)) & 1 == 1)
    }
}

#[derive(Default)]
pub(super) struct Faces {
    chunks: Vec<Chunk>,
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
                .push(Chunk::Full(vec![DEAD; MASK + 1].into_boxed_slice()));
            self.live.push(0);
        }
        match &mut self.chunks[c] {
            Chunk::Full(ch) => ch[i] = f,
            _ => unreachable!("the last chunk is kept whole"),
        }
        self.live[c] += 1;
        self.len += 1;
    }

    /// Marks live face `id` dead; frees its chunk when that was the
    /// chunk's last live face, and packs a chunk (not the last: faces go
    /// there next) down to [`PACK_AT`] live faces, or a packed one down
    /// to half its slots.
    pub(super) fn kill(&mut self, id: usize) {
        let (c, i) = (id >> BITS, id & MASK);
        self.live[c] -= 1;
        let n = self.live[c];
        let last = c + 1 == self.chunks.len();
        let repack = match &mut self.chunks[c] {
            Chunk::Full(ch) => {
                debug_assert!(ch[i].alive);
                ch[i].alive = false;
                n <= PACK_AT && !last
            }
            Chunk::Packed(p) => {
                let k = p.slot(i).expect("a live face has a slot");
                debug_assert!(p.faces[k].alive);
                p.faces[k].alive = false;
                n == 0 || 2 * n as usize <= p.faces.len()
            }
            Chunk::Gone => unreachable!("a live face's chunk is kept"),
        };
        if !repack {
            return;
        }
        self.chunks[c] = match std::mem::replace(&mut self.chunks[c], Chunk::Gone) {
            _ if n == 0 => Chunk::Gone,
            Chunk::Full(ch) => Chunk::Packed(Box::new(Packed::new(ch.iter().enumerate(), n))),
            Chunk::Packed(p) => {
                Chunk::Packed(Box::new(Packed::new(p.offsets().zip(p.faces.iter()), n)))
            }
            Chunk::Gone => unreachable!("a live face's chunk is kept"),
        };
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
            Chunk::Full(c) => &c[id & MASK],
            Chunk::Packed(p) => p.slot(id & MASK).map_or(&DEAD, |k| &p.faces[k]),
            Chunk::Gone => &DEAD,
        }
    }
}

impl IndexMut<usize> for Faces {
    /// Live faces only (a dead face's chunk may be gone).
    #[inline]
    fn index_mut(&mut self, id: usize) -> &mut Face {
        assert!(id < self.len, "face {id} of {}", self.len);
        match &mut self.chunks[id >> BITS] {
            Chunk::Full(c) => &mut c[id & MASK],
            Chunk::Packed(p) => {
                let k = p.slot(id & MASK).expect("a live face");
                &mut p.faces[k]
            }
            Chunk::Gone => panic!("face {id} is dead"),
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
    /// which order; no chunk but the last kept whole with [`PACK_AT`] live
    /// faces or fewer, a packed chunk holds under twice its live faces,
    /// and a chunk with none is gone.
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
        for step in 0..60_000u32 {
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
                // Every 40th face of the first half lives to the end, like
                // a pass's faces on its part's walls.
                let kept = |id: usize| id.is_multiple_of(40) && id < 8000;
                if plain[id].alive && !kept(id) {
                    s.kill(id);
                    plain[id].alive = false;
                }
                while oldest < plain.len() && (!plain[oldest].alive || kept(oldest)) {
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
        let (mut packed, mut gone) = (0, 0);
        for (c, (ch, &n)) in s.chunks.iter().zip(&s.live).enumerate() {
            let want = plain[c << BITS..]
                .iter()
                .take(MASK + 1)
                .filter(|f| f.alive)
                .count();
            assert_eq!(n as usize, want);
            let last = c + 1 == s.chunks.len();
            match ch {
                Chunk::Full(_) => assert!(last || n > PACK_AT, "chunk {c}: {n} live"),
                Chunk::Packed(p) => {
                    packed += 1;
                    assert!(!last && n > 0 && n <= PACK_AT, "chunk {c}: {n} live");
                    // At most twice its live faces, and one slot per set bit.
                    assert!(p.faces.len() < 2 * n as usize, "chunk {c}");
                    let bits: u32 = p.mask.iter().map(|m| m.count_ones()).sum();
                    assert_eq!(bits as usize, p.faces.len());
                }
                Chunk::Gone => {
                    gone += 1;
                    assert!(!last && n == 0, "chunk {c}");
                }
            }
        }
        assert!(packed > 0 && gone > 0, "{packed} packed, {gone} gone");
        s[plain.iter().position(|f| f.alive).unwrap()].tries += 1;
    }
}
