mod plot;
fn main() {}
