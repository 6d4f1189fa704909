//! Reader of FRF CSV files.
//!
//! Format: a header, then one row per frequency.  The first column is `omega_rad_s` or
//! `freq_hz` (Hz is converted to rad/s).  Each output `i` and input `j` (1-based) is given as
//! `re_i_j,im_i_j` or `mag_i_j,phase_deg_i_j`.  An optional `noise_radius` column gives a
//! per-frequency noise radius.  Lines starting with `#` are comments.

use super::frf::FrfData;
use super::table::TableReader;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::collections::HashMap;
use std::path::Path;

#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, Default)]
enum Part {
    #[default]
    Re,
    Im,
    Mag,
    PhaseDeg,
}

/// Reads an FRF CSV file; every error names the file and the line.  The file is streamed
/// (never held whole in memory).
pub fn read_frf_csv(path: &Path) -> Result<FrfData> {
    let mut rows = FrfRows::open(path)?;
    let mut data = Vec::new();
    while let Some(d) = rows.next_datum()? {
        data.push(d);
    }
    rows.finish(data)
}

/// Parses FRF CSV text; `path` is used in messages.
pub fn parse_frf_csv(text: &str, path: &Path) -> Result<FrfData> {
    let mut rows = FrfRows {
        table: TableReader::new(text.as_bytes(), path, HEADER)?,
        layout: Layout::default(),
        sample_time: None,
    };
    rows.layout = Layout::of(&rows.table)?;
    let mut data = Vec::new();
    while let Some(d) = rows.next_datum()? {
        data.push(d);
    }
    rows.finish(data)
}

const HEADER: &str = "freq_hz,re_1_1,im_1_1";

/// Largest output or input index of a column name (`re_i_j`): far beyond any measured FRF,
/// small enough that `p·m` can never overflow.
pub const MAX_CHANNEL: usize = 10_000;

/// One row of an FRF file: `(omega, Φ, noise radius, line)`.
pub type Datum = (f64, DMatrix<Complex64>, Option<f64>, usize);

/// Where each entry of `Φ` is in a row.
#[derive(Default)]
struct Layout {
    hz: bool,
    p: usize,
    m: usize,
    /// `(representation, column a, column b)` of entry `(i, j)` at `i·m + j`.
    entries: Vec<(Part, usize, usize)>,
    noise_col: Option<usize>,
}

/// A streaming reader of an FRF CSV file: one datum at a time, in file order, for inputs
/// too large to hold (the `envelope` of 1e6 frequencies).  Every error names the file and
/// the line.
pub struct FrfRows<'r> {
    table: TableReader<'r>,
    layout: Layout,
    /// `Some(Ts)`: the frequency column is normalized (per sample), divided by `Ts`.
    sample_time: Option<f64>,
}

impl FrfRows<'static> {
    /// Opens `path` and reads its header.
    pub fn open(path: &Path) -> Result<Self> {
        let table = TableReader::open(path, HEADER)?;
        let layout = Layout::of(&table)?;
        Ok(Self {
            table,
            layout,
            sample_time: None,
        })
    }
}

impl FrfRows<'_> {
    /// Reads the frequency column as normalized (cycles or radians per sample) and divides
    /// it by `ts` seconds (the config's `sample_time`, [`crate::data::denormalize_frf`]); `None` keeps
    /// the column's unit.
    pub fn with_sample_time(mut self, ts: Option<f64>) -> Self {
        self.sample_time = ts;
        self
    }

    /// Number of outputs `p` and inputs `m` of the data.
    pub fn size(&self) -> (usize, usize) {
        (self.layout.p, self.layout.m)
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        self.table.path()
    }

    /// An error on the header line.
    pub fn err_at_header(&self, msg: String) -> crate::error::Error {
        self.table.err(self.table.header_line, msg)
    }

    /// Whether the file has a `noise_radius` column.
    pub fn has_noise_column(&self) -> bool {
        self.layout.noise_col.is_some()
    }

    /// The next datum in file order, `None` at the end.
    pub fn next_datum(&mut self) -> Result<Option<Datum>> {
        let Some(line) = self.table.next_row()? else {
            return Ok(None);
        };
        let (t, l) = (&self.table, &self.layout);
        let err = |msg: String| t.err(line, msg);
        let num = |col: usize| -> Result<f64> {
            let (name, field) = (&t.names[col], t.field(col));
            let v: f64 = field.parse().map_err(|_| {
                err(format!(
                    "column `{}`: `{}` is not a number{}",
                    crate::util::echo(name),
                    crate::util::echo(field),
                    super::table::decimal_hint(field)
                ))
            })?;
            if !v.is_finite() {
                return Err(err(format!(
                    "column `{}`: value `{}` is not finite",
                    crate::util::echo(name),
                    crate::util::echo(field)
                )));
            }
            Ok(v)
        };
        let f = num(0)?;
        if f <= 0.0 {
            return Err(err(format!("frequency {f} must be positive")));
        }
        let omega = if l.hz {
            2.0 * std::f64::consts::PI * f
        } else {
            f
        };
        if !omega.is_finite() {
            return Err(err(format!(
                "frequency {f:e} Hz overflows in rad/s (2π·f is beyond the largest number): is the column in Hz?"
            )));
        }
        let omega = match self.sample_time {
            Some(ts) => super::sample_time::denormalize(omega, ts, t.path(), line)?,
            None => omega,
        };
        let mut phi = DMatrix::zeros(l.p, l.m);
        for i in 0..l.p {
            for j in 0..l.m {
                let (kind, a, b) = l.entries[i * l.m + j];
                let (x, y) = (num(a)?, num(b)?);
                phi[(i, j)] = match kind {
                    Part::Re => Complex64::new(x, y),
                    _ => {
                        if x < 0.0 {
                            return Err(err(format!(
                                "column `{}`: magnitude {x} is negative",
                                t.names[a]
                            )));
                        }
                        Complex64::from_polar(x, y.to_radians())
                    }
                };
            }
        }
        let noise = match l.noise_col {
            Some(c) => {
                let v = num(c)?;
                if v < 0.0 {
                    return Err(err(format!("noise_radius {v} is negative")));
                }
                Some(v)
            }
            None => None,
        };
        Ok(Some((omega, phi, noise, line)))
    }

    /// The data set of the rows read: sorted by frequency, duplicates refused.
    pub fn finish(self, mut data: Vec<Datum>) -> Result<FrfData> {
        let t = &self.table;
        if data.is_empty() {
            return Err(self.err_at_header("no data rows after the header".into()));
        }
        data.sort_by(|a, b| a.0.total_cmp(&b.0));
        check_distinct(data.len(), |k| (data[k].0, data[k].3))
            .map_err(|(line, msg)| t.err(line, msg))?;
        Ok(FrfData {
            path: t.path().to_path_buf(),
            omega: data.iter().map(|d| d.0).collect(),
            noise_radius: (self.layout.noise_col)
                .map(|_| data.iter().map(|d| d.2.unwrap_or(0.0)).collect()),
            lines: data.iter().map(|d| d.3).collect(),
            response: data.into_iter().map(|d| d.1).collect(),
        })
    }
}

/// Refuses two data closer than a relative 1e-12 in frequency; `key(k)` is the
/// `(frequency, line)` of the `k`-th of `n` data sorted by frequency.  `Err((line, message))`.
pub fn check_distinct(
    n: usize,
    key: impl Fn(usize) -> (f64, usize),
) -> std::result::Result<(), (usize, String)> {
    for k in 1..n {
        let ((w0, l0), (w1, l1)) = (key(k - 1), key(k));
        if w1 <= w0 * (1.0 + 1e-12) {
            return Err((
                l1.max(l0),
                format!(
                    "duplicate frequency {w1} rad/s (also on line {}): each frequency must appear once",
                    l1.min(l0)
                ),
            ));
        }
    }
    Ok(())
}

impl Layout {
    /// The layout named by the header; a missing or unknown column is an error on its line.
    fn of(table: &TableReader) -> Result<Self> {
        let (hline, names) = (table.header_line, &table.names);
        let err = |msg: String| table.err(hline, msg);
        let hz = table.first_column_is_hz()?;
        let mut cells: HashMap<(usize, usize, Part), usize> = HashMap::new();
        let mut noise_col = None;
        let (mut p, mut m) = (0, 0);
        for (col, name) in names.iter().enumerate().skip(1) {
            if name == "omega_rad_s" || name == "freq_hz" {
                return Err(err(format!(
                    "column `{name}` besides `{}`: keep one frequency column, first",
                    names[0]
                )));
            }
            if name == "noise_radius" {
                if noise_col.replace(col).is_some() {
                    return Err(err(format!("column `{name}` appears twice")));
                }
                continue;
            }
            let parsed = parse_column(name).ok_or_else(|| {
                err(format!("unknown column `{}`: expected re_i_j, im_i_j, mag_i_j, phase_deg_i_j or noise_radius (i, j ≤ {MAX_CHANNEL})", crate::util::echo(name)))
            })?;
            if cells.insert(parsed, col).is_some() {
                return Err(err(format!(
                    "column `{}` appears twice",
                    crate::util::echo(name)
                )));
            }
            p = p.max(parsed.0);
            m = m.max(parsed.1);
        }
        if p == 0 {
            return Err(err(
                "no response columns: add re_1_1,im_1_1 (or mag_1_1,phase_deg_1_1)".into(),
            ));
        }
        // Every (i, j) needs one complete representation.
        // Sized by the columns present, never by the indices named: a header naming
        // re_100000_100000 fails at its first missing column below, which comes within
        // `cells.len() + 1` entries.
        let mut entries = Vec::with_capacity((p * m).min(cells.len()));
        for i in 1..=p {
            for j in 1..=m {
                let get = |part| cells.get(&(i, j, part));
                let re = (get(Part::Re), get(Part::Im));
                let mp = (get(Part::Mag), get(Part::PhaseDeg));
                entries.push(match (re, mp) {
                    ((Some(a), Some(b)), (None, None)) => (Part::Re, *a, *b),
                    ((None, None), (Some(a), Some(b))) => (Part::Mag, *a, *b),
                    ((Some(_), None), _) => return Err(err(format!("missing column im_{i}_{j}"))),
                    ((None, Some(_)), _) => return Err(err(format!("missing column re_{i}_{j}"))),
                    (_, (Some(_), None)) => {
                        return Err(err(format!("missing column phase_deg_{i}_{j}")))
                    }
                    (_, (None, Some(_))) => return Err(err(format!("missing column mag_{i}_{j}"))),
                    ((None, None), (None, None)) => {
                        return Err(err(format!(
                            "missing columns re_{i}_{j},im_{i}_{j} (the data are {p}×{m})"
                        )))
                    }
                    _ => {
                        return Err(err(format!(
                            "entry ({i},{j}) is given both as re/im and as mag/phase: keep one"
                        )))
                    }
                });
            }
        }
        Ok(Self {
            hz,
            p,
            m,
            entries,
            noise_col,
        })
    }
}

fn parse_column(name: &str) -> Option<(usize, usize, Part)> {
    let (part, rest) = if let Some(r) = name.strip_prefix("re_") {
        (Part::Re, r)
    } else if let Some(r) = name.strip_prefix("im_") {
        (Part::Im, r)
    } else if let Some(r) = name.strip_prefix("mag_") {
        (Part::Mag, r)
    } else if let Some(r) = name.strip_prefix("phase_deg_") {
        (Part::PhaseDeg, r)
    } else {
        return None;
    };
    let (i, j) = rest.split_once('_')?;
    let (i, j): (usize, usize) = (i.parse().ok()?, j.parse().ok()?);
    ((1..=MAX_CHANNEL).contains(&i) && (1..=MAX_CHANNEL).contains(&j)).then_some((i, j, part))
}
