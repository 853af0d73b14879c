//! Textured emission (`Material::emission_map`, the skies and facades behind windows) against
//! analytic truth: seen directly, an emitter shows `emission × map(uv)` texel for texel; as a
//! light, it gives a diffuse receiver the irradiance of its lit part alone (Lambert's polygon
//! formula), through light sampling and BSDF hits alike, in both shading modes.

mod common;

use common::{Harness, Part, camera, emitter, quad, scene, settings};
use glam::{DVec3, Quat, Vec3};
use lfgen::scene::{SurfaceModel, Texture, Transform};

/// Irradiance at `p` (normal +Z) from a Lambertian polygon of unit radiance: Lambert's formula
/// `E = ½ Σ θ_i (n · (v_i × v_{i+1}) / |v_i × v_{i+1}|)` over its edges.
fn polygon_irradiance(p: DVec3, polygon: &[DVec3]) -> f64 {
    let n = DVec3::Z;
    let mut sum = 0.0;
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (va, vb) = ((a - p).normalize(), (b - p).normalize());
        let theta = va.dot(vb).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(va.cross(vb).normalize());
    }
    0.5 * sum.abs()
}

/// The mean of `img` (linear RGB, `w` wide) over the `k × k` block with corner `(i0, j0)`.
fn block_mean(img: &[Vec3], w: usize, (i0, j0): (usize, usize), k: usize) -> Vec3 {
    let sum: Vec3 = (0..k * k).map(|n| img[(j0 + n / k) * w + i0 + n % k]).sum();
    sum / (k * k) as f32
}

#[test]
fn an_emitter_seen_directly_shows_its_map() {
    let (a, b) = ([0.2, 0.5, 0.9], [1.5, 1.0, 0.3]);
    let mut light = emitter([2.0; 3]);
    light.emission_map = Some(Texture::Checker { a, b, size: 0.25 });
    let cam = camera([48, 48], [1, 1], 50.0, DVec3::new(0.0, 0.0, 3.0));
    let h = Harness::new(scene(
        cam,
        [1.0, 5.0],
        [0.0; 3],
        vec![quad([4.0, 4.0], Vec3::ZERO, light)],
    ));
    let img = h.render(0, &settings(4, 2), false).image.pixels;
    let want = [Vec3::from(a) * 2.0, Vec3::from(b) * 2.0];
    // Pixels inside a cell are exactly one of the two radiances; only cell edges mix them.
    let mut count = [0usize; 2];
    for c in &img {
        if let Some(k) = want
            .iter()
            .position(|w| (*c - *w).abs().max_element() < 1e-4)
        {
            count[k] += 1;
        }
    }
    let n = img.len();
    assert!(
        count[0] + count[1] > n * 3 / 4,
        "{count:?} of {n} pixels are a texel"
    );
    assert!(
        count[0] > n / 4 && count[1] > n / 4,
        "both texels cover the view: {count:?}"
    );
}

/// A diffuse floor lit only by a 1 m² emitter above and beside the view whose right half
/// (stripes of 0.5 m) emits and left half is dark.
fn half_lit_emitter() -> (Harness, [DVec3; 4]) {
    let radiance = 4.0;
    let mut light = emitter([radiance; 3]);
    light.base_color = Texture::constant([0.0; 3]);
    light.emission_map = Some(Texture::Stripes {
        a: [0.0; 3],
        b: [1.0; 3],
        width: 0.5,
    });
    let mut floor = common::matte([0.5; 3], 1.0);
    floor.model = SurfaceModel::Diffuse;
    // Turned half a turn about X: it faces −Z (the floor), and local +X stays world +X, so
    // the second stripe (U ≥ 0.5 m from the quad's −X edge) is the world's right half.
    let lamp = Part {
        transform: Transform {
            translation: Vec3::new(1.5, 0.0, 1.0),
            rotation: Quat::from_rotation_x(std::f32::consts::PI),
            scale: Vec3::ONE,
        },
        ..quad([1.0, 1.0], Vec3::ZERO, light)
    };
    // 87.5 mm on 35 mm at 3 m: the view spans x, y ∈ [−0.6, 0.6] of the floor; the lamp is
    // outside it.
    let cam = camera([32, 32], [1, 1], 87.5, DVec3::new(0.0, 0.0, 3.0));
    let parts = vec![quad([8.0, 8.0], Vec3::ZERO, floor), lamp];
    let lit =
        [[1.5, -0.5], [2.0, -0.5], [2.0, 0.5], [1.5, 0.5]].map(|[x, y]| DVec3::new(x, y, 1.0));
    (Harness::new(scene(cam, [1.0, 5.0], [0.0; 3], parts)), lit)
}

#[test]
fn a_textured_emitter_lights_with_its_lit_part_only() {
    let (h, lit) = half_lit_emitter();
    let s = settings(64, 2);
    let cache = h.cache(&s, 64);
    let renders = [
        ("independent", h.render(0, &s, false).image.pixels),
        ("shared", h.render_shared(0, &s, &cache, false).image.pixels),
    ];
    let whole =
        [[1.0, -0.5], [2.0, -0.5], [2.0, 0.5], [1.0, 0.5]].map(|[x, y]| DVec3::new(x, y, 1.0));
    for (mode, img) in &renders {
        // Blocks of 4×4 pixels at the left edge, centre and right edge of the view (32 px over
        // 1.2 m: pixel i's centre at x = (i + 0.5)/32·1.2 − 0.6; image y runs against world y).
        for i0 in [0, 14, 28] {
            let x = (i0 as f64 + 2.0) / 32.0 * 1.2 - 0.6;
            let p = DVec3::new(x, 0.0, 0.0);
            let want = 0.5 / std::f64::consts::PI * 4.0 * polygon_irradiance(p, &lit);
            // What a renderer that ignored the map (its mean, 2 W/m²sr over the whole
            // square) would give: the test must tell the two apart.
            let mean = 0.5 / std::f64::consts::PI * 2.0 * polygon_irradiance(p, &whole);
            assert!((mean - want).abs() > 0.15 * want, "x {x}: {mean} vs {want}");
            let got = block_mean(img, 32, (i0, 14), 4);
            for c in got.to_array() {
                let err = (c as f64 - want).abs() / want;
                assert!(
                    err < 0.04,
                    "{mode}, x {x:.3}: {c} vs analytic {want} ({err:.3})"
                );
            }
        }
    }
}
