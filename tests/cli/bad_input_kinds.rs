//! The bad-input suite: every kind of bad (or merely unusual) input a user can give, across
//! the subcommands, with what rshape must answer.  For each kind: the exit code (2 for a
//! bad input, 0 where the input is accepted), a one-line message that names the file and
//! line, or the frequency, or the flag, and says what to do; never a panic; no output file
//! written or left behind on failure.  docs/guide/bad-input.md's table lists the same kinds with
//! the message each gets (`RSHAPE_BAD_INPUT_TABLE=FILE` writes the table from a run).
use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

const HEADER: &str = "omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2,re_1_3,im_1_3,re_2_1,im_2_1,re_2_2,im_2_2,re_2_3,im_2_3";

fn row(w: &str) -> String {
    format!("{w},0.5,0.1,0.8,0,-1.6,0,0,0,0.2,0.1,0.9,-0.2")
}

fn paper_data() -> String {
    format!("{HEADER}\n{}\n{}\n{}\n", row("0.1"), row("1"), row("10"))
}

fn paper_config() -> String {
    std::fs::read_to_string(common::repo("configs/paper_mimo.toml"))
        .unwrap()
        .replace("data = \"paper_mimo.csv\"", "data = \"data.csv\"")
}

/// A SISO standard factorization M̃ = (s + 2)/(s + 1), Ñ = 1/(s + 1), r = (0.1 s + 0.3)/(s + 1).
const SISO: &str = r#"data = "data.csv"
[model]
factorization = "standard"
m = [[{ num = [1, 2], den = [1, 1] }]]
n = [[{ num = [1], den = [1, 1] }]]
[r]
num = [0.1, 0.3]
den = [1, 1]
"#;

fn siso_data(extra_col: &str, extra: &[&str]) -> String {
    let mut s = format!("omega_rad_s,re_1_1,im_1_1{extra_col}\n");
    for (k, w) in ["0.1", "1", "10"].iter().enumerate() {
        s += &format!("{w},0.55,-0.1{}\n", extra.get(k).copied().unwrap_or(""));
    }
    s
}

/// One kind of input: files written into a fresh folder, a command line (`{dir}` is the
/// folder), the expected exit code and substrings of the message.
struct Kind {
    name: &'static str,
    files: Vec<(&'static str, Vec<u8>)>,
    args: Vec<String>,
    code: i32,
    needles: Vec<&'static str>,
}

fn kind(name: &'static str, code: i32, args: &str, needles: &[&'static str]) -> Kind {
    Kind {
        name,
        files: Vec::new(),
        args: args.split_whitespace().map(str::to_owned).collect(),
        code,
        needles: needles.to_vec(),
    }
}

impl Kind {
    fn file(mut self, name: &'static str, body: impl Into<Vec<u8>>) -> Self {
        self.files.push((name, body.into()));
        self
    }
    fn config(self, body: impl Into<Vec<u8>>) -> Self {
        self.file("model.toml", body)
    }
    fn data(self, body: impl Into<Vec<u8>>) -> Self {
        self.file("data.csv", body)
    }
}

const ENV: &str = "envelope {dir}/model.toml --out {dir}/out";

/// The SISO config with `[noise] coherence = "coh.csv"` and `keys`, and the coherence file
/// `coh` (`freq_hz_unused`: a valid one at the data's frequencies).
fn coherence_kind(
    name: &'static str,
    code: i32,
    keys: &str,
    coh: &str,
    needles: &[&'static str],
) -> Kind {
    let coh = if coh == "freq_hz_unused" {
        "omega_rad_s,coh_1_1\n0.1,0.9\n1,0.99\n10,0.999\n"
    } else {
        coh
    };
    kind(name, code, ENV, needles)
        .config(format!("{SISO}[noise]\ncoherence = \"coh.csv\"\n{keys}\n"))
        .data(siso_data("", &[]))
        .file("coh.csv", coh.to_string())
}

fn csv_kinds() -> Vec<Kind> {
    let paper = |name, code, body: String, needles: &[&'static str]| {
        kind(name, code, ENV, needles)
            .config(paper_config())
            .data(body)
    };
    let utf16: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(paper_data().encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    let utf16_no_bom: Vec<u8> = paper_data()
        .encode_utf16()
        .flat_map(u16::to_le_bytes)
        .collect();
    vec![
        paper(
            "CSV: empty file",
            2,
            String::new(),
            &["data.csv:1", "empty file", "header"],
        ),
        paper(
            "CSV: comments only",
            2,
            "# nothing\n\n".into(),
            &["data.csv:1", "empty file"],
        ),
        paper(
            "CSV: header only",
            2,
            format!("{HEADER}\n"),
            &["data.csv:1", "no data rows"],
        ),
        paper(
            "CSV: UTF-8 byte-order mark",
            0,
            format!("\u{FEFF}{}", paper_data()),
            &[],
        ),
        paper(
            "CSV: CRLF line ends",
            0,
            paper_data().replace('\n', "\r\n"),
            &[],
        ),
        paper(
            "CSV: `;` separators",
            0,
            paper_data().replace(',', ";"),
            &[],
        ),
        paper(
            "CSV: `;` separators with decimal commas",
            2,
            paper_data().replace(',', ";").replace('.', ","),
            &["data.csv:2", "not a number", "decimal point as `.`"],
        ),
        paper(
            "CSV: tab separators",
            0,
            paper_data().replace(',', "\t"),
            &[],
        ),
        paper(
            "CSV: quoted fields",
            0,
            format!(
                "\"{}\"\n{}",
                HEADER.replace(',', "\",\""),
                &paper_data()[HEADER.len() + 1..]
            ),
            &[],
        ),
        paper(
            "CSV: a field with an escaped quote",
            2,
            paper_data().replacen("0.5", "\"0\"\"5\"", 1),
            &["data.csv:2", "0\"5", "not a number"],
        ),
        paper(
            "CSV: trailing commas",
            0,
            paper_data().replace('\n', ",\n"),
            &[],
        ),
        paper(
            "CSV: an extra field in a row",
            2,
            format!("{HEADER}\n{}\n{},7\n", row("0.1"), row("1")),
            &["data.csv:3", "14 fields, the header has 13"],
        ),
        paper(
            "CSV: a missing field in a row",
            2,
            format!(
                "{HEADER}\n{}\n{}\n",
                row("0.1"),
                row("1").rsplit_once(',').unwrap().0
            ),
            &["data.csv:3", "12 fields, the header has 13"],
        ),
        paper(
            "CSV: an unknown column",
            2,
            format!("{HEADER},temp\n{},20\n", row("1")),
            &["data.csv:1", "unknown column `temp`", "expected re_i_j"],
        ),
        paper(
            "CSV: a missing column",
            2,
            format!(
                "{}\n{}\n",
                HEADER.replace(",im_2_3", ""),
                row("1").rsplit_once(',').unwrap().0
            ),
            &["data.csv:1", "missing column im_2_3"],
        ),
        paper(
            "CSV: a column twice",
            2,
            format!("{HEADER},re_1_1\n{},1\n", row("1")),
            &["data.csv:1", "column `re_1_1` appears twice"],
        ),
        paper(
            "CSV: both freq_hz and omega_rad_s",
            2,
            format!("freq_hz,{HEADER}\n0.1,{}\n", row("1")),
            &[
                "data.csv:1",
                "`omega_rad_s` besides `freq_hz`",
                "keep one frequency column",
            ],
        ),
        paper(
            "CSV: frequency column not first",
            2,
            "re_1_1,omega_rad_s\n1,2\n".to_string(),
            &[
                "data.csv:1",
                "first column is `re_1_1`",
                "omega_rad_s` or `freq_hz",
            ],
        ),
        paper(
            "CSV: unsorted rows",
            0,
            format!("{HEADER}\n{}\n{}\n{}\n", row("10"), row("0.1"), row("1")),
            &[],
        ),
        paper(
            "CSV: a single datum",
            0,
            format!("{HEADER}\n{}\n", row("1")),
            &[],
        ),
        paper(
            "CSV: duplicate frequency",
            2,
            format!("{HEADER}\n{}\n{}\n{}\n", row("0.1"), row("1"), row("0.1")),
            &["data.csv:4", "duplicate frequency 0.1", "line 2"],
        ),
        paper(
            "CSV: zero frequency",
            2,
            format!("{HEADER}\n{}\n{}\n", row("0.1"), row("0")),
            &["data.csv:3", "frequency 0 must be positive"],
        ),
        paper(
            "CSV: negative frequency",
            2,
            format!("{HEADER}\n{}\n", row("-1")),
            &["data.csv:2", "must be positive"],
        ),
        paper(
            "CSV: subnormal values",
            0,
            format!(
                "{HEADER}\n{}\n",
                row("1").replace("0.5", "5e-324").replace("0.8", "2.2e-310")
            ),
            &[],
        ),
        paper(
            "CSV: values of 1e308",
            0,
            format!(
                "{HEADER}\n{}\n",
                row("1").replace("0.5", "1e308").replace("0.9", "-1e308")
            ),
            &[],
        ),
        paper(
            "CSV: a value beyond f64 (1e309)",
            2,
            format!("{HEADER}\n{}\n", row("1").replace("0.5", "1e309")),
            &["data.csv:2", "re_1_1", "not finite"],
        ),
        paper(
            "CSV: +inf and -inf",
            2,
            format!("{HEADER}\n{}\n", row("1").replace("0.8", "-inf")),
            &["data.csv:2", "re_1_2", "`-inf` is not finite"],
        ),
        paper(
            "CSV: NaN",
            2,
            format!("# c\n{HEADER}\n{}\n", row("1").replace("-1.6", "NaN")),
            &["data.csv:3", "re_1_3", "not finite"],
        ),
        paper(
            "CSV: a non-numeric cell",
            2,
            format!("{HEADER}\n{}\n", row("1").replace("0.8", "abc")),
            &["data.csv:2", "`abc` is not a number", "re_1_2"],
        ),
        kind(
            "CSV: binary garbage (an ELF header)",
            2,
            ENV,
            &["data.csv:1", "NUL byte"],
        )
        .config(paper_config())
        .data(b"\x7fELF\x02\x01\x01\x00\x00\x00\x00\x00\x03\x00>\x00\x01\n\xff\xfe".to_vec()),
        kind("CSV: UTF-16 with a byte-order mark", 0, ENV, &[])
            .config(paper_config())
            .data(utf16),
        kind(
            "CSV: UTF-16 without a byte-order mark",
            2,
            ENV,
            &["data.csv:1", "NUL byte", "UTF-8"],
        )
        .config(paper_config())
        .data(utf16_no_bom),
        kind(
            "CSV: invalid UTF-8 bytes",
            2,
            ENV,
            &["data.csv:5", "not UTF-8 text", "save it as UTF-8"],
        )
        .config(paper_config())
        .data([paper_data().as_bytes(), b"\x80\xff,1\n"].concat()),
        kind(
            "CSV: a negative magnitude",
            2,
            ENV,
            &["data.csv:2", "mag_1_1", "magnitude -2 is negative"],
        )
        .config(SISO)
        .data("omega_rad_s,mag_1_1,phase_deg_1_1\n1,-2,30\n"),
        kind(
            "CSV: a negative noise radius",
            2,
            ENV,
            &["data.csv:3", "noise_radius -0.1 is negative"],
        )
        .config(SISO)
        .data(siso_data(",noise_radius", &[",0.1", ",-0.1", ",0.1"])),
        kind(
            "CSV: a NaN noise radius",
            2,
            ENV,
            &["data.csv:2", "noise_radius", "not finite"],
        )
        .config(SISO)
        .data(siso_data(",noise_radius", &[",nan", ",0.1", ",0.1"])),
        kind("CSV: a noise radius larger than |G|", 0, ENV, &[])
            .config(SISO)
            .data(siso_data(",noise_radius", &[",10", ",10", ",10"])),
        coherence_kind(
            "noise: coherence file, valid",
            0,
            "averages = 5",
            "freq_hz_unused",
            &[],
        ),
        coherence_kind(
            "noise: a coherence above 1",
            2,
            "averages = 5",
            "omega_rad_s,coh_1_1\n0.1,0.9\n1,1.2\n10,0.9\n",
            &["coh.csv:3", "coh_1_1", "not a coherence in (0, 1]"],
        ),
        coherence_kind(
            "noise: a coherence of 0",
            2,
            "averages = 5",
            "omega_rad_s,coh_1_1\n0.1,0\n1,0.9\n10,0.9\n",
            &["coh.csv:2", "not a coherence in (0, 1]"],
        ),
        coherence_kind(
            "noise: coherence at other frequencies than the data",
            2,
            "averages = 5",
            "omega_rad_s,coh_1_1\n0.1,0.9\n2,0.9\n10,0.9\n",
            &["coh.csv", "omega = 1 rad/s", "must match the FRF file"],
        ),
        coherence_kind(
            "noise: coherence without averages",
            2,
            "coverage = 3",
            "freq_hz_unused",
            &["model.toml", "needs averages"],
        ),
        coherence_kind(
            "noise: averages = 0",
            2,
            "averages = 0",
            "freq_hz_unused",
            &["model.toml", "averages = 0", "integer ≥ 1"],
        ),
        coherence_kind(
            "noise: coverage = -1",
            2,
            "averages = 5\ncoverage = -1",
            "freq_hz_unused",
            &["model.toml", "coverage = -1", "> 0"],
        ),
        kind(
            "CSV: the data file is missing",
            2,
            ENV,
            &["data.csv", "No such file"],
        )
        .config(paper_config()),
        kind(
            "CSV: the data file is a folder",
            2,
            ENV,
            &["data.csv", "directory"],
        )
        .config(paper_config())
        .file("data.csv/x", ""),
        paper(
            "CSV: data size does not match the model",
            2,
            "omega_rad_s,re_1_1,im_1_1\n1,0.5,0.1\n".into(),
            &["data.csv", "1×1", "2×3", "select a channel"],
        ),
    ]
}

fn toml_kinds() -> Vec<Kind> {
    let siso = |name, code, cfg: String, needles: &[&'static str]| {
        kind(name, code, ENV, needles)
            .config(cfg)
            .data(siso_data("", &[]))
    };
    let check = |name, code, cfg: String, needles: &[&'static str]| {
        kind(name, code, "check {dir}/model.toml", needles)
            .config(cfg)
            .data(siso_data("", &[]))
    };
    let r = |num: &str, den: &str| {
        SISO.replace("num = [0.1, 0.3]", &format!("num = {num}"))
            .replace("den = [1, 1]\n", &format!("den = {den}\n"))
    };
    vec![
        siso(
            "TOML: syntax error",
            2,
            SISO.replace("[r]", "[r"),
            &["model.toml", "line 6"],
        ),
        siso(
            "TOML: wrong type",
            2,
            SISO.replace("num = [0.1, 0.3]", "num = \"0.1, 0.3\""),
            &["model.toml", "line 7", "invalid type"],
        ),
        siso(
            "TOML: unknown key",
            2,
            SISO.replace("[r]\n", "[r]\ngian = 3\n"),
            &["model.toml", "line ", "unknown field `gian`"],
        ),
        siso(
            "TOML: empty polynomial",
            2,
            SISO.replace("num = [1], den = [1, 1]", "num = [], den = [1, 1]"),
            &["model.toml", "empty"],
        ),
        siso(
            "TOML: leading-zero polynomial",
            0,
            SISO.replace(
                "num = [1, 2], den = [1, 1]",
                "num = [0, 1, 2], den = [0, 0, 1, 1]",
            ),
            &[],
        ),
        check(
            "TOML: non-biproper r",
            2,
            r("[0.3]", "[1, 1]"),
            &["model.toml", "not a unit", "biproper"],
        ),
        check(
            "TOML: unstable r",
            2,
            r("[0.1, 0.3]", "[1, -1]"),
            &["model.toml", "not a unit", "stable"],
        ),
        check(
            "TOML: non-minimum-phase r",
            2,
            r("[0.1, -0.3]", "[1, 1]"),
            &["model.toml", "not a unit", "minimum phase"],
        ),
        check(
            "TOML: r with a zero at the origin",
            2,
            r("[0.1, 0]", "[1, 1]"),
            &["model.toml", "not a unit"],
        ),
        siso(
            "TOML: non-square M̃",
            2,
            SISO.replace(
                "m = [[{ num = [1, 2], den = [1, 1] }]]",
                "m = [[{ num = [1, 2], den = [1, 1] }, 1]]",
            ),
            &["model.toml", "square"],
        ),
        siso(
            "TOML: M̃ and Ñ sizes differ",
            2,
            SISO.replace("n = [[{ num = [1], den = [1, 1] }]]", "n = [[1], [1]]"),
            &["model.toml", "rows"],
        ),
        siso(
            "TOML: the data file named in the config is missing",
            2,
            SISO.replace("data.csv", "nowhere.csv"),
            &["nowhere.csv", "No such file"],
        ),
        kind(
            "TOML: the config is missing",
            2,
            "envelope {dir}/none.toml --out {dir}/out",
            &["none.toml", "No such file"],
        ),
        kind("TOML: the config is not UTF-8", 2, ENV, &["model.toml"])
            .config(b"\xff\xfe[r]\n".to_vec())
            .data(siso_data("", &[])),
        siso(
            "TOML: zeta = 0",
            2,
            physical("zeta = 0.0"),
            &["model.toml", "zeta"],
        ),
        siso(
            "TOML: negative zeta",
            2,
            physical("zeta = -0.1"),
            &["model.toml", "zeta"],
        ),
        siso(
            "TOML: unknown measured quantity",
            2,
            physical("quantity = \"accel\""),
            &["model.toml", "quantity", "acceleration"],
        ),
        siso(
            "TOML: negative omega_n",
            2,
            physical("omega_n = -5.0"),
            &["model.toml", "omega_n"],
        ),
        siso(
            "TOML: negative delay",
            2,
            physical("").replace(
                "[[physical.mode]]",
                "[[physical.effect]]\nkind = \"delay\"\ntau_s = -0.01\n[[physical.mode]]",
            ),
            &["model.toml", "tau_s"],
        ),
    ]
}

/// A one-mode physical model with one key changed (or added).
fn physical(change: &str) -> String {
    let base = r#"data = "data.csv"
[physical]
factor_den = [1.0, 41.2, 40.2]
[[physical.mode]]
omega_n = 5.0
zeta = 0.1
mass = 4.0
input_gain = 1800.0
output_gain = -3.3e-3
"#;
    let Some(key) = change.split_whitespace().next() else {
        return base.to_string();
    };
    match base.lines().find(|l| l.starts_with(key)) {
        Some(line) => base.replace(line, change),
        None => base.replace("[physical]\n", &format!("[physical]\n{change}\n")),
    }
}

fn cli_kinds() -> Vec<Kind> {
    let paper = |name, code, args: &str, needles: &[&'static str]| {
        kind(name, code, args, needles)
            .config(paper_config())
            .data(paper_data())
    };
    vec![
        paper(
            "CLI: --out is an existing file",
            2,
            "envelope {dir}/model.toml --out {dir}/data.csv",
            &["data.csv", "--out"],
        ),
        paper(
            "CLI: --out is the input folder",
            2,
            "envelope {dir}/model.toml --out {dir}",
            &["--out", "input"],
        ),
        paper(
            "CLI: --out cannot be created",
            2,
            "envelope {dir}/model.toml --out /dev/null/out",
            &["/dev/null"],
        ),
        paper(
            "CLI: --shard 0/0",
            2,
            "batch {dir}/model.toml --data-dir {dir} --out {dir}/out --shard 0/0",
            &["--shard", "0/0"],
        ),
        paper(
            "CLI: --shard 5/3",
            2,
            "batch {dir}/model.toml --data-dir {dir} --out {dir}/out --shard 5/3",
            &["--shard", "5/3"],
        ),
        paper(
            "CLI: --order 99",
            2,
            "fit {dir}/model.toml --order 99 --out {dir}/out",
            &["--order", "99"],
        ),
        paper(
            "CLI: --order -1",
            2,
            "fit {dir}/model.toml --order -1 --out {dir}/out",
            &["--order", "-1"],
        ),
        paper(
            "CLI: letters in --r-num",
            2,
            "check {dir}/model.toml --r-num 0.3,abc --r-den 1,1",
            &["--r-num", "abc"],
        ),
        paper(
            "CLI: --noise-radius -1",
            2,
            "envelope {dir}/model.toml --noise-radius -1 --out {dir}/out",
            &["--noise-radius", "-1"],
        ),
        paper(
            "CLI: --noise-radius nan",
            2,
            "envelope {dir}/model.toml --noise-radius nan --out {dir}/out",
            &["--noise-radius", "NaN"],
        ),
        paper(
            "CLI: an unknown flag",
            2,
            "envelope {dir}/model.toml --outt {dir}/out",
            &["--outt"],
        ),
        kind(
            "CLI: --envelope file with a bad row",
            2,
            "fit --envelope {dir}/e.csv --out {dir}/out",
            &["e.csv:3", "r_min `-1`"],
        )
        .file("e.csv", "omega_rad_s,r_min\n1,0.5\n2,-1\n"),
        paper(
            "CLI: stability --out is the input folder",
            2,
            "stability {dir}/model.toml --controller {dir}/k.toml --out {dir}",
            &["--out", "input"],
        )
        .file("k.toml", "[controller]\nd = [[1, 0], [0, 1], [0, 0]]\n"),
        paper(
            "CLI: compare --svg is the config",
            2,
            "compare {dir}/model.toml --channel 1,1 --svg {dir}/model.toml",
            &["--svg", "model.toml", "input"],
        ),
        paper(
            "CLI: history --svg is a folder",
            2,
            "history {dir}/model.toml --channel 1,1 --svg {dir}",
            &["--svg", "folder"],
        ),
        paper(
            "CLI: diagnose --write is the data file",
            2,
            "diagnose {dir}/model.toml --channel 1,1 --apply 1 --write {dir}/data.csv",
            &["--write", "data.csv", "input"],
        ),
    ]
}

/// SISO data whose datum at 1 rad/s has `r_min` at the A1 limit `σ_min(M̃)`: no admissible
/// `r` explains it, so every fit fails.
const BEYOND_A1: &str = "omega_rad_s,re_1_1,im_1_1\n0.1,0.55,-0.1\n1,1e8,1e8\n10,0.55,-0.1\n";

/// A file body that `run_kind` creates as a named pipe (FIFO) without a writer.
const FIFO: &[u8] = b"<FIFO>";

/// A SISO `[model]` with `m` and `n` replaced (issue 23: stability and coprimeness).
fn factors(m: &str, n: &str) -> String {
    SISO.replace(
        "m = [[{ num = [1, 2], den = [1, 1] }]]",
        &format!("m = [[{m}]]"),
    )
    .replace(
        "n = [[{ num = [1], den = [1, 1] }]]",
        &format!("n = [[{n}]]"),
    )
}

/// A `[closed_loop]` config with an unstable nominal 1/s² (rcf (N̂, D̂)) and the controller
/// given by `n_c`, `d_c`.
fn closed_loop(n_c: &str, d_c: &str) -> String {
    format!(
        "data = \"data.csv\"\n[closed_loop]\nn_hat = [[{{ num = [1], den = [1, 4, 4] }}]]\nd_hat = [[{{ num = [1, 0, 0], den = [1, 4, 4] }}]]\nn_c = [[{n_c}]]\nd_c = [[{d_c}]]\n"
    )
}

/// Issue 23 (Hardening II): invalid models, inputs that could hang or exhaust the machine,
/// misattributed messages and leftovers.
fn hardening_kinds() -> Vec<Kind> {
    let siso = |name, code, cfg: String, needles: &[&'static str]| {
        kind(name, code, ENV, needles)
            .config(cfg)
            .data(siso_data("", &[]))
    };
    let siso_csv = |name, code, args: &str, body: Vec<u8>, needles: &[&'static str]| {
        kind(name, code, args, needles).config(SISO).data(body)
    };
    let k_toml = "[controller]\nd = [[1, 0], [0, 1], [0, 0]]\n";
    vec![
        siso(
            "TOML: an unstable M̃ entry",
            2,
            factors(
                "{ num = [1, 2], den = [1, -1] }",
                "{ num = [1], den = [1, 1] }",
            ),
            &["model.toml", "[model] m[1][1]", "pole at s = 1", "stable"],
        ),
        siso(
            "TOML: an unstable Ñ entry",
            2,
            factors(
                "{ num = [1, 2], den = [1, 1] }",
                "{ num = [1], den = [1, 0, 4] }",
            ),
            &["model.toml", "[model] n[1][1]", "pole at s = ", "stable"],
        ),
        siso(
            "TOML: M̃ and Ñ with a common right-half-plane zero",
            2,
            factors(
                "{ num = [1, -1], den = [1, 1] }",
                "{ num = [1, -1], den = [1, 2, 1] }",
            ),
            &["model.toml", "common zero at s = 1", "not left coprime"],
        ),
        siso(
            "TOML: M̃ and Ñ with zeros 1e-9 apart (common to working precision)",
            2,
            factors(
                "{ num = [1, -1], den = [1, 1] }",
                "{ num = [1, -1.000000001], den = [1, 2, 1] }",
            ),
            &["model.toml", "common zero", "not left coprime"],
        ),
        siso(
            "TOML: M̃ and Ñ with zeros 1e-3 apart",
            0,
            factors(
                "{ num = [1, -1], den = [1, 1] }",
                "{ num = [1, -1.001], den = [1, 2, 1] }",
            ),
            &[],
        ),
        siso(
            "TOML: M̃ and Ñ both vanish at s = 0",
            2,
            factors(
                "{ num = [1, 0], den = [1, 1] }",
                "{ num = [2, 0], den = [1, 3] }",
            ),
            &["model.toml", "common zero at s = 0", "not left coprime"],
        ),
        siso(
            "TOML: M̃ and Ñ both strictly proper (not coprime at s = ∞)",
            2,
            factors("{ num = [1], den = [1, 1] }", "{ num = [2], den = [1, 3] }"),
            &["model.toml", "s = ∞", "not left coprime"],
        ),
        siso(
            "TOML: [closed_loop] controller factors with a common zero",
            2,
            closed_loop(
                "{ num = [20, 0], den = [1, 10, 25] }",
                "{ num = [1, 0], den = [1, 3] }",
            ),
            &[
                "model.toml",
                "[closed_loop]",
                "n_c and d_c",
                "not right coprime",
            ],
        ),
        siso(
            "TOML: [closed_loop] an unstable d_c entry",
            2,
            closed_loop(
                "{ num = [20], den = [1, 10] }",
                "{ num = [1, 0], den = [1, -3] }",
            ),
            &[
                "model.toml",
                "[closed_loop] d_c[1][1]",
                "pole at s = 3",
                "stable",
            ],
        ),
        kind(
            "CLI: stability --r-json with an unstable r",
            2,
            "stability {dir}/model.toml --controller {dir}/k.toml --r-json {dir}/r.json",
            &["r.json", "not a unit", "not stable", "pole at s = 2"],
        )
        .config(paper_config())
        .data(paper_data())
        .file("k.toml", k_toml)
        .file("r.json", r#"{"num": [1, 1], "den": [1, -2]}"#),
        kind(
            "CLI: stability --r-json with a non-minimum-phase r of degree 40",
            2,
            "stability {dir}/model.toml --controller {dir}/k.toml --r-json {dir}/r.json",
            &["r.json", "not a unit", "degree 40", "minimum phase"],
        )
        .config(paper_config())
        .data(paper_data())
        .file("k.toml", k_toml)
        .file("r.json", high_degree_r()),
        kind(
            "CLI: stability --r-json of degree 300",
            2,
            "stability {dir}/model.toml --controller {dir}/k.toml --r-json {dir}/r.json",
            &["r.json", "degree 300", "lower order"],
        )
        .config(paper_config())
        .data(paper_data())
        .file("k.toml", k_toml)
        .file("r.json", degree_300_r()),
        kind(
            "CLI: run on an unstable M̃ issues no certificate",
            2,
            "run {dir}/model.toml --out {dir}/out",
            &["[model] m[1][1]", "pole at s = 1"],
        )
        .config(factors(
            "{ num = [1, 2], den = [1, -1] }",
            "{ num = [1], den = [1, 1] }",
        ))
        .data(siso_data("", &[])),
        siso_csv(
            "CSV: a datum of 1e308+1e308j",
            0,
            ENV,
            siso_data("", &[])
                .replace("10,0.55,-0.1", "10,1e308,1e308")
                .into(),
            &[],
        ),
        siso_csv(
            "CSV: freq_hz of 1e308 (overflows in rad/s)",
            2,
            ENV,
            "freq_hz,re_1_1,im_1_1\n1,0.5,0.1\n1e308,0.5,0.1\n".into(),
            &["data.csv:3", "overflows in rad/s", "Hz"],
        ),
        siso_csv(
            "CSV: the data file is a FIFO",
            2,
            ENV,
            FIFO.to_vec(),
            &["data.csv", "not a regular file", "FIFO"],
        ),
        kind(
            "CSV: --data /dev/zero",
            2,
            "envelope {dir}/model.toml --data /dev/zero --out {dir}/out",
            &["/dev/zero", "not a regular file", "device"],
        )
        .config(SISO),
        siso_csv(
            "CSV: a 3 MB line without a line end",
            2,
            ENV,
            format!("omega_rad_s,re_1_1,im_1_1\n1,{}", "9".repeat(3 << 20)).into(),
            &["data.csv:2", "longer than 1 MB"],
        ),
        siso_csv(
            "CSV: a 300 kB field",
            2,
            ENV,
            format!("omega_rad_s,re_1_1,im_1_1\n1,{},0.1\n", "a".repeat(300_000)).into(),
            &["data.csv:2", "…` is not a number"],
        ),
        siso_csv(
            "CSV: a 1 MB comment line",
            0,
            ENV,
            format!("#{}\n{}", "c".repeat(1 << 20), siso_data("", &[])).into(),
            &[],
        ),
        siso_csv(
            "CSV: header column re_100000_100000",
            2,
            ENV,
            "omega_rad_s,re_1_1,im_1_1,re_100000_100000\n1,1,1,1\n".into(),
            &["data.csv:1", "unknown column `re_100000_100000`", "10000"],
        ),
        siso_csv(
            "CSV: header column re_5000_5000",
            2,
            ENV,
            "omega_rad_s,re_1_1,im_1_1,re_5000_5000\n1,1,1,1\n".into(),
            &["data.csv:1", "missing column", "5000×5000"],
        ),
        siso(
            "TOML: omega_n = 1e300",
            2,
            physical("omega_n = 1e300"),
            &["model.toml", "[[physical.mode]] #1", "omega_n", "outside"],
        ),
        siso(
            "TOML: omega_n = 1e155 (ω_n² overflows)",
            2,
            physical("omega_n = 1e155"),
            &["model.toml", "[[physical.mode]] #1", "outside"],
        ),
        siso(
            "TOML: omega_n = 1e20",
            2,
            physical("omega_n = 1e20"),
            &["model.toml", "[[physical.mode]] #1", "outside"],
        ),
        siso(
            "TOML: omega_n = inf",
            2,
            physical("omega_n = inf"),
            &["model.toml", "[[physical.mode]] #1", "not a finite number"],
        ),
        siso(
            "TOML: zeta = 1e300",
            2,
            physical("zeta = 1e300"),
            &["model.toml", "[[physical.mode]] #1", "zeta"],
        ),
        kind(
            "TOML: [channel] beyond the data",
            2,
            ENV,
            &["[channel] output = 5", "not a channel of the data", "1..=2"],
        )
        .config(SISO.replace("[r]", "[channel]\noutput = 5\ninput = 1\n[r]"))
        .data(paper_data()),
        kind(
            "CLI: batch --jobs 100000",
            2,
            "batch {dir}/model.toml --data-dir {dir} --out {dir}/out --jobs 100000",
            &["--jobs 100000", "1 to 1024"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: batch --jobs 0",
            2,
            "batch {dir}/model.toml --data-dir {dir} --out {dir}/out --jobs 0",
            &["--jobs 0", "1 to 1024"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: batch --jobs -1",
            2,
            "batch {dir}/model.toml --data-dir {dir} --out {dir}/out --jobs -1",
            &["--jobs -1", "1 to 1024"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: fit --margin -1",
            2,
            "fit {dir}/model.toml --margin -1 --out {dir}/out",
            &["--margin -1", "below r_min"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: check --r-num -0.1,0.3 (negative coefficients are values)",
            2,
            "check {dir}/model.toml --r-num -0.1,0.3 --r-den 1,1",
            &["--r-num/--r-den", "not a unit", "minimum phase"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: diagnose --beam -1",
            2,
            "diagnose {dir}/model.toml --channel 1,1 --beam -1",
            &["--beam", "-1"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
        kind(
            "CLI: a fit that fails leaves no out/",
            2,
            "fit {dir}/model.toml --order 0 --out {dir}/out",
            &["order 0", "A1"],
        )
        .config(SISO)
        .data(BEYOND_A1),
        kind(
            "CLI: a stability --fit that fails leaves no out/",
            2,
            "stability {dir}/model.toml --controller {dir}/k.toml --fit --out {dir}/out",
            &["failed its certificate", "A1"],
        )
        .config(SISO)
        .data(BEYOND_A1)
        .file(
            "k.toml",
            "[controller]\ntf = [[{ num = [2, 1], den = [1, 4] }]]\n",
        ),
        kind(
            "CLI: --out under /proc",
            2,
            "envelope {dir}/model.toml --out /proc/rshape-issue23/out",
            &["/proc/rshape-issue23/out", "cannot be created"],
        )
        .config(SISO)
        .data(siso_data("", &[])),
    ]
}

/// `r.json` of degree 40 with one right-half-plane zero (its coefficients would make a
/// message of kilobytes if echoed).
fn high_degree_r() -> String {
    let mut num = vec![1.0f64];
    let mut den = vec![1.0f64];
    for k in 0..40 {
        let z = if k == 0 { 0.5 } else { -1.0 - k as f64 / 10.0 };
        num = poly_mul(&num, &[1.0, -z]);
        den = poly_mul(&den, &[1.0, 2.0 + k as f64 / 10.0]);
    }
    format!("{{\"num\": {num:?}, \"den\": {den:?}}}")
}

/// A unit `r` of degree 300 (poles on the circle of radius 1, zeros on that of radius 1.5,
/// all in the left half-plane): its coefficients reach 1e104, beyond what the root
/// iteration resolves, and there are 602 of them to (not) quote.
fn degree_300_r() -> String {
    let (mut num, mut den) = (vec![1.0f64], vec![1.0f64]);
    for k in 0..150 {
        let c = (std::f64::consts::PI * (0.5 + (k as f64 + 0.5) / 300.0)).cos();
        num = poly_mul(&num, &[1.0, -3.0 * c, 2.25]);
        den = poly_mul(&den, &[1.0, -2.0 * c, 1.0]);
    }
    format!("{{\"num\": {num:?}, \"den\": {den:?}}}")
}

fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

fn all_kinds() -> Vec<Kind> {
    let mut k = csv_kinds();
    k.extend(toml_kinds());
    k.extend(cli_kinds());
    k.extend(hardening_kinds());
    k
}

struct Outcome {
    code: Option<i32>,
    stderr: String,
    problems: Vec<String>,
}

fn run_kind(k: &Kind) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    for (name, body) in &k.files {
        let p = dir.path().join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        if body.as_slice() == FIFO {
            let ok = Command::new("mkfifo").arg(&p).status().unwrap().success();
            assert!(ok, "mkfifo {}", p.display());
        } else if !name.ends_with("/x") {
            std::fs::write(&p, body).unwrap();
        }
    }
    let d = dir.path().to_str().unwrap();
    let args: Vec<String> = k.args.iter().map(|a| a.replace("{dir}", d)).collect();
    let before = listing(dir.path());
    let o = run_with_timeout(&args, KIND_TIMEOUT);
    let Some(o) = o else {
        return Outcome {
            code: None,
            stderr: String::new(),
            problems: vec![format!("still running after {KIND_TIMEOUT:?}: killed")],
        };
    };
    let stderr = String::from_utf8_lossy(&o.stderr).replace(d, "DIR");
    let mut problems = Vec::new();
    if o.status.code() != Some(k.code) {
        problems.push(format!("exit {:?}, expected {}", o.status.code(), k.code));
    }
    if stderr.contains("panicked") {
        problems.push("panic".into());
    }
    if stderr.len() > MAX_STDERR {
        problems.push(format!(
            "{} bytes of stderr (at most {MAX_STDERR})",
            stderr.len()
        ));
    }
    if k.code == 2 {
        let clap = stderr.contains("Usage:");
        if !stderr.starts_with("error: ") || (!clap && stderr.trim_end().lines().count() != 1) {
            problems.push("not a one-line `error: ` message".into());
        }
        for n in &k.needles {
            if !stderr.contains(n) {
                problems.push(format!("`{n}` missing"));
            }
        }
        let after = listing(dir.path());
        let new: Vec<_> = after.iter().filter(|p| !before.contains(p)).collect();
        if !new.is_empty() {
            problems.push(format!("files left behind: {new:?}"));
        }
    } else if args[0] == "envelope" {
        match std::fs::read_to_string(dir.path().join("out/envelope.csv")) {
            Err(_) => problems.push("no envelope.csv".into()),
            Ok(t) if t.to_ascii_lowercase().contains("nan") => {
                problems.push("NaN in envelope.csv".into())
            }
            Ok(_) => {}
        }
    }
    Outcome {
        code: o.status.code(),
        stderr,
        problems,
    }
}

/// No kind may run longer (a hang is a failure, not a stuck test).
const KIND_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(30);

/// Longest error output accepted: one line that quotes little of its input.
const MAX_STDERR: usize = 1000;

/// Runs rshape with `args`; `None` (after killing it) when it outlives `limit`.
fn run_with_timeout(args: &[String], limit: std::time::Duration) -> Option<std::process::Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Drain the pipes on threads so a chatty child never blocks on a full pipe.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut out, &mut v).ok();
        v
    });
    let t_err = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut err, &mut v).ok();
        v
    });
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let (stdout, stderr) = (t_out.join().unwrap(), t_err.join().unwrap());
    status.map(|status| std::process::Output {
        status,
        stdout,
        stderr,
    })
}

/// Every file under `dir` (folders included), relative.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out
}

#[test]
fn every_kind_gets_its_answer() {
    let kinds = all_kinds();
    assert!(kinds.len() >= 40, "{} kinds", kinds.len());
    let mut failures = Vec::new();
    let mut table = String::from("| input | exit | message |\n|---|---|---|\n");
    for k in &kinds {
        let o = run_kind(k);
        let msg = match o.code {
            Some(0) => "accepted".to_string(),
            _ => o.stderr.lines().next().unwrap_or("").replace('|', "\\|"),
        };
        table += &format!(
            "| {} | {} | {} |\n",
            k.name,
            o.code.map_or("signal".into(), |c| c.to_string()),
            msg
        );
        if !o.problems.is_empty() {
            failures.push(format!(
                "{}: {}\n    stderr: {}",
                k.name,
                o.problems.join("; "),
                o.stderr.trim_end()
            ));
        }
    }
    if let Ok(p) = std::env::var("RSHAPE_BAD_INPUT_TABLE") {
        std::fs::write(p, &table).unwrap();
    }
    assert!(
        failures.is_empty(),
        "{} of {} kinds fail:\n{}",
        failures.len(),
        kinds.len(),
        failures.join("\n")
    );
}

#[test]
fn readme_lists_every_kind() {
    let readme = std::fs::read_to_string(common::repo("docs/guide/bad-input.md")).unwrap();
    let missing: Vec<_> = all_kinds()
        .iter()
        .map(|k| k.name)
        .filter(|n| !readme.contains(&format!("| {n} |")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/guide/bad-input.md's table lacks: {missing:?}"
    );
}
