//! The figures of `compare` and `history` read at a glance (issue 20, item 9), checked on the
//! SVG text: tick labels never overlap, the legend lies outside the data, the model is a
//! line on a dense grid with a continuous phase, each datum's phase sits on the model's
//! branch, the noise is drawn, and the history figure is titled by the model and the data
//! and labels each revision by the effect it added.

use crate::common;
use common::{repo, rshape, stderr};
use num_complex::Complex64;
use rshape::diagnose::revision_label;
use rshape::diagnose::{bode_svg, dense_grid, unwrap_deg, BodeData, ModelCurve};

/// One `<text>` element: position, anchor, font size and content.
#[derive(Debug)]
struct Label {
    x: f64,
    y: f64,
    anchor: String,
    size: f64,
    text: String,
    rotated: bool,
    /// Baseline (y plus the `dy` shift of the anchor).
    base: f64,
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let k = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(tag[k..k + tag[k..].find('"')?].to_string())
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN)
}

fn labels(svg: &str) -> Vec<Label> {
    svg.split("<text ")
        .skip(1)
        .map(|t| {
            let (tag, rest) = t.split_once('>').expect("tag");
            let tag = &format!(" {tag}");
            let size = num(tag, "font-size");
            let dy = attr(tag, "dy").unwrap_or_default();
            let shift = if let Some(v) = dy.strip_suffix("em") {
                v.parse::<f64>().unwrap_or(0.0) * size
            } else if let Some(v) = dy.strip_suffix("ex") {
                v.parse::<f64>().unwrap_or(0.0) * 0.5 * size
            } else {
                0.0
            };
            Label {
                base: num(tag, "y") + shift,
                x: num(tag, "x"),
                y: num(tag, "y"),
                anchor: attr(tag, "text-anchor").unwrap_or_else(|| "start".into()),
                size: num(tag, "font-size"),
                text: rest
                    .split("</text>")
                    .next()
                    .unwrap_or("")
                    .trim()
                    .to_string(),
                rotated: tag.contains("rotate("),
            }
        })
        .collect()
}

/// Horizontal extent of a label; 0.5 em per character is a lower bound for digits and
/// letters of common sans-serif fonts, so an overlap found here is a real one.
fn extent(l: &Label) -> (f64, f64) {
    let w = l.text.chars().count() as f64 * 0.5 * l.size;
    match l.anchor.as_str() {
        "middle" => (l.x - w / 2.0, l.x + w / 2.0),
        "end" => (l.x - w, l.x),
        _ => (l.x, l.x + w),
    }
}

/// No two labels overlap (boxes from the baseline: 0.7 em above, 0.2 em below).
fn assert_no_overlap(svg: &str, what: &str) {
    let ls: Vec<Label> = labels(svg)
        .into_iter()
        .filter(|l| !l.rotated && !l.text.is_empty())
        .collect();
    let rows = |l: &Label| (l.base - 0.7 * l.size, l.base + 0.2 * l.size);
    for (i, a) in ls.iter().enumerate() {
        for b in &ls[i + 1..] {
            let ((a0, a1), (b0, b1)) = (rows(a), rows(b));
            if a0 < b1 && b0 < a1 {
                let (a0, a1) = extent(a);
                let (b0, b1) = extent(b);
                assert!(
                    a1 <= b0 || b1 <= a0,
                    "{what}: labels overlap: {a:?} and {b:?}"
                );
            }
        }
    }
}

/// Points of every `<polyline>` with the given stroke colour.
fn polylines(svg: &str, stroke: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline ")
        .skip(1)
        .map(|t| t.split('>').next().unwrap_or(""))
        .filter(|t| t.contains(&format!("stroke=\"{stroke}\"")))
        .map(|t| {
            let pts = attr(&format!(" {t}"), "points").unwrap_or_default();
            pts.split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect()
        })
        .collect()
}

/// Centres of the `<circle>` elements with the given fill.
fn circles(svg: &str, fill: &str) -> Vec<(f64, f64)> {
    svg.split("<circle ")
        .skip(1)
        .map(|t| t.split('>').next().unwrap_or(""))
        .filter(|t| t.contains(&format!("fill=\"{fill}\"")))
        .map(|t| {
            let t = format!(" {t}");
            (num(&t, "cx"), num(&t, "cy"))
        })
        .collect()
}

/// The legend box: the framed rectangle (`fill="none"`, black stroke).
fn legend_box(svg: &str) -> (f64, f64, f64, f64) {
    let t = svg
        .split("<rect ")
        .skip(1)
        .map(|t| t.split('>').next().unwrap_or(""))
        .find(|t| t.contains("fill=\"none\"") && t.contains("stroke=\"#000000\""))
        .expect("a legend box");
    let t = format!(" {t}");
    let (x, y) = (num(&t, "x"), num(&t, "y"));
    (x, y, x + num(&t, "width"), y + num(&t, "height"))
}

fn run_svg(args: &[&str], out: &std::path::Path) -> String {
    let mut a: Vec<&str> = args.to_vec();
    let o = out.to_str().unwrap();
    a.extend(["--svg", o]);
    let r = rshape(&a);
    assert!(r.status.success(), "{args:?}: {}", stderr(&r));
    std::fs::read_to_string(out).unwrap()
}

/// `compare --svg` on the motor bench (SISO) and the ball screw (channel 2,1 of MIMO data):
/// no overlapping labels, the legend below every datum and every point of the curves, the
/// model drawn as a line of more points than there are data, the noise band drawn, the
/// frequency axis saying Hz and why.
#[test]
fn compare_figure_reads_at_a_glance() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str]); 3] = [
        ("twomass rigid", &["compare", "configs/twomass_rigid.toml"]),
        ("twomass rev3", &["compare", "configs/twomass_rev3.toml"]),
        (
            "ballscrew rev4, channel 2,1",
            &["compare", "configs/ballscrew_rev4.toml", "--channel", "2,1"],
        ),
    ];
    for (what, args) in cases {
        let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        args[1] = repo(&args[1]).display().to_string();
        let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let svg = run_svg(&a, &dir.path().join("x.svg"));
        assert_no_overlap(&svg, what);
        let ls = labels(&svg);
        assert!(
            ls.iter()
                .any(|l| l.text.contains("(Hz") && l.text.contains("ω/2π")),
            "{what}: the frequency axis says Hz and why"
        );
        let (x0, y0, x1, _) = legend_box(&svg);
        let inside = |(x, y): (f64, f64)| x >= x0 && x <= x1 && y >= y0;
        let data: Vec<(f64, f64)> = circles(&svg, "#000000")
            .into_iter()
            .chain(circles(&svg, "#D62728"))
            .filter(|p| !inside(*p))
            .collect();
        assert!(data.len() > 100, "{what}: data drawn");
        assert!(
            data.iter().all(|(_, y)| *y < y0),
            "{what}: a datum lies at or below the legend's top"
        );
        let model = polylines(&svg, "#1F77B4");
        let longest = model.iter().map(|l| l.len()).max().unwrap_or(0);
        assert!(
            longest > data.len() / 2 + 200,
            "{what}: the model is a line on a dense grid ({longest} points, {} data)",
            data.len() / 2
        );
        assert!(
            model
                .iter()
                .filter(|l| !l.iter().all(|p| inside(*p)))
                .flatten()
                .all(|p| p.1 < y0),
            "{what}: the model line runs under the legend"
        );
        // Tick labels of both axes lie above the legend too.
        assert!(ls
            .iter()
            .filter(|l| l.text.parse::<f64>().is_ok())
            .all(|l| l.y < y0));
        assert!(svg.contains("<polygon"), "{what}: the noise band is drawn");
    }
}

/// A model at +179° and data at −179° are 2° apart: each datum's phase dot sits on the
/// model's phase line (the old figure wrapped both to (−180°, 180°] and drew them 358° apart,
/// the full height of the panel).
#[test]
fn data_phase_sits_on_the_model_branch() {
    let omega: Vec<f64> = (0..60).map(|k| 10.0 * 1.05f64.powi(k)).collect();
    let at = |deg: f64| Complex64::from_polar(1.0, deg.to_radians());
    let data: Vec<Complex64> = omega.iter().map(|_| at(-179.0)).collect();
    let grid = dense_grid(&omega);
    let model: Vec<Complex64> = grid.iter().map(|_| at(179.0)).collect();
    let invalid = vec![false; omega.len()];
    let radius = vec![0.1; omega.len()];
    let svg = bode_svg(
        "phase branch",
        &BodeData {
            omega: &omega,
            g: &data,
            radius: Some(&radius),
            invalid: &invalid,
        },
        &[ModelCurve {
            name: "model".into(),
            omega: grid,
            g: model,
        }],
    )
    .unwrap();
    // The phase line is the model polyline lower on the page; the phase dots are the lower
    // of each datum's two dots.
    let lines = polylines(&svg, "#1F77B4");
    let phase_line = lines
        .iter()
        .filter(|l| l.len() > 100)
        .max_by(|a, b| a[0].1.total_cmp(&b[0].1))
        .expect("phase line");
    let line_y = phase_line[phase_line.len() / 2].1;
    let (_, legend_top, _, _) = legend_box(&svg);
    let dots: Vec<(f64, f64)> = circles(&svg, "#000000")
        .into_iter()
        .filter(|d| d.1 < legend_top)
        .collect();
    let mid = dots.iter().map(|d| d.1).sum::<f64>() / dots.len() as f64;
    let phase_dots: Vec<_> = dots.iter().filter(|d| d.1 > mid).collect();
    assert_eq!(phase_dots.len(), omega.len());
    // The panel is about 300 px for at least 90°; 2° is a few pixels, 358° is the panel.
    for d in phase_dots {
        assert!(
            (d.1 - line_y).abs() < 12.0,
            "dot at {} vs line at {line_y}",
            d.1
        );
    }
}

/// The model's phase is unwrapped: a delay of 1 ms with a pole over 1–1000 Hz (phase falling
/// by 360 000·τ·f degrees, more than 360° in all) has no jump larger than 180° between
/// neighbouring points, on the grid and on the drawn line, and the unwrapped phase equals the
/// closed form −ωτ − atan(ω/a) everywhere.
#[test]
fn model_phase_is_continuous() {
    let (tau, a) = (1e-3, 300.0);
    let omega: Vec<f64> = (0..80)
        .map(|k| std::f64::consts::TAU * 10f64.powf(3.0 * k as f64 / 79.0))
        .collect();
    let g = |w: f64| Complex64::from_polar(1.0, -w * tau) / Complex64::new(1.0, w / a);
    let grid = dense_grid(&omega);
    let gm: Vec<Complex64> = grid.iter().map(|w| g(*w)).collect();
    let ph = unwrap_deg(&gm);
    for (w, p) in grid.iter().zip(&ph) {
        let exact = -(w * tau + (w / a).atan()).to_degrees();
        assert!((p - exact).abs() < 1e-6, "ω = {w}: {p} vs {exact}");
    }
    let data: Vec<Complex64> = omega.iter().map(|w| g(*w)).collect();
    let invalid = vec![false; omega.len()];
    let svg = bode_svg(
        "delay",
        &BodeData {
            omega: &omega,
            g: &data,
            radius: None,
            invalid: &invalid,
        },
        &[ModelCurve {
            name: "model".into(),
            omega: grid.clone(),
            g: gm,
        }],
    )
    .unwrap();
    let lines = polylines(&svg, "#1F77B4");
    let line = lines
        .iter()
        .filter(|l| l.len() > 100)
        .max_by(|a, b| a.last().unwrap().1.total_cmp(&b.last().unwrap().1))
        .expect("phase line");
    let total_deg = ph[0] - ph[ph.len() - 1];
    assert!(total_deg > 360.0);
    let px_per_deg = (line.last().unwrap().1 - line[0].1) / total_deg;
    assert!(px_per_deg > 0.0);
    for w in line.windows(2) {
        assert!((w[1].1 - w[0].1).abs() < 180.0 * px_per_deg, "{w:?}");
    }
}

/// `history --svg` on the motor bench with experiments A and B: each figure's title names
/// the model and its data (the two differ), each revision is labelled by the effect it added
/// (mode with its frequency, friction, delay), none as `rev k`, and no labels overlap.
#[test]
fn history_figure_names_model_data_and_effects() {
    let dir = tempfile::tempdir().unwrap();
    let configs: Vec<String> = [
        "twomass_rigid",
        "twomass_rev1",
        "twomass_rev2",
        "twomass_rev3",
    ]
    .iter()
    .map(|c| repo(&format!("configs/{c}.toml")).display().to_string())
    .collect();
    let b = repo("configs/data/twomass/frf_multisineB.csv")
        .display()
        .to_string();
    let mut titles = Vec::new();
    for extra in [vec![], vec!["--data", b.as_str()]] {
        let mut args = vec!["history"];
        args.extend(configs.iter().map(|s| s.as_str()));
        args.extend(extra);
        let svg = run_svg(&args, &dir.path().join("h.svg"));
        assert_no_overlap(&svg, "history");
        let ls = labels(&svg);
        let texts: Vec<&str> = ls.iter().map(|l| l.text.as_str()).collect();
        let title = ls
            .iter()
            .min_by(|a, b| a.y.total_cmp(&b.y))
            .unwrap()
            .text
            .clone();
        assert!(title.contains("twomass motor side"), "{title}");
        assert!(!title.contains("error vs revision"), "{title}");
        for want in ["rigid body", "+ mode 76.2", "+ friction", "+ delay 0.11"] {
            assert!(
                texts.iter().any(|t| t.starts_with(want)),
                "no label {want:?} in {texts:?}"
            );
        }
        assert!(!texts.iter().any(|t| t.starts_with("rev ")), "{texts:?}");
        titles.push(title);
    }
    assert!(titles[0].contains("frf_multisineA"), "{}", titles[0]);
    assert!(titles[1].contains("frf_multisineB"), "{}", titles[1]);
}

/// The revision labels read from the headers `diagnose --write` writes: one effect, an effect
/// whose label holds parentheses, `--apply chosen` with several effects and a retune.
#[test]
fn revision_labels_from_headers() {
    let one = "# Revised by `rshape diagnose a.toml --apply 1`: mode (omega_n = 478.9, rho = 100.2, zeta = 0.01987), every parameter refit jointly.\nname = \"x, rev 0: rigid body + mode\"\n";
    assert_eq!(revision_label(one, "a"), "+ mode 76.22 Hz");
    let delay = "# Revised by `rshape diagnose b.toml --apply 1`: delay (output 2) (tau_s = 2.309e-4), every parameter refit jointly.\n";
    assert_eq!(revision_label(delay, "b"), "+ delay (output 2) 0.2309 ms");
    let chosen = "# Revised by `rshape diagnose m.toml --apply chosen`: mode + mode (mode: omega_n = 5654, rho = 1.1, zeta = 0.001; mode: omega_n = 5090, rho = 0.35, zeta = 0.0014; retuned: rigid_body[1].mass -0.83 → -0.91 (σ 4.6e-4)), every parameter refit jointly.\n";
    assert_eq!(
        revision_label(chosen, "m"),
        "+ mode 899.9 Hz, mode 810.1 Hz"
    );
    let plain = "# a hand-written model\nname = \"twomass motor side, rev 0: rigid body\"\n";
    assert_eq!(revision_label(plain, "s"), "rigid body");
    assert_eq!(revision_label("[physical]\n", "stem"), "stem");
}

/// On a narrow band (700–1300 Hz, less than a decade: the old figure printed
/// `800.900.01000.0`) the frequency labels are several, readable and apart.
#[test]
fn narrow_band_ticks_do_not_collide() {
    let omega: Vec<f64> = (0..=600)
        .map(|k| std::f64::consts::TAU * (700.0 + k as f64))
        .collect();
    let g: Vec<Complex64> = omega
        .iter()
        .map(|w| Complex64::new(1.0, 0.0) / Complex64::new(5654f64.powi(2) - w * w, 0.01 * w))
        .collect();
    let invalid = vec![false; omega.len()];
    let grid = dense_grid(&omega);
    let gm = grid
        .iter()
        .map(|w| Complex64::new(1.0, 0.0) / Complex64::new(5654f64.powi(2) - w * w, 0.02 * w))
        .collect();
    let svg = bode_svg(
        "narrow",
        &BodeData {
            omega: &omega,
            g: &g,
            radius: None,
            invalid: &invalid,
        },
        &[ModelCurve {
            name: "model".into(),
            omega: grid,
            g: gm,
        }],
    )
    .unwrap();
    assert_no_overlap(&svg, "narrow band");
    let ticks: Vec<f64> = labels(&svg)
        .iter()
        .filter(|l| l.anchor == "middle")
        .filter_map(|l| l.text.parse::<f64>().ok())
        .filter(|v| (600.0..1500.0).contains(v))
        .collect();
    assert!(ticks.len() >= 3, "frequency labels {ticks:?}");
}
