//! Mutated valid files of every format: the readers return Ok or Err,
//! never panic, hang or allocate without bound. Crashes found here are
//! kept below as named regression tests.

mod read_common;

use parafront_surface::read::{medit, msh, read_surface_bytes, Format};
use proptest::prelude::*;
use read_common::samples;

/// Things worth splicing in: special numbers, huge counts, bad indices,
/// binary extremes, keywords that open sections.
const TOKENS: &[&[u8]] = &[
    b" nan ",
    b" inf ",
    b" -inf ",
    b" 1e400 ",
    b" 0 ",
    b" -1 ",
    b" -99999 ",
    b" 4294967295 ",
    b" 4294967296 ",
    b" 18446744073709551615 ",
    b" 99999999999999999999999 ",
    b"\n$Nodes\n",
    b"\n$Elements\n",
    b"\n$EndNodes\n",
    b"\nsolid\n",
    b"\nendsolid\n",
    b"\nf 1 2 99\n",
    b"\nf -99 1 2\n",
    b"\ng\n",
    b"\nVertices\n",
    b"\nTriangles\n",
    b"\xff\xfe\xfd",
    b"\0\0\0\0",
    b"\xff\xff\xff\xff",
    b"\xff\xff\xff\xff\xff\xff\xff\x7f",
    b"\x00\x00\x00\x00\x00\x00\xf8\x7f", // f64 NaN
    b"\x00\x00\xc0\x7f",                 // f32 NaN
    b"\x00\x00\x80\x7f",                 // f32 inf
    b"\x01\x00\x00\x00",
    b"\x00\x00\x00\x01",
];

#[derive(Clone, Debug)]
enum Mutation {
    Truncate(f64),
    Flip(f64, u8),
    Insert(f64, usize),
    Overwrite(f64, usize),
    Delete(f64, usize),
    Garbage(f64, Vec<u8>),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let at = 0.0..1.0f64;
    prop_oneof![
        at.clone().prop_map(Mutation::Truncate),
        (at.clone(), any::<u8>()).prop_map(|(a, x)| Mutation::Flip(a, x)),
        (at.clone(), 0..TOKENS.len()).prop_map(|(a, k)| Mutation::Insert(a, k)),
        (at.clone(), 0..TOKENS.len()).prop_map(|(a, k)| Mutation::Overwrite(a, k)),
        (at.clone(), 1..20usize).prop_map(|(a, n)| Mutation::Delete(a, n)),
        (at, prop::collection::vec(any::<u8>(), 1..16)).prop_map(|(a, g)| Mutation::Garbage(a, g)),
    ]
}

fn apply(b: &mut Vec<u8>, m: &Mutation) {
    let pos = |a: f64, len: usize| ((a * len as f64) as usize).min(len);
    match m {
        Mutation::Truncate(a) => b.truncate(pos(*a, b.len())),
        Mutation::Flip(a, x) => {
            if !b.is_empty() {
                let i = pos(*a, b.len() - 1);
                b[i] ^= x | 1;
            }
        }
        Mutation::Insert(a, k) => {
            let i = pos(*a, b.len());
            b.splice(i..i, TOKENS[*k].iter().copied());
        }
        Mutation::Overwrite(a, k) => {
            let t = TOKENS[*k];
            let i = pos(*a, b.len().saturating_sub(t.len()));
            let n = t.len().min(b.len() - i);
            b[i..i + n].copy_from_slice(&t[..n]);
        }
        Mutation::Delete(a, n) => {
            let i = pos(*a, b.len());
            let e = (i + n).min(b.len());
            b.drain(i..e);
        }
        Mutation::Garbage(a, g) => {
            let i = pos(*a, b.len());
            b.splice(i..i, g.iter().copied());
        }
    }
}

/// Runs every reader that could see these bytes; must not panic.
fn read_all(name: &str, fmt: Format, b: &[u8]) {
    let r = read_surface_bytes(name, b, fmt);
    if let Ok(s) = &r {
        let n = s.points.len();
        assert!(
            s.tris.iter().flatten().all(|&i| (i as usize) < n),
            "index out of range"
        );
        assert_eq!(s.tris.len(), s.patch.len());
        assert!(s.points.iter().flatten().all(|x| x.is_finite()));
    }
    if let Err(e) = &r {
        assert!(e.to_string().starts_with(name), "{e}");
    }
    match fmt {
        Format::Msh => check_volume(msh::parse(name, b)),
        Format::Medit => check_volume(medit::parse(name, b)),
        _ => {}
    }
}

fn check_volume(
    r: Result<parafront_surface::read::VolumeData, parafront_surface::read::ReadError>,
) {
    if let Ok(d) = r {
        let n = d.points.len();
        assert!(d.tets.iter().flatten().all(|&i| (i as usize) < n));
        assert!(d.tris.iter().flatten().all(|&i| (i as usize) < n));
        assert_eq!(d.tets.len(), d.tet_tags.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_files_never_panic(which in 0..11usize, muts in prop::collection::vec(mutation(), 1..5)) {
        let all = samples();
        let (name, fmt, mut b) = all[which % all.len()].clone();
        for m in &muts {
            apply(&mut b, m);
        }
        read_all(name, fmt, &b);
    }

}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(fmt in 0..5usize, b in prop::collection::vec(any::<u8>(), 0..400)) {
        let f = [Format::Stl, Format::Obj, Format::Off, Format::Msh, Format::Medit][fmt];
        read_all("g", f, &b);
    }
}

/// Every format reads the unmutated samples (the fuzz starts from valid files).
#[test]
fn samples_are_valid() {
    for (name, fmt, b) in samples() {
        let s = read_surface_bytes(name, &b, fmt).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.tris.len() >= 4, "{name}");
    }
}

/// Every truncation of every sample, exhaustively.
#[test]
fn every_truncation_is_handled() {
    for (name, fmt, b) in samples() {
        for cut in 0..b.len() {
            read_all(name, fmt, &b[..cut]);
        }
    }
}

/// Counts far beyond the input: an error, at once, without reserving.
#[test]
fn hostile_counts_fail_fast() {
    let mut stl = vec![0u8; 84];
    stl[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let cases: [(&str, Format, Vec<u8>); 6] = [
        ("h.stl", Format::Stl, stl),
        ("h.off", Format::Off, b"OFF\n4000000000 4000000000 0\n0 0 0\n".to_vec()),
        ("h.mesh", Format::Medit, b"Dimension 3\nVertices 4294967295\n0 0 0 1\n".to_vec()),
        ("h.msh", Format::Msh, b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n18446744073709551615\n1 0 0 0\n".to_vec()),
        ("h.msh", Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n99999999999 99999999999 1 99999999999\n2 1 0 99999999999\n1\n".to_vec()),
        ("h.msh", Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n99999999999 0 0 0\n".to_vec()),
    ];
    let t = std::time::Instant::now();
    for (name, fmt, b) in cases {
        let e = read_surface_bytes(name, &b, fmt).unwrap_err();
        assert!(e.to_string().starts_with(name), "{e}");
    }
    assert!(t.elapsed().as_secs_f64() < 1.0, "took {:?}", t.elapsed());
}
