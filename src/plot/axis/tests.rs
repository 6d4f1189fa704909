use super::*;

#[test]
fn bounds_are_finite_and_bounded() {
    for (lo, hi) in [
        (5e-324, 1e308),
        (0.0, f64::INFINITY),
        (f64::NAN, 1.0),
        (1e308, 1e308),
        (1e-300, 1e300),
        (-1.0, -2.0),
        (3.0, 3.0),
    ] {
        let (a, b) = log_bounds(lo, hi);
        assert!(
            a.is_finite() && b.is_finite() && a > 0.0 && b > a * 1.009,
            "{lo} {hi}: {a} {b}"
        );
        assert!((b / a).log10() <= MAX_DECADES + 1e-9, "{lo} {hi}: {a} {b}");
        let ax = LogAxis::new(lo, hi);
        let t = ax.ticks(12);
        assert!(
            t.len() <= MAX_TICKS + 1 && t.iter().all(|v| ax.contains(*v)),
            "{t:?}"
        );
        assert!(ax.light(1000).len() <= MAX_LIGHT);
    }
    let (a, b) = lin_bounds(f64::NEG_INFINITY, 1e308 * 10.0);
    assert!(a.is_finite() && b.is_finite() && b > a);
}

#[test]
fn log_ticks_are_round() {
    assert_eq!(
        LogAxis::new(0.1, 1000.0).ticks(12),
        vec![0.1, 1.0, 10.0, 100.0, 1000.0]
    );
    let t = LogAxis::new(1e-300, 1e300).ticks(12);
    assert!(t.len() >= 3 && t.len() <= 12, "{t:?}");
    let t = LogAxis::new(700.0, 1300.0).ticks(12);
    assert!(t.len() >= 3, "{t:?}");
}

/// Two decades in a small panel (six labels; the DaISy CD player arm's Bode panels,
/// 0.0245–2.5 rad/s): every decade keeps a label, never linear steps 1, 2, 3, 4 that leave
/// the lower decades bare.
#[test]
fn log_ticks_label_every_decade_of_a_two_decade_panel() {
    for (lo, hi) in [(0.0245, 2.5), (0.0245, 4.0), (0.02, 3.0), (0.15, 40.0)] {
        let t = LogAxis::new(lo, hi).ticks(6);
        assert!(t.len() >= 2 && t.len() <= 6, "{lo}–{hi}: {t:?}");
        let d0 = lo.log10().ceil() as i32;
        let d1 = hi.log10().floor() as i32;
        for d in d0..=d1 {
            let v = 10f64.powi(d);
            assert!(
                t.iter().any(|x| (x / v - 1.0).abs() < 1e-9),
                "{lo}–{hi}: {v} in {t:?}"
            );
        }
    }
}

#[test]
fn phase_ticks_are_multiples_of_90() {
    let ax = PhaseAxis::covering([-90.0, -235.0]);
    assert_eq!(ax.ends(), (-270.0, 0.0));
    assert_eq!(ax.ticks(), vec![-270.0, -180.0, -90.0, 0.0]);
    let ax = PhaseAxis::covering([-5000.0, 10.0]);
    assert!(ax.ticks().iter().all(|t| t % 90.0 == 0.0) && ax.ticks().len() <= MAX_TICKS);
    assert_eq!(phase_tick(&-90.0), "−90°");
}
