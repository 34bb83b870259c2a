//! The bytes a message travels as between processes.
//!
//! [`Wire`] is the one bound the collectives of [`Comm`](crate::Comm) add
//! to `Send`: a value writes itself to a byte buffer and reads itself back.
//! The encoding is little-endian and exact (a float travels as its bits,
//! so -0.0 and NaN payloads survive), with no header: both ends are the
//! same program. The threads backend never encodes (it moves buffers); a
//! distributed backend encodes what leaves the process.

use std::fmt;

/// A buffer ended before the value it should hold, or held a byte no value
/// of its type writes: the two ends disagree on the message's type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WireError {
    /// What was being read.
    pub what: &'static str,
}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "malformed message: bad or missing bytes for {}",
            self.what
        )
    }
}

impl std::error::Error for WireError {}

/// A value that can travel between processes as bytes.
pub trait Wire: Sized {
    /// Appends the value's bytes to `buf`.
    fn put(&self, buf: &mut Vec<u8>);
    /// Reads one value from the front of `buf` and advances it past it.
    fn get(buf: &mut &[u8]) -> Result<Self, WireError>;
}

/// The first `N` bytes of `buf`, which advances past them.
pub fn take<const N: usize>(buf: &mut &[u8], what: &'static str) -> Result<[u8; N], WireError> {
    if buf.len() < N {
        return Err(WireError { what });
    }
    let (head, rest) = buf.split_at(N);
    *buf = rest;
    Ok(head.try_into().expect("N bytes"))
}

macro_rules! wire_num {
    ($($t:ty),*) => {$(
        impl Wire for $t {
            #[inline]
            fn put(&self, buf: &mut Vec<u8>) {
                buf.extend_from_slice(&self.to_le_bytes());
            }
            #[inline]
            fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
                Ok(<$t>::from_le_bytes(take(buf, stringify!($t))?))
            }
        }
    )*};
}
wire_num!(u8, u16, u32, u64, i8, i16, i32, i64);

impl Wire for usize {
    #[inline]
    fn put(&self, buf: &mut Vec<u8>) {
        (*self as u64).put(buf);
    }
    #[inline]
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        usize::try_from(u64::get(buf)?).map_err(|_| WireError { what: "usize" })
    }
}

impl Wire for f64 {
    #[inline]
    fn put(&self, buf: &mut Vec<u8>) {
        self.to_bits().put(buf);
    }
    #[inline]
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        Ok(f64::from_bits(u64::get(buf)?))
    }
}

impl Wire for f32 {
    #[inline]
    fn put(&self, buf: &mut Vec<u8>) {
        self.to_bits().put(buf);
    }
    #[inline]
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        Ok(f32::from_bits(u32::get(buf)?))
    }
}

impl Wire for bool {
    #[inline]
    fn put(&self, buf: &mut Vec<u8>) {
        buf.push(*self as u8);
    }
    #[inline]
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        match take::<1>(buf, "bool")?[0] {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(WireError { what: "bool" }),
        }
    }
}

impl Wire for () {
    fn put(&self, _: &mut Vec<u8>) {}
    fn get(_: &mut &[u8]) -> Result<Self, WireError> {
        Ok(())
    }
}

impl<T: Wire, const N: usize> Wire for [T; N] {
    #[inline]
    fn put(&self, buf: &mut Vec<u8>) {
        for x in self {
            x.put(buf);
        }
    }
    #[inline]
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let mut err = None;
        let a: [Option<T>; N] = std::array::from_fn(|_| {
            if err.is_some() {
                return None;
            }
            T::get(buf).map_err(|e| err = Some(e)).ok()
        });
        match err {
            Some(e) => Err(e),
            None => Ok(a.map(|x| x.expect("read above"))),
        }
    }
}

impl<T: Wire> Wire for Vec<T> {
    fn put(&self, buf: &mut Vec<u8>) {
        self.len().put(buf);
        for x in self {
            x.put(buf);
        }
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let n = usize::get(buf)?;
        // A length larger than the bytes left is malformed: no huge
        // allocation on a bad buffer.
        let mut v = Vec::with_capacity(n.min(buf.len()));
        for _ in 0..n {
            v.push(T::get(buf)?);
        }
        Ok(v)
    }
}

impl<T: Wire> Wire for Option<T> {
    fn put(&self, buf: &mut Vec<u8>) {
        self.is_some().put(buf);
        if let Some(x) = self {
            x.put(buf);
        }
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        Ok(if bool::get(buf)? {
            Some(T::get(buf)?)
        } else {
            None
        })
    }
}

impl Wire for String {
    fn put(&self, buf: &mut Vec<u8>) {
        self.len().put(buf);
        buf.extend_from_slice(self.as_bytes());
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let n = usize::get(buf)?;
        if buf.len() < n {
            return Err(WireError { what: "String" });
        }
        let (head, rest) = buf.split_at(n);
        *buf = rest;
        String::from_utf8(head.to_vec()).map_err(|_| WireError { what: "String" })
    }
}

macro_rules! wire_tuple {
    ($($n:ident),+) => {
        impl<$($n: Wire),+> Wire for ($($n,)+) {
            #[inline]
            #[allow(non_snake_case)]
            fn put(&self, buf: &mut Vec<u8>) {
                let ($($n,)+) = self;
                $($n.put(buf);)+
            }
            #[inline]
            fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
                Ok(($($n::get(buf)?,)+))
            }
        }
    };
}
wire_tuple!(A);
wire_tuple!(A, B);
wire_tuple!(A, B, C);
wire_tuple!(A, B, C, D);

/// `x` as bytes.
pub fn to_bytes<T: Wire>(x: &T) -> Vec<u8> {
    let mut buf = Vec::new();
    x.put(&mut buf);
    buf
}

/// The value `bytes` hold, which must be all of them.
pub fn from_bytes<T: Wire>(mut bytes: &[u8]) -> Result<T, WireError> {
    let x = T::get(&mut bytes)?;
    if bytes.is_empty() {
        Ok(x)
    } else {
        Err(WireError {
            what: "the end of the message",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round<T: Wire + PartialEq + fmt::Debug>(x: T) {
        assert_eq!(from_bytes::<T>(&to_bytes(&x)).unwrap(), x);
    }

    #[test]
    fn values_come_back() {
        round(7u8);
        round(u32::MAX);
        round(-5i64);
        round(usize::MAX);
        round(true);
        round([1.5f64, -2.0, 1e300]);
        round(vec![vec![1u32, 2], vec![], vec![3]]);
        round((3u32, [0.25f64; 3], Some(false), None::<u8>));
        round(String::from("ρ = 1"));
    }

    #[test]
    fn floats_travel_as_bits() {
        let back: [f64; 3] = from_bytes(&to_bytes(&[-0.0f64, f64::NAN, f64::INFINITY])).unwrap();
        assert_eq!(back[0].to_bits(), (-0.0f64).to_bits());
        assert_eq!(back[1].to_bits(), f64::NAN.to_bits());
        assert_eq!(back[2], f64::INFINITY);
    }

    #[test]
    fn short_or_long_buffers_are_errors() {
        let b = to_bytes(&vec![1u32, 2, 3]);
        assert!(from_bytes::<Vec<u32>>(&b[..b.len() - 1]).is_err());
        let mut long = b.clone();
        long.push(0);
        assert!(from_bytes::<Vec<u32>>(&long).is_err());
        assert!(from_bytes::<bool>(&[2]).is_err());
        // A length that the bytes cannot hold does not allocate it.
        assert!(from_bytes::<Vec<u8>>(&to_bytes(&u64::MAX)).is_err());
    }
}
