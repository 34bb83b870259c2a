//! Builds the DDG of a surface file and prints its size and time.
fn main() {
    let path = std::env::args().nth(1).expect("surface file");
    let c: f64 = std::env::args().nth(2).map_or(1.6, |s| s.parse().unwrap());
    let s = parafront_surface::read::read_surface(std::path::Path::new(&path)).unwrap();
    let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    match parafront_ddg::build(s.points.clone(), s.mean_edge_lengths(), faces, c) {
        Ok(d) => println!(
            "c={c}: {} tets, {} points ({} surface), {:.2} s",
            d.tets.len(),
            d.points.len(),
            d.n_input,
            d.seconds
        ),
        Err(e) => println!("c={c}: {e}"),
    }
}
