//! The combined envelope of a batch: at every frequency of any dataset, the largest
//! `r_min` over the datasets measured there (a unit `r` above it explains them all), with
//! the smallest A1 limit.  Frequencies closer than a relative 1e-9 are the same frequency.

use crate::consistency::{Envelope, EnvelopeMethod};

/// Pointwise maximum of envelopes at the union of their frequencies.
pub fn combine<'a, I: IntoIterator<Item = &'a Envelope>>(envs: I) -> Option<Envelope> {
    let mut pts: Vec<(f64, f64, Option<f64>)> = Vec::new();
    let mut method = None;
    let mut has_a1 = true;
    for e in envs {
        method.get_or_insert(e.method);
        has_a1 &= e.a1_limit.is_some();
        for i in 0..e.len() {
            pts.push((e.omega[i], e.r_min[i], e.a1_limit.as_ref().map(|a| a[i])));
        }
    }
    let method = method?;
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut omega: Vec<f64> = Vec::new();
    let mut r_min: Vec<f64> = Vec::new();
    let mut a1: Vec<f64> = Vec::new();
    for (w, r, a) in pts {
        let a = a.unwrap_or(f64::INFINITY);
        match omega.last() {
            Some(&last) if (w - last).abs() <= 1e-9 * w.abs().max(last.abs()) => {
                let k = r_min.len() - 1;
                r_min[k] = r_min[k].max(r);
                a1[k] = a1[k].min(a);
            }
            _ => {
                omega.push(w);
                r_min.push(r);
                a1.push(a);
            }
        }
    }
    Some(Envelope {
        omega,
        r_min,
        a1_limit: has_a1.then_some(a1),
        method,
    })
}

/// Parses an `envelope.csv` (as written by [`crate::report::envelope_csv`]).
pub fn parse_envelope_csv(text: &str, what: &str) -> crate::error::Result<Envelope> {
    let bad = |line: usize, m: &str| crate::error::Error::Invalid(format!("{what}:{line}: {m}"));
    let num = |s: &str, line: usize| -> crate::error::Result<f64> {
        match s.trim() {
            "inf" => Ok(f64::INFINITY),
            t => t
                .parse()
                .map_err(|_| bad(line, &format!("`{t}` is not a number"))),
        }
    };
    let mut env = Envelope {
        omega: vec![],
        r_min: vec![],
        a1_limit: Some(vec![]),
        method: EnvelopeMethod::File,
    };
    for (k, l) in text
        .lines()
        .enumerate()
        .skip(1)
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let f: Vec<&str> = l.split(',').collect();
        if f.len() != 3 {
            return Err(bad(k + 1, "expected omega_rad_s,r_min,a1_limit"));
        }
        env.omega.push(num(f[0], k + 1)?);
        env.r_min.push(num(f[1], k + 1)?);
        match (&mut env.a1_limit, f[2].trim()) {
            (Some(_), "") => env.a1_limit = None,
            (Some(a), s) => a.push(num(s, k + 1)?),
            (None, _) => {}
        }
    }
    Ok(env)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(w: &[f64], r: &[f64]) -> Envelope {
        Envelope {
            omega: w.to_vec(),
            r_min: r.to_vec(),
            a1_limit: Some(vec![1.0; w.len()]),
            method: EnvelopeMethod::Theorem2,
        }
    }

    #[test]
    fn pointwise_max_on_union() {
        let c = combine([
            &env(&[1.0, 2.0], &[0.1, 0.5]),
            &env(&[2.0, 3.0], &[0.7, f64::INFINITY]),
        ])
        .unwrap();
        assert_eq!(c.omega, vec![1.0, 2.0, 3.0]);
        assert_eq!(c.r_min[1], 0.7);
        assert!(c.r_min[2].is_infinite());
        let back = parse_envelope_csv(&crate::report::envelope_csv(&c), "x").unwrap();
        assert_eq!(back.omega, c.omega);
        assert_eq!(back.r_min, c.r_min);
    }
}
