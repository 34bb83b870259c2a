fn main() {
    let c: f64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let lvl: u32 = std::env::args().nth(2).unwrap().parse().unwrap();
    let s = parafront_surface::generate::icosphere([0.0; 3], 1.0, lvl);
    let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    match parafront_ddg::build(s.points.clone(), s.mean_edge_lengths(), faces, c) {
        Ok(d) => println!("c={c} lvl={lvl} ok tets {} pts {} (surface {}) {:.2}s", d.tets.len(), d.points.len(), d.n_input, d.seconds),
        Err(e) => println!("c={c} lvl={lvl} err {e}"),
    }
}
