//! The memory a scene will take, estimated before anything large is allocated, and the limit
//! it must fit in.
//!
//! One rule bounds a scene's peak: the estimate of everything it holds at once — the buffers
//! of the view being rendered (its image, its ground truth, the encoded files), the triangles
//! with their BVH, the decoded textures — plus the passing peak of decoding one texture must
//! not exceed [`limit`]. Each part is charged to a [`Budget`] as soon as its size is known
//! (the camera and the shapes from `scene.json`, a glTF's triangles from its accessors, an
//! OBJ's from its face lines, a texture's from its image header), so a scene that cannot fit
//! is refused with the estimate and the limit in the message instead of aborting half-way.
//! The per-unit costs below were measured (`/usr/bin/time -v`, maximum resident set size) and
//! rounded up.

use super::{MAX_TRIANGLES, SceneDesc, Shape};
use anyhow::{Context, Result, bail, ensure};

/// Environment variable that sets the limit, in bytes or with a `K`, `M`, `G` or `T` suffix
/// (powers of 1024).
pub const LIMIT_VAR: &str = "LFGEN_MEMORY_LIMIT";

/// Share of the machine's memory (or of the process's address-space limit, if lower) a scene
/// may plan for by default: the rest covers the program, thread stacks and the allocator.
const DEFAULT_SHARE: (u64, u64) = (3, 4);

/// Bytes per pixel of the view being rendered: its linear image, its ground truth (modes,
/// their colours, depth) and the files encoded from them (measured: 690 at 1024², 1 view).
pub const PIXEL_BYTES: u64 = 768;

/// Bytes per pixel of every view: the shared-shading cache fills from all views (measured: 30
/// at 512², 3×3 views against one).
pub const VIEW_PIXEL_BYTES: u64 = 32;

/// Bytes per triangle while a scene renders: the mesh-space copy, the world-space triangle
/// with its material and object, and its share of the BVH (measured: 375 resident with a
/// sphere of 2 M triangles; about twice that in address space, where growing vectors reserve
/// double, so a 7.5 M-triangle sphere at 400 failed under a 4 GiB `prlimit --as`).
pub const TRIANGLE_BYTES: u64 = 768;

/// The limit: [`LIMIT_VAR`] if set, else [`DEFAULT_SHARE`] of the smaller of the machine's
/// memory and the address-space limit (`ulimit -v`, `prlimit --as`); with neither known, no
/// limit.
pub fn limit() -> Result<u64> {
    if let Ok(text) = std::env::var(LIMIT_VAR) {
        return parse_size(&text).with_context(|| format!("{LIMIT_VAR}={text:?}"));
    }
    let known = [machine_memory(), address_space_limit()];
    let (num, den) = DEFAULT_SHARE;
    Ok(known
        .into_iter()
        .flatten()
        .min()
        .map_or(u64::MAX, |m| m / den * num))
}

/// `123`, `512M`, `8G` … → bytes.
fn parse_size(text: &str) -> Result<u64> {
    let t = text.trim();
    let (digits, shift) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let shift = match c.to_ascii_uppercase() {
                'K' => 10,
                'M' => 20,
                'G' => 30,
                'T' => 40,
                _ => bail!("the unit must be K, M, G or T"),
            };
            (&t[..i], shift)
        }
        _ => (t, 0),
    };
    let n: u64 = digits
        .parse()
        .context("not a size such as 8G, 512M or a byte count")?;
    n.checked_mul(1 << shift)
        .filter(|&b| b > 0)
        .context("must be between 1 byte and 16 EiB")
}

/// `MemTotal` of `/proc/meminfo`.
fn machine_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib = info
        .lines()
        .find_map(|l| l.strip_prefix("MemTotal:"))?
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse::<u64>()
        .ok()?;
    Some(kib << 10)
}

/// The soft `Max address space` of `/proc/self/limits`, unless unlimited.
fn address_space_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

/// Bytes the views of a `grid` of cameras take while they render (one view at a time, the
/// shading cache of all).
pub fn view_bytes(resolution: [u32; 2], grid: [u32; 2]) -> u64 {
    let pixels = resolution[0] as u64 * resolution[1] as u64;
    let views = grid[0] as u64 * grid[1] as u64;
    pixels * (PIXEL_BYTES + views * VIEW_PIXEL_BYTES)
}

/// Bytes `n` triangles take while the scene renders.
pub fn triangle_bytes(n: u64) -> u64 {
    n.saturating_mul(TRIANGLE_BYTES)
}

/// Bytes decoding a `width × height` image takes at its peak: the decoder's output with
/// `channel_bytes` bytes a pixel, its RGBA8 conversion (unless it is RGBA8 already) and the
/// texels kept.
pub fn texture_decode_bytes(width: u32, height: u32, channel_bytes: u64) -> u64 {
    let pixels = width as u64 * height as u64;
    let conversion = if channel_bytes == 4 { 0 } else { 4 };
    pixels * (channel_bytes + conversion + 4)
}

/// The budget of `desc` charged with what its description sizes: its views and the
/// triangles of its parametric shapes (meshes are charged when their files are opened).
pub fn scene_budget(desc: &SceneDesc) -> Result<Budget> {
    let mut budget = Budget::of_this_process()?;
    let cam = &desc.camera;
    let views = format!(
        "camera.resolution {:?} (grid {:?})",
        cam.resolution, cam.grid
    );
    budget.charge(&views, view_bytes(cam.resolution, cam.grid))?;
    let triangles = (desc.objects.iter())
        .map(|o| shape_triangles(&o.shape))
        .fold(0u64, u64::saturating_add);
    budget.charge_triangles("the shapes", triangles)?;
    Ok(budget)
}

/// Triangles a parametric shape tessellates into, at most (0 for a mesh: its file counts).
fn shape_triangles(shape: &Shape) -> u64 {
    let n = |segments: u32| segments.max(3) as u64;
    match shape {
        Shape::Cuboid { .. } | Shape::Room { .. } => 12,
        Shape::Quad { .. } => 2,
        Shape::Wall { holes, .. } => 2 + 8 * holes.len() as u64,
        Shape::Sphere {
            rings, segments, ..
        } => 2 * n(*rings) * n(*segments),
        Shape::Cylinder { segments, .. } => 4 * n(*segments),
        Shape::Lathe { profile, segments } => 2 * profile.len() as u64 * n(*segments),
        Shape::Mesh { .. } => 0,
    }
}

/// What a scene is estimated to take so far, against its limit.
#[derive(Clone, Debug)]
pub struct Budget {
    /// "memory limit", "decoded-texture budget": what the limit is, for messages.
    name: &'static str,
    limit: u64,
    used: u64,
    /// Triangles charged so far (a scene has at most [`MAX_TRIANGLES`]).
    triangles: u64,
}

impl Budget {
    /// An empty budget of `limit` bytes of memory.
    pub fn new(limit: u64) -> Self {
        Self {
            name: "memory limit",
            limit,
            used: 0,
            triangles: 0,
        }
    }

    /// An empty budget of `limit` bytes of decoded texels.
    pub fn textures(limit: u64) -> Self {
        Self {
            name: "decoded-texture budget",
            ..Self::new(limit)
        }
    }

    /// An empty budget of [`limit`] bytes.
    pub fn of_this_process() -> Result<Self> {
        limit().map(Self::new)
    }

    /// Bytes charged so far.
    pub fn used(&self) -> u64 {
        self.used
    }

    /// Bytes left before the limit.
    pub fn left(&self) -> u64 {
        self.limit.saturating_sub(self.used)
    }

    /// Adds `bytes` for `what` (e.g. "camera.resolution [16384, 16384]"), or refuses them
    /// with the estimate and the limit when they would not fit.
    pub fn charge(&mut self, what: &str, bytes: u64) -> Result<()> {
        self.fits(what, bytes)?;
        self.used += bytes;
        Ok(())
    }

    /// Adds `n` triangles of `what` (e.g. "mesh 0 of chair.obj"), or refuses them when the
    /// scene would have more than [`MAX_TRIANGLES`] or they would not fit.
    pub fn charge_triangles(&mut self, what: &str, n: u64) -> Result<()> {
        let total = self.triangles.saturating_add(n);
        ensure!(
            total <= MAX_TRIANGLES as u64,
            "{what}: {n} triangles make the scene's {total}, more than the {MAX_TRIANGLES} a \
             scene may have"
        );
        self.charge(&format!("{what} ({n} triangles)"), triangle_bytes(n))?;
        self.triangles = total;
        Ok(())
    }

    /// Refuses `bytes` for `what` that would not fit, charging nothing (a passing peak).
    pub fn fits(&self, what: &str, bytes: u64) -> Result<()> {
        if bytes > self.left() {
            bail!(
                "{what} needs an estimated {} MiB, with the rest of the scene {} MiB: over the \
                 {} of {} MiB{}",
                mib(bytes),
                mib(self.used.saturating_add(bytes)),
                self.name,
                mib(self.limit),
                match self.name {
                    "memory limit" => format!(" (set {LIMIT_VAR} to change it)"),
                    _ => String::new(),
                }
            );
        }
        Ok(())
    }
}

/// Bytes in MiB, rounded up.
fn mib(bytes: u64) -> u64 {
    bytes.div_ceil(1 << 20)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_units() {
        assert_eq!(parse_size("123").unwrap(), 123);
        assert_eq!(parse_size("512M").unwrap(), 512 << 20);
        assert_eq!(parse_size(" 8g ").unwrap(), 8 << 30);
        for bad in ["", "0", "8X", "-1G", "1.5G", "99999999999T"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_charge_over_the_limit_names_estimate_and_limit() {
        let mut b = Budget::new(10 << 20);
        b.charge("the views", 6 << 20).unwrap();
        let err = b
            .charge("texture \"a.png\"", 5 << 20)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("texture \"a.png\"")
                && err.contains("5 MiB")
                && err.contains("11 MiB")
                && err.contains("limit of 10 MiB"),
            "{err}"
        );
        assert_eq!((b.used(), b.left()), (6 << 20, 4 << 20));
        assert!(b.fits("a peak", 4 << 20).is_ok());
    }
}
