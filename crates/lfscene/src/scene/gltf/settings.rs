//! The importer's own parameters (the `[gltf]` section of `generator.toml`) and everything else
//! an import needs from the caller, so that the import layer reads no CLI configuration.

use crate::scene::SceneStart;
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

/// Rendering glTF 2.0 scenes (`lfgen render SCENE.gltf`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GltfSettings {
    /// Which glTF scene: `"default"` (the file's `scene`, else its first), a scene name or an
    /// index.
    pub scene: String,
    /// The centre view: `"first"` (the first perspective camera in node order), a camera or
    /// camera-node name (`--camera NAME` sets this), or `"config"` for the pose below.
    pub camera: String,
    /// With `camera = "config"`: centre camera position, the point it looks at, the up hint
    /// (metres, glTF world: +Y up) and the vertical field of view.
    pub camera_position: [f64; 3],
    pub camera_look_at: [f64; 3],
    pub camera_up: [f64; 3],
    pub camera_yfov_deg: f64,
    /// Environment radiance (linear RGB) of a scene with lights (punctual or emissive).
    pub environment: [f64; 3],
    /// Environment radiance of a scene without any light: a uniform white sky, so that an
    /// unlit export still renders.
    pub unlit_environment: [f64; 3],
}

impl Default for GltfSettings {
    fn default() -> Self {
        Self {
            scene: "default".into(),
            camera: "first".into(),
            camera_position: [0.0, 1.0, 3.0],
            camera_look_at: [0.0, 1.0, 0.0],
            camera_up: [0.0, 1.0, 0.0],
            camera_yfov_deg: 40.0,
            environment: [0.0, 0.0, 0.0],
            unlit_environment: [1.0, 1.0, 1.0],
        }
    }
}

impl GltfSettings {
    /// Checks the pose and radiances; the error names the keys.
    pub fn validate(&self) -> Result<()> {
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        let vectors = [self.camera_position, self.camera_look_at, self.camera_up];
        let fov = self.camera_yfov_deg;
        if !(vectors.iter().all(finite) && fov > 0.0 && fov < 180.0) {
            bail!("gltf camera pose must be finite and camera_yfov_deg in (0, 180)");
        }
        let radiance = [self.environment, self.unlit_environment];
        if radiance
            .iter()
            .flatten()
            .any(|v| !(v.is_finite() && *v >= 0.0))
        {
            bail!("gltf.environment and gltf.unlit_environment must be finite and non-negative");
        }
        Ok(())
    }
}

/// What an import takes besides the file: the `[gltf]` settings and what the new scene
/// description starts with (the importer aims the rig at the file's camera).
#[derive(Clone, Debug)]
pub struct ImportSettings<'a> {
    pub gltf: &'a GltfSettings,
    pub start: SceneStart,
}
