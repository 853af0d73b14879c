//! One scene folder (docs/reference/format.md, Scene folder), written atomically: into `.NAME.partial`, then renamed.
//!
//! While a scene is written its folder is locked (`.NAME.lock`, see [`Lock`]), so two runs
//! never write into one partial folder. An existing folder at the final place is replaced only
//! if it holds nothing but the files a scene writer writes: `--out` pointing at a dataset, a
//! glTF's own folder or any other folder of the user's is refused before anything renders.
//! The temporary folders `.NAME.partial` and `.NAME.old` carry a marker file while they exist,
//! and a folder of either name without it is the user's: refused, never removed.

use super::gt_files::{
    write_depth_maps, write_ids_json, write_objectids_highres, write_surface_maps, write_valid,
};
use super::hci_mask_files::write_hci_masks;
use super::images::{ToneCurve, write_linear_exr, write_png};
use crate::camera::LightFieldCamera;
use crate::scene::SceneDesc;
use crate::stats::SceneStats;
use anyhow::{Context, Result, bail};
use glam::Vec3;
use lfformat::gt_maps::HciLayer;
use lfformat::lock::Lock;
use lfformat::manifest::{FileEntry, sha256_file};
use lfformat::modes::write_modes_exr_with_surfaces;
use lfformat::mpi::{LOADER_LAYERS, Mpi, write_mpi_npz};
use lfformat::params::hci_disp_bounds;
use lfformat::region_masks::{MASK_STEMS, mask_file};
use lfformat::{HciParameters, ModeMap, ModeSurface};
use std::fs;
use std::path::{Path, PathBuf};

/// Writes the files of one scene into a temporary folder and publishes it on [`Self::finish`].
pub struct SceneWriter {
    final_dir: PathBuf,
    tmp_dir: PathBuf,
    /// Where a previous scene at `final_dir` is moved while the new one takes its place.
    old_dir: PathBuf,
    write_exr: bool,
    tone_curve: ToneCurve,
    /// High-resolution GT written at this many pixels per pixel (`depth_map_scale`), if any.
    highres_scale: Option<u32>,
    /// Beside a view the camera model recorded, also write its clean render as
    /// `clean_CamNNN.png`.
    write_clean: bool,
    /// Held until the folder is published (or the writer is dropped on an error).
    _lock: Lock,
}

/// Ground truth of one view, as the writer needs it.
pub struct GtImages<'a> {
    pub modes: &'a ModeMap,
    /// Linear colour per mode, in `modes` storage order.
    pub colors: &'a [[f32; 3]],
    /// Normal and ids per mode, in `modes` storage order.
    pub surfaces: &'a [ModeSurface],
    /// The HCI single-valued layer: depth, normal and ids per pixel.
    pub hci: &'a HciLayer,
    /// Where the HCI disparity is trustworthy (`valid_mask.png`).
    pub valid: &'a [bool],
}

impl SceneWriter {
    /// Starts a scene that will end up at `final_dir`: locks it, checks that whatever is there
    /// may be replaced, and removes a stale partial folder of a killed run.
    pub fn create(final_dir: &Path, write_exr: bool, tone_curve: ToneCurve) -> Result<Self> {
        let name = final_dir
            .file_name()
            .context("scene folder has no name")?
            .to_string_lossy();
        if let Some(parent) = final_dir.parent().filter(|p| !p.as_os_str().is_empty()) {
            fs::create_dir_all(parent)
                .with_context(|| format!("cannot create {}", parent.display()))?;
        }
        let lock = Lock::exclusive(&final_dir.with_file_name(format!(".{name}.lock")))?;
        check_replaceable(final_dir)?;
        let tmp_dir = final_dir.with_file_name(format!(".{name}.partial"));
        let old_dir = final_dir.with_file_name(format!(".{name}.old"));
        remove_own_temporary(&tmp_dir)?;
        remove_own_temporary(&old_dir)?;
        fs::create_dir(&tmp_dir).with_context(|| format!("cannot create {}", tmp_dir.display()))?;
        mark_temporary(&tmp_dir)?;
        Ok(Self {
            final_dir: final_dir.to_path_buf(),
            tmp_dir,
            old_dir,
            write_exr,
            tone_curve,
            highres_scale: None,
            write_clean: false,
            _lock: lock,
        })
    }

    /// With `write_clean`, views given with a camera's recording keep their clean render
    /// beside it (see [`Self::write_view`]).
    pub fn with_clean_views(self, write_clean: bool) -> Self {
        Self {
            write_clean,
            ..self
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.tmp_dir.join(name)
    }

    /// `input_CamNNN.png` of the linear radiance `pixels` times `exposure` (and `.exr` of the
    /// radiance when enabled). With `recorded`, the display-linear image a camera model made of
    /// them, the PNG is that recording, and `clean_CamNNN.png` the clean render if asked.
    pub fn write_view(
        &self,
        view: u32,
        (width, height): (usize, usize),
        pixels: &[Vec3],
        exposure: f32,
        recorded: Option<&[Vec3]>,
    ) -> Result<()> {
        let png = |name: &str, pixels: &[Vec3], exposure: f32| {
            let path = self.path(&format!("{name}_Cam{view:03}.png"));
            write_png(&path, width, height, pixels, exposure, self.tone_curve)
        };
        match recorded {
            Some(recorded) => {
                png("input", recorded, 1.0)?;
                if self.write_clean {
                    png("clean", pixels, exposure)?;
                }
            }
            None => png("input", pixels, exposure)?,
        }
        if self.write_exr {
            write_linear_exr(
                &self.path(&format!("input_Cam{view:03}.exr")),
                width,
                height,
                pixels,
            )?;
        }
        Ok(())
    }

    /// Ground-truth files of a view. The centre view gets HCI's unsuffixed names plus the
    /// MPI; with per-view GT (`per_view`) every view also gets `_CamNNN` variants.
    pub fn write_gt(
        &self,
        view: u32,
        is_center: bool,
        per_view: bool,
        cam: &LightFieldCamera,
        gt: &GtImages,
    ) -> Result<()> {
        let (w, h) = (gt.modes.width, gt.modes.height);
        if is_center {
            write_mpi_npz(
                &self.path("gt_mpi_lowres.npz"),
                &Mpi::from_modes(gt.modes, Some(gt.colors), LOADER_LAYERS),
            )?;
        }
        let disparity = |z: f32| cam.disparity(z as f64) as f32;
        let dir = &self.tmp_dir;
        for s in gt_suffixes(view, is_center, per_view) {
            write_depth_maps(dir, "lowres", &s, gt.hci, disparity)?;
            let modes = self.path(&format!("modes{s}.exr"));
            write_modes_exr_with_surfaces(&modes, gt.modes, gt.surfaces)?;
            write_surface_maps(dir, "lowres", &s, gt.hci)?;
            write_valid(dir, &s, w, h, gt.valid)?;
        }
        if is_center {
            write_hci_masks(dir, cam, gt.hci, 1)?;
        }
        Ok(())
    }

    /// High-resolution GT of a view (`gt_depth_highres.pfm`, `gt_disp_highres.pfm`,
    /// `objectids_highres.png`, named as [`Self::write_gt`] names the low-resolution files),
    /// `scale` pixels per low-resolution pixel; `parameters.cfg` then says `depth_map_scale`.
    pub fn write_highres(
        &mut self,
        (view, is_center, per_view): (u32, bool, bool),
        cam: &LightFieldCamera,
        layer: &HciLayer,
        scale: u32,
    ) -> Result<()> {
        self.highres_scale = Some(scale);
        let disparity = |z: f32| cam.disparity(z as f64) as f32;
        for s in gt_suffixes(view, is_center, per_view) {
            write_depth_maps(&self.tmp_dir, "highres", &s, layer, disparity)?;
            write_objectids_highres(&self.tmp_dir, &s, layer)?;
        }
        if is_center {
            write_hci_masks(&self.tmp_dir, cam, layer, scale)?;
        }
        Ok(())
    }

    /// Writes `parameters.cfg`, `scene.json` and `stats.json`, publishes the folder and returns
    /// its files (paths relative to `root`) with their checksums.
    pub fn finish(
        self,
        desc: &SceneDesc,
        stats: &SceneStats,
        root: &Path,
    ) -> Result<Vec<FileEntry>> {
        let mut params = hci_parameters(desc, stats);
        if let Some(scale) = self.highres_scale {
            params.depth_map_scale = scale as f64;
        }
        params.write(&self.path("parameters.cfg"))?;
        write_json(&self.path("scene.json"), desc)?;
        write_ids_json(&self.path("ids.json"), desc)?;
        write_json(&self.path("stats.json"), stats)?;
        self.publish()?;
        list_files(&self.final_dir, root)
    }

    /// Renames the partial folder into place. A previous scene there (checked replaceable at
    /// [`Self::create`], and again here) is first marked and renamed aside, and removed only
    /// after; the new folder's marker goes last, so a run killed at any point leaves only
    /// folders that the next one recognises as its own.
    fn publish(&self) -> Result<()> {
        let replaced = fs::symlink_metadata(&self.final_dir).is_ok();
        if replaced {
            check_replaceable(&self.final_dir)?;
            remove_own_temporary(&self.old_dir)?;
            mark_temporary(&self.final_dir)?;
            fs::rename(&self.final_dir, &self.old_dir)
                .with_context(|| format!("cannot replace {}", self.final_dir.display()))?;
        }
        fs::rename(&self.tmp_dir, &self.final_dir)
            .with_context(|| format!("cannot rename {} into place", self.tmp_dir.display()))?;
        let marker = self.final_dir.join(TEMPORARY_MARKER);
        fs::remove_file(&marker).with_context(|| format!("cannot remove {}", marker.display()))?;
        if replaced {
            remove_own_temporary(&self.old_dir)?;
        }
        Ok(())
    }
}

/// The name suffixes of a view's GT files: none for the centre view (HCI's names), `_CamNNN`
/// for every view with per-view GT.
fn gt_suffixes(view: u32, is_center: bool, per_view: bool) -> Vec<String> {
    let centre = is_center.then(String::new);
    centre
        .into_iter()
        .chain(per_view.then(|| format!("_Cam{view:03}")))
        .collect()
}

/// The file that marks a folder as lfgen's own temporary one (a scene being written, or a
/// previous scene being replaced): only folders holding it are ever removed, so a user's own
/// `.NAME.partial` or `.NAME.old` beside `--out NAME` is never deleted.
const TEMPORARY_MARKER: &str = ".lfgen-temporary";

fn mark_temporary(dir: &Path) -> Result<()> {
    let text = b"lfgen writes or removes this folder; it is not part of any scene\n";
    Ok(lfformat::files::write_file(
        &dir.join(TEMPORARY_MARKER),
        text,
    )?)
}

/// Removes `dir` if it is a temporary folder of lfgen's: marked with [`TEMPORARY_MARKER`] and
/// holding only files (a scene folder is flat), or empty (a run killed before marking it).
/// Anything else of that name is refused, naming it: it is the user's. The marker is removed
/// last, so a removal cut short leaves a folder still recognised as lfgen's.
fn remove_own_temporary(dir: &Path) -> Result<()> {
    let in_the_way = |what: String| {
        anyhow::anyhow!(
            "{} {what}, and lfgen did not make it: lfgen needs this name for a temporary \
             folder beside the scene; move or rename it",
            dir.display()
        )
    };
    match fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e).with_context(|| format!("cannot inspect {}", dir.display())),
        Ok(m) if !m.is_dir() => return Err(in_the_way("exists and is not a folder".into())),
        Ok(_) => {}
    }
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))? {
        let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !entry.file_type().is_ok_and(|t| t.is_file()) {
            return Err(in_the_way(format!("holds {name:?}, which is not a file")));
        }
        names.push(name);
    }
    if !names.is_empty() && !names.iter().any(|n| n == TEMPORARY_MARKER) {
        return Err(in_the_way(format!("holds {:?}", names[0])));
    }
    names.sort_by_key(|n| n == TEMPORARY_MARKER);
    for name in names {
        let path = dir.join(name);
        fs::remove_file(&path).with_context(|| format!("cannot remove {}", path.display()))?;
    }
    fs::remove_dir(dir).with_context(|| format!("cannot remove {}", dir.display()))
}

/// Fails unless `dir` is absent, or a folder holding only files a [`SceneWriter`] writes (and
/// perhaps the temporary marker of a run killed just as it published the folder).
pub fn check_replaceable(dir: &Path) -> Result<()> {
    let meta = match fs::symlink_metadata(dir) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e).with_context(|| format!("cannot inspect {}", dir.display())),
    };
    if !meta.is_dir() {
        bail!(
            "{} exists and is not a folder: choose a new or empty folder for the scene",
            dir.display()
        );
    }
    for entry in fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))? {
        let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if !is_file || !(is_scene_file(&name) || name == TEMPORARY_MARKER) {
            bail!(
                "{} already holds {name:?}, which is not a file of an lfgen scene: lfgen \
                 replaces only a previous scene folder; choose a new or empty folder",
                dir.display()
            );
        }
    }
    Ok(())
}

/// Whether `name` is one of the files [`SceneWriter`] writes.
fn is_scene_file(name: &str) -> bool {
    const FIXED: [&str; 5] = [
        "parameters.cfg",
        "scene.json",
        "stats.json",
        "ids.json",
        "gt_mpi_lowres.npz",
    ];
    let per_view = |stem: &str, ext: &str| {
        name.strip_prefix(stem)
            .and_then(|rest| rest.strip_suffix(ext))
            .is_some_and(|mid| {
                mid.is_empty()
                    || mid
                        .strip_prefix("_Cam")
                        .is_some_and(|n| n.len() == 3 && n.bytes().all(|b| b.is_ascii_digit()))
            })
    };
    let view = name
        .strip_prefix("input_Cam")
        .or_else(|| name.strip_prefix("clean_Cam"))
        .and_then(|r| r.strip_suffix(".png").or_else(|| r.strip_suffix(".exr")))
        .is_some_and(|n| n.len() == 3 && n.bytes().all(|b| b.is_ascii_digit()));
    FIXED.contains(&name)
        || view
        || ["gt_depth_", "gt_disp_"].iter().any(|map| {
            ["lowres", "highres"]
                .iter()
                .any(|res| per_view(&format!("{map}{res}"), ".pfm"))
        })
        || per_view("gt_normals_lowres", ".exr")
        || ["objectids", "materialids", "classids"]
            .iter()
            .any(|map| per_view(&format!("{map}_lowres"), ".png"))
        || per_view("objectids_highres", ".png")
        || per_view("valid_mask", ".png")
        || MASK_STEMS.iter().any(|stem| {
            [false, true]
                .iter()
                .any(|&high| name == mask_file(stem, high))
        })
        || per_view("modes", ".exr")
}

/// Pretty JSON, with the path in any error.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    Ok(lfformat::files::write_file(path, text.as_bytes())?)
}

/// Checksums of every file in `dir`, sorted by name, paths relative to `root`.
pub fn list_files(dir: &Path, root: &Path) -> Result<Vec<FileEntry>> {
    let mut names: Vec<PathBuf> = fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<_>>()?;
    names.sort();
    names
        .iter()
        .map(|p| {
            let (sha256, bytes) = sha256_file(p)?;
            let rel = p.strip_prefix(root).unwrap_or(p);
            let path = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy())
                .collect::<Vec<_>>()
                .join("/");
            Ok(FileEntry {
                path,
                sha256,
                bytes,
            })
        })
        .collect()
}

/// HCI `parameters.cfg` of a scene (docs/reference/format.md, Scene folder).
fn hci_parameters(desc: &SceneDesc, stats: &SceneStats) -> HciParameters {
    let cam = &desc.camera;
    let [px, py, pz] = cam.blender_position();
    let [rx, ry, rz] = cam.blender_rotation();
    let (disp_min, disp_max) =
        hci_disp_bounds(stats.hci_disparity_range[0], stats.hci_disparity_range[1]);
    HciParameters {
        focal_length_mm: cam.focal_length_mm,
        image_resolution_x_px: cam.resolution[0],
        image_resolution_y_px: cam.resolution[1],
        sensor_size_mm: cam.sensor_size_mm,
        fstop: 100.0,
        num_cams_x: cam.grid[0],
        num_cams_y: cam.grid[1],
        baseline_mm: cam.baseline_m * 1000.0,
        focus_distance_m: cam.focus_distance_m,
        center_cam_x_m: px,
        center_cam_y_m: py,
        center_cam_z_m: pz,
        center_cam_rx_rad: rx,
        center_cam_ry_rad: ry,
        center_cam_rz_rad: rz,
        scene: desc.name.clone(),
        category: "lfgen".into(),
        date: stats.date.clone(),
        version: desc.generator.clone(),
        cycles_seed: desc.seed,
        disp_min,
        disp_max,
        frustum_disp_min: cam.disparity(desc.slices.z_far),
        frustum_disp_max: cam.disparity(desc.slices.z_near),
        depth_map_scale: 1.0,
    }
}
