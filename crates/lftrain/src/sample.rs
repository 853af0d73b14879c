//! Training samples: a random crop of a scene, rotated, EPI-shifted and colour-augmented, as
//! the four stacks and the shifted targets; and batches of them in the network's layout.

use lfdata::camera::Vignette;
use lfdata::lightfield::{crop_plane, rotate_plane};
use lfdata::stacks::{Direction, Region};
use rand::{Rng, RngExt};

use crate::augment::{Degrade, Photometric};
use crate::config::AugmentConfig;
use crate::input::StackInput;
use crate::mask::inside_border;
use crate::scene::{Scene, Targets};

/// The random choices of one sample, drawn first so that a sample is a pure function of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draw {
    /// Crop origin (left, top) in the scene.
    pub origin: (usize, usize),
    /// Down-scaling factor: the crop takes every `scale`-th pixel of `scale · patch` ones.
    pub scale: usize,
    /// Quarter turns.
    pub turns: usize,
    /// EPI shift, pixels.
    pub shift: f32,
    /// Colour, brightness and contrast.
    pub photometric: Photometric,
    /// Blur and sensor noise.
    pub degrade: Degrade,
}

impl Draw {
    /// A random draw for a `patch`-sized crop of a `width × height` scene, at least `margin`
    /// pixels inside it where the scene is large enough (else as far inside as it allows).
    pub fn random(
        cfg: &AugmentConfig,
        patch: usize,
        margin: usize,
        (width, height): (usize, usize),
        rng: &mut impl Rng,
    ) -> Self {
        // The largest factor whose crop still fits the scene, then one of 1 ..= it.
        let fits = (1..=cfg.max_downscale.max(1))
            .rev()
            .find(|k| k * patch <= width.min(height))
            .unwrap_or(1);
        let scale = rng.random_range(1..=fits);
        let mut origin = |size: usize| {
            let room = size.saturating_sub(scale * patch);
            let lo = margin.min(room / 2);
            rng.random_range(lo..=room - lo)
        };
        let origin = (origin(width), origin(height));
        let shift = if cfg.max_shift > 0.0 {
            rng.random_range(-cfg.max_shift..=cfg.max_shift)
        } else {
            0.0
        };
        Self {
            origin,
            scale,
            turns: if cfg.rotate {
                rng.random_range(0..4)
            } else {
                0
            },
            shift,
            photometric: Photometric::random(cfg, rng),
            degrade: Degrade::random(cfg, rng),
        }
    }

    /// The vignetting of a lens centred on a `scene`-sized image as the draw's crop sees it:
    /// `side²` pixels from `corner`, every `scale`-th, turned by the draw's turns.
    pub fn lens(&self, scene: (usize, usize), corner: (isize, isize), side: usize) -> Vignette {
        Vignette::centred(self.degrade.vignetting, scene)
            .in_crop(corner, self.scale.max(1))
            .rotated(side, self.turns)
    }
}

/// One sample: stacks in [`Direction::ALL`] order, each `n * 3` planes of `patch²`, and the
/// targets as planes `[modes][patch²]` of disparity and of η.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// The four stacks.
    pub stacks: [Vec<f32>; 4],
    /// Target disparities (after the shift).
    pub disparity: Vec<f32>,
    /// Target weights, 0 outside the loss region.
    pub eta: Vec<f32>,
    /// Pixels inside the loss region (the losses' `N`).
    pub loss_pixels: usize,
}

/// The sample of `scene` for `draw`, with `input` as the stacks' content.
///
/// The crop is taken with a margin wide enough for the EPI shift of the outer views (and
/// the cost volume's furthest hypothesis), so the
/// shifted stacks read real pixels wherever the scene has them, then rotated (views, view grid
/// and targets together), then the stacks are extracted with the shift. The loss region leaves
/// out `border` pixels at each crop edge and the scene's flat pixels ([`Scene::texture`],
/// cropped and rotated with the views).
pub fn make_sample(
    scene: &Scene,
    draw: &Draw,
    patch: usize,
    border: usize,
    input: &StackInput,
) -> Sample {
    let c = scene.lf.centre().0 as f32;
    let margin = (c * (draw.shift.abs() + input.reach())).ceil() as usize + 1;
    let (x0, y0) = (draw.origin.0 as isize, draw.origin.1 as isize);
    let (m, k) = (margin as isize, draw.scale.max(1));
    let side = patch + 2 * margin;
    let corner = (x0 - m * k as isize, y0 - m * k as isize);
    let mut lf = scene.lf.crop(corner, (side, side), k).rotate(draw.turns);
    let region = Region {
        x0: margin,
        y0: margin,
        width: patch,
        height: patch,
    };
    let (cu, cv) = lf.centre();
    let centre = crop_plane(
        lf.view(cu, cv),
        lf.width,
        lf.height,
        3,
        (m, m),
        (patch, patch),
        1,
    );
    let pivot = draw.photometric.pivot(&centre);
    // Once on the crop's views (RGB interleaved: one pixel per "view" of `apply`), not on
    // every stack: the draw is affine per pixel and commutes with the stacks' bilinear
    // resampling, and a cost volume resamples each view once per hypothesis.
    for view in lf.views.iter_mut().flatten() {
        draw.photometric.apply(view, 1, pivot);
    }
    // After the colours, as a camera's noise comes after the scene's light.
    let lens = draw.lens((scene.lf.width, scene.lf.height), corner, side);
    draw.degrade.apply_all(&mut lf.views, lf.width, lens);
    let stacks = Direction::ALL.map(|dir| input.planes(&lf, dir, region, draw.shift));
    let (disparity, mut eta) = target_planes(&scene.targets, (x0, y0), patch, draw);
    let region = loss_region(scene, (x0, y0), patch, draw, border);
    for slot in eta.chunks_exact_mut(patch * patch) {
        slot.iter_mut().zip(&region).for_each(|(e, r)| *e *= r);
    }
    Sample {
        stacks,
        disparity,
        eta,
        loss_pixels: region.iter().filter(|&&r| r > 0.0).count(),
    }
}

/// 1 where the crop's pixels get a loss, 0 elsewhere (`patch²`, in the rotated frame).
pub(crate) fn loss_region(
    scene: &Scene,
    origin: (isize, isize),
    patch: usize,
    draw: &Draw,
    border: usize,
) -> Vec<f32> {
    let (w, h) = (scene.lf.width, scene.lf.height);
    let mut texture = crop_plane(&scene.texture, w, h, 1, origin, (patch, patch), draw.scale);
    for _ in 0..draw.turns % 4 {
        texture = rotate_plane(&texture, patch, patch, 1);
    }
    for (i, t) in texture.iter_mut().enumerate() {
        if !inside_border(i % patch, i / patch, patch, border) {
            *t = 0.0;
        }
    }
    texture
}

/// The targets of the crop, rotated, shifted by `-shift` and split into planes.
pub(crate) fn target_planes(
    t: &Targets,
    origin: (isize, isize),
    patch: usize,
    draw: &Draw,
) -> (Vec<f32>, Vec<f32>) {
    let ch = t.modes * 2;
    let mut pairs = crop_plane(
        &t.pairs,
        t.width,
        t.height,
        ch,
        origin,
        (patch, patch),
        draw.scale,
    );
    let scale = draw.scale.max(1) as f32;
    for _ in 0..draw.turns % 4 {
        pairs = rotate_plane(&pairs, patch, patch, ch);
    }
    let plane = patch * patch;
    let mut disparity = vec![0.0; t.modes * plane];
    let mut eta = vec![0.0; t.modes * plane];
    for (i, px) in pairs.chunks_exact(ch).enumerate() {
        for (j, pair) in px.chunks_exact(2).enumerate() {
            if pair[1] > 0.0 {
                disparity[j * plane + i] = pair[0] / scale - draw.shift;
                eta[j * plane + i] = pair[1];
            }
        }
    }
    (disparity, eta)
}

/// A batch in the network's layout: `stacks[k]` is `[batch, n*3, patch, patch]`, targets are
/// `[batch, modes, patch, patch]`, all flattened row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    /// Samples.
    pub size: usize,
    /// Crop side.
    pub patch: usize,
    /// Channels per stack.
    pub stack_channels: usize,
    /// Target slots per pixel.
    pub modes: usize,
    /// The four stacks.
    pub stacks: [Vec<f32>; 4],
    /// Target disparities.
    pub disparity: Vec<f32>,
    /// Target weights.
    pub eta: Vec<f32>,
    /// Pixels inside the loss region, over all samples.
    pub loss_pixels: usize,
}

impl Batch {
    /// Concatenates `samples` (all of the same shape).
    pub fn from_samples(samples: Vec<Sample>, patch: usize, modes: usize) -> Self {
        let size = samples.len();
        let stack_channels = samples[0].stacks[0].len() / (patch * patch);
        let mut stacks: [Vec<f32>; 4] = Default::default();
        let (mut disparity, mut eta) = (Vec::new(), Vec::new());
        let loss_pixels = samples.iter().map(|s| s.loss_pixels).sum();
        for s in samples {
            for (all, one) in stacks.iter_mut().zip(s.stacks) {
                all.extend(one);
            }
            disparity.extend(s.disparity);
            eta.extend(s.eta);
        }
        Self {
            size,
            patch,
            stack_channels,
            modes,
            stacks,
            disparity,
            eta,
            loss_pixels,
        }
    }
}

#[cfg(test)]
mod tests {
    use lfdata::lightfield::LightField;
    use lfdata::stacks::{Direction, Region, extract};

    use crate::augment::{Photometric, grey_axis_rotation};

    /// The loader colours a crop's views once instead of every resampled stack
    /// (`sample::make_sample`): a photometric draw is affine per pixel and the resampling's
    /// weights sum to one, so both orders agree to rounding, also where sampling clamps.
    #[test]
    fn a_photometric_draw_commutes_with_the_epi_shift() {
        let lf = LightField::from_fn(9, 20, 20, |u, v, x, y| {
            let s = ((x * 7 + y * 13 + u * 3 + v * 5) % 17) as f32 / 17.0;
            [s, 1.0 - s, 0.3 + 0.4 * s * s]
        });
        let draw = Photometric {
            matrix: grey_axis_rotation(1.1),
            gain: 1.4,
            stretch: 0.7,
            contrast: 1.2,
            brightness: -0.05,
        };
        let region = Region {
            x0: 1,
            y0: 2,
            width: 16,
            height: 15,
        };
        let plane = region.width * region.height;
        let mut coloured = lf.clone();
        for view in coloured.views.iter_mut().flatten() {
            draw.apply(view, 1, 0.45);
        }
        for dir in Direction::ALL {
            let mut after = extract(&lf, dir, region, 1.37);
            draw.apply(&mut after, plane, 0.45);
            let before = extract(&coloured, dir, region, 1.37);
            let worst = before
                .iter()
                .zip(&after)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(worst < 1e-5, "{dir:?}: {worst}");
        }
    }
}
