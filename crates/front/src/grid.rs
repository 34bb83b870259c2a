//! A hierarchical loose hash grid for the close-point and close-face
//! searches (AF2.2, AF2.3).
//!
//! Sizes in one mesh span five orders of magnitude (CAD needles next to a
//! coarse DDG interior), so one uniform grid is either too fine for the big
//! faces or too coarse for the small ones. Level `k` has cells of size
//! `s0 * 2^k`; an item of extent `e` lives at the level whose cell is at
//! least `2e`, keyed by the cell of its centre, so it stays within a
//! quarter cell of that cell ("loose"). A cell holds its items' boxes, so a query
//! returns only items whose box meets it. A query visits each non-empty level,
//! either cell by cell or, when that would touch more cells than the level
//! holds items, by scanning the level's items.
use parafront_geom::{Aabb, P3};
use rustc_hash::FxHashMap;

const MAX_LEVELS: usize = 40;

/// An item with its box in `f32`, relative to the grid's origin and
/// rounded outwards: a query filters on it without touching the caller's
/// arrays (a random load per item was most of the search's time).
///
/// The box is kept as `[lo, -hi, -inf, -inf]` against a query's `[qhi,
/// -qlo, inf, inf]`: the test is eight `<=` lane by lane, two vector
/// compares (AF2.2's search scans about seven entries per hit).
#[derive(Clone, Copy, Debug)]
struct Entry {
    key: [f32; 8],
    id: u32,
    /// The item's payload (a face's corners): a hit then needs no load
    /// from the caller's arrays, which are ten times the live front.
    v: [u32; 3],
}

#[inline]
fn lanes(lo: [f32; 3], hi: [f32; 3], pad: f32) -> [f32; 8] {
    [lo[0], lo[1], lo[2], -hi[0], -hi[1], -hi[2], pad, pad]
}

#[derive(Clone, Debug)]
struct Level {
    cell: f64,
    /// Cell key -> index into `LooseGrid::cells`.
    heads: FxHashMap<u64, u32>,
    len: usize,
}

/// Items are `u32` ids chosen by the caller (point ids, face ids). The grid
/// keeps nothing per id, only per live item: ids of dead faces cost no
/// memory here.
#[derive(Clone, Debug)]
pub struct LooseGrid {
    origin: P3,
    levels: Vec<Level>,
    cells: Vec<Vec<Entry>>,
    /// Emptied cells, kept with their allocation for reuse.
    free: Vec<u32>,
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

/// `x.floor() as i64` without a call to libm's `floor` (x86-64 has no
/// rounding instruction before SSE4.1): truncate, then step down for a
/// negative fraction; saturates as `as` does.
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    t.saturating_sub(((t as f64) > x) as i64)
}

#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint; it never faults, whatever the address.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(p as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

#[inline]
fn down(x: f64) -> f32 {
    let y = x as f32;
    if y as f64 > x {
        y.next_down()
    } else {
        y
    }
}

#[inline]
fn up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        y.next_up()
    } else {
        y
    }
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
                len: 0,
            })
            .collect();
        LooseGrid {
            origin,
            levels,
            cells: Vec::new(),
            free: Vec::new(),
            len: 0,
            used: 0,
        }
    }

    /// Items held (the tests count them).
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.len
    }

    #[inline]
    fn cell_of(&self, p: P3, cell: f64) -> [i64; 3] {
        [0, 1, 2].map(|k| floor_i64((p[k] - self.origin[k]) / cell))
    }

    /// Level and cell key of an item with box `b`.
    #[inline]
    fn place(&self, b: &Aabb) -> (usize, u64) {
        let ext = (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0, f64::max);
        let mut k = 0;
        // Cells of at least twice the extent: a query's box (about twice a
        // face) then spans 2-3 cells per axis. Equal cells took 15 % longer:
        // each cell is a cache miss, a box test is not.
        while k + 1 < MAX_LEVELS && self.levels[k].cell < 2.0 * ext {
            k += 1;
        }
        (k, cell_key(self.cell_of(b.center(), self.levels[k].cell)))
    }

    /// `b` relative to the origin, rounded outwards to `f32`.
    #[inline]
    fn rel(&self, b: &Aabb) -> ([f32; 3], [f32; 3]) {
        let o = self.origin;
        (
            [0, 1, 2].map(|k| down(b.min[k] - o[k])),
            [0, 1, 2].map(|k| up(b.max[k] - o[k])),
        )
    }

    /// Insert item `id`, carrying `v`, with box `b` (the same box must be given to
    /// `remove`).
    pub fn insert(&mut self, id: u32, v: [u32; 3], b: &Aabb) {
        let (k, key) = self.place(b);
        let (lo, hi) = self.rel(b);
        let lv = &mut self.levels[k];
        let c = match lv.heads.get(&key) {
            Some(&c) => c,
            None => {
                let c = match self.free.pop() {
                    Some(c) => c,
                    None => {
                        self.cells.push(Vec::new());
                        (self.cells.len() - 1) as u32
                    }
                };
                lv.heads.insert(key, c);
                c
            }
        };
        let key = lanes(lo, hi, f32::NEG_INFINITY);
        self.cells[c as usize].push(Entry { key, id, v });
        lv.len += 1;
        self.used |= 1 << k;
        self.len += 1;
    }

    /// Remove item `id`, inserted with box `b`; absent items are ignored.
    pub fn remove(&mut self, id: u32, b: &Aabb) {
        let (k, key) = self.place(b);
        let lv = &mut self.levels[k];
        let Some(&c) = lv.heads.get(&key) else {
            return;
        };
        let cell = &mut self.cells[c as usize];
        let Some(at) = cell.iter().position(|e| e.id == id) else {
            return;
        };
        cell.swap_remove(at);
        // A cell the front has passed through keeps no more than twice its
        // items: at their largest, the cells held 2.3 times the live front.
        if cell.len() * 4 <= cell.capacity() && cell.capacity() > 8 {
            cell.shrink_to(2 * cell.len());
        }
        if cell.is_empty() {
            lv.heads.remove(&key);
            self.free.push(c);
        }
        lv.len -= 1;
        if lv.len == 0 {
            self.used &= !(1 << k);
        }
        self.len -= 1;
    }

    /// Calls `f(id, v)` for every item whose box may overlap `q` (a superset:
    /// the boxes are `f32`, rounded outwards).
    pub fn query(&self, q: &Aabb, mut f: impl FnMut(u32, [u32; 3])) {
        let (qlo, qhi) = self.rel(q);
        let qk = lanes(qhi, qlo, f32::INFINITY);
        // Once per query: zeroing it per cell was 2 % of the front's time.
        let mut buf = [(0u32, [0u32; 3]); 64];
        let mut scan = |cell: &[Entry]| {
            // Branch-free: a branch per entry was often mispredicted.
            for chunk in cell.chunks(64) {
                let mut n = 0;
                for e in chunk {
                    let mut hit = true;
                    for (a, b) in e.key.iter().zip(&qk) {
                        hit &= a <= b;
                    }
                    buf[n & 63] = (e.id, e.v);
                    n += hit as usize;
                }
                for &(id, v) in &buf[..n] {
                    f(id, v);
                }
            }
        };
        let mut used = self.used;
        while used != 0 {
            let k = used.trailing_zeros() as usize;
            used &= used - 1;
            let lv = &self.levels[k];
            // Items sit within a quarter cell of their cell.
            let qq = q.inflated(0.25 * lv.cell);
            let lo = self.cell_of(qq.min, lv.cell);
            let hi = self.cell_of(qq.max, lv.cell);
            let ncell = (hi[0] - lo[0] + 1) as f64
                * (hi[1] - lo[1] + 1) as f64
                * (hi[2] - lo[2] + 1) as f64;
            if ncell > lv.heads.len() as f64 || ncell > (1u64 << 40) as f64 {
                for &c in lv.heads.values() {
                    scan(&self.cells[c as usize]);
                }
                continue;
            }
            // The cells first, each prefetched, then their items: the
            // loads of one cell's items overlap the next one's misses.
            let mut found = [0u32; 64];
            let mut n = 0;
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        // Wrapped keys can alias: the box test filters.
                        if let Some(&c) = lv.heads.get(&cell_key([x, y, z])) {
                            if n == found.len() {
                                found.iter().for_each(|&c| scan(&self.cells[c as usize]));
                                n = 0;
                            }
                            prefetch(self.cells[c as usize].as_ptr());
                            found[n] = c;
                            n += 1;
                        }
                    }
                }
            }
            found[..n]
                .iter()
                .for_each(|&c| scan(&self.cells[c as usize]));
        }
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
    fn floor_i64_is_floor() {
        for x in [
            0.0, -0.0, 0.5, -0.5, 1.0, -1.0, -1.5, 2.75, -2.75, 1e30, -1e30, 9.3e18, -9.3e18,
        ] {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
        for x in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
    }

    #[test]
    fn a_cell_emptied_to_a_quarter_gives_back_its_room() {
        let mut g = LooseGrid::new(1.0, [0.0; 3]);
        let b = Aabb {
            min: [0.1; 3],
            max: [0.2; 3],
        };
        for id in 0..64 {
            g.insert(id, [id; 3], &b);
        }
        assert_eq!(g.cells.len(), 1);
        for id in 0..60 {
            g.remove(id, &b);
        }
        let cell = &g.cells[0];
        assert_eq!(cell.len(), 4);
        assert!(cell.capacity() <= 16, "{}", cell.capacity());
        let mut got = Vec::new();
        g.query(&b, |id, _| got.push(id));
        got.sort();
        assert_eq!(got, vec![60, 61, 62, 63]);
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
            g.insert(id, [id; 3], &Aabb { min: c, max: c }.inflated(0.5 * e));
            items.push((id, c, e));
        }
        // Remove a third, then check queries.
        for id in (0..3000u32).step_by(3) {
            let (_, c, e) = items[id as usize];
            g.remove(id, &Aabb { min: c, max: c }.inflated(0.5 * e));
        }
        items.retain(|x| x.0 % 3 != 0);
        assert_eq!(g.len(), items.len());
        for _ in 0..200 {
            let c = [rnd(), rnd(), rnd()];
            let r = 0.2 * rnd();
            let q = Aabb { min: c, max: c }.inflated(r);
            let mut got = Vec::new();
            g.query(&q, |id, v| {
                assert_eq!(v, [id; 3]);
                got.push(id)
            });
            got.sort();
            got.dedup();
            for id in brute(&items, &q) {
                assert!(got.binary_search(&id).is_ok(), "missed item {id}");
            }
            assert!(got.iter().all(|id| id % 3 != 0), "returned a removed item");
        }
    }
}
