//! EPI-Shift (thesis chapter 4): the losses against hand-computed values, the shift
//! invariance the method rests on and the inference range (the overfitting run is in
//! `epishift_overfit.rs`).

use burn::prelude::*;
use burn::tensor::TensorData;
use lftrain::config::{ClassTarget, EpiShiftConfig};
use lftrain::epishift::EpiShiftNet;
use lftrain::run::seeded;
use lftrain::shift_loss::{ShiftTargets, epishift_loss};
use lftrain::shift_predict::{ShiftMaps, run_shifts, scene_shifts};
use lftrain::synthetic::TwoPlanes;
use lftrain::tensors::tensor4;

fn device() -> Device {
    Device::default()
}

/// One crop of 1×2 pixels at the shifts -1, 0, 1. Pixel 0: `D_true = 0.3`; pixel 1:
/// `D_true = -0.6`, clipped at shift +1.
fn hand_case(dev: &Device) -> (Tensor<4>, Tensor<4>, ShiftTargets) {
    let class = tensor4(vec![0.1, 0.6, 0.7, 0.2, 0.2, 0.9], [1, 3, 1, 2], dev);
    let reg = tensor4(vec![0.5, 0.3, 0.1, 0.0, -0.4, 0.2], [1, 3, 1, 2], dev);
    let t = ShiftTargets {
        disparity: tensor4(vec![0.3, -0.6], [1, 1, 1, 2], dev),
        mask: tensor4(vec![1.0, 1.0, 1.0, 1.0, 1.0, 0.0], [1, 3, 1, 2], dev),
        shifts: Tensor::from_data(TensorData::new(vec![-1.0f32, 0.0, 1.0], [1, 3, 1, 1]), dev),
        pixels: 2.0,
    };
    (class, reg, t)
}

#[test]
fn losses_match_hand_computed_values() {
    let dev = device();
    // Final estimates (eq. 4.6): pixel 0 peaks at s = 0, D = 0 + 0.1, W = (0.1 - 0.3)² = 0.04;
    // pixel 1 peaks at s = +1 (its clipped shift still decides D), D = 1.2, W = 1.8² = 3.24.
    // Rectangle, ε = 0.17 (|d - s| ≤ 0.67): pixel 0 targets (0, 1, 0), pixel 1 (1, 1, ·).
    // L_class = 0.04 (0.1² + 0.3² + 0.2²) + 3.24 (0.4² + 0.8²) = 0.0056 + 2.592.
    // L_reg, ε' = 0.25 (|d - s| ≤ 0.75): pixel 0 at s = 0: |0.1 - 0.3|, at s = 1: |-0.4 + 0.7|;
    // pixel 1 at s = -1: |0.3 - 0.4|, at s = 0: |0.0 + 0.6|: 0.2 + 0.3 + 0.1 + 0.6 = 1.2.
    // L = (2.5 · 1.2 + 2.5976) / 2 pixels.
    let cfg = EpiShiftConfig::default();
    let (class, reg, t) = hand_case(&dev);
    let l = epishift_loss(&cfg, class, reg, &t).into_scalar::<f32>();
    assert!((l - 2.7988).abs() < 1e-5, "{l}");
    // Triangle (eq. 4.8): targets max(0.67 - |d - s|, 0): (0, 0.37, 0) and (0.27, 0.07, ·).
    // L_class = 0.04 (0.01 + 0.33² + 0.04) + 3.24 (0.33² + 0.13²) = 0.006356 + 0.407592.
    let tri = EpiShiftConfig {
        class_target: ClassTarget::Triangle,
        ..cfg.clone()
    };
    let (class, reg, t) = hand_case(&dev);
    let l = epishift_loss(&tri, class, reg, &t).into_scalar::<f32>();
    assert!((l - (3.0 + 0.413948) / 2.0).abs() < 1e-5, "{l}");
    // α = 0 leaves the classification part alone.
    let no_reg = EpiShiftConfig { alpha: 0.0, ..cfg };
    let (class, reg, t) = hand_case(&dev);
    let l = epishift_loss(&no_reg, class, reg, &t).into_scalar::<f32>();
    assert!((l - 2.5976 / 2.0).abs() < 1e-5, "{l}");
}

/// A small network: one feature block of 4 channels, a U-Net of width 4 and depth 1.
fn tiny(depth: usize) -> EpiShiftConfig {
    EpiShiftConfig {
        feature_width: 4,
        feature_blocks: 1,
        unet_width: 4,
        unet_depth: depth,
        ..EpiShiftConfig::default()
    }
}

#[test]
fn an_integer_shift_of_the_input_moves_the_classification_peak_by_as_much() {
    // Scene B is scene A with every disparity raised by k: B^{s+k} = A^s exactly, so any
    // network's C^{s+k} on B equals C^s on A (away from the image border, where the clipping
    // differs and the receptive field reaches it), and the per-pixel peak moves by k.
    let dev = device();
    let cfg = tiny(1);
    let net = seeded(&dev, 7, || EpiShiftNet::new(&cfg, 15, &dev));
    let a = TwoPlanes::new(5, 72);
    let k = 2;
    let b = TwoPlanes {
        back: a.back + k as f32,
        front: a.front + k as f32,
        ..a
    };
    let shifts: Vec<i32> = (-2..=2).collect();
    let moved: Vec<i32> = shifts.iter().map(|s| s + k).collect();
    let ma = run_shifts(&net, &a.render(), &shifts, 1, &dev);
    let mb = run_shifts(&net, &b.render(), &moved, 1, &dev);
    let peak = |m: &ShiftMaps, i: usize| {
        let best = (0..m.shifts.len())
            .max_by(|&p, &q| m.class[p][i].total_cmp(&m.class[q][i]))
            .unwrap();
        m.shifts[best]
    };
    // Reach of the outer views at |s| = 5 (2 · 6 px) plus the receptive radius (< 20 px).
    let margin = 30;
    let mut checked = 0;
    let mut worst = 0.0f32;
    for y in margin..72 - margin {
        for x in margin..72 - margin {
            let i = y * 72 + x;
            for j in 0..shifts.len() {
                let (ca, cb) = (ma.class[j][i], mb.class[j][i]);
                worst = worst.max((ca - cb).abs());
            }
            assert_eq!(peak(&mb, i), peak(&ma, i) + k, "peak at ({x}, {y})");
            checked += 1;
        }
    }
    assert_eq!(checked, 12 * 12);
    // An untrained net's C varies little between shifts (≈1e-4 here), so the checks are
    // relative to that variation: the interior agrees to float rounding, the clipped corner
    // does not (the borders really differ: this is not a tautology of the test).
    let centre = 36 * 72 + 36;
    let column: Vec<f32> = ma.class.iter().map(|c| c[centre]).collect();
    let spread = column.iter().fold(f32::MIN, |a, &b| a.max(b))
        - column.iter().fold(f32::MAX, |a, &b| a.min(b));
    let corner = (0..shifts.len())
        .map(|j| (ma.class[j][0] - mb.class[j][0]).abs())
        .fold(0.0, f32::max);
    eprintln!("C spread over shifts {spread}, interior difference {worst}, corner {corner}");
    assert!(
        spread > 0.0 && worst <= 1e-3 * spread,
        "{worst} vs {spread}"
    );
    assert!(
        corner > 0.01 * spread,
        "the clipped corner should differ: {corner}"
    );
}

#[test]
fn inference_shifts_cover_the_range_of_parameters_cfg() {
    let dir = tempfile::tempdir().unwrap();
    let scene = TwoPlanes {
        back: -6.0,
        front: 5.0,
        ..TwoPlanes::new(3, 16)
    };
    scene.write(dir.path(), false).unwrap();
    let lf = lfdata::lightfield::LightField::load_star(dir.path()).unwrap();
    // HCI writes the range widened: [-6.1, 5.1].
    let r = lf.disparity_range.unwrap();
    assert!(
        (r[0] + 6.1).abs() < 1e-5 && (r[1] - 5.1).abs() < 1e-5,
        "{r:?}"
    );
    let cfg = EpiShiftConfig::default();
    assert_eq!(scene_shifts(&cfg, &lf), (-6..=5).collect::<Vec<_>>());
    // A configured range wins.
    let fixed = EpiShiftConfig {
        range: Some([-1.0, 1.0]),
        ..cfg
    };
    assert_eq!(scene_shifts(&fixed, &lf), vec![-1, 0, 1]);
}
