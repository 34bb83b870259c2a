//! A hierarchical loose hash grid for the close-point and close-face
//! searches (AF2.2, AF2.3).
//!
//! Sizes in one mesh span five orders of magnitude (CAD needles next to a
//! coarse DDG interior), so one uniform grid is either too fine for the big
//! faces or too coarse for the small ones. Level `k` has cells of size
//! `s0 * 2^k`; an item of extent `e` lives at the level whose cell is at
//! least `e`, keyed by the cell of its centre, so it stays within half a
//! cell of that cell ("loose"). A query visits each non-empty level,
//! either cell by cell or, when that would touch more cells than the level
//! holds items, by scanning the level's items.
use parafront_geom::{Aabb, P3};
use rustc_hash::FxHashMap;

const NIL: u32 = u32::MAX;
const MAX_LEVELS: usize = 40;

#[derive(Clone, Debug)]
struct Level {
    cell: f64,
    /// Cell key -> first slot of that cell's doubly linked list.
    heads: FxHashMap<u64, u32>,
    /// Items at this level, for the scan path (swap-remove, `pos` indexes it).
    items: Vec<u32>,
}

/// Items are `u32` ids chosen by the caller (point ids, face ids).
#[derive(Clone, Debug)]
pub struct LooseGrid {
    s0: f64,
    origin: P3,
    levels: Vec<Level>,
    // Per item id: its level, cell key, list links. No centre: the caller
    // filters exactly anyway, and 24 bytes per face id was a third of the
    // front's memory.
    lvl: Vec<u8>,
    key: Vec<u64>,
    next: Vec<u32>,
    prev: Vec<u32>,
    pos: Vec<u32>,
    len: usize,
    /// Bit `k` set: level `k` holds items (queries skip the rest).
    used: u64,
}

#[inline]
fn cell_key(c: [i64; 3]) -> u64 {
    // 21 bits per axis, wrapped: collisions only cost extra candidates.
    let m = (1u64 << 21) - 1;
    ((c[0] as u64) & m) | (((c[1] as u64) & m) << 21) | (((c[2] as u64) & m) << 42)
}

impl LooseGrid {
    /// `s0`: the finest cell size (about the smallest item extent);
    /// `origin`: any point near the data (keeps cell indices small).
    pub fn new(s0: f64, origin: P3) -> LooseGrid {
        let s0 = if s0.is_finite() && s0 > 0.0 { s0 } else { 1.0 };
        let levels = (0..MAX_LEVELS)
            .map(|k| Level {
                cell: s0 * (1u64 << k.min(62)) as f64,
                heads: FxHashMap::default(),
                items: Vec::new(),
            })
            .collect();
        LooseGrid {
            s0,
            origin,
            levels,
            lvl: Vec::new(),
            key: Vec::new(),
            next: Vec::new(),
            prev: Vec::new(),
            pos: Vec::new(),
            len: 0,
            used: 0,
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    #[inline]
    fn cell_of(&self, p: P3, cell: f64) -> [i64; 3] {
        [
            ((p[0] - self.origin[0]) / cell).floor() as i64,
            ((p[1] - self.origin[1]) / cell).floor() as i64,
            ((p[2] - self.origin[2]) / cell).floor() as i64,
        ]
    }

    fn level_for(&self, extent: f64) -> usize {
        let mut k = 0;
        while k + 1 < MAX_LEVELS && self.levels[k].cell < extent {
            k += 1;
        }
        k
    }

    pub fn contains(&self, id: u32) -> bool {
        (id as usize) < self.lvl.len() && self.lvl[id as usize] != u8::MAX
    }

    /// Insert item `id` with centre `c` and extent (diameter) `extent`.
    pub fn insert(&mut self, id: u32, c: P3, extent: f64) {
        let i = id as usize;
        if i >= self.lvl.len() {
            let n = (i + 1).max(self.lvl.len() * 3 / 2);
            self.lvl.resize(n, u8::MAX);
            self.key.resize(n, 0);
            self.next.resize(n, NIL);
            self.prev.resize(n, NIL);
            self.pos.resize(n, NIL);
        }
        debug_assert!(self.lvl[i] == u8::MAX, "item {id} inserted twice");
        let k = self.level_for(extent);
        let key = cell_key(self.cell_of(c, self.levels[k].cell));
        let lv = &mut self.levels[k];
        let head = lv.heads.entry(key).or_insert(NIL);
        self.next[i] = *head;
        self.prev[i] = NIL;
        if *head != NIL {
            self.prev[*head as usize] = id;
        }
        *head = id;
        self.pos[i] = lv.items.len() as u32;
        lv.items.push(id);
        self.lvl[i] = k as u8;
        self.used |= 1 << k;
        self.key[i] = key;
        self.len += 1;
    }

    pub fn remove(&mut self, id: u32) {
        let i = id as usize;
        if !self.contains(id) {
            return;
        }
        let k = self.lvl[i] as usize;
        let lv = &mut self.levels[k];
        let (p, n) = (self.prev[i], self.next[i]);
        if p != NIL {
            self.next[p as usize] = n;
        } else if n == NIL {
            lv.heads.remove(&self.key[i]);
        } else {
            lv.heads.insert(self.key[i], n);
        }
        if n != NIL {
            self.prev[n as usize] = p;
        }
        let at = self.pos[i] as usize;
        lv.items.swap_remove(at);
        if lv.items.is_empty() {
            self.used &= !(1 << k);
        }
        if at < lv.items.len() {
            self.pos[lv.items[at] as usize] = at as u32;
        }
        self.lvl[i] = u8::MAX;
        self.len -= 1;
    }

    /// Calls `f(id)` for every item whose loose cell may overlap `q`
    /// (a superset: the caller filters exactly).
    pub fn query(&self, q: &Aabb, mut f: impl FnMut(u32)) {
        let mut used = self.used;
        while used != 0 {
            let k = used.trailing_zeros() as usize;
            used &= used - 1;
            let lv = &self.levels[k];
            // Items sit within half a cell of their cell.
            let qq = q.inflated(0.5 * lv.cell);
            let lo = self.cell_of(qq.min, lv.cell);
            let hi = self.cell_of(qq.max, lv.cell);
            let ncell = (hi[0] - lo[0] + 1) as f64
                * (hi[1] - lo[1] + 1) as f64
                * (hi[2] - lo[2] + 1) as f64;
            if ncell > lv.items.len() as f64 || ncell > (1u64 << 40) as f64 {
                for &id in &lv.items {
                    f(id);
                }
                continue;
            }
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        if let Some(&h) = lv.heads.get(&cell_key([x, y, z])) {
                            let mut id = h;
                            while id != NIL {
                                // Wrapped keys can alias: the caller filters.
                                f(id);
                                id = self.next[id as usize];
                            }
                        }
                    }
                }
            }
        }
    }

    pub fn finest_cell(&self) -> f64 {
        self.s0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(items: &[(u32, P3, f64)], q: &Aabb) -> Vec<u32> {
        // Every item whose box (centre +- extent/2) overlaps q.
        let mut v: Vec<u32> = items
            .iter()
            .filter(|(_, c, e)| {
                let b = Aabb { min: *c, max: *c }.inflated(0.5 * e);
                b.overlaps(q)
            })
            .map(|x| x.0)
            .collect();
        v.sort();
        v
    }

    #[test]
    fn query_is_a_superset_of_overlapping_items() {
        let mut g = LooseGrid::new(0.01, [0.0; 3]);
        let mut items = Vec::new();
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for id in 0..3000u32 {
            let c = [rnd(), rnd(), rnd()];
            let e = 0.001 * (1.0 + 300.0 * rnd() * rnd() * rnd());
            g.insert(id, c, e);
            items.push((id, c, e));
        }
        // Remove a third, then check queries.
        for id in (0..3000u32).step_by(3) {
            g.remove(id);
        }
        items.retain(|x| x.0 % 3 != 0);
        assert_eq!(g.len(), items.len());
        for _ in 0..200 {
            let c = [rnd(), rnd(), rnd()];
            let r = 0.2 * rnd();
            let q = Aabb { min: c, max: c }.inflated(r);
            let mut got = Vec::new();
            g.query(&q, |id| got.push(id));
            got.sort();
            got.dedup();
            for id in brute(&items, &q) {
                assert!(got.binary_search(&id).is_ok(), "missed item {id}");
            }
            assert!(got.iter().all(|id| id % 3 != 0), "returned a removed item");
        }
    }
}
