//! Posteriors at chosen pixels, kept for the plots against the true modes (thesis Fig. 5.1).

use std::str::FromStr;

use lfdata::bins::Bins;
use lfdata::metrics::Frame;
use lfdata::prediction::ScenePrediction;
use lfdata::scene_eval::predicted_masses;
use lfdata::truth::{EtaKind, SceneTruth, eta_of};
use serde::Serialize;

/// A pixel asked for on the command line as `SCENE:X,Y`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PixelRequest {
    /// Scene folder name.
    pub scene: String,
    /// Column.
    pub x: usize,
    /// Row from the top.
    pub y: usize,
}

impl FromStr for PixelRequest {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("expected SCENE:X,Y (e.g. scene_0010:64,40), got {s:?}");
        let (scene, xy) = s.rsplit_once(':').ok_or_else(bad)?;
        let (x, y) = xy.split_once(',').ok_or_else(bad)?;
        Ok(Self {
            scene: scene.to_string(),
            x: x.trim().parse().map_err(|_| bad())?,
            y: y.trim().parse().map_err(|_| bad())?,
        })
    }
}

/// One method's distribution at a sampled pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodPosterior {
    /// Method name.
    pub method: String,
    /// Probability of each evaluation bin (before the KLD's `ε`).
    pub masses: Vec<f64>,
    /// The point estimate.
    pub disparity: f64,
}

/// Every method's posterior at one pixel, with the true modes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PosteriorSample {
    /// Scene name.
    pub scene: String,
    /// Column.
    pub x: usize,
    /// Row from the top.
    pub y: usize,
    /// `(disparity, η)` of each true mode, front to back.
    pub modes: Vec<(f64, f64)>,
    /// One entry per method.
    pub methods: Vec<MethodPosterior>,
}

impl PosteriorSample {
    /// The true modes at `(x, y)`, ready for the methods to be added.
    pub fn new(scene: &str, truth: &SceneTruth, (x, y): (usize, usize), eta: EtaKind) -> Self {
        let modes = truth
            .modes
            .pixel(x, y)
            .iter()
            .filter(|m| eta_of(m, eta) > 0.0)
            .map(|m| (f64::from(m.disparity), f64::from(eta_of(m, eta))))
            .collect();
        Self {
            scene: scene.to_string(),
            x,
            y,
            modes,
            methods: Vec::new(),
        }
    }

    /// Adds `method`'s distribution at this pixel.
    pub fn add(&mut self, method: &str, pred: &ScenePrediction, bins: &Bins) {
        let i = self.y * pred.disparity.width + self.x;
        let mut masses = vec![0.0; bins.count];
        predicted_masses(pred, i, bins, &mut masses);
        self.methods.push(MethodPosterior {
            method: method.to_string(),
            masses,
            disparity: pred.disparity.data[i].into(),
        });
    }
}

/// Pixels worth plotting when none are requested: the most clearly bimodal pixel (largest
/// second-strongest `η`) inside the frame, if the scene has one, and the frame's centre.
pub fn auto_pixels(truth: &SceneTruth, frame: &Frame, eta: EtaKind) -> Vec<(usize, usize)> {
    let w = frame.width;
    let second_eta = |i: usize| {
        let mut etas: Vec<f32> = truth
            .modes
            .pixel(i % w, i / w)
            .iter()
            .map(|m| eta_of(m, eta))
            .collect();
        etas.sort_by(|a, b| b.total_cmp(a));
        etas.get(1).copied().unwrap_or(0.0)
    };
    let mut pixels = Vec::new();
    let best = frame
        .indices()
        .map(|i| (i, second_eta(i)))
        .filter(|&(_, e)| e > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
    if let Some((i, _)) = best {
        pixels.push((i % w, i / w));
    }
    if !frame.is_empty() {
        let centre = (frame.width / 2, frame.height / 2);
        if !pixels.contains(&centre) {
            pixels.push(centre);
        }
    }
    pixels
}

#[cfg(test)]
mod tests {
    use super::*;
    use lfformat::pfm::FloatImage;
    use lfformat::{Mode, ModeMap};

    #[test]
    fn pixel_requests_parse() {
        let r: PixelRequest = "scene_0001:12,7".parse().unwrap();
        assert_eq!((r.scene.as_str(), r.x, r.y), ("scene_0001", 12, 7));
        assert!("scene_0001:12".parse::<PixelRequest>().is_err());
        assert!("12,7".parse::<PixelRequest>().is_err());
        assert!("s:a,b".parse::<PixelRequest>().is_err());
    }

    #[test]
    fn auto_pixels_pick_the_most_bimodal_pixel_and_the_centre() {
        let mode = |d: f32, eta: f32| Mode {
            disparity: d,
            depth: 1.0,
            eta,
            eta_exact: eta,
        };
        let mut modes = ModeMap::new(3, 3);
        for i in 0..9 {
            match i {
                1 => modes.push_pixel(&[mode(1.0, 0.8), mode(0.0, 0.2)]),
                5 => modes.push_pixel(&[mode(1.0, 0.6), mode(0.0, 0.4)]),
                _ => modes.push_pixel(&[mode(0.0, 1.0)]),
            }
        }
        let truth = SceneTruth {
            hci: FloatImage::new(3, 3, vec![0.0; 9]),
            modes,
        };
        let frame = Frame::new(3, 3, 0);
        assert_eq!(
            auto_pixels(&truth, &frame, EtaKind::Over),
            vec![(2, 1), (1, 1)]
        );
        let s = PosteriorSample::new("s", &truth, (2, 1), EtaKind::Over);
        assert_eq!(s.modes.len(), 2);
        assert!((s.modes[1].1 - 0.4).abs() < 1e-7);
    }
}
