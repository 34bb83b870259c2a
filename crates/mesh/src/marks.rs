//! A set of indices that empties in O(1): an index is in it while its
//! stamp is the current epoch. The mesher's walks use it for what they
//! have visited (the tets a ball walk has reached, the points a batch
//! holds, the front points a close-face search has seen).

/// An index set over `0..n` whose [`Marks::clear`] costs nothing but a
/// new epoch (all stamps are reset only when the epoch wraps). Stamp 0 is
/// never an epoch, so unstamped and removed indices are never in it.
#[derive(Clone, Debug)]
pub struct Marks {
    stamp: Vec<u32>,
    epoch: u32,
}

impl Default for Marks {
    /// Empty, with room for no index (see [`Marks::clear`], [`Marks::grow`]).
    fn default() -> Self {
        Marks {
            stamp: Vec::new(),
            epoch: 1,
        }
    }
}

impl Marks {
    /// Empties the set, for indices below `n` from now on (it only grows).
    #[inline]
    pub fn clear(&mut self, n: usize) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
        if self.stamp.len() < n {
            self.stamp.resize(n, 0);
        }
    }

    /// Adds `i`; whether it was not in the set yet.
    #[inline]
    pub fn insert(&mut self, i: usize) -> bool {
        let new = self.stamp[i] != self.epoch;
        self.stamp[i] = self.epoch;
        new
    }

    /// Takes `i` out of the set.
    #[inline]
    pub fn remove(&mut self, i: usize) {
        self.stamp[i] = 0;
    }

    /// Makes room for indices below `n`, the set unchanged (a store that
    /// grows between clears).
    #[inline]
    pub fn grow(&mut self, n: usize) {
        if self.stamp.len() < n {
            self.stamp.resize(n, 0);
        }
    }

    /// Whether `i` is in the set.
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        self.stamp[i] == self.epoch
    }

    /// The invariant: no stamp is ahead of the epoch (a stamp from the
    /// future would put its index in a later set it was never added to).
    pub fn check(&self) -> Result<(), String> {
        match self.stamp.iter().position(|&s| s > self.epoch) {
            Some(i) => Err(format!(
                "index {i} has stamp {} ahead of the epoch {}",
                self.stamp[i], self.epoch
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Marks;

    #[test]
    fn a_clear_empties_the_set_and_keeps_its_size() {
        let mut m = Marks::default();
        m.clear(4);
        assert!(m.insert(2));
        assert!(!m.insert(2), "already in");
        assert!(m.contains(2) && !m.contains(1));
        m.clear(2);
        assert!(!m.contains(2), "emptied");
        assert!(m.insert(3), "index 3 is still there after a smaller clear");
        m.check().unwrap();
    }

    /// A new set is empty before any clear, also where `grow` made room
    /// (with the epoch at 0 every unstamped index was in it).
    #[test]
    fn a_new_set_is_empty() {
        let mut m = Marks::default();
        m.grow(3);
        assert!((0..3).all(|i| !m.contains(i)));
        assert!(m.insert(1));
        m.remove(1);
        assert!(!m.contains(1));
        m.check().unwrap();
    }

    /// A removed index is out until inserted again; `grow` makes room and
    /// keeps what is in (the Delaunay kernel adds tets to a cavity's
    /// store while the cavity stands).
    #[test]
    fn remove_takes_one_out_and_grow_keeps_the_set() {
        let mut m = Marks::default();
        m.clear(2);
        m.insert(0);
        m.insert(1);
        m.remove(0);
        assert!(!m.contains(0) && m.contains(1));
        m.grow(5);
        assert!(m.contains(1), "grow keeps the set");
        assert!(!m.contains(4) && m.insert(4));
        m.check().unwrap();
    }

    /// When the epoch wraps, every old stamp goes, or an index stamped
    /// at epoch 1 long ago would be in the new set.
    #[test]
    fn the_wrap_of_the_epoch_resets_every_stamp() {
        let mut m = Marks::default();
        m.clear(3);
        m.insert(0); // stamped 1
        m.epoch = u32::MAX;
        m.insert(1); // stamped u32::MAX
        m.clear(3); // wraps: epoch 1 again
        assert!(!m.contains(0), "a stamp of the old epoch 1");
        assert!(!m.contains(1));
        m.check().unwrap();
        m.stamp[2] = 7;
        assert!(m.check().is_err(), "a stamp ahead of the epoch");
    }
}
