use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_unit, FitSettings};
use rshape::system::logspace;
fn main() {
    for band in [2.0, 4.0, 6.0] {
        for rise in [0.5, 1.0, 2.0, 3.0] {
            for n in [50usize, 300] {
                let lo = 1.0f64;
                let hi = 10f64.powf(band);
                let omega = logspace(lo, hi, n);
                let knee = hi / 10f64.powf(rise);
                let r: Vec<f64> = omega
                    .iter()
                    .map(|w| {
                        if *w < knee {
                            1e-3
                        } else {
                            1e-3 * (w / knee).powi(2)
                        }
                    })
                    .collect();
                let env = Envelope {
                    omega: omega.clone(),
                    r_min: r,
                    a1_limit: None,
                    method: EnvelopeMethod::File,
                };
                for order in 1..4 {
                    let s = FitSettings {
                        order,
                        ..Default::default()
                    };
                    match fit_unit(&env, None, &s) {
                        Ok(f) => {
                            if !f.solver_events.is_empty() {
                                println!("band {band} rise {rise} n {n} order {order}: ok max {:.3} events {}", f.certificate.max_log10_ratio, f.solver_events.len());
                            }
                        }
                        Err(e) => println!(
                            "band {band} rise {rise} n {n} order {order}: ERR {}",
                            e.to_string().chars().take(300).collect::<String>()
                        ),
                    }
                }
            }
        }
    }
}
