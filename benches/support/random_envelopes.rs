//! Random envelopes of the kind users produce (issue 38), shared by `benches/fit.rs` and
//! `tests/fit_sweep.rs`: a log-quadratic trend times 0–3 Lorentzian bumps, smooth or jagged,
//! 1–6 decades, 20–2000 points, from a fixed seed.
//!
//! `log10 r_trend(x) = c0 + c1·x + c2·x²` with `x ∈ [−1, 1]` the position in the band (log ω);
//! each bump multiplies by `1 + h / (1 + ((ℓ − ℓ_c)/w)²)` with `ℓ = log10 ω`, height
//! `h ∈ [1, 20]`, half-width `w` 0.005–0.05 of the band (in decades) and a centre inside the
//! band; a jagged envelope is multiplied datum by datum by `10^N(0, 0.08)`.

#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::system::logspace;

/// Seed of the 24-envelope sweep.
pub const SWEEP_SEED: u64 = 38;
/// Number of envelopes of the sweep.
pub const SWEEP_LEN: usize = 24;

/// One Lorentzian bump: centre and half-width in decades, height.
#[derive(Debug, Clone, Copy)]
pub struct Bump {
    pub centre: f64,
    pub width: f64,
    pub height: f64,
}

/// Everything that defines one envelope.
#[derive(Debug, Clone)]
pub struct Spec {
    pub jagged: bool,
    /// `log10 ω` of the first datum.
    pub lo: f64,
    pub decades: f64,
    pub points: usize,
    /// `c0, c1, c2` of the log-quadratic trend.
    pub trend: [f64; 3],
    pub bumps: Vec<Bump>,
    /// Seed of the jagged noise.
    pub noise_seed: u64,
}

impl Spec {
    /// One line describing the envelope.
    pub fn label(&self) -> String {
        format!(
            "{} {:.1} dec {} pts {} bumps",
            if self.jagged { "jagged" } else { "smooth" },
            self.decades,
            self.points,
            self.bumps.len()
        )
    }
}

/// A standard normal draw (Box–Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.gen::<f64>();
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A random spec: smooth or jagged, 1–6 decades, 20–2000 points (log-uniform), 0–3 bumps.
pub fn random_spec(rng: &mut ChaCha8Rng) -> Spec {
    let jagged = rng.gen_bool(0.5);
    let decades = rng.gen_range(1.0..=6.0);
    let points = (20.0 * 100f64.powf(rng.gen::<f64>())).round() as usize;
    let lo = rng.gen_range(-2.0..=1.0);
    let trend = [
        rng.gen_range(-2.0..=0.0),
        rng.gen_range(-1.0..=1.0),
        rng.gen_range(-0.5..=0.5),
    ];
    let nb = rng.gen_range(0..=3);
    let bumps = (0..nb)
        .map(|_| Bump {
            centre: lo + decades * rng.gen_range(0.05..=0.95),
            width: decades * rng.gen_range(0.005..=0.05),
            height: rng.gen_range(1.0..=20.0),
        })
        .collect();
    Spec {
        jagged,
        lo,
        decades,
        points: points.clamp(20, 2000),
        trend,
        bumps,
        noise_seed: rng.gen(),
    }
}

/// The envelope of `spec`.
pub fn envelope(spec: &Spec) -> Envelope {
    let omega = logspace(
        10f64.powf(spec.lo),
        10f64.powf(spec.lo + spec.decades),
        spec.points,
    );
    let mut noise = ChaCha8Rng::seed_from_u64(spec.noise_seed);
    let [c0, c1, c2] = spec.trend;
    let r_min = omega
        .iter()
        .map(|w| {
            let l = w.log10();
            let x = 2.0 * (l - spec.lo) / spec.decades - 1.0;
            let mut v = 10f64.powf(c0 + c1 * x + c2 * x * x);
            for b in &spec.bumps {
                v *= 1.0 + b.height / (1.0 + ((l - b.centre) / b.width).powi(2));
            }
            if spec.jagged {
                v *= 10f64.powf(0.08 * normal(&mut noise));
            }
            v
        })
        .collect();
    Envelope {
        omega,
        r_min,
        a1_limit: None,
        method: EnvelopeMethod::File,
    }
}

/// The 24 specs of the sweep (fixed seed).
pub fn sweep_specs() -> Vec<Spec> {
    let mut rng = ChaCha8Rng::seed_from_u64(SWEEP_SEED);
    (0..SWEEP_LEN).map(|_| random_spec(&mut rng)).collect()
}

/// A smooth 4-decade envelope of `points` data with two bumps (the "smooth, bumps"
/// cases: 2000 and 21 points).
pub fn smooth_bumps(points: usize) -> Envelope {
    envelope(&Spec {
        jagged: false,
        lo: -1.0,
        decades: 4.0,
        points,
        trend: [-1.0, 0.6, -0.3],
        bumps: vec![
            Bump {
                centre: 0.3,
                width: 0.06,
                height: 8.0,
            },
            Bump {
                centre: 1.7,
                width: 0.1,
                height: 3.0,
            },
        ],
        noise_seed: 0,
    })
}

/// The envelope as the CSV `rshape fit --envelope` reads (`omega_rad_s,r_min`).
pub fn to_csv(env: &Envelope) -> String {
    let mut s = String::from("omega_rad_s,r_min\n");
    for (w, r) in env.omega.iter().zip(&env.r_min) {
        s.push_str(&format!("{w:.17e},{r:.17e}\n"));
    }
    s
}
