//! Writes the hard surfaces of issue 20 (`parafront_surface::hard`) as OBJ
//! files, for `scripts/bench.py --sets hard` and for the peers:
//! `cargo run --release -p parafront --example hard_surfaces -- OUTDIR`.
use parafront_io::{write_surface, WriteOptions};
use parafront_surface::hard::{boss_box, frustum, rod, slotted_box, twisted_tower};
use std::path::Path;

/// The squat tower's twists (found by the fill's property test).
const SQUAT_TWISTS: [f64; 3] = [0.42912146221657504, 0.4137627233452473, 0.7758174272098246];

fn main() {
    let Some(dir) = std::env::args().nth(1) else {
        eprintln!("usage: hard_surfaces OUTDIR");
        std::process::exit(2);
    };
    let dir = Path::new(&dir);
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("{}: {e}", dir.display());
        std::process::exit(1);
    }
    let parts = [
        // Needles: tip radius 1/aspect of the length.
        ("needle_1000", frustum(6, 1.0, 1e-3, 5e-4, 0.0)),
        ("needle_5000", frustum(6, 1.0, 2e-4, 1e-4, 0.0)),
        // Twisted prisms: no tetrahedralization of their own corners.
        ("schonhardt", frustum(3, 1.0, 1.0, 1.0, 0.5)),
        ("twisted_square", frustum(4, 1.0, 1.0, 1.0, 0.6)),
        // Three twisted layers 0.01 high on a radius of 1: as one cavity,
        // flips leave 11 of its 20 faces missing and only the conforming
        // fill closes it (the front makes a tet first, and the fill closes
        // what is left).
        ("squat_tower", twisted_tower(&SQUAT_TWISTS, 0.01)),
        // A rod of aspect 1,000 with side triangles of aspect 3,000.
        ("rod", rod(8, 0.02, 20.0, 4)),
        // Slots 1 % and 0.1 % of the part.
        ("slot_1e-2", slotted_box(1e-2)),
        ("slot_1e-3", slotted_box(1e-3)),
        // A feature 1e-4 of the part beside faces of 1.
        ("boss_1e-4", boss_box(1e-4)),
    ];
    for (name, s) in parts {
        let path = dir.join(format!("{name}.obj"));
        if let Err(e) = write_surface(&path, &s, &WriteOptions::default()) {
            eprintln!("{}: {e}", path.display());
            std::process::exit(1);
        }
        println!("{}", path.display());
    }
}
