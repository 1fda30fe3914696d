//! One simulated attempt: place the items, let them settle, then run an
//! action through the controller and the skewering model and judge it.

use std::time::{Duration, Instant};

use hil_paper::food_data::HOLD_SECONDS;
use mujoco_rs::prelude::*;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::Serialize;

use crate::controller::{
    Action, Kinematics, PoseTarget, RollBy, approach_direction, fork_base_orientation, min_jerk,
    tine_direction,
};
use crate::error::KinovaError;
use crate::food::{FoodKind, FoodProps, Shape};
use crate::model::{self, MjcfSource, N_TINES, SceneIds};
use crate::skewer::{FoodView, MAX_DT, REF_DT, SkewerModel, SkewerStats, TinePose, Wrench};

/// Height of the plate's top surface above its body frame (m).
const PLATE_TOP: f64 = 0.006;
/// Approach starts this far back from the entry point along the move-in (m).
const PRE_OFFSET: f64 = 0.04;
/// Deepest travel past the perceived top surface, along the move-in (m):
/// ADA's Gen3 value.
const DEPTH_LIMIT: f64 = 0.035;
/// Lift height (m), as ADA's two 0.025 m moves plus margin.
const LIFT: f64 = 0.06;
/// Duration of the lift (s): a mean speed of 10 cm/s.
const LIFT_TIME: f64 = 0.6;
/// Smallest rotational inertia given to an item (kg·m²).
const MIN_INERTIA: f64 = 3e-6;
/// Height of the lettuce leaf's midrib above its blade (m, MJCF).
const LEAF_RIB: f64 = 0.0035;
/// Item height above the plate that counts as lifted (m).
const LIFTED: f64 = 0.03;

/// Checks a hold duration (s): finite and within 0–60 s. The one rule for
/// [`Simulator::set_hold`] and a config's `hold_s`.
pub(crate) fn check_hold(seconds: f64) -> Result<(), KinovaError> {
    if seconds.is_finite() && (0.0..=60.0).contains(&seconds) {
        Ok(())
    } else {
        Err(KinovaError::InvalidHold { seconds })
    }
}
/// Step (s) of the phases in which no tine cuts: settling, the move to the
/// pre-pose and the hold. Penetration and lift, where tines indent, pierce,
/// cut and tear, run at the model's own step (at most [`REF_DT`]); a long
/// step is also cut back to that whenever a tine is indenting.
pub const FREE_DT: f64 = MAX_DT;
/// Fewest tines that must touch the item for an attempt to count
/// (Feng et al. 2019: attempts where fewer touched are discarded).
pub const MIN_TINES_TOUCHED: usize = 2;
/// Simulated time the items settle after staging (s).
const SETTLE_TIME: f64 = 0.15;

/// One item on the plate: kind, properties and pose relative to the plate centre.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// The item.
    pub props: FoodProps,
    /// Position on the plate (m, plate frame).
    pub xy: [f64; 2],
    /// Yaw of the major axis (rad).
    pub yaw: f64,
}

/// Where the lettuce leaf lies (the `lettuce` setting) and which item rests on it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LeafPlacement {
    /// Centre of the leaf on the plate (m, plate frame); the item is centred on it.
    pub xy: [f64; 2],
    /// Yaw of the leaf's long side (rad).
    pub yaw: f64,
    /// The item resting on the leaf.
    pub under: FoodKind,
}

/// An item's true pose after settling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TruePose {
    /// Kind.
    pub kind: FoodKind,
    /// Centre (world).
    pub centre: [f64; 3],
    /// Yaw of the major axis (rad).
    pub yaw: f64,
    /// Half extents (major, minor, height) (m).
    pub half_extents: [f64; 3],
    /// It rests on the lettuce leaf.
    pub on_leaf: bool,
}

impl TruePose {
    /// The target as a perfect perception would report it: the true
    /// centre, yaw and half height.
    pub fn exact_target(&self) -> PerceivedTarget {
        PerceivedTarget {
            centre: self.centre,
            yaw: self.yaw,
            half_height: self.half_extents[2],
        }
    }
}

/// What the controller is told about the target: a noisy perceived pose.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PerceivedTarget {
    /// Centre (world, m).
    pub centre: [f64; 3],
    /// Yaw of the major axis (rad).
    pub yaw: f64,
    /// Half height (m).
    pub half_height: f64,
}

/// Why penetration ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The wrist force reached the action's threshold.
    Force,
    /// The tines reached the depth limit.
    Depth,
}

/// Everything measured during one attempt.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AttemptReport {
    /// The action executed.
    pub action: &'static str,
    /// The food attempted.
    pub food: FoodKind,
    /// The item stayed on the fork through lift and hold.
    pub success: bool,
    /// Fork pitch reached before the approach (rad).
    pub reached_pitch: f64,
    /// Fork roll joint γ reached before the approach (rad).
    pub reached_gamma: f64,
    /// Angle of the tine row to the perceived major axis before the approach (rad, in [0, π/2]).
    pub reached_roll: f64,
    /// Angle of the fork base's y axis (the handle's roll, set by the arm)
    /// to the perceived major axis before the approach (rad, in [0, π/2]):
    /// 0 for every action when γ makes the roll.
    pub handle_roll: f64,
    /// Why penetration ended.
    pub stop: StopReason,
    /// Largest axial wrist force during penetration (N).
    pub peak_force: f64,
    /// Tine counters over the whole attempt.
    pub tines: SkewerStats,
    /// The same counters when penetration ended: with
    /// [`tines_after_lift`](Self::tines_after_lift) they tell in which
    /// phase tines tore out or the item slid off (penetration, lift or
    /// hold), which the attempt log (`hil kinova calibrate --attempts`)
    /// needs to tell a rim that tears the tines out during the lift from
    /// an item that creeps off in the hold.
    pub tines_after_penetration: SkewerStats,
    /// The counters when the lift ended and the hold began.
    pub tines_after_lift: SkewerStats,
    /// How far the item moved across the plate (horizontally) from the
    /// pre-pose to the end of penetration (m): an angled push that slides
    /// it away shows here.
    pub push_shift: f64,
    /// How far the item tipped (angle of its body z axis from vertical)
    /// by the end of penetration (rad).
    pub push_tilt: f64,
    /// The attempt counts under the published rule: at least
    /// [`MIN_TINES_TOUCHED`] tines touched the item (Feng et al. 2019
    /// discard attempts where fewer did; they are neither successes nor
    /// failures).
    pub counted: bool,
    /// Height of the item above the plate at the end (m).
    pub final_height: f64,
    /// Height of the item above the plate when the hold began (m).
    pub lifted_height: f64,
    /// How far the item slid along the tines during the hold, summed over
    /// its pierced tines (m).
    pub hold_slip: f64,
    /// Simulated time (s).
    pub sim_time: f64,
    /// Physics steps taken.
    pub steps: u64,
}

/// Wall-clock accounting: total time in attempts and time inside `mj_step`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// Time inside `mj_step`.
    pub in_step: Duration,
    /// Total time spent in `stage` and `execute`.
    pub total: Duration,
    /// CPU time this thread spent in `stage` and `execute`: the busy time
    /// of one core, unaffected by other programs sharing the machine.
    pub cpu: Duration,
    /// Attempts executed.
    pub attempts: u64,
    /// Physics steps taken (staging and attempts).
    pub steps: u64,
}

/// Called with a phase name and the physics state at each keyframe.
pub type KeyframeHook<'a> = &'a mut dyn FnMut(&str, &mut MjData<Box<MjModel>>);

/// The MuJoCo simulation of the feeding scene.
#[derive(Debug)]
pub struct Simulator {
    data: MjData<Box<MjModel>>,
    ids: SceneIds,
    kin: Kinematics,
    home: [f64; 6],
    plate_centre: Vector3<f64>,
    props: [Option<FoodProps>; 3],
    leaf_under: Option<FoodKind>,
    target: Option<FoodKind>,
    dt: f64,
    free_dt: f64,
    hold: f64,
    roll_by: RollBy,
    /// The fork motors (pitch, roll) as loaded: the 2-DoF fork's own servos.
    fork_servo: [ForkServo; 2],
    /// Contact bits of every geom as loaded, to restore parked bodies.
    contacts0: Vec<(i32, i32)>,
    timing: Timing,
}

impl Simulator {
    /// Loads the built-in scene.
    pub fn new() -> Result<Self, KinovaError> {
        Self::from_source(MjcfSource::Builtin)
    }

    /// Loads the scene from `source`.
    pub fn from_source(source: MjcfSource<'_>) -> Result<Self, KinovaError> {
        let origin = source.origin();
        let (model, ids) = model::load(source)?;
        let kin_model = Box::new(model.clone());
        let model = Box::new(model);
        let dt = model.opt().timestep;
        if !(dt > 0.0 && dt <= REF_DT + 1e-12) {
            return Err(KinovaError::MjcfInvalid {
                origin,
                what: format!(
                    "option timestep is {dt} s; the skewering model needs at most {REF_DT} s"
                ),
            });
        }
        let mut kin = Kinematics::new(kin_model, ids.clone());
        let data = MjData::new(model);
        let plate_centre = Vector3::from(data.xpos()[ids.plate_body]);
        let plate_centre = if plate_centre == Vector3::zeros() {
            // xpos is filled by the first forward pass; the body pos is static.
            let mut d = MjData::new(Box::new(data.model().clone()));
            d.forward();
            Vector3::from(d.xpos()[ids.plate_body])
        } else {
            plate_centre
        };
        let home_target = PoseTarget {
            tip: plate_centre + Vector3::new(0.0, 0.0, 0.15),
            base: fork_base_orientation(0.0),
        };
        let seed = [0.0, 0.35, -2.0, 0.0, -0.9, std::f64::consts::FRAC_PI_2];
        let home = kin.solve(&seed, [0.0, 0.0], &home_target, "home pose above the plate")?;
        let m = data.model();
        let contacts0 = m
            .geom_contype()
            .iter()
            .zip(m.geom_conaffinity())
            .map(|(&t, &a)| (t, a))
            .collect();
        let fork_servo = [0, 1].map(|i| ForkServo::of(data.model(), &ids, i));
        Ok(Self {
            fork_servo,
            data,
            ids,
            kin,
            home,
            plate_centre,
            props: [None, None, None],
            leaf_under: None,
            target: None,
            dt,
            free_dt: FREE_DT,
            hold: HOLD_SECONDS,
            roll_by: RollBy::default(),
            contacts0,
            timing: Timing::default(),
        })
    }

    /// Sets how long an item must stay on the lifted fork (s); the default
    /// is the published [`HOLD_SECONDS`].
    pub fn set_hold(&mut self, seconds: f64) -> Result<(), KinovaError> {
        check_hold(seconds)?;
        self.hold = seconds;
        Ok(())
    }

    /// Sets the step of the phases in which no tine cuts (settling, the
    /// move to the pre-pose, the hold); default [`FREE_DT`]. The model's own
    /// step gives the slowest, most exact run.
    pub fn set_free_step(&mut self, seconds: f64) -> Result<(), KinovaError> {
        if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_DT) {
            return Err(KinovaError::InvalidFreeStep {
                seconds,
                max: MAX_DT,
            });
        }
        self.free_dt = seconds;
        Ok(())
    }

    /// The step of the phases in which no tine cuts (s).
    pub fn free_step(&self) -> f64 {
        self.free_dt
    }

    /// How long an item must stay on the lifted fork (s).
    pub fn hold(&self) -> f64 {
        self.hold
    }

    /// Sets what turns the tine row by an action's roll (default: the
    /// fork's γ joint).
    pub fn set_roll_by(&mut self, roll_by: RollBy) {
        self.roll_by = roll_by;
        let servos = match roll_by {
            RollBy::ForkGamma => self.fork_servo,
            RollBy::ArmYaw => [ForkServo::RIGID; 2],
        };
        for (i, servo) in servos.iter().enumerate() {
            // SAFETY: only servo parameters of existing elements change
            // (see ForkServo::apply); no count, address or array size.
            servo.apply(unsafe { self.data.model_mut() }, &self.ids, i);
        }
    }

    /// What turns the tine row by an action's roll.
    pub fn roll_by(&self) -> RollBy {
        self.roll_by
    }

    /// Arm joint angles of the home pose.
    pub fn home(&self) -> [f64; 6] {
        self.home
    }

    /// Centre of the plate's top surface (world).
    pub fn plate_top_centre(&self) -> Vector3<f64> {
        self.plate_centre + Vector3::new(0.0, 0.0, PLATE_TOP)
    }

    /// The physics state.
    pub fn data(&self) -> &MjData<Box<MjModel>> {
        &self.data
    }

    /// The arm kinematics.
    pub fn kinematics(&mut self) -> &mut Kinematics {
        &mut self.kin
    }

    /// Model indices.
    pub fn ids(&self) -> &SceneIds {
        &self.ids
    }

    /// Wall-clock accounting so far.
    pub fn timing(&self) -> Timing {
        self.timing
    }

    /// Places `items` on the plate (at most one per kind; the others are put
    /// aside) and the lettuce leaf under one of them if `leaf` is given (else
    /// aside), lets them settle, and returns their true poses.
    pub fn stage(
        &mut self,
        items: &[Placement],
        leaf: Option<LeafPlacement>,
        target: FoodKind,
    ) -> Result<Vec<TruePose>, KinovaError> {
        let start = Instant::now();
        let cpu0 = thread_cpu_time();
        let mut props: [Option<FoodProps>; 3] = [None, None, None];
        for p in items {
            if props[p.props.kind.slot()].is_some() {
                return Err(KinovaError::MjcfInvalid {
                    origin: "scene".into(),
                    what: format!(
                        "the scene has one body per calibrated kind; {} takes the {} body twice",
                        p.props.kind.name(),
                        p.props.kind.base().name()
                    ),
                });
            }
            props[p.props.kind.slot()] = Some(p.props.clone());
        }
        let leaf_ids = match (leaf, self.ids.lettuce) {
            (Some(l), None) => {
                return Err(KinovaError::MjcfMissing {
                    origin: "scene".into(),
                    kind: "body",
                    name: format!(
                        "{} (needed to put the {} on lettuce)",
                        model::LETTUCE_BODY,
                        l.under.name()
                    ),
                });
            }
            (_, ids) => ids,
        };
        if let Some(l) = leaf
            && props[l.under.slot()].is_none()
        {
            return Err(KinovaError::MjcfInvalid {
                origin: "scene".into(),
                what: format!("the {} on the lettuce is not on the plate", l.under.name()),
            });
        }
        if props[target.slot()].is_none() {
            return Err(KinovaError::MjcfInvalid {
                origin: "scene".into(),
                what: format!("target {} is not on the plate", target.name()),
            });
        }
        for kind in FoodKind::SCENE {
            if let Some(p) = &props[kind.slot()] {
                self.apply_props(kind, p);
            }
        }
        // Items not on the plate, and the leaf when nothing lies on it, are
        // parked: no contacts and weightless, so they cost the solver
        // nothing (resting on the floor they made half of all contacts).
        for kind in FoodKind::SCENE {
            let body = self.ids.food[kind.slot()].body;
            self.set_parked(body, props[kind.slot()].is_none());
        }
        if let Some(l) = leaf_ids {
            self.set_parked(l.body, leaf.is_none());
        }
        // Recompute the model constants that depend on masses and inertias
        // (constraint scaling uses them).
        // SAFETY: model and data belong together; mj_setConst only writes
        // constant fields of the model and scratch fields of the data.
        unsafe {
            let d: *mut mujoco_rs::mujoco_c::mjData = self.data.ffi_mut();
            let m: *mut mujoco_rs::mujoco_c::mjModel = self.data.model_mut().ffi_mut();
            mujoco_rs::mujoco_c::mj_setConst(m, d);
        }
        self.data.reset();
        {
            let home = self.home;
            let ids = self.ids.clone();
            let leaf_thickness =
                leaf_ids.map_or(0.0, |l| 2.0 * self.data.model().geom_size()[l.geom][2]);
            let qpos = self.data.qpos_mut();
            for i in 0..6 {
                qpos[ids.arm_qpos[i]] = home[i];
            }
            for kind in FoodKind::SCENE {
                let f = ids.food[kind.slot()];
                let (pos, yaw) = match items.iter().find(|p| p.props.kind.slot() == kind.slot()) {
                    Some(p) => {
                        let h = p.props.shape.half_extents()[2];
                        let (xy, base) = match leaf {
                            Some(l) if l.under.slot() == kind.slot() => {
                                (l.xy, leaf_thickness + LEAF_RIB)
                            }
                            _ => (p.xy, 0.0),
                        };
                        (
                            self.plate_centre
                                + Vector3::new(xy[0], xy[1], PLATE_TOP + base + h + 0.0005),
                            p.yaw,
                        )
                    }
                    None => (
                        Vector3::new(-0.6, -0.3 + 0.3 * kind.slot() as f64, 0.05),
                        0.0,
                    ),
                };
                set_free_pose(&mut qpos[f.qpos..f.qpos + 7], pos, yaw);
            }
            if let Some(l) = leaf_ids {
                let (pos, yaw) = match leaf {
                    Some(p) => (
                        self.plate_centre
                            + Vector3::new(
                                p.xy[0],
                                p.xy[1],
                                PLATE_TOP + 0.5 * leaf_thickness + 0.0002,
                            ),
                        p.yaw,
                    ),
                    None => (Vector3::new(-0.6, 0.6, 0.05), 0.0),
                };
                set_free_pose(&mut qpos[l.qpos..l.qpos + 7], pos, yaw);
            }
        }
        self.props = props;
        self.leaf_under = leaf.map(|l| l.under);
        self.target = Some(target);
        self.set_ctrl(&self.home.clone(), [0.0, 0.0]);
        self.data.forward();
        let mut idle = SkewerModel::new(target.slot());
        self.advance(&mut idle, SETTLE_TIME, self.free_dt)?;
        self.timing.total += start.elapsed();
        self.timing.cpu += thread_cpu_time().saturating_sub(cpu0);
        Ok(self.true_poses())
    }

    /// Parks `body` (no contacts, gravity compensated, allowed to sleep)
    /// or restores it (never asleep: the skewering model pushes it with
    /// applied forces, which must act at once).
    fn set_parked(&mut self, body: usize, parked: bool) {
        use mujoco_rs::mujoco_c::mjtSleepPolicy::{mjSLEEP_ALLOWED, mjSLEEP_NEVER};
        // SAFETY: only contact bits and gravity compensation of existing
        // elements change; no count, address or array size.
        let m = unsafe { self.data.model_mut() };
        let adr = m.body_geomadr()[body];
        let num = m.body_geomnum()[body];
        for g in adr.max(0) as usize..(adr.max(0) + num.max(0)) as usize {
            let (t, a) = if parked { (0, 0) } else { self.contacts0[g] };
            m.geom_contype_mut()[g] = t;
            m.geom_conaffinity_mut()[g] = a;
        }
        m.body_gravcomp_mut()[body] = if parked { 1.0 } else { 0.0 };
        let tree = m.body_treeid()[body];
        if tree >= 0 {
            m.tree_sleep_policy_mut()[tree as usize] = if parked {
                mjSLEEP_ALLOWED
            } else {
                mjSLEEP_NEVER
            };
        }
    }

    fn apply_props(&mut self, kind: FoodKind, p: &FoodProps) {
        let f = self.ids.food[kind.slot()];
        let (size, aabb) = match p.shape {
            Shape::Disc {
                radius,
                half_height,
            } => ([radius, half_height, 0.0], [radius, radius, half_height]),
            Shape::Capsule {
                radius,
                half_length,
            } => (
                [radius, half_length, 0.0],
                [radius, radius, half_length + radius],
            ),
            Shape::Cuboid { half } => (half, half),
        };
        // Items weigh grams and their rotational inertia is tiny; a floor
        // keeps their contacts with the plate numerically stable at 1 ms.
        let body_frame = p.shape.inertia(p.mass).map(|i| i.max(MIN_INERTIA));
        // MuJoCo stores inertia in the body's inertial frame (body_iquat),
        // which the compiler aligned with the geom; it may also place the
        // geom in that frame, so the frame stays and the diagonal is
        // expressed in it (the shapes are symmetric: a permutation).
        let iq = self.data.model().body_iquat()[f.body];
        let r =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(iq[0], iq[1], iq[2], iq[3]))
                .to_rotation_matrix();
        let inertial = r.matrix().transpose()
            * Matrix3::from_diagonal(&Vector3::from(body_frame))
            * r.matrix();
        let inertia = [inertial[(0, 0)], inertial[(1, 1)], inertial[(2, 2)]];
        // SAFETY: only sizes, masses and inertias of existing elements change;
        // no count, address or array size of the model is touched.
        let m = unsafe { self.data.model_mut() };
        m.geom_size_mut()[f.geom] = size;
        // The plate's own friction is set below every food's (MJCF), so
        // MuJoCo's rule (the larger of the two) makes the item's govern.
        m.geom_friction_mut()[f.geom][0] = p.plate_friction;
        m.geom_aabb_mut()[f.geom] = [0.0, 0.0, 0.0, aabb[0], aabb[1], aabb[2]];
        m.geom_rbound_mut()[f.geom] = p.shape.bounding_radius();
        m.body_mass_mut()[f.body] = p.mass;
        m.body_inertia_mut()[f.body] = inertia;
    }

    /// True poses of the items on the plate.
    pub fn true_poses(&self) -> Vec<TruePose> {
        FoodKind::SCENE
            .into_iter()
            .filter_map(|kind| {
                let p = self.props[kind.slot()].as_ref()?;
                let b = self.ids.food[kind.slot()].body;
                let r = Matrix3::from_row_slice(&self.data.xmat()[b]);
                Some(TruePose {
                    kind: p.kind,
                    centre: self.data.xpos()[b],
                    yaw: r[(1, 0)].atan2(r[(0, 0)]),
                    half_extents: p.shape.half_extents(),
                    on_leaf: self.leaf_under.map(FoodKind::slot) == Some(kind.slot()),
                })
            })
            .collect()
    }

    fn set_ctrl(&mut self, q: &[f64; 6], fork: [f64; 2]) {
        let ctrl = self.data.ctrl_mut();
        ctrl[..6].copy_from_slice(q);
        ctrl[6] = fork[0];
        ctrl[7] = fork[1];
    }

    fn wrist_force(&self) -> Vector3<f64> {
        let a = self.ids.wrist_force_adr;
        let s = self.data.sensordata();
        let f = Vector3::new(s[a], s[a + 1], s[a + 2]);
        Matrix3::from_row_slice(&self.data.site_xmat()[self.ids.wrist_site]) * f
    }

    /// Steps for `seconds` of simulated time with steps of at most `dt`.
    fn advance(
        &mut self,
        skewer: &mut SkewerModel,
        seconds: f64,
        dt: f64,
    ) -> Result<(), KinovaError> {
        let mut t = 0.0;
        while t < seconds - 1e-9 {
            t += self.physics_step(skewer, dt.min(seconds - t))?;
        }
        Ok(())
    }

    /// One physics step of `dt` (cut back to the model's own step while a
    /// tine is indenting: the indentation spring is only stable there);
    /// returns the step taken.
    fn physics_step(&mut self, skewer: &mut SkewerModel, dt: f64) -> Result<f64, KinovaError> {
        let dt = if skewer.is_indenting() {
            dt.min(self.dt)
        } else {
            dt.min(MAX_DT)
        };
        if self.data.model().opt().timestep != dt {
            // SAFETY: only the step length changes; no count, address or
            // array size of the model.
            unsafe { self.data.model_mut().opt_mut().timestep = dt };
        }
        // mj_step1 computes the poses of this step; the skewering forces
        // must come from them. (After a plain mj_step, xpos still holds the
        // poses from before the integration: forces computed from them act
        // one step late, and a delayed stiff spring rings - the coupling
        // was unstable beyond 1 ms for that reason alone.)
        let t0 = Instant::now();
        self.data.step1();
        let mut in_step = t0.elapsed();
        let d = &self.data;
        let sx = d.site_xpos();
        let sm = d.site_xmat();
        let tines: [TinePose; N_TINES] = std::array::from_fn(|i| {
            let s = self.ids.tine_sites[i];
            TinePose {
                tip: Vector3::from(sx[s]),
                dir: Vector3::new(sm[s][0], sm[s][3], sm[s][6]),
            }
        });
        let foods: [FoodView<'_>; 3] = std::array::from_fn(|k| {
            let b = self.ids.food[k].body;
            FoodView {
                pos: Vector3::from(d.xpos()[b]),
                rot: Matrix3::from_row_slice(&d.xmat()[b]),
                com: Vector3::from(d.xipos()[b]),
                props: self.props[k].as_ref(),
            }
        });
        let fork_com = Vector3::from(d.xipos()[self.ids.fork_body]);
        let mut on_food = [Wrench::default(); 3];
        let on_fork = skewer.step(dt, &tines, fork_com, &foods, &mut on_food);
        let xfrc = self.data.xfrc_applied_mut();
        for k in 0..3 {
            let w = &on_food[k];
            xfrc[self.ids.food[k].body] = wrench6(w);
        }
        xfrc[self.ids.fork_body] = wrench6(&on_fork);
        let t0 = Instant::now();
        self.data.step2();
        in_step += t0.elapsed();
        self.timing.in_step += in_step;
        self.timing.steps += 1;
        Ok(dt)
    }

    /// Executes `action` on the staged target, as perceived.
    pub fn execute(
        &mut self,
        action: &Action,
        perceived: &PerceivedTarget,
        mut keyframe: Option<KeyframeHook<'_>>,
    ) -> Result<AttemptReport, KinovaError> {
        let start = Instant::now();
        let cpu0 = thread_cpu_time();
        let Some(target) = self.target.take() else {
            return Err(KinovaError::MjcfInvalid {
                origin: "scene".into(),
                what: "execute called before stage".into(),
            });
        };
        let t_begin = self.data.time();
        let steps_before = self.timing.steps;
        let beta = action.pitch;
        // With the fork's γ the arm holds the handle with the tine row (at
        // γ = 0) along the major axis and γ turns it by the action's roll;
        // with the arm, the whole fork turns about the vertical.
        let (gamma, handle_yaw) = match self.roll_by {
            RollBy::ForkGamma => (action.roll, perceived.yaw),
            RollBy::ArmYaw => (0.0, perceived.yaw + action.roll),
        };
        let fork = [beta, gamma];
        let base = fork_base_orientation(wrap_half_pi(handle_yaw));
        let u = tine_direction(&base, beta, gamma);
        let dir = approach_direction(action, &u);
        let c = Vector3::from(perceived.centre);
        let entry = c + Vector3::new(0.0, 0.0, perceived.half_height);
        let pre = entry - PRE_OFFSET * dir;
        let q_pre = self
            .kin
            .solve(&self.home, fork, &PoseTarget { tip: pre, base }, "pre-pose")?;
        let mut skewer = SkewerModel::new(target.slot());
        if let Some(k) = keyframe.as_mut() {
            k("start", &mut self.data);
        }

        // Pre-pose: joint-space minimum-jerk move; the fork motors turn to β.
        let home = self.home;
        let t_move = 0.6;
        let mut t = 0.0;
        while t < t_move - 1e-9 {
            let w = min_jerk(t / t_move);
            let q: [f64; 6] = std::array::from_fn(|j| home[j] + w * (q_pre[j] - home[j]));
            self.set_ctrl(&q, fork);
            t += self.physics_step(&mut skewer, self.free_dt.min(t_move - t))?;
        }
        self.set_ctrl(&q_pre, fork);
        self.advance(&mut skewer, 0.15, self.free_dt)?;
        self.check_finite("pre-pose")?;
        let reached_pitch = self.data.qpos()[self.ids.fork_qpos[0]];
        let reached_gamma = self.data.qpos()[self.ids.fork_qpos[1]];
        let reached_roll = self.row_angle_to(perceived.yaw);
        let handle_roll = self.handle_angle_to(perceived.yaw);
        let tare = self.wrist_force();
        let b = self.ids.food[target.slot()].body;
        let item_at_pre = Vector3::from(self.data.xpos()[b]);
        if let Some(k) = keyframe.as_mut() {
            k("pre_pose", &mut self.data);
        }

        // Approach and penetrate along the action's move-in direction
        // (vertical for VS and TV, tilted for TA); the force threshold
        // reads the wrist force along the tines.
        let mut q = q_pre;
        let mut travel = 0.0;
        let approach = PRE_OFFSET - 0.005;
        let mut peak: f64 = 0.0;
        let stop;
        let mut step_i = 0u64;
        loop {
            let v = if travel < approach { 0.10 } else { 0.03 };
            travel += v * self.dt;
            if step_i % 2 == 0 {
                let target = PoseTarget {
                    tip: pre + travel * dir,
                    base,
                };
                q = self.kin.dls_step(&q, fork, &target, 0.05).0;
            }
            step_i += 1;
            self.set_ctrl(&q, fork);
            self.physics_step(&mut skewer, self.dt)?;
            let f_ax = (self.wrist_force() - tare).dot(&u).abs();
            if travel > approach {
                peak = peak.max(f_ax);
                if f_ax >= action.max_force {
                    stop = StopReason::Force;
                    break;
                }
            }
            if travel >= PRE_OFFSET + DEPTH_LIMIT {
                stop = StopReason::Depth;
                break;
            }
        }
        self.check_finite("penetration")?;
        let moved = Vector3::from(self.data.xpos()[b]) - item_at_pre;
        let push_shift = moved.x.hypot(moved.y);
        let tines_after_penetration = skewer.stats;
        // xmat row-major: element 8 is the z component of the body z axis.
        let push_tilt = self.data.xmat()[b][8].clamp(-1.0, 1.0).acos();
        if let Some(k) = keyframe.as_mut() {
            k("skewer", &mut self.data);
        }

        // Lift straight up on a minimum-jerk profile (a real arm's
        // trajectory generator ramps up and down; an instant 10 cm/s start
        // jerks the item off the tines), then hold.
        let tip0 = pre + travel * dir;
        let n_lift = (LIFT_TIME / self.dt).round() as usize;
        for i in 1..=n_lift {
            if i % 2 == 0 || i == n_lift {
                let lift = LIFT * min_jerk(i as f64 / n_lift as f64);
                let target = PoseTarget {
                    tip: tip0 + Vector3::new(0.0, 0.0, lift),
                    base,
                };
                q = self.kin.dls_step(&q, fork, &target, 0.05).0;
            }
            self.set_ctrl(&q, fork);
            self.physics_step(&mut skewer, self.dt)?;
        }
        if let Some(k) = keyframe.as_mut() {
            k("lift", &mut self.data);
        }
        let lifted_height = self.data.xpos()[b][2] - self.plate_top_centre().z;
        let tines_after_lift = skewer.stats;
        let slip_at_lift = tines_after_lift.slip_m;
        self.advance(&mut skewer, self.hold, self.free_dt)?;
        self.check_finite("hold")?;
        if let Some(k) = keyframe.as_mut() {
            k("hold", &mut self.data);
        }
        let height = self.data.xpos()[b][2] - self.plate_top_centre().z;
        let success = height > LIFTED && skewer.pierced_into(target.slot()) >= 1;
        self.timing.total += start.elapsed();
        self.timing.cpu += thread_cpu_time().saturating_sub(cpu0);
        self.timing.attempts += 1;
        Ok(AttemptReport {
            action: action.name,
            food: target,
            success,
            reached_pitch,
            reached_gamma,
            reached_roll,
            handle_roll,
            stop,
            peak_force: peak,
            tines: skewer.stats,
            tines_after_penetration,
            tines_after_lift,
            push_shift,
            push_tilt,
            counted: skewer.stats.touched >= MIN_TINES_TOUCHED,
            final_height: height,
            lifted_height,
            hold_slip: skewer.stats.slip_m - slip_at_lift,
            sim_time: self.data.time() - t_begin,
            steps: self.timing.steps - steps_before,
        })
    }

    /// Angle in [0, π/2] between the tine row (the roll link's y axis,
    /// horizontal part) and the major axis at `yaw`.
    fn row_angle_to(&self, yaw: f64) -> f64 {
        let r = Matrix3::from_row_slice(&self.data.xmat()[self.ids.fork_body]);
        horizontal_angle(&r.column(1).into_owned(), yaw)
    }

    /// Angle in [0, π/2] between the fork base's y axis (horizontal part)
    /// and the major axis at `yaw`.
    fn handle_angle_to(&self, yaw: f64) -> f64 {
        let r = Matrix3::from_row_slice(&self.data.site_xmat()[self.ids.wrist_site]);
        horizontal_angle(&r.column(1).into_owned(), yaw)
    }

    fn check_finite(&self, phase: &'static str) -> Result<(), KinovaError> {
        if self.data.qpos().iter().all(|v| v.is_finite())
            && self.data.warning()[MjtWarning::mjWARN_BADQACC as usize].number == 0
        {
            Ok(())
        } else {
            Err(KinovaError::Diverged {
                time: self.data.time(),
                phase,
            })
        }
    }
}

/// The fork's two position servos (pitch β, roll γ): gains, torque limit
/// and the reflected inertia of their gears.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ForkServo {
    /// Stiffness (N·m/rad).
    kp: f64,
    /// Damping (N·m·s/rad).
    kv: f64,
    /// Torque range of the actuator (N·m).
    torque: [f64; 2],
    /// Torque range the joint accepts from its actuators (N·m).
    joint_torque: [f64; 2],
    /// Armature (kg·m²).
    armature: f64,
}

impl ForkServo {
    /// A fork without joints, as in the published data set (Feng et al.
    /// 2019: a fork with a force/torque sensor fixed to the arm): both
    /// joints held by servos stiff and strong enough that a 25 N push on
    /// the tines (about 3.5 N·m about the pitch axis) turns them by less
    /// than a degree. The armature keeps the stiff servo stable at the 4 ms
    /// step (`sqrt(kp / armature)·dt` ≈ 0.6).
    const RIGID: ForkServo = ForkServo {
        kp: 300.0,
        kv: 3.0,
        torque: [-40.0, 40.0],
        joint_torque: [-40.0, 40.0],
        armature: 0.01,
    };

    /// Fork servo `i` (0 pitch, 1 roll) of `model`.
    fn of(model: &MjModel, ids: &SceneIds, i: usize) -> Self {
        let a = ids.fork_actuator[i];
        ForkServo {
            kp: model.actuator_gainprm()[a][0],
            kv: -model.actuator_biasprm()[a][2],
            torque: model.actuator_forcerange()[a],
            joint_torque: model.jnt_actfrcrange()[ids.fork_joint[i]],
            armature: model.dof_armature()[ids.fork_dof[i]],
        }
    }

    /// Makes fork servo `i` (0 pitch, 1 roll) of `model` this one.
    fn apply(&self, model: &mut MjModel, ids: &SceneIds, i: usize) {
        let a = ids.fork_actuator[i];
        // SAFETY: only parameter values of existing actuators, joints and
        // dofs change; no count, address or array size of the model.
        unsafe {
            model.actuator_gainprm_mut()[a][0] = self.kp;
            model.actuator_biasprm_mut()[a][1] = -self.kp;
            model.actuator_biasprm_mut()[a][2] = -self.kv;
            model.actuator_forcerange_mut()[a] = self.torque;
            model.jnt_actfrcrange_mut()[ids.fork_joint[i]] = self.joint_torque;
            model.dof_armature_mut()[ids.fork_dof[i]] = self.armature;
        }
    }
}

/// Angle in [0, π/2] between the horizontal part of `axis` and the line at `yaw`.
fn horizontal_angle(axis: &Vector3<f64>, yaw: f64) -> f64 {
    wrap_half_pi(axis.y.atan2(axis.x) - yaw).abs()
}

/// CPU time consumed by the calling thread so far.
pub fn thread_cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0;
    if ok {
        Duration::new(ts.tv_sec.max(0) as u64, ts.tv_nsec.max(0) as u32)
    } else {
        Duration::ZERO
    }
}

/// Writes a free joint's position and a yaw-only orientation.
fn set_free_pose(qpos: &mut [f64], pos: Vector3<f64>, yaw: f64) {
    let q = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw);
    qpos[..3].copy_from_slice(pos.as_slice());
    qpos[3] = q.w;
    qpos[4] = q.i;
    qpos[5] = q.j;
    qpos[6] = q.k;
}

fn wrench6(w: &Wrench) -> [f64; 6] {
    [
        w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z,
    ]
}

/// Wraps an angle to (−π/2, π/2]: a tine row is the same line turned by π.
pub fn wrap_half_pi(a: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut x = a.rem_euclid(PI);
    if x > FRAC_PI_2 {
        x -= PI;
    }
    x
}
