//! The figure of `rshape history --svg`: `misfit_rms` and `invalid_fraction` after each
//! model revision, each revision labelled by the effect it added, titled by the model and the
//! data it is evaluated on.  Written atomically.

use crate::error::Result;
use crate::plot::style::{
    draw_x_labels, plot_err, C_BLUE, C_GREEN, C_RED, FONT, TICKS, Y_LABEL_AREA,
};
use plotters::prelude::*;
use std::path::Path;

/// What a revision added, from the config text `rshape diagnose --write` produced
/// (`# Revised by `…`: mode (omega_n = 478.9, …), every parameter refit jointly.`): `+ mode
/// 76.2 Hz`, `+ delay 0.11 ms`, `+ friction (pole = 12.76, …)`.  A config not written by
/// `diagnose` is labelled by its `name` after the last `: ` (`rigid body`), else by `stem`.
pub fn revision_label(text: &str, stem: &str) -> String {
    for line in text.lines().take_while(|l| l.starts_with('#')) {
        let Some(rest) = line.strip_prefix("# Revised by `") else {
            continue;
        };
        let Some((_, rest)) = rest.split_once("`: ") else {
            continue;
        };
        let body = rest
            .split(", every parameter refit jointly")
            .next()
            .unwrap_or(rest);
        // The parameters are the last parenthesised group; the effect label may hold its
        // own "(output 2)".
        let (effect, params) = match open_of_last_group(body) {
            Some(k) => (body[..k].trim_end(), &body[k + 1..body.len() - 1]),
            None => (body, ""),
        };
        // `--apply chosen` lists each effect's parameters: `mode: omega_n = …; mode: …;
        // retuned: …`.
        let parts: Vec<String> = params
            .split("; ")
            .filter_map(|seg| {
                let (name, kv) = match seg.split_once(": ") {
                    Some((n, kv)) if !n.contains('=') => (n, kv),
                    _ => (effect, seg),
                };
                (!name.starts_with("retuned")).then(|| format!("{name}{}", detail(kv)))
            })
            .collect();
        return if parts.is_empty() {
            format!("+ {effect}")
        } else {
            format!("+ {}", parts.join(", "))
        };
    }
    let name = text.lines().find_map(|l| {
        let v = l
            .trim()
            .strip_prefix("name")?
            .trim_start()
            .strip_prefix('=')?;
        Some(v.trim().trim_matches('"').to_string())
    });
    match name {
        Some(n) => n.rsplit(": ").next().unwrap_or(&n).to_string(),
        None => stem.to_string(),
    }
}

/// The byte index of the `(` matching the `)` that ends `s`, if `s` ends with one.
fn open_of_last_group(s: &str) -> Option<usize> {
    if !s.ends_with(')') {
        return None;
    }
    let mut depth = 0i32;
    for (k, c) in s.char_indices().rev() {
        match c {
            ')' => depth += 1,
            '(' => {
                depth -= 1;
                if depth == 0 {
                    return Some(k);
                }
            }
            _ => {}
        }
    }
    None
}

/// The short form of an effect's parameters `omega_n = 478.9, rho = …`: ` 76.22 Hz` for a
/// mode, ` 0.1115 ms` for a delay, ` (pole 12.76 rad/s)` for friction, else nothing.
fn detail(params: &str) -> String {
    let value = |key: &str| -> Option<f64> {
        params.split(", ").find_map(|kv| {
            kv.trim()
                .strip_prefix(key)?
                .strip_prefix(" = ")?
                .parse()
                .ok()
        })
    };
    if let Some(w) = value("omega_n") {
        format!(" {} Hz", sig4(w / std::f64::consts::TAU))
    } else if let Some(t) = value("tau_s") {
        format!(" {} ms", sig4(t * 1e3))
    } else if let Some(p) = value("pole") {
        format!(" (pole {p} rad/s)")
    } else {
        String::new()
    }
}

/// Four significant digits, trailing zeros dropped: `76.2193` → `76.22`, `0.1115` → `0.1115`.
fn sig4(v: f64) -> String {
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The model's name without its revision history (`twomass motor side, rev 0: rigid body + …`
/// → `twomass motor side`), from the config text; `stem` without a name.
pub fn model_name(text: &str, stem: &str) -> String {
    let name = text.lines().find_map(|l| {
        let v = l
            .trim()
            .strip_prefix("name")?
            .trim_start()
            .strip_prefix('=')?;
        Some(v.trim().trim_matches('"').to_string())
    });
    match name {
        Some(n) => n
            .split(", rev")
            .next()
            .and_then(|s| s.split(": ").next())
            .unwrap_or(&n)
            .to_string(),
        None => stem.to_string(),
    }
}

/// The history figure as an SVG document.  `labels[k]` names revision `k` by what it added;
/// `invalid_fraction` is NaN where the noise is unknown.
pub fn history_svg(
    title: &str,
    labels: &[String],
    misfit_rms: &[f64],
    invalid_fraction: &[f64],
) -> Result<String> {
    let n = labels.len().max(1);
    let xr = -0.5..(n as f64 - 0.5);
    let lo = misfit_rms
        .iter()
        .cloned()
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min)
        .clamp(1e-6, 1.0)
        / 1.5;
    // Up to the next power of ten, so the top of the axis carries a label.
    let hi = 10f64.powf(
        (misfit_rms.iter().cloned().fold(1.0, f64::max) * 1.2)
            .log10()
            .ceil(),
    );
    let (w, caption_h, panel, x_area) = (960u32, 40u32, 270u32, 80u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, caption_h + 2 * panel + x_area))
            .into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let center_top = || {
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            )
        };
        root.draw(&Text::new(
            title.to_string(),
            (w as i32 / 2, 12),
            TextStyle::from((FONT, 20).into_font()).pos(center_top()),
        ))
        .map_err(plot_err)?;
        let (_, rest) = root.split_vertically(caption_h);
        let (top, bottom) = rest.split_vertically(panel);
        let mut a = ChartBuilder::on(&top)
            .margin_left(14)
            .margin_right(24)
            .margin_top(4)
            .x_label_area_size(6)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xr.clone(), crate::plot::axis::LogAxis::new(lo, hi))
            .map_err(plot_err)?;
        a.configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .x_label_formatter(&|_| String::new())
            .y_desc("misfit_rms (log)")
            .axis_desc_style((FONT, 17))
            .label_style((FONT, TICKS))
            .y_label_formatter(&crate::plot::axis::log_label)
            .draw()
            .map_err(plot_err)?;
        let mut b = ChartBuilder::on(&bottom)
            .margin_left(14)
            .margin_right(24)
            .margin_top(10)
            .x_label_area_size(x_area)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xr.clone(), 0.0..100.0)
            .map_err(plot_err)?;
        b.configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .x_label_formatter(&|_| String::new())
            .y_label_formatter(&|v| format!("{v:.0}"))
            .max_light_lines(1)
            .y_desc("invalid data (%)")
            .axis_desc_style((FONT, 17))
            .label_style((FONT, TICKS))
            .draw()
            .map_err(plot_err)?;
        let above = || {
            TextStyle::from((FONT, 13).into_font()).color(&C_RED).pos(
                plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Left,
                    plotters::style::text_anchor::VPos::Bottom,
                ),
            )
        };
        let lim = |c: RGBColor| ShapeStyle::from(&c.mix(0.8)).stroke_width(1);
        // A dashed reference level with its note just above it, on either panel (a macro:
        // the two panels' chart types differ in their y coordinate).
        macro_rules! reference {
            ($area:expr, $y:expr, $note:expr) => {
                $area
                    .draw_series(DashedLineSeries::new(
                        vec![(xr.start, $y), (xr.end, $y)],
                        8,
                        5,
                        lim(C_RED),
                    ))
                    .map_err(plot_err)?;
                $area
                    .draw_series(std::iter::once(Text::new(
                        $note,
                        (xr.start + 0.02, $y),
                        above(),
                    )))
                    .map_err(plot_err)?;
            };
        }
        reference!(a, 1.0, "within the noise below this line (misfit_rms = 1)");
        reference!(b, 5.0, "consistent below 5 %");
        let pts = |v: &[f64], scale: f64| -> Vec<(f64, f64)> {
            v.iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(k, v)| (k as f64, v * scale))
                .collect()
        };
        let rms = pts(misfit_rms, 1.0);
        a.draw_series(LineSeries::new(rms.clone(), C_BLUE.stroke_width(2)))
            .map_err(plot_err)?;
        a.draw_series(rms.iter().map(|q| Circle::new(*q, 5, C_BLUE.filled())))
            .map_err(plot_err)?;
        let inv = pts(invalid_fraction, 100.0);
        b.draw_series(LineSeries::new(inv.clone(), C_GREEN.stroke_width(2)))
            .map_err(plot_err)?;
        b.draw_series(inv.iter().map(|q| Circle::new(*q, 5, C_GREEN.filled())))
            .map_err(plot_err)?;
        let ticks: Vec<(i32, String)> = labels
            .iter()
            .enumerate()
            .map(|(k, l)| (b.backend_coord(&(k as f64, 0.0)).0, l.clone()))
            .collect();
        let (_, y_axis) = b.backend_coord(&(0.0, 0.0));
        draw_x_labels(&root, &ticks, y_axis, TICKS)?;
        let x_mid = (b.backend_coord(&(xr.start, 0.0)).0 + b.backend_coord(&(xr.end, 0.0)).0) / 2;
        root.draw(&Text::new(
            "revision, labelled by the effect it added",
            (x_mid, y_axis + 2 * TICKS as i32 + 24),
            TextStyle::from((FONT, 16).into_font()).pos(center_top()),
        ))
        .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

/// Writes [`history_svg`] to `path` (atomically).
pub fn error_history(
    path: &Path,
    title: &str,
    labels: &[String],
    misfit_rms: &[f64],
    invalid_fraction: &[f64],
) -> Result<()> {
    let svg = history_svg(title, labels, misfit_rms, invalid_fraction).map_err(|e| {
        crate::error::Error::Input {
            path: path.to_path_buf(),
            msg: format!("cannot draw the figure: {e}"),
        }
    })?;
    crate::util::write_atomic(path, svg.as_bytes())
}
