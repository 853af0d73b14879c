//! Shared shading against independent truth: a diffuse plane's views must be exact parallax
//! shifts of each other (the ground truth says they see the same points), and where light
//! depends on the view — a glossy highlight, a mirror — shared shading must converge to what
//! the independent estimator converges to.

mod common;

use common::{Harness, Part, camera, disparity, emitter, f_px, matte, quad, scene, settings};
use glam::{DVec3, Quat, Vec3};
use lfgen::output::images::to_srgb8;
use lfgen::render::cache::{CacheParams, RadianceCache};
use lfgen::render::view::{Adaptive, RenderSettings};
use lfgen::scene::{Material, SceneDesc, Shape, SurfaceModel, Texture, Transform};

const EYE: DVec3 = DVec3::new(0.0, 1.0, 4.0);
/// The plane's depth and its (integer) disparity: views are integer shifts of each other.
const PLANE_Z: f64 = 2.0;
const PLANE_D: i32 = 2;
const RES: u32 = 48;

/// A plane at `PLANE_Z` of `material`, lit by a square light above the camera facing it.
fn lit_plane(material: Material) -> SceneDesc {
    let mut cam = camera([RES, RES], [5, 5], 100.0, EYE);
    let inv_zf = 1.0 / PLANE_Z - PLANE_D as f64 / (f_px(&cam) * cam.baseline_m);
    cam.focus_distance_m = 1.0 / inv_zf;
    let at = |dz: f64, dy: f64| (EYE + DVec3::new(0.0, dy, -dz)).as_vec3();
    // A whole number of checker cells, centred on the optical axis: cell edges then fall on
    // pixel boundaries in every view (the views are integer shifts).
    let size = 52.0 * checker_cell();
    let plane = quad([size, size], at(PLANE_Z, 0.0), material);
    let mut light = quad([0.6, 0.6], at(1.0, 0.8), emitter([25.0; 3]));
    // Facing the plane (−Z), out of the views' field.
    light.transform = Transform {
        rotation: Quat::from_rotation_y(std::f32::consts::PI),
        ..light.transform
    };
    scene(cam, [1.0, 5.0], [0.0; 3], vec![plane, light])
}

/// Adds `part` to `desc` as object `name` with its own material.
fn add(desc: &mut SceneDesc, name: &str, part: Part) {
    desc.materials.push(part.material);
    desc.objects.push(lfgen::scene::Object {
        name: name.into(),
        shape: part.shape,
        transform: part.transform,
        material: desc.materials.len() as u32 - 1,
    });
}

/// Side of a checker cell: 4 pixels on the plane.
fn checker_cell() -> f32 {
    (4.0 * PLANE_Z / (100.0 * RES as f64 / 35.0)) as f32
}

/// A checker of 4-pixel cells on the plane, in a Lambert (no glossy layer) material.
fn textured_lambert() -> Material {
    let cell = checker_cell();
    Material {
        model: SurfaceModel::Diffuse,
        base_color: Texture::Checker {
            a: [0.7, 0.2, 0.3],
            b: [0.15, 0.5, 0.6],
            size: cell,
        },
        ..matte([1.0; 3], 1.0)
    }
}

/// Mean 8-bit difference between every view and the centre view shifted by its parallax.
fn parallax_residual(views: &[Vec<u8>], grid: u32) -> f64 {
    let (w, c) = (RES as i32, (grid / 2) as i32);
    let centre = &views[(c * grid as i32 + c) as usize];
    let (mut sum, mut n) = (0.0, 0usize);
    for (v, img) in views.iter().enumerate() {
        let (du, dv) = (v as i32 % grid as i32 - c, v as i32 / grid as i32 - c);
        for j in 0..w {
            for i in 0..w {
                let (ci, cj) = (i + du * PLANE_D, j + dv * PLANE_D);
                if !(0..w).contains(&ci) || !(0..w).contains(&cj) {
                    continue;
                }
                for ch in 0..3 {
                    let a = img[((j * w + i) * 3 + ch) as usize] as f64;
                    let b = centre[((cj * w + ci) * 3 + ch) as usize] as f64;
                    sum += (a - b).abs();
                    n += 1;
                }
            }
        }
    }
    sum / n as f64
}

#[test]
fn a_textured_lambert_plane_looks_the_same_from_every_view() {
    let h = Harness::new(lit_plane(textured_lambert()));
    assert!((disparity(&h.desc.camera, PLANE_Z) - PLANE_D as f64).abs() < 1e-9);
    let s = settings(16, 5);
    let views = h.desc.camera.num_views();
    let cache = h.cache(&s, 4);
    let shared: Vec<Vec<u8>> = (0..views)
        .map(|v| to_srgb8(&h.render_shared(v, &s, &cache, false).image.pixels, 1.0))
        .collect();
    let independent: Vec<Vec<u8>> = (0..views)
        .map(|v| to_srgb8(&h.render(v, &s, false).image.pixels, 1.0))
        .collect();
    let (rs, ri) = (
        parallax_residual(&shared, 5),
        parallax_residual(&independent, 5),
    );
    eprintln!("parallax residual at 16 spp: shared {rs:.3}, independent {ri:.3} levels");
    // The image is not flat: the checker and the light's falloff are both visible.
    let centre = &shared[12];
    let (lo, hi) = (centre.iter().min().unwrap(), centre.iter().max().unwrap());
    assert!(hi - lo > 60, "{lo}..{hi}");
    assert!(rs <= 0.5, "shared shading: views differ by {rs:.3} levels");
    assert!(
        ri > 1.0,
        "the independent estimator should not pass: {ri:.3}"
    );
}

/// Mean relative difference of two linear images (over pixels brighter than 1 % of the peak).
fn rel_diff(a: &[Vec3], b: &[Vec3]) -> f64 {
    let peak = b.iter().map(|c| c.max_element()).fold(0.0, f32::max);
    let (mut sum, mut n) = (0.0, 0);
    for (x, y) in a.iter().zip(b) {
        let m = (x.element_sum() + y.element_sum()) / 6.0;
        if m > 0.01 * peak {
            sum += ((x.element_sum() - y.element_sum()).abs() / 3.0 / m) as f64;
            n += 1;
        }
    }
    sum / n as f64
}

/// A glossy plane of `roughness` and `metallic` under the light, with something for it to
/// reflect: a diffuse wall behind the camera, lit by the sky (light reaching it only through
/// a mirror would be caustics, all fireflies).
fn glossy_scene(roughness: f32, metallic: f32) -> Harness {
    let material = Material {
        roughness,
        metallic,
        base_color: Texture::constant([0.6, 0.5, 0.4]),
        ..matte([1.0; 3], 1.0)
    };
    let mut desc = lit_plane(material);
    desc.environment = [0.3; 3];
    let at = (EYE + DVec3::new(0.0, 0.0, 1.0)).as_vec3();
    let mut wall = quad([6.0, 6.0], at, textured_lambert());
    wall.transform.rotation = Quat::from_rotation_y(std::f32::consts::PI);
    add(&mut desc, "wall", wall);
    Harness::new(desc)
}

/// At high sample counts (`fill_spp` fill samples per view, 256 per pixel) shared shading
/// agrees with the independent estimator view by view (corner, centre, corner), within the
/// independent estimator's own noise.
fn assert_views_converge(name: &str, h: &Harness, fill_spp: u32) {
    let s = settings(256, 5);
    let cache = h.cache(&settings(16, 5), fill_spp);
    for view in [0, 12, 24] {
        let shared = h.render_shared(view, &s, &cache, false).image.pixels;
        let a = h.render(view, &s, false).image.pixels;
        let other_seed = lfgen::render::view::RenderSettings { seed: 12, ..s };
        let b = h.render(view, &other_seed, false).image.pixels;
        let noise = rel_diff(&a, &b);
        let d = rel_diff(&shared, &a);
        let energy = |img: &[Vec3]| img.iter().map(|c| c.element_sum() as f64).sum::<f64>();
        let bias = energy(&shared) / energy(&a) - 1.0;
        let spread = (energy(&b) / energy(&a) - 1.0).abs();
        eprintln!(
            "{name} view {view}: shared vs independent {d:.4} (independent vs itself \
             {noise:.4}), energy {bias:+.4}"
        );
        // Per pixel about as far from the independent render as a second independent render
        // is (a highlight in the wrong place would be far farther); in total within 1 %, or
        // three times what two independent renders differ by.
        assert!(
            d < 1.5 * noise,
            "{name} view {view}: {d:.4} vs noise {noise:.4}"
        );
        assert!(
            bias.abs() < 0.01f64.max(3.0 * spread),
            "{name} view {view}: energy {bias:+.4} (two independent renders: {spread:.4})"
        );
    }
}

/// Highlights and reflections narrower than the camera grid's angle move between views as
/// with the independent estimator: the lobe is traced per view.
#[test]
fn glossy_and_mirror_surfaces_converge_to_the_independent_views() {
    for (name, roughness, metallic) in [("glossy", 0.3, 0.0), ("mirror", 0.0, 1.0)] {
        let h = glossy_scene(roughness, metallic);
        // The grid spans 0.28 m / 2 m = 0.14 rad at the plane: 4× that is wider than
        // 2α = 0.18 (roughness 0.3), so the cache holds no glossy term there.
        let cache = h.cache(&settings(4, 5), 4);
        let at_plane = cache
            .lookup(plane_point(), Vec3::Z, 0)
            .expect("a filled cell");
        assert_eq!(
            at_plane.glossy, None,
            "{name}: the lobe should stay per view"
        );
        assert_views_converge(name, &h, 16);
    }
}

/// A rough metal's lobe (2α = 0.98 rad) is 7× wider than the grid's angle: it is estimated
/// once for all views, and still agrees with every view's independent render. Its highlight
/// does change across the grid: a plain mean over the views was 4 % too bright in one corner
/// view and 4.6 % too dark in the other; the linear fit in the view position leaves < 0.1 %.
#[test]
fn a_wide_glossy_lobe_is_shared_and_converges_to_the_independent_views() {
    let h = glossy_scene(0.7, 1.0);
    let cache = h.cache(&settings(4, 5), 4);
    let at_plane = cache
        .lookup(plane_point(), Vec3::Z, 0)
        .expect("a filled cell");
    assert!(at_plane.glossy.is_some(), "the lobe should be shared");
    assert_views_converge("rough metal", &h, 128);
}

/// A point of the plane in the middle of the views.
fn plane_point() -> Vec3 {
    (EYE + DVec3::new(0.0, 0.0, -PLANE_Z)).as_vec3()
}

/// The ground truth does not depend on how the colour is shaded: behind a half-transparent
/// veil (stochastic transparency draws a key per sample), an independent and a shared render
/// of the same view write the same modes, η and HCI depth bit for bit (only the modes'
/// colours, which are shaded radiance, may differ) — and the veil is there
/// (two modes at some pixels), so the comparison is not of empty maps.
#[test]
fn the_ground_truth_is_the_same_with_shared_and_independent_shading() {
    let mut desc = lit_plane(textured_lambert());
    let veil = quad(
        [0.4, 0.4],
        (EYE + DVec3::new(0.0, 0.0, -1.5)).as_vec3(),
        matte([0.9; 3], 0.5),
    );
    add(&mut desc, "veil", veil);
    let h = Harness::new(desc);
    let s = settings(8, 4);
    let cache = h.cache(&s, 4);
    for view in [0, 12] {
        let a = h.render(view, &s, true).gt.unwrap();
        let b = h.render_shared(view, &s, &cache, true).gt.unwrap();
        assert!(a.modes == b.modes, "view {view}: modes differ");
        assert_eq!(a.hci.depth, b.hci.depth, "view {view}: HCI depth differs");
        let two = a.modes.pixels().filter(|m| m.len() == 2).count();
        assert!(
            two > 100,
            "view {view}: only {two} pixels see the veil and the plane"
        );
    }
}

/// The point `dz` in front of the eye.
fn at(dz: f64) -> Vec3 {
    (EYE + DVec3::new(0.0, 0.0, -dz)).as_vec3()
}

/// `m` as black Lambert, no glossy layer: a light is its emission alone, and a veil adds none
/// (glossy layers would pass a little light back and forth between them).
fn black(m: Material) -> Material {
    Material {
        model: SurfaceModel::Diffuse,
        base_color: Texture::constant([0.0; 3]),
        ..m
    }
}

/// Shared shading's camera rays composite a semi-transparent surface over what lies behind it
/// (the over operator) instead of keeping it in a share of the samples: a black veil of opacity
/// 0.3 in front of a light gives every pixel exactly 0.7 of the light's emission, where
/// stochastic transparency (the independent estimator) is off by up to one sample in 16.
#[test]
fn a_veil_over_a_light_is_composited_exactly() {
    let cam = camera([24, 24], [3, 3], 100.0, EYE);
    let light = quad([2.0, 2.0], at(3.0), black(emitter([10.0; 3])));
    let veil = quad([2.0, 2.0], at(1.5), black(matte([1.0; 3], 0.3)));
    let h = Harness::new(scene(cam, [1.0, 5.0], [0.0; 3], vec![light, veil]));
    let s = settings(16, 5);
    let cache = h.cache(&s, 4);
    for (view, with_gt) in [(4, true), (0, false)] {
        let shared = h.render_shared(view, &s, &cache, with_gt).image.pixels;
        let worst = shared
            .iter()
            .map(|c| (*c - Vec3::splat(7.0)).abs().max_element());
        let worst = worst.fold(0.0, f32::max);
        assert!(worst < 1e-4, "view {view}: a pixel is {worst} off 7");
    }
    let independent = h.render(0, &s, false).image.pixels;
    let worst = (independent.iter())
        .map(|c| (*c - Vec3::splat(7.0)).abs().max_element())
        .fold(0.0, f32::max);
    assert!(worst > 0.1, "stochastic transparency should show: {worst}");
}

/// Shared shading splits smooth glass on a camera ray into its reflection and its refraction,
/// each with its Fresnel weight. A pane (IOR 1.5, one interface) in front of a black light of
/// emission 10, under a sky of 20: every camera sample sees `F·20 + (1 − F)/η²·10` (refracted
/// radiance is compressed by η² on entering the glass), with `F ≈ ((η − 1)/(η + 1))² = 0.04` at
/// the camera's near-normal incidence, so every pixel of every view is that value with no
/// noise. Choosing one branch per sample with probability F instead gives the same mean, but
/// a pixel is off by a sixteenth of the difference for each reflection sample it drew.
#[test]
fn glass_on_camera_rays_is_split_into_both_branches() {
    let cam = camera([24, 24], [3, 3], 100.0, EYE);
    let glass = Material {
        model: SurfaceModel::Glass { ior: 1.5 },
        ..matte([1.0; 3], 1.0)
    };
    let light = quad([4.0, 4.0], at(3.0), black(emitter([10.0; 3])));
    let pane = quad([4.0, 4.0], at(1.5), glass);
    let h = Harness::new(scene(cam, [1.0, 5.0], [20.0; 3], vec![light, pane]));
    let fresnel = (0.5f64 / 2.5).powi(2);
    let truth = fresnel * 20.0 + (1.0 - fresnel) / 2.25 * 10.0;
    let render = |split_glass| {
        let mut s = settings(16, 5);
        s.path.split_glass = split_glass;
        let cache = h.cache(&s, 4);
        (0..9)
            .flat_map(|view| h.render_shared(view, &s, &cache, view == 4).image.pixels)
            .map(|c| c.x as f64)
            .collect::<Vec<_>>()
    };
    let worst = |pixels: &[f64]| pixels.iter().map(|v| (v - truth).abs()).fold(0.0, f64::max);
    let mean = |pixels: &[f64]| pixels.iter().sum::<f64>() / pixels.len() as f64;
    let (split, chosen) = (render(true), render(false));
    eprintln!(
        "glass split: worst {:.2e}, mean {:.5}; chosen: worst {:.3}, mean {:.5}; truth {truth:.5}",
        worst(&split),
        mean(&split),
        worst(&chosen),
        mean(&chosen)
    );
    // Off-normal incidence raises F by at most ~1e-4 across the narrow field of view.
    assert!(worst(&split) < 2e-3 * truth, "split: {}", worst(&split));
    assert!(
        worst(&chosen) > 0.1 * truth,
        "the choice should show as noise"
    );
    assert!((mean(&chosen) / truth - 1.0).abs() < 0.02, "both unbiased");
}

/// Adaptive sampling spends its extra samples where a view is still noisy: on a glossy plane
/// under a small light (its highlight is traced per view) the pixels it refines were far
/// noisier than those it left alone, the view ends closer to the converged render, and an
/// unreachable threshold changes nothing.
#[test]
fn adaptive_sampling_refines_the_noisy_pixels() {
    let h = glossy_scene(0.3, 0.0);
    let cache = h.cache(&settings(16, 5), 16);
    let view = 12;
    let render = |s: &RenderSettings| h.render_shared(view, s, &cache, false).image;
    // Converged from its own seed and the same cache: what remains between it and a render
    // is that render's per-view noise, the part adaptive sampling acts on.
    let reference = render(&RenderSettings {
        seed: 99,
        ..settings(1024, 5)
    })
    .pixels;
    let base = settings(8, 5);
    let with = |threshold| RenderSettings {
        adaptive: Adaptive {
            extra: 24,
            threshold,
            display_scale: 1.0,
        },
        ..base
    };
    let plain = render(&base);
    let off = render(&with(f32::INFINITY));
    assert_eq!((off.pixels == plain.pixels, off.refined), (true, 0));
    let sq = |a: &Vec3, b: &Vec3| (*a - *b).length_squared() as f64;
    let adaptive = render(&with(0.1));
    // Per-pixel squared error of the plain render, summed over the pixels adaptive sampling
    // refined (those whose value changed) and over the rest.
    let (mut refined, mut kept) = ((0.0, 0), (0.0, 0));
    for ((p, a), r) in plain.pixels.iter().zip(&adaptive.pixels).zip(&reference) {
        let group = if p == a { &mut kept } else { &mut refined };
        *group = (group.0 + sq(p, r), group.1 + 1);
    }
    let n = plain.pixels.len();
    let mse = |img: &[Vec3]| {
        img.iter()
            .zip(&reference)
            .map(|(a, r)| sq(a, r))
            .sum::<f64>()
    };
    let (before, after) = (
        mse(&plain.pixels) / n as f64,
        mse(&adaptive.pixels) / n as f64,
    );
    let (noisy, quiet) = (refined.0 / refined.1 as f64, kept.0 / kept.1 as f64);
    eprintln!(
        "refined {} of {n}; their error {noisy:.2e} vs the rest {quiet:.2e}; \
         MSE {before:.2e} → {after:.2e}",
        adaptive.refined
    );
    assert_eq!(
        adaptive.refined, refined.1,
        "the count is the pixels that changed"
    );
    assert!(
        refined.1 > 0 && refined.1 < n / 4,
        "{} of {n} refined",
        refined.1
    );
    assert!(
        noisy > 10.0 * quiet,
        "refined {noisy:.2e} vs kept {quiet:.2e}"
    );
    assert!(after < 0.5 * before, "MSE {before:.2e} → {after:.2e}");
}

/// A furnace: a closed Lambert room of albedo `FURNACE_ALBEDO` whose every wall also emits
/// radiance 1. Light arriving anywhere from any direction is then known in closed form (the
/// emission after 0, 1, … bounces), and so is every cell's coupled irradiance.
const FURNACE_ALBEDO: f32 = 0.5;

fn furnace() -> Harness {
    let cam = camera([64, 64], [5, 5], 35.0, DVec3::new(0.0, 1.5, 2.0));
    let walls = Material {
        model: SurfaceModel::Diffuse,
        emission: [1.0; 3],
        ..matte([FURNACE_ALBEDO; 3], 1.0)
    };
    let room = Part {
        shape: Shape::Room {
            size: Vec3::new(4.0, 3.0, 6.0),
        },
        transform: Transform::at(Vec3::ZERO),
        material: walls,
    };
    Harness::new(scene(cam, [1.0, 5.2], [0.0; 3], vec![room]))
}

/// The finest cells on the back wall (z = −3, facing +Z) that the cache filled: each cell's
/// coupled irradiance over `truth` averaged across the wall points (a 5 cm grid) inside it,
/// the area its fill samples cover.
fn back_wall_ratios(cache: &RadianceCache, truth: impl Fn(Vec3) -> f64) -> Vec<f64> {
    let mut cells = std::collections::HashMap::new();
    for iy in 0..60 {
        for ix in 0..80 {
            let p = Vec3::new(-1.95 + ix as f32 * 0.05, 0.05 + iy as f32 * 0.05, -3.0);
            let key = cache.grid.keys(p, Vec3::Z, 0)[0];
            if let Some(i) = cache.get(key).and_then(|c| c.irradiance) {
                let cell = cells.entry(key).or_insert((i.x as f64, 0.0, 0.0));
                (cell.1, cell.2) = (cell.1 + truth(p), cell.2 + 1.0);
            }
        }
    }
    cells.values().map(|(i, sum, n)| i / (sum / n)).collect()
}

/// The mean and the rms scatter about 1 of cell ratios.
fn mean_and_scatter(ratios: &[f64]) -> (f64, f64) {
    let n = ratios.len() as f64;
    let mean = ratios.iter().sum::<f64>() / n;
    let rms = (ratios.iter().map(|r| (r - 1.0).powi(2)).sum::<f64>() / n).sqrt();
    (mean, rms)
}

/// What arrives anywhere in the furnace after 0…max_depth−1 bounces, times π (the
/// cosine-weighted hemisphere): every cell's coupled irradiance.
fn furnace_truth(max_depth: u32) -> f64 {
    let arriving: f64 = (0..max_depth as i32)
        .map(|k| (FURNACE_ALBEDO as f64).powi(k))
        .sum();
    std::f64::consts::PI * arriving
}

/// The scatter (rms, relative) of the furnace's back-wall cells about `truth`, filled with 1
/// sample per pixel of every view and `params`; their mean must be on it.
fn furnace_scatter(h: &Harness, s: &RenderSettings, params: CacheParams, what: &str) -> f64 {
    let truth = furnace_truth(s.path.max_depth);
    let ratios = back_wall_ratios(&h.cache_with(s, 1, params), |_| truth);
    let (mean, rms) = mean_and_scatter(&ratios);
    let n = ratios.len();
    eprintln!("{what}: {n} cells, mean {mean:.4} of the truth, rms {rms:.4}");
    // The mean of hundreds of cells: its own noise is about 0.1 %.
    assert!(n > 200, "{n} cells");
    assert!(
        (mean - 1.0).abs() < 0.005,
        "{what}: mean {mean} of the truth"
    );
    rms
}

/// The later vertices of the fill paths (`render.fill_vertices`) estimate the same coupled
/// irradiance as their first: in the furnace, where every cell's value is known, the cells
/// stay on the closed form with and without Russian roulette (a later estimate weighted as
/// the path, or cut off at the path's depth, would be dark), and they scatter less about it
/// since each holds more samples.
#[test]
fn later_fill_vertices_agree_with_the_furnace_and_cut_its_noise() {
    let h = furnace();
    let max_depth = 5u32;
    for rr_depth in [max_depth + 1, 2] {
        let s = RenderSettings {
            path: lfgen::render::integrator::PathSettings {
                rr_depth,
                ..settings(1, max_depth).path
            },
            ..settings(1, max_depth)
        };
        let spread = |fill_vertices| {
            let params = CacheParams {
                fill_vertices,
                ..common::CACHE
            };
            let what = format!("rr_depth {rr_depth}, fill_vertices {fill_vertices}");
            furnace_scatter(&h, &s, params, &what)
        };
        let (first, later) = (spread(1), spread(5));
        assert!(
            later < 0.85 * first,
            "rr_depth {rr_depth}: rms {later:.4} with later vertices vs {first:.4}"
        );
    }
}

/// The defaults together: later fill vertices (`fill_vertices = 5`) and four light samples
/// where the fill starts, each tested above only with the other at 1. In the furnace (its
/// emitting walls are the lights those samples pick) the cells stay on the closed form with
/// both — the first vertex's average divided wrongly would move every cell, its own estimate
/// and the later ones that share its light.
#[test]
fn later_fill_vertices_and_more_light_samples_together_stay_on_the_furnace() {
    let h = furnace();
    let s = settings(1, 5);
    for fill_light_samples in [1, 4] {
        let params = CacheParams {
            fill_light_samples,
            ..common::CACHE
        };
        let what = format!("fill_vertices 5, fill_light_samples {fill_light_samples}");
        furnace_scatter(&h, &s, params, &what);
    }
}

/// Irradiance at `p` on the plane z = −3 (facing +Z) from a square light of side `side` and
/// radiance `emission`, parallel to it at `centre` and facing it: π L times the form factor of
/// the rectangle, the signed sum of four corner rectangles of the standard closed form
/// (a differential area under one corner of a parallel `x × y` rectangle at height `c`).
fn parallel_square_irradiance(p: Vec3, centre: Vec3, side: f64, emission: f64) -> f64 {
    let c = (centre.z - p.z) as f64;
    let corner = |x: f64, y: f64| {
        let (x, y) = (x / c, y / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    let (dx, dy) = ((centre.x - p.x) as f64, (centre.y - p.y) as f64);
    let (x1, x2, y1, y2) = (
        dx - side / 2.0,
        dx + side / 2.0,
        dy - side / 2.0,
        dy + side / 2.0,
    );
    let form = corner(x2, y2) - corner(x1, y2) - corner(x2, y1) + corner(x1, y1);
    std::f64::consts::PI * emission * form
}

/// A black wall (z = −3) lit by two small square lights at different distances, seen by a
/// 3×3 grid, and its closed-form coupled irradiance: all of it direct, from the two squares.
fn two_lights() -> (Harness, impl Fn(Vec3) -> f64) {
    let cam = camera([64, 64], [3, 3], 35.0, DVec3::new(0.0, 1.5, 2.0));
    let (side, emission) = (0.4, 20.0);
    let centres = [Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.2, 2.0, -0.4)];
    let light = |centre| {
        let mut light = quad([side as f32; 2], centre, emitter([emission as f32; 3]));
        light.transform.rotation = Quat::from_rotation_y(std::f32::consts::PI);
        light
    };
    let wall = quad(
        [8.0, 6.0],
        Vec3::new(0.0, 1.5, -3.0),
        black(matte([0.0; 3], 1.0)),
    );
    let parts = vec![wall, light(centres[0]), light(centres[1])];
    let h = Harness::new(scene(cam, [1.0, 5.2], [0.0; 3], parts));
    let truth = move |p: Vec3| {
        (centres.iter())
            .map(|&c| parallel_square_irradiance(p, c, side, emission))
            .sum::<f64>()
    };
    (h, truth)
}

/// The mean and rms scatter of the two lights' wall cells about the closed form, filled with
/// one sample per pixel of every view and `params`.
fn two_lights_spread(params: CacheParams, what: &str) -> (f64, f64) {
    let (h, truth) = two_lights();
    let ratios = back_wall_ratios(&h.cache_with(&settings(1, 5), 1, params), truth);
    let (mean, rms) = mean_and_scatter(&ratios);
    let n = ratios.len();
    eprintln!("{what}: {n} cells, mean {mean:.4} of the closed form, rms {rms:.4}");
    assert!(n > 200, "{n} cells");
    (mean, rms)
}

/// More light samples at a fill path's first vertex (`render.fill_light_samples`) average
/// copies of the same MIS-weighted estimator. On the two lights' wall each cell's coupled
/// irradiance is known in closed form; one light sample picks one light (by power over
/// distance) and carries nearly all of it, so its choice and point are the cells' noise. With
/// eight the cells stay on the closed form and scatter less than half as much.
#[test]
fn more_fill_light_samples_stay_on_the_closed_form_and_cut_its_noise() {
    let spread = |fill_light_samples| {
        let params = CacheParams {
            fill_vertices: 1,
            fill_light_samples,
            ..common::CACHE
        };
        two_lights_spread(params, &format!("fill_light_samples {fill_light_samples}"))
    };
    let ((mean_one, one), (mean_eight, eight)) = (spread(1), spread(8));
    for mean in [mean_one, mean_eight] {
        assert!((mean - 1.0).abs() < 0.01, "mean {mean}");
    }
    assert!(
        eight < 0.5 * one,
        "rms {eight:.4} with 8 light samples vs {one:.4}"
    );
}

/// A final gather (`render.final_gather`): a second fill pass whose paths read the first
/// pass's cache at their second surface. In the furnace every cell's coupled irradiance is
/// known: the cells stay on it with the gathered estimates added (one weighted other than the
/// path it stands for, or reading the prior at the wrong vertex, would move them; at 12
/// bounces the one more that the prior's light adds is 0.5¹² of it) and scatter less.
#[test]
fn a_final_gather_stays_on_the_furnace_and_cuts_its_noise() {
    let gather = |on| CacheParams {
        final_gather: on,
        ..common::CACHE
    };
    furnace_scatter_falls(12, gather, "gathered", 0.9);
}

/// The furnace's cells at `max_depth` with an option off and on (`with(false)`, `with(true)`):
/// both on the closed form ([`furnace_scatter`]), and the option's scatter below `factor` of
/// the plain one's.
fn furnace_scatter_falls(
    max_depth: u32,
    with: impl Fn(bool) -> CacheParams,
    what: &str,
    factor: f64,
) {
    let (h, s) = (furnace(), settings(1, max_depth));
    let plain = furnace_scatter(&h, &s, with(false), "furnace");
    let on = furnace_scatter(&h, &s, with(true), &format!("furnace, {what}"));
    assert!(
        on < factor * plain,
        "furnace rms {on:.4} {what} vs {plain:.4}"
    );
}

/// Shrinking the cells towards their coarser levels (`render.cache_shrink`) against two
/// closed forms. In the furnace every cell's coupled irradiance is the same: the cells stay
/// on it and scatter far less, pooling the coarser levels' samples. On the two lights' wall
/// it varies several-fold within a metre, steepest under the near light: the cells stay on
/// the closed form there too (a shrink that blurred the falloff would move them) and still
/// scatter less.
#[test]
fn shrunk_cells_stay_on_the_closed_forms_and_scatter_less() {
    let shrink = |on: bool| CacheParams {
        shrink: on,
        ..common::CACHE
    };
    furnace_scatter_falls(5, shrink, "shrunk", 0.7);
    let lights = |on| CacheParams {
        fill_vertices: 1,
        ..shrink(on)
    };
    let (_, plain) = two_lights_spread(lights(false), "two lights");
    let (mean, shrunk) = two_lights_spread(lights(true), "two lights, shrunk");
    assert!((mean - 1.0).abs() < 0.01, "mean {mean}");
    assert!(
        shrunk < 0.8 * plain,
        "two lights rms {shrunk:.4} shrunk vs {plain:.4}"
    );
}
