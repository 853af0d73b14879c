//! `lfgen bench`: throughput of the ray queries and the cost of the 128-slice ground truth,
//! as ratios measured in one run (absolute figures on a shared machine are noise).

use crate::config::Config;
use crate::pipeline::{RenderJob, generate_scene};
use anyhow::Result;
use rayon::prelude::*;
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// Image side of the benchmark view: big enough for stable timings, small enough for seconds.
const BENCH_RES: u32 = 192;

/// Runs the benchmark on scene 0 of `cfg` (resolution fixed to 192², other settings as given).
pub fn run(cfg: &Config) -> Result<()> {
    let mut cfg = cfg.clone();
    cfg.camera.resolution = [BENCH_RES, BENCH_RES];
    let (desc, scene) = generate_scene(&cfg, 0, None)?;
    let cam = &desc.camera;
    println!(
        "scene: {} triangles, {} threads, {}x{} px, {} spp, max depth {}",
        scene.geometry.triangle_count(),
        rayon::current_num_threads(),
        BENCH_RES,
        BENCH_RES,
        cfg.render.spp,
        cfg.render.max_depth
    );
    let rays = cam.view_rays(cam.center_view());
    let pixels: Vec<(u32, u32)> = (0..BENCH_RES)
        .flat_map(|y| (0..BENCH_RES).map(move |x| (x, y)))
        .collect();
    let reps = 8;
    let closest = time(|| {
        pixels.par_iter().for_each(|&(x, y)| {
            let r = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            for k in 0..reps {
                std::hint::black_box(scene.geometry.closest(
                    &scene.materials,
                    r.origin,
                    r.dir,
                    f32::INFINITY,
                    k,
                ));
            }
        })
    });
    let all = time(|| {
        pixels.par_iter().for_each_init(Vec::new, |hits, &(x, y)| {
            let r = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
            for _ in 0..reps {
                scene
                    .geometry
                    .all_hits(r.origin, r.dir, f32::INFINITY, hits);
                std::hint::black_box(hits.len());
            }
        })
    });
    let n = (pixels.len() * reps as usize) as f64;
    println!(
        "closest hit (stochastic opacity): {:.2} Mrays/s",
        n / closest / 1e6
    );
    println!(
        "all hits (anyhit + sort + dedupe): {:.2} Mrays/s",
        n / all / 1e6
    );
    println!("all_hits_cost_ratio: {:.3}", all / closest);
    let job = RenderJob::from_config(&cfg, "");
    let settings = job.settings(&desc);
    let counter = AtomicU64::new(0);
    let render = |gt: bool| {
        time(|| {
            drop(scene.render_view(
                cam,
                &desc.slices,
                &settings,
                cam.center_view(),
                gt,
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
    let samples = (pixels.len() as u64 * cfg.render.spp as u64) as f64;
    println!(
        "colour only: {:.3} s ({:.0} camera samples/s)",
        colour,
        samples / colour
    );
    println!(
        "colour + {}-slice GT: {:.3} s ({:.0} camera samples/s)",
        cfg.render.slices,
        with_gt,
        samples / with_gt
    );
    println!("gt_overhead_ratio: {:.3}", with_gt / colour);
    Ok(())
}

fn time(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}
