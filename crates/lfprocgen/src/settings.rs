//! The generator's own parameters (the `[scene]` section of `generator.toml`) with their
//! bounds, so that procgen reads no CLI configuration.

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

/// Largest room side: scene descriptions hold positions up to 1e6 m, and a room far larger
/// than any real one only hides a typo.
pub const MAX_ROOM_M: f64 = 1000.0;
/// Largest environment or daylight radiance (the sun's luminance is about 1.6e9 cd/m², but
/// scenes are exposed for interiors; 1e6 leaves products of radiances finite in f32).
pub const MAX_RADIANCE: f64 = 1e6;
/// Most pieces drawn per room (each is a placement attempt; 48 by default).
pub const MAX_OBJECTS: u32 = 10_000;
/// Most ceiling lights per room.
pub const MAX_LIGHTS: u32 = 1024;
/// Largest exposure offset either way, in stops (`scene.ev_offset`).
pub const MAX_EV: f64 = 10.0;
/// Largest texture library (each texture is a 768 KiB tile when used).
pub const MAX_TEXTURES: u32 = 100_000;

/// The built-in procedural scene generator.
/// `catalog`'s default: the binary picks the Sweet Home 3D catalogue when it is installed.
pub const AUTO_CATALOG: &str = "auto";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoomSettings {
    /// Room width range (x, metres).
    pub room_width: [f64; 2],
    /// Room depth range (along the view, metres).
    pub room_depth: [f64; 2],
    /// Room height range (metres).
    pub room_height: [f64; 2],
    /// Pieces of furniture and accessories drawn per room (rejected when no free spot is found).
    pub objects: u32,
    /// Probability that a solid material of a piece is semi-transparent (opacity in
    /// `opacity_range`), when it is neither glass nor a cut-out.
    pub semi_transparent: f64,
    pub opacity_range: [f64; 2],
    /// Probability that a solid material of a piece is glass (smooth dielectric).
    pub glass: f64,
    /// Probability that a solid material becomes a grid / woven alpha cut-out.
    pub cutout: f64,
    /// Size of the procedural texture library that room and object textures are drawn from
    /// (`lfgen textures --count N` writes the same textures to files).
    pub textures: u32,
    /// Master seed of that texture library (independent of the dataset seed, so every
    /// dataset draws from the same library).
    pub texture_seed: u64,
    /// Number of ceiling area lights (random colour temperature and luminance each).
    pub lights: u32,
    /// Radiance of the environment seen through openings (linear RGB).
    pub environment: [f64; 3],
    /// Number of windows in the back wall, drawn from `[min, max]`.
    pub windows: [u32; 2],
    /// Probability of a door in the back wall.
    pub door: f64,
    /// Luminance range of the sky seen through windows (linear; the outdoor layers in front
    /// of it emit 0.2–0.6 of it).
    pub window_light: [f64; 2],
    /// Asset catalogue (`catalog.json`) to draw pieces from besides the procedural furniture;
    /// empty: procedural only. The binary resolves `"auto"` (its default) to the Sweet Home 3D
    /// catalogue where `lfgen assets fetch sweethome3d` writes it, or to empty.
    pub catalog: String,
    /// With a catalogue: the share of pieces drawn from it (the rest are procedural).
    pub catalog_share: f64,
    /// Weights of catalogue categories (absent ones weigh 1), times each entry's own weight.
    pub category_weights: std::collections::BTreeMap<String, f64>,
    /// How each room is lit, drawn per scene by these weights (see [`LightingWeights`]).
    pub lighting: LightingWeights,
    /// Probability that a light (ceiling panel, spot) has a saturated colour instead of a
    /// white of random colour temperature.
    pub coloured_light: f64,
    /// Exposure offset in stops, drawn uniformly from `[min, max]` per scene and applied on
    /// top of the automatic exposure: negative values leave a scene darker than mid grey.
    pub ev_offset: [f64; 2],
    /// Probability that a room surface or a piece's solid material is texture-poor: one plain
    /// colour instead of its texture.
    pub plain_share: f64,
    /// Probability that a wall, ceiling, floor or painted surface takes a low-contrast
    /// texture (smooth plaster, concrete, paint wash or paper; luminance within ±4 % of its
    /// mean) instead of one of the library's textured families.
    pub subtle_share: f64,
    /// Probability that a piece's opaque dielectric material is glossy (GGX roughness
    /// 0.02–0.12) ...
    pub glossy_share: f64,
    /// ... and, of the rest, that it is metallic (roughness 0.05–0.35).
    pub metallic_share: f64,
}

/// Relative weights of the lighting moods a room is drawn with (they need not sum to 1; at
/// least one must be positive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightingWeights {
    /// Every ceiling panel on, evenly lighting the room.
    pub even: f64,
    /// A dim room: one ceiling panel at a tenth to a third of its power, and 1.5 stops less
    /// exposure on top of `ev_offset`.
    pub dim: f64,
    /// Ceiling panels off; one spot lamp high on a wall aimed into the room (a point source:
    /// hard shadows).
    pub spot: f64,
    /// Ceiling panels off; at least one window, its sky 2–5 times `window_light`: light
    /// from the back wall and dark corners.
    pub window: f64,
}

impl LightingWeights {
    /// The classic generator's lighting: every room evenly lit.
    pub const EVEN: Self = Self {
        even: 1.0,
        dim: 0.0,
        spot: 0.0,
        window: 0.0,
    };

    /// The weights in the order even, dim, spot, window.
    pub fn as_array(&self) -> [f64; 4] {
        [self.even, self.dim, self.spot, self.window]
    }
}

impl Default for LightingWeights {
    fn default() -> Self {
        Self {
            even: 0.4,
            dim: 0.2,
            spot: 0.2,
            window: 0.2,
        }
    }
}

impl Default for RoomSettings {
    fn default() -> Self {
        Self {
            room_width: [4.0, 7.0],
            room_depth: [7.0, 12.0],
            room_height: [2.6, 3.4],
            objects: 48,
            semi_transparent: 0.3,
            opacity_range: [0.25, 0.75],
            glass: 0.1,
            cutout: 0.15,
            textures: 750,
            texture_seed: 0,
            lights: 4,
            environment: [0.2, 0.22, 0.25],
            windows: [0, 2],
            door: 0.35,
            window_light: [2.0, 6.0],
            catalog: AUTO_CATALOG.into(),
            catalog_share: 0.5,
            category_weights: std::collections::BTreeMap::new(),
            lighting: LightingWeights::default(),
            coloured_light: 0.15,
            ev_offset: [-1.5, 0.5],
            plain_share: 0.2,
            subtle_share: 0.4,
            glossy_share: 0.15,
            metallic_share: 0.1,
        }
    }
}

impl RoomSettings {
    /// Checks ranges, probabilities and the bounds above; the error names the key.
    pub fn validate(&self) -> Result<()> {
        let ranges = [
            self.room_width,
            self.room_depth,
            self.room_height,
            self.opacity_range,
        ];
        if ranges
            .iter()
            .any(|[a, b]| !(a.is_finite() && b.is_finite() && *a > 0.0 && a <= b))
        {
            bail!("scene ranges must be positive [min, max] pairs");
        }
        let rooms = [self.room_width, self.room_depth, self.room_height];
        if rooms.iter().flatten().any(|&m| m > MAX_ROOM_M) {
            bail!(
                "scene.room_width, room_depth and room_height must be at most {MAX_ROOM_M} m, \
                 got {:?}, {:?}, {:?}",
                self.room_width,
                self.room_depth,
                self.room_height
            );
        }
        if self
            .environment
            .iter()
            .any(|v| !(0.0..=MAX_RADIANCE).contains(v))
        {
            bail!(
                "scene.environment must be 0 to {MAX_RADIANCE}, got {:?}",
                self.environment
            );
        }
        if self.objects > MAX_OBJECTS || self.lights > MAX_LIGHTS || self.textures > MAX_TEXTURES {
            bail!(
                "scene.objects (≤ {MAX_OBJECTS}), scene.lights (≤ {MAX_LIGHTS}) or scene.textures \
                 (≤ {MAX_TEXTURES}) is too large: {}, {}, {}",
                self.objects,
                self.lights,
                self.textures
            );
        }
        if self.textures < 14 {
            bail!("scene.textures must be at least 14 (one per texture family)");
        }
        let probs = [self.semi_transparent, self.glass, self.cutout];
        if probs.iter().any(|p| !(0.0..=1.0).contains(p)) || self.opacity_range[1] > 1.0 {
            bail!("scene probabilities and opacities must lie in [0, 1]");
        }
        if self.windows[0] > self.windows[1] || self.windows[1] > 4 {
            bail!("scene.windows must be [min, max] with min <= max <= 4");
        }
        let [a, b] = self.window_light;
        if !((0.0..=1.0).contains(&self.door) && b <= MAX_RADIANCE && 0.0 <= a && a <= b) {
            bail!("scene.door must lie in [0, 1] and scene.window_light be a [min, max] range");
        }
        if !(0.0..=1.0).contains(&self.catalog_share) {
            bail!("scene.catalog_share must lie in [0, 1]");
        }
        if let Some((c, w)) =
            (self.category_weights.iter()).find(|(_, w)| !(w.is_finite() && **w >= 0.0))
        {
            bail!("scene.category_weights: {c:?} has weight {w}, expected a number >= 0");
        }
        self.validate_appearance()
    }

    fn validate_appearance(&self) -> Result<()> {
        let weights = self.lighting.as_array();
        if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0))
            || weights.iter().sum::<f64>() <= 0.0
        {
            bail!(
                "scene.lighting weights must be numbers >= 0, at least one positive, got {:?}",
                self.lighting
            );
        }
        let [a, b] = self.ev_offset;
        if !(a.is_finite() && b.is_finite() && a <= b && a >= -MAX_EV && b <= MAX_EV) {
            bail!(
                "scene.ev_offset must be a [min, max] range within ±{MAX_EV} stops, got {:?}",
                self.ev_offset
            );
        }
        let shares = [
            ("coloured_light", self.coloured_light),
            ("plain_share", self.plain_share),
            ("subtle_share", self.subtle_share),
            ("glossy_share", self.glossy_share),
            ("metallic_share", self.metallic_share),
        ];
        if let Some((key, p)) = shares.iter().find(|(_, p)| !(0.0..=1.0).contains(p)) {
            bail!("scene.{key} must lie in [0, 1], got {p}");
        }
        Ok(())
    }
}
