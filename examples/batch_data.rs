//! Writes N synthetic repeated experiments of a config's data into a directory, for
//! `rshape batch` and its benchmark:
//! `cargo run --release --example batch_data -- configs/robot.toml 1000 /tmp/robot1000 [SCALE]`.
#[path = "../benches/support/gen.rs"]
mod gen;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!("usage: batch_data CONFIG N DIR [SCALE]");
        std::process::exit(2);
    }
    let cfg = rshape::model::Config::load(std::path::Path::new(&a[1])).unwrap();
    let data =
        rshape::data::read_frf_csv(cfg.data.as_ref().expect("config names its data")).unwrap();
    let n: usize = a[2].parse().unwrap();
    let scale: f64 = a.get(4).map_or(0.01, |s| s.parse().unwrap());
    gen::write_datasets(&data, n, scale, std::path::Path::new(&a[3]));
    println!(
        "wrote {n} datasets of {} frequencies into {}",
        data.len(),
        a[3]
    );
}
