//! Loading the MJCF scene and resolving the names the simulation needs.

use std::path::Path;

use mujoco_rs::prelude::*;

use crate::error::KinovaError;
use crate::food::FoodKind;

/// The built-in scene: Gen3 6-DoF + 2-DoF fork, table, plate, foods.
pub const BUILTIN_MJCF: &str = include_str!("../assets/gen3_feeding.xml");

/// Names of the arm joints, base to wrist.
pub const ARM_JOINTS: [&str; 6] = [
    "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6",
];

/// Number of tines on the fork.
pub const N_TINES: usize = 4;

/// Where a model came from, for error messages.
#[derive(Clone, Debug)]
pub enum MjcfSource<'a> {
    /// The scene bundled with the crate.
    Builtin,
    /// A file on disk.
    File(&'a Path),
}

impl MjcfSource<'_> {
    pub(crate) fn origin(&self) -> String {
        match self {
            MjcfSource::Builtin => "<built-in gen3_feeding.xml>".into(),
            MjcfSource::File(p) => p.display().to_string(),
        }
    }
}

/// Indices into the model of everything the simulation touches.
#[derive(Clone, Debug)]
pub struct SceneIds {
    /// qpos address of each arm joint.
    pub arm_qpos: [usize; 6],
    /// dof address of each arm joint.
    pub arm_dof: [usize; 6],
    /// qpos address of fork pitch and roll.
    pub fork_qpos: [usize; 2],
    /// Joint ids of fork pitch and roll.
    pub fork_joint: [usize; 2],
    /// Dof address of fork pitch and roll.
    pub fork_dof: [usize; 2],
    /// The fork motors (position servos `act_fork_pitch`, `act_fork_roll`).
    pub fork_actuator: [usize; 2],
    /// Body of the fork (tines).
    pub fork_body: usize,
    /// Site at the wrist force/torque sensor (fork base frame).
    pub wrist_site: usize,
    /// Site at the centre of the tine tips (x along the tines).
    pub tip_site: usize,
    /// One site per tine tip.
    pub tine_sites: [usize; N_TINES],
    /// Address of the wrist force sensor in sensordata.
    pub wrist_force_adr: usize,
    /// Per food kind: body, geom, free-joint qpos address, dof address.
    pub food: [FoodIds; 3],
    /// The lettuce leaf of the `lettuce` setting, if the scene has one.
    pub lettuce: Option<FoodIds>,
    /// Body of the plate.
    pub plate_body: usize,
}

/// Name of the lettuce leaf's body (free joint `lettuce_free`).
pub const LETTUCE_BODY: &str = "lettuce";
/// Name of the lettuce leaf's geom (a box).
pub const LETTUCE_GEOM: &str = "lettuce_geom";

/// Model indices of one free body (a food item or the leaf).
#[derive(Clone, Copy, Debug)]
pub struct FoodIds {
    /// Body id.
    pub body: usize,
    /// Geom id.
    pub geom: usize,
    /// qpos address of its free joint.
    pub qpos: usize,
    /// dof address of its free joint.
    pub dof: usize,
}

/// Loads the scene from `source` and resolves its names.
pub fn load(source: MjcfSource<'_>) -> Result<(MjModel, SceneIds), KinovaError> {
    keep_logs_out_of_cwd();
    let origin = source.origin();
    let model = match source {
        MjcfSource::Builtin => MjModel::from_xml_string(BUILTIN_MJCF),
        MjcfSource::File(path) => {
            // MuJoCo's own message for a missing file is terse; read it first
            // so the error names the path and the OS reason.
            let text =
                std::fs::read_to_string(path).map_err(|source| KinovaError::MjcfUnreadable {
                    path: path.to_path_buf(),
                    source,
                })?;
            if text.contains('\0') {
                return Err(KinovaError::MjcfMalformed {
                    origin,
                    why: "file contains a NUL byte".into(),
                });
            }
            MjModel::from_xml(path)
        }
    }
    .map_err(|e| KinovaError::MjcfMalformed {
        origin: origin.clone(),
        why: format!("{e}"),
    })?;
    let ids = resolve(&model, &origin)?;
    Ok((model, ids))
}

fn id(model: &MjModel, origin: &str, kind: MjtObjBase, name: &str) -> Result<usize, KinovaError> {
    model
        .name_to_id(kind, name)
        .ok_or_else(|| KinovaError::MjcfMissing {
            origin: origin.to_string(),
            kind: match kind {
                MjtObjBase::mjOBJ_BODY => "body",
                MjtObjBase::mjOBJ_JOINT => "joint",
                MjtObjBase::mjOBJ_SITE => "site",
                MjtObjBase::mjOBJ_GEOM => "geom",
                MjtObjBase::mjOBJ_SENSOR => "sensor",
                MjtObjBase::mjOBJ_ACTUATOR => "actuator",
                _ => "element",
            },
            name: name.to_string(),
        })
}

fn resolve(model: &MjModel, origin: &str) -> Result<SceneIds, KinovaError> {
    use mujoco_rs::mujoco_c::_mjtObjBase::*;
    let qposadr = model.jnt_qposadr();
    let dofadr = model.jnt_dofadr();
    let mut arm_qpos = [0; 6];
    let mut arm_dof = [0; 6];
    for (i, name) in ARM_JOINTS.iter().enumerate() {
        let j = id(model, origin, mjOBJ_JOINT, name)?;
        arm_qpos[i] = qposadr[j] as usize;
        arm_dof[i] = dofadr[j] as usize;
    }
    let pitch = id(model, origin, mjOBJ_JOINT, "fork_pitch")?;
    let roll = id(model, origin, mjOBJ_JOINT, "fork_roll")?;
    let fork_qpos = [qposadr[pitch] as usize, qposadr[roll] as usize];
    let fork_dof = [dofadr[pitch] as usize, dofadr[roll] as usize];
    let fork_actuator = [
        id(model, origin, mjOBJ_ACTUATOR, "act_fork_pitch")?,
        id(model, origin, mjOBJ_ACTUATOR, "act_fork_roll")?,
    ];
    let mut tine_sites = [0; N_TINES];
    for (i, s) in tine_sites.iter_mut().enumerate() {
        *s = id(model, origin, mjOBJ_SITE, &format!("tine_tip_{i}"))?;
    }
    let sensor = id(model, origin, mjOBJ_SENSOR, "wrist_force")?;
    let mut food = [FoodIds {
        body: 0,
        geom: 0,
        qpos: 0,
        dof: 0,
    }; 3];
    for kind in FoodKind::SCENE {
        let want = match kind {
            FoodKind::Banana => MjtGeomBase::mjGEOM_CYLINDER,
            FoodKind::Carrot => MjtGeomBase::mjGEOM_CAPSULE,
            _ => MjtGeomBase::mjGEOM_BOX,
        };
        food[kind.slot()] = free_body(model, origin, &kind.body_name(), &kind.geom_name(), want)?;
    }
    // The leaf is optional: a custom scene without one cannot stage the
    // `lettuce` setting, and says so when asked to.
    let lettuce = match model.name_to_id(mjOBJ_BODY, LETTUCE_BODY) {
        Some(_) => Some(free_body(
            model,
            origin,
            LETTUCE_BODY,
            LETTUCE_GEOM,
            MjtGeomBase::mjGEOM_BOX,
        )?),
        None => None,
    };
    Ok(SceneIds {
        arm_qpos,
        arm_dof,
        fork_qpos,
        fork_joint: [pitch, roll],
        fork_dof,
        fork_actuator,
        fork_body: id(model, origin, mjOBJ_BODY, "forkroll")?,
        wrist_site: id(model, origin, mjOBJ_SITE, "wrist_ft")?,
        tip_site: id(model, origin, mjOBJ_SITE, "fork_tip")?,
        tine_sites,
        wrist_force_adr: model.sensor_adr()[sensor] as usize,
        food,
        lettuce,
        plate_body: id(model, origin, mjOBJ_BODY, "plate")?,
    })
}

/// Resolves a free body `body` with geom `geom` of type `want` (joint `{body}_free`).
fn free_body(
    model: &MjModel,
    origin: &str,
    body: &str,
    geom: &str,
    want: MjtGeomBase,
) -> Result<FoodIds, KinovaError> {
    use mujoco_rs::mujoco_c::_mjtObjBase::*;
    let body_id = id(model, origin, mjOBJ_BODY, body)?;
    let geom_id = id(model, origin, mjOBJ_GEOM, geom)?;
    let joint = id(model, origin, mjOBJ_JOINT, &format!("{body}_free"))?;
    if model.jnt_type()[joint] != MjtJoint::mjJNT_FREE {
        return Err(KinovaError::MjcfInvalid {
            origin: origin.into(),
            what: format!("joint `{body}_free` must be a free joint"),
        });
    }
    if model.geom_type()[geom_id] != want {
        return Err(KinovaError::MjcfInvalid {
            origin: origin.into(),
            what: format!("geom `{geom}` must be of type {want:?}"),
        });
    }
    Ok(FoodIds {
        body: body_id,
        geom: geom_id,
        qpos: model.jnt_qposadr()[joint] as usize,
        dof: model.jnt_dofadr()[joint] as usize,
    })
}

/// Stops MuJoCo's default log handler from appending its warnings to
/// `MUJOCO_LOG.TXT` in the working directory (it did so for every unstable
/// trial a test provoked). Warnings still go to stderr, and the simulator
/// reads the data warnings it acts on (`mjWARN_BADQACC`) from `mjData`
/// and turns them into [`KinovaError::Diverged`].
fn keep_logs_out_of_cwd() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        use mujoco_rs::wrappers::mj_logging::{log_config, set_log_config};
        // SAFETY: every simulator, and so every MuJoCo call of this crate,
        // starts with `load`, which passes through this `Once`: a thread
        // that races here blocks until the configuration is written.
        unsafe { set_log_config(log_config().with_logto_file(false)) };
    });
}
