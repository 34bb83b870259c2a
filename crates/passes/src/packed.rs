//! A part's finished tets, packed: once a front call has made them, §7's
//! later passes only add to them, and §8 reads them once. Each tet is its
//! first point as a step from the previous tet's first point, then its
//! other three as steps from its first, each a zigzag varint. A front's
//! tets are made in order of their faces, so the steps are small: about
//! 7 bytes a tet in place of 16 (sphere_5e6 at `--parts 32` on 4 MPI
//! ranks: 9 MB of each rank's peak, which was in the passes).
use parafront_comm::{Wire, WireError};

/// Tets (four point ids each) in the order they were added.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PackedTets {
    bytes: Vec<u8>,
    len: usize,
    /// The last tet's first point: where the next tet's step starts.
    last: u32,
}

#[inline]
fn put(out: &mut Vec<u8>, step: u32) {
    // Zigzag: small steps either way are small numbers.
    let mut x = (step << 1) ^ ((step as i32 >> 31) as u32);
    while x >= 0x80 {
        out.push(x as u8 | 0x80);
        x >>= 7;
    }
    out.push(x as u8);
}

/// One step at `at` (advanced past it), or none where the bytes end
/// inside it or it is longer than a `u32`'s five bytes.
fn try_get(bytes: &[u8], at: &mut usize) -> Option<u32> {
    let mut x = 0u32;
    for k in 0..5 {
        let b = *bytes.get(*at)?;
        *at += 1;
        x |= u32::from(b & 0x7f).checked_shl(7 * k)?;
        if b < 0x80 {
            return Some((x >> 1) ^ (x & 1).wrapping_neg());
        }
    }
    None
}

#[inline]
fn get(bytes: &[u8], at: &mut usize) -> u32 {
    let mut x = 0u32;
    let mut shift = 0;
    loop {
        let b = bytes[*at];
        *at += 1;
        x |= u32::from(b & 0x7f) << shift;
        if b < 0x80 {
            break;
        }
        shift += 7;
    }
    (x >> 1) ^ (x & 1).wrapping_neg()
}

impl PackedTets {
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Appends `tets`, with room made once for all of them.
    pub(crate) fn extend(&mut self, tets: impl IntoIterator<Item = [u32; 4]>) {
        let mut add = Vec::new();
        let mut last = self.last;
        let mut n = 0;
        for t in tets {
            put(&mut add, t[0].wrapping_sub(last));
            for &v in &t[1..] {
                put(&mut add, v.wrapping_sub(t[0]));
            }
            last = t[0];
            n += 1;
        }
        if self.bytes.is_empty() {
            add.shrink_to_fit();
            self.bytes = add;
        } else {
            self.bytes.reserve_exact(add.len());
            self.bytes.extend_from_slice(&add);
        }
        self.len += n;
        self.last = last;
    }

    /// The tets in order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        let (mut at, mut last) = (0, 0u32);
        (0..self.len).map(move |_| {
            let first = last.wrapping_add(get(&self.bytes, &mut at));
            last = first;
            let mut t = [first; 4];
            for v in &mut t[1..] {
                *v = first.wrapping_add(get(&self.bytes, &mut at));
            }
            t
        })
    }

    pub(crate) fn to_vec(&self) -> Vec<[u32; 4]> {
        let mut v = Vec::with_capacity(self.len);
        v.extend(self.iter());
        v
    }

    /// The bytes they take.
    #[cfg(test)]
    pub(crate) fn bytes(&self) -> usize {
        self.bytes.len()
    }
}

/// On the wire as they are held: a batch of tets between processes (§8)
/// is as small as a part's.
impl Wire for PackedTets {
    fn put(&self, buf: &mut Vec<u8>) {
        self.len.put(buf);
        self.bytes.len().put(buf);
        buf.extend_from_slice(&self.bytes);
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let bad = WireError {
            what: "packed tets",
        };
        let (len, n) = <(usize, usize)>::get(buf)?;
        if n > buf.len() {
            return Err(bad);
        }
        let (bytes, rest) = buf.split_at(n);
        *buf = rest;
        // Every tet whole and nothing after the last: the fast reader
        // then never runs off the end.
        let (mut at, mut last) = (0, 0u32);
        for _ in 0..len {
            last = last.wrapping_add(try_get(bytes, &mut at).ok_or(bad)?);
            for _ in 0..3 {
                try_get(bytes, &mut at).ok_or(bad)?;
            }
        }
        if at != bytes.len() {
            return Err(bad);
        }
        Ok(PackedTets {
            bytes: bytes.to_vec(),
            len,
            last,
        })
    }
}

impl FromIterator<[u32; 4]> for PackedTets {
    fn from_iter<I: IntoIterator<Item = [u32; 4]>>(it: I) -> Self {
        let mut p = PackedTets::default();
        p.extend(it);
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Any ids come back as they went in, in order, through any number of
    /// appends, steps up and down and the ends of the range included.
    #[test]
    fn tets_come_back_as_they_went_in() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % n) as u32
        };
        let mut want: Vec<[u32; 4]> = (0..5000)
            .map(|i| {
                let near = 4 * i / 5;
                [0; 4].map(|_| near + next(300))
            })
            .collect();
        want.push([u32::MAX, 0, u32::MAX - 1, 1]);
        want.push([0, u32::MAX, 7, 1 << 31]);
        want.extend((0..100).map(|_| [0; 4].map(|_| next(u32::MAX as u64 + 1))));
        let mut p = PackedTets::default();
        assert_eq!(p.len(), 0);
        for chunk in want.chunks(777) {
            p.extend(chunk.iter().copied());
        }
        assert_eq!(p.len(), want.len());
        assert_eq!(p.to_vec(), want);
        assert_eq!(p.iter().collect::<Vec<_>>(), want);
        let q: PackedTets = want.iter().copied().collect();
        assert_eq!(q.to_vec(), want);
    }

    /// Tets sent and received come back whole; a cut or padded message
    /// is an error, not a panic.
    #[test]
    fn packed_tets_cross_the_wire_and_bad_bytes_are_refused() {
        let tets: Vec<[u32; 4]> = (0..300u32)
            .map(|i| [7 * i, 7 * i + 1, u32::MAX - i, 3 * i + 200_000])
            .collect();
        let p: PackedTets = tets.iter().copied().collect();
        let mut buf = Vec::new();
        p.put(&mut buf);
        (5u8).put(&mut buf);
        let mut r = &buf[..];
        let q = PackedTets::get(&mut r).unwrap();
        assert_eq!(q, p);
        assert_eq!(r, &[5u8][..]);
        let mut more = p.clone();
        more.extend([[1, 2, 3, 4]]);
        let mut both = q;
        both.extend([[1, 2, 3, 4]]);
        assert_eq!(both.to_vec(), more.to_vec());
        for cut in [1, 9, 17, buf.len() - 2] {
            assert!(PackedTets::get(&mut &buf[..cut]).is_err(), "cut at {cut}");
        }
        // One tet fewer than the bytes hold.
        let mut short = Vec::new();
        (p.len() - 1).put(&mut short);
        short.extend_from_slice(&buf[8..buf.len() - 1]);
        assert!(PackedTets::get(&mut &short[..]).is_err());
    }

    /// Tets of nearby ids, as a front makes them, take under half their
    /// 16 bytes.
    #[test]
    fn nearby_ids_pack_small() {
        let tets: Vec<[u32; 4]> = (0..10_000u32)
            .map(|i| {
                let a = 1000 + i / 5;
                [a, a + 3 + i % 7, a - 40 - i % 13, a + 200]
            })
            .collect();
        let p: PackedTets = tets.iter().copied().collect();
        assert_eq!(p.to_vec(), tets);
        assert!(p.bytes() < 8 * tets.len(), "{} bytes", p.bytes());
    }
}
