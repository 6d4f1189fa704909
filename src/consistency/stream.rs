//! The noise-free envelope (Theorems 2 and 3) of an FRF file read one datum at a time, for
//! inputs too large to hold as an [`FrfData`](crate::data::FrfData): per datum only
//! `(ω, r_min, A1 limit, line)` is kept (32 bytes), then sorted by frequency if needed.  The numbers
//! are those of [`noise_free_envelope`](super::noise_free_envelope) on the same file.

use super::envelope::{check_shape, Envelope, EnvelopeMethod};
use super::noise_free::{r_min_special, r_min_standard};
use crate::data::reader::{check_distinct, FrfRows};
use crate::error::{Error, Result};
use crate::model::{Factorization, FactorizationKind};

/// The noise-free envelope of the rows still unread in `rows`.  `channel` (1-based output,
/// input) selects one entry of each datum when the data do not have the model's size (the
/// config's `[channel]`).  Errors name the file and line, or the frequency of a datum where
/// an assumption fails.
pub fn noise_free_envelope_rows(
    f: &Factorization,
    mut rows: FrfRows,
    channel: Option<(usize, usize)>,
) -> Result<Envelope> {
    let path = rows.path().to_path_buf();
    let (p, m) = rows.size();
    if let Some((o, i)) = channel {
        if (p, m) != (f.outputs(), f.inputs()) {
            crate::data::check_channel(&path, (o, i), (p, m))?;
        }
    }
    let select = channel.filter(|&(o, i)| {
        (p, m) != (f.outputs(), f.inputs()) && (1..=p).contains(&o) && (1..=m).contains(&i)
    });
    let (p, m) = if select.is_some() { (1, 1) } else { (p, m) };
    check_shape(f, &path, p, m)?;
    // ω, r_min, A1 limit and line: 32 bytes per datum, kept straight in the envelope's
    // vectors (no second copy when the file is sorted, the usual case).
    let mut out = Envelope {
        omega: Vec::new(),
        r_min: Vec::new(),
        a1_limit: Some(Vec::new()),
        method: match f.kind {
            FactorizationKind::Standard => EnvelopeMethod::Theorem2,
            FactorizationKind::Special => EnvelopeMethod::Theorem3,
        },
    };
    let mut a1 = Vec::new();
    let mut lines = Vec::new();
    while let Some((omega, phi, _, line)) = rows.next_datum()? {
        let phi = match select {
            Some((o, i)) => phi.view((o - 1, i - 1), (1, 1)).into_owned(),
            None => phi,
        };
        let at = f.at(omega);
        let r = match f.kind {
            FactorizationKind::Standard => r_min_standard(&at, &phi),
            FactorizationKind::Special => r_min_special(&at, &phi),
        }
        .map_err(|e| Error::Assumption {
            omega,
            msg: format!("{} ({}:{line})", e.message(), path.display()),
        })?;
        out.omega.push(omega);
        out.r_min.push(r);
        a1.push(at.a1_limit());
        lines.push(line);
    }
    if out.omega.is_empty() {
        return Err(rows.err_at_header("no data rows after the header".into()));
    }
    if !out.omega.is_sorted_by(|a, b| a < b) {
        let mut order: Vec<usize> = (0..out.omega.len()).collect();
        order.sort_by(|&i, &j| out.omega[i].total_cmp(&out.omega[j]));
        out.omega = order.iter().map(|&k| out.omega[k]).collect();
        out.r_min = order.iter().map(|&k| out.r_min[k]).collect();
        a1 = order.iter().map(|&k| a1[k]).collect();
        lines = order.iter().map(|&k| lines[k]).collect();
    }
    check_distinct(lines.len(), |k| (out.omega[k], lines[k])).map_err(|(line, msg)| {
        Error::Data {
            path: path.clone(),
            line,
            msg,
        }
    })?;
    out.a1_limit = Some(a1);
    Ok(out)
}
