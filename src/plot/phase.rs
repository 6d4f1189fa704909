//! Phase pieces shared by the two Bode figures (`bode.rs`, `run`'s data against the nominal
//! model; `bode_overlay.rs`, `compare`'s data against one or more models): a measured phase
//! moved to the branch nearest a reference, and the phase span of a noise disk.

/// The phase `p` (degrees) moved by whole turns to the branch nearest `to` (a datum at −179°
/// beside a model at +179° is drawn 2° from it, not 358°).
pub fn nearest_branch(p: f64, to: f64) -> f64 {
    p + 360.0 * ((to - p) / 360.0).round()
}

/// Half the phase span (degrees) of the disk `|G − z| ≤ r` around a point `z` with `|z| = a`:
/// `asin(r/a)`, or 180° (every phase) when the disk holds 0.
pub fn disk_half_span_deg(r: f64, a: f64) -> f64 {
    if r < a {
        (r / a).asin().to_degrees()
    } else {
        180.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn branches_and_disk_spans_match_their_closed_forms() {
        assert_eq!(nearest_branch(-179.0, 179.0), 181.0);
        assert_eq!(nearest_branch(10.0, -710.0), -710.0);
        assert_eq!(nearest_branch(45.0, 50.0), 45.0);
        // A disk of radius 1 at distance 2 is seen under ±30°.
        assert!((disk_half_span_deg(1.0, 2.0) - 30.0).abs() < 1e-12);
        assert_eq!(disk_half_span_deg(2.0, 2.0), 180.0);
        assert_eq!(disk_half_span_deg(3.0, 1.0), 180.0);
    }
}
