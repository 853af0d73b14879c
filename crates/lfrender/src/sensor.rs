//! The camera's imaging model: what a real light-field camera adds to the light the renderer
//! computes, so that networks trained on the views also meet sensor noise, lens vignetting and
//! the exposure and white balance of a capture.
//!
//! Off by default: the views are then the clean render, byte for byte. When on, every scene
//! draws one capture ([`SensorSettings::capture`]): an ISO, an exposure error, a white balance
//! and a vignetting strength, shared by all its views, as the lenslets or cameras of one light
//! field share their exposure and optics. The noise is drawn per view and per pixel. Everything
//! is a pure function of the scene's seed and index, the view and the pixel (counter-based
//! hashing), so the result is the same for any thread count.
//!
//! The model works on display-linear values (scene radiance times the exposure, before the
//! tone curve), where 1 is the display white of the `clip` curve:
//!
//! - gain: `2^e · wb`, with the exposure error `e` uniform in ±`exposure_jitter_ev` and the
//!   white balance `wb = (2^r, 1, 2^b)`, `r` and `b` uniform in ±`white_balance_jitter_ev`;
//! - vignetting: the cos⁴ law `v(ρ) = (1 + t² ρ²)^-2` of a lens whose corners (ρ = 1, ρ the
//!   distance from the image centre over the half-diagonal) get `1 − f` of the centre's light,
//!   `t² = (1 − f)^-1/2 − 1`;
//! - noise: Poisson–Gaussian (photon shot noise and read noise) in its usual Gaussian form,
//!   variance `x / N + (r / N)²` at value `x`, where `N = electrons_at_white · 100 / ISO` is the
//!   photo-electrons a pixel collects at value 1 and `r` the read noise in electrons.

use crate::util::hash::{mix64, unit_float};
use anyhow::{Result, bail};
use glam::Vec3;
pub use lfformat::views::CaptureDraw;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The camera model's settings (`[sensor]` of the generator config).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorSettings {
    /// Simulate the camera: noise, vignetting, exposure and white-balance error on the written
    /// views (`--preset camera`). Off: the views are the clean render.
    pub enabled: bool,
    /// The ISO of a scene, drawn log-uniformly from `[min, max]`; noise grows with it.
    pub iso: [f64; 2],
    /// Photo-electrons a pixel collects at display white (linear 1 after exposure) at ISO 100;
    /// at ISO `k` it collects `100 / k` of them.
    pub electrons_at_white: f64,
    /// Read noise of the sensor, in electrons.
    pub read_noise: f64,
    /// The share of light lost at the image corners by vignetting (cos⁴ law), drawn uniformly
    /// per scene from `[min, max]`; 0 is none.
    pub vignetting: [f64; 2],
    /// Exposure error per scene: a gain of `2^e`, `e` uniform in ±this many stops.
    pub exposure_jitter_ev: f64,
    /// White-balance error per scene: red and blue gains of `2^r`, `2^b`, each uniform in
    /// ±this many stops (green kept).
    pub white_balance_jitter_ev: f64,
    /// Also write the clean views as `clean_CamNNN.png` beside the camera's `input_CamNNN.png`.
    pub write_clean: bool,
}

impl Default for SensorSettings {
    fn default() -> Self {
        Self {
            enabled: false,
            iso: [100.0, 1600.0],
            electrons_at_white: 10_000.0,
            read_noise: 3.0,
            vignetting: [0.0, 0.5],
            exposure_jitter_ev: 0.5,
            white_balance_jitter_ev: 0.15,
            write_clean: false,
        }
    }
}

/// What one scene's views go through: drawn once per scene by [`SensorSettings::capture`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capture {
    /// Exposure error times white balance, per channel.
    pub gain: Vec3,
    /// `t²` of the cos⁴ law (0: no vignetting).
    pub vignetting_t2: f32,
    /// Photo-electrons at value 1 (`N`; infinite: no shot noise).
    pub electrons: f32,
    /// Read noise in units of value 1 (`r / N`).
    pub read_sigma: f32,
    /// Seeds the per-pixel noise.
    pub seed: u64,
    /// The draw in a camera's terms, for the scene's `stats.json`.
    pub draw: CaptureDraw,
}

impl SensorSettings {
    /// Fails naming the first key out of range.
    pub fn validate(&self) -> Result<()> {
        let [lo, hi] = self.iso;
        if !(lo.is_finite() && hi.is_finite() && 1.0 <= lo && lo <= hi && hi <= 1e6) {
            bail!(
                "sensor.iso must be a range [min, max] within 1 to 1e6, got {:?}",
                self.iso
            );
        }
        let [lo, hi] = self.vignetting;
        if !(0.0..1.0).contains(&lo) || !(lo..1.0).contains(&hi) {
            bail!(
                "sensor.vignetting must be a range [min, max] within [0, 1), got {:?}",
                self.vignetting
            );
        }
        let e = self.electrons_at_white;
        if !(e.is_finite() && e > 0.0) {
            bail!("sensor.electrons_at_white must be positive, got {e}");
        }
        let non_negative = [
            ("read_noise", self.read_noise),
            ("exposure_jitter_ev", self.exposure_jitter_ev),
            ("white_balance_jitter_ev", self.white_balance_jitter_ev),
        ];
        for (key, v) in non_negative {
            if !(v.is_finite() && (0.0..=20.0).contains(&v)) {
                bail!("sensor.{key} must lie in [0, 20], got {v}");
            }
        }
        Ok(())
    }

    /// The capture of the scene with dataset seed `seed` and index `index`, or `None` when the
    /// model is off.
    pub fn capture(&self, seed: u64, index: u64) -> Option<Capture> {
        if !self.enabled {
            return None;
        }
        let key = mix64(seed ^ mix64(index ^ 0x5e75_0a11));
        let uniform =
            |k: u64, [lo, hi]: [f64; 2]| lo + (hi - lo) * unit_float(mix64(key ^ mix64(k))) as f64;
        let jitter = |k: u64, ev: f64| uniform(k, [-ev, ev]);
        let draw = CaptureDraw {
            iso: uniform(1, self.iso.map(f64::ln)).exp(),
            exposure_ev: jitter(5, self.exposure_jitter_ev),
            white_balance_ev: [3, 4].map(|k| jitter(k, self.white_balance_jitter_ev)),
            vignetting: uniform(2, self.vignetting),
        };
        let gain = |ev: f64| 2f64.powf(ev) as f32;
        let [red, blue] = draw.white_balance_ev.map(gain);
        let electrons = self.electrons_at_white * 100.0 / draw.iso;
        Some(Capture {
            gain: Vec3::new(red, 1.0, blue) * gain(draw.exposure_ev),
            vignetting_t2: ((1.0 - draw.vignetting).powf(-0.5) - 1.0) as f32,
            electrons: electrons as f32,
            read_sigma: (self.read_noise / electrons) as f32,
            seed: mix64(key ^ 6),
            draw,
        })
    }
}

impl Capture {
    /// The display-linear image the camera records of view `view` (linear radiance `pixels`,
    /// `width` wide, times `exposure`): gain, vignetting, then noise; not clamped (the tone
    /// curve does that).
    pub fn develop(&self, pixels: &[Vec3], width: usize, exposure: f32, view: u32) -> Vec<Vec3> {
        let height = pixels.len() / width.max(1);
        let half_diagonal = 0.5 * ((width * width + height * height) as f32).sqrt();
        let view_key = mix64(self.seed ^ mix64(view as u64));
        let mut out = vec![Vec3::ZERO; pixels.len()];
        out.par_chunks_mut(width.max(1))
            .zip(pixels.par_chunks(width.max(1)))
            .enumerate()
            .for_each(|(y, (row_out, row))| {
                let dy = y as f32 + 0.5 - 0.5 * height as f32;
                for (x, (o, &c)) in row_out.iter_mut().zip(row).enumerate() {
                    let dx = x as f32 + 0.5 - 0.5 * width as f32;
                    let rho2 = (dx * dx + dy * dy) / (half_diagonal * half_diagonal);
                    let signal = c * exposure * self.gain * self.falloff(rho2);
                    let key = mix64(view_key ^ (y * width + x) as u64);
                    *o = Vec3::from(std::array::from_fn(|ch| {
                        self.noisy(signal[ch], key ^ ch as u64)
                    }));
                }
            });
        out
    }

    /// The cos⁴ falloff at squared normalised radius `rho2`.
    pub fn falloff(&self, rho2: f32) -> f32 {
        let s = 1.0 + self.vignetting_t2 * rho2;
        1.0 / (s * s)
    }

    /// The standard deviation of the recorded value at signal `x`.
    pub fn sigma(&self, x: f32) -> f32 {
        (x.max(0.0) / self.electrons + self.read_sigma * self.read_sigma).sqrt()
    }

    /// `x` plus Gaussian noise of [`Capture::sigma`], from the hash `key` (Box–Muller).
    fn noisy(&self, x: f32, key: u64) -> f32 {
        let h = mix64(key);
        let u1 = 1.0 - unit_float(h);
        let u2 = unit_float(mix64(h));
        let z = (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos();
        x + self.sigma(x) * z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(iso: f64) -> SensorSettings {
        SensorSettings {
            enabled: true,
            iso: [iso, iso],
            vignetting: [0.0, 0.0],
            exposure_jitter_ev: 0.0,
            white_balance_jitter_ev: 0.0,
            ..SensorSettings::default()
        }
    }

    /// A flat grey patch: the mean stays the signal and the variance is the model's
    /// `x / N + (r / N)²` (N = 10 000 · 100 / 800 = 1 250 electrons, r = 3), within sampling
    /// bounds of 3 · 256² values.
    #[test]
    fn noise_of_a_flat_patch_has_the_model_mean_and_variance() {
        let cap = flat(800.0).capture(7, 3).unwrap();
        assert_eq!(cap.gain, Vec3::ONE);
        let x = 0.18;
        let (w, n) = (256, 256 * 256);
        let out = cap.develop(&vec![Vec3::splat(x); n], w, 1.0, 0);
        let values: Vec<f64> = out
            .iter()
            .flat_map(|c| c.to_array())
            .map(f64::from)
            .collect();
        let count = values.len() as f64;
        let mean = values.iter().sum::<f64>() / count;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (count - 1.0);
        let want = x as f64 / 1250.0 + (3.0f64 / 1250.0).powi(2);
        // Standard error of the mean: √(var / count); of the variance: var · √(2 / count).
        assert!(
            (mean - x as f64).abs() < 5.0 * (want / count).sqrt(),
            "{mean}"
        );
        assert!(
            (var / want - 1.0).abs() < 5.0 * (2.0 / count).sqrt(),
            "{var} vs {want}"
        );
        // Independent channels and pixels: neighbours are uncorrelated.
        let lag: f64 = values
            .windows(2)
            .map(|p| (p[0] - mean) * (p[1] - mean))
            .sum::<f64>();
        assert!((lag / (count - 1.0) / var).abs() < 5.0 / count.sqrt());
    }

    /// Without noise (N infinite, no read noise) the image is the cos⁴ law: 1 at the centre,
    /// `1 − f` at the corners, `(1 + t²/2)^-2` at the middle of an edge of a square image.
    #[test]
    fn vignetting_follows_the_cos4_law() {
        let lost = 0.4f32;
        let t2 = (1.0 - lost).powf(-0.5) - 1.0;
        let cap = Capture {
            gain: Vec3::ONE,
            vignetting_t2: t2,
            electrons: f32::INFINITY,
            read_sigma: 0.0,
            seed: 1,
            draw: CaptureDraw {
                iso: 100.0,
                exposure_ev: 0.0,
                white_balance_ev: [0.0; 2],
                vignetting: lost.into(),
            },
        };
        let w = 201;
        let out = cap.develop(&vec![Vec3::ONE; w * w], w, 1.0, 0);
        let at = |x: usize, y: usize| out[y * w + x].x;
        assert!((at(100, 100) - 1.0).abs() < 1e-6);
        // Pixel centres: the corner pixel sits 200/201 of the half-diagonal out.
        let corner = cap.falloff((200.0f32 / 201.0).powi(2));
        assert!((at(0, 0) - corner).abs() < 1e-6 && (at(200, 200) - corner).abs() < 1e-6);
        assert!((cap.falloff(1.0) - (1.0 - lost)).abs() < 1e-6);
        let edge = (1.0 + t2 * 0.5 * (200.0f32 / 201.0).powi(2)).powi(-2);
        assert!((at(100, 0) - edge).abs() < 1e-5, "{} vs {edge}", at(100, 0));
    }

    /// The same scene and view give the same values on 1 and on 4 threads; another view or
    /// another scene other noise.
    #[test]
    fn noise_is_a_function_of_scene_view_and_pixel_only() {
        let s = SensorSettings {
            enabled: true,
            ..SensorSettings::default()
        };
        let pixels: Vec<Vec3> = (0..64 * 48)
            .map(|i| Vec3::splat(i as f32 / 3072.0))
            .collect();
        let run = |threads: usize, index: u64, view: u32| {
            let cap = s.capture(901, index).unwrap();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| cap.develop(&pixels, 64, 0.7, view))
        };
        let one = run(1, 2, 5);
        assert_eq!(one, run(4, 2, 5));
        assert_ne!(one, run(1, 2, 6));
        assert_ne!(one, run(1, 3, 5));
        assert!(SensorSettings::default().capture(901, 2).is_none());
    }

    /// Draws stay inside their ranges, and the ISO range spreads the electron counts.
    #[test]
    fn captures_draw_within_the_configured_ranges() {
        let s = SensorSettings {
            enabled: true,
            ..SensorSettings::default()
        };
        let caps: Vec<Capture> = (0..200).map(|i| s.capture(0, i).unwrap()).collect();
        for c in &caps {
            assert!((625.0..=10_000.0).contains(&c.electrons), "{}", c.electrons);
            let lost = 1.0 - c.falloff(1.0);
            assert!((-1e-6..=0.5 + 1e-6).contains(&lost), "{lost}");
            let ev = c.gain.y.log2();
            assert!(ev.abs() <= 0.5 + 1e-5);
            assert!((c.gain.x / c.gain.y).log2().abs() <= 0.15 + 1e-5);
        }
        let low = caps.iter().filter(|c| c.electrons > 2_500.0).count();
        // log-uniform over 4 stops: half the scenes above ISO 400.
        assert!((70..=130).contains(&low), "{low}");
    }

    #[test]
    fn out_of_range_settings_are_refused_by_name() {
        let bad = SensorSettings {
            vignetting: [0.2, 1.0],
            ..SensorSettings::default()
        };
        let err = bad.validate().unwrap_err().to_string();
        assert!(err.contains("sensor.vignetting"), "{err}");
        let bad = SensorSettings {
            electrons_at_white: 0.0,
            ..SensorSettings::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("electrons_at_white")
        );
        SensorSettings::default().validate().unwrap();
    }
}
