//! Every figure over extreme finite ranges (issue 34 item 4): data of 1e308, frequencies
//! from 1e-300 to 1e300, a subnormal 5e-324 — each figure must come back quickly with a
//! small, well-formed document whose coordinates are finite.  Before the axis guard
//! (src/plot/axis.rs) `run`'s bode.svg grew past 4 GB in 28 s on one datum of 1e308+1e308j.
//!
//! And the look the figures promise (issue 35): a legend swatch has the dash pattern of its
//! curve, the title fits the 960 px canvas, phase ticks are multiples of 90°.
//!
//! Set `RSHAPE_FIGURE_DIR` to keep the drawn figures (to render and look at them).

use nalgebra::DMatrix;
use num_complex::Complex64;
use proptest::prelude::*;
use rshape::diagnose::{bode_svg as overlay_svg, history_svg, BodeData, ModelCurve};
use rshape::plot::{
    batch_svg, bode_svg, mu_svg, r_vs_delta_svg, stability_svg, BatchFigureInput, BodeInput,
    MuInput, RVsDeltaInput, StabilityInput, Symbols,
};
use rshape::TransferFunction;
use std::time::{Duration, Instant};

/// Largest accepted document (the normal figures are 50–400 kB).
const MAX_BYTES: usize = 3_000_000;
/// Longest accepted drawing time of one figure (debug build, shared cores; a hang was
/// endless, the normal figures take well under a second).
const MAX_TIME: Duration = Duration::from_secs(30);

fn keep(name: &str, svg: &str) {
    if let Ok(dir) = std::env::var("RSHAPE_FIGURE_DIR") {
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(std::path::Path::new(&dir).join(name), svg).unwrap();
    }
}

/// Draws with `f`, checking time, size, well-formedness and finite coordinates.
fn check(name: &str, f: impl FnOnce() -> rshape::Result<String>) -> String {
    let t = Instant::now();
    let svg = f().unwrap_or_else(|e| panic!("{name}: {e}"));
    let dt = t.elapsed();
    assert!(dt < MAX_TIME, "{name}: {dt:?}");
    assert!(svg.len() < MAX_BYTES, "{name}: {} bytes", svg.len());
    let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
    for n in doc.descendants().filter(|n| n.is_element()) {
        for a in n.attributes() {
            if [
                "x", "y", "cx", "cy", "x1", "x2", "y1", "y2", "points", "width", "height",
            ]
            .contains(&a.name())
            {
                let v = a.value().to_ascii_lowercase();
                assert!(
                    !v.contains("nan") && !v.contains("inf"),
                    "{name}: {}={}",
                    a.name(),
                    a.value()
                );
                for num in v.split([' ', ',']).filter(|s| !s.is_empty()) {
                    let x: f64 = num.parse().unwrap_or(0.0);
                    assert!(x.abs() < 1e6, "{name}: {}={x}", a.name());
                }
            }
        }
    }
    keep(name, &svg);
    svg
}

/// Draws every figure on the frequencies `omega` with the values `v` (both positive), as
/// data, envelopes, μ, limits and misfits.
fn every_figure(tag: &str, omega: &[f64], v: &[f64]) {
    let n = omega.len();
    let r = TransferFunction::new(vec![1.0, 1e-3], vec![1.0, 1.0]);
    let data: Vec<DMatrix<Complex64>> = v
        .iter()
        .map(|x| DMatrix::from_element(1, 1, Complex64::new(*x, *x)))
        .collect();
    let model: Vec<Option<DMatrix<Complex64>>> = data.iter().cloned().map(Some).collect();
    let failing: Vec<bool> = (0..n).map(|k| k % 3 == 0).collect();
    check(&format!("{tag}_r_vs_delta.svg"), || {
        r_vs_delta_svg(&RVsDeltaInput {
            title: "extreme",
            omega,
            r_min: v,
            r_min_label: "r_min",
            failing: &failing,
            a1_failing: &[],
            r_configured: Some(&r),
            r_fitted: Some(&r),
            grid: omega,
            a1_on_grid: Some(v),
        })
    });
    let radius: Vec<f64> = v.iter().map(|x| x * 0.5).collect();
    check(&format!("{tag}_bode.svg"), || {
        bode_svg(&BodeInput {
            title: "extreme",
            omega,
            data: &data,
            noise_radius: Some(&radius),
            grid: omega,
            model: &model,
            symbol: "G",
        })
    });
    check(&format!("{tag}_mu.svg"), || {
        mu_svg(&MuInput {
            title: "extreme",
            omega,
            mu: v,
            a1_failing: &[],
        })
    });
    let per = [(omega, v), (omega, v)];
    check(&format!("{tag}_batch.svg"), || {
        batch_svg(
            &BatchFigureInput {
                title: "extreme",
                datasets: &per,
                combined: (omega, v),
                r_configured: Some(&r),
                r_fitted: Some(&r),
                grid: omega,
                a1_on_grid: Some(v),
            },
            &Symbols::OPEN_LOOP,
        )
    });
    let curves = vec![("configured".to_string(), v.to_vec())];
    check(&format!("{tag}_stability.svg"), || {
        stability_svg(&StabilityInput {
            title: "extreme",
            omega,
            inv_t: v,
            r: &curves,
            binding: &[omega[0], 0.0, f64::INFINITY],
            notes: &["configured r: α* = 1e308: PROVEN robust".to_string()],
        })
    });
    let g: Vec<Complex64> = v.iter().map(|x| Complex64::new(*x, -*x)).collect();
    let invalid = vec![false; n];
    check(&format!("{tag}_overlay.svg"), || {
        overlay_svg(
            "extreme",
            &BodeData {
                omega,
                g: &g,
                radius: Some(&radius),
                invalid: &invalid,
            },
            &[ModelCurve {
                name: "model".into(),
                omega: omega.to_vec(),
                g: g.clone(),
            }],
        )
    });
    let labels: Vec<String> = (0..n.min(6)).map(|k| format!("rev{k}")).collect();
    let frac: Vec<f64> = v.iter().take(labels.len()).map(|x| x.min(1.0)).collect();
    check(&format!("{tag}_history.svg"), || {
        history_svg("extreme", &labels, &v[..labels.len()], &frac)
    });
}

#[test]
fn huge_values() {
    let omega: Vec<f64> = (0..40).map(|k| 1.0 + k as f64).collect();
    let mut v = vec![1.0; 40];
    v[7] = 1e308;
    v[8] = f64::MAX;
    every_figure("huge", &omega, &v);
}

#[test]
fn frequencies_over_600_decades() {
    let omega: Vec<f64> = (0..61).map(|k| 10f64.powi(-300 + 10 * k)).collect();
    let v: Vec<f64> = (0..61).map(|k| 10f64.powi(-300 + 10 * k)).collect();
    every_figure("wide", &omega, &v);
}

#[test]
fn subnormal_values_and_frequencies() {
    let mut omega: Vec<f64> = (0..20).map(|k| 1.0 + k as f64).collect();
    omega[0] = 5e-324;
    let mut v = vec![0.5; 20];
    v[3] = 5e-324;
    v[4] = f64::MIN_POSITIVE;
    every_figure("tiny", &omega, &v);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    /// Random decades for the frequencies and the values, anywhere in the finite range.
    #[test]
    fn random_extreme_ranges(w0 in -323i32..300, dw in 0i32..300, v0 in -323i32..300, dv in 0i32..300) {
        let n = 12;
        let omega: Vec<f64> = (0..n)
            .map(|k| 10f64.powf(w0 as f64 + dw as f64 * k as f64 / (n - 1) as f64).max(5e-324))
            .filter(|w| w.is_finite())
            .collect();
        let v: Vec<f64> = (0..omega.len())
            .map(|k| 10f64.powf(v0 as f64 + dv as f64 * k as f64 / (n - 1) as f64).clamp(5e-324, f64::MAX))
            .collect();
        prop_assume!(omega.len() >= 2);
        every_figure("prop", &omega, &v);
    }
}

// ---- the look (issue 35) -------------------------------------------------------------

/// `(class, stroke, dasharray)` of every overlay polyline.
fn lines(svg: &str) -> Vec<(String, String, String)> {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline") && n.attribute("class").is_some())
        .map(|n| {
            (
                n.attribute("class").unwrap().to_string(),
                n.attribute("stroke").unwrap_or("").to_string(),
                n.attribute("stroke-dasharray").unwrap_or("").to_string(),
            )
        })
        .collect()
}

/// Every legend swatch of a line has a curve of its colour with its dash pattern.
fn assert_swatches_match(name: &str, svg: &str) {
    let l = lines(svg);
    let swatches: Vec<_> = l.iter().filter(|x| x.0 == "legend").collect();
    assert!(!swatches.is_empty(), "{name}: no line swatch");
    for s in swatches {
        assert!(
            l.iter().any(|c| c.0 == "curve" && c.1 == s.1 && c.2 == s.2),
            "{name}: swatch {s:?} has no curve of its look: {l:?}"
        );
    }
}

/// The texts of the document with their font size and x.
fn texts(svg: &str) -> Vec<(String, f64)> {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| {
            let t: String = n
                .descendants()
                .filter(|d| d.is_text())
                .filter_map(|d| d.text())
                .collect();
            let size = n
                .attribute("font-size")
                .and_then(|s| s.trim_end_matches("px").parse().ok())
                .unwrap_or(12.0);
            (t.trim().to_string(), size)
        })
        .collect()
}

fn figures_of_the_look() -> Vec<(&'static str, String)> {
    let omega: Vec<f64> = (0..60).map(|k| 0.5 * 1.1f64.powi(k)).collect();
    let rmin: Vec<f64> = omega.iter().map(|w| 0.01 * (1.0 + w / 10.0)).collect();
    let conf = TransferFunction::new(vec![0.5, 0.05], vec![0.1, 1.0]);
    let fit = TransferFunction::new(vec![0.3, 0.02], vec![0.1, 1.0]);
    let a1: Vec<f64> = omega.iter().map(|w| 2.0 / (1.0 + w / 30.0)).collect();
    let long = "Smallest consistent |r| per datum vs |r(jω)| — a very long configuration name that goes on and on with many words about the flexible robot of Boulet and Francis 1998";
    let rvd = r_vs_delta_svg(&RVsDeltaInput {
        title: long,
        omega: &omega,
        r_min: &rmin,
        r_min_label: "‖Δᵢ‖ (Theorem 2, eq. 8)",
        failing: &vec![false; omega.len()],
        a1_failing: &[],
        r_configured: Some(&conf),
        r_fitted: Some(&fit),
        grid: &omega,
        a1_on_grid: Some(&a1),
    })
    .unwrap();
    let g = |w: f64| Complex64::new(1.0, w / 3.0).powi(3).inv() * Complex64::new(0.0, -1.0);
    let data: Vec<DMatrix<Complex64>> = omega
        .iter()
        .map(|w| DMatrix::from_element(1, 1, g(*w)))
        .collect();
    let model: Vec<Option<DMatrix<Complex64>>> = data.iter().cloned().map(Some).collect();
    let bode = bode_svg(&BodeInput {
        title: long,
        omega: &omega,
        data: &data,
        noise_radius: None,
        grid: &omega,
        model: &model,
        symbol: "G",
    })
    .unwrap();
    let curves = vec![
        (
            "configured".to_string(),
            omega.iter().map(|w| conf.freq(*w).norm()).collect(),
        ),
        (
            "fitted".to_string(),
            omega.iter().map(|w| fit.freq(*w).norm()).collect(),
        ),
    ];
    let stab = stability_svg(&StabilityInput {
        title: long,
        omega: &omega,
        inv_t: &a1,
        r: &curves,
        binding: &[0.0, 3.0],
        notes: &["configured r: α* = 0.5: NOT proven robust (α* < 1)".to_string()],
    })
    .unwrap();
    let per = [(omega.as_slice(), rmin.as_slice())];
    let batch = batch_svg(
        &BatchFigureInput {
            title: long,
            datasets: &per,
            combined: (&omega, &rmin),
            r_configured: Some(&conf),
            r_fitted: Some(&fit),
            grid: &omega,
            a1_on_grid: Some(&a1),
        },
        &Symbols::OPEN_LOOP,
    )
    .unwrap();
    let mu = mu_svg(&MuInput {
        title: long,
        omega: &omega,
        mu: &a1,
        a1_failing: &[],
    })
    .unwrap();
    let gs: Vec<Complex64> = omega.iter().map(|w| g(*w)).collect();
    let overlay = overlay_svg(
        long,
        &BodeData {
            omega: &omega,
            g: &gs,
            radius: None,
            invalid: &vec![false; omega.len()],
        },
        &[ModelCurve {
            name: "model".into(),
            omega: omega.clone(),
            g: gs.clone(),
        }],
    )
    .unwrap();
    vec![
        ("look_r_vs_delta.svg", rvd),
        ("look_bode.svg", bode),
        ("look_stability.svg", stab),
        ("look_batch.svg", batch),
        ("look_mu.svg", mu),
        ("look_overlay.svg", overlay),
    ]
}

#[test]
fn swatches_titles_and_phase_ticks() {
    for (name, svg) in figures_of_the_look() {
        keep(name, &svg);
        assert_swatches_match(name, &svg);
        // The title (first text) fits 960 px at 0.55 em per character (wider than the
        // digits and lower-case letters of common sans fonts) and is not cut mid-word.
        let (title, size) = texts(&svg)[0].clone();
        let width = title.chars().count() as f64 * 0.55 * size;
        assert!(width <= 940.0, "{name}: `{title}` ≈ {width} px");
        assert!(
            title.contains(" … ") || !title.contains('…'),
            "{name}: `{title}`"
        );
        // Phase ticks: every degree label a multiple of 90.
        for (t, _) in texts(&svg) {
            if let Some(d) = t.strip_suffix('°') {
                let v: f64 = d.replace('−', "-").parse().unwrap();
                assert_eq!(v % 90.0, 0.0, "{name}: tick {t}");
            }
        }
    }
}

/// The fitted r is dashed in every figure and its swatch too; the configured r solid.
#[test]
fn fitted_dashed_configured_solid() {
    for (name, svg) in figures_of_the_look() {
        for (class, stroke, dash) in lines(&svg) {
            if stroke == "#E67814" && name != "look_bode.svg" {
                assert!(!dash.is_empty(), "{name}: {class} fitted r solid");
            }
            if stroke == "#1F77B4" && class == "legend" {
                assert!(dash.is_empty(), "{name}: configured r dashed");
            }
        }
    }
}
