//! One part of the passes (§7): the records its messages carry, its
//! local points, tets and front, and what one front call gave back.
pub(crate) use crate::packed::PackedTets;
use parafront_comm::{Wire, WireError};
use parafront_geom::P3;
use rustc_hash::FxHashMap;

/// A point as it travels in a message: its global id, where it is, its size.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rec {
    pub(crate) gid: u32,
    pub(crate) p: P3,
    pub(crate) h: f64,
}

impl Wire for Rec {
    fn put(&self, buf: &mut Vec<u8>) {
        (self.gid, self.p, self.h).put(buf);
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let (gid, p, h) = Wire::get(buf)?;
        Ok(Rec { gid, p, h })
    }
}

/// The front faces one part sends another (§7): their points once each,
/// then the faces the receiver advances (owned) and those it only has to
/// know are there (context), as indices into `points`, each list in the
/// sender's face order. A face as three located points was 109 bytes on
/// the wire and 136 in memory, and pass 2's messages were a process's
/// peak under MPI (sphere_5e6, `--size 0.021`, 4 ranks).
#[derive(Default)]
pub(crate) struct FaceBatch {
    pub(crate) points: Vec<Rec>,
    pub(crate) owned: Vec<[u32; 3]>,
    pub(crate) context: Vec<[u32; 3]>,
}

impl FaceBatch {
    /// The faces of `list` (`owned` or `context`) as located points.
    pub(crate) fn faces<'a>(&'a self, list: &'a [[u32; 3]]) -> impl Iterator<Item = [Rec; 3]> + 'a {
        list.iter().map(|f| f.map(|i| self.points[i as usize]))
    }
}

impl Wire for FaceBatch {
    fn put(&self, buf: &mut Vec<u8>) {
        self.points.put(buf);
        self.owned.put(buf);
        self.context.put(buf);
    }
    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let (points, owned, context) = Wire::get(buf)?;
        Ok(FaceBatch {
            points,
            owned,
            context,
        })
    }
}

/// A part's global point ids to its local ones. The points a part's own
/// front calls made get their global ids in runs, one per call, in the
/// order of their local ids: those are kept as runs, only the points it
/// received one by one in a map (a map of every point was 4 MB of each
/// MPI rank's 8 parts on sphere_5e6 at 32 parts).
#[derive(Default)]
pub(crate) struct Index {
    map: FxHashMap<u32, u32>,
    /// `(first global id, first local id, length)`, ascending.
    runs: Vec<(u32, u32, u32)>,
}

impl Index {
    pub(crate) fn get(&self, gid: u32) -> Option<u32> {
        let r = self.runs.partition_point(|r| r.0 <= gid);
        if let Some(&(g, l, n)) = r.checked_sub(1).map(|r| &self.runs[r]) {
            if gid - g < n {
                return Some(l + (gid - g));
            }
        }
        self.map.get(&gid).copied()
    }

    /// Global id `gid` is local point `l`; it is in no run.
    pub(crate) fn insert(&mut self, gid: u32, l: u32) {
        self.map.insert(gid, l);
    }

    /// Global ids `gid..gid + n` are local points `l..l + n`, above every
    /// global id in a run so far and in none in the map.
    pub(crate) fn insert_run(&mut self, gid: u32, l: u32, n: u32) {
        debug_assert!(self.runs.last().is_none_or(|r| r.0 + r.2 <= gid));
        if n > 0 {
            self.runs.push((gid, l, n));
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.map.len() + self.runs.iter().map(|r| r.2 as usize).sum::<usize>()
    }
}

/// The pass that made each of a part's tets, as runs: a front call's tets
/// come in one block (a byte a tet was 1.3 MB of each MPI rank on
/// sphere_5e6 at 32 parts).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct TetPasses {
    /// `(pass, tets)`, in tet order.
    runs: Vec<(u8, u32)>,
}

impl TetPasses {
    pub(crate) fn len(&self) -> usize {
        self.runs.iter().map(|r| r.1 as usize).sum()
    }

    /// `n` more tets of `pass`.
    pub(crate) fn push_n(&mut self, pass: u8, n: usize) {
        match self.runs.last_mut() {
            Some(r) if r.0 == pass => r.1 += n as u32,
            _ if n == 0 => {}
            _ => self.runs.push((pass, n as u32)),
        }
    }

    /// Each tet's pass, in order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = u8> + '_ {
        self.runs
            .iter()
            .flat_map(|&(p, n)| std::iter::repeat_n(p, n as usize))
    }

    pub(crate) fn to_vec(&self) -> Vec<u8> {
        self.iter().collect()
    }
}

/// One part's local data.
#[derive(Default)]
pub(crate) struct Part {
    pub(crate) pts: Vec<P3>,
    pub(crate) size: Vec<f64>,
    pub(crate) gid: Vec<u32>,
    pub(crate) index: Index,
    /// Local ids.
    pub(crate) tets: PackedTets,
    pub(crate) tet_pass: TetPasses,
    /// The faces this part holds, local ids.
    pub(crate) front: Vec<[u32; 3]>,
    /// Global ids of the points of the faces that got stuck in its last
    /// front call (region rules allowed them, the front could not).
    pub(crate) stuck: Vec<u32>,
}

/// The parts `owned` holds, with the input front in `holders` blocks of
/// consecutive faces on parts `0..holders`. The DDG's passes seed part 0
/// only (the reader); the fine passes seed every part, so that no process
/// routes the whole front in pass 1 (on sphere_5e6 at 4 ranks, part 0's
/// faces and their copies for the parts their boxes meet were 45 MB on
/// rank 0 alone). Pass 1 sends them out.
pub(crate) fn seed_parts(
    owned: std::ops::Range<usize>,
    holders: usize,
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
) -> Vec<Part> {
    let mut parts: Vec<Part> = owned.clone().map(|_| Part::default()).collect();
    let holders = holders.max(1);
    for k in owned.clone().filter(|&k| k < holders) {
        let part = &mut parts[k - owned.start];
        let block = k * faces.len() / holders..(k + 1) * faces.len() / holders;
        for f in &faces[block] {
            let v = f.map(|i| part.local_input(i, (points, point_size)));
            part.front.push(v);
        }
    }
    parts
}

/// §2's lattice tets into the parts held: `core_tets[i]` (ids into
/// `points`) into `parts[i]`, with pass 0 (none where the list is
/// missing). Redistribution (§8) then sends each to the lowest part its
/// points' DDG hosts give, as it does a front's.
pub(crate) fn add_core_tets(
    parts: &mut [Part],
    (points, point_size): (&[P3], &[f64]),
    core_tets: &[Vec<[u32; 4]>],
) {
    for (part, block) in parts.iter_mut().zip(core_tets) {
        let local: Vec<[u32; 4]> = block
            .iter()
            .map(|t| t.map(|i| part.local_input(i, (points, point_size))))
            .collect();
        part.tets.extend(local);
        part.tet_pass.push_n(0, block.len());
    }
}

impl Part {
    pub(crate) fn local(&mut self, r: Rec) -> u32 {
        if let Some(i) = self.index.get(r.gid) {
            return i;
        }
        let i = self.pts.len() as u32;
        self.pts.push(r.p);
        self.size.push(r.h);
        self.gid.push(r.gid);
        self.index.insert(r.gid, i);
        i
    }
    /// [`Part::local`] of input point `i` (its global id).
    fn local_input(&mut self, i: u32, (points, point_size): (&[P3], &[f64])) -> u32 {
        self.local(Rec {
            gid: i,
            p: points[i as usize],
            h: point_size[i as usize],
        })
    }
    pub(crate) fn rec(&self, i: u32) -> Rec {
        Rec {
            gid: self.gid[i as usize],
            p: self.pts[i as usize],
            h: self.size[i as usize],
        }
    }

    /// The part's invariants, for the tests and debug builds (after every
    /// pass): one point record per local id, the index maps each global
    /// id to its local one and nothing else, every tet and face names local
    /// points (distinct ones), and each tet has the pass that made it.
    pub(crate) fn check(&self) -> Result<(), PartCheckError> {
        let n = self.pts.len();
        if self.size.len() != n || self.gid.len() != n || self.index.len() != n {
            return Err(PartCheckError::Lengths);
        }
        if let Some(i) = (0..n).find(|&i| self.index.get(self.gid[i]) != Some(i as u32)) {
            return Err(PartCheckError::Index(self.gid[i]));
        }
        if self.tet_pass.len() != self.tets.len() {
            return Err(PartCheckError::Lengths);
        }
        let bad = |v: &[u32]| {
            v.iter().any(|&i| i as usize >= n)
                || (0..v.len()).any(|a| (a + 1..v.len()).any(|b| v[a] == v[b]))
        };
        if let Some(t) = self.tets.iter().position(|t| bad(&t)) {
            return Err(PartCheckError::Tet(t));
        }
        if let Some(f) = self.front.iter().position(|f| bad(f)) {
            return Err(PartCheckError::Face(f));
        }
        Ok(())
    }
}

/// What [`Part::check`] found wrong.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub(crate) enum PartCheckError {
    #[error("the part's per-point or per-tet arrays differ in length")]
    Lengths,
    #[error("the part's index does not map global point {0} to its local id")]
    Index(u32),
    #[error("the part's tet {0} names a missing point or repeats one")]
    Tet(usize),
    #[error("the part's front face {0} names a missing point or repeats one")]
    Face(usize),
}

/// [`Part::check`] on every part, in debug builds.
pub(crate) fn debug_check_parts(parts: &[Part], after: impl std::fmt::Display) {
    if cfg!(debug_assertions) {
        for (k, p) in parts.iter().enumerate() {
            if let Err(e) = p.check() {
                panic!("part {k} after {after}: {e}");
            }
        }
    }
}

/// What one part's front call gave back, before new points get global ids.
pub(crate) struct Made {
    pub(crate) res: Option<parafront_front::FrontResult>,
    /// Global ids of the input points.
    pub(crate) input_gid: Vec<u32>,
    /// Input points inside this part (conservative assignment).
    pub(crate) input_ok: Vec<bool>,
    /// Per face of `res.front`: stuck rather than held by the region.
    pub(crate) stuck: Vec<bool>,
    pub(crate) seconds: f64,
}

impl Made {
    /// The points the front call made (global ids to be given).
    pub(crate) fn new_points(&self) -> u32 {
        self.res
            .as_ref()
            .map_or(0, |r| (r.points.len() - self.input_gid.len()) as u32)
    }
}

#[cfg(test)]
mod part_check_tests {
    use super::*;

    #[test]
    fn a_sound_part_passes_and_each_fault_is_named() {
        let mut p = Part::default();
        let ids: Vec<u32> = (0..4)
            .map(|g| {
                p.local(Rec {
                    gid: 10 + g,
                    p: [g as f64, 0.0, 0.0],
                    h: 1.0,
                })
            })
            .collect();
        let tet = |last: u32| PackedTets::from_iter([[ids[0], ids[1], ids[2], last]]);
        p.tets = tet(ids[3]);
        p.tet_pass.push_n(1, 1);
        p.front.push([ids[0], ids[2], ids[1]]);
        assert_eq!(p.check(), Ok(()));
        p.tets = tet(ids[0]);
        assert_eq!(p.check(), Err(PartCheckError::Tet(0)));
        p.tets = tet(9);
        assert_eq!(p.check(), Err(PartCheckError::Tet(0)));
        p.tets = tet(ids[3]);
        p.front[0][1] = 7;
        assert_eq!(p.check(), Err(PartCheckError::Face(0)));
        p.front[0][1] = ids[2];
        p.index.insert(10, 3);
        assert_eq!(p.check(), Err(PartCheckError::Index(10)));
        p.index.insert(10, 0);
        p.tet_pass = TetPasses::default();
        assert_eq!(p.check(), Err(PartCheckError::Lengths));
    }
}

#[cfg(test)]
mod index_tests {
    use super::*;

    /// Runs and single points answer as one map of every point would,
    /// and ids in no run nor the map are missing.
    #[test]
    fn runs_and_single_points_answer_as_one_map() {
        let mut ix = Index::default();
        let mut all: FxHashMap<u32, u32> = FxHashMap::default();
        let mut l = 0u32;
        // Received points and runs of new ones, interleaved, as passes go.
        for (pass, singles) in [(0u32, [900u32, 3, 77]), (1, [5, 1200, 64])] {
            for g in singles {
                ix.insert(g, l);
                all.insert(g, l);
                l += 1;
            }
            let (g0, n) = (1000 + 500 * pass, 40 + pass);
            ix.insert_run(g0, l, n);
            for k in 0..n {
                all.insert(g0 + k, l + k);
            }
            l += n;
        }
        ix.insert_run(5000, l, 0);
        assert_eq!(ix.len(), all.len());
        for g in 0..2000 {
            assert_eq!(ix.get(g), all.get(&g).copied(), "global id {g}");
        }
        assert_eq!(ix.get(u32::MAX), None);
    }
}

#[cfg(test)]
mod pass_tests {
    use super::*;

    /// Runs of passes give back each tet's pass, and a block of the same
    /// pass joins the run before it.
    #[test]
    fn runs_of_passes_give_each_tets_pass() {
        let mut tp = TetPasses::default();
        let mut want = Vec::new();
        for (pass, n) in [
            (1u8, 5usize),
            (1, 3),
            (0, 0),
            (2, 1),
            (3, 4),
            (2, 2),
            (2, 0),
        ] {
            tp.push_n(pass, n);
            want.extend(std::iter::repeat_n(pass, n));
        }
        assert_eq!(tp.to_vec(), want);
        assert_eq!(tp.len(), want.len());
        assert_eq!(tp.runs, vec![(1, 8), (2, 1), (3, 4), (2, 2)]);
    }
}

#[cfg(test)]
mod batch_tests {
    use super::*;

    /// A batch crosses the wire as it is, and gives its faces back as the
    /// located points they were made of.
    #[test]
    fn a_batch_round_trips_and_names_its_points() {
        let rec = |g: u32| Rec {
            gid: 100 + g,
            p: [g as f64, 0.5 * g as f64, -1.0],
            h: 0.25 + g as f64,
        };
        let b = FaceBatch {
            points: (0..5).map(rec).collect(),
            owned: vec![[0, 1, 2], [2, 1, 3]],
            context: vec![[3, 4, 0]],
        };
        let mut buf = Vec::new();
        b.put(&mut buf);
        let mut at = &buf[..];
        let c = FaceBatch::get(&mut at).unwrap();
        assert!(at.is_empty());
        let gids = |x: &FaceBatch, l: &[[u32; 3]]| -> Vec<[u32; 3]> {
            x.faces(l).map(|v| v.map(|r| r.gid)).collect()
        };
        assert_eq!(gids(&c, &c.owned), vec![[100, 101, 102], [102, 101, 103]]);
        assert_eq!(gids(&c, &c.context), vec![[103, 104, 100]]);
        let pts: Vec<(P3, f64)> = c
            .faces(&c.context)
            .next()
            .unwrap()
            .map(|r| (r.p, r.h))
            .to_vec();
        assert_eq!(pts, [3, 4, 0].map(|g| (rec(g).p, rec(g).h)).to_vec());
        // A cut message is an error, not a panic.
        let mut short = &buf[..buf.len() - 1];
        assert!(FaceBatch::get(&mut short).is_err());
    }
}

#[cfg(test)]
mod seed_tests {
    use super::*;
    use parafront_geom::P3;

    /// The input front as global ids, part by part, from the parts of
    /// every holder in `ranks` (ranges of part ids).
    fn seeded(ranks: &[std::ops::Range<usize>], holders: usize, n: u32) -> Vec<Vec<[u32; 3]>> {
        let points: Vec<P3> = (0..n + 2).map(|i| [i as f64, 0.0, 0.0]).collect();
        let size = vec![1.0; points.len()];
        let faces: Vec<[u32; 3]> = (0..n).map(|i| [i, i + 1, i + 2]).collect();
        let mut out = Vec::new();
        for r in ranks {
            for p in seed_parts(r.clone(), holders, &points, &size, &faces) {
                assert_eq!(p.check(), Ok(()));
                out.push(
                    p.front
                        .iter()
                        .map(|f| f.map(|i| p.gid[i as usize]))
                        .collect(),
                );
            }
        }
        out
    }

    #[test]
    fn spread_seeding_gives_each_part_a_block_in_face_order() {
        let all: Vec<[u32; 3]> = (0..101).map(|i| [i, i + 1, i + 2]).collect();
        // One process or three: the same blocks, every face once, in order.
        let one = seeded(std::slice::from_ref(&(0..8)), 8, 101);
        let three = seeded(&[0..3, 3..6, 6..8], 8, 101);
        assert_eq!(one, three);
        assert_eq!(one.concat(), all);
        assert!(one.iter().all(|b| (12..=13).contains(&b.len())), "{one:?}");
        // One holder: all on part 0.
        let held = seeded(&[0..3, 3..8], 1, 101);
        assert_eq!(held[0], all);
        assert!(held[1..].iter().all(Vec::is_empty));
    }
}
