//! Dropping dead entries from flat arrays: one renumbering for the front's
//! output and the improvement's, so that tets, neighbours and points are
//! compacted the same way everywhere.

/// The new id of a dropped entry.
pub const DROPPED: u32 = u32::MAX;

/// New ids for the entries `keep` says to keep, in order (`DROPPED` for
/// the others), and how many are kept.
pub fn keep_map(keep: impl IntoIterator<Item = bool>) -> (Vec<u32>, usize) {
    let mut k = 0u32;
    let map = keep
        .into_iter()
        .map(|kept| {
            if kept {
                k += 1;
                k - 1
            } else {
                DROPPED
            }
        })
        .collect();
    (map, k as usize)
}

/// Move each kept entry of `v` (`per` values an entry) to its new id under
/// `map`, in place (a new id is never above the old), and truncate.
pub fn compact<T: Copy>(v: &mut Vec<T>, map: &[u32], per: usize) {
    let mut n = 0;
    for (i, &j) in map.iter().enumerate() {
        if j == DROPPED {
            continue;
        }
        let j = j as usize;
        for c in 0..per {
            v[per * j + c] = v[per * i + c];
        }
        n = j + 1;
    }
    v.truncate(per * n);
}

/// A face reference `4t+f` (or `none`) under the tet map `tmap`.
#[inline]
pub fn remap_face(nb: u32, tmap: &[u32], none: u32) -> u32 {
    if nb == none {
        none
    } else {
        4 * tmap[(nb >> 2) as usize] + (nb & 3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_entries_move_down_in_order() {
        let (map, n) = keep_map([true, false, true, true, false]);
        assert_eq!((map.clone(), n), (vec![0, DROPPED, 1, 2, DROPPED], 3));
        let mut v = vec![10, 11, 20, 21, 30, 31, 40, 41, 50, 51];
        compact(&mut v, &map, 2);
        assert_eq!(v, vec![10, 11, 30, 31, 40, 41]);
        assert_eq!(remap_face(4 * 3 + 2, &map, u32::MAX), 4 * 2 + 2);
        assert_eq!(remap_face(u32::MAX, &map, u32::MAX), u32::MAX);
        let (map, n) = keep_map([false, false]);
        let mut v = vec![1, 2];
        compact(&mut v, &map, 1);
        assert!(v.is_empty() && n == 0);
    }
}
