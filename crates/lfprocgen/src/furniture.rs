//! Procedural furniture and accessories: the embedded default asset library (no download).
//!
//! A [`Piece`] is a group of parametric parts sharing one placement, built in its own frame:
//! origin on the floor at the centre of its footprint, front towards +Z, back towards −Z (the
//! side that goes against a wall). It reports its footprint (a rectangle, oriented once
//! placed) and the surfaces others can stand on, which is all the placement needs.
//!
//! Every kind draws its proportions continuously and its structure (leg style, number of
//! shelves, arm rests …) from a few discrete choices. The choices are recorded in
//! [`Piece::style`]; together with the kind and a size class they define a *variant*, and the
//! tests count the distinct variants the library produces.

use crate::scene::{Shape, Transform};
use glam::{Quat, Vec2, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::f32::consts::FRAC_PI_2;

/// What a part is made of; the scene generator turns each role into a material (and may make
/// it semi-transparent or glass).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    Wood,
    Fabric,
    Metal,
    Paint,
    Glass,
    Ceramic,
    /// Thin translucent cloth (curtains, lamp shades).
    Sheer,
    /// Woven or grid alpha cut-out (mesh backs, screens).
    Mesh,
    /// A leaf silhouette cut out of a unit quad (one leaf per quad, scaled to its size).
    Leaf,
    Book,
    /// A picture: a textured print.
    Picture,
    /// Emissive lamp bulb.
    Bulb,
    /// Floor covering: always opaque (a translucent rug 8 mm above the floor would count as a
    /// second depth where there is none to speak of).
    Rug,
}

/// Chooses the material of a role; the same role within one piece gets the same material.
pub trait MaterialSource {
    fn material(&mut self, role: Role) -> u32;
}

/// Where a kind is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// On the floor, free-standing or with its back against a wall.
    Floor,
    /// On the floor, back against a wall (shelves, cabinets, curtains).
    Wall,
    /// Hanging on a wall (picture frames): back against it, above the floor.
    WallHung,
    /// On a surface of another piece.
    OnTop,
    /// Flat on the floor; others may stand on it (rugs).
    FloorCover,
    /// Hanging from the ceiling, its top against it (catalogue pendant lamps).
    Ceiling,
}

/// A horizontal rectangle others can stand on, in the piece's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub y: f32,
    pub centre: Vec2,
    pub half: Vec2,
    /// Free height above it (shelves have a board above).
    pub clearance: f32,
}

/// One part of a piece, in the piece's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub name: &'static str,
    pub shape: Shape,
    pub transform: Transform,
    pub material: u32,
}

/// A generated piece of furniture or accessory.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub placement: Placement,
    pub parts: Vec<Part>,
    /// Footprint half extents along X and Z around the origin.
    pub half: Vec2,
    pub height: f32,
    pub surfaces: Vec<Surface>,
    /// Height of the piece's bottom above the floor (wall-hung pieces).
    pub elevation: f32,
    /// The discrete structural choices, e.g. `"legs2.round0"`.
    pub style: String,
}

macro_rules! kinds {
    ($($k:ident: $place:ident, $weight:expr;)*) => {
        /// The furniture and accessory kinds.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Kind { $($k),* }
        impl Kind {
            pub const ALL: &[Kind] = &[$(Kind::$k),*];
            pub fn placement(self) -> Placement {
                match self { $(Kind::$k => Placement::$place),* }
            }
            /// Relative frequency in a scene.
            pub fn weight(self) -> f32 {
                match self { $(Kind::$k => $weight),* }
            }
        }
    };
}

kinds! {
    Table: Floor, 3.0;
    CoffeeTable: Floor, 2.0;
    GlassTable: Floor, 1.5;
    Chair: Floor, 4.0;
    MeshChair: Floor, 2.0;
    Stool: Floor, 2.0;
    Bookshelf: Wall, 2.5;
    GlassShelf: Wall, 1.5;
    Cabinet: Wall, 2.0;
    Sofa: Floor, 1.5;
    Armchair: Floor, 1.5;
    Bed: Floor, 0.7;
    FloorLamp: Floor, 1.5;
    Plant: Floor, 3.0;
    Screen: Floor, 1.5;
    Curtain: Wall, 1.0;
    Pedestal: Floor, 1.5;
    Crate: Floor, 1.5;
    Rug: FloorCover, 1.0;
    PictureFrame: WallHung, 1.5;
    TableLamp: OnTop, 2.0;
    Vase: OnTop, 3.0;
    Bottle: OnTop, 3.0;
    DrinkingGlass: OnTop, 3.0;
    Bowl: OnTop, 2.0;
    BookStack: OnTop, 2.0;
    SmallBox: OnTop, 2.0;
}

/// Random draws that record the discrete ones.
pub struct Draw<'a> {
    rng: &'a mut Pcg32,
    style: String,
}

impl Draw<'_> {
    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.rng.random::<f32>()
    }

    /// A structural choice among `n`, recorded in the style under `label`.
    pub fn pick(&mut self, label: &str, n: u32) -> u32 {
        let k = self.rng.random_range(0..n);
        self.style.push_str(&format!("{label}{k}."));
        k
    }
}

/// Parts under construction, with the roles resolved through the material source.
struct Builder<'a> {
    mats: &'a mut dyn MaterialSource,
    parts: Vec<Part>,
    surfaces: Vec<Surface>,
}

impl Builder<'_> {
    fn push(&mut self, name: &'static str, shape: Shape, transform: Transform, role: Role) {
        let material = self.mats.material(role);
        self.parts.push(Part {
            name,
            shape,
            transform,
            material,
        });
    }

    /// A box given by its size and the centre of its bottom face.
    fn block(&mut self, name: &'static str, size: Vec3, bottom: Vec3, role: Role) {
        let xf = Transform::at(bottom + Vec3::Y * size.y / 2.0);
        self.push(name, Shape::Cuboid { size }, xf, role);
    }

    /// A soft cushion: a sphere flattened to `size`, given by the centre of its bottom.
    fn cushion(&mut self, name: &'static str, size: Vec3, bottom: Vec3, role: Role) {
        let shape = Shape::Sphere {
            radius: 0.5,
            rings: 12,
            segments: 24,
        };
        let mut xf = Transform::at(bottom + Vec3::Y * size.y / 2.0);
        xf.scale = size;
        self.push(name, shape, xf, role);
    }

    fn cylinder(&mut self, name: &'static str, r: f32, h: f32, bottom: Vec3, role: Role) {
        let shape = Shape::Cylinder {
            radius: r,
            height: h,
            segments: 20,
        };
        self.push(name, shape, Transform::at(bottom), role);
    }

    fn lathe(&mut self, name: &'static str, profile: Vec<[f32; 2]>, bottom: Vec3, role: Role) {
        let shape = Shape::Lathe {
            profile,
            segments: 28,
        };
        self.push(name, shape, Transform::at(bottom), role);
    }

    /// A vertical panel centred at `centre`, turned by `yaw` about Y. One quad: every surface
    /// is two-sided in the renderer, and a second, coincident quad would double a
    /// semi-transparent panel's coverage and tie the depth order.
    fn panel(&mut self, name: &'static str, size: [f32; 2], centre: Vec3, yaw: f32, role: Role) {
        let xf = Transform::at(centre).rotated_y(yaw);
        self.push(name, Shape::Quad { size }, xf, role);
    }

    /// A leaf: a unit quad (one period of the leaf silhouette, [`Role::Leaf`]) scaled to the
    /// leaf's size, its base at the attachment point. Returns its corners.
    fn leaf(&mut self, leaf: Leaf) -> [Vec3; 4] {
        let rotation = Quat::from_rotation_y(leaf.yaw) * Quat::from_rotation_x(leaf.tilt);
        let xf = Transform {
            translation: leaf.base + rotation * Vec3::Y * (leaf.size.y / 2.0),
            rotation,
            scale: leaf.size.extend(1.0),
        };
        let corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
            .map(|[u, v]| xf.matrix().transform_point3(Vec3::new(u, v, 0.0)));
        self.push("leaf", Shape::Quad { size: [1.0, 1.0] }, xf, Role::Leaf);
        corners
    }

    /// A surface at height `y` over the rectangle `centre ± half`.
    fn surface(&mut self, y: f32, centre: Vec2, half: Vec2, clearance: f32) {
        self.surfaces.push(Surface {
            y,
            centre,
            half,
            clearance,
        });
    }

    /// Four legs inside a `w × d` rectangle: round, square, tapered or splayed.
    fn legs(&mut self, d: &mut Draw, w: f32, depth: f32, h: f32, role: Role) {
        let style = d.pick("legs", 3);
        let t = d.range(0.025, 0.05);
        for (sx, sz) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            let at = Vec3::new(sx * (w / 2.0 - t), 0.0, sz * (depth / 2.0 - t));
            match style {
                0 => self.cylinder("leg", t * 0.6, h, at, role),
                1 => self.block("leg", Vec3::new(t, h, t), at, role),
                _ => self.lathe(
                    "leg",
                    vec![[0.0, 0.0], [t * 0.35, 0.0], [t * 0.7, h], [0.0, h]],
                    at,
                    role,
                ),
            }
        }
    }
}

/// Builds one piece of `kind` from `rng`, resolving materials through `mats`.
pub fn build(kind: Kind, rng: &mut Pcg32, mats: &mut dyn MaterialSource) -> Piece {
    let mut d = Draw {
        rng,
        style: String::new(),
    };
    let mut b = Builder {
        mats,
        parts: Vec::new(),
        surfaces: Vec::new(),
    };
    let (half, height, elevation) = match kind {
        Kind::Table => table(
            &mut d,
            &mut b,
            [0.7, 1.8],
            [0.6, 1.0],
            [0.70, 0.78],
            Role::Wood,
        ),
        Kind::CoffeeTable => table(
            &mut d,
            &mut b,
            [0.6, 1.2],
            [0.4, 0.7],
            [0.35, 0.48],
            Role::Wood,
        ),
        Kind::GlassTable => table(
            &mut d,
            &mut b,
            [0.6, 1.4],
            [0.5, 0.9],
            [0.4, 0.76],
            Role::Glass,
        ),
        Kind::Chair => chair(&mut d, &mut b, Role::Wood),
        Kind::MeshChair => chair(&mut d, &mut b, Role::Mesh),
        Kind::Stool => stool(&mut d, &mut b),
        Kind::Bookshelf => shelf(&mut d, &mut b, Role::Wood),
        Kind::GlassShelf => shelf(&mut d, &mut b, Role::Glass),
        Kind::Cabinet => cabinet(&mut d, &mut b),
        Kind::Sofa => sofa(&mut d, &mut b, [1.4, 2.3]),
        Kind::Armchair => sofa(&mut d, &mut b, [0.7, 1.0]),
        Kind::Bed => bed(&mut d, &mut b),
        Kind::FloorLamp => lamp(&mut d, &mut b, [1.2, 1.8]),
        Kind::TableLamp => lamp(&mut d, &mut b, [0.3, 0.6]),
        Kind::Plant => plant(&mut d, &mut b),
        Kind::Screen => screen(&mut d, &mut b),
        Kind::Curtain => curtain(&mut d, &mut b),
        Kind::Pedestal => pedestal(&mut d, &mut b),
        Kind::Crate => crate_box(&mut d, &mut b, [0.3, 0.8]),
        Kind::SmallBox => crate_box(&mut d, &mut b, [0.08, 0.25]),
        Kind::Rug => rug(&mut d, &mut b),
        Kind::PictureFrame => picture(&mut d, &mut b),
        Kind::Vase => vessel(&mut d, &mut b, Vessel::Vase),
        Kind::Bottle => vessel(&mut d, &mut b, Vessel::Bottle),
        Kind::DrinkingGlass => vessel(&mut d, &mut b, Vessel::Glass),
        Kind::Bowl => vessel(&mut d, &mut b, Vessel::Bowl),
        Kind::BookStack => book_stack(&mut d, &mut b),
    };
    Piece {
        placement: kind.placement(),
        parts: b.parts,
        half,
        height,
        surfaces: b.surfaces,
        elevation,
        style: d.style,
    }
}

/// Footprint half extents, height and elevation of a built piece.
type Extent = (Vec2, f32, f32);

fn table(
    d: &mut Draw,
    b: &mut Builder,
    w: [f32; 2],
    dp: [f32; 2],
    h: [f32; 2],
    top: Role,
) -> Extent {
    let (w, dp, h) = (
        d.range(w[0], w[1]),
        d.range(dp[0], dp[1]),
        d.range(h[0], h[1]),
    );
    let t = d.range(0.02, 0.05);
    let round = d.pick("round", 2) == 1;
    let frame = if top == Role::Glass {
        Role::Metal
    } else {
        Role::Wood
    };
    if round {
        let r = w.min(dp) / 2.0;
        b.cylinder("top", r, t, Vec3::Y * (h - t), top);
        let base = d.pick("base", 2);
        if base == 0 {
            b.lathe(
                "pedestal",
                vec![
                    [0.0, 0.0],
                    [r * 0.5, 0.0],
                    [r * 0.5, 0.03],
                    [0.04, 0.1],
                    [0.04, h - t],
                    [0.0, h - t],
                ],
                Vec3::ZERO,
                frame,
            );
        } else {
            b.legs(d, r * 1.3, r * 1.3, h - t, frame);
        }
        b.surface(h, Vec2::ZERO, Vec2::splat(r * 0.7), 2.0);
        return (Vec2::splat(r), h, 0.0);
    }
    b.block("top", Vec3::new(w, t, dp), Vec3::Y * (h - t), top);
    b.legs(d, w, dp, h - t, frame);
    if h < 0.6 && d.pick("shelf", 2) == 1 {
        b.block(
            "undershelf",
            Vec3::new(w * 0.9, 0.02, dp * 0.9),
            Vec3::Y * 0.1,
            top,
        );
    }
    b.surface(h, Vec2::ZERO, Vec2::new(w, dp) / 2.0 - 0.04, 2.0);
    (Vec2::new(w, dp) / 2.0, h, 0.0)
}

fn chair(d: &mut Draw, b: &mut Builder, back: Role) -> Extent {
    let (w, dp, seat) = (d.range(0.4, 0.55), d.range(0.4, 0.55), d.range(0.42, 0.48));
    let back_h = d.range(0.35, 0.6);
    let frame = if d.pick("metal", 2) == 1 {
        Role::Metal
    } else {
        Role::Wood
    };
    b.legs(d, w, dp, seat - 0.04, frame);
    let cushion = d.pick("cushion", 2) == 1;
    let seat_role = if cushion { Role::Fabric } else { frame };
    b.block(
        "seat",
        Vec3::new(w, 0.04 + 0.04 * cushion as u8 as f32, dp),
        Vec3::Y * (seat - 0.04),
        seat_role,
    );
    let z = -dp / 2.0 + 0.02;
    let top = seat + back_h;
    for sx in [-1.0, 1.0] {
        b.block(
            "post",
            Vec3::new(0.03, back_h, 0.03),
            Vec3::new(sx * (w / 2.0 - 0.03), seat, z),
            frame,
        );
    }
    let style = if back == Role::Mesh {
        3
    } else {
        d.pick("back", 3)
    };
    match style {
        3 => b.panel(
            "back",
            [w - 0.06, back_h * 0.85],
            Vec3::new(0.0, seat + back_h * 0.5, z),
            0.0,
            Role::Mesh,
        ),
        0 => b.block(
            "back",
            Vec3::new(w, back_h * 0.6, 0.025),
            Vec3::new(0.0, top - back_h * 0.6, z),
            seat_role,
        ),
        1 => {
            for k in 0..4 {
                let x = (k as f32 - 1.5) * (w - 0.08) / 4.0;
                b.block(
                    "slat",
                    Vec3::new(0.02, back_h, 0.02),
                    Vec3::new(x, seat, z),
                    frame,
                );
            }
            b.block(
                "rail",
                Vec3::new(w, 0.05, 0.03),
                Vec3::new(0.0, top - 0.05, z),
                frame,
            );
        }
        _ => b.block(
            "rail",
            Vec3::new(w, 0.08, 0.03),
            Vec3::new(0.0, top - 0.08, z),
            frame,
        ),
    }
    (Vec2::new(w, dp) / 2.0, top, 0.0)
}

fn stool(d: &mut Draw, b: &mut Builder) -> Extent {
    let (r, h) = (d.range(0.15, 0.22), d.range(0.45, 0.8));
    let role = if d.pick("metal", 2) == 1 {
        Role::Metal
    } else {
        Role::Wood
    };
    match d.pick("seat", 2) {
        0 => b.cylinder("seat", r, 0.04, Vec3::Y * (h - 0.04), Role::Fabric),
        _ => b.block(
            "seat",
            Vec3::new(r * 1.8, 0.04, r * 1.8),
            Vec3::Y * (h - 0.04),
            role,
        ),
    }
    if d.pick("base", 2) == 0 {
        b.legs(d, r * 1.6, r * 1.6, h - 0.04, role);
    } else {
        b.lathe(
            "column",
            vec![
                [0.0, 0.0],
                [r, 0.0],
                [r, 0.02],
                [0.03, 0.05],
                [0.03, h - 0.04],
                [0.0, h - 0.04],
            ],
            Vec3::ZERO,
            role,
        );
    }
    b.surface(h, Vec2::ZERO, Vec2::splat(r * 0.6), 2.0);
    (Vec2::splat(r), h, 0.0)
}

/// Bookshelves and glass shelves: sides, back, boards; books on wooden boards.
fn shelf(d: &mut Draw, b: &mut Builder, boards: Role) -> Extent {
    let (w, dp, h) = (d.range(0.6, 1.4), d.range(0.25, 0.4), d.range(0.8, 2.1));
    let n = 2 + d.pick("boards", 4);
    let frame = if boards == Role::Glass {
        Role::Metal
    } else {
        Role::Wood
    };
    let sides = d.pick("sides", 2) == 0;
    if sides {
        for sx in [-1.0, 1.0] {
            b.block(
                "side",
                Vec3::new(0.02, h, dp),
                Vec3::new(sx * (w / 2.0 - 0.01), 0.0, 0.0),
                frame,
            );
        }
    } else {
        for (sx, sz) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            b.cylinder(
                "post",
                0.012,
                h,
                Vec3::new(sx * (w / 2.0 - 0.015), 0.0, sz * (dp / 2.0 - 0.015)),
                Role::Metal,
            );
        }
    }
    if d.pick("back", 2) == 1 {
        b.block(
            "back",
            Vec3::new(w, h, 0.01),
            Vec3::new(0.0, 0.0, -dp / 2.0 + 0.005),
            frame,
        );
    }
    let books = boards != Role::Glass || d.pick("books", 2) == 1;
    let gap = (h - 0.05) / n as f32;
    for k in 0..=n {
        let y = 0.04 + k as f32 * gap;
        b.block(
            "board",
            Vec3::new(w - 0.04, 0.02, dp - 0.02),
            Vec3::Y * (y - 0.02),
            boards,
        );
        if k < n && books && d.range(0.0, 1.0) < 0.75 {
            row_of_books(d, b, y, w - 0.08, dp - 0.06, gap - 0.04);
        }
    }
    b.surface(
        h.min(0.04 + n as f32 * gap),
        Vec2::ZERO,
        Vec2::new(w / 2.0 - 0.06, dp / 2.0 - 0.04),
        2.0,
    );
    (Vec2::new(w, dp) / 2.0, h, 0.0)
}

/// Upright books from the left end of a board, leaving a random gap at the right.
fn row_of_books(d: &mut Draw, b: &mut Builder, y: f32, w: f32, depth: f32, max_h: f32) {
    let mut x = -w / 2.0;
    let end = w / 2.0 - d.range(0.0, w * 0.5);
    while x < end - 0.05 {
        let t = d.range(0.015, 0.05);
        let h = d.range(0.6, 0.98) * max_h.min(0.35);
        let dz = depth * d.range(0.6, 0.95);
        b.block(
            "book",
            Vec3::new(t, h, dz),
            Vec3::new(x + t / 2.0, y, depth / 2.0 - dz / 2.0 - 0.0),
            Role::Book,
        );
        x += t + 0.002;
    }
}

fn cabinet(d: &mut Draw, b: &mut Builder) -> Extent {
    let (w, dp, h) = (d.range(0.5, 1.6), d.range(0.35, 0.6), d.range(0.5, 1.2));
    let feet = if d.pick("feet", 2) == 1 { 0.08 } else { 0.0 };
    if feet > 0.0 {
        b.legs(d, w * 0.95, dp * 0.95, feet, Role::Metal);
    }
    let body = if d.pick("painted", 2) == 1 {
        Role::Paint
    } else {
        Role::Wood
    };
    b.block("body", Vec3::new(w, h - feet, dp), Vec3::Y * feet, body);
    let doors = 1 + d.pick("doors", 3);
    let drawers = d.pick("drawers", 2) == 1;
    for k in 0..doors {
        let dw = w / doors as f32;
        let x = -w / 2.0 + dw * (k as f32 + 0.5);
        let (y0, hh) = if drawers {
            (feet + (h - feet) * 0.5, (h - feet) * 0.5)
        } else {
            (feet, h - feet)
        };
        b.block(
            "door",
            Vec3::new(dw - 0.01, hh - 0.02, 0.015),
            Vec3::new(x, y0 + 0.01, dp / 2.0),
            body,
        );
        b.block(
            "handle",
            Vec3::new(0.012, 0.1, 0.02),
            Vec3::new(x + dw * 0.35, y0 + hh * 0.5, dp / 2.0 + 0.015),
            Role::Metal,
        );
        if drawers {
            b.block(
                "drawer",
                Vec3::new(dw - 0.01, hh - 0.02, 0.015),
                Vec3::new(x, feet + 0.01, dp / 2.0),
                body,
            );
        }
    }
    b.surface(
        h,
        Vec2::ZERO,
        Vec2::new(w / 2.0 - 0.04, dp / 2.0 - 0.04),
        2.0,
    );
    (Vec2::new(w / 2.0, dp / 2.0 + 0.03), h, 0.0)
}

fn sofa(d: &mut Draw, b: &mut Builder, width: [f32; 2]) -> Extent {
    let (w, dp) = (d.range(width[0], width[1]), d.range(0.75, 0.95));
    let seat = d.range(0.38, 0.46);
    let back_h = d.range(0.3, 0.45);
    let feet = if d.pick("feet", 2) == 1 { 0.1 } else { 0.0 };
    if feet > 0.0 {
        b.legs(d, w * 0.95, dp * 0.9, feet, Role::Wood);
    }
    let arm = match d.pick("arms", 3) {
        0 => 0.0,
        1 => 0.12,
        _ => 0.2,
    };
    b.block(
        "base",
        Vec3::new(w, seat - feet - 0.1, dp),
        Vec3::Y * feet,
        Role::Fabric,
    );
    let cushions = 1 + d.pick("cushions", 3);
    let cw = (w - 2.0 * arm) / cushions as f32;
    for k in 0..cushions {
        let x = -w / 2.0 + arm + cw * (k as f32 + 0.5);
        b.block(
            "cushion",
            Vec3::new(cw - 0.01, 0.1, dp - 0.2),
            Vec3::new(x, seat - 0.1, 0.09),
            Role::Fabric,
        );
    }
    b.block(
        "back",
        Vec3::new(w, back_h + 0.1, 0.2),
        Vec3::new(0.0, seat - 0.1, -dp / 2.0 + 0.1),
        Role::Fabric,
    );
    if arm > 0.0 {
        for sx in [-1.0, 1.0] {
            b.block(
                "arm",
                Vec3::new(arm, 0.2, dp),
                Vec3::new(sx * (w - arm) / 2.0, seat - 0.1, 0.0),
                Role::Fabric,
            );
        }
    }
    (Vec2::new(w, dp) / 2.0, seat + back_h, 0.0)
}

fn bed(d: &mut Draw, b: &mut Builder) -> Extent {
    let (w, l) = (d.range(0.9, 1.8), d.range(1.9, 2.1));
    let frame_h = d.range(0.2, 0.35);
    let board = d.range(0.8, 1.2);
    let mut top = frame_h + 0.3;
    b.block("frame", Vec3::new(w, frame_h, l), Vec3::ZERO, Role::Wood);
    b.block(
        "mattress",
        Vec3::new(w - 0.04, 0.2, l - 0.06),
        Vec3::new(0.0, frame_h, 0.02),
        Role::Fabric,
    );
    if d.pick("headboard", 2) == 1 {
        b.block(
            "headboard",
            Vec3::new(w, board, 0.05),
            Vec3::new(0.0, 0.0, -l / 2.0 + 0.025),
            Role::Wood,
        );
        top = top.max(board);
    }
    let pillows = 1 + d.pick("pillows", 2);
    let pw = (w - 0.1) / pillows as f32;
    for k in 0..pillows {
        let x = -w / 2.0 + 0.05 + pw * (k as f32 + 0.5);
        b.cushion(
            "pillow",
            Vec3::new(pw - 0.05, 0.12, 0.35),
            Vec3::new(x, frame_h + 0.18, -l / 2.0 + 0.3),
            Role::Fabric,
        );
    }
    if d.pick("blanket", 2) == 1 {
        b.block(
            "blanket",
            Vec3::new(w, 0.03, l * 0.55),
            Vec3::new(0.0, frame_h + 0.19, l * 0.2),
            Role::Sheer,
        );
    }
    (Vec2::new(w / 2.0, l / 2.0), top, 0.0)
}

/// Floor and table lamps: a base, a stem, a glowing bulb and a shade of revolution.
fn lamp(d: &mut Draw, b: &mut Builder, h: [f32; 2]) -> Extent {
    let h = d.range(h[0], h[1]);
    let r = h * d.range(0.1, 0.15);
    b.lathe(
        "base",
        vec![[0.0, 0.0], [r * 0.8, 0.0], [r * 0.6, 0.03], [0.0, 0.03]],
        Vec3::ZERO,
        Role::Metal,
    );
    let shade_h = h * d.range(0.18, 0.3);
    b.cylinder("stem", 0.012, h - shade_h * 0.6, Vec3::ZERO, Role::Metal);
    let bottom = h - shade_h;
    b.push(
        "bulb",
        Shape::Sphere {
            radius: 0.03,
            rings: 8,
            segments: 12,
        },
        Transform::at(Vec3::Y * (bottom + shade_h * 0.4)),
        Role::Bulb,
    );
    let (lo, hi) = match d.pick("shade", 3) {
        0 => (r * 1.3, r * 0.8),
        1 => (r * 1.1, r * 1.1),
        _ => (r * 1.5, r * 0.3),
    };
    let role = if d.pick("glassshade", 2) == 1 {
        Role::Glass
    } else {
        Role::Sheer
    };
    b.lathe(
        "shade",
        vec![[lo, 0.0], [hi, shade_h]],
        Vec3::Y * bottom,
        role,
    );
    (Vec2::splat(lo.max(r * 0.8)), h, 0.0)
}

/// A pot of revolution with a plant of single leaves, each its own tilted quad: a rosette
/// fanning out of the soil (a dracaena, a snake plant) or a trunk carrying a crown (a ficus).
fn plant(d: &mut Draw, b: &mut Builder) -> Extent {
    let (r, ph) = (d.range(0.12, 0.25), d.range(0.2, 0.45));
    let pot = match d.pick("pot", 3) {
        0 => vec![
            [0.0, 0.0],
            [r * 0.75, 0.0],
            [r, ph],
            [r * 0.9, ph],
            [0.0, ph * 0.9],
        ],
        1 => vec![
            [0.0, 0.0],
            [r, 0.0],
            [r, ph],
            [r * 0.92, ph],
            [0.0, ph * 0.9],
        ],
        _ => vec![
            [0.0, 0.0],
            [r * 0.6, 0.0],
            [r * 1.05, ph * 0.5],
            [r * 0.8, ph],
            [0.0, ph * 0.9],
        ],
    };
    b.lathe("pot", pot, Vec3::ZERO, Role::Ceramic);
    let soil = ph * 0.9;
    let tall = d.range(0.4, 1.4);
    let mut reach = Reach {
        half: Vec2::splat(r),
        top: ph,
    };
    if d.pick("habit", 2) == 0 {
        let count = 10 + d.pick("leaves", 3) * 6;
        let length = tall * d.range(0.35, 0.6);
        let width = d.range(0.2, 0.4);
        for k in 0..count {
            let l = length * d.range(0.6, 1.0);
            let leaf = Leaf {
                base: Vec3::Y * soil,
                yaw: k as f32 * GOLDEN_ANGLE + d.range(-0.3, 0.3),
                tilt: d.range(0.1, 1.1),
                size: Vec2::new(l * width, l),
            };
            reach.add(b.leaf(leaf));
        }
    } else {
        let trunk = soil + tall * 0.5;
        b.cylinder("trunk", r * 0.08, trunk - soil, Vec3::Y * soil, Role::Wood);
        let crown = tall * d.range(0.2, 0.35);
        let count = 24 + d.pick("leaves", 3) * 12;
        let length = d.range(0.08, 0.16);
        for k in 0..count {
            let yaw = k as f32 * GOLDEN_ANGLE;
            let out = crown * d.range(0.0, 0.8);
            let l = length * d.range(0.7, 1.0);
            let leaf = Leaf {
                base: Vec3::new(
                    yaw.sin() * out,
                    trunk + d.range(0.0, tall * 0.4),
                    yaw.cos() * out,
                ),
                yaw: yaw + d.range(-0.5, 0.5),
                tilt: d.range(0.6, 1.9),
                size: Vec2::new(l * d.range(0.35, 0.5), l),
            };
            reach.add(b.leaf(leaf));
        }
    }
    (reach.half, reach.top, 0.0)
}

/// The angle between successive leaves of a spiral (phyllotaxis): no two line up.
const GOLDEN_ANGLE: f32 = 2.399_963;

/// One leaf: attached at `base`, turned `yaw` about the vertical and tilted `tilt` from it
/// (radians; past π/2 it hangs), `size` its width and length.
struct Leaf {
    base: Vec3,
    yaw: f32,
    tilt: f32,
    size: Vec2,
}

/// The footprint half extents and the height a piece's parts reach so far.
struct Reach {
    half: Vec2,
    top: f32,
}

impl Reach {
    fn add(&mut self, corners: [Vec3; 4]) {
        for c in corners {
            self.half = self.half.max(Vec2::new(c.x.abs(), c.z.abs()));
            self.top = self.top.max(c.y);
        }
    }
}

/// A folding room screen: hinged leaves with a woven or grid alpha pattern in a frame.
fn screen(d: &mut Draw, b: &mut Builder) -> Extent {
    let leaves = 2 + d.pick("leaves", 3);
    let (lw, h) = (d.range(0.4, 0.6), d.range(1.5, 1.9));
    let fold = d.range(0.2, 0.5);
    let infill = if d.pick("sheer", 2) == 1 {
        Role::Sheer
    } else {
        Role::Mesh
    };
    let total = leaves as f32 * lw * fold.cos();
    for k in 0..leaves {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let x = -total / 2.0 + (k as f32 + 0.5) * lw * fold.cos();
        // Centres on one line: alternate leaves then meet at their hinges.
        let z = 0.0;
        b.panel(
            "leaf",
            [lw - 0.04, h - 0.1],
            Vec3::new(x, h / 2.0 + 0.03, z),
            sign * fold,
            infill,
        );
        let rot = Quat::from_rotation_y(sign * fold);
        for sx in [-0.5, 0.5] {
            let at = Vec3::new(x, 0.0, z) + rot * Vec3::X * sx * (lw - 0.02);
            b.block("stile", Vec3::new(0.025, h, 0.025), at, Role::Wood);
        }
    }
    let half = Vec2::new(total / 2.0 + 0.05, lw * fold.sin() * 0.5 + 0.05);
    (half, h, 0.0)
}

/// Sheer curtain panels hanging from a rod, with folds (zig-zag strips).
fn curtain(d: &mut Draw, b: &mut Builder) -> Extent {
    let (w, h) = (d.range(1.0, 2.2), d.range(2.0, 2.4));
    let folds = 6 + 2 * d.pick("folds", 4);
    let depth = d.range(0.04, 0.08);
    let strip = w / folds as f32;
    let angle = (depth / strip).atan();
    let len = (strip * strip + depth * depth).sqrt();
    for k in 0..folds {
        let x = -w / 2.0 + strip * (k as f32 + 0.5);
        let yaw = if k % 2 == 0 { angle } else { -angle };
        b.panel(
            "fold",
            [len, h - 0.05],
            Vec3::new(x, (h - 0.05) / 2.0 + 0.01, 0.0),
            yaw,
            Role::Sheer,
        );
    }
    if d.pick("rod", 2) == 1 {
        let mut xf = Transform::at(Vec3::new(-w / 2.0 - 0.05, h - 0.02, 0.0));
        xf.rotation = Quat::from_rotation_z(-FRAC_PI_2);
        b.push(
            "rod",
            Shape::Cylinder {
                radius: 0.012,
                height: w + 0.1,
                segments: 12,
            },
            xf,
            Role::Metal,
        );
    }
    (Vec2::new(w / 2.0 + 0.06, depth / 2.0 + 0.02), h, 0.0)
}

/// A column or plinth carrying a sculpture (sphere, vessel or block).
fn pedestal(d: &mut Draw, b: &mut Builder) -> Extent {
    let (r, h) = (d.range(0.12, 0.25), d.range(0.5, 1.2));
    match d.pick("column", 2) {
        0 => b.block(
            "plinth",
            Vec3::new(2.0 * r, h, 2.0 * r),
            Vec3::ZERO,
            Role::Paint,
        ),
        _ => b.lathe(
            "column",
            vec![
                [0.0, 0.0],
                [r, 0.0],
                [r, 0.05],
                [r * 0.7, 0.08],
                [r * 0.7, h - 0.08],
                [r, h - 0.05],
                [r, h],
                [0.0, h],
            ],
            Vec3::ZERO,
            Role::Ceramic,
        ),
    }
    let s = d.range(0.1, 0.25).min(r * 0.95);
    match d.pick("sculpture", 3) {
        0 => b.push(
            "sphere",
            Shape::Sphere {
                radius: s,
                rings: 16,
                segments: 32,
            },
            Transform::at(Vec3::Y * (h + s)),
            Role::Ceramic,
        ),
        1 => b.lathe(
            "urn",
            vec![
                [0.0, 0.0],
                [s * 0.5, 0.0],
                [s, s],
                [s * 0.4, 2.0 * s],
                [s * 0.6, 2.4 * s],
                [0.0, 2.3 * s],
            ],
            Vec3::Y * h,
            Role::Ceramic,
        ),
        _ => {
            let xf = Transform::at(Vec3::Y * (h + s * 0.7)).rotated_y(0.6);
            b.push(
                "block",
                Shape::Cuboid {
                    size: Vec3::splat(s) * Vec3::new(1.0, 1.4, 1.0),
                },
                xf,
                Role::Metal,
            )
        }
    }
    (Vec2::splat(r), h + 2.4 * s, 0.0)
}

/// Crates and small boxes, optionally with a lid.
fn crate_box(d: &mut Draw, b: &mut Builder, size: [f32; 2]) -> Extent {
    let s = Vec3::new(
        d.range(size[0], size[1]),
        d.range(size[0], size[1]) * 0.8,
        d.range(size[0], size[1]),
    );
    let role = match d.pick("mat", 3) {
        0 => Role::Wood,
        1 => Role::Paint,
        _ => Role::Fabric,
    };
    b.block("box", s, Vec3::ZERO, role);
    if d.pick("lid", 2) == 1 {
        b.block(
            "lid",
            Vec3::new(s.x + 0.01, s.y * 0.1, s.z + 0.01),
            Vec3::Y * s.y,
            role,
        );
    }
    b.surface(s.y * 1.1, Vec2::ZERO, Vec2::new(s.x, s.z) / 2.0 - 0.02, 2.0);
    (Vec2::new(s.x + 0.01, s.z + 0.01) / 2.0, s.y * 1.1, 0.0)
}

fn rug(d: &mut Draw, b: &mut Builder) -> Extent {
    let (w, l) = (d.range(1.2, 2.5), d.range(1.6, 3.0));
    if d.pick("round", 2) == 1 {
        b.cylinder("rug", w / 2.0, 0.008, Vec3::ZERO, Role::Rug);
        return (Vec2::splat(w / 2.0), 0.008, 0.0);
    }
    b.block("rug", Vec3::new(w, 0.008, l), Vec3::ZERO, Role::Rug);
    (Vec2::new(w / 2.0, l / 2.0), 0.008, 0.0)
}

/// A picture in a frame, hanging on a wall (its back at −Z).
fn picture(d: &mut Draw, b: &mut Builder) -> Extent {
    let (w, h) = (d.range(0.3, 1.2), d.range(0.3, 1.0));
    let y = d.range(1.1, 1.6);
    let f = d.range(0.02, 0.06);
    let frame = if d.pick("metal", 2) == 1 {
        Role::Metal
    } else {
        Role::Wood
    };
    for (size, at) in [
        (Vec3::new(w, f, 0.03), Vec3::new(0.0, y - h / 2.0, 0.0)),
        (Vec3::new(w, f, 0.03), Vec3::new(0.0, y + h / 2.0 - f, 0.0)),
        (
            Vec3::new(f, h, 0.03),
            Vec3::new(-w / 2.0 + f / 2.0, y - h / 2.0, 0.0),
        ),
        (
            Vec3::new(f, h, 0.03),
            Vec3::new(w / 2.0 - f / 2.0, y - h / 2.0, 0.0),
        ),
    ] {
        b.block("frame", size, at, frame);
    }
    let xf = Transform::at(Vec3::new(0.0, y, 0.0));
    b.push(
        "print",
        Shape::Quad {
            size: [w - 2.0 * f, h - 2.0 * f],
        },
        xf,
        Role::Picture,
    );
    if d.pick("glazed", 2) == 1 {
        b.push(
            "glazing",
            Shape::Quad {
                size: [w - 2.0 * f, h - 2.0 * f],
            },
            Transform::at(Vec3::new(0.0, y, 0.012)),
            Role::Sheer,
        );
    }
    (Vec2::new(w / 2.0, 0.02), y + h / 2.0, y - h / 2.0)
}

enum Vessel {
    Vase,
    Bottle,
    Glass,
    Bowl,
}

/// Vessels of revolution: profiles drawn from a few shape families, hollow where they are
/// glasses or bowls (a wall turns back down inside).
fn vessel(d: &mut Draw, b: &mut Builder, kind: Vessel) -> Extent {
    let (r, h) = match kind {
        Vessel::Vase => (d.range(0.06, 0.14), d.range(0.2, 0.5)),
        Vessel::Bottle => (d.range(0.03, 0.05), d.range(0.2, 0.33)),
        Vessel::Glass => (d.range(0.03, 0.045), d.range(0.08, 0.2)),
        Vessel::Bowl => (d.range(0.08, 0.16), d.range(0.05, 0.1)),
    };
    let shape = d.pick("profile", 3);
    let profile: Vec<[f32; 2]> = match kind {
        Vessel::Vase => match shape {
            0 => vec![
                [0.0, 0.0],
                [r * 0.6, 0.0],
                [r, h * 0.4],
                [r * 0.4, h * 0.85],
                [r * 0.55, h],
                [r * 0.45, h],
                [r * 0.3, h * 0.8],
                [0.0, h * 0.75],
            ],
            1 => vec![
                [0.0, 0.0],
                [r * 0.7, 0.0],
                [r * 0.7, h * 0.1],
                [r, h],
                [r * 0.9, h],
                [r * 0.6, h * 0.1],
                [0.0, h * 0.08],
            ],
            _ => vec![
                [0.0, 0.0],
                [r * 0.5, 0.0],
                [r, h * 0.3],
                [r * 0.9, h * 0.7],
                [r * 0.35, h],
                [0.0, h],
            ],
        },
        Vessel::Bottle => {
            let neck = h * [0.6, 0.7, 0.5][shape as usize];
            vec![
                [0.0, 0.0],
                [r, 0.0],
                [r, neck],
                [r * 0.35, neck + h * 0.12],
                [r * 0.3, h],
                [0.0, h],
            ]
        }
        Vessel::Glass => match shape {
            0 => vec![
                [0.0, 0.0],
                [r * 0.8, 0.0],
                [r, h],
                [r * 0.92, h],
                [r * 0.74, h * 0.1],
                [0.0, h * 0.08],
            ],
            1 => vec![
                [0.0, 0.0],
                [r * 0.8, 0.0],
                [0.005, 0.01],
                [0.005, h * 0.5],
                [r, h * 0.65],
                [r * 1.05, h],
                [r * 0.98, h],
                [0.0, h * 0.55],
            ],
            _ => vec![
                [0.0, 0.0],
                [r, 0.0],
                [r, h],
                [r * 0.93, h],
                [r * 0.93, h * 0.06],
                [0.0, h * 0.06],
            ],
        },
        Vessel::Bowl => vec![
            [0.0, 0.0],
            [r * 0.5, 0.0],
            [r, h * [1.0, 0.8, 0.6][shape as usize]],
            [r * 0.93, h],
            [r * 0.45, h * 0.12],
            [0.0, h * 0.1],
        ],
    };
    let role = match kind {
        Vessel::Glass => Role::Glass,
        Vessel::Bottle if d.pick("glassy", 2) == 1 => Role::Glass,
        _ if d.pick("glassy", 4) == 0 => Role::Glass,
        _ => Role::Ceramic,
    };
    let radius = profile.iter().map(|p| p[0]).fold(0.0, f32::max);
    b.lathe("vessel", profile, Vec3::ZERO, role);
    (Vec2::splat(radius), h, 0.0)
}

fn book_stack(d: &mut Draw, b: &mut Builder) -> Extent {
    let n = 1 + d.pick("books", 5);
    let (w, dp) = (d.range(0.13, 0.25), d.range(0.18, 0.3));
    let mut y = 0.0;
    for _ in 0..n {
        let t = d.range(0.015, 0.05);
        let xf = Transform::at(Vec3::new(0.0, y + t / 2.0, 0.0)).rotated_y(d.range(-0.15, 0.15));
        b.push(
            "book",
            Shape::Cuboid {
                size: Vec3::new(w, t, dp),
            },
            xf,
            Role::Book,
        );
        y += t;
    }
    let r = Vec2::new(w, dp).length() / 2.0;
    (Vec2::splat(r), y, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::assets::Assets;
    use crate::scene::shapes::tessellate;
    use std::collections::BTreeSet;

    struct Count(u32);
    impl MaterialSource for Count {
        fn material(&mut self, _: Role) -> u32 {
            self.0 += 1;
            self.0
        }
    }

    /// Size class: the piece's largest dimension in thirds of what the kind produces.
    fn size_class(p: &Piece, lo: f32, hi: f32) -> u32 {
        let s = p.half.max_element() * 2.0 + p.height;
        (((s - lo) / (hi - lo).max(1e-6)) * 3.0).clamp(0.0, 2.0) as u32
    }

    /// A variant = (kind, discrete structure, size class). The default library must offer at
    /// least 750 of them.
    #[test]
    fn the_library_offers_at_least_750_distinct_variants() {
        let mut total = 0;
        for &kind in Kind::ALL {
            let pieces: Vec<Piece> = (0..600)
                .map(|i| build(kind, &mut Pcg32::new(i, 7), &mut Count(0)))
                .collect();
            let dims: Vec<f32> = pieces
                .iter()
                .map(|p| p.half.max_element() * 2.0 + p.height)
                .collect();
            let (lo, hi) = dims
                .iter()
                .fold((f32::MAX, f32::MIN), |(a, b), &d| (a.min(d), b.max(d)));
            let variants: BTreeSet<(String, u32)> = pieces
                .iter()
                .map(|p| (p.style.clone(), size_class(p, lo, hi)))
                .collect();
            total += variants.len();
        }
        assert!(Kind::ALL.len() >= 20);
        println!("{} kinds, {total} distinct variants", Kind::ALL.len());
        assert!(total >= 750, "{total} variants");
    }

    /// A plant is single leaves, not cards: at least ten unit quads scaled to leaf size
    /// (one silhouette each), fanned out around the stem at many tilts, each attached at the
    /// soil or on the trunk, inside the pot's rim or the crown.
    #[test]
    fn plants_are_single_tilted_leaves() {
        for i in 0..40 {
            let p = build(Kind::Plant, &mut Pcg32::new(i, 5), &mut Count(0));
            let leaves: Vec<&Part> = p.parts.iter().filter(|q| q.name == "leaf").collect();
            assert!(leaves.len() >= 10, "#{i}: {} leaves", leaves.len());
            let mut axes: Vec<Vec3> = Vec::new();
            for leaf in &leaves {
                assert_eq!(leaf.shape, Shape::Quad { size: [1.0, 1.0] });
                let s = leaf.transform.scale;
                assert!(s.x > 0.01 && s.y > s.x && s.y < 1.0, "#{i}: leaf {s}");
                axes.push(leaf.transform.rotation * Vec3::Y);
                let m = leaf.transform.matrix();
                let base = m.transform_point3(Vec3::new(0.0, -0.5, 0.0));
                assert!(
                    base.y > 0.1 && Vec2::new(base.x, base.z).length() < 0.6,
                    "#{i}: {base}"
                );
            }
            // They fan out around the stem (their horizontal directions cancel) at many tilts.
            let n = axes.len() as f32;
            let fan = axes
                .iter()
                .map(|a| Vec2::new(a.x, a.z))
                .sum::<Vec2>()
                .length()
                / n;
            let mean_up = axes.iter().map(|a| a.y).sum::<f32>() / n;
            let spread = (axes.iter().map(|a| (a.y - mean_up).powi(2)).sum::<f32>() / n).sqrt();
            assert!(
                fan < 0.35 && spread > 0.05,
                "#{i}: fan {fan}, tilt spread {spread}"
            );
        }
    }

    /// Every part lies within the reported footprint (plus a small tolerance) and height.
    #[test]
    fn parts_stay_inside_the_reported_extent() {
        for &kind in Kind::ALL {
            for i in 0..40 {
                let p = build(kind, &mut Pcg32::new(i, 3), &mut Count(0));
                let mut tris = Vec::new();
                for part in &p.parts {
                    tessellate(&part.shape, &part.transform, &Assets::default(), &mut tris)
                        .unwrap();
                }
                for q in tris.iter().flat_map(|t| t.p) {
                    assert!(q.is_finite());
                    assert!(
                        q.x.abs() <= p.half.x + 0.03 && q.z.abs() <= p.half.y + 0.03,
                        "{kind:?} #{i} {} at {q} outside {:?}",
                        p.style,
                        p.half
                    );
                    assert!(
                        q.y >= p.elevation - 0.02 && q.y <= p.height + 0.03,
                        "{kind:?} #{i} y {}",
                        q.y
                    );
                }
            }
        }
    }
}
