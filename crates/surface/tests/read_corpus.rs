//! Every corpus file reads, with the triangle and vertex counts of
//! manifest.json (STL vertex counts assume exact welding). Needs
//! PARAFRONT_GEOMETRY; skips with a message when it is unset.

use parafront_surface::read::read_surface;
use std::path::PathBuf;

/// (file, triangles, vertices) of each entry of manifest.json. Entries are
/// flat objects starting with "file"; nested objects (shell nesting) are
/// indented deeper, so the top-level keys are found by their indentation.
fn manifest(text: &str) -> Vec<(String, usize, Option<usize>)> {
    let mut out = Vec::new();
    for chunk in text.split("\n   \"file\": \"").skip(1) {
        let file = chunk[..chunk.find('"').unwrap()].to_string();
        let num = |key: &str| -> Option<usize> {
            let pat = format!("\n   \"{key}\": ");
            let at = chunk.find(&pat)? + pat.len();
            let end = chunk[at..].find(|c: char| !c.is_ascii_digit())?;
            chunk[at..at + end].parse().ok()
        };
        let tris = num("triangles").unwrap_or_else(|| panic!("{file}: no triangle count"));
        out.push((file, tris, num("vertices")));
    }
    out
}

#[test]
fn corpus_reads_with_manifest_counts() {
    let Some(dir) = std::env::var_os("PARAFRONT_GEOMETRY") else {
        eprintln!("PARAFRONT_GEOMETRY unset: corpus test skipped");
        return;
    };
    let dir = PathBuf::from(dir);
    let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    let entries = manifest(&text);
    assert!(entries.len() >= 10, "manifest parsed: {entries:?}");
    let mut seen = 0;
    for sub in ["valid", "invalid"] {
        for f in std::fs::read_dir(dir.join(sub)).unwrap() {
            let path = f.unwrap().path();
            let rel = format!("{sub}/{}", path.file_name().unwrap().to_string_lossy());
            let s = read_surface(&path).unwrap_or_else(|e| panic!("{e}"));
            let (_, tris, verts) = entries
                .iter()
                .find(|e| e.0 == rel)
                .unwrap_or_else(|| panic!("{rel} not in manifest"));
            assert_eq!(s.tris.len(), *tris, "{rel}: triangles");
            assert_eq!(s.patch.len(), *tris, "{rel}: patch tags");
            if let Some(v) = verts {
                assert_eq!(s.points.len(), *v, "{rel}: vertices");
            }
            assert!(s.points.iter().flatten().all(|x| x.is_finite()));
            seen += 1;
        }
    }
    assert_eq!(seen, entries.len(), "every manifest entry has a file");
}
