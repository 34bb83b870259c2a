//! The check of a partitioned mesh where it lies (the pieces of §8, not
//! merged: memory stays distributed). The merged mesh's check without the
//! merge: every tet positive (exactly, and in floating point, as a solver
//! computes it), every face in at most two tets seen from opposite sides
//! (within a piece, then across pieces by an exact key sent to one part),
//! the faces in one tet exactly the input triangles, and the volumes
//! adding up to the enclosed volume.
use crate::Piece;
use parafront_comm::Comm;
use parafront_geom::{orient3d, tet_volume6};
use rayon::prelude::*;

/// A face by its global point ids, rotated so the smallest comes first and
/// the next two ascending, with whether that kept the orientation.
type Key = [u32; 3];

// Faces of a positive tet, outward.
use parafront_mesh::TET_FACES as OUTWARD;

fn canon(w: [u32; 3]) -> (Key, bool) {
    let r = (0..3).min_by_key(|&k| w[k]).unwrap_or(0);
    let (a, b, c) = (w[r], w[(r + 1) % 3], w[(r + 2) % 3]);
    if b < c {
        ([a, b, c], true)
    } else {
        ([a, c, b], false)
    }
}

/// What the check counted, over all pieces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PieceCheck {
    /// Tets.
    pub tets: usize,
    /// Faces in one tet (the input triangles on the outside).
    pub boundary_faces: usize,
    /// Faces whose two tets lie in different pieces.
    pub cut_faces: usize,
    /// The tets' volume.
    pub volume: f64,
}

/// What is wrong with the pieces (a defect of the mesher, never of the
/// input), as the process that found it says it.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("partitioned mesh: {message}")]
pub struct PieceCheckError {
    /// The first fault found, by part.
    pub message: String,
}

/// Faces a part's check sorts at once (16 bytes each): more go in bands
/// of their smallest global id (2^20 were 11 MB of an MPI rank's peak on
/// sphere_5e6 at 32 parts, 4 ranks, where a piece has 680k faces; 2^18, a
/// third more time for the check).
const BAND_FACES: usize = 1 << 19;

/// The most bands a part's faces are sorted in: each band reads every tet
/// again (ten bands of 2^18 faces were 2.5 s of sphere_5e6's run at
/// `--parts 8`, in the check and the boundary points).
pub(crate) const MAX_BANDS: usize = 4;

/// Ranges `[lo, hi)` of smallest ids, bucket `b` of `hist` holding the
/// faces whose smallest id is in `[b << shift, (b + 1) << shift)`, each
/// range with at most `band` faces unless one bucket has more; and the most
/// faces in one range.
fn bands(hist: &[usize], shift: u32, band: usize) -> (Vec<(u64, u64)>, usize) {
    let (mut ranges, mut most) = (Vec::new(), 0);
    let (mut lo, mut n) = (0u64, 0usize);
    for (b, &c) in hist.iter().enumerate() {
        let at = (b as u64) << shift;
        if n > 0 && n + c > band {
            ranges.push((lo, at));
            most = most.max(n);
            (lo, n) = (at, 0);
        }
        n += c;
    }
    ranges.push((lo, u64::MAX));
    (ranges, most.max(n))
}

/// The bands of smallest ids of `n_faces` faces whose ids are at most
/// `max_id`, as [`bands`] makes them, and the most faces in one; one band
/// of all when they fit in `band`, else `mins` gives each face's smallest
/// id (to count them by bucket). The bands are as many as `band` asks for
/// and about equal: filled up to `band` in turn, the first ones of a part
/// of 680k faces held 2^19 and the last the rest (8 MB of a band where
/// 5.4 do, at the check, on the highest MPI rank of sphere_5e6).
pub(crate) fn face_bands(
    n_faces: usize,
    max_id: u32,
    band: usize,
    mins: impl FnOnce(&mut dyn FnMut(u32)),
) -> (Vec<(u64, u64)>, usize) {
    if n_faces <= band {
        return (vec![(0, u64::MAX)], n_faces);
    }
    let shift = (32 - max_id.leading_zeros()).saturating_sub(12);
    let mut hist = vec![0usize; (max_id >> shift) as usize + 1];
    mins(&mut |m| hist[(m >> shift) as usize] += 1);
    // A bucket is about 1/4096 of the faces: a sixteenth more than an
    // equal share keeps the count of bands.
    let share = n_faces.div_ceil(n_faces.div_ceil(band.max(1)));
    bands(&hist, shift, (share + share / 16).min(band))
}

/// Checks the pieces this process holds, `pieces[i]` those of part
/// `owned().start + i` (one per region), against the input triangles
/// `tris` (the pieces' global ids) and six times the enclosed volume.
/// Every process gets the same answer.
pub fn check_pieces<C: Comm>(
    comm: &C,
    pieces: &[Vec<&Piece>],
    tris: &[[u32; 3]],
    enclosed_vol6: f64,
) -> Result<PieceCheck, PieceCheckError> {
    let band = |faces: usize| BAND_FACES.max(faces.div_ceil(MAX_BANDS));
    check_in_bands(comm, pieces, tris, enclosed_vol6, band)
}

/// [`check_pieces`] sorting at most `band(faces)` faces of a part with
/// `faces` faces at once.
fn check_in_bands<C: Comm>(
    comm: &C,
    pieces: &[Vec<&Piece>],
    tris: &[[u32; 3]],
    enclosed_vol6: f64,
    band: impl Fn(usize) -> usize + Sync,
) -> Result<PieceCheck, PieceCheckError> {
    let np = comm.parts() as u64;
    // Sorted, looked up by bisection: as a hash set, sphere_5e6's 118k
    // triangles were 3.4 MB of every process's check.
    let mut input: Vec<Key> = tris.iter().map(|&t| canon(t).0).collect();
    input.sort_unstable();
    input.dedup();
    let in_input = |k: &Key| input.binary_search(k).is_ok();
    let home = |k: &Key| -> u32 {
        let h = (k[0] as u64)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add((k[1] as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_add((k[2] as u64).wrapping_mul(0x1656_67B1_9E37_79F9));
        ((h >> 32) % np) as u32
    };
    struct Local {
        fault: Option<String>,
        tets: usize,
        vol6: f64,
        covered: usize,
        out: Vec<(u32, (Key, bool))>,
    }
    let local: Vec<Local> = pieces
        .par_iter()
        .enumerate()
        .map(|(i, list)| {
            let part = comm.owned().start + i;
            let mut l = Local {
                fault: None,
                tets: 0,
                vol6: 0.0,
                covered: 0,
                out: Vec::new(),
            };
            for pc in list {
                for (t, tv) in pc.tets.iter().enumerate() {
                    let p = tv.map(|i| pc.points[i as usize]);
                    let v6 = tet_volume6(p[0], p[1], p[2], p[3]);
                    if !(orient3d(p[0], p[1], p[2], p[3]) > 0.0 && v6 > 0.0) {
                        l.fault.get_or_insert(format!(
                            "part {part}: tet {} (global points {:?}) is not positive",
                            pc.tet_gid.get(t).copied().unwrap_or(t as u32),
                            tv.map(|i| pc.gid[i as usize])
                        ));
                    }
                    l.vol6 += v6;
                }
                l.tets += pc.tets.len();
            }
            // The faces by their smallest global id, one band of ids at a
            // time: all of a piece's faces at once were 64 bytes a tet,
            // the peak of an MPI rank on sphere_5e6. Bands ascend, so the
            // faces come out in the order one sort of them all gives.
            let faces_of = |f: &mut dyn FnMut((Key, bool))| {
                for pc in list {
                    for tv in &pc.tets {
                        for o in OUTWARD {
                            f(canon(o.map(|j| pc.gid[tv[j] as usize])));
                        }
                    }
                }
            };
            let n_faces = 4 * l.tets;
            let max_id = list.iter().flat_map(|pc| pc.gid.iter()).copied().max();
            let (ranges, most) =
                face_bands(n_faces, max_id.unwrap_or(0), band(n_faces), |f| {
                    faces_of(&mut |(k, _)| f(k[0]))
                });
            let mut faces: Vec<(Key, bool)> = Vec::with_capacity(most);
            for &(lo, hi) in &ranges {
                faces.clear();
                faces_of(&mut |(k, o)| {
                    if (lo..hi).contains(&(k[0] as u64)) {
                        faces.push((k, o));
                    }
                });
                faces.par_sort_unstable();
                let mut i = 0;
                while i < faces.len() {
                    let mut j = i + 1;
                    while j < faces.len() && faces[j].0 == faces[i].0 {
                        j += 1;
                    }
                    match &faces[i..j] {
                        [a] => l.out.push((home(&a.0), *a)),
                        [a, b] if a.1 != b.1 => l.covered += in_input(&a.0) as usize,
                        _ => {
                            l.fault.get_or_insert(format!(
                                "part {part}: face {:?} is in {} tets of one piece, or in two on one side",
                                faces[i].0,
                                j - i
                            ));
                        }
                    }
                    i = j;
                }
            }
            l
        })
        .collect();
    let mut outs = Vec::with_capacity(local.len());
    let mut sums = Vec::with_capacity(local.len());
    for l in local {
        sums.push((l.fault, l.tets, l.vol6, l.covered));
        outs.push(l.out);
    }
    // Faces on a piece's boundary, each at its home part.
    let inbox = comm.exchange(outs);
    let homes: Vec<(Option<String>, usize, usize, usize)> = inbox
        .into_par_iter()
        .enumerate()
        .map(|(i, msgs)| {
            let part = comm.owned().start + i;
            let mut f: Vec<(Key, bool)> = msgs.into_iter().map(|m| m.1).collect();
            f.par_sort_unstable();
            let (mut fault, mut covered, mut boundary, mut cut) = (None, 0, 0, 0);
            let mut i = 0;
            while i < f.len() {
                let mut j = i + 1;
                while j < f.len() && f[j].0 == f[i].0 {
                    j += 1;
                }
                let is_input = in_input(&f[i].0);
                match &f[i..j] {
                    [_] if is_input => {
                        covered += 1;
                        boundary += 1;
                    }
                    [a] => {
                        fault.get_or_insert(format!(
                            "face {:?} is in one tet but no input triangle (checked by part {part})",
                            a.0
                        ));
                    }
                    [a, b] if a.1 != b.1 => {
                        covered += is_input as usize;
                        cut += 1;
                    }
                    _ => {
                        fault.get_or_insert(format!(
                            "face {:?} is in {} tets of several pieces, or in two on one side",
                            f[i].0,
                            j - i
                        ));
                    }
                }
                i = j;
            }
            (fault, covered, boundary, cut)
        })
        .collect();
    // (fault, (tets, 6 x volume), (input triangles covered, boundary, cut)).
    type Sums = (Option<String>, (usize, f64), (usize, usize, usize));
    let all: Sums = comm.all_reduce(
        sums.into_iter()
            .zip(homes)
            .map(|((f1, tets, v, c1), (f2, c2, b, cut))| (f1.or(f2), (tets, v), (c1 + c2, b, cut)))
            .collect(),
        |a: Sums, b: Sums| {
            (
                a.0.or(b.0),
                (a.1 .0 + b.1 .0, a.1 .1 + b.1 .1),
                (a.2 .0 + b.2 .0, a.2 .1 + b.2 .1, a.2 .2 + b.2 .2),
            )
        },
    );
    let (fault, (tets, vol6), (covered, boundary_faces, cut_faces)) = all;
    if let Some(message) = fault {
        return Err(PieceCheckError { message });
    }
    if covered != input.len() {
        return Err(PieceCheckError {
            message: format!(
                "{} of {} input triangles are no face of the mesh",
                input.len() - covered.min(input.len()),
                input.len()
            ),
        });
    }
    if (vol6 - enclosed_vol6).abs() > 1e-9 * enclosed_vol6.abs().max(f64::MIN_POSITIVE) {
        return Err(PieceCheckError {
            message: format!(
                "the tets' volume {} is not the enclosed volume {}",
                vol6 / 6.0,
                enclosed_vol6 / 6.0
            ),
        });
    }
    Ok(PieceCheck {
        tets,
        boundary_faces,
        cut_faces,
        volume: vol6 / 6.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_comm::Threads;

    /// A box mesh in two pieces (by centroid), its boundary triangles, and
    /// six times its volume.
    fn two_pieces() -> (Vec<Piece>, Vec<[u32; 3]>, f64) {
        let m = parafront_mesh::generate::box_mesh(4, 3, 2, [0.0; 3], [2.0, 1.5, 1.0]);
        let tets: Vec<[u32; 4]> = m.tets.iter().map(|t| t.map(|p| p.raw())).collect();
        let mut faces: Vec<(Key, bool, [u32; 3])> = Vec::new();
        for t in &tets {
            for f in OUTWARD {
                let w = f.map(|j| t[j]);
                let (k, o) = canon(w);
                faces.push((k, o, w));
            }
        }
        faces.sort_unstable();
        let mut tris = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            if i + 1 < faces.len() && faces[i + 1].0 == faces[i].0 {
                i += 2;
            } else {
                tris.push(faces[i].2);
                i += 1;
            }
        }
        let mut pieces = vec![Piece::default(), Piece::default()];
        for pc in &mut pieces {
            pc.points = m.points.clone();
            pc.gid = (0..m.points.len() as u32).collect();
        }
        for (t, tv) in tets.iter().enumerate() {
            let cx: f64 = tv.iter().map(|&p| m.points[p as usize][0]).sum::<f64>() / 4.0;
            let pc = &mut pieces[(cx > 1.0) as usize];
            pc.tets.push(*tv);
            pc.tet_gid.push(t as u32);
            pc.tet_pass.push(1);
        }
        (pieces, tris, 6.0 * 2.0 * 1.5 * 1.0)
    }

    fn check(
        pieces: &[Piece],
        tris: &[[u32; 3]],
        vol6: f64,
    ) -> Result<PieceCheck, PieceCheckError> {
        let by_part: Vec<Vec<&Piece>> = pieces.iter().map(|p| vec![p]).collect();
        let comm = Threads::new(pieces.len());
        let all = check_pieces(&comm, &by_part, tris, vol6);
        // Sorted in bands of a few faces, the check says the same.
        for band in [1, 7, 40] {
            assert_eq!(check_in_bands(&comm, &by_part, tris, vol6, |_| band), all);
        }
        all
    }

    #[test]
    fn bands_cover_every_id_and_hold_at_most_a_band() {
        let hist = [3, 0, 5, 1, 9, 2, 2];
        let (r, most) = bands(&hist, 4, 6);
        // [0,32): 3+0; [32,64): 5+1; [64,80): 9 (one bucket over); rest 4.
        assert_eq!(r, vec![(0, 32), (32, 64), (64, 80), (80, u64::MAX)]);
        assert_eq!(most, 9);
        for w in r.windows(2) {
            assert_eq!(w[0].1, w[1].0);
        }
        assert_eq!(bands(&hist, 4, 100), (vec![(0, u64::MAX)], 22));
        assert_eq!(bands(&[0; 4], 0, 1), (vec![(0, u64::MAX)], 0));
    }

    #[test]
    fn face_bands_are_as_many_as_the_band_asks_and_about_equal() {
        // 1000 faces over ids 0..5000, a band of 600: two bands of about
        // 500, where filling the first to 600 left 400 to the second.
        let ids: Vec<u32> = (0..1000).map(|i| (i * 7919 % 1000) * 5).collect();
        let (r, most) = face_bands(1000, 4995, 600, |f| ids.iter().for_each(|&m| f(m)));
        assert_eq!(r.len(), 2);
        assert!((500..=531).contains(&most), "{most}");
        let count = |&(lo, hi): &(u64, u64)| {
            ids.iter()
                .filter(|&&m| (lo..hi).contains(&(m as u64)))
                .count()
        };
        assert_eq!(r.iter().map(count).sum::<usize>(), 1000);
        assert_eq!(r.iter().map(count).max(), Some(most));
        // Three bands of 2^18 or fewer where 600k faces fill two of 2^19.
        let ids: Vec<u32> = (0..600_000).collect();
        let (r, most) = face_bands(600_000, 599_999, 1 << 18, |f| {
            ids.iter().for_each(|&m| f(m))
        });
        assert_eq!(r.len(), 3);
        assert!((200_000..=1 << 18).contains(&most), "{most}");
        // All in one band when they fit.
        assert_eq!(
            face_bands(10, 9, 10, |_| unreachable!()),
            (vec![(0, u64::MAX)], 10)
        );
    }

    #[test]
    fn sound_pieces_pass_and_each_fault_is_found() {
        let (pieces, tris, vol6) = two_pieces();
        let n: usize = pieces.iter().map(|p| p.tets.len()).sum();
        let st = check(&pieces, &tris, vol6).expect("sound");
        assert_eq!(st.tets, n);
        assert_eq!(st.boundary_faces, tris.len());
        assert!(st.cut_faces > 0);
        assert!((st.volume - 3.0).abs() < 1e-12);

        // A tet turned inside out.
        let mut bad = pieces.clone();
        bad[1].tets[0].swap(0, 1);
        let e = check(&bad, &tris, vol6).unwrap_err();
        assert!(e.message.contains("not positive"), "{e}");
        // A tet missing: a hole whose faces are no input triangles.
        let mut bad = pieces.clone();
        bad[0].tets.pop();
        let e = check(&bad, &tris, vol6).unwrap_err();
        assert!(e.message.contains("no input triangle"), "{e}");
        // A tet in both pieces: its faces in too many tets.
        let mut bad = pieces.clone();
        let t = bad[0].tets[0];
        bad[1].tets.push(t);
        let e = check(&bad, &tris, vol6).unwrap_err();
        assert!(e.message.contains("several pieces"), "{e}");
        // An input triangle the mesh lacks.
        let mut more = tris.clone();
        more.push([0, 1, 7]);
        let e = check(&pieces, &more, vol6).unwrap_err();
        assert!(e.message.contains("input triangles are no face"), "{e}");
        // The wrong enclosed volume.
        let e = check(&pieces, &tris, 2.0 * vol6).unwrap_err();
        assert!(e.message.contains("volume"), "{e}");
    }
}
