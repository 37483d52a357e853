//! The paper's experiments write their data.

use crate::support::*;
use simlod::experiments::step_response;

#[test]
fn step_response_writes_velocities_and_paths_that_follow_the_steps() {
    let out = scratch_dir("step_response");
    let file = assets_root().join("experiments/step_response.ron");
    let summary = step_response::run(&default_config(), &file, &out).unwrap();
    assert!(
        summary.contains("rigid: 240 samples") && summary.contains("hybrid: 240 samples"),
        "{summary}"
    );
    assert!(summary.contains("the models are"), "{summary}");
    let velocity = std::fs::read_to_string(out.join("velocity.csv")).unwrap();
    let path = std::fs::read_to_string(out.join("path.csv")).unwrap();
    assert_eq!(velocity.lines().count(), 1 + 2 * 240);
    assert_eq!(path.lines().count(), 1 + 2 * 240);
    let vx_at = |model: &str, t: f32| -> f32 {
        let row = velocity
            .lines()
            .skip(1)
            .filter(|l| l.starts_with(model))
            .find(|l| l.split(',').nth(1).unwrap().parse::<f32>().unwrap() >= t)
            .unwrap();
        row.split(',').nth(4).unwrap().parse().unwrap()
    };
    for model in ["rigid", "hybrid"] {
        // The 2 m/s step at 1 s: still at rest before it, past 1.5 m/s by 3.5 s.
        assert!(
            vx_at(model, 0.9).abs() < 0.05,
            "{model} still at rest before the first step"
        );
        assert!(
            vx_at(model, 3.45) > 1.5,
            "{model} sped up after the step: {}",
            vx_at(model, 3.45)
        );
    }
    // Figure 4: where the paths end, and how far apart: the last rows of path.csv.
    let end_of = |model: &str| -> (f32, f32) {
        let row = path.lines().rfind(|l| l.starts_with(model)).unwrap();
        let v: Vec<f32> = row.split(',').skip(2).map(|x| x.parse().unwrap()).collect();
        (v[0], v[1])
    };
    let last = std::fs::read_to_string(out.join("final.csv")).unwrap();
    let v: Vec<f32> = last
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let ((rx, rz), (hx, hz)) = (end_of("rigid"), end_of("hybrid"));
    assert_eq!((v[0], v[1], v[2], v[3]), (rx, rz, hx, hz), "{last}");
    let apart = ((rx - hx).powi(2) + (rz - hz).powi(2)).sqrt();
    assert!((v[4] - apart).abs() < 1e-3 && apart > 0.0, "{last}");
    // Figure 3: the hybrid responds to the step with less delay.
    assert!(
        vx_at("hybrid", 1.5) > vx_at("rigid", 1.5),
        "{} vs {}",
        vx_at("hybrid", 1.5),
        vx_at("rigid", 1.5)
    );
}

#[test]
fn step_response_refuses_a_broken_experiment_file() {
    let dir = scratch_dir("step_response_bad");
    let file = dir.join("bad.ron");
    std::fs::write(
        &file,
        "(creature: \"hopper\", duration_s: -1.0, start_m: (0.0, 0.0), steps: [])",
    )
    .unwrap();
    let err = step_response::run(&default_config(), &file, &dir).unwrap_err();
    assert!(err.contains("`duration_s`") && err.contains("`steps`"), "{err}");
}
