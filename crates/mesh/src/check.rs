//! `check()`: every invariant of a [`TetMesh`], tested in parallel, with
//! orientation decided by the exact predicate. `check_against_surface()`
//! adds that the mesh boundary is exactly the input triangulation and that
//! the tets fill the volume it encloses exactly once.
//!
//! All problems are collected (the first [`SAMPLES`] of each kind are kept
//! with ids and coordinates, the rest counted), so one run shows the whole
//! picture of a broken mesh.
use crate::faces::*;
use crate::ids::*;
use crate::problem::*;
use crate::tetmesh::TetMesh;
use parafront_geom::{cross, dot, orient3d, sub, tet_volume6, Aabb, P3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

/// How many problems of each kind are kept with their details.
pub const SAMPLES: usize = 5;

/// Relative tolerance of the volume comparison.
pub const VOLUME_RTOL: f64 = 1e-9;

/// Items per work item of the parallel checks.
const CHECK_CHUNK: usize = 1 << 14;

/// `item(acc, i, x)` over every `x = items[i]`, chunk by chunk in
/// parallel, each chunk into its own `new()`, the chunks merged in order:
/// the result does not depend on the threads (float sums included), and
/// no accumulator moves per item (rayon's `fold` moved one per tet, a
/// tenth of the check).
fn over_chunks<T: Sync, A: Send>(
    items: &[T],
    new: impl Fn() -> A + Sync,
    item: impl Fn(&mut A, usize, &T) + Sync,
    merge: impl Fn(A, A) -> A,
) -> A {
    let accs: Vec<A> = items
        .par_chunks(CHECK_CHUNK)
        .enumerate()
        .map(|(c, ch)| {
            let mut acc = new();
            for (i, x) in ch.iter().enumerate() {
                item(&mut acc, c * CHECK_CHUNK + i, x);
            }
            acc
        })
        .collect();
    accs.into_iter().fold(new(), merge)
}

/// What a successful check measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CheckStats {
    /// Points of the mesh.
    pub n_points: usize,
    /// Points that no tet uses.
    pub n_unused_points: usize,
    /// Tets of the mesh.
    pub n_tets: usize,
    /// Distinct region ids (1 when `region` is empty and there are tets).
    pub n_regions: usize,
    /// Faces shared by two tets of the same region.
    pub n_interior_faces: usize,
    /// Faces shared by two tets of different regions.
    pub n_interface_faces: usize,
    /// Faces of one tet only.
    pub n_boundary_faces: usize,
    /// Sum of tet volumes, taken absolute so inverted tets cannot cancel
    /// against others: it equals the enclosed volume only when the tets
    /// cover the domain exactly once.
    pub volume: f64,
    /// Smallest tet volume (floating point; the sign test is exact).
    pub min_volume: f64,
    /// Volume enclosed by the input triangles (`check_against_surface` only).
    pub surface_volume: Option<f64>,
}

/// Problems found by one piece of parallel work; merging keeps the first
/// `SAMPLES` of each kind in order.
#[derive(Default)]
struct Found {
    counts: [usize; NK],
    kept: [usize; NK],
    samples: Vec<MeshProblem>,
}
impl Found {
    fn push(&mut self, p: MeshProblem) {
        let k = p.kind() as usize;
        self.counts[k] += 1;
        if self.kept[k] < SAMPLES {
            self.kept[k] += 1;
            self.samples.push(p);
        }
    }
    fn merge(mut self, o: Found) -> Found {
        for p in o.samples {
            let k = p.kind() as usize;
            if self.kept[k] < SAMPLES {
                self.kept[k] += 1;
                self.samples.push(p);
            }
        }
        for k in 0..NK {
            self.counts[k] += o.counts[k];
        }
        self
    }
    fn is_empty(&self) -> bool {
        self.counts.iter().all(|&c| c == 0)
    }
    fn into_error(mut self) -> CheckError {
        self.samples.sort_by_key(|p| p.kind());
        let kinds = [
            ProblemKind::ArrayLength,
            ProblemKind::NonFinitePoint,
            ProblemKind::PointOutOfRange,
            ProblemKind::RepeatedVertex,
            ProblemKind::NotPositive,
            ProblemKind::FaceInManyTets,
            ProblemKind::FaceSameSide,
            ProblemKind::NeighWrong,
            ProblemKind::BadInputTriangle,
            ProblemKind::MissingBoundaryFace,
            ProblemKind::ExtraBoundaryFace,
            ProblemKind::FlippedBoundaryFace,
            ProblemKind::DuplicateInputTriangle,
            ProblemKind::VolumeMismatch,
        ];
        CheckError {
            problems: self.samples,
            counts: kinds
                .into_iter()
                .filter(|&k| self.counts[k as usize] > 0)
                .map(|k| (k, self.counts[k as usize]))
                .collect(),
        }
    }
}

/// Per-chunk result of the tet pass.
struct TetAcc {
    found: Found,
    vol6: f64,
    min_vol6: f64,
}

/// Per-chunk result of the face pass.
#[derive(Default)]
struct FaceAcc {
    found: Found,
    interior: usize,
    interface: usize,
    boundary: usize,
}

fn fa_merge(a: FaceAcc, b: FaceAcc) -> FaceAcc {
    FaceAcc {
        found: a.found.merge(b.found),
        interior: a.interior + b.interior,
        interface: a.interface + b.interface,
        boundary: a.boundary + b.boundary,
    }
}

/// The input triangles' side of the check, summed over the slices of the
/// face table: problems, and the enclosed volume's flux (six times it)
/// with its absolute sum (for the rounding bound).
#[derive(Default)]
struct InputSide {
    found: Found,
    flux: f64,
    flux_abs: f64,
}

impl InputSide {
    fn merge(self, o: InputSide) -> InputSide {
        InputSide {
            found: self.found.merge(o.found),
            flux: self.flux + o.flux,
            flux_abs: self.flux_abs + o.flux_abs,
        }
    }
}

impl TetMesh {
    /// Checks every invariant: point ids in range, no repeated vertex in a
    /// tet, every tet positive under the exact predicate, every face in at
    /// most two tets and seen from opposite sides, finite coordinates, and
    /// (when built) `neigh` symmetric and matching the faces.
    pub fn check(&self) -> Result<CheckStats, CheckError> {
        self.check_impl(None)
    }

    /// [`check`](Self::check), plus: the mesh boundary faces, and the faces
    /// between tets of different regions, are exactly the triangles `tris`
    /// (point ids into `self.points`; boundary faces in the same
    /// orientation, interface faces in either), and the tet volumes add up
    /// to the volume the triangles enclose.
    pub fn check_against_surface(&self, tris: &[[u32; 3]]) -> Result<CheckStats, CheckError> {
        self.check_impl(Some(tris))
    }

    fn check_impl(&self, tris: Option<&[[u32; 3]]>) -> Result<CheckStats, CheckError> {
        let np = self.points.len();
        let nt = self.tets.len();
        let mut found = Found::default();
        let Some((neigh_ok, region_ok)) = self.check_arrays(&mut found) else {
            return Err(found.into_error());
        };
        let pf = self.check_points();
        let finite_ok = pf.is_empty();
        found = found.merge(pf);
        let (ta, n_unused_points) = self.check_tets(finite_ok);
        found = found.merge(ta.found);
        let (f, in_keys) = match tris {
            None => (Found::default(), Vec::new()),
            Some(tris) => input_keys(tris, np),
        };
        found = found.merge(f);
        // Slice by slice of the face table (by smallest vertex); the input
        // triangles of a slice are a run of their sorted keys.
        let mut fa = FaceAcc::default();
        let mut side = InputSide::default();
        // The flux's origin, the same for every slice.
        let c = Aabb::from_points(&self.points).center();
        for_each_key_slice(&self.tets, |keys, r| {
            fa = fa_merge(
                std::mem::take(&mut fa),
                self.check_faces(keys, tris.map(|t| (t, &in_keys[..])), neigh_ok, region_ok),
            );
            if let Some(tris) = tris {
                let lo = in_keys.partition_point(|&k| unpack_triple(k)[0] < r.start);
                let hi = in_keys.partition_point(|&k| unpack_triple(k)[0] < r.end);
                let part = self.check_input_side(tris, keys, &in_keys[lo..hi], region_ok, c);
                side = std::mem::take(&mut side).merge(part);
            }
        });
        found = found.merge(fa.found);
        let mut surface_volume = None;
        if tris.is_some() {
            let (f, vs) = self.volume_match(side, ta.vol6);
            found = found.merge(f);
            surface_volume = Some(vs);
        }
        if !found.is_empty() {
            return Err(found.into_error());
        }
        let n_regions = if nt == 0 {
            0
        } else if self.region.is_empty() {
            1
        } else {
            // The runs of one region, then their distinct ids: tets come
            // region by region, and a sort of every tet's id was a tenth
            // of the check.
            let mut r: Vec<u32> = self
                .region
                .par_chunks(1 << 16)
                .flat_map_iter(|c| {
                    let mut runs: Vec<u32> = Vec::new();
                    for &x in c {
                        if runs.last() != Some(&x) {
                            runs.push(x);
                        }
                    }
                    runs
                })
                .collect();
            crate::faces::sort_unstable(&mut r);
            r.dedup();
            r.len()
        };
        Ok(CheckStats {
            n_points: np,
            n_unused_points,
            n_tets: nt,
            n_regions,
            n_interior_faces: fa.interior,
            n_interface_faces: fa.interface,
            n_boundary_faces: fa.boundary,
            volume: ta.vol6 / 6.0,
            min_volume: if nt == 0 { 0.0 } else { ta.min_vol6 / 6.0 },
            surface_volume,
        })
    }

    /// The arrays' lengths: `None` when there are too many tets to check,
    /// else whether `neigh` and `region` can be used.
    fn check_arrays(&self, found: &mut Found) -> Option<(bool, bool)> {
        let nt = self.tets.len();
        if nt > crate::adjacency::MAX_TETS {
            found.push(MeshProblem::ArrayLength {
                name: "tets",
                len: nt,
                expected: format!("at most {}", crate::adjacency::MAX_TETS),
            });
            return None;
        }
        let neigh_ok = match self.neigh.len() {
            0 => false,
            l if l == 4 * nt => true,
            l => {
                found.push(MeshProblem::ArrayLength {
                    name: "neigh",
                    len: l,
                    expected: format!("0 or 4 * {nt} tets = {}", 4 * nt),
                });
                false
            }
        };
        let region_ok = self.region.is_empty() || self.region.len() == nt;
        if !region_ok {
            found.push(MeshProblem::ArrayLength {
                name: "region",
                len: self.region.len(),
                expected: format!("0 or {nt} (one per tet)"),
            });
        }
        Some((neigh_ok, region_ok))
    }

    /// Tet `t`'s region, or 0 when the region array is unusable.
    fn region_or_0(&self, t: TetId, region_ok: bool) -> u32 {
        if region_ok {
            self.region_of(t)
        } else {
            0
        }
    }

    /// Every point finite.
    fn check_points(&self) -> Found {
        over_chunks(
            &self.points,
            Found::default,
            |acc, i, p| {
                if !p.iter().all(|x| x.is_finite()) {
                    acc.push(MeshProblem::NonFinitePoint {
                        point: PointId::new(i),
                        coords: *p,
                    });
                }
            },
            Found::merge,
        )
    }

    /// Tets: ids, repeats, exact orientation, volume; and the points no
    /// tet uses.
    fn check_tets(&self, finite_ok: bool) -> (TetAcc, usize) {
        let np = self.points.len();
        let used: Vec<AtomicBool> = (0..np)
            .into_par_iter()
            .map(|_| AtomicBool::new(false))
            .collect();
        let ta = over_chunks(
            &self.tets,
            || TetAcc {
                found: Found::default(),
                vol6: 0.0,
                min_vol6: f64::INFINITY,
            },
            |acc, t, tet| {
                let tid = TetId::new(t);
                let mut in_range = true;
                for &p in tet {
                    if p.idx() < np {
                        used[p.idx()].store(true, Relaxed);
                    } else {
                        in_range = false;
                        acc.found.push(MeshProblem::PointOutOfRange {
                            tet: tid,
                            point: p,
                            n_points: np,
                        });
                    }
                }
                if has_repeat(tet) {
                    acc.found.push(MeshProblem::RepeatedVertex {
                        tet: tid,
                        verts: *tet,
                    });
                } else if in_range {
                    let c = self.tet_points(tid);
                    let v6 = tet_volume6(c[0], c[1], c[2], c[3]);
                    acc.vol6 += v6.abs();
                    acc.min_vol6 = acc.min_vol6.min(v6);
                    if finite_ok && orient3d(c[0], c[1], c[2], c[3]) <= 0.0 {
                        acc.found.push(MeshProblem::NotPositive {
                            tet: tid,
                            verts: *tet,
                            coords: c,
                            volume6: v6,
                            flat: orient3d(c[0], c[1], c[2], c[3]) == 0.0,
                        });
                    }
                }
            },
            |a, b| TetAcc {
                found: a.found.merge(b.found),
                vol6: a.vol6 + b.vol6,
                min_vol6: a.min_vol6.min(b.min_vol6),
            },
        );
        let n_unused_points = used.par_iter().filter(|u| !u.load(Relaxed)).count();
        (ta, n_unused_points)
    }

    /// Faces: pairing, neigh, and the mesh side of the surface match
    /// (against the input triangles and their sorted keys, when given).
    fn check_faces(
        &self,
        keys: &[u128],
        input: Option<(&[[u32; 3]], &[u128])>,
        neigh_ok: bool,
        region_ok: bool,
    ) -> FaceAcc {
        let tris = input.map(|i| i.0);
        let in_keys: &[u128] = input.map_or(&[], |i| i.1);
        let in_parity = |k: u128| sort3(tris.unwrap()[low(k) as usize]).1;
        let region = |t: TetId| self.region_or_0(t, region_ok);
        let tets = &self.tets;
        let pt = |p: PointId| self.points.get(p.idx()).copied().unwrap_or([f64::NAN; 3]);
        group_chunks(keys)
            .par_iter()
            .map(|chunk| {
                let mut acc = FaceAcc::default();
                for_each_group(chunk, |g| {
                    let face = unpack_triple(g[0]).map(PointId::from_raw);
                    let expect = |acc: &mut FaceAcc, f: u32, e: FaceRef| {
                        if neigh_ok && self.neigh[f as usize] != e {
                            acc.found.push(MeshProblem::NeighWrong {
                                face: FaceRef::from_raw(f),
                                verts: self.face_points(FaceRef::from_raw(f)),
                                found: self.neigh[f as usize],
                                expected: e,
                            });
                        }
                    };
                    let mut regions = None;
                    match g.len() {
                        1 => {
                            acc.boundary += 1;
                            expect(&mut acc, low(g[0]), NO_FACE);
                        }
                        2 => {
                            let (a, b) = (low(g[0]), low(g[1]));
                            if face_parity(tets, a) == face_parity(tets, b) {
                                acc.found.push(MeshProblem::FaceSameSide {
                                    face,
                                    tets: [FaceRef::from_raw(a).tet(), FaceRef::from_raw(b).tet()],
                                });
                                return;
                            }
                            expect(&mut acc, a, FaceRef::from_raw(b));
                            expect(&mut acc, b, FaceRef::from_raw(a));
                            let (ra, rb) = (
                                region(FaceRef::from_raw(a).tet()),
                                region(FaceRef::from_raw(b).tet()),
                            );
                            if ra == rb {
                                acc.interior += 1;
                                return;
                            }
                            acc.interface += 1;
                            regions = Some([ra, rb]);
                        }
                        _ => {
                            acc.found.push(MeshProblem::FaceInManyTets {
                                face,
                                tets: g.iter().map(|&k| FaceRef::from_raw(low(k)).tet()).collect(),
                            });
                            return;
                        }
                    }
                    if tris.is_none() {
                        return;
                    }
                    // A boundary or interface face: it must be an input triangle.
                    let fr = FaceRef::from_raw(low(g[0]));
                    let r = find_triple(in_keys, unpack_triple(g[0]));
                    let tv = unpack_triple(g[0]);
                    if r.is_empty() {
                        let verts = self.face_points(fr);
                        acc.found.push(MeshProblem::ExtraBoundaryFace {
                            face: fr,
                            verts,
                            coords: verts.map(pt),
                            regions,
                        });
                    } else if regions.is_none() {
                        let p = face_parity(tets, fr.raw());
                        if r.len() > 1 {
                            acc.found.push(MeshProblem::DuplicateInputTriangle {
                                tris: r.iter().map(|&k| low(k) as usize).collect(),
                                verts: tv,
                            });
                        } else if in_parity(r[0]) != p {
                            acc.found.push(MeshProblem::FlippedBoundaryFace {
                                tri: low(r[0]) as usize,
                                verts: tris.unwrap()[low(r[0]) as usize],
                                face: fr,
                                mesh_verts: self.face_points(fr),
                            });
                        }
                    } else if r.len() > 2 || (r.len() == 2 && in_parity(r[0]) == in_parity(r[1])) {
                        acc.found.push(MeshProblem::DuplicateInputTriangle {
                            tris: r.iter().map(|&k| low(k) as usize).collect(),
                            verts: tv,
                        });
                    }
                });
                acc
            })
            .reduce(FaceAcc::default, fa_merge)
    }

    /// The input side of one slice of the face table (`keys`, and the
    /// input triangles' keys with smallest vertices in its range):
    /// triangles that are no boundary face, and their share of the
    /// enclosed volume (interface triangles enclose nothing), as the flux
    /// about `c`.
    fn check_input_side(
        &self,
        tris: &[[u32; 3]],
        keys: &[u128],
        in_keys: &[u128],
        region_ok: bool,
        c: P3,
    ) -> InputSide {
        let tets = &self.tets;
        let region = |t: TetId| self.region_or_0(t, region_ok);
        let (found, flux, flux_abs) = group_chunks(in_keys)
            .par_iter()
            .map(|chunk| {
                let mut f = Found::default();
                let (mut flux, mut flux_abs) = (0.0, 0.0);
                for_each_group(chunk, |g| {
                    let m = find_triple(keys, unpack_triple(g[0]));
                    let interface = m.len() == 2
                        && region(FaceRef::from_raw(low(m[0])).tet())
                            != region(FaceRef::from_raw(low(m[1])).tet());
                    let why = match m.len() {
                        0 => Some("no tet has this face".to_string()),
                        2 if !interface
                            && face_parity(tets, low(m[0])) != face_parity(tets, low(m[1])) =>
                        {
                            let (a, b) = (
                                FaceRef::from_raw(low(m[0])).tet(),
                                FaceRef::from_raw(low(m[1])).tet(),
                            );
                            Some(format!(
                                "it lies inside region {}, between tets {a} and {b}",
                                region(a)
                            ))
                        }
                        _ => None,
                    };
                    for &k in g {
                        let t = tris[low(k) as usize];
                        if let Some(why) = &why {
                            f.push(MeshProblem::MissingBoundaryFace {
                                tri: low(k) as usize,
                                verts: t,
                                coords: t.map(|p| self.points[p as usize]),
                                why: why.clone(),
                            });
                        }
                        if !interface {
                            let [a, b, d] = t.map(|p| sub(self.points[p as usize], c));
                            let v = dot(a, cross(b, d));
                            flux += v;
                            flux_abs += v.abs();
                        }
                    }
                });
                (f, flux, flux_abs)
            })
            .reduce(
                || (Found::default(), 0.0, 0.0),
                |a, b| (a.0.merge(b.0), a.1 + b.1, a.2 + b.2),
            );
        InputSide {
            found,
            flux,
            flux_abs,
        }
    }

    /// The enclosed volume (the input triangles' flux, `side`) against the
    /// tets' (`vol6`, six times theirs): the problems, and the surface's
    /// volume.
    fn volume_match(&self, side: InputSide, vol6: f64) -> (Found, f64) {
        let InputSide {
            mut found,
            flux,
            flux_abs,
        } = side;
        let (vm, vs) = (vol6 / 6.0, flux / 6.0);
        // Rounding bound of both sums, or the relative tolerance.
        let tol = (VOLUME_RTOL * vm.abs().max(vs.abs()))
            .max(64.0 * f64::EPSILON * (vol6 + flux_abs) / 6.0);
        let diff = (vm - vs).abs();
        if diff > tol || diff.is_nan() {
            found.push(MeshProblem::VolumeMismatch {
                mesh: vm,
                surface: vs,
                rel: (vm - vs).abs() / vm.abs().max(vs.abs()),
            });
        }
        (found, vs)
    }
}

/// The input triangles, validated, as sorted keys (low = index).
fn input_keys(tris: &[[u32; 3]], np: usize) -> (Found, Vec<u128>) {
    let (f, mut keys) = over_chunks(
        tris,
        || (Found::default(), Vec::new()),
        |(f, keys), i, t| {
            if let Some(&p) = t.iter().find(|&&p| p as usize >= np) {
                f.push(MeshProblem::BadInputTriangle {
                    tri: i,
                    verts: *t,
                    why: if p == u32::MAX {
                        "uses point id u32::MAX"
                    } else {
                        "uses a point id past the end of the points"
                    },
                });
            } else if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                f.push(MeshProblem::BadInputTriangle {
                    tri: i,
                    verts: *t,
                    why: "repeats a vertex",
                });
            } else {
                keys.push(pack(sort3(*t).0, i as u32));
            }
        },
        |(fa, mut ka), (fb, kb)| {
            ka.extend(kb);
            (fa.merge(fb), ka)
        },
    );
    crate::faces::sort_unstable(&mut keys);
    (f, keys)
}
