//! Hard surfaces built in code (issue 20): needles, thin slots, tiny
//! features beside large faces, twisted prisms. Each must mesh with default
//! options and with a size far above its smallest edge, keep its surface
//! and fill it exactly.
use parafront_pipeline::{mesh_surface, MeshOptions};
use parafront_surface::hard::{boss_box, frustum, rod, slotted_box, twisted_tower};
use parafront_surface::read::{read_surface_bytes, Format};
use parafront_surface::Surface;
use proptest::prelude::*;

fn smallest_edge(s: &Surface) -> f64 {
    let d = |a: u32, b: u32| {
        let (p, q) = (s.points[a as usize], s.points[b as usize]);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    s.tris
        .iter()
        .flat_map(|t| [d(t[0], t[1]), d(t[1], t[2]), d(t[2], t[0])])
        .fold(f64::INFINITY, f64::min)
}

/// Default options, then `--size` 10 and 100 times the smallest edge.
fn meshes(name: &str, s: &Surface) {
    let e = smallest_edge(s);
    meshes_at(name, s, &[None, Some(10.0 * e), Some(100.0 * e)]);
}

fn meshes_at(name: &str, s: &Surface, sizes: &[Option<f64>]) {
    for &h in sizes {
        let mut o = MeshOptions::default();
        o.size.h = h;
        let (m, sum) =
            mesh_surface(s, &o).unwrap_or_else(|err| panic!("{name}, size {h:?}: {err}"));
        m.check_against_surface(&s.tris)
            .unwrap_or_else(|err| panic!("{name}, size {h:?}: invalid mesh: {err}"));
        let v = s.signed_volume();
        assert!(
            (m.volume() - v).abs() <= 1e-9 * v,
            "{name}: volume {} of {v}",
            m.volume()
        );
        println!(
            "{name} size {h:?}: {} tets, {} cavities filled ({} tets)",
            m.tets.len(),
            sum.cavities_filled,
            sum.fill_tets
        );
    }
}

#[test]
fn needle_frustums() {
    for aspect in [1000.0, 2500.0, 5000.0] {
        // Tip 1/aspect of the length, base twice as wide.
        let r = 0.5 / aspect;
        meshes(
            &format!("frustum 1:{aspect}"),
            &frustum(6, 1.0, 2.0 * r, r, 0.0),
        );
    }
}

#[test]
fn thin_rod_is_closed_by_the_fill() {
    // The thin rod of issue 20 (r 0.02, length 20, side triangles 5 long:
    // aspect 3000): recovery alone never closed it; the fill does.
    let s = rod(8, 0.02, 20.0, 4);
    let (m, sum) = mesh_surface(&s, &MeshOptions::default()).expect("the rod meshes");
    m.check_against_surface(&s.tris).expect("valid");
    assert!(sum.cavities_filled > 0 && sum.fill_tets > 0, "the fill ran");
    meshes("rod", &s);
}

#[test]
fn needle_rod_is_filled_whole_at_once() {
    // round.stl's shape: side triangles 8.7 long and 0.23 wide under a
    // size of their mean edge. The front stalls before it has a tet for
    // every other face; the fill takes the whole region, with no
    // recovery round.
    let s = rod(70, 2.54, 60.96, 7);
    let (m, sum) = mesh_surface(&s, &MeshOptions::default()).expect("the rod meshes");
    m.check_against_surface(&s.tris).expect("valid");
    let v = s.signed_volume();
    assert!((m.volume() - v).abs() <= 1e-9 * v);
    assert_eq!(sum.recovery_rounds, 0, "no recovery round");
    assert_eq!(sum.cavities_filled, 1, "one fill");
    assert!(sum.fill_tets > 0);
}

#[test]
fn twisted_prisms() {
    // Schönhardt: a triangular prism twisted so that no tetrahedralization
    // of its six corners exists; and a twisted square prism.
    meshes("schonhardt", &frustum(3, 1.0, 1.0, 1.0, 0.5));
    meshes("twisted square prism", &frustum(4, 1.0, 1.0, 1.0, 0.6));
}

#[test]
fn thin_slots() {
    for gap in [1e-2, 1e-3] {
        meshes_at(&format!("slot {gap}"), &slotted_box(gap), &[None]);
    }
}

/// Under a size 10 times the slot's width the front stalls beside the slot
/// in thin, folded, nearly flat cavities (6V ~ 1e-4 of the slot's scale)
/// that neither the flips nor the search close; after a failed fill the
/// pipeline fills the whole region from its surface and refines it to the
/// size (GDT). The 0.1 % slot at size 0.01 is a run of minutes (a
/// million-tet front before it stalls, then millions of refined tets):
/// ignored for CI; `slot_under_ten_times_its_width` is the quick case.
#[test]
#[ignore = "minutes: a million-tet front, then the region fill refined to millions of tets (run with --ignored)"]
fn thin_slots_under_a_large_size() {
    for gap in [1e-2, 1e-3] {
        meshes(&format!("slot {gap}"), &slotted_box(gap));
    }
}

#[test]
fn slot_under_ten_times_its_width() {
    // The front stalls beside the slot on most of its faces at once; the
    // fill at that first stall and the cavity fills after recovery close
    // it (before them, the front could not, and the region was filled
    // whole and refined to the size). Either way the mesh is valid and at
    // the size.
    let s = slotted_box(1e-2);
    let mut o = MeshOptions::default();
    o.size.h = Some(0.1);
    let (m, sum) = mesh_surface(&s, &o).expect("the slot meshes");
    m.check_against_surface(&s.tris).expect("valid");
    println!(
        "slot 0.01 at size 0.1: {} tets, regions filled whole {:?}, {} cavities filled",
        m.tets.len(),
        sum.regions_filled,
        sum.cavities_filled
    );
    let v = s.signed_volume();
    assert!((m.volume() - v).abs() <= 1e-9 * v);
    // A regular tet of edge 0.1 is 1.2e-4, so about 8,000 of them; the
    // surface alone closes with 23.
    assert!(m.tets.len() > 3000, "{} tets", m.tets.len());
    let (mut sum_l, mut n) = (0.0, 0);
    for t in &m.tets {
        for (a, b) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let (p, q) = (m.points[t[a].idx()], m.points[t[b].idx()]);
            sum_l += ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            n += 1;
        }
    }
    let mean = sum_l / n as f64;
    assert!(mean < 0.15, "mean edge {mean}");
}

#[test]
fn a_small_surface_whose_cavity_fill_fails_goes_to_the_region_fill() {
    // The twisted square prism (12 faces) at size 0.1: the front stalls on
    // about 600 faces and the fill leaves a cavity open. The region's
    // surface is filled and refined at once; before, the front recovered
    // until it gave up and the pipeline made that fill (regions_filled).
    let s = frustum(4, 1.0, 1.0, 1.0, 0.6);
    let mut o = MeshOptions::default();
    o.size.h = Some(0.1);
    let (m, sum) = mesh_surface(&s, &o).expect("the prism at size 0.1 meshes");
    m.check_against_surface(&s.tris).expect("valid");
    assert!((m.volume() - s.signed_volume()).abs() <= 1e-9 * s.signed_volume());
    assert!(sum.fills_failed > 0, "the cavities' fill came first");
    assert_eq!(sum.regions_refined, vec![1]);
    assert!(sum.regions_filled.is_empty(), "{:?}", sum.regions_filled);
    assert_eq!(sum.recovery_rounds, 0);
}

#[test]
fn tiny_feature_beside_large_faces() {
    // A boss 1e-4 of the part on a face of 1, at the default size.
    meshes_at("boss 1e-4", &boss_box(1e-4), &[None]);
}

/// The same boss under a given size: the surface growth once dropped the
/// box's seeds (sizes above the cap) and built its tree on the boss alone,
/// so every point outside it got the boss's 1e-4, and the front ran away.
#[test]
fn tiny_feature_under_a_given_size() {
    meshes_at("boss 1e-4", &boss_box(1e-4), &[Some(0.5), Some(0.1)]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]
    /// Rods of needle faces, thin or stout: whether the front stalls at
    /// once (and the fill takes the region) or not, each meshes with
    /// default options, and the mesh keeps the surface and its volume.
    #[test]
    fn needle_rods(
        k in 24usize..90,
        r in 0.3f64..4.0,
        len in 20.0f64..80.0,
        segs in 3usize..10,
    ) {
        meshes_at("needle rod", &rod(k, r, len, segs), &[None]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    /// Towers of twisted layers (no layer has a tetrahedralization of its
    /// own corners), squat or tall: each meshes with default options.
    #[test]
    fn twisted_towers(
        twists in prop::collection::vec(0.2f64..0.9, 1..5),
        height in prop::sample::select(vec![0.01, 0.3, 5.0]),
    ) {
        meshes_at("tower", &twisted_tower(&twists, height), &[None]);
    }
}

/// The angle block of trimesh's models, healed (see the file's header).
fn angle_block() -> Surface {
    let text = include_str!("data/angle_block_healed.obj");
    read_surface_bytes("angle_block_healed.obj", text.as_bytes(), Format::Obj).expect("OBJ")
}

/// `m` keeps `s`'s triangles and fills its volume exactly.
fn fills_exactly(m: &parafront_mesh::TetMesh, s: &Surface) {
    m.check_against_surface(&s.tris).expect("valid");
    let v = s.signed_volume();
    assert!(
        (m.volume() - v).abs() <= 1e-9 * v,
        "volume {} of {v}",
        m.volume()
    );
}

/// A CAD part (the angle block, healed; its needle triangles come from a
/// plane at y = 0 whose vertices lie up to 4e-17 off it) whose front, at
/// its first stall, leaves the fill two cavities it cannot close that hold
/// more faces than the surface: the region's whole surface is filled and
/// refined to the size field instead (GDT), without a recovery round. The
/// mesh keeps the surface, fills it exactly, has points inside (the
/// refinement's), and is the same on one thread and on two. The hinge,
/// whose first-stall cavities all close, keeps its front's tets.
#[test]
fn a_region_the_fill_cannot_close_in_pieces_is_filled_whole_and_refined() {
    let s = angle_block();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| mesh_surface(&s, &MeshOptions::default()))
            .expect("the angle block meshes")
    };
    let (m, sum) = run(1);
    fills_exactly(&m, &s);
    assert_eq!(sum.regions_refined, vec![1], "{sum:?}");
    assert_eq!(sum.recovery_rounds, 0, "{sum:?}");
    assert!(sum.regions_filled.is_empty(), "{sum:?}");
    // The fill alone adds a few dozen split points (39); the refinement
    // brings the interior to the size field.
    assert!(
        m.points.len() > s.points.len() + 400,
        "{} points for {} on the surface",
        m.points.len(),
        s.points.len()
    );
    let (m2, _) = run(2);
    assert_eq!(m.tets, m2.tets, "the same mesh on two threads");
    assert_eq!(m.points, m2.points);

    let text = include_str!("../../delaunay/tests/data/hinge_surface.obj");
    // Its faces point inward, as the delaunay crate's fills take them.
    let hinge = read_surface_bytes("hinge.obj", text.as_bytes(), Format::Obj)
        .expect("OBJ")
        .flipped();
    let (m, sum) = mesh_surface(&hinge, &MeshOptions::default()).expect("the hinge meshes");
    m.check_against_surface(&hinge.tris).expect("valid");
    assert!(sum.regions_refined.is_empty(), "{sum:?}");
    assert!(sum.cavities_filled > 0, "{sum:?}");
}

/// The angle block under a given size, so with a lattice (§2) in its
/// front's input: the first stall's open cavities hand the region back to
/// the pipeline, which fills its surface whole with the lattice's points
/// as seeds (the lattice's own tets give way); without the lattice the
/// front fills it in place. Both meshes keep the surface and fill the
/// volume exactly, and neither takes the warning's path.
#[test]
fn a_region_with_a_lattice_is_handed_back_and_filled_whole() {
    use parafront_pipeline::LatticeMode;
    let s = angle_block();
    for lattice in [LatticeMode::On, LatticeMode::Off] {
        let mut o = MeshOptions {
            lattice,
            ..MeshOptions::default()
        };
        o.size.h = Some(0.1);
        let (m, sum) = mesh_surface(&s, &o).expect("the angle block meshes");
        fills_exactly(&m, &s);
        assert_eq!(sum.regions_refined, vec![1], "{lattice:?}: {sum:?}");
        assert!(sum.regions_filled.is_empty(), "{lattice:?}: {sum:?}");
        assert_eq!(sum.lattice_tets, 0, "{lattice:?}: the lattice gave way");
    }
}
