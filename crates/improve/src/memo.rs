//! The idle memo of the swaps and collapses (`Improver::idle_at`): the
//! operations that did nothing, by key, at the clock of the try. A
//! direct-mapped table of fixed size: a newer try takes the slot of an
//! older one (which is then only tried again), so a lookup is one probe
//! and the memory stays bounded. A hash map of every try cost smooth
//! meshes, whose bad tets are rarely neighbours, more than it saved
//! (sphere_1e5: swaps 0.130 -> 0.158 s, 14 more bytes per tet at peak).

/// Operations that did nothing, by key (three point ids; see
/// `Improver::idle_at`), with the clock of the try.
pub(crate) struct IdleMemo {
    /// Allocated at the first insertion (many parts never need one).
    slots: Vec<([u32; 3], u32)>,
    len: usize,
}

/// No key: an edge's or a collapse's key ends in one sentinel, a face's
/// holds three point ids.
const EMPTY: [u32; 3] = [u32::MAX; 3];

impl IdleMemo {
    /// A table for a mesh of `tets` tets: a slot per tet, 2^10 to 2^15.
    pub(crate) fn new(tets: usize) -> IdleMemo {
        IdleMemo {
            slots: Vec::new(),
            len: tets.next_power_of_two().clamp(1 << 10, 1 << 15),
        }
    }

    #[inline]
    fn slot(&self, k: [u32; 3]) -> usize {
        let h = (k[0] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (k[1] as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
            ^ (k[2] as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
        (h >> 32) as usize & (self.len - 1)
    }

    /// `key`'s try at clock `at` did nothing.
    #[inline]
    pub(crate) fn insert(&mut self, key: [u32; 3], at: u32) {
        if self.slots.is_empty() {
            self.slots = vec![(EMPTY, 0); self.len];
        }
        let i = self.slot(key);
        self.slots[i] = (key, at);
    }

    /// The clock of `key`'s last try that did nothing, if the table still
    /// holds it.
    #[inline]
    pub(crate) fn get(&self, key: [u32; 3]) -> Option<u32> {
        let &(k, at) = self.slots.get(self.slot(key))?;
        (k == key && key != EMPTY).then_some(at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What it holds is what was put last in its slot: every key of a
    /// table too small for them is either found at its clock or not found.
    #[test]
    fn holds_the_last_try_of_a_slot_or_nothing() {
        let mut m = IdleMemo::new(0);
        let keys: Vec<[u32; 3]> = (0..5000u32).map(|i| [i, i + 7, u32::MAX]).collect();
        for (at, &k) in keys.iter().enumerate() {
            m.insert(k, at as u32 + 1);
        }
        let mut found = 0;
        for (at, &k) in keys.iter().enumerate() {
            if let Some(a) = m.get(k) {
                assert_eq!(a, at as u32 + 1);
                found += 1;
            }
        }
        // 1,024 slots: at most that many, and most of them used.
        assert!(found <= 1024 && found > 500, "{found}");
        assert_eq!(m.get([1, 2, 3]), None);
        assert_eq!(m.get(EMPTY), None);
    }
}
