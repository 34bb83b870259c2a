//! The binary end to end: exit codes and what it writes.
mod common;
use common::{have_meshio, meshcheck, tets_said, tmp};
use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_parafront"))
}

fn corpus() -> Option<PathBuf> {
    match std::env::var_os("PARAFRONT_GEOMETRY") {
        Some(p) => Some(PathBuf::from(p)),
        None => {
            eprintln!("skipped: PARAFRONT_GEOMETRY is not set");
            None
        }
    }
}

#[test]
fn demo_surface_is_valid_and_written() {
    let out = tmp("demo_surface.msh");
    let o = bin()
        .args(["demo", "--check-only", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(
        text.contains("void") && text.contains("inner body"),
        "{text}"
    );
    // Read back: the same triangles.
    let m = parafront_io::read_mesh(&out).unwrap();
    let s = parafront_surface::generate::demo_part();
    assert_eq!(m.bnd_tris.len(), s.tris.len());
    assert_eq!(m.points.len(), s.points.len());
}

#[test]
fn check_rejects_an_open_surface_with_exit_1() {
    let f = tmp("open.obj");
    std::fs::write(
        &f,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n",
    )
    .unwrap();
    let o = bin().arg("check").arg(&f).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let text = String::from_utf8_lossy(&o.stdout).to_lowercase();
    assert!(text.contains("open"), "{text}");
}

/// A reader that stops early (`parafront check X | head -1`) ends the
/// run without a panic.
#[cfg(unix)]
#[test]
fn a_closed_stdout_pipe_is_no_panic() {
    use std::process::Stdio;
    let out = tmp("pipe_demo.msh");
    bin()
        .args(["demo", "--check-only", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let mut child = bin()
        .arg("check")
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the read end before the child writes its report.
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(o.status.code(), Some(101), "{err}");
}

#[test]
fn unreadable_input_gives_exit_2_and_names_the_line() {
    let f = tmp("bad.obj");
    std::fs::write(&f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let o = bin().arg("check").arg(&f).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.obj:4"), "{err}");
}

#[test]
fn convert_round_trips_a_box_mesh_through_every_format() {
    let m = parafront_mesh::generate::box_mesh(3, 2, 2, [0.0; 3], [1.0, 1.0, 1.0]);
    let src = tmp("box.vtu");
    parafront_io::write_mesh(&src, &m, &Default::default()).unwrap();
    for (ext, extra) in [
        ("msh", &[][..]),
        ("msh", &["--msh-version", "2.2", "--binary"][..]),
        ("mesh", &[][..]),
    ] {
        let dst = tmp(&format!("box_{}.{ext}", extra.len()));
        let o = bin()
            .arg("convert")
            .arg(&src)
            .arg(&dst)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let back = parafront_io::read_mesh(&dst).unwrap();
        assert_eq!(back.points, m.points);
        assert_eq!(back.tets.len(), m.tets.len());
        back.check().unwrap();
    }
    let o = bin().arg("quality").arg(&src).output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("dihedral"));
}

#[test]
fn a_box_mesh_passes_meshcheck() {
    let m = parafront_mesh::generate::box_mesh(4, 3, 2, [0.0; 3], [2.0, 1.5, 1.0]);
    m.check_against_surface(
        &m.bnd_tris
            .iter()
            .map(|t| t.map(|p| p.raw()))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let vol = tmp("meshcheck_box.vtu");
    parafront_io::write_mesh(&vol, &m, &Default::default()).unwrap();
    let surf = tmp("meshcheck_surface.msh");
    let s = parafront_mesh::TetMesh {
        points: m.points.clone(),
        bnd_tris: m.bnd_tris.clone(),
        bnd_patch: m.bnd_patch.clone(),
        ..Default::default()
    };
    parafront_io::write_mesh(&surf, &s, &Default::default()).unwrap();
    meshcheck(&vol, &surf);
}

#[test]
fn check_corpus_exit_codes() {
    let Some(g) = corpus() else { return };
    for e in std::fs::read_dir(g.join("valid")).unwrap() {
        let p = e.unwrap().path();
        let o = bin().arg("check").arg(&p).output().unwrap();
        assert!(
            o.status.success(),
            "{}: {}",
            p.display(),
            String::from_utf8_lossy(&o.stdout)
        );
    }
    for (f, want) in [
        ("stanford-bunny.obj", &["open"][..]),
        ("cow.obj", &["pinched", "self-intersect"][..]),
        ("wingnut.obj", &["self-intersect"][..]),
    ] {
        let o = bin()
            .arg("check")
            .arg(g.join("invalid").join(f))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{f}");
        let text = String::from_utf8_lossy(&o.stdout).to_lowercase();
        for w in want {
            assert!(text.contains(w), "{f}: expected '{w}' in\n{text}");
        }
    }
}

/// The README's first command, end to end: the demo part (a hole, a void
/// and an embedded body) is meshed, and meshcheck agrees that the mesh keeps
/// the surface and fills it exactly.
/// `meshcheck.py` on a volume mesh of the demo part, against the surface
/// `demo --check-only` writes.
fn meshcheck_demo(vol: &Path) {
    let surf = vol.with_extension("surface.vtu");
    let o = bin()
        .args(["demo", "--check-only", "-o"])
        .arg(&surf)
        .output()
        .unwrap();
    assert!(o.status.success());
    meshcheck(vol, &surf);
}

#[test]
fn demo_mesh_passes_meshcheck() {
    let vol = tmp("demo_volume.vtu");
    let o = bin().args(["demo", "-o"]).arg(&vol).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let m = parafront_io::read_mesh(&vol).unwrap();
    let s = parafront_surface::generate::demo_part();
    assert!(m.tets.len() > 5000, "{} tets", m.tets.len());
    // Two regions: the block and the embedded sphere.
    let mut regions = m.region.clone();
    regions.sort_unstable();
    regions.dedup();
    assert_eq!(regions.len(), 2, "{regions:?}");
    let tris: Vec<[u32; 3]> = s.tris.clone();
    m.check_against_surface(&tris).unwrap();

    meshcheck_demo(&vol);
}

/// `--optimize 0` switches improvement off; the default reports before and
/// after, and `quality --before` compares the two meshes and plots both.
#[test]
fn optimize_flag_and_quality_before() {
    let raw = tmp("demo_raw.vtu");
    let imp = tmp("demo_improved.vtu");
    let o = bin()
        .args(["demo", "--optimize", "0", "-o"])
        .arg(&raw)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(!text.contains("before improvement"), "{text}");
    let o = bin().args(["demo", "-o"]).arg(&imp).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(
        text.contains("before improvement") && text.contains("swap"),
        "{text}"
    );
    let plot = tmp("demo_before_after.svg");
    let o = bin()
        .arg("quality")
        .arg(&imp)
        .arg("--before")
        .arg(&raw)
        .arg("--plot")
        .arg(&plot)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(plot.exists());
    // The share of tets under 10 degrees, before and after.
    let share = |name: &Path| -> f64 {
        let line = text
            .lines()
            .find(|l| l.starts_with(&*name.display().to_string()) && l.contains("under 10 deg"))
            .unwrap_or_else(|| panic!("no summary line for {}:\n{text}", name.display()));
        let s = line.split("deg, ").nth(1).unwrap();
        s.split('%').next().unwrap().trim().parse().unwrap()
    };
    assert!(share(&imp) < share(&raw), "{text}");
}

/// `--parts 2 --pvtu`: the merged mesh passes meshcheck, and the pieces
/// hold every tet of it once. With improvement on, `--pvtu` is refused
/// up front (its pieces number the mesh before improvement).
#[test]
fn parts_write_a_partitioned_mesh() {
    let vol = tmp("demo_parts.vtu");
    let pv = tmp("demo_parts.pvtu");
    let o = bin()
        .args(["demo", "--parts", "2", "--pvtu"])
        .arg(&pv)
        .arg("-o")
        .arg(&vol)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("--optimize 0"));
    assert!(!vol.exists() && !pv.exists());
    let o = bin()
        .args(["demo", "--parts", "2", "--optimize", "0", "--pvtu"])
        .arg(&pv)
        .arg("-o")
        .arg(&vol)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let m = parafront_io::read_mesh(&vol).unwrap();
    m.check_against_surface(&parafront_surface::generate::demo_part().tris)
        .unwrap();
    meshcheck_demo(&vol);
    // Every piece file is there, and together they hold each tet once.
    let pvtu = std::fs::read_to_string(&pv).unwrap();
    let mut total = 0;
    for src in pvtu.split("Source=\"").skip(1) {
        let name = src.split('"').next().unwrap();
        let piece = parafront_io::read_mesh(&pv.parent().unwrap().join(name)).unwrap();
        total += piece.tets.len();
    }
    assert_eq!(total, m.tets.len(), "{pvtu}");
}

/// Every piece of `-o x.pvtu` opens in meshio (compressed, as written by
/// default), and their tets add up to the summary's count. The demo on 8
/// parts has an empty piece, which is left out, and a piece whose arrays
/// meshio 5.3 mixed up when the data went in document order.
#[test]
fn meshio_reads_every_piece() {
    if !have_meshio() {
        eprintln!("skipped: python3 with numpy+meshio not available");
        return;
    }
    let pv = tmp("meshio_pieces.pvtu");
    let o = bin()
        .args(["demo", "--parts", "8", "-o"])
        .arg(&pv)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{text}");
    let said = tets_said(&text);
    let script = r#"
import sys, re, os, meshio
index = open(sys.argv[1]).read()
total = 0
for name in re.findall(r'Source="([^"]+)"', index):
    m = meshio.read(os.path.join(os.path.dirname(sys.argv[1]), name))
    n = sum(len(c.data) for c in m.cells if c.type == "tetra")
    assert n > 0, name
    total += n
print("tets", total)
"#;
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(&pv)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains(&format!("tets {said}")), "{out} vs {said}");
}

/// The stdout of a run that must have succeeded (else its output is the
/// failure's message).
fn stdout_ok(o: &std::process::Output) -> String {
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

/// The demo's pieces written by `demo --parts <parts> <args> -o pv` (a
/// .pvtu), merged by exact coordinates (the surface's points first,
/// regions from the piece numbers): the tet count the summary gives, the
/// summary, the mesh.
fn demo_pieces(
    demo: &parafront_surface::Surface,
    parts: u32,
    args: &[&str],
    pv: &Path,
) -> (usize, String, parafront_mesh::TetMesh) {
    let o = bin()
        .args(["demo", "--parts", &parts.to_string()])
        .args(args)
        .arg("-o")
        .arg(pv)
        .output()
        .unwrap();
    let text = stdout_ok(&o);
    let said = tets_said(&text);
    let (n, m) = merge_pieces(demo, pv, parts);
    // Two regions on `parts` parts, no piece empty (a part may hold none
    // of the small region).
    assert!(n <= 2 * parts && n > parts, "{n} pieces");
    (said, text, m)
}

/// The pieces `pv` names (`parts` per region), merged by exact
/// coordinates, the surface's points first; and how many there are.
fn merge_pieces(
    surface: &parafront_surface::Surface,
    pv: &Path,
    parts: u32,
) -> (u32, parafront_mesh::TetMesh) {
    let index = std::fs::read_to_string(pv).unwrap();
    let names: Vec<&str> = index
        .split("Source=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    let mut m = parafront_mesh::TetMesh {
        points: surface.points.clone(),
        ..Default::default()
    };
    let mut id: std::collections::HashMap<[u64; 3], u32> = surface
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (p.map(f64::to_bits), i as u32))
        .collect();
    for n in &names {
        let piece = parafront_io::read_mesh(&pv.parent().unwrap().join(n)).unwrap();
        assert!(!piece.tets.is_empty(), "{n} is empty");
        // Pieces go region by region: `<stem>_<r * parts + k>`.
        let k: u32 = n
            .trim_end_matches(".vtu")
            .rsplit('_')
            .next()
            .and_then(|k| k.parse().ok())
            .expect("a piece number");
        m.region
            .extend(std::iter::repeat_n(k / parts, piece.tets.len()));
        let local: Vec<u32> = piece
            .points
            .iter()
            .map(|p| {
                *id.entry(p.map(f64::to_bits)).or_insert_with(|| {
                    m.points.push(*p);
                    m.points.len() as u32 - 1
                })
            })
            .collect();
        m.tets.extend(
            piece
                .tets
                .iter()
                .map(|t| t.map(|p| parafront_mesh::PointId::from_raw(local[p.idx()]))),
        );
    }
    (names.len() as u32, m)
}

/// `-o x.pvtu`: the mesh stays in its pieces (no merged mesh; under MPI
/// each process writes its own), improved piece by piece with a shift
/// between two rounds (§9.5). The pieces hold the tets the summary gives,
/// and merged by their global ids they are a valid mesh of the surface.
/// Without improvement they are the merged run's tets.
#[test]
fn a_pvtu_output_keeps_the_pieces() {
    let demo = parafront_surface::generate::demo_part();
    let pieces = |args: &[&str], pv: &Path| demo_pieces(&demo, 4, args, pv);
    let pv = tmp("demo_pieces.pvtu");
    let (said, text, m) = pieces(&[], &pv);
    assert_eq!(m.tets.len(), said);
    assert!(text.contains("quality: min dihedral"), "{text}");
    m.check_against_surface(&demo.tris).unwrap();
    // Without improvement: the merged run's tets.
    let pv0 = tmp("demo_pieces0.pvtu");
    let (said0, _, m0) = pieces(&["--optimize", "0"], &pv0);
    m0.check_against_surface(&demo.tris).unwrap();
    assert_eq!(
        gathered_tets("demo_merged.vtu", &["--optimize", "0"]),
        said0
    );
}

/// The tets of the demo's merged run at `--parts 4 <args>`, written to
/// `name`.
fn gathered_tets(name: &str, args: &[&str]) -> usize {
    let vol = tmp(name);
    let o = bin()
        .args(["demo", "--parts", "4"])
        .args(args)
        .arg("-o")
        .arg(&vol)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    parafront_io::read_mesh(&vol).unwrap().tets.len()
}

/// `-o x.pvtu` with a lattice core (§2, a size bound and `--lattice on`;
/// by default pieces have none): its tets go into the pieces with the
/// fronts'. Merged, the pieces are a valid mesh of the surface with the
/// summary's tets; unimproved, they are the gathered run's tets.
#[test]
fn a_pvtu_output_holds_the_lattice() {
    let demo = parafront_surface::generate::demo_part();
    let pv = tmp("lattice_pieces.pvtu");
    let on = ["--size", "0.8", "--lattice", "on"];
    let (plain, _, _) = demo_pieces(&demo, 4, &on[..2], &tmp("no_lattice.pvtu"));
    let (said, text, m) = demo_pieces(&demo, 4, &on, &pv);
    assert_ne!(plain, said);
    let lattice: usize = text
        .split("lattice: ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no lattice: {text}"));
    assert!(lattice > 1000 && lattice < said, "{text}");
    assert_eq!(m.tets.len(), said);
    m.check_against_surface(&demo.tris).unwrap();
    let pv0 = tmp("lattice_pieces0.pvtu");
    let unimproved = [&on[..], &["--optimize", "0"]].concat();
    let (said0, _, m0) = demo_pieces(&demo, 4, &unimproved, &pv0);
    m0.check_against_surface(&demo.tris).unwrap();
    assert_eq!(gathered_tets("lattice_merged.vtu", &unimproved), said0);
}

/// `-o x.pvtu` where the passes give way (`--serial-from 0`: any volume
/// left to pass 4 sends a region to the serial front): the serial front's
/// mesh is sent to the parts, and the pieces merge into a valid mesh of
/// the surface; unimproved, they are the gathered run's tets.
#[test]
fn a_pvtu_output_takes_the_serial_front_where_the_passes_give_way() {
    let demo = parafront_surface::generate::demo_part();
    let serial = ["--serial-from", "0"];
    let (said, text, m) = demo_pieces(&demo, 4, &serial, &tmp("serial_pieces.pvtu"));
    assert!(text.contains("meshed by the serial front"), "{text}");
    assert_eq!(m.tets.len(), said);
    m.check_against_surface(&demo.tris).unwrap();
    let unimproved = [&serial[..], &["--optimize", "0"]].concat();
    let (said0, _, m0) = demo_pieces(&demo, 4, &unimproved, &tmp("serial_pieces0.pvtu"));
    m0.check_against_surface(&demo.tris).unwrap();
    assert_eq!(gathered_tets("serial_merged.vtu", &unimproved), said0);
}

/// A thin plate's passes give way before they start (its depth is under
/// an edge): `-o x.pvtu --parts 4` gets the serial front's mesh in four
/// pieces of about equal size, also after their improvement, whose shifts
/// had moved every tet of a thin part into one piece; merged, they are a
/// valid mesh of the plate with the summary's tets.
#[test]
fn a_thin_part_in_pieces_keeps_its_parts() {
    let s = parafront_surface::generate::needle_plate(0.5, 64);
    let surf = tmp("thin_plate.stl");
    parafront_io::write_surface(&surf, &s, &Default::default()).unwrap();
    let pv = tmp("thin_plate.pvtu");
    let o = bin()
        .arg("mesh")
        .arg(&surf)
        .args(["--parts", "4", "-o"])
        .arg(&pv)
        .output()
        .unwrap();
    let text = stdout_ok(&o);
    assert!(text.contains("meshed by the serial front"), "{text}");
    let sizes: Vec<usize> = (0..4)
        .map(|k| {
            let piece = pv.with_file_name(format!("thin_plate_{k}.vtu"));
            parafront_io::read_mesh(&piece).unwrap().tets.len()
        })
        .collect();
    let said = tets_said(&text);
    assert_eq!(sizes.iter().sum::<usize>(), said);
    for &n in &sizes {
        assert!(4 * n > said / 2 && 4 * n < 3 * said / 2, "{sizes:?}");
    }
    let (named, m) = merge_pieces(&s, &pv, 4);
    assert_eq!(named, 4);
    m.check_against_surface(&s.tris).unwrap();
    let v: f64 = m.volume();
    assert!((v - s.signed_volume()).abs() < 1e-9 * v, "{v}");
    // Pieces beside a merged mesh (`--pvtu`) are the passes' own: none
    // here, which the error says.
    let beside = tmp("thin_plate_beside.pvtu");
    let o = bin()
        .arg("mesh")
        .arg(&surf)
        .args(["--parts", "4", "--optimize", "0", "-o"])
        .arg(tmp("thin_plate.vtu"))
        .arg("--pvtu")
        .arg(&beside)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("meshed by the serial front"), "{err}");
    assert!(!beside.exists());
}

/// `-o x.pvtu` with the parts left to the estimate: the demo, small
/// enough for the serial front, gets two parts (pieces need parts), and
/// the pieces are those of `--parts 2`, byte for byte, a valid mesh of
/// the surface once merged.
#[test]
fn a_pvtu_output_with_auto_parts_gets_two_at_least() {
    let demo = parafront_surface::generate::demo_part();
    let pv = tmp("auto_pieces.pvtu");
    let o = bin().args(["demo", "-o"]).arg(&pv).output().unwrap();
    let text = stdout_ok(&o);
    assert!(text.contains("parts (auto): 2 parts"), "{text}");
    let given = tmp("given_pieces.pvtu");
    let (said, _, m) = demo_pieces(&demo, 2, &[], &given);
    assert_eq!(tets_said(&text), said);
    m.check_against_surface(&demo.tris).unwrap();
    let mut written = 0;
    for k in 0..4 {
        let a = pv.with_file_name(format!("auto_pieces_{k}.vtu"));
        let b = given.with_file_name(format!("given_pieces_{k}.vtu"));
        let (a, b) = (std::fs::read(&a).ok(), std::fs::read(&b).ok());
        assert_eq!(a, b, "piece {k}");
        written += usize::from(a.is_some());
    }
    // Two regions on two parts (a part may hold none of the small one).
    assert!(written > 2, "{written} pieces");
}

/// The pieces' improvement reaches across their cuts: a tet under the
/// lift's floor of 20° that the second round left near a cut goes, with
/// the tets around it, into one piece, and a third round lifts it. At 4
/// and 8 parts the demo's merged pieces have no tet under 19.5° (before the
/// third round: 18.7° and 16.9°; gathered, 22.8°).
#[test]
fn pieces_are_lifted_across_their_cuts() {
    let demo = parafront_surface::generate::demo_part();
    for parts in [4, 8] {
        let pv = tmp(&format!("demo_lift{parts}.pvtu"));
        let (said, _, m) = demo_pieces(&demo, parts, &[], &pv);
        assert_eq!(m.tets.len(), said);
        m.check_against_surface(&demo.tris).unwrap();
        let worst = m
            .tets
            .iter()
            .map(|t| {
                parafront_mesh::quality::tet_quality(t.map(|p| m.points[p.idx()])).min_dihedral
            })
            .fold(f64::INFINITY, f64::min);
        assert!(worst >= 19.5, "{parts} parts: min dihedral {worst}");
    }
}

/// An extreme needle (a 6-sided frustum, triangles 2500 times longer than
/// its tip is wide) that the front alone cannot close: the constrained fill
/// closes it (issue 20), the mesh is valid, and the summary says so.
#[test]
fn an_extreme_needle_is_closed_by_the_fill() {
    let surf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/needle_frustum.obj");
    let out = tmp("needle_frustum.vtu");
    let o = bin()
        .arg("mesh")
        .arg(&surf)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(stdout.contains("constrained fill: 1 cavity"), "{stdout}");
    let m = parafront_io::read_mesh(&out).unwrap();
    let s = parafront_surface::read::read_surface(&surf).unwrap();
    m.check_against_surface(&s.tris).unwrap();
    assert!((m.volume() - s.signed_volume()).abs() < 1e-9 * s.signed_volume());
}

/// `--size-report` adds a line on the edges against the size field; the
/// default summary has none (it cost more than half the report's time).
#[test]
fn size_report_on_demand() {
    let run = |extra: &[&str], name: &str| {
        let o = bin()
            .args(["demo", "-o"])
            .arg(tmp(name))
            .args(extra)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(o.status.success(), "{text}");
        text
    };
    let plain = run(&[], "sr0.vtu");
    assert!(plain.contains("quality: min dihedral"), "{plain}");
    assert!(!plain.contains("edge length / target size"), "{plain}");
    let text = run(&["--size-report"], "sr1.vtu");
    let line = text
        .lines()
        .find(|l| l.starts_with("edge length / target size:"))
        .unwrap_or_else(|| panic!("no size report: {text}"));
    let nums: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let [min, mean, max, edges] = nums[..] else {
        panic!("{line}")
    };
    assert!(0.0 < min && min <= mean && mean <= max, "{line}");
    assert!(mean > 0.5 && mean < 2.0, "{line}");
    assert!(edges > tets_said(&text) as f64, "{line}");
    // The same for a mesh kept in pieces (the field is kept for it only
    // when asked).
    let pieces = run(&["--parts", "4"], "sr2.pvtu");
    assert!(pieces.contains("quality: min dihedral"), "{pieces}");
    assert!(!pieces.contains("edge length / target size"), "{pieces}");
    let pieces = run(&["--parts", "4", "--size-report"], "sr3.pvtu");
    let line = pieces
        .lines()
        .find(|l| l.starts_with("edge length / target size:"))
        .unwrap_or_else(|| panic!("no size report: {pieces}"));
    assert!(line.contains(" mean "), "{line}");
}

/// `--parts auto`, the default: the summary says what it chose (the demo
/// part is small: the serial front; under a small `--part-tets`, parts),
/// and the mesh is that of the parts given outright. `--pvtu` needs parts
/// given, and says so before meshing, writing nothing.
#[test]
fn auto_parts_are_reported_and_pieces_need_them_given() {
    let run = |args: &[&str], out: &Path| {
        let o = bin().args(args).arg("-o").arg(out).output().unwrap();
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        (o.status.code(), text, err)
    };
    let out = tmp("auto_parts.vtu");
    let (code, text, err) = run(&["demo"], &out);
    assert_eq!(code, Some(0), "{text}{err}");
    assert!(text.contains("parts (auto): the serial front"), "{text}");
    let (code, text, err) = run(&["demo", "--part-tets", "4000"], &out);
    assert_eq!(code, Some(0), "{text}{err}");
    let parts: usize = text
        .split("parts (auto): ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no parts chosen: {text}"));
    assert!(parts > 1, "{text}");
    let given = tmp("given_parts.vtu");
    let p = parts.to_string();
    let (code, text2, err) = run(&["demo", "--parts", p.as_str()], &given);
    assert_eq!(code, Some(0), "{text2}{err}");
    assert_eq!(tets_said(&text), tets_said(&text2));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&given).unwrap());
    let pv = tmp("auto_parts.pvtu");
    let (code, _, err) = run(
        &["demo", "--optimize", "0", "--pvtu", pv.to_str().unwrap()],
        &tmp("pv.vtu"),
    );
    assert_eq!(code, Some(2));
    assert!(err.contains("give --parts 2 or more"), "{err}");
    assert!(!pv.exists() && !tmp("pv.vtu").exists());
}
