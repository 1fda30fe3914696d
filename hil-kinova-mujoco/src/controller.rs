//! The six skewering actions and the arm's differential inverse kinematics.
//!
//! An action is a fork pitch β (handle relative to vertical, G21: VS 0, TV
//! −0.5, TA +0.4 rad), a roll of the tine row relative to the food's
//! perceived major axis (0 or 90°) and a force threshold (VS 25 N, TV 20 N,
//! TA 10 N). The arm holds the fork base (the handle) pointing straight
//! down, turned about the vertical so that at γ = 0 the tine row lies along
//! the perceived major axis; the fork's pitch motor sets β and its roll
//! motor sets γ to the action's roll (0 or 90°), turning the tines about the
//! pitched handle as the paper's fork does. The tines curve 0.26 rad towards
//! the fork's +z, so at γ = 0 VS tines lean 0.26 rad, TV tines −0.24 rad
//! (nearly vertical) and TA tines 0.66 rad from vertical; at γ = 90° the
//! curve and the pitch lean them in different planes.
//!
//! Inverse kinematics runs on a private copy of the model from commanded
//! joint positions only (what a robot's trajectory generator knows); the
//! physical arm follows through its joint servos.

use std::sync::OnceLock;

use mujoco_rs::prelude::*;
use nalgebra::{Matrix3, Matrix6, Rotation3, Vector3, Vector6};

use crate::error::KinovaError;
use crate::model::SceneIds;

/// One skewering action.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Action {
    /// Label (VS0 ... TA90), as in `hil_envs::feeding::action_space`.
    pub name: &'static str,
    /// The pitch family the label names.
    pub family: PitchFamily,
    /// Fork pitch β (rad).
    pub pitch: f64,
    /// Tine-row angle to the major axis (rad).
    pub roll: f64,
    /// Force threshold ending penetration (N).
    pub max_force: f64,
    /// Angle of the move-in from vertical (rad), leaning the way the tines
    /// lean ([`PitchFamily::approach_tilt`]).
    pub approach_tilt: f64,
}

/// TA's move-in: vertical component twice the horizontal (atan(1/2), rad).
const TA_APPROACH_TILT: f64 = 0.463_647_609_000_806_1;

/// The fork's mechanics per pitch family (VS, TV, TA): the pitch β, the
/// force threshold ending penetration and the move-in tilt. The roll is the
/// other half of an action's name (`0` or `90` degrees to the major axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum PitchFamily {
    /// Vertical skewer: tines straight down, vertical approach.
    Vs,
    /// Tilted vertical: tines leaning back, vertical approach.
    Tv,
    /// Tilted angled: tines leaning forward, approach along the lean.
    Ta,
}

impl PitchFamily {
    /// The family named by an action label's prefix (`VS`, `TV`, `TA`).
    fn from_prefix(prefix: &str) -> Option<Self> {
        match prefix {
            "VS" => Some(Self::Vs),
            "TV" => Some(Self::Tv),
            "TA" => Some(Self::Ta),
            _ => None,
        }
    }

    /// Fork pitch β (rad).
    pub fn pitch(self) -> f64 {
        match self {
            Self::Vs => 0.0,
            Self::Tv => -0.5,
            Self::Ta => 0.4,
        }
    }

    /// Force threshold ending penetration (N).
    pub fn max_force(self) -> f64 {
        match self {
            Self::Vs => 25.0,
            Self::Tv => 20.0,
            Self::Ta => 10.0,
        }
    }

    /// Angle of the move-in from vertical (rad): 0 for VS and TV, whose
    /// approach is vertical, and atan(1/2) for TA (ADA's Gen3 skewering,
    /// fact sheet §3).
    pub fn approach_tilt(self) -> f64 {
        match self {
            Self::Vs | Self::Tv => 0.0,
            Self::Ta => TA_APPROACH_TILT,
        }
    }
}

impl Action {
    /// The mechanics of the feeding task's action labelled `name`: a pitch
    /// family (`VS`, `TV`, `TA`) followed by the tine row's angle to the
    /// food's major axis in degrees (`0` or `90`), e.g. `TV90`.
    ///
    /// ```
    /// let a = hil_kinova_mujoco::Action::from_label("TV90").unwrap();
    /// assert_eq!(a.roll, std::f64::consts::FRAC_PI_2);
    /// assert!(hil_kinova_mujoco::Action::from_label("XX0").is_err());
    /// ```
    pub fn from_label(name: &'static str) -> Result<Self, KinovaError> {
        let unknown = || KinovaError::UnknownAction {
            name: name.to_string(),
        };
        let (prefix, degrees) = name.split_at_checked(2).ok_or_else(unknown)?;
        let family = PitchFamily::from_prefix(prefix).ok_or_else(unknown)?;
        let roll = match degrees {
            "0" => 0.0,
            "90" => std::f64::consts::FRAC_PI_2,
            _ => return Err(unknown()),
        };
        Ok(Self {
            name,
            family,
            pitch: family.pitch(),
            roll,
            max_force: family.max_force(),
            approach_tilt: family.approach_tilt(),
        })
    }
}

/// The six actions in the feeding task's arm order (VS0 VS90 TV0 TV90 TA0
/// TA90), built from `hil_envs::feeding::action_space` so the simulator's
/// arm `i` is the task's arm `i` by construction.
///
/// ```
/// let names: Vec<_> = hil_kinova_mujoco::actions().iter().map(|a| a.name).collect();
/// assert_eq!(names, hil_envs::feeding::FeedingTask::bundled().actions());
/// ```
pub fn actions() -> &'static [Action] {
    static ACTIONS: OnceLock<Vec<Action>> = OnceLock::new();
    ACTIONS.get_or_init(|| {
        hil_envs::feeding::FeedingTask::bundled()
            .actions()
            .iter()
            .map(|name| match Action::from_label(name) {
                Ok(action) => action,
                // The bundled table is compiled in; a test below reads it.
                Err(e) => panic!("hil-envs' bundled feeding actions: {e}"),
            })
            .collect()
    })
}

/// What turns the tine row by an action's roll.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollBy {
    /// The fork's own roll joint γ, about the pitched handle, while the arm
    /// holds the handle (the paper's 2-DoF fork). At β ≠ 0 this also
    /// changes the tines' lean and tilts the tine row.
    #[default]
    ForkGamma,
    /// The arm turns the whole fork about the vertical and the fork is
    /// rigid: γ stays 0 and both fork joints are held by stiff, strong
    /// servos (the 2-DoF fork's own motors yield under a 20 N push on
    /// pitched tines). This is the tool of the data set the published rates
    /// come from (a fork fixed to the arm, rolled by the arm), the default
    /// of `hil kinova calibrate`; the tines' lean is the same at 0° and 90°.
    ArmYaw,
}

impl RollBy {
    /// The label used in configs and flags.
    pub fn name(self) -> &'static str {
        match self {
            RollBy::ForkGamma => "fork_gamma",
            RollBy::ArmYaw => "arm_yaw",
        }
    }

    /// Parses a label (`fork_gamma`, `arm_yaw`).
    pub fn parse(s: &str) -> Option<Self> {
        [RollBy::ForkGamma, RollBy::ArmYaw]
            .into_iter()
            .find(|r| r.name() == s)
    }
}

/// Curvature of the tines towards the fork's +z (rad), from the MJCF.
pub const TINE_CURVE: f64 = 0.262;

/// Desired orientation of the fork base for a tine row at yaw `psi`: x (the
/// handle at β = 0) straight down, y (across the tine row) horizontal.
pub fn fork_base_orientation(psi: f64) -> Matrix3<f64> {
    let x = Vector3::new(0.0, 0.0, -1.0);
    let y = Vector3::new(psi.cos(), psi.sin(), 0.0);
    let z = x.cross(&y);
    Matrix3::from_columns(&[x, y, z])
}

/// Orientation of the fork's roll link (tines and tine row) for a fork base
/// at `base`, pitch `beta` and roll `gamma`, as the MJCF's joints turn it:
/// β about the base's −y, then γ about the pitched handle (x).
pub fn fork_roll_orientation(base: &Matrix3<f64>, beta: f64, gamma: f64) -> Matrix3<f64> {
    let pitch = Rotation3::from_axis_angle(&-Vector3::y_axis(), beta);
    let roll = Rotation3::from_axis_angle(&Vector3::x_axis(), gamma);
    base * (pitch * roll).matrix()
}

/// Direction of the tines (root to tip) for a fork base at `base`, pitch
/// `beta` and roll `gamma`: the fork's x axis bent by the tines' curve
/// towards its +z.
pub fn tine_direction(base: &Matrix3<f64>, beta: f64, gamma: f64) -> Vector3<f64> {
    fork_roll_orientation(base, beta, gamma) * Vector3::new(TINE_CURVE.cos(), 0.0, TINE_CURVE.sin())
}

/// Direction of the move-in for `action` with tines along `u`: straight
/// down tilted by the action's [`Action::approach_tilt`] towards the side
/// the tines lean (their horizontal part).
pub fn approach_direction(action: &Action, u: &Vector3<f64>) -> Vector3<f64> {
    let lean = Vector3::new(u.x, u.y, 0.0);
    let n = lean.norm();
    if action.approach_tilt == 0.0 || n < 1e-9 {
        return -Vector3::z();
    }
    let (s, c) = action.approach_tilt.sin_cos();
    -c * Vector3::z() + s * lean / n
}

/// Kinematics of the arm on a private copy of the model.
#[derive(Debug)]
pub struct Kinematics {
    data: MjData<Box<MjModel>>,
    ids: SceneIds,
    jacp: Vec<f64>,
    jacr: Vec<f64>,
}

/// A pose target for the tip: position of the tine-tip centre and
/// orientation of the fork base.
#[derive(Clone, Copy, Debug)]
pub struct PoseTarget {
    /// Tine-tip centre (world).
    pub tip: Vector3<f64>,
    /// Fork base orientation (world).
    pub base: Matrix3<f64>,
}

impl Kinematics {
    /// Kinematics on a copy of `model`.
    pub fn new(model: Box<MjModel>, ids: SceneIds) -> Self {
        let nv = model.ffi().nv as usize;
        Self {
            data: MjData::new(model),
            ids,
            jacp: vec![0.0; 3 * nv],
            jacr: vec![0.0; 3 * nv],
        }
    }

    /// Forward kinematics: sets the arm and fork joints and returns the
    /// tine-tip centre position and the fork base orientation.
    pub fn forward(&mut self, q: &[f64; 6], fork: [f64; 2]) -> (Vector3<f64>, Matrix3<f64>) {
        {
            let qpos = self.data.qpos_mut();
            for i in 0..6 {
                qpos[self.ids.arm_qpos[i]] = q[i];
            }
            qpos[self.ids.fork_qpos[0]] = fork[0];
            qpos[self.ids.fork_qpos[1]] = fork[1];
        }
        self.data.kinematics();
        self.data.com_pos();
        (
            self.site_pos(self.ids.tip_site),
            self.site_rot(self.ids.wrist_site),
        )
    }

    /// Position of a body's frame after the last [`forward`](Self::forward).
    pub fn body_pos(&self, body: usize) -> Vector3<f64> {
        Vector3::from(self.data.xpos()[body])
    }

    /// Position of a site after the last [`forward`](Self::forward).
    pub fn site_pos(&self, site: usize) -> Vector3<f64> {
        Vector3::from(self.data.site_xpos()[site])
    }

    /// Orientation of a site after the last [`forward`](Self::forward).
    pub fn site_rot(&self, site: usize) -> Matrix3<f64> {
        Matrix3::from_row_slice(&self.data.site_xmat()[site])
    }

    /// One damped-least-squares step from `q` towards `target`; returns the
    /// new joints and the remaining error norm before the step.
    pub fn dls_step(
        &mut self,
        q: &[f64; 6],
        fork: [f64; 2],
        target: &PoseTarget,
        max_step: f64,
    ) -> ([f64; 6], f64) {
        let (p, r) = self.forward(q, fork);
        let ep = target.tip - p;
        let mut er = Vector3::zeros();
        for c in 0..3 {
            er += 0.5 * r.column(c).cross(&target.base.column(c));
        }
        let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        let err = ep.norm() + er.norm();
        self.jacobians();
        let nv = self.jacp.len() / 3;
        let mut j = Matrix6::zeros();
        for (col, &dof) in self.ids.arm_dof.iter().enumerate() {
            for row in 0..3 {
                j[(row, col)] = self.jacp[row * nv + dof];
                j[(row + 3, col)] = self.jacr[row * nv + dof];
            }
        }
        let lambda2 = 1e-4;
        let jjt = j * j.transpose() + Matrix6::identity() * lambda2;
        let dq = match jjt.try_inverse() {
            Some(inv) => j.transpose() * inv * e,
            None => Vector6::zeros(),
        };
        let scale = (max_step / dq.amax().max(1e-12)).min(1.0);
        let mut out = *q;
        for i in 0..6 {
            out[i] += scale * dq[i];
        }
        clamp_limits(&mut out);
        (out, err)
    }

    fn jacobians(&mut self) {
        // mj_jacSite writes 3×nv row-major blocks for the tip (position) and
        // the wrist (rotation is the same for every point on the chain).
        let (jp, _) = self.data.jac_site(true, false, self.ids.tip_site);
        let (_, jr) = self.data.jac_site(false, true, self.ids.wrist_site);
        self.jacp.copy_from_slice(&jp);
        self.jacr.copy_from_slice(&jr);
    }

    /// Solves for joints reaching `target` from `seed`.
    pub fn solve(
        &mut self,
        seed: &[f64; 6],
        fork: [f64; 2],
        target: &PoseTarget,
        what: &str,
    ) -> Result<[f64; 6], KinovaError> {
        let mut q = *seed;
        let mut err = f64::INFINITY;
        for _ in 0..300 {
            let (next, e) = self.dls_step(&q, fork, target, 0.2);
            err = e;
            if e < 1e-5 {
                return Ok(q);
            }
            q = next;
        }
        if err < 1e-3 {
            Ok(q)
        } else {
            Err(KinovaError::IkFailed {
                what: what.into(),
                residual: err,
            })
        }
    }
}

/// Joint limits of joints 2, 3 and 5 (fact sheet, K2).
fn clamp_limits(q: &mut [f64; 6]) {
    q[1] = q[1].clamp(-2.24, 2.24);
    q[2] = q[2].clamp(-2.57, 2.57);
    q[4] = q[4].clamp(-2.09, 2.09);
}

/// Minimum-jerk interpolation weight for `t` in [0, 1].
pub fn min_jerk(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_action_label_decodes_in_arm_order() {
        let task = hil_envs::feeding::FeedingTask::bundled();
        let names: Vec<&str> = actions().iter().map(|a| a.name).collect();
        assert_eq!(names, task.actions());
        for bad in ["", "VS", "VS45", "XY0", "vs0"] {
            assert!(matches!(
                Action::from_label(bad),
                Err(KinovaError::UnknownAction { .. })
            ));
        }
    }

    #[test]
    fn vs_and_tv_move_in_vertically_and_ta_two_down_for_one_across() {
        for action in actions() {
            let u = tine_direction(&fork_base_orientation(0.3), action.pitch, action.roll);
            let dir = approach_direction(action, &u);
            assert!((dir.norm() - 1.0).abs() < 1e-12);
            let across = dir.x.hypot(dir.y);
            if action.family == PitchFamily::Ta {
                // Vertical component twice the horizontal (fact sheet §3),
                // towards the side the tines lean.
                assert!(
                    (-dir.z - 2.0 * across).abs() < 1e-9,
                    "{}: {dir}",
                    action.name
                );
                assert!(dir.x * u.x + dir.y * u.y > 0.0, "{}", action.name);
            } else {
                assert!(across < 1e-12 && dir.z < 0.0, "{}: {dir}", action.name);
            }
        }
    }

    #[test]
    fn gamma_turns_the_tines_about_the_pitched_handle() {
        let base = fork_base_orientation(0.0);
        // At β = 0 the handle is vertical: rolling by γ is the same as the
        // arm turning the fork about the vertical (by −γ: γ turns the row's
        // y towards the fork's z, which points the other way round).
        let by_gamma = tine_direction(&base, 0.0, FRAC_PI_2);
        let by_arm = tine_direction(&fork_base_orientation(-FRAC_PI_2), 0.0, 0.0);
        assert!((by_gamma - by_arm).norm() < 1e-12, "{by_gamma} vs {by_arm}");
        // Pitched (TV, β = −0.5), γ = 0 leaves the tines nearly vertical;
        // γ = 90° turns the tines' curve out of the pitch plane, so they
        // lean by the pitch and the curve together.
        let lean = |u: Vector3<f64>| u.dot(&-Vector3::z()).acos();
        let tv0 = tine_direction(&base, -0.5, 0.0);
        let tv90 = tine_direction(&base, -0.5, FRAC_PI_2);
        assert!((lean(tv0) - (0.5 - TINE_CURVE)).abs() < 1e-9);
        let expected = (0.5f64.cos() * TINE_CURVE.cos()).acos();
        assert!((lean(tv90) - expected).abs() < 1e-9, "{}", lean(tv90));
        // Both keep unit length.
        assert!((tv90.norm() - 1.0).abs() < 1e-12);
    }

    use std::f64::consts::FRAC_PI_2;
}
