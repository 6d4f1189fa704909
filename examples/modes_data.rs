//! Writes a large lightly damped `[physical]` model and its noisy data (the issue-21 target
//! "a 200-mode physical model's `run` ≤ 30 s"; the same files as `cargo bench --bench run`).
//!
//! Run: `cargo run --release --example modes_data -- [MODES] [POINTS] [DIR]` (defaults 200,
//! 1000, `/tmp/modes`), then `rshape run DIR/modes200.toml --out DIR/out`.

#[path = "../benches/support/modes.rs"]
mod modes;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let k = args
        .get(1)
        .map_or(200, |a| a.parse().expect("MODES: a number"));
    let points = args
        .get(2)
        .map_or(1000, |a| a.parse().expect("POINTS: a number"));
    let dir = std::path::PathBuf::from(args.get(3).map_or("/tmp/modes", |a| a.as_str()));
    let cfg = modes::write(&dir, k, points);
    println!("wrote {} ({k} modes, {points} points)", cfg.display());
}
