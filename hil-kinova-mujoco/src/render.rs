//! PNG keyframes of attempts through MuJoCo's offscreen renderer on EGL
//! (headless: Mesa's software rasteriser works without a GPU or display).
//!
//! Built with the crate feature `render` (mujoco-rs's `renderer`). Without
//! the feature, or where no EGL device opens, [`KeyframeWriter::new`]
//! returns the reason, and callers carry on without pictures.

use std::path::{Path, PathBuf};

use hil_core::{ActionSpace, ArmId, Context, Environment, Item, Outcome, Result};
use mujoco_rs::prelude::*;

use crate::env::KinovaFeedingEnv;
use crate::sim::Simulator;

/// One recorded keyframe: the positions of every joint and the sizes of
/// the food geoms (they change per item), enough to redraw the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// File stem.
    pub name: String,
    qpos: Box<[f64]>,
    food_sizes: [[f64; 3]; 3],
}

/// Records keyframes during attempts. Plain data (`Send`), so it can sit in
/// an [`Environment`]; the OpenGL context lives in [`KeyframeWriter`] on the
/// caller's thread.
#[derive(Debug, Default)]
pub struct KeyframeRecorder {
    prefix: String,
    attempt: usize,
    frames: Vec<Keyframe>,
}

impl KeyframeRecorder {
    /// Prefix of the next frames (e.g. the method and repetition).
    pub fn set_prefix(&mut self, prefix: impl Into<String>) {
        self.prefix = prefix.into();
        self.attempt = 0;
    }

    /// Keeps only the pending frames whose name passes `keep` (names are
    /// `{prefix}_{attempt}_{item}_{phase}`, phases `start`, `pre_pose`,
    /// `skewer`, `lift`, `hold`).
    pub fn retain(&mut self, mut keep: impl FnMut(&str) -> bool) {
        self.frames.retain(|f| keep(&f.name));
    }

    /// Frames recorded and not yet written.
    pub fn pending(&self) -> usize {
        self.frames.len()
    }

    fn record(
        &mut self,
        item: &str,
        phase: &str,
        sim_geoms: [usize; 3],
        data: &MjData<Box<MjModel>>,
    ) {
        if phase == "start" {
            self.attempt += 1;
        }
        let sizes = data.model().geom_size();
        self.frames.push(Keyframe {
            name: format!("{}_{:02}_{item}_{phase}", self.prefix, self.attempt),
            qpos: data.qpos().into(),
            food_sizes: sim_geoms.map(|g| sizes[g]),
        });
    }
}

/// Which camera renders the keyframes, and at what size.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct View {
    /// Name of a camera in the MJCF.
    pub camera: String,
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
}

impl Default for View {
    /// The whole arm and plate: the `side` camera at 640×480.
    fn default() -> Self {
        Self {
            camera: "side".into(),
            width: 640,
            height: 480,
        }
    }
}

/// Writes recorded keyframes as PNGs (by default 640×480 from the scene's
/// `side` camera; see [`View`]).
#[derive(Debug)]
pub struct KeyframeWriter {
    dir: PathBuf,
    written: usize,
    #[cfg(feature = "render")]
    renderer: mujoco_rs::renderer::MjRenderer,
    #[cfg(feature = "render")]
    data: MjData<Box<MjModel>>,
    #[cfg(feature = "render")]
    geoms: [usize; 3],
}

impl KeyframeWriter {
    /// Opens an offscreen renderer for `sim`'s model, writing into `dir`
    /// (created if missing). Errors say why rendering is unavailable.
    pub fn new(dir: &Path, sim: &Simulator) -> std::result::Result<Self, String> {
        Self::with_view(dir, sim, &View::default())
    }

    /// As [`new`](Self::new), rendering through `view`.
    pub fn with_view(
        dir: &Path,
        sim: &Simulator,
        view: &View,
    ) -> std::result::Result<Self, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        Self::open(dir, sim, view)
    }

    #[cfg(feature = "render")]
    fn open(dir: &Path, sim: &Simulator, view: &View) -> std::result::Result<Self, String> {
        use mujoco_rs::renderer::MjRenderer;
        let model = sim.data().model();
        let cam = model
            .name_to_id(MjtObjBase::mjOBJ_CAMERA, &view.camera)
            .ok_or_else(|| format!("the scene has no camera named `{}`", view.camera))?;
        let renderer = MjRenderer::builder()
            .width(view.width)
            .height(view.height)
            .rgb(true)
            .depth(false)
            .camera(MjvCamera::new_fixed(cam))
            // Committed pictures stay small (the default writes raw pixels).
            .png_compression(mujoco_rs::renderer::png::Compression::High)
            .build(model)
            .map_err(|e| format!("no offscreen EGL context: {e}"))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            written: 0,
            renderer,
            data: MjData::new(Box::new(model.clone())),
            geoms: sim.ids().food.map(|f| f.geom),
        })
    }

    #[cfg(not(feature = "render"))]
    fn open(_dir: &Path, _sim: &Simulator, _view: &View) -> std::result::Result<Self, String> {
        Err("hil-kinova-mujoco was built without the `render` feature".into())
    }

    /// Images written so far.
    pub fn written(&self) -> usize {
        self.written
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Renders and writes every pending frame of `rec`, emptying it.
    #[cfg(feature = "render")]
    pub fn write(&mut self, rec: &mut KeyframeRecorder) -> std::result::Result<(), String> {
        for frame in rec.frames.drain(..) {
            // SAFETY: only geom sizes of existing geoms change.
            let m = unsafe { self.data.model_mut() };
            for (g, s) in self.geoms.iter().zip(frame.food_sizes) {
                m.geom_size_mut()[*g] = s;
            }
            self.data.qpos_mut().copy_from_slice(&frame.qpos);
            self.data.forward();
            let path = self.dir.join(format!("{}.png", frame.name));
            self.renderer
                .sync_data(&mut self.data)
                .map_err(|e| format!("rendering {}: {e}", frame.name))?;
            self.renderer
                .render()
                .map_err(|e| format!("rendering {}: {e}", frame.name))?;
            self.renderer
                .save_rgb(&path)
                .map_err(|e| format!("writing {}: {e}", path.display()))?;
            self.written += 1;
        }
        Ok(())
    }

    /// Without the `render` feature there is nothing to write with.
    #[cfg(not(feature = "render"))]
    pub fn write(&mut self, rec: &mut KeyframeRecorder) -> std::result::Result<(), String> {
        rec.frames.clear();
        Err("built without the `render` feature".into())
    }
}

/// A [`KinovaFeedingEnv`] whose attempts are recorded as keyframes.
#[derive(Debug)]
pub struct RenderingEnv<'a> {
    env: &'a mut KinovaFeedingEnv,
    recorder: &'a mut KeyframeRecorder,
}

impl<'a> RenderingEnv<'a> {
    /// Wraps `env`.
    pub fn new(env: &'a mut KinovaFeedingEnv, recorder: &'a mut KeyframeRecorder) -> Self {
        Self { env, recorder }
    }
}

impl Environment for RenderingEnv<'_> {
    fn name(&self) -> &str {
        self.env.name()
    }
    fn action_space(&self) -> &ActionSpace {
        self.env.action_space()
    }
    fn context_dim(&self) -> usize {
        self.env.context_dim()
    }
    fn reset(&mut self, seed: u64) -> Result<()> {
        self.env.reset(seed)
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        self.env.next_item()
    }
    fn observe(&mut self) -> Result<Context> {
        self.env.observe()
    }
    fn execute(&mut self, arm: ArmId) -> Result<Outcome> {
        let item = self
            .env
            .current_item()
            .map(|i| format!("{}{}", i.index, i.label))
            .unwrap_or_default();
        let geoms = self.env.simulator().ids().food.map(|f| f.geom);
        let rec = &mut *self.recorder;
        let mut hook =
            |phase: &str, data: &mut MjData<Box<MjModel>>| rec.record(&item, phase, geoms, data);
        self.env.execute_with(arm, Some(&mut hook))
    }
    fn best_action(&self) -> Option<ArmId> {
        self.env.best_action()
    }
    fn current_item(&self) -> Option<&Item> {
        self.env.current_item()
    }
}
