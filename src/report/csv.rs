//! CSV renderings.

use crate::consistency::Envelope;
use std::io::Write;

/// `envelope.csv`: `omega_rad_s,r_min,a1_limit`, one row per datum, sorted by frequency;
/// `inf` where no admissible r explains the datum, an empty `a1_limit` when the model is
/// unknown.  Numbers use 17 significant digits so the file round-trips exactly.
pub fn envelope_csv(env: &Envelope) -> String {
    let mut s = Vec::new();
    write_envelope_csv(env, &mut s).expect("writing to memory");
    String::from_utf8(s).expect("ASCII")
}

/// [`envelope_csv`] written row by row to `w` (no copy of the whole file in memory).
pub fn write_envelope_csv(env: &Envelope, w: &mut impl Write) -> std::io::Result<()> {
    writeln!(w, "omega_rad_s,r_min,a1_limit")?;
    for i in 0..env.len() {
        let a1 = env.a1_limit.as_ref().map_or(String::new(), |a| num(a[i]));
        writeln!(w, "{},{},{}", num(env.omega[i]), num(env.r_min[i]), a1)?;
    }
    Ok(())
}

/// A number with full precision, `inf` for infinity.
pub fn num(x: f64) -> String {
    if x.is_infinite() {
        if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else {
        format!("{x:.17e}")
    }
}
