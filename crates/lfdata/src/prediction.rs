//! A method's predictions on disk: the HCI submission layout plus optional uncertainty and
//! posterior files.
//!
//! ```text
//! METHOD/disp_maps/<scene>.pfm      disparity, HCI PFM (rows bottom-up on disk)
//! METHOD/runtimes/<scene>.txt       seconds, one number (HCI submission format)
//! METHOD/uncertainty/<scene>.pfm    optional: larger = less certain (e.g. the variance)
//! METHOD/posteriors/<scene>.npz     optional: one of the three forms below, rows top-down
//!   discrete: probs (H, W, K), range (2,) = [min, max] of K equal bins
//!   laplace:  mu (H, W), log_b (H, W)              natural log of the scale b
//!   mixture:  weights (H, W, M), mu (H, W, M), log_b (H, W, M)
//! ```
//! The disparity map may be left out when a posterior is given; its point estimate is then
//! used (see [`crate::posterior::PixelPosterior::point_estimate`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use lfformat::pfm::{FloatImage, read_pfm, write_pfm};

use crate::bins::Bins;
use crate::npz::{Array, NpzReader, write_npz};
use crate::posterior::{PosteriorForm, PosteriorMap};
use crate::stacks::Region;

/// Folder of the disparity maps.
pub const DISP_DIR: &str = "disp_maps";
/// Folder of the uncertainty maps.
pub const UNCERTAINTY_DIR: &str = "uncertainty";
/// Folder of the posteriors.
pub const POSTERIOR_DIR: &str = "posteriors";
/// Folder of the runtimes.
pub const RUNTIME_DIR: &str = "runtimes";

/// What a method predicted for one scene.
#[derive(Clone, Debug)]
pub struct ScenePrediction {
    /// Point estimate per pixel.
    pub disparity: FloatImage,
    /// Larger = less certain; ranks pixels for sparsification.
    pub uncertainty: Option<FloatImage>,
    /// The full distribution per pixel.
    pub posterior: Option<PosteriorMap>,
    /// Seconds the method took on the scene.
    pub runtime_s: Option<f64>,
}

/// One method: a folder of predictions, named after the folder.
#[derive(Clone, Debug)]
pub struct Method {
    /// The folder name, used in reports.
    pub name: String,
    /// The folder.
    pub dir: PathBuf,
}

impl Method {
    /// The method stored in `dir`, which must exist.
    pub fn new(dir: &Path) -> Result<Self> {
        if !dir.is_dir() {
            bail!("{}: prediction folder does not exist", dir.display());
        }
        let canonical = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
        let name = canonical
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .with_context(|| format!("{}: a prediction folder needs a name", dir.display()))?;
        Ok(Self {
            name,
            dir: dir.to_path_buf(),
        })
    }

    /// `METHOD/<folder>/<scene>.<ext>`.
    pub fn file(&self, folder: &str, scene: &str, ext: &str) -> PathBuf {
        self.dir.join(folder).join(format!("{scene}.{ext}"))
    }

    /// Reads the prediction for `scene` and checks it is `width × height`.
    pub fn load(&self, scene: &str, width: usize, height: usize) -> Result<ScenePrediction> {
        self.load_cropped(scene, width, height, None)
    }

    /// [`Method::load`], also taking a prediction the size of `crop` when one is given (a
    /// method run on the crop only, as `lfeval slfc --crop`): such a prediction is placed
    /// into the whole image, not-a-number around it.
    pub fn load_cropped(
        &self,
        scene: &str,
        width: usize,
        height: usize,
        crop: Option<Region>,
    ) -> Result<ScenePrediction> {
        let whole = Region {
            x0: 0,
            y0: 0,
            width,
            height,
        };
        let placed = |path: &Path, w: usize, h: usize| -> Result<Region> {
            match crop {
                _ if (w, h) == (width, height) => Ok(whole),
                Some(c) if (w, h) == (c.width, c.height) => Ok(c),
                Some(c) => bail!(
                    "{}: {w}x{h}, but the ground truth is {width}x{height} and its crop {}x{}",
                    path.display(),
                    c.width,
                    c.height
                ),
                None => bail!(
                    "{}: {w}x{h}, but the ground truth is {width}x{height}",
                    path.display()
                ),
            }
        };
        let image = |path: &Path| -> Result<FloatImage> {
            let img = read_pfm(path)?;
            let at = placed(path, img.width, img.height)?;
            Ok(embed_image(img, at, width, height))
        };
        let posterior = optional(self.file(POSTERIOR_DIR, scene, "npz"), |p| {
            // Without a crop the header alone can refuse a file of the wrong size.
            let map = match crop {
                None => read_posterior_sized(p, Some([height, width]))?,
                Some(_) => read_posterior(p)?,
            };
            let at = placed(p, map.width, map.height)?;
            Ok(embed_posterior(map, at, width, height))
        })?;
        let uncertainty = optional(self.file(UNCERTAINTY_DIR, scene, "pfm"), image)?;
        let runtime_s = optional(self.file(RUNTIME_DIR, scene, "txt"), read_runtime)?;
        let disp_path = self.file(DISP_DIR, scene, "pfm");
        let disparity = match (disp_path.exists(), &posterior) {
            (true, _) => image(&disp_path)?,
            (false, Some(map)) => point_estimates(map),
            (false, None) => bail!(
                "{}: missing, and there is no {} either",
                disp_path.display(),
                self.file(POSTERIOR_DIR, scene, "npz").display()
            ),
        };
        Ok(ScenePrediction {
            disparity,
            uncertainty,
            posterior,
            runtime_s,
        })
    }
}

/// `values` (`per_pixel` per pixel of `at`, row-major) placed at `at` in a `width × height`
/// image of `fill`.
fn embed<T: Copy>(
    values: &[T],
    per_pixel: usize,
    at: Region,
    width: usize,
    height: usize,
    fill: T,
) -> Vec<T> {
    let mut out = vec![fill; width * height * per_pixel];
    for (y, row) in values.chunks_exact(at.width * per_pixel).enumerate() {
        let start = ((at.y0 + y) * width + at.x0) * per_pixel;
        out[start..start + row.len()].copy_from_slice(row);
    }
    out
}

/// `img`, predicted over `at`, in a `width × height` image; not-a-number outside `at`.
fn embed_image(img: FloatImage, at: Region, width: usize, height: usize) -> FloatImage {
    if (img.width, img.height) == (width, height) {
        return img;
    }
    let data = embed(&img.data, 1, at, width, height, f32::NAN);
    FloatImage::new(width, height, data)
}

/// `map`, predicted over `at`, in a `width × height` image; outside `at` the pixels hold
/// no distribution (zero probabilities, not-a-number Laplacians).
fn embed_posterior(map: PosteriorMap, at: Region, width: usize, height: usize) -> PosteriorMap {
    if (map.width, map.height) == (width, height) {
        return map;
    }
    let place = |values: &[f32], per_pixel: usize, fill: f32| {
        embed(values, per_pixel, at, width, height, fill)
    };
    let form = match &map.form {
        PosteriorForm::Discrete { bins, probs } => PosteriorForm::Discrete {
            bins: *bins,
            probs: place(probs, bins.count, 0.0),
        },
        PosteriorForm::Laplace { mu, log_b } => PosteriorForm::Laplace {
            mu: place(mu, 1, f32::NAN),
            log_b: place(log_b, 1, f32::NAN),
        },
        PosteriorForm::Mixture {
            components,
            weights,
            mu,
            log_b,
        } => PosteriorForm::Mixture {
            components: *components,
            weights: place(weights, *components, 0.0),
            mu: place(mu, *components, f32::NAN),
            log_b: place(log_b, *components, f32::NAN),
        },
    };
    PosteriorMap {
        width,
        height,
        form,
    }
}

/// `read(path)` when `path` exists, `None` otherwise.
fn optional<T>(path: PathBuf, read: impl FnOnce(&Path) -> Result<T>) -> Result<Option<T>> {
    if path.exists() {
        read(&path).map(Some)
    } else {
        Ok(None)
    }
}

/// The point estimate of every pixel of `map`.
pub fn point_estimates(map: &PosteriorMap) -> FloatImage {
    let data = (0..map.width * map.height)
        .map(|i| map.pixel(i).point_estimate() as f32)
        .collect();
    FloatImage::new(map.width, map.height, data)
}

/// Seconds from an HCI runtime file (one number, whitespace around it allowed).
pub fn read_runtime(path: &Path) -> Result<f64> {
    let text = lfformat::read::text(path)?;
    let value: f64 = text.trim().parse().with_context(|| {
        format!(
            "{}: expected one number of seconds, found {:?}",
            path.display(),
            text.trim()
        )
    })?;
    if !(value.is_finite() && value >= 0.0) {
        bail!(
            "{}: runtime {value} is not a non-negative number",
            path.display()
        );
    }
    Ok(value)
}

/// Writes the files of `pred` for `scene` under `dir` (creating the folders).
pub fn write_prediction(dir: &Path, scene: &str, pred: &ScenePrediction) -> Result<()> {
    let file = |folder: &str, ext: &str| -> Result<PathBuf> {
        let sub = dir.join(folder);
        std::fs::create_dir_all(&sub)
            .with_context(|| format!("{}: cannot create", sub.display()))?;
        Ok(sub.join(format!("{scene}.{ext}")))
    };
    write_pfm(&file(DISP_DIR, "pfm")?, &pred.disparity)?;
    if let Some(u) = &pred.uncertainty {
        write_pfm(&file(UNCERTAINTY_DIR, "pfm")?, u)?;
    }
    if let Some(p) = &pred.posterior {
        write_posterior(&file(POSTERIOR_DIR, "npz")?, p)?;
    }
    if let Some(t) = pred.runtime_s {
        let path = file(RUNTIME_DIR, "txt")?;
        std::fs::write(&path, format!("{t}\n"))
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// Writes `map` in the documented npz layout.
pub fn write_posterior(path: &Path, map: &PosteriorMap) -> Result<()> {
    let (h, w) = (map.height, map.width);
    match &map.form {
        PosteriorForm::Discrete { bins, probs } => {
            let range = [bins.min as f32, bins.max as f32];
            write_npz(
                path,
                &[
                    ("probs", &[h, w, bins.count], probs),
                    ("range", &[2], &range),
                ],
            )
        }
        PosteriorForm::Laplace { mu, log_b } => {
            write_npz(path, &[("mu", &[h, w], mu), ("log_b", &[h, w], log_b)])
        }
        PosteriorForm::Mixture {
            components,
            weights,
            mu,
            log_b,
        } => {
            let shape = [h, w, *components];
            write_npz(
                path,
                &[
                    ("weights", &shape, weights),
                    ("mu", &shape, mu),
                    ("log_b", &shape, log_b),
                ],
            )
        }
    }
}

/// Reads a posterior npz; the form follows from the array names present.
pub fn read_posterior(path: &Path) -> Result<PosteriorMap> {
    read_posterior_sized(path, None)
}

/// [`read_posterior`], refusing from the header alone arrays that are not `[height, width]`.
fn read_posterior_sized(path: &Path, image: Option<[usize; 2]>) -> Result<PosteriorMap> {
    let mut npz = NpzReader::open(path)?;
    if let Some([h, w]) = image {
        npz = npz.expect_image(h, w);
    }
    if npz.has("probs") {
        read_discrete(&mut npz, path)
    } else if npz.has("weights") {
        read_mixture(&mut npz, path)
    } else if npz.has("mu") && npz.has("log_b") {
        read_laplace(&mut npz, path)
    } else {
        Err(invalid(
            path,
            format!(
                "holds arrays {:?}; expected probs + range (discrete), mu + log_b (Laplace) \
                 or weights + mu + log_b (mixture)",
                npz.names()
            ),
        ))
    }
}

/// A format problem of the file at `path`.
fn invalid(path: &Path, message: String) -> anyhow::Error {
    anyhow::anyhow!("{}: {message}", path.display())
}

fn read_discrete(npz: &mut NpzReader, path: &Path) -> Result<PosteriorMap> {
    let probs = npz.read("probs")?;
    let range = npz.read("range")?;
    let [h, w, k] = dims(&probs, "probs").map_err(|m| invalid(path, m))?;
    let [min, max] = range.data[..] else {
        let shape = &range.shape;
        return Err(invalid(
            path,
            format!("array \"range\" must hold [min, max], has shape {shape:?}"),
        ));
    };
    let bins = Bins::new(min.into(), max.into(), k).map_err(|m| invalid(path, m))?;
    check_non_negative(&probs.data, "probs").map_err(|m| invalid(path, m))?;
    let form = PosteriorForm::Discrete {
        bins,
        probs: probs.data,
    };
    Ok(PosteriorMap {
        width: w,
        height: h,
        form,
    })
}

fn read_mixture(npz: &mut NpzReader, path: &Path) -> Result<PosteriorMap> {
    let (weights, mu, log_b) = (npz.read("weights")?, npz.read("mu")?, npz.read("log_b")?);
    let [h, w, m] = same_dims(&[(&weights, "weights"), (&mu, "mu"), (&log_b, "log_b")])
        .map_err(|m| invalid(path, m))?;
    check_non_negative(&weights.data, "weights").map_err(|m| invalid(path, m))?;
    let form = PosteriorForm::Mixture {
        components: m,
        weights: weights.data,
        mu: mu.data,
        log_b: log_b.data,
    };
    Ok(PosteriorMap {
        width: w,
        height: h,
        form,
    })
}

fn read_laplace(npz: &mut NpzReader, path: &Path) -> Result<PosteriorMap> {
    let (mu, log_b) = (npz.read("mu")?, npz.read("log_b")?);
    let [h, w, k] = same_dims(&[(&mu, "mu"), (&log_b, "log_b")]).map_err(|m| invalid(path, m))?;
    if k != 1 {
        let shape = &mu.shape;
        let hint = "several components need \"weights\" (mixture)";
        return Err(invalid(
            path,
            format!("array \"mu\" has shape {shape:?}, expected (H, W); {hint}"),
        ));
    }
    let form = PosteriorForm::Laplace {
        mu: mu.data,
        log_b: log_b.data,
    };
    Ok(PosteriorMap {
        width: w,
        height: h,
        form,
    })
}

/// `[H, W, K]` of an `(H, W, K)` array, or `[H, W, 1]` of an `(H, W)` one.
fn dims(a: &Array, name: &str) -> Result<[usize; 3], String> {
    match a.shape[..] {
        [h, w] => Ok([h, w, 1]),
        [h, w, k] if k > 0 => Ok([h, w, k]),
        _ => Err(format!(
            "array {name:?} has shape {:?}, expected (H, W) or (H, W, K)",
            a.shape
        )),
    }
}

/// The common dims of arrays that must all have the same shape.
fn same_dims(arrays: &[(&Array, &str)]) -> Result<[usize; 3], String> {
    let (first, first_name) = arrays[0];
    let d = dims(first, first_name)?;
    for (a, name) in &arrays[1..] {
        if a.shape != first.shape {
            return Err(format!(
                "array {name:?} has shape {:?} but {first_name:?} has {:?}",
                a.shape, first.shape
            ));
        }
    }
    Ok(d)
}

/// Probabilities and weights may be NaN (pixel without prediction) but never negative.
fn check_non_negative(values: &[f32], name: &str) -> Result<(), String> {
    match values.iter().position(|&v| v < 0.0) {
        Some(i) => Err(format!(
            "array {name:?} holds a negative value {} at flat index {i}",
            values[i]
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(form: PosteriorForm) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.npz");
        let map = PosteriorMap {
            width: 2,
            height: 1,
            form,
        };
        write_posterior(&path, &map).unwrap();
        assert_eq!(read_posterior(&path).unwrap(), map);
    }

    #[test]
    fn all_three_forms_round_trip() {
        round_trip(PosteriorForm::Discrete {
            bins: Bins::new(-1.0, 1.0, 2).unwrap(),
            probs: vec![0.5, 0.5, 1.0, 0.0],
        });
        round_trip(PosteriorForm::Laplace {
            mu: vec![0.5, -0.5],
            log_b: vec![-1.0, -2.0],
        });
        round_trip(PosteriorForm::Mixture {
            components: 2,
            weights: vec![0.5, 0.5, 1.0, 0.0],
            mu: vec![0.0, 1.0, 2.0, 3.0],
            log_b: vec![-1.0; 4],
        });
    }

    #[test]
    fn bad_posterior_files_are_explained() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.npz");
        write_npz(&path, &[("foo", &[1], &[1.0])]).unwrap();
        let err = read_posterior(&path).unwrap_err().to_string();
        assert!(
            err.contains("bad.npz") && err.contains("probs + range"),
            "{err}"
        );
        write_npz(
            &path,
            &[
                ("probs", &[1, 1, 2], &[0.5, -0.5]),
                ("range", &[2], &[0.0, 1.0]),
            ],
        )
        .unwrap();
        let err = read_posterior(&path).unwrap_err().to_string();
        assert!(err.contains("negative"), "{err}");
        write_npz(
            &path,
            &[
                ("mu", &[1, 2], &[0.0, 0.0]),
                ("log_b", &[2, 1], &[0.0, 0.0]),
            ],
        )
        .unwrap();
        let err = read_posterior(&path).unwrap_err().to_string();
        assert!(err.contains("\"log_b\" has shape"), "{err}");
        let shape: &[usize] = &[1, 1, 2];
        write_npz(
            &path,
            &[("mu", shape, &[0.0, 0.0]), ("log_b", shape, &[0.0, 0.0])],
        )
        .unwrap();
        let err = read_posterior(&path).unwrap_err().to_string();
        assert!(err.contains("expected (H, W)"), "{err}");
    }

    #[test]
    fn runtime_files_hold_one_number() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.txt");
        std::fs::write(&path, " 2.5\n").unwrap();
        assert_eq!(read_runtime(&path).unwrap(), 2.5);
        std::fs::write(&path, "fast").unwrap();
        let err = format!("{:#}", read_runtime(&path).unwrap_err());
        assert!(err.contains("t.txt") && err.contains("fast"), "{err}");
    }

    #[test]
    fn missing_files_name_what_was_expected() {
        let dir = tempfile::tempdir().unwrap();
        let method = Method::new(dir.path()).unwrap();
        let err = method.load("scene_0000", 4, 4).unwrap_err().to_string();
        assert!(
            err.contains("disp_maps/scene_0000.pfm") && err.contains("posteriors"),
            "{err}"
        );
        assert!(Method::new(&dir.path().join("nope")).is_err());
    }

    #[test]
    fn a_posterior_claiming_a_huge_shape_is_refused_from_its_header() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join(POSTERIOR_DIR)).unwrap();
        // An .npy header that claims 49152 × 49152 × 108 float32 (1 TB) over 16 bytes.
        let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (49152, 49152, 108), }";
        let mut header = dict.to_string();
        while !(10 + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut npy = b"\x93NUMPY\x01\x00".to_vec();
        npy.extend_from_slice(&(header.len() as u16).to_le_bytes());
        npy.extend_from_slice(header.as_bytes());
        npy.extend_from_slice(&[0u8; 16]);
        let path = dir.path().join("posteriors/s.npz");
        let mut zip = npyz::zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
        zip.start_file("probs.npy", npyz::zip::write::FileOptions::default())
            .unwrap();
        std::io::Write::write_all(&mut zip, &npy).unwrap();
        zip.finish().unwrap();
        let method = Method::new(dir.path()).unwrap();
        let err = format!("{:#}", method.load("s", 4, 4).unwrap_err());
        assert!(err.contains("49152") && err.contains("4x4"), "{err}");
    }

    #[test]
    fn posterior_alone_gives_the_point_estimate_and_sizes_are_checked() {
        let dir = tempfile::tempdir().unwrap();
        let map = PosteriorMap {
            width: 2,
            height: 1,
            form: PosteriorForm::Laplace {
                mu: vec![0.25, -1.0],
                log_b: vec![0.0, 0.0],
            },
        };
        std::fs::create_dir(dir.path().join(POSTERIOR_DIR)).unwrap();
        write_posterior(&dir.path().join("posteriors/s.npz"), &map).unwrap();
        let method = Method::new(dir.path()).unwrap();
        let pred = method.load("s", 2, 1).unwrap();
        assert_eq!(pred.disparity.data, vec![0.25, -1.0]);
        let err = method.load("s", 3, 1).unwrap_err().to_string();
        assert!(err.contains("2x1") && err.contains("3x1"), "{err}");
    }

    #[test]
    fn a_crop_sized_posterior_is_placed_at_the_crop() {
        let dir = tempfile::tempdir().unwrap();
        let bins = Bins::new(0.0, 2.0, 2).unwrap();
        // A 2×1 crop at column 1, row 1 of a 4×3 image, two bins per pixel.
        let map = PosteriorMap {
            width: 2,
            height: 1,
            form: PosteriorForm::Discrete {
                bins,
                probs: vec![1.0, 0.0, 0.0, 1.0],
            },
        };
        std::fs::create_dir(dir.path().join(POSTERIOR_DIR)).unwrap();
        write_posterior(&dir.path().join("posteriors/s.npz"), &map).unwrap();
        let method = Method::new(dir.path()).unwrap();
        let crop = Region {
            x0: 1,
            y0: 1,
            width: 2,
            height: 1,
        };
        let pred = method.load_cropped("s", 4, 3, Some(crop)).unwrap();
        let d = &pred.disparity.data;
        assert_eq!((d[5], d[6]), (0.5, 1.5));
        assert!(
            d.iter()
                .enumerate()
                .all(|(i, v)| [5, 6].contains(&i) || v.is_nan())
        );
        let Some(PosteriorMap {
            width: 4,
            height: 3,
            form: PosteriorForm::Discrete { probs, .. },
        }) = pred.posterior
        else {
            panic!("a 4x3 discrete posterior");
        };
        assert_eq!(&probs[10..14], &[1.0, 0.0, 0.0, 1.0]);
        assert_eq!(probs.iter().sum::<f32>(), 2.0);
        let other = Region { x0: 0, ..crop };
        assert!(
            method
                .load_cropped("s", 4, 3, Some(Region { width: 3, ..other }))
                .is_err()
        );
    }
}
