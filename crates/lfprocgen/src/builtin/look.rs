//! The scene's look: how the room is lit (its [`Mood`]), the exposure offset, the colour of
//! its lights, and which surfaces are plain, low-contrast, glossy or metallic.
//!
//! Every draw here comes from a stream of its own (`Gen::look`), never from the scene's main
//! stream, and the classic settings (even lighting, no offset, no coloured light, all shares
//! 0) change nothing: so `--preset classic` makes exactly the scenes lfgen made before these
//! settings existed, and each setting moves only what it names.

use super::{Gen, kelvin_rgb};
use crate::scene::{Light, Texture};
use crate::textures::generators::{FAMILIES, SUBTLE, SUBTLE_BASE, TextureSpec};
use crate::util::colour::luminance;
use glam::Vec3;
use rand::RngExt;

/// How a room is lit (`scene.lighting` weighs them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mood {
    Even,
    Dim,
    Spot,
    Window,
}

/// Exposure a dim room loses on top of `scene.ev_offset`, in stops.
const DIM_EV: f32 = -1.5;
/// Power range of a dim room's one ceiling panel, relative to its drawn power.
const DIM_POWER: [f32; 2] = [0.1, 0.33];
/// Factor range on the sky's luminance in a window-lit room.
const WINDOW_BOOST: [f32; 2] = [2.0, 5.0];
/// Luminous intensity range of the spot lamp (cd): a ceiling panel gives about 30 cd.
const SPOT_INTENSITY: [f32; 2] = [150.0, 600.0];

impl Gen<'_> {
    fn look_unit(&mut self) -> f32 {
        self.look.random::<f32>()
    }

    fn look_between(&mut self, [a, b]: [f32; 2]) -> f32 {
        a + (b - a) * self.look_unit()
    }

    fn look_chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.look.random::<f64>() < p
    }

    /// The room's lighting mood, by `scene.lighting`'s weights.
    pub(super) fn draw_mood(&mut self) -> Mood {
        let w = self.room.lighting.as_array();
        let moods = [Mood::Even, Mood::Dim, Mood::Spot, Mood::Window];
        let mut t = self.look.random::<f64>() * w.iter().sum::<f64>();
        for (mood, w) in moods.into_iter().zip(w) {
            t -= w;
            if t < 0.0 {
                return mood;
            }
        }
        // Rounding left t at 0: the last mood that can be drawn.
        *moods
            .iter()
            .zip(w)
            .rev()
            .find(|(_, w)| *w > 0.0)
            .expect("a weight")
            .0
    }

    /// The scene's exposure offset in stops: `scene.ev_offset`, less [`DIM_EV`] in a dim room.
    pub(super) fn draw_ev(&mut self) -> f32 {
        let [a, b] = self.room.ev_offset.map(|v| v as f32);
        let ev = if a < b { self.look_between([a, b]) } else { a };
        ev + if self.mood == Mood::Dim { DIM_EV } else { 0.0 }
    }

    /// Emission (luminance `power`) of a lamp of colour temperature `kelvin`, or, by chance
    /// `scene.coloured_light`, of a saturated colour of the same luminance.
    pub(super) fn light_rgb(&mut self, kelvin: f32, power: f32) -> [f32; 3] {
        let rgb = match self.look_chance(self.room.coloured_light) {
            true => {
                let (h, s) = (self.look_unit(), self.look_between([0.35, 0.8]));
                hue_rgb(h, s)
            }
            false => kelvin_rgb(kelvin),
        };
        rgb.map(|c| c * power)
    }

    /// The power factor of ceiling panel `i` in this room's mood: 1 when evenly lit, a
    /// fraction for the first panel of a dim room, 0 (off) otherwise.
    pub(super) fn panel_factor(&mut self, i: u32) -> f32 {
        match self.mood {
            Mood::Even => 1.0,
            Mood::Dim if i == 0 => self.look_between(DIM_POWER),
            _ => 0.0,
        }
    }

    /// The factor on the sky's luminance seen through windows.
    pub(super) fn window_factor(&mut self) -> f32 {
        match self.mood {
            Mood::Window => self.look_between(WINDOW_BOOST),
            _ => 1.0,
        }
    }

    /// `texture` of a room surface or a piece, made plain by chance `scene.plain_share`, or,
    /// where `subtle` allows it, replaced by a low-contrast library texture by chance
    /// `scene.subtle_share`.
    pub(super) fn surface(&mut self, texture: Texture, subtle: bool) -> Texture {
        if self.look_chance(self.room.plain_share) {
            return Texture::constant(base_colour(&texture));
        }
        if subtle && self.look_chance(self.room.subtle_share) {
            let per_family = (self.room.textures / FAMILIES.len() as u32).max(1);
            let k = self.look.random_range(0..SUBTLE.len() as u32 * per_family);
            return Texture::Library {
                seed: self.room.texture_seed,
                index: SUBTLE_BASE + k,
                tint: [1.0; 3],
            };
        }
        texture
    }

    /// The roughness and metalness of a piece's opaque material: as drawn, or glossy by
    /// chance `scene.glossy_share`, else metallic by chance `scene.metallic_share`.
    pub(super) fn finish(&mut self, roughness: f32, metallic: f32) -> (f32, f32) {
        if self.look_chance(self.room.glossy_share) {
            (self.look_between([0.02, 0.12]), 0.0)
        } else if self.look_chance(self.room.metallic_share) {
            (self.look_between([0.05, 0.35]), 1.0)
        } else {
            (roughness, metallic)
        }
    }

    /// The spot lamp of a spot-lit room: just under the ceiling near a side wall, aimed at
    /// a floor point 2.5 m or more ahead of the camera at `eye` (the room's centre line).
    pub(super) fn spot_lamp(&mut self, size: Vec3, eye: Vec3) -> Light {
        let side = if self.look_unit() < 0.5 { -1.0 } else { 1.0 };
        let x = side * (size.x / 2.0 - self.look_between([0.2, 0.6]));
        let z = self.look_between([-size.z / 2.0 + 1.0, eye.z - 1.0]);
        let position = Vec3::new(x, size.y - 0.1, z);
        let ahead = self.look_between([2.5, (eye.z + size.z / 2.0 - 0.5).max(2.5)]);
        let aim = Vec3::new(eye.x + self.look_between([-1.0, 1.0]), 0.0, eye.z - ahead);
        let kelvin = self.look_between([2700.0, 4500.0]);
        let power = self.look_between(SPOT_INTENSITY);
        let inner = self.look_between([0.25, 0.5]);
        Light::Spot {
            position,
            direction: (aim - position).normalize(),
            intensity: self.light_rgb(kelvin, power),
            inner_cone: inner,
            outer_cone: inner + self.look_between([0.1, 0.3]),
            range: None,
        }
    }
}

/// The colour of a plain surface standing in for `texture`: its main colour.
fn base_colour(texture: &Texture) -> [f32; 3] {
    match *texture {
        Texture::Constant { color } => color,
        Texture::Checker { a, .. } | Texture::Stripes { a, .. } | Texture::Noise { a, .. } => a,
        Texture::Library { seed, index, tint } => {
            let a = TextureSpec::from_index(seed, index).a;
            [0, 1, 2].map(|c| a[c] * tint[c])
        }
        Texture::Image { factor, .. } => factor,
    }
}

/// Linear RGB of hue `h` (turns) at saturation `s` and full value, normalised to luminance 1.
fn hue_rgb(h: f32, s: f32) -> [f32; 3] {
    let k = |n: f32| {
        let k = (n + h.rem_euclid(1.0) * 6.0) % 6.0;
        1.0 - s * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    let c = Vec3::new(k(5.0), k(3.0), k(1.0));
    (c / luminance(c)).to_array()
}

#[cfg(test)]
mod tests {
    use super::super::tests::cfg;
    use super::*;
    use crate::scene::SceneDesc;
    use crate::settings::{LightingWeights, RoomSettings};
    use rand_pcg::Pcg32;

    /// Scenes 0..n of the default config with `scene` settings changed by `edit`.
    fn scenes(n: u64, edit: impl Fn(&mut RoomSettings)) -> Vec<SceneDesc> {
        (0..n)
            .map(|i| {
                let mut c = cfg(7);
                edit(&mut c.scene);
                c.scene.validate().unwrap();
                super::super::generate(&c.scene, &c.scene_start(), i, None)
            })
            .collect()
    }

    fn only(mood: usize) -> LightingWeights {
        let mut w = [0.0; 4];
        w[mood] = 1.0;
        LightingWeights {
            even: w[0],
            dim: w[1],
            spot: w[2],
            window: w[3],
        }
    }

    fn panels(d: &SceneDesc) -> Vec<[f32; 3]> {
        (d.objects.iter())
            .filter(|o| o.name.starts_with("light_"))
            .map(|o| d.materials[o.material as usize].emission)
            .collect()
    }

    fn classic(s: &mut RoomSettings) {
        s.lighting = LightingWeights::EVEN;
        (s.coloured_light, s.ev_offset) = (0.0, [0.0, 0.0]);
        (s.plain_share, s.subtle_share) = (0.0, 0.0);
        (s.glossy_share, s.metallic_share) = (0.0, 0.0);
    }

    #[test]
    fn classic_settings_light_every_panel_and_keep_the_exposure() {
        for d in scenes(8, classic) {
            assert_eq!(d.exposure, 1.0);
            assert!(d.lights.is_empty());
            assert!(panels(&d).iter().all(|e| luminance(Vec3::from(*e)) >= 5.9));
        }
    }

    #[test]
    fn each_mood_lights_the_room_as_documented() {
        for d in scenes(6, |s| s.lighting = only(1)) {
            let lit: Vec<f32> = panels(&d).iter().map(|&e| luminance(e.into())).collect();
            assert!(
                lit[0] > 0.5 && lit[0] < 16.0 * DIM_POWER[1] + 1e-3,
                "{lit:?}"
            );
            assert!(lit[1..].iter().all(|&l| l == 0.0), "{lit:?}");
            assert!(
                d.exposure <= 2f32.powf(0.5 + DIM_EV) + 1e-6,
                "{}",
                d.exposure
            );
        }
        for d in scenes(6, |s| s.lighting = only(2)) {
            assert!(panels(&d).iter().all(|e| *e == [0.0; 3]));
            let [Light::Spot { position, .. }] = d.lights[..] else {
                panic!("one spot lamp: {:?}", d.lights);
            };
            let ceiling = d.objects.iter().find(|o| o.name == "ceiling").unwrap();
            assert!(position.y < ceiling.transform.translation.y);
        }
        for d in scenes(6, |s| (s.lighting, s.windows) = (only(3), [0, 0])) {
            assert!(panels(&d).iter().all(|e| *e == [0.0; 3]));
            assert!(
                d.objects.iter().any(|o| o.name == "outside_sky"),
                "a window"
            );
        }
    }

    #[test]
    fn moods_are_drawn_by_their_weights() {
        let (n, c) = (400, cfg(0));
        let moods = [Mood::Even, Mood::Dim, Mood::Spot, Mood::Window];
        let mut counts = [0u32; 4];
        for seed in 0..n {
            let (rng, look) = (Pcg32::new(seed, 1), Pcg32::new(seed, 2));
            let mood = Gen::new(rng, look, &c.scene, &c.start.rig, None).draw_mood();
            counts[moods.iter().position(|&m| m == mood).unwrap()] += 1;
        }
        // Default weights 0.4, 0.2, 0.2, 0.2: every count within 4 standard deviations.
        for (k, w) in counts.iter().zip(c.scene.lighting.as_array()) {
            let (mean, sd) = (w * n as f64, (n as f64 * w * (1.0 - w)).sqrt());
            assert!((*k as f64 - mean).abs() < 4.0 * sd, "{counts:?}");
        }
    }

    #[test]
    fn the_exposure_offset_stays_in_its_range_and_varies() {
        let evs: Vec<f32> = scenes(24, |s| {
            (s.lighting, s.ev_offset) = (LightingWeights::EVEN, [-2.0, 1.0]);
        })
        .iter()
        .map(|d| d.exposure.log2())
        .collect();
        assert!(evs.iter().all(|e| (-2.0..=1.0).contains(e)), "{evs:?}");
        let spread = evs.iter().fold(f32::MIN, |m, &e| m.max(e))
            - evs.iter().fold(f32::MAX, |m, &e| m.min(e));
        assert!(spread > 1.5, "{evs:?}");
    }

    #[test]
    fn plain_and_subtle_shares_replace_the_room_textures() {
        let names = ["floor", "walls", "ceiling"];
        let room = |d: &SceneDesc| -> Vec<Texture> {
            (d.materials.iter())
                .filter(|m| names.contains(&m.name.as_str()))
                .map(|m| m.base_color.clone())
                .collect()
        };
        for d in scenes(6, |s| s.plain_share = 1.0) {
            let t = room(&d);
            assert_eq!(t.len(), 3);
            assert!(
                t.iter().all(|t| matches!(t, Texture::Constant { .. })),
                "{t:?}"
            );
        }
        for d in scenes(6, |s| (s.plain_share, s.subtle_share) = (0.0, 1.0)) {
            for t in room(&d) {
                let Texture::Library { index, .. } = t else {
                    panic!("{t:?}")
                };
                assert!(index >= SUBTLE_BASE, "{index}");
            }
        }
        for d in scenes(6, classic) {
            for t in room(&d) {
                assert!(matches!(t, Texture::Library { index, .. } if index < SUBTLE_BASE));
            }
        }
    }

    #[test]
    fn coloured_lights_keep_their_luminance_and_are_saturated() {
        for d in scenes(4, |s| {
            (s.lighting, s.coloured_light) = (LightingWeights::EVEN, 1.0)
        }) {
            for e in panels(&d) {
                let c = Vec3::from(e);
                let l = luminance(c);
                assert!((6.0..=16.0 + 1e-3).contains(&l), "{l}");
                // Every white of kelvin_rgb has min/max above 0.28; these reach below 0.65·max.
                assert!(c.min_element() < 0.66 * c.max_element(), "{c}");
            }
        }
    }

    #[test]
    fn glossy_and_metallic_shares_set_the_finish_of_pieces() {
        // The roles whose finish `finish` draws (metal is metallic already; rugs, leaves,
        // cloth and bulbs have their own).
        let roles = ["_wood", "_fabric", "_paint", "_ceramic", "_book"];
        let finishes = |d: &SceneDesc| -> Vec<(f32, f32)> {
            (d.materials.iter())
                .filter(|m| m.model == crate::scene::SurfaceModel::Standard)
                .filter(|m| roles.iter().any(|r| m.name.ends_with(r)))
                .map(|m| (m.roughness, m.metallic))
                .collect()
        };
        let glossy: Vec<_> = scenes(3, |s| s.glossy_share = 1.0)
            .iter()
            .flat_map(finishes)
            .collect();
        assert!(glossy.len() > 20);
        assert!(
            glossy
                .iter()
                .all(|&(r, m)| (0.02..=0.12).contains(&r) && m == 0.0),
            "{glossy:?}"
        );
        let metal: Vec<_> = scenes(3, |s| (s.glossy_share, s.metallic_share) = (0.0, 1.0))
            .iter()
            .flat_map(finishes)
            .collect();
        assert!(
            metal
                .iter()
                .all(|&(r, m)| (0.05..=0.35).contains(&r) && m == 1.0),
            "{metal:?}"
        );
    }

    #[test]
    fn bad_appearance_settings_are_refused_naming_the_key() {
        let refused = |edit: &dyn Fn(&mut RoomSettings)| {
            let mut s = RoomSettings::default();
            edit(&mut s);
            s.validate().unwrap_err().to_string()
        };
        assert!(refused(&|s| s.plain_share = 1.5).contains("scene.plain_share"));
        assert!(refused(&|s| s.ev_offset = [1.0, -1.0]).contains("scene.ev_offset"));
        assert!(
            refused(&|s| s.lighting = LightingWeights {
                even: 0.0,
                ..only(0)
            })
            .contains("scene.lighting")
        );
        assert!(refused(&|s| s.lighting.dim = f64::NAN).contains("scene.lighting"));
    }

    #[test]
    fn hue_colours_have_unit_luminance() {
        for h in [0.0, 0.3, 0.55, 0.9] {
            assert!((luminance(Vec3::from(hue_rgb(h, 0.7))) - 1.0).abs() < 1e-5);
        }
    }
}
