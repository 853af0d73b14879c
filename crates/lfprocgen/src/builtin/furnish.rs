//! Furnishing: which pieces a scene gets (built-in kinds or catalogue assets), where they go
//! (on the floor in the camera's view, against a wall, on top of another piece), and the
//! materials of each piece's roles.

use super::{Gen, SKIRTING};
use crate::camera::LightFieldCamera;
use crate::furniture::{self, Kind, MaterialSource, Piece, Placement, Role};
use crate::placement::{Body, Footprint, Layer, Layout, PlacementReport, WorldSurface};
use crate::scene::Transform;
use glam::{Quat, Vec2, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::collections::BTreeMap;
use std::f32::consts::{FRAC_PI_2, TAU};

/// Closest distance from the camera at which pieces are placed (metres).
const NEAR: f32 = 2.0;
/// Pieces taller than [`TALL`] keep [`TALL_NEAR`] metres from the camera: closer, a screen or
/// a bookshelf would fill the narrow view on its own.
const TALL: f32 = 1.3;
const TALL_NEAR: f32 = 4.0;
/// Extra width beyond the view frustum where pieces still count as visible (they cut the
/// image border as partial occluders).
const VIEW_MARGIN: f32 = 0.5;
/// Random positions tried per piece before it is rejected.
const TRIES: u32 = 60;

/// What a furniture slot of a scene is filled with.
#[derive(Clone, Copy, Debug)]
enum Pick {
    Kind(Kind),
    /// Entry of the asset library.
    Asset(usize),
}

/// Resolves the roles of one piece to materials, one material per role.
pub(super) struct PieceMaterials<'g, 'a> {
    pub(super) owner: &'g mut Gen<'a>,
    pub(super) name: String,
    pub(super) by_role: BTreeMap<Role, u32>,
}

impl MaterialSource for PieceMaterials<'_, '_> {
    fn material(&mut self, role: Role) -> u32 {
        if let Some(&m) = self.by_role.get(&role) {
            return m;
        }
        let m = self.owner.role_material(&self.name, role);
        self.by_role.insert(role, m);
        m
    }
}

impl Gen<'_> {
    /// Draws `scene.objects` pieces — by kind weight, and with an asset library a share of
    /// them by catalogue weight — and places them: floor and wall pieces first, then
    /// accessories on their surfaces.
    pub(super) fn furnish(&mut self, room: Vec3, cam: &LightFieldCamera) -> PlacementReport {
        let kinds: Vec<f32> = Kind::ALL.iter().map(|k| k.weight()).collect();
        let assets = self
            .library
            .map(|lib| lib.weights(&self.room.category_weights));
        let mut picks: Vec<Pick> = (0..self.room.objects)
            .map(|_| self.pick(&kinds, assets.as_deref()))
            .collect();
        picks.sort_by_key(|&p| self.placement_of(p) == Placement::OnTop);
        let view = View::of(cam, room);
        let mut layout = Layout::new(room);
        for o in &self.openings {
            layout.add(o.keep_clear(-room.z / 2.0));
        }
        let mut report = PlacementReport {
            requested: picks.len() as u32,
            ..PlacementReport::default()
        };
        for (i, pick) in picks.into_iter().enumerate() {
            let before = (self.materials.len(), self.objects.len(), self.sources.len());
            let (name, piece) = self.build(i, pick);
            match self.place(&piece, &mut layout, &view) {
                Some(xf) => {
                    report.placed += 1;
                    report.on_top += (piece.placement == Placement::OnTop) as u32;
                    report.from_catalog += matches!(pick, Pick::Asset(_)) as u32;
                    self.emit(&name, &piece, &xf);
                }
                None => {
                    report.rejected += 1;
                    self.materials.truncate(before.0);
                    self.objects.truncate(before.1);
                    self.sources.truncate(before.2);
                }
            }
        }
        report
    }

    /// Draws what fills one furniture slot. Without a library the draws are exactly those of
    /// the procedural generator alone.
    /// `kinds` and `assets` are the weights of the procedural kinds and of the library's
    /// entries (computed once per scene).
    fn pick(&mut self, kinds: &[f32], assets: Option<&[f32]>) -> Pick {
        if let Some(weights) = assets
            && self.chance(self.room.catalog_share)
        {
            return Pick::Asset(self.weighted(weights).unwrap_or(0));
        }
        Pick::Kind(Kind::ALL[self.weighted(kinds).unwrap_or(Kind::ALL.len() - 1)])
    }

    /// An index drawn with probability proportional to `weights` (`None`: all zero).
    fn weighted(&mut self, weights: &[f32]) -> Option<usize> {
        let mut t = self.unit() * weights.iter().sum::<f32>();
        weights.iter().position(|w| {
            t -= w;
            t < 0.0
        })
    }

    fn placement_of(&self, pick: Pick) -> Placement {
        match (pick, self.library) {
            (Pick::Kind(k), _) => k.placement(),
            (Pick::Asset(i), Some(lib)) => lib.piece_placement(i),
            (Pick::Asset(_), None) => unreachable!("assets are drawn from a library"),
        }
    }

    /// Builds the piece of slot `i` with its own RNG stream and materials.
    fn build(&mut self, i: usize, pick: Pick) -> (String, Piece) {
        let mut rng = Pcg32::new(self.rng.random(), 0xF0_0D);
        match pick {
            Pick::Kind(kind) => {
                let name = format!("object_{i}_{kind:?}").to_lowercase();
                let mut mats = PieceMaterials {
                    owner: self,
                    name: name.clone(),
                    by_role: BTreeMap::new(),
                };
                (name, furniture::build(kind, &mut rng, &mut mats))
            }
            Pick::Asset(a) => {
                let lib = self.library.expect("assets are drawn from a library");
                let name = format!("object_{i}_{}", identifier(&lib.asset(a).id));
                let file = lib.source(a);
                let source = match self.sources.iter().position(|s| s.path == file.path) {
                    Some(s) => s,
                    None => {
                        self.sources.push(file.clone());
                        self.sources.len() - 1
                    }
                };
                let piece = lib.piece(a, source as u32, &mut |mut m| {
                    m.name = format!("{name}_{}", m.name);
                    self.randomised(m)
                });
                (name, piece)
            }
        }
    }

    /// Adds the parts of `piece` placed by `at` (yaw and floor position).
    fn emit(&mut self, name: &str, piece: &Piece, at: &Transform) {
        for part in &piece.parts {
            let xf = Transform {
                translation: at.rotation * part.transform.translation + at.translation,
                rotation: at.rotation * part.transform.rotation,
                scale: part.transform.scale,
            };
            self.add(
                &format!("{name}_{}", part.name),
                part.shape.clone(),
                xf,
                part.material,
            );
        }
    }

    /// Finds a free spot for `piece`; registers its body and surfaces and returns its
    /// placement, or `None` after [`TRIES`] attempts.
    pub(super) fn place(
        &mut self,
        piece: &Piece,
        layout: &mut Layout,
        view: &View,
    ) -> Option<Transform> {
        for _ in 0..TRIES {
            let candidate = match piece.placement {
                Placement::OnTop => self.on_top_spot(piece, layout),
                Placement::Wall | Placement::WallHung => self.wall_spot(piece, layout.room, view),
                Placement::Floor if self.chance(0.25) => self.wall_spot(piece, layout.room, view),
                Placement::Floor | Placement::FloorCover => Some(self.floor_spot(piece, view)),
                Placement::Ceiling => {
                    let (fp, _, host) = self.floor_spot(piece, view);
                    Some((fp, layout.room.y - piece.height, host))
                }
            };
            let Some((footprint, base, host)) = candidate else {
                continue;
            };
            let body = Body {
                footprint,
                y: [base + piece.elevation, base + piece.height],
                layer: match piece.placement {
                    Placement::FloorCover => Layer::Cover,
                    _ => Layer::Solid,
                },
            };
            if !view.sees(&footprint, body.y[1]) || !layout.fits(&body, host) {
                continue;
            }
            let index = layout.add(body);
            if piece.placement != Placement::OnTop {
                for s in &piece.surfaces {
                    let area = Footprint {
                        centre: footprint.to_world(s.centre),
                        half: s.half,
                        yaw: footprint.yaw,
                    };
                    layout.surfaces.push(WorldSurface {
                        area,
                        y: base + s.y,
                        clearance: s.clearance,
                        host: index,
                    });
                }
            }
            let mut xf = Transform::at(Vec3::new(footprint.centre.x, base, footprint.centre.y));
            xf.rotation = Quat::from_rotation_y(footprint.yaw);
            return Some(xf);
        }
        None
    }

    /// A free-standing spot inside the view wedge: random yaw, often square to the room.
    fn floor_spot(&mut self, piece: &Piece, view: &View) -> (Footprint, f32, Option<usize>) {
        let dist = self.between(NEAR, view.far);
        let half_w = view.half_width(dist);
        let x = view.x + self.between(-half_w, half_w);
        let yaw = if self.chance(0.5) {
            self.rng.random_range(0..4) as f32 * FRAC_PI_2 + self.between(-0.15, 0.15)
        } else {
            self.unit() * TAU
        };
        let fp = Footprint {
            centre: Vec2::new(x, view.z - dist),
            half: piece.half,
            yaw,
        };
        (fp, 0.0, None)
    }

    /// A spot with the piece's back against the back wall (or, rarely, a side wall).
    fn wall_spot(
        &mut self,
        piece: &Piece,
        room: Vec3,
        view: &View,
    ) -> Option<(Footprint, f32, Option<usize>)> {
        // Pictures hang flush on the wall; standing pieces clear the skirting.
        let off = match piece.placement {
            Placement::WallHung => piece.half.y,
            _ => SKIRTING[1] + 0.005 + piece.half.y,
        };
        let (centre, yaw) = match self.rng.random_range(0..5) {
            0..=2 => {
                let half_w = view.half_width(view.z + room.z / 2.0);
                let x = view.x + self.between(-half_w, half_w);
                (Vec2::new(x, -room.z / 2.0 + off), 0.0)
            }
            k => {
                let side = if k == 3 { -1.0 } else { 1.0 };
                let z = self.between(-room.z / 2.0, view.z - NEAR);
                (Vec2::new(side * (room.x / 2.0 - off), z), -side * FRAC_PI_2)
            }
        };
        let fp = Footprint {
            centre,
            half: piece.half,
            yaw,
        };
        Some((fp, 0.0, None))
    }

    /// A spot on a random surface that is large and high enough for the accessory.
    fn on_top_spot(
        &mut self,
        piece: &Piece,
        layout: &Layout,
    ) -> Option<(Footprint, f32, Option<usize>)> {
        let fitting: Vec<&WorldSurface> = layout
            .surfaces
            .iter()
            .filter(|s| {
                s.clearance >= piece.height
                    && s.area.half.cmpge(piece.half).all()
                    && s.y + piece.height <= layout.room.y - 0.05
            })
            .collect();
        if fitting.is_empty() {
            return None;
        }
        let s = *fitting[self.rng.random_range(0..fitting.len())];
        let room = (s.area.half - piece.half.max_element()).max(Vec2::ZERO);
        let local = Vec2::new(self.between(-room.x, room.x), self.between(-room.y, room.y));
        let fp = Footprint {
            centre: s.area.to_world(local),
            half: piece.half,
            yaw: self.unit() * TAU,
        };
        s.area.contains(&fp).then_some((fp, s.y, Some(s.host)))
    }
}

/// A catalogue id as part of an object name: letters and digits, the rest `_`.
fn identifier(id: &str) -> String {
    id.chars()
        .map(|c| match c.is_ascii_alphanumeric() {
            true => c.to_ascii_lowercase(),
            false => '_',
        })
        .collect()
}

/// The part of the floor the centre camera sees: a wedge from the camera along −Z, widened
/// by [`VIEW_MARGIN`].
pub(super) struct View {
    x: f32,
    z: f32,
    /// tan of half the horizontal field of view.
    tan_half: f32,
    /// Distance to the back wall.
    far: f32,
}

impl View {
    pub(super) fn of(cam: &LightFieldCamera, room: Vec3) -> Self {
        let z = cam.position.z as f32;
        Self {
            x: cam.position.x as f32,
            z,
            tan_half: (cam.sensor_size_mm / 2.0 / cam.focal_length_mm) as f32,
            far: z + room.z / 2.0,
        }
    }

    fn half_width(&self, dist: f32) -> f32 {
        self.tan_half * dist + VIEW_MARGIN
    }

    /// Whether some part of the footprint lies in the wedge, and none of it closer to the
    /// camera than [`NEAR`] − 0.5 m ([`TALL_NEAR`] for a piece whose `top` is above [`TALL`]).
    fn sees(&self, fp: &Footprint, top: f32) -> bool {
        let near = if top > TALL { TALL_NEAR } else { NEAR - 0.5 };
        let corners = fp.corners();
        let near_ok = corners.iter().all(|c| self.z - c.y >= near);
        near_ok
            && corners.iter().chain([&fp.centre]).any(|c| {
                let dist = self.z - c.y;
                (c.x - self.x).abs() <= self.half_width(dist)
            })
    }
}
