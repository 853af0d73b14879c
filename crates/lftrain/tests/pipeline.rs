//! The data pipeline against rendered scenes: stack extraction, the EPI shift's sign, and the
//! rotation augmentation compared with a render of the rotated scene.

use lfdata::lightfield::{LightField, rotate_plane};
use lfdata::stacks::{Direction, Region, extract};
use lftrain::augment::{Degrade, Photometric};
use lftrain::config::AugmentConfig;
use lftrain::input::StackInput;
use lftrain::sample::{Draw, make_sample};
use lftrain::scene::Scene;
use lftrain::synthetic::TwoPlanes;

fn uni() -> lftrain::scene::Unimodal {
    lftrain::scene::Unimodal::of(&lftrain::config::TrainConfig::default())
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

fn stacks(lf: &LightField, shift: f32) -> Vec<Vec<f32>> {
    Direction::ALL
        .iter()
        .map(|&d| extract(lf, d, Region::whole(lf), shift))
        .collect()
}

#[test]
fn rotated_light_field_has_the_stacks_of_the_rendered_rotation() {
    for n in [3, 5, 9] {
        let scene = TwoPlanes::new(n, 24);
        let lf = scene.render();
        for turns in 1..4 {
            let rendered = TwoPlanes { turns, ..scene }.render();
            let rotated = lf.rotate(turns);
            for (dir, (a, b)) in Direction::ALL
                .iter()
                .zip(stacks(&rotated, 0.0).iter().zip(stacks(&rendered, 0.0)))
            {
                let diff = max_diff(a, &b);
                assert!(
                    diff < 1e-5,
                    "{n}x{n}, {turns} turns, {dir:?}: differs by {diff}"
                );
            }
        }
    }
}

#[test]
fn rotated_samples_match_samples_of_the_rendered_rotation() {
    let dir = tempfile::tempdir().unwrap();
    let scene = TwoPlanes::new(5, 20);
    for turns in 0..4 {
        TwoPlanes { turns, ..scene }
            .write(&dir.path().join(format!("t{turns}")), true)
            .unwrap();
    }
    let load = |t: usize| Scene::load(&dir.path().join(format!("t{t}")), "s", 3, uni()).unwrap();
    let original = load(0);
    for turns in 1..4 {
        let draw = |turns| Draw {
            origin: (0, 0),
            scale: 1,
            turns,
            shift: 0.75,
            photometric: Photometric::IDENTITY,
            degrade: Degrade::NONE,
        };
        // The whole image as the crop: rotating it is rotating the scene.
        let a = make_sample(&original, &draw(turns), 20, 0, &StackInput::Views);
        let b = make_sample(&load(turns), &draw(0), 20, 0, &StackInput::Views);
        for k in 0..4 {
            // 8-bit views: the rotated scene's PNG rounds the same colours.
            let diff = max_diff(&a.stacks[k], &b.stacks[k]);
            assert!(diff < 1e-6, "{turns} turns, stack {k}: {diff}");
        }
        assert_eq!(a.disparity, b.disparity, "{turns} turns: targets");
        assert_eq!(a.eta, b.eta);
        // The loss region turns with the views: the texture mask of the rotated crop is the
        // mask of the rotated scene (mmlf forgets this), and the border is the same square.
        let masked = |s: Scene| s.with_texture_mask(5, 0.12);
        let a = make_sample(&masked(load(0)), &draw(turns), 20, 3, &StackInput::Views);
        let b = make_sample(&masked(load(turns)), &draw(0), 20, 3, &StackInput::Views);
        assert_eq!(a.eta, b.eta, "{turns} turns: loss region");
        assert_eq!(a.loss_pixels, b.loss_pixels);
        let inner = 14 * 14;
        assert!(
            a.loss_pixels > 0 && a.loss_pixels < inner,
            "{turns} turns: {} of {inner} inner pixels textured (the test needs both kinds)",
            a.loss_pixels
        );
    }
}

#[test]
fn shifting_by_the_disparity_aligns_the_views_and_zeroes_the_target() {
    // One plane at disparity d (the square covers the image): shifted by s = d, every view of
    // every stack shows the centre view, and the target becomes d - s = 0.
    let d = 0.8;
    let plane = TwoPlanes {
        front: d,
        half: 1e6,
        alpha: 1.0,
        ..TwoPlanes::new(5, 32)
    };
    let lf = plane.render();
    let inner = Region {
        x0: 6,
        y0: 6,
        width: 20,
        height: 20,
    };
    let plane_len = inner.width * inner.height * 3;
    for dir in Direction::ALL {
        let s = extract(&lf, dir, inner, d);
        let centre = &s[2 * plane_len..3 * plane_len];
        for k in 0..5 {
            let diff = max_diff(&s[k * plane_len..(k + 1) * plane_len], centre);
            assert!(diff < 0.02, "{dir:?} view {k}: {diff}");
        }
        // The opposite sign doubles the misalignment instead.
        let wrong = extract(&lf, dir, inner, -d);
        assert!(max_diff(&wrong[..plane_len], &wrong[2 * plane_len..3 * plane_len]) > 0.1);
    }
    let dir = tempfile::tempdir().unwrap();
    plane.write(dir.path(), false).unwrap();
    let scene = Scene::load(dir.path(), "plane", 1, uni()).unwrap();
    let draw = Draw {
        origin: (4, 4),
        scale: 1,
        turns: 0,
        shift: d,
        photometric: Photometric::IDENTITY,
        degrade: Degrade::NONE,
    };
    let sample = make_sample(&scene, &draw, 16, 0, &StackInput::Views);
    assert!(sample.disparity.iter().all(|t| t.abs() < 1e-6));
    assert!(sample.eta.iter().all(|&e| e == 1.0));
    assert_eq!(sample.loss_pixels, 256);
    // A 4 px loss border keeps the inner 8 × 8 pixels, and only them.
    let sample = make_sample(&scene, &draw, 16, 4, &StackInput::Views);
    assert_eq!(sample.loss_pixels, 64);
    for (i, &e) in sample.eta.iter().enumerate() {
        let inner = (4..12).contains(&(i % 16)) && (4..12).contains(&(i / 16));
        assert_eq!(e, if inner { 1.0 } else { 0.0 }, "pixel {i}");
    }
}

/// Down-scaling by 2 (every second pixel) halves the disparity: a plane at d = 2 px is at 1 px
/// in the sample, so shifting by 1 aligns every view and zeroes the target.
#[test]
fn downscaling_halves_the_disparity_of_views_and_targets() {
    let d = 2.0;
    let plane = TwoPlanes {
        front: d,
        half: 1e6,
        alpha: 1.0,
        ..TwoPlanes::new(5, 32)
    };
    let dir = tempfile::tempdir().unwrap();
    plane.write(dir.path(), false).unwrap();
    let scene = Scene::load(dir.path(), "plane", 1, uni()).unwrap();
    let draw = |shift| Draw {
        origin: (4, 4),
        scale: 2,
        turns: 0,
        shift,
        photometric: Photometric::IDENTITY,
        degrade: Degrade::NONE,
    };
    let sample = make_sample(&scene, &draw(d / 2.0), 8, 0, &StackInput::Views);
    assert!(
        sample.disparity.iter().all(|t| t.abs() < 1e-6),
        "{:?}",
        sample.disparity
    );
    let len = 8 * 8 * 3;
    for (k, stack) in sample.stacks.iter().enumerate() {
        let centre = &stack[2 * len..3 * len];
        for v in 0..5 {
            let diff = max_diff(&stack[v * len..(v + 1) * len], centre);
            assert!(diff < 0.02, "stack {k} view {v}: {diff}");
        }
    }
    // Shifted by the full-resolution disparity instead, the views disagree.
    let wrong = make_sample(&scene, &draw(d), 8, 0, &StackInput::Views);
    assert!(max_diff(&wrong.stacks[0][..len], &wrong.stacks[0][2 * len..3 * len]) > 0.1);
}

#[test]
fn target_rotation_follows_the_views() {
    let scene = TwoPlanes {
        centre: (4.0, -3.0),
        ..TwoPlanes::new(3, 16)
    };
    let gt = scene.hci_disparity();
    let rendered = TwoPlanes { turns: 1, ..scene }.hci_disparity();
    assert_eq!(rotate_plane(&gt.data, 16, 16, 1), rendered.data);
}

#[test]
fn random_draws_stay_in_range() {
    let cfg = AugmentConfig::default();
    let mut rng = rand_pcg::Pcg32::new(1, 2);
    for _ in 0..200 {
        // 8 px inside along x (room 24); along y the room (8) allows 4 on each side.
        let d = Draw::random(&cfg, 16, 8, (40, 24), &mut rng);
        assert!((8..=16).contains(&d.origin.0) && d.origin.1 == 4 && d.turns < 4);
        assert_eq!(d.scale, 1, "a 2× crop (32 px) does not fit 24 rows");
        assert!(d.shift.abs() <= 2.0);
    }
    // On a 100 × 70 scene every factor up to 4 fits (4 · 16 = 64 ≤ 70), and each crop stays
    // inside: origin + scale · patch ≤ size.
    let mut seen = [false; 5];
    for _ in 0..400 {
        let d = Draw::random(&cfg, 16, 8, (100, 70), &mut rng);
        seen[d.scale] = true;
        assert!(d.origin.0 + d.scale * 16 <= 100 && d.origin.1 + d.scale * 16 <= 70);
    }
    assert_eq!(seen, [false, true, true, true, true]);
}
