//! The sweep validation checks on their own setups: the rendered highlight follows the predicted
//! peak, and the renderer matches the BSDF evaluated directly. (`xylem validate sweep` runs the
//! same functions and also the figure signatures, which depend on the wood presets.)

use xylem::render::RunOptions;
use xylem_lab::sweep::{highlight_tracking, renderer_vs_bsdf};

fn run() -> RunOptions<'static> {
    RunOptions {
        threads: 1,
        ..Default::default()
    }
}

#[test]
fn rendered_highlight_peaks_where_the_model_predicts() {
    for incl in [0.0, 30.0] {
        let c = highlight_tracking(incl, None, &run()).unwrap();
        assert!(c.verdict.passed, "{}: {}", c.verdict.check, c.figure);
        let within = c.values["fraction_within_step"].as_f64().unwrap();
        assert!(within >= 0.99, "{within}");
    }
}

#[test]
fn rendered_pixels_equal_the_bsdf_times_cosine() {
    let c = renderer_vs_bsdf(&run()).unwrap();
    assert!(c.verdict.passed, "{}", c.figure);
    assert!(c.values["compared"].as_u64().unwrap() > 1000);
}
