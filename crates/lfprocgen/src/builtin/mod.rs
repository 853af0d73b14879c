//! The built-in procedural scene generator: a deep closed room — floor, walls and ceiling
//! textured from the procedural texture library at their real tile sizes, skirting, ceiling
//! lights of random colour temperature — furnished with pieces of the procedural furniture
//! library ([`furniture`](crate::furniture)) placed without collisions
//! ([`placement`](crate::placement)) where the narrow HCI lens sees them, plus accessories on
//! their tops.
//!
//! Everything is drawn from one RNG stream per (seed, scene index), so a scene is a pure
//! function of the config. [`generate`] holds the order of the draws; one `Gen` carries the
//! stream and the scene under construction through its parts, each in its own file:
//! `palette` (materials), `shell` (room, lights, camera), `outdoors` (openings and what lies
//! behind them), `furnish` (pieces and their placement) and `look` (lighting mood, exposure
//! offset and surface finishes, from a stream of their own).

mod furnish;
mod look;
mod outdoors;
mod palette;
mod shell;

use super::library::AssetLibrary;
use super::openings::Opening;
use super::settings::RoomSettings;
use crate::camera::LightFieldCamera;
use crate::scene::{Material, Object, SceneDesc, SceneStart, Shape, SourceFile, Transform};
use crate::util::colour::luminance;
use crate::util::hash::mix64;
use glam::Vec3;
use look::Mood;
use rand::RngExt;
use rand_pcg::Pcg32;

/// Skirting board height and thickness.
const SKIRTING: [f32; 2] = [0.08, 0.015];

/// Generates scene `index` of a dataset: a room drawn by `room`, starting from `start`. The
/// camera's baseline, focus and the slice range are provisional until the renderer frames the
/// scene.
pub fn generate(
    room: &RoomSettings,
    start: &SceneStart,
    index: u64,
    library: Option<&AssetLibrary>,
) -> SceneDesc {
    let mut g = Gen::new(
        Pcg32::new(mix64(start.seed ^ mix64(index)), 0x5CE7E),
        Pcg32::new(mix64(start.seed ^ mix64(index)), 0x1_00C5),
        room,
        &start.rig,
        library,
    );
    g.mood = g.draw_mood();
    let ev = g.draw_ev();
    let s = room;
    let size = Vec3::new(
        g.range(s.room_width),
        g.range(s.room_height),
        g.range(s.room_depth),
    );
    g.room(size);
    g.lights(size);
    let camera = g.camera(size);
    let report = g.furnish(size, &camera);
    let lights = match g.mood {
        Mood::Spot => vec![g.spot_lamp(size, camera.position.as_vec3())],
        _ => Vec::new(),
    };
    SceneDesc {
        generator: format!("lfgen {}", env!("CARGO_PKG_VERSION")),
        name: format!("scene_{index:04}"),
        index,
        seed: start.seed,
        camera,
        slices: start.slices,
        environment: s.environment.map(|v| v as f32),
        exposure: start.exposure * ev.exp2(),
        materials: g.materials,
        objects: g.objects,
        lights,
        placement: Some(report),
        sources: g.sources,
    }
}

struct Gen<'a> {
    rng: Pcg32,
    /// The stream of the scene's look (`look`), apart from `rng` so that looks can vary
    /// without moving any other draw.
    look: Pcg32,
    mood: Mood,
    room: &'a RoomSettings,
    /// The camera rig the room's camera aims.
    rig: &'a LightFieldCamera,
    library: Option<&'a AssetLibrary>,
    materials: Vec<Material>,
    objects: Vec<Object>,
    /// Model files of the catalogue pieces placed so far.
    sources: Vec<SourceFile>,
    /// Window and door openings of the back wall.
    openings: Vec<Opening>,
}

impl<'a> Gen<'a> {
    fn new(
        rng: Pcg32,
        look: Pcg32,
        room: &'a RoomSettings,
        rig: &'a LightFieldCamera,
        library: Option<&'a AssetLibrary>,
    ) -> Self {
        Self {
            rng,
            look,
            mood: Mood::Even,
            room,
            rig,
            library,
            materials: Vec::new(),
            objects: Vec::new(),
            sources: Vec::new(),
            openings: Vec::new(),
        }
    }

    fn range(&mut self, [a, b]: [f64; 2]) -> f32 {
        self.rng.random_range(a..=b) as f32
    }

    fn between(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit()
    }

    fn unit(&mut self) -> f32 {
        self.rng.random::<f32>()
    }

    fn chance(&mut self, p: f64) -> bool {
        self.rng.random::<f64>() < p
    }

    fn color(&mut self) -> [f32; 3] {
        let base = 0.15 + 0.6 * self.unit();
        [0, 1, 2].map(|_| (base * (0.6 + 0.8 * self.unit())).min(0.9))
    }

    fn add(&mut self, name: &str, shape: Shape, transform: Transform, material: u32) {
        self.objects.push(Object {
            name: name.into(),
            shape,
            transform,
            material,
        });
    }
}

/// Linear RGB of a black body at `kelvin`, normalised to luminance 1: a smooth fit between
/// warm white (2700 K) and daylight (6500 K), which is all the lights need.
fn kelvin_rgb(kelvin: f32) -> [f32; 3] {
    let t = ((kelvin - 2700.0) / 3800.0).clamp(0.0, 1.0);
    let warm = Vec3::new(1.0, 0.62, 0.30);
    let cool = Vec3::new(0.95, 0.98, 1.05);
    let c = warm.lerp(cool, t);
    (c / luminance(c)).to_array()
}

#[cfg(test)]
mod tests {
    use super::furnish::{PieceMaterials, View};
    use super::*;
    use crate::furniture::{self, Kind};
    use crate::openings::REVEAL;
    use crate::placement::Layout;
    use glam::{DVec3, Vec2};
    use std::collections::BTreeMap;

    /// lfgen's default `[scene]` settings, and what its default config starts a scene with
    /// (the HCI rig: 512², 9×9 views, 100 mm lens on a 35 mm sensor, 50 mm baseline, focus at
    /// 3 m; 128 depth slices; exposure 1), with dataset seed `seed`.
    pub(super) struct Cfg {
        pub(super) scene: RoomSettings,
        pub(super) start: SceneStart,
    }

    impl Cfg {
        pub(super) fn scene_start(&self) -> SceneStart {
            self.start.clone()
        }
    }

    pub(super) fn cfg(seed: u64) -> Cfg {
        let rig = LightFieldCamera {
            resolution: [512, 512],
            grid: [9, 9],
            focal_length_mm: 100.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.05,
            focus_distance_m: 3.0,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let slices = crate::scene::SliceRange::unframed(128, crate::scene::SliceSpacing::Depth);
        Cfg {
            scene: RoomSettings::default(),
            start: SceneStart {
                rig,
                seed,
                slices,
                exposure: 1.0,
            },
        }
    }

    /// Re-derives every placed piece's body from the scene's objects is not possible after
    /// emission, so the layout is checked through the generator itself on many seeds.
    #[test]
    fn placement_is_collision_free_and_inside_the_room_on_many_seeds() {
        for seed in 0..40 {
            let c = cfg(seed);
            let (rng, look) = (Pcg32::new(mix64(seed), 1), Pcg32::new(mix64(seed), 2));
            let mut g = Gen::new(rng, look, &c.scene, &c.start.rig, None);
            let room = Vec3::new(
                g.range(c.scene.room_width),
                g.range(c.scene.room_height),
                g.range(c.scene.room_depth),
            );
            let cam = g.camera(room);
            let view = View::of(&cam, room);
            let mut layout = Layout::new(room);
            let mut placed = 0;
            for i in 0..60 {
                let kind = Kind::ALL[i % Kind::ALL.len()];
                let mut mats = PieceMaterials {
                    owner: &mut g,
                    name: "x".into(),
                    by_role: BTreeMap::new(),
                };
                let piece =
                    furniture::build(kind, &mut Pcg32::new(seed * 100 + i as u64, 2), &mut mats);
                placed += g.place(&piece, &mut layout, &view).is_some() as u32;
            }
            assert!(placed >= 25, "seed {seed}: only {placed} placed");
            let b = &layout.bodies;
            for (i, a) in b.iter().enumerate() {
                assert!(layout.in_room(a), "seed {seed}: body {i} outside the room");
                for c in &b[i + 1..] {
                    // Accessories touch their host's top only (height intervals meet).
                    assert!(
                        !a.collides(c, 0.0)
                            || (a.y[1] - c.y[0]).abs() < 0.05
                            || (c.y[1] - a.y[0]).abs() < 0.05,
                        "seed {seed}: {a:?} hits {c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn scenes_are_deterministic_per_seed_and_index_and_report_placement() {
        let c = cfg(5);
        let a = generate(&c.scene, &c.scene_start(), 3, None);
        assert_eq!(a, generate(&c.scene, &c.scene_start(), 3, None));
        assert_ne!(a, generate(&c.scene, &c.scene_start(), 4, None));
        let r = a.placement.clone().unwrap();
        assert_eq!(r.requested, c.scene.objects);
        assert_eq!(r.placed + r.rejected, r.requested);
        assert!(r.placed >= 30, "{r:?}");
        assert!(
            a.objects
                .iter()
                .all(|o| (o.material as usize) < a.materials.len())
        );
        let json = serde_json::to_string(&a).unwrap();
        assert!(
            json.len() < 400_000,
            "scene.json stays small: {} bytes",
            json.len()
        );
        let back: SceneDesc = serde_json::from_str(&json).unwrap();
        assert_eq!(back, a);
    }

    /// The emitted geometry itself — every vertex of every part — stays inside the room box.
    #[test]
    fn every_triangle_of_a_scene_is_inside_its_room() {
        use crate::scene::assets::Assets;
        use crate::scene::shapes::tessellate;
        for seed in 0..12 {
            let desc = generate(&cfg(seed).scene, &cfg(seed).scene_start(), seed, None);
            let room = desc
                .objects
                .iter()
                .find(|o| o.name == "floor")
                .map(|o| match o.shape {
                    Shape::Quad { size } => Vec2::from(size),
                    _ => unreachable!("the floor is a quad"),
                })
                .unwrap();
            let ceiling = desc.objects.iter().find(|o| o.name == "ceiling").unwrap();
            let height = ceiling.transform.translation.y;
            let mut tris = Vec::new();
            for o in &desc.objects {
                tris.clear();
                tessellate(&o.shape, &o.transform, &Assets::default(), &mut tris).unwrap();
                for p in tris.iter().flat_map(|t| t.p) {
                    // What lies beyond the openings is behind the back wall, all else inside.
                    let inside = match o.name.starts_with("outside_") {
                        true => p.z <= -room.y / 2.0 + 1e-3,
                        false => {
                            p.x.abs() <= room.x / 2.0 + 1e-3
                                && p.z.abs() <= room.y / 2.0 + 1e-3
                                && (-1e-3..=height + 1e-3).contains(&p.y)
                        }
                    };
                    assert!(inside, "seed {seed}: {} has a vertex at {p}", o.name);
                }
            }
        }
    }

    /// Behind every window: a sky, and emitting layers at more than one depth in front of it,
    /// every one of them textured (structure for a depth method), all beyond the wall.
    #[test]
    fn windows_look_out_on_textured_layers_at_several_depths() {
        let mut windows = 0;
        for seed in 0..20 {
            let desc = generate(&cfg(seed).scene, &cfg(seed).scene_start(), seed, None);
            let wall = desc.objects.iter().find(|o| o.name == "wall_back").unwrap();
            let z_wall = wall.transform.translation.z;
            let outside: Vec<_> = (desc.objects.iter())
                .filter(|o| desc.materials[o.material as usize].is_emissive())
                .filter(|o| o.transform.translation.z < z_wall - REVEAL)
                .collect();
            let skies = outside.iter().filter(|o| o.name == "outside_sky").count();
            windows += skies;
            for o in &outside {
                let m = &desc.materials[o.material as usize];
                assert!(m.emission_map.is_some(), "seed {seed}: {} is flat", o.name);
            }
            let mut depths: Vec<f32> = outside.iter().map(|o| o.transform.translation.z).collect();
            depths.sort_by(f32::total_cmp);
            depths.dedup_by(|a, b| (*a - *b).abs() < 0.05);
            if skies > 0 {
                assert!(
                    outside.len() >= 3 * skies,
                    "seed {seed}: {} layers",
                    outside.len()
                );
                assert!(depths.len() >= 3, "seed {seed}: depths {depths:?}");
            }
        }
        assert!(windows >= 10, "{windows} windows");
    }

    /// Openings appear, the back wall has exactly their holes, windows have a sky behind
    /// them, and no piece hangs across a window or stands in a doorway.
    #[test]
    fn openings_are_cut_lit_and_kept_clear() {
        use crate::scene::assets::Assets;
        use crate::scene::shapes::tessellate;
        let (mut windows, mut doors) = (0, 0);
        for seed in 0..20 {
            let desc = generate(&cfg(seed).scene, &cfg(seed).scene_start(), seed, None);
            let wall = desc.objects.iter().find(|o| o.name == "wall_back").unwrap();
            let (Shape::Wall { size, holes }, z) = (&wall.shape, wall.transform.translation.z)
            else {
                panic!("the back wall is a wall with holes");
            };
            let daylight = desc.objects.iter().any(|o| o.name == "outside_sky");
            let mut lit = false;
            for h in holes {
                let (x0, x1, y0, y1) = (h[0], h[2], h[1] + size[1] / 2.0, h[3] + size[1] / 2.0);
                let door = y0 == 0.0;
                (doors, windows) = (doors + door as u32, windows + !door as u32);
                lit |= !door;
                // Nothing but the room and the outside within 3 cm of the wall in the hole
                // (pictures), nor in the 0.9 m in front of a door.
                let reach = if door { 0.9 } else { 0.03 };
                let mut tris = Vec::new();
                for o in desc
                    .objects
                    .iter()
                    .filter(|o| o.name.starts_with("object_"))
                {
                    tris.clear();
                    tessellate(&o.shape, &o.transform, &Assets::default(), &mut tris).unwrap();
                    for p in tris.iter().flat_map(|t| t.p) {
                        let blocks = p.x > x0 + 1e-3
                            && p.x < x1 - 1e-3
                            && p.y > y0 + 0.02
                            && p.y < y1 - 1e-3
                            && p.z < z + reach;
                        assert!(!blocks, "seed {seed}: {} at {p} in opening {h:?}", o.name);
                    }
                }
            }
            assert_eq!(lit, daylight, "seed {seed}: a sky exactly behind windows");
        }
        assert!(
            windows >= 10 && doors >= 3,
            "{windows} windows, {doors} doors"
        );
    }

    #[test]
    fn colour_temperatures_are_warm_to_cool_at_unit_luminance() {
        let (warm, cool) = (kelvin_rgb(2700.0), kelvin_rgb(6500.0));
        assert!(warm[0] > warm[2] && cool[2] > cool[0]);
        let lum = |c: [f32; 3]| luminance(Vec3::from(c));
        assert!((lum(warm) - 1.0).abs() < 1e-5 && (lum(cool) - 1.0).abs() < 1e-5);
    }
}
