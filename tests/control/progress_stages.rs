//! Issue 34 item 9: `stability` and `synthesize` tell what they start (the CLI prints it on
//! a large model), and telling changes nothing. On the 20-mode structure of the large-model
//! bench: the stages in the order they run, each once (the loop realized and its poles
//! computed once), the pole count announced equal to the poles reported, the proof of
//! `synthesize` announced stage by stage, and the same numbers as without a listener.

use crate::modes;

use rshape::model::{Config, Controller};
use rshape::pipeline::stability::{run as stability, run_with_stages as stability_with};
use rshape::pipeline::synthesize::{run as synthesize, run_with_stages, SynthesisSettings};
use rshape::system::TransferFunction;
use std::sync::Mutex;

/// Strips the ` (…)` detail of a stage line (sizes), keeping its name.
fn name(s: &str) -> String {
    s.split(" (").next().unwrap().to_string()
}

fn stages_of_a_proof(prefix: &str) -> Vec<String> {
    [
        "the loop's realization",
        "closed-loop poles",
        "the grid curve sigma_max(T(jw)) at 1000 frequencies",
        "||T||_inf, exact",
        "b(G,K), exact",
    ]
    .iter()
    .map(|s| format!("{prefix}{s}"))
    .collect()
}

#[test]
fn stability_and_synthesize_tell_their_stages_once_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = modes::write(dir.path(), 20, 30);
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").unwrap();
    let config = Config::load(&cfg).unwrap();
    let controller = Controller::load(&kp).unwrap();
    let rs = vec![("configured".to_string(), TransferFunction::gain(1e-3))];

    let heard = Mutex::new(Vec::<String>::new());
    let listen = |s: &str| heard.lock().unwrap().push(s.to_string());
    let told = stability_with(&config, &controller, &rs, None, &listen).unwrap();
    let lines = std::mem::take(&mut *heard.lock().unwrap());
    let names: Vec<String> = lines.iter().map(|s| name(s)).collect();
    assert_eq!(names, stages_of_a_proof(""), "{lines:?}");
    // The size announced is the loop's: one pole per state.
    let n = told.report.closed_loop_poles.len();
    assert_eq!(lines[1], format!("closed-loop poles ({n} states)"));
    assert_eq!(n, 4 * 20);
    let quiet = stability(&config, &controller, &rs, None).unwrap();
    assert_eq!(quiet.report.margins[0].alpha, told.report.margins[0].alpha);
    assert_eq!(quiet.report.b_gk, told.report.b_gk);
    assert_eq!(quiet.robust, told.robust);

    // synthesize: the controller, then the same proof stages on its loop.
    let settings = SynthesisSettings::default();
    let kout = dir.path().join("controller.toml");
    let o = run_with_stages(&config, &cfg, &rs, &settings, None, &kout, &listen).unwrap();
    let lines = std::mem::take(&mut *heard.lock().unwrap());
    let names: Vec<String> = lines.iter().map(|s| name(s)).collect();
    let mut want = vec!["the Glover–McFarlane controller".to_string()];
    want.extend(stages_of_a_proof("proof: "));
    assert_eq!(names, want, "{lines:?}");
    assert_eq!(
        lines[0],
        "the Glover–McFarlane controller (40 plant states: two Riccati equations)"
    );
    // The proof's loop: the factors' 80 states and the controller's.
    let n = o.stability.report.closed_loop_poles.len();
    assert_eq!(n, 80 + o.gm.k.states());
    assert_eq!(lines[2], format!("proof: closed-loop poles ({n} states)"));
    let quiet = synthesize(&config, &cfg, &rs, &settings, None, &kout).unwrap();
    assert_eq!(quiet.gm.b_opt, o.gm.b_opt);
    assert_eq!(quiet.bounds[0].alpha, o.bounds[0].alpha);
    assert_eq!(quiet.robust, o.robust);
}
