//! Per-frequency noise files of a config: `[noise] std_file` and `[noise] coherence` (the H1
//! random error), read on the data's frequency axis.

use super::{NoiseSource, ResolvedNoise};
use crate::data::std_file::{h1_random_error, read_coherence_csv, read_std_csv};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::Config;

/// A std or coherence file on the config's frequency axis (its `sample_time`).
fn on_axis(
    cfg: &Config,
    f: crate::data::StdData,
    path: &std::path::Path,
) -> Result<crate::data::StdData> {
    match cfg.sample_time() {
        Some(ts) => crate::data::denormalize_std(f, ts, path),
        None => Ok(f),
    }
}

/// The radii of a config's `[noise] std_file` for the data: the file belongs to the config's
/// own data; for other data (`--data`) `<data stem>_std.csv` beside them is used.
pub(super) fn std_file_noise(
    cfg: &Config,
    data: &FrfData,
    (out, inp): (usize, usize),
) -> Result<ResolvedNoise> {
    let Some((file, k)) = &cfg.noise_std else {
        return Err(Error::Invalid("no [noise] std_file in the config".into()));
    };
    let file = file_for_data(cfg, data, file, "std", "std_file")?;
    let std = on_axis(cfg, read_std_csv(&file)?, &file)?;
    let radii = std.radius_at(&file, &data.omega, out, inp, *k)?;
    Ok(ResolvedNoise {
        description: format!("{k} × std_{out}_{inp} of {}", file.display()),
        radii,
        source: NoiseSource::ConfigStdFile,
    })
}

/// The radii of a config's `[noise] coherence`: `coverage·ε·|H|` per datum, with the H1
/// random error `ε` of [`h1_random_error`] (Bendat & Piersol, *Random Data*, Table 9.6).
pub(super) fn coherence_noise(
    cfg: &Config,
    data: &FrfData,
    (out, inp): (usize, usize),
) -> Result<ResolvedNoise> {
    let sec = &cfg.raw.noise;
    let (Some(file), Some(n)) = (&sec.coherence, sec.averages) else {
        return Err(Error::Invalid(
            "[noise] coherence needs averages = n".into(),
        ));
    };
    let n = u32::try_from(n).unwrap_or(1);
    let k = sec.coverage.unwrap_or(3.0);
    let base = cfg.path.parent().unwrap_or(std::path::Path::new("."));
    let file = file_for_data(cfg, data, &base.join(file), "coherence", "coherence")?;
    let gamma2 = on_axis(cfg, read_coherence_csv(&file)?, &file)?.values_at(
        &file,
        "coh",
        &data.omega,
        out,
        inp,
    )?;
    // SISO data are the channel already; MIMO data hold it at (out, inp).
    let at = if data.outputs() == 1 && data.inputs() == 1 {
        (0, 0)
    } else if (1..=data.outputs()).contains(&out) && (1..=data.inputs()).contains(&inp) {
        (out - 1, inp - 1)
    } else {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "channel ({out}, {inp}) of [noise] coherence is not in the {}×{} data",
                data.outputs(),
                data.inputs(),
            ),
        });
    };
    let radii = gamma2
        .iter()
        .zip(&data.response)
        .map(|(&g2, h)| k * h1_random_error(g2, n) * h[at].norm())
        .collect();
    Ok(ResolvedNoise {
        description: format!(
            "{k} × ε·|H|, ε = √(1 − γ²)/(|γ|√(2·{n})) from coh_{out}_{inp} of {}",
            file.display()
        ),
        radii,
        source: NoiseSource::ConfigCoherence,
    })
}

/// The file of a per-frequency noise source for `data`: the config's own `file` when the
/// data are the config's data, else `<data stem>_<suffix>.csv` beside the data.
fn file_for_data(
    cfg: &Config,
    data: &FrfData,
    file: &std::path::Path,
    suffix: &str,
    key: &str,
) -> Result<std::path::PathBuf> {
    let own = cfg.data.as_ref().is_some_and(|d| {
        d == &data.path
            || d.canonicalize()
                .ok()
                .is_some_and(|a| Some(a) == data.path.canonicalize().ok())
    });
    Ok(if own {
        file.to_path_buf()
    } else {
        let stem = data
            .path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let sib = data.path.with_file_name(format!("{stem}_{suffix}.csv"));
        if !sib.exists() {
            return Err(Error::Input {
                path: data.path.to_path_buf(),
                msg: format!(
                    "the config's [noise] {key} belongs to its own data; put {} beside these data or pass --noise-radius",
                    sib.display(),
                ),
            });
        }
        sib
    })
}
