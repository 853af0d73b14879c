//! `lfgen bench speed`: throughput of the ray queries and the cost of the 128-slice ground
//! truth, as ratios measured in one run (absolute figures on a shared machine are noise);
//! `lfgen bench quality`: the views' error against a converged render. Both print their figures
//! and return them as data for the results file (`lfformat::results`).

use crate::config::{Config, ShadingMode};
use crate::output::images::{ToneCurve, write_linear_exr, write_png};
use crate::pipeline::{RenderJob, generate_scene};
use crate::render::RenderScene;
use crate::render::framing::auto_exposure;
use crate::render::integrator::Shading;
use crate::render::view::{Adaptive, RenderSettings};
use anyhow::{Context, Result};
use glam::Vec3;
use rayon::prelude::*;
use serde_json::{Value, json};
use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// Image side of the benchmark view: big enough for stable timings, small enough for seconds.
const BENCH_RES: u32 = 192;

/// Runs the speed benchmark on scene 0 of `cfg` (resolution fixed to 192², other settings as
/// given) and returns its figures.
pub fn speed(cfg: &Config) -> Result<Value> {
    let mut cfg = cfg.clone();
    cfg.camera.resolution = [BENCH_RES, BENCH_RES];
    let (desc, scene) = generate_scene(&cfg, 0, None)?;
    let cam = &desc.camera;
    lfformat::say!(
        "scene: {} triangles, {} threads, {}x{} px, {} spp, max depth {}, {} BVH kernel",
        scene.geometry.triangle_count(),
        rayon::current_num_threads(),
        BENCH_RES,
        BENCH_RES,
        cfg.render.spp,
        cfg.render.max_depth,
        scene.geometry.kernel().name()
    )?;
    let rays = cam.view_rays(cam.center_view());
    let pixels: Vec<(u32, u32)> = (0..BENCH_RES)
        .flat_map(|y| (0..BENCH_RES).map(move |x| (x, y)))
        .collect();
    let camera: Vec<(Vec3, Vec3)> = pixels
        .iter()
        .map(|&(x, y)| {
            let r = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            (r.origin, r.dir)
        })
        .collect();
    let mut figures = json!({
        "threads": rayon::current_num_threads(),
        "size": BENCH_RES,
        "spp": cfg.render.spp,
        "kernel": scene.geometry.kernel().name(),
    });
    traversal(&scene, camera, &mut figures)?;
    let job = RenderJob::from_config(&cfg, "");
    let settings = job.render.view_settings(&desc);
    let counter = AtomicU64::new(0);
    // The configured shading's cache, filled once (its cost is the scene's, not the GT's).
    let cache = (job.render.shading == ShadingMode::Shared)
        .then(|| scene.fill_shared_cache(cam, &job.render, &settings, &counter));
    let configured = cache.as_ref().map_or(Shading::Independent, Shading::read);
    let samples = (pixels.len() as u64 * cfg.render.spp as u64) as f64;
    let mut ratio = 0.0;
    let configured_name = format!("{:?}", job.render.shading).to_lowercase();
    let rows = [
        ("independent", Shading::Independent),
        (&configured_name, configured),
    ];
    for (name, shading) in rows {
        let render = |gt: bool| {
            time(|| {
                let view = cam.center_view();
                drop(scene.render_view_with(
                    cam,
                    &desc.slices,
                    &settings,
                    view,
                    gt,
                    shading,
                    &counter,
                ))
            })
        };
        // Alternate and keep the best of three to damp the noise of a shared machine.
        let (mut colour, mut with_gt) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..3 {
            colour = colour.min(render(false));
            with_gt = with_gt.min(render(true));
        }
        lfformat::say!(
            "{name} shading: colour only {colour:.3} s ({:.0} camera samples/s); colour + \
             {}-slice GT {with_gt:.3} s ({:.0} camera samples/s): ratio {:.3}",
            samples / colour,
            cfg.render.slices,
            samples / with_gt,
            with_gt / colour
        )?;
        ratio = with_gt / colour;
        figures[format!("{name}_colour_s")] = json!(colour);
        figures[format!("{name}_with_gt_s")] = json!(with_gt);
    }
    lfformat::say!("gt_overhead_ratio: {ratio:.3}")?;
    figures["gt_overhead_ratio"] = json!(ratio);
    Ok(figures)
}

/// Repetitions of every query in [`traversal`], so each timing covers well over a second.
const REPS: u32 = 8;

/// Mrays/s of each kind of query the renderer makes, into `figures`: closest hits and all
/// hits (the ground truth's query) of the camera rays, the most coherent rays there are;
/// closest hits of cosine-distributed rays from the camera rays' first surfaces (the path's
/// incoherent bounces); and shadow rays from those surfaces to a sampled point on a light
/// (the renderer's fixed probe rays, [`RenderScene::probe_rays`]).
fn traversal(scene: &RenderScene, camera: Vec<(Vec3, Vec3)>, figures: &mut Value) -> Result<()> {
    let probe = scene.probe_rays(camera);
    let closest = |rays: &[(Vec3, Vec3)]| {
        time(|| {
            rays.par_iter().for_each(|&(o, d)| {
                for k in 0..REPS {
                    black_box(scene.probe_closest(o, d, k));
                }
            })
        })
    };
    let coherent = closest(&probe.camera);
    let all = time(|| {
        probe
            .camera
            .par_iter()
            .for_each_init(Vec::new, |hits, &(o, d)| {
                for _ in 0..REPS {
                    scene.geometry.all_hits(o, d, f32::INFINITY, hits);
                    black_box(hits.len());
                }
            })
    });
    let incoherent = closest(&probe.bounces);
    let rays = probe.camera.len();
    let label = "closest hit, camera rays (stochastic opacity)";
    rate(figures, "closest_mrays_per_s", label, rays, coherent)?;
    let label = "all hits, camera rays (anyhit + sort + dedupe)";
    rate(figures, "all_hits_mrays_per_s", label, rays, all)?;
    let label = "closest hit, cosine bounces from the first surfaces";
    let (name, bounces) = ("incoherent_closest_mrays_per_s", probe.bounces.len());
    rate(figures, name, label, bounces, incoherent)?;
    figures["all_hits_cost_ratio"] = json!(all / coherent);
    lfformat::say!("all_hits_cost_ratio: {:.3}", all / coherent)?;
    if probe.shadows.is_empty() {
        return Ok(lfformat::say!(
            "shadow rays: the scene has no emissive surface to aim at"
        )?);
    }
    let shadow = time(|| {
        probe.shadows.par_iter().for_each(|&(o, d, t)| {
            for _ in 0..REPS {
                black_box(scene.probe_shadow(o, d, t));
            }
        })
    });
    let label = "shadow rays to a light sample (any hit, early exit)";
    rate(
        figures,
        "shadow_mrays_per_s",
        label,
        probe.shadows.len(),
        shadow,
    )
}

/// Records and prints the rate of `rays` queries, each repeated [`REPS`] times, in `seconds`.
fn rate(figures: &mut Value, name: &str, label: &str, rays: usize, seconds: f64) -> Result<()> {
    let mrays = (rays * REPS as usize) as f64 / seconds / 1e6;
    figures[name] = json!(mrays);
    Ok(lfformat::say!("{label}: {mrays:.2} Mrays/s")?)
}

fn time(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

/// Samples per pixel of the converged independent reference (two halves of its own seeds).
const REFERENCE_SPP: u32 = 1024;
/// Salt of the reference halves' seeds (the scene seed's), so they share no samples with the
/// renders they score.
const REFERENCE_SALT: u64 = 0x2EF0;

/// `lfgen bench quality`: for built-in scenes `scenes` at `size`², the centre view of the
/// configured settings, shared and independent side by side, against a converged independent
/// render: PSNR, the photo-consistency residual of the adjacent view, and the time. Returns
/// the table's rows as figures.
pub fn quality(cfg: &Config, scenes: &[u64], size: u32, images: Option<&Path>) -> Result<Value> {
    if let Some(dir) = images {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut cfg = cfg.clone();
    cfg.camera.resolution = [size, size];
    lfformat::say!(
        "scene | shading | PSNR linear dB: vs reference (vs truth) | PSNR 8-bit dB: vs reference \
         (vs truth) | photo residual (8-bit levels) | s per scene | per-view noise share: \
         linear / 8-bit | pixels given adaptive samples | cache noise share: linear / 8-bit"
    )?;
    let mut rows = Vec::new();
    for &index in scenes {
        let (desc, scene) = generate_scene(&cfg, index, None)?;
        let cam = &desc.camera;
        let center = cam.center_view();
        let counter = AtomicU64::new(0);
        let mut job = RenderJob::from_config(&cfg, "");
        // The reference from its own seeds, as two halves: their difference measures its noise.
        let converged = |salt: u64, spp: u32| RenderSettings {
            spp,
            gt_spp: spp,
            seed: desc.seed ^ salt,
            adaptive: Adaptive::default(),
            ..job.render.view_settings(&desc)
        };
        let [a, b] = [REFERENCE_SALT, REFERENCE_SALT + 1].map(|salt| {
            let s = converged(salt, REFERENCE_SPP / 2);
            scene.render_view(
                cam,
                &desc.slices,
                &s,
                center,
                salt == REFERENCE_SALT,
                &counter,
            )
        });
        let (a_px, b_px) = (&a.image.pixels, &b.image.pixels);
        let reference: Vec<Vec3> = a_px
            .iter()
            .zip(b_px)
            .map(|(x, y)| (*x + *y) * 0.5)
            .collect();
        let exposure = desc.exposure * auto_exposure(&reference);
        let tone = cfg.render.tone_curve;
        // Linear and 8-bit mean squared differences of two images.
        let mse =
            |a: &[Vec3], b: &[Vec3]| [mse_linear(a, b, exposure), mse_8bit(a, b, exposure, tone)];
        let own_noise = mse(a_px, b_px).map(reference_noise);
        // PSNR against the reference and (estimated) against the truth, linear and 8-bit.
        let score = |mse: [f64; 2]| {
            let peak = [1.0, 255.0 * 255.0];
            let psnr = |k: usize, mse: f64| 10.0 * (peak[k] / mse).log10();
            [0, 1].map(|k| [psnr(k, mse[k]), psnr(k, mse_to_truth(mse[k], own_noise[k]))])
        };
        let [w, h] = cam.resolution.map(|n| n as usize);
        let write = |name: &str, pixels: &[Vec3]| -> Result<()> {
            let Some(dir) = images else { return Ok(()) };
            let path = dir.join(format!("scene{index}_{name}"));
            write_linear_exr(&path.with_extension("exr"), w, h, pixels)?;
            write_png(&path.with_extension("png"), w, h, pixels, exposure, tone)
        };
        write("reference", &reference)?;
        let gt = a.gt.as_ref().expect("the reference has GT");
        let disparity: Vec<f32> = (gt.hci.depth.iter())
            .map(|&z| cam.disparity(z as f64) as f32)
            .collect();
        // The residual of two converged views: its floor, from resampling alone (texture detail
        // finer than a pixel does not survive the bilinear lookup of the shifted view).
        let adjacent = scene.render_view(
            cam,
            &desc.slices,
            &converged(REFERENCE_SALT, REFERENCE_SPP),
            center + 1,
            false,
            &counter,
        );
        let floor = photo_residual(
            &reference,
            &adjacent.image.pixels,
            &disparity,
            &gt.modes,
            [w, h],
            exposure,
            tone,
        );
        let [own_linear, own_8bit] = [10.0 * (1.0 / own_noise[0]).log10(), {
            10.0 * (255.0f64 * 255.0 / own_noise[1]).log10()
        }];
        lfformat::say!(
            "{index} | converged ({REFERENCE_SPP} spp) | ({own_linear:.1}) | ({own_8bit:.1}) | \
             {floor:.2} | –"
        )?;
        rows.push(json!({
            "scene": index,
            "shading": "converged",
            "psnr_linear_truth": own_linear,
            "psnr_8bit_truth": own_8bit,
            "photo_residual": floor,
        }));
        for shading in [ShadingMode::Shared, ShadingMode::Independent] {
            job.render.shading = shading;
            let mut settings = job.render.view_settings(&desc);
            // As in a dataset: adaptive sampling's noise in the final exposure's display units.
            settings.adaptive.display_scale = exposure;
            let started = Instant::now();
            let cache = (shading == ShadingMode::Shared)
                .then(|| scene.fill_shared_cache(cam, &job.render, &settings, &counter));
            let fill = started.elapsed().as_secs_f64();
            let mode = cache.as_ref().map_or(Shading::Independent, Shading::read);
            let render = |settings: &RenderSettings, view| {
                let t = Instant::now();
                let out = scene.render_view_with(
                    cam,
                    &desc.slices,
                    settings,
                    view,
                    false,
                    mode,
                    &counter,
                );
                (out.image, t.elapsed().as_secs_f64())
            };
            let (c, t_view) = render(&settings, center);
            let refined = 100.0 * c.refined as f64 / c.pixels.len() as f64;
            let c = c.pixels;
            let (adjacent, _) = render(&settings, center + 1);
            let adjacent = adjacent.pixels;
            let scene_s = fill + t_view * cam.num_views() as f64;
            write(&format!("{shading:?}").to_lowercase(), &c)?;
            let to_reference = mse(&c, &reference);
            let [linear, eight_bit] = score(to_reference);
            let shown =
                |[vs_reference, vs_truth]: [f64; 2]| format!("{vs_reference:.1} ({vs_truth:.1})");
            // The centre view again from other camera seeds but the same cache: the two
            // differ only by the noise that is the view's own.
            let seed = settings.seed ^ PER_VIEW_SALT;
            let (again, _) = render(&RenderSettings { seed, ..settings }, center);
            let again = again.pixels;
            write(&format!("{shading:?}_again").to_lowercase(), &again)?;
            let share = |between: [f64; 2], k: usize| {
                let to_truth = mse_to_truth(to_reference[k], own_noise[k]);
                100.0 * noise_share(between[k], to_truth)
            };
            let per_view = mse(&c, &again);
            // The centre view again from the same camera seeds but a cache filled from other
            // seeds: the two differ by the cache's noise alone; what neither noise explains is
            // the cache's bias (its blur over a cell, the fit of the shared lobes).
            let cache_share = match &cache {
                None => None,
                Some(_) => {
                    let fill = RenderSettings {
                        seed: settings.seed ^ CACHE_SALT,
                        ..settings
                    };
                    let other = scene.fill_shared_cache(cam, &job.render, &fill, &counter);
                    let out = scene.render_view_with(
                        cam,
                        &desc.slices,
                        &settings,
                        center,
                        false,
                        Shading::read(&other),
                        &counter,
                    );
                    write("shared_other_cache", &out.image.pixels)?;
                    let between = mse(&c, &out.image.pixels);
                    Some([share(between, 0), share(between, 1)])
                }
            };
            let residual =
                photo_residual(&c, &adjacent, &disparity, &gt.modes, [w, h], exposure, tone);
            let per_view = [share(per_view, 0), share(per_view, 1)];
            let cache_shown =
                cache_share.map_or("–".to_owned(), |[l, e]| format!("{l:.0} % / {e:.0} %"));
            lfformat::say!(
                "{index} | {shading:?} | {} | {} | {residual:.2} | {scene_s:.1} | {:.0} % / {:.0} % \
                 | {refined:.1} % | {cache_shown}",
                shown(linear),
                shown(eight_bit),
                per_view[0],
                per_view[1],
            )?;
            rows.push(json!({
                "scene": index,
                "shading": format!("{shading:?}").to_lowercase(),
                "psnr_linear": linear[0],
                "psnr_linear_truth": linear[1],
                "psnr_8bit": eight_bit[0],
                "psnr_8bit_truth": eight_bit[1],
                "photo_residual": residual,
                "seconds_per_scene": scene_s,
                "per_view_noise_share_pct": per_view,
                "adaptive_pixels_pct": refined,
                "cache_noise_share_pct": cache_share,
            }));
        }
    }
    Ok(json!({ "size": size, "spp": cfg.render.spp, "rows": rows }))
}

/// Salt of the second render of a view that measures its own noise ([`noise_share`]).
const PER_VIEW_SALT: u64 = 0x005E_C04D;

/// Salt of the second cache's fill seeds, which measures the cache's noise ([`noise_share`]).
const CACHE_SALT: u64 = 0x00CA_C4E5;

/// The share of a render's error against the truth that is one source's noise, from the
/// squared difference of two renders that differ only in that source's seeds: they differ by
/// twice its variance, and the rest of the error is common to both. Shared shading's two
/// renders of a view read the same cache for its per-view noise (the rest, the cache's noise
/// and bias, is common to every view), and the same camera seeds with caches of their own for
/// the cache's noise.
fn noise_share(mse_between_renders: f64, mse_vs_truth: f64) -> f64 {
    (mse_between_renders / 2.0 / mse_vs_truth).min(1.0)
}

/// The reference's own mean squared error against the truth, from the squared difference
/// of its two independent halves: each half has twice the variance of their mean, and they
/// differ by the sum of theirs, four times it.
fn reference_noise(mse_between_halves: f64) -> f64 {
    mse_between_halves / 4.0
}

/// An image's mean squared error against the truth, from its error against a noisy but
/// unbiased reference of independent noise `reference_noise`: the two add up. Never below a
/// thousandth of the measured error (a noisy estimate may subtract more than is there).
fn mse_to_truth(mse_vs_reference: f64, reference_noise: f64) -> f64 {
    (mse_vs_reference - reference_noise).max(1e-3 * mse_vs_reference)
}

/// Mean squared error of exposure-scaled linear radiance (PSNR peak 1: display white).
fn mse_linear(a: &[Vec3], reference: &[Vec3], exposure: f32) -> f64 {
    (a.iter().zip(reference))
        .map(|(&x, &r)| ((x - r) * exposure).length_squared() as f64 / 3.0)
        .sum::<f64>()
        / a.len() as f64
}

/// Mean squared error of the 8-bit images the PNGs hold.
fn mse_8bit(a: &[Vec3], reference: &[Vec3], exposure: f32, tone: ToneCurve) -> f64 {
    let (a, r) = (tone.encode(a, exposure), tone.encode(reference, exposure));
    (a.iter().zip(&r))
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64
}

/// Mean 8-bit difference between the centre view and the adjacent view (one column to the
/// right) sampled where the centre's GT disparity puts the same point (`x − d`, bilinear), over
/// single-mode pixels whose 3×3 neighbourhood lies within 0.1 px of their disparity (away from
/// depth edges, where the two views see the same surface).
fn photo_residual(
    center: &[Vec3],
    adjacent: &[Vec3],
    disparity: &[f32],
    modes: &lfformat::ModeMap,
    [w, h]: [usize; 2],
    exposure: f32,
    tone: ToneCurve,
) -> f64 {
    let (c8, a8) = (
        tone.encode(center, exposure),
        tone.encode(adjacent, exposure),
    );
    let px = |img: &[u8], x: usize, y: usize, ch: usize| img[(y * w + x) * 3 + ch] as f64;
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let d = disparity[y * w + x];
            let flat = (0..9).all(|k| {
                let dn = disparity[(y + k / 3 - 1) * w + x + k % 3 - 1];
                (dn - d).abs() < 0.1
            });
            let xs = x as f32 - d;
            if !flat || modes.pixel(x, y).len() != 1 || xs < 0.0 || xs >= (w - 1) as f32 {
                continue;
            }
            let (x0, f) = (xs.floor() as usize, (xs - xs.floor()) as f64);
            for ch in 0..3 {
                let s = px(&a8, x0, y, ch) * (1.0 - f) + px(&a8, x0 + 1, y, ch) * f;
                sum += (s - px(&c8, x, y, ch)).abs();
            }
            n += 3;
        }
    }
    sum / n.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Against independent truth: a constant image, a reference made of two halves with
    /// uniform noise, and a test image with noise of known variance.
    #[test]
    fn the_error_against_the_truth_is_recovered_from_a_noisy_reference() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let n = 200_000;
        let truth = Vec3::splat(0.5);
        // U(−a, a) has variance a²/3.
        let mut noisy = |a: f32| -> Vec<Vec3> {
            (0..n)
                .map(|_| truth + Vec3::splat(rng.random_range(-a..a)))
                .collect()
        };
        let (half_a, half_b) = (noisy(0.2), noisy(0.2));
        let test = noisy(0.1);
        let reference: Vec<Vec3> = (half_a.iter().zip(&half_b))
            .map(|(a, b)| (*a + *b) * 0.5)
            .collect();
        let own = reference_noise(mse_linear(&half_a, &half_b, 1.0));
        assert!((own - 0.04 / 3.0 / 2.0).abs() < 1e-4, "{own}");
        let measured = mse_linear(&test, &reference, 1.0);
        let recovered = mse_to_truth(measured, own);
        let exact = 0.01 / 3.0;
        assert!(
            (recovered - exact).abs() < 0.02 * exact,
            "{recovered} vs {exact}"
        );
        assert!(
            measured > 2.0 * exact,
            "the uncorrected error is far off: {measured}"
        );
    }

    /// Two renders with a common error (a fixed offset per pixel, as a shared cache's) and
    /// noise of their own: the noise's share of the error is recovered.
    #[test]
    fn the_per_view_share_of_the_error_is_recovered() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let n = 200_000;
        let common: Vec<f32> = (0..n).map(|_| rng.random_range(-0.1f32..0.1)).collect();
        let mut render = || -> Vec<Vec3> {
            (common.iter())
                .map(|&c| Vec3::splat(0.5 + c + rng.random_range(-0.2f32..0.2)))
                .collect()
        };
        let (a, b) = (render(), render());
        let truth = vec![Vec3::splat(0.5); n];
        // Per-view variance 0.04 / 3, common 0.01 / 3: the noise is 80 % of the error.
        let share = noise_share(mse_linear(&a, &b, 1.0), mse_linear(&a, &truth, 1.0));
        assert!((share - 0.8).abs() < 0.01, "{share}");
        assert_eq!(noise_share(2.0, 0.5), 1.0, "never above the whole error");
    }
}
