//! lfeval's HCI scores equal the HCI evaluation toolkit's own on a fixture: a 64² scene of two
//! slanted planes, a smooth bump and a thin bar, its 5× high-resolution ground truth and the
//! five evaluation masks at both resolutions, and a blurred, noisy, fattened "algorithm"
//! result with NaN pixels. `toolkit_scores.json` holds the toolkit's numbers for these files,
//! computed by its `compute_scores` through `scripts/hci_region_fixture.py` (which says how to
//! re-run it).

use std::path::Path;

use lfdata::prediction::ScenePrediction;
use lfdata::regions::load_region_truth;
use lfdata::scene_eval::{EvalConfig, PreparedTruth, evaluate};
use lfdata::truth::{Reference, SceneTruth};
use lfformat::pfm::read_pfm;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/hci_region");

fn toolkit(key: &str) -> f64 {
    let text = std::fs::read_to_string(Path::new(FIXTURE).join("toolkit_scores.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json[key].as_f64().unwrap_or_else(|| panic!("no {key}"))
}

#[test]
fn region_and_hci_scores_equal_the_toolkits_on_the_fixture() {
    let dir = Path::new(FIXTURE).join("regions");
    let truth = SceneTruth::load(&dir).unwrap();
    let (w, h) = (truth.width(), truth.height());
    let regions = load_region_truth(&dir, w, h).unwrap();
    assert!(regions.is_some(), "the fixture has masks");
    let cfg = EvalConfig::default();
    let gt = PreparedTruth::new(&truth, &cfg).with_regions(regions);
    let pred = ScenePrediction {
        disparity: read_pfm(&Path::new(FIXTURE).join("disp_maps/regions.pfm")).unwrap(),
        uncertainty: None,
        posterior: None,
        runtime_s: None,
    };
    let scores = evaluate(&gt, &pred, &cfg);
    let r = scores.regions.expect("region scores");
    let hci = scores.against(Reference::Hci);
    // The region scores: the toolkit works in float64 there (the bumpiness, the normals) or
    // counts pixels, and our sums and median run in another order: ~1e-13 apart.
    let region = [
        ("discontinuities_0070", r.discontinuities),
        ("bumpiness_planes_100_0050", r.bumpiness_planes),
        ("bumpiness_contin_surfaces_100_0050", r.bumpiness_surfaces),
        ("mae_planes", r.mae_planes),
        ("mae_contin_surfaces", r.mae_surfaces),
        ("fine_fattening_0150", r.fine_fattening),
        ("fine_thinning_0150", r.fine_thinning),
        ("badpix_0010", hci.badpix_001),
        ("badpix_0030", hci.badpix_003),
        ("badpix_0070", hci.badpix_007),
    ];
    // MSE and Q25: numpy squares, averages and scales the float32 maps in float32, we in
    // float64, so they agree to float32's precision (~1e-7 relative).
    let float32 = [("mse_100", hci.mse_x100), ("q_25_100", hci.q25)];
    for (cases, relative) in [(&region[..], 1e-12), (&float32[..], 1e-6)] {
        for &(key, ours) in cases {
            let (ours, theirs) = (
                ours.unwrap_or_else(|| panic!("{key} missing")),
                toolkit(key),
            );
            let tolerance = relative * theirs.abs().max(1.0);
            assert!(
                (ours - theirs).abs() <= tolerance,
                "{key}: lfeval {ours}, toolkit {theirs}"
            );
        }
    }
    assert_eq!(
        r.fine_resolution,
        Some(lfdata::metrics::region::Resolution::High)
    );
}
