//! Material regions and the front that bounds each.
//!
//! A shell with positive volume is material inside (the outer shell, or a
//! body embedded in another region: its triangles are then an interface);
//! one with negative volume is a void. Each material shell gives a region:
//! inside it, outside its child shells.
use parafront_surface::validate::Shell;
use parafront_surface::Surface;

/// One region's closed front, in local ids.
#[derive(Clone, Debug)]
pub struct RegionFront {
    /// Region id written to the mesh (1-based shell order of material shells).
    pub region_id: u32,
    /// Global surface point ids used by the region, ascending.
    pub points: Vec<u32>,
    /// Front triangles in local ids, normals pointing into the region.
    pub faces: Vec<[u32; 3]>,
}

/// The regions of `s`, one per material shell in shell order (`shells`
/// from `validate`), each with the front that bounds it (AF1).
pub fn material_regions(s: &Surface, shells: &[Shell]) -> Vec<RegionFront> {
    let mut out = Vec::new();
    for (i, sh) in shells.iter().enumerate() {
        if sh.volume <= 0.0 {
            continue;
        }
        let mut faces: Vec<[u32; 3]> = Vec::new();
        // Own triangles point out of the region: reversed.
        faces.extend(sh.tris.iter().map(|&t| {
            let v = s.tris[t as usize];
            [v[0], v[2], v[1]]
        }));
        for ch in shells.iter().filter(|c| c.parent == Some(i as u32)) {
            if ch.volume < 0.0 {
                // A void's triangles point into the void, away from us.
                faces.extend(ch.tris.iter().map(|&t| {
                    let v = s.tris[t as usize];
                    [v[0], v[2], v[1]]
                }));
            } else {
                // An embedded body's triangles point into this region.
                faces.extend(ch.tris.iter().map(|&t| s.tris[t as usize]));
            }
        }
        let mut pts: Vec<u32> = faces.iter().flatten().copied().collect();
        pts.sort_unstable();
        pts.dedup();
        let local = |p: u32| pts.binary_search(&p).unwrap() as u32;
        let faces = faces.iter().map(|f| f.map(local)).collect();
        out.push(RegionFront {
            region_id: out.len() as u32 + 1,
            points: pts,
            faces,
        });
    }
    out
}
