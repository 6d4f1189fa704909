//! `diagnose` of a three-effect plant on 400 data: a servo (rigid body, modes at 77 and
//! 190 Hz) whose data carry an added mode (900 rad/s), a lag and a delay, 2 % noise.
//! The whole search: retune, beam search (beam 3, up to 3 effects), final holdout.
//!
//! Run: `cargo bench --bench diagnose -- --sample-count 3`.
use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{
    EffectKind, EffectSpec, Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec,
};

fn main() {
    divan::main();
}

fn mode(w: f64, z: f64, rho: f64) -> ModeSpec {
    ModeSpec {
        name: None,
        omega_n: w,
        zeta: z,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(rho),
    }
}

fn problem() -> (PhysicalModel, Channels) {
    let base = PhysicalModel {
        rigid_body: vec![PoleAtZeroSpec {
            friction_pole: None,
            name: None,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(100.0),
        }],
        mode: vec![mode(484.0, 0.02, 110.0), mode(1194.0, 0.03, -60.0)],
        ..Default::default()
    };
    let mut truth = base.clone();
    truth.mode.push(mode(900.0, 0.02, 4.0));
    let mut lag = EffectSpec::new(EffectKind::Lag);
    lag.omega_c = Some(520.0);
    let mut delay = EffectSpec::new(EffectKind::Delay);
    delay.tau_s = Some(4e-4);
    truth.effect = vec![lag, delay];
    let omega = rshape::system::logspace(69.0, 1571.0, 400);
    // Deterministic noise inside the disk (a fixed pattern of radii and angles).
    let g: Vec<Complex64> = omega
        .iter()
        .enumerate()
        .map(|(k, w)| {
            let v = truth.eval_siso(*w);
            let u = ((k * 7919) % 1000) as f64 / 1000.0;
            let a = ((k * 104_729) % 1000) as f64 / 1000.0 * std::f64::consts::TAU;
            v + Complex64::from_polar(0.02 * v.norm() * u.sqrt(), a)
        })
        .collect();
    let r = omega
        .iter()
        .map(|w| 0.02 * truth.eval_siso(*w).norm())
        .collect();
    let data = Channels {
        path: "bench".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![r],
        radius_source: vec!["bench".into()],
    };
    (base, data)
}

#[divan::bench(sample_count = 3)]
fn three_effects_400_data(bencher: divan::Bencher) {
    let (base, data) = problem();
    bencher.bench(|| {
        let d = diagnose_channels(&base, &data, &SearchSettings::default()).unwrap();
        assert!(!d.chosen.is_empty());
        d
    });
}
