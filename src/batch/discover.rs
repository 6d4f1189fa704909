//! Which datasets a batch processes: every `*.csv` file of a directory (sorted by name), or
//! the rows of a manifest.
//!
//! Manifest format (CSV, `#` starts a comment line, paths relative to the manifest):
//!
//! ```text
//! name,data,noise_radius
//! run01,experiments/run01.csv,0.002
//! run02,experiments/run02.csv,
//! ```
//!
//! Only `data` is required; `name` defaults to the file stem and an empty or missing
//! `noise_radius` means "as for a single run" (`--noise-radius`, the data file, the config).

use crate::data::table::TableReader;
use crate::error::{Error, Result};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One dataset of a batch.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// Position in the full (unsharded) list, 0-based: the output order.
    pub index: usize,
    /// Unique name, safe as a directory name.
    pub name: String,
    /// The FRF CSV file.
    pub path: PathBuf,
    /// Noise radius for this dataset (manifest), overriding the run-wide one.
    pub noise_radius: Option<f64>,
}

/// A name made safe for a directory: characters other than `A-Za-z0-9._-` become `_`.
pub fn safe_name(s: &str) -> String {
    let n: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if n.is_empty() || n.starts_with('.') {
        format!("_{n}")
    } else {
        n
    }
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or("dataset".into(), |s| s.to_string_lossy().into_owned())
}

/// Whether `stem` is `<other>_std` or `<other>_coherence` with `<other>` among `stems`.
fn is_noise_sibling(stem: &str, stems: &std::collections::HashSet<String>) -> bool {
    ["_std", "_coherence"].iter().any(|suffix| {
        stem.strip_suffix(suffix)
            .is_some_and(|base| stems.contains(base))
    })
}

/// Every `*.csv` file in `dir` (not recursive), sorted by file name, except the noise files
/// of another (`<stem>_std.csv`, `<stem>_coherence.csv` beside `<stem>.csv`).
pub fn discover_dir(dir: &Path) -> Result<Vec<Dataset>> {
    let rd = std::fs::read_dir(dir).map_err(|source| Error::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut paths: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        // Every *.csv entry but folders: a FIFO or a device named *.csv becomes a failed
        // dataset (the reader refuses it), never a silently smaller batch.
        .filter(|p| !p.is_dir() && p.extension().is_some_and(|x| x.eq_ignore_ascii_case("csv")))
        .collect();
    paths.sort();
    // The noise files of a dataset (`<stem>_std.csv`, `<stem>_coherence.csv` beside
    // `<stem>.csv`, which a config's [noise] finds for each dataset) are not datasets.
    let csvs: std::collections::HashSet<String> = paths.iter().map(|p| stem(p)).collect();
    paths.retain(|p| !is_noise_sibling(&stem(p), &csvs));
    if paths.is_empty() {
        return Err(Error::Input {
            path: dir.to_path_buf(),
            msg: "no *.csv dataset in this directory".into(),
        });
    }
    let list = paths
        .into_iter()
        .enumerate()
        .map(|(index, path)| Dataset {
            index,
            name: safe_name(&stem(&path)),
            noise_radius: None,
            path,
        })
        .collect();
    unique(list)
}

/// The datasets listed in a manifest (see the module doc for the format).
pub fn discover_manifest(file: &Path) -> Result<Vec<Dataset>> {
    let base = file.parent().unwrap_or(Path::new("."));
    let err = |line: usize, msg: String| Error::Data {
        path: file.to_path_buf(),
        line,
        msg,
    };
    // The csv crate's parser (quotes, BOM, CRLF), as for every CSV input.
    let mut table = TableReader::open(file, "name,data,noise_radius")?;
    let (hl, cols) = (table.header_line, table.names.clone());
    let header = cols.join(",");
    let col = |n: &str| cols.iter().position(|c| c == n);
    let data_col = col("data").ok_or_else(|| {
        err(hl, format!("header `{header}` has no `data` column; expected `name,data,noise_radius` (name and noise_radius optional)"))
    })?;
    if let Some(bad) = cols
        .iter()
        .find(|c| !["name", "data", "noise_radius"].contains(&c.as_str()))
    {
        return Err(err(
            hl,
            format!("unknown column `{bad}`; the columns are name, data, noise_radius"),
        ));
    }
    let (name_col, noise_col) = (col("name"), col("noise_radius"));
    let mut list = Vec::new();
    while let Some(line) = table.next_row()? {
        let f: Vec<&str> = table.fields().collect();
        let get = |c: Option<usize>| {
            c.and_then(|c| f.get(c))
                .map(|s| s.trim())
                .filter(|s| !s.is_empty())
        };
        let data = get(Some(data_col)).ok_or_else(|| {
            err(
                line,
                "empty `data` field: give the path of an FRF CSV file".into(),
            )
        })?;
        let path = base.join(data);
        let noise_radius = match get(noise_col) {
            None => None,
            Some(s) => match s.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => Some(x),
                _ => {
                    return Err(err(
                        line,
                        format!("noise_radius `{s}` is not a finite number ≥ 0"),
                    ))
                }
            },
        };
        let name = safe_name(&get(name_col).map_or_else(|| stem(&path), str::to_string));
        list.push(Dataset {
            index: list.len(),
            name,
            path,
            noise_radius,
        });
    }
    if list.is_empty() {
        return Err(err(hl, "the manifest lists no dataset".into()));
    }
    unique(list)
}

fn unique(list: Vec<Dataset>) -> Result<Vec<Dataset>> {
    let mut seen = BTreeSet::new();
    for d in &list {
        if !seen.insert(d.name.clone()) {
            return Err(Error::Invalid(format!(
                "two datasets are named `{}`: names must be unique (they name the output directories)",
                d.name
            )));
        }
    }
    Ok(list)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safe_names() {
        assert_eq!(safe_name("run 01/x"), "run_01_x");
        assert_eq!(safe_name(".."), "_..");
    }
}
