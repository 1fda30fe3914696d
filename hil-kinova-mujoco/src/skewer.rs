//! The tine–food interaction model: how a fork tine indents, punctures,
//! cuts into, grips and tears out of a food item.
//!
//! MuJoCo's rigid contacts cannot be pierced, so tines do not collide with
//! food (collision groups in the MJCF); instead every physics step this
//! model turns the relative pose of each tine and each item into equal and
//! opposite forces on the fork and the item (`xfrc_applied`). Per tine:
//!
//! 1. **Free** → **Indenting** when its tip enters an item at less than the
//!    item's dig-in angle from the surface normal (45° for soft flesh, 30°
//!    for a carrot's hard skin; a tip meeting the surface more obliquely
//!    skids past it: no force, it stays free). The surface
//!    pushes back with `k·d` along the tine (`d` = travel past the entry
//!    point) and holds the tip laterally by friction (at most half the
//!    normal force, so a tilted tine can shove an item across the plate).
//! 2. **Indenting** → **Pierced** once `k·d` exceeds the item's puncture
//!    force. The fork's force threshold decides whether that happens: four
//!    tines on a hard carrot need four times one tine's force.
//! 3. **Pierced**: the item is tied to the tine by a stiff spring split into
//!    an axial and a lateral part. Axially it slips (stick–slip friction)
//!    when the load exceeds the cutting resistance (advancing) or the grip
//!    (pulling off: grip per embedded metre plus friction times the lateral
//!    bearing load — a tilted tine carries the item partly on its side,
//!    which is why tilted-angled actions hold soft slices). Laterally the
//!    flesh bears at most its tear strength (per embedded metre); beyond it
//!    the tine cuts a slot sideways, and a slot longer than the item's cut
//!    limit tears the tine out.
//!    A tine whose anchor slides past its tip has lost the item.
//!
//! Item-side forces act at the item's centre of mass: the items are light
//! and their rotational inertia tiny, and explicit torques from stiff
//! springs would destabilise them; tine-side forces act at the tines.
//!
//! Spring constants are limited by the item's mass and the reference time
//! step [`REF_DT`] so the explicit coupling stays stable (`k·dt²/m` small);
//! physical puncture forces are kept, only the indentation depth at which
//! they are reached grows. The constants are fixed physical values (set
//! once from `REF_DT`), so a caller may step the model with a longer `dt`
//! where no piercing happens (the hold): `k·dt²/m` then grows by
//! `(dt/REF_DT)²` and stays stable up to [`MAX_DT`].

use nalgebra::{Matrix3, Vector3};

use crate::food::FoodProps;
use crate::model::N_TINES;

/// Tine length from tip to root (m), from the fork mesh (fact sheet §2).
pub const TINE_LENGTH: f64 = 0.030;
/// The step (s) the coupling constants are expressed against: the
/// model's base timestep.
pub const REF_DT: f64 = 0.001;
/// The longest step (s) the explicit coupling tolerates: with four tines
/// pierced, `4·COUPLING_STIFFNESS·(dt/REF_DT)²` and
/// `4·COUPLING_DAMPING·dt/REF_DT` must stay inside the stability region of
/// semi-implicit Euler (`a + 2b < 4` for `a = k·dt²/m`, `b = c·dt/m`); at
/// 4 ms `a + 2b = 1.92 + 1.6`, and the margin shrinks fast beyond.
pub const MAX_DT: f64 = 0.004;
const EMBED_SAMPLES: usize = 20;

/// The state of one tine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TineState {
    /// Not touching any item.
    Free,
    /// Pressing on item `food`'s surface at `entry` (item frame).
    Indenting {
        /// Item index.
        food: usize,
        /// Where the tip entered, in the item frame.
        entry: Vector3<f64>,
    },
    /// Inside item `food`: the item point `anchor` (item frame) sits on the
    /// tine `s` metres behind its tip.
    Pierced {
        /// Item index.
        food: usize,
        /// Anchor in the item frame.
        anchor: Vector3<f64>,
        /// Axial position of the anchor behind the tip (m).
        s: f64,
        /// Anchor offset at the previous step (world), for damping.
        prev: Vector3<f64>,
        /// Length of the sideways slot cut so far (m).
        cut: f64,
        /// Direction of the channel the tine cut, in the item frame.
        channel: Vector3<f64>,
        /// Misalignment of channel and tine at the previous step, for damping.
        prev_tilt: Vector3<f64>,
    },
    /// Torn out of the item; stays free for the rest of the attempt.
    Torn,
}

/// Pose of one tine tip (world frame).
#[derive(Clone, Copy, Debug)]
pub struct TinePose {
    /// Tip position.
    pub tip: Vector3<f64>,
    /// Unit direction from root to tip.
    pub dir: Vector3<f64>,
}

/// What the model needs to know about one item this step.
#[derive(Clone, Copy, Debug)]
pub struct FoodView<'a> {
    /// Body frame origin (world).
    pub pos: Vector3<f64>,
    /// Body orientation (world).
    pub rot: Matrix3<f64>,
    /// Centre of mass (world).
    pub com: Vector3<f64>,
    /// Its properties; `None` for items off the plate.
    pub props: Option<&'a FoodProps>,
}

/// Force and torque (about the body's centre of mass) to apply to a body.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    /// Force (N).
    pub force: Vector3<f64>,
    /// Torque (N·m).
    pub torque: Vector3<f64>,
}

impl Wrench {
    fn add_at(&mut self, f: Vector3<f64>, point: Vector3<f64>, com: Vector3<f64>) {
        self.force += f;
        self.torque += (point - com).cross(&f);
    }
}

/// Counters over one attempt.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct SkewerStats {
    /// Most tines pierced into the target at once.
    pub max_pierced: usize,
    /// Tines that reached an item's surface.
    pub touched: usize,
    /// Tines torn out laterally.
    pub torn: usize,
    /// Tines the item slid off.
    pub slid_off: usize,
    /// Distance the target slid towards the tips, summed over its pierced
    /// tines (m): how far it crept along the fork.
    pub slip_m: f64,
}

/// The interaction state of the four tines.
#[derive(Clone, Debug)]
pub struct SkewerModel {
    tines: [TineState; N_TINES],
    touched: [bool; N_TINES],
    /// Counters.
    pub stats: SkewerStats,
    target: usize,
    /// Length of the current step (s).
    dt: f64,
}

impl SkewerModel {
    /// A fresh model for an attempt at item `target`.
    pub fn new(target: usize) -> Self {
        Self {
            tines: [TineState::Free; N_TINES],
            touched: [false; N_TINES],
            stats: SkewerStats::default(),
            target,
            dt: REF_DT,
        }
    }

    /// The tines' states.
    #[cfg(test)]
    pub fn tines(&self) -> &[TineState; N_TINES] {
        &self.tines
    }

    /// Some tine is pressing on a surface before puncture: the stiff
    /// indentation spring needs the short reference step.
    pub fn is_indenting(&self) -> bool {
        self.tines
            .iter()
            .any(|t| matches!(t, TineState::Indenting { .. }))
    }

    /// Number of tines currently pierced into item `food`.
    pub fn pierced_into(&self, food: usize) -> usize {
        self.tines
            .iter()
            .filter(|t| matches!(t, TineState::Pierced { food: f, .. } if *f == food))
            .count()
    }

    /// Advances the model one step of `dt` s (at most [`MAX_DT`]): returns
    /// the wrench on each item and the wrench on the fork body (centre of
    /// mass `fork_com`).
    pub fn step(
        &mut self,
        dt: f64,
        tines: &[TinePose; N_TINES],
        fork_com: Vector3<f64>,
        foods: &[FoodView<'_>],
        out_food: &mut [Wrench],
    ) -> Wrench {
        debug_assert!(dt > 0.0 && dt <= MAX_DT + 1e-12, "step {dt} s");
        self.dt = dt;
        let mut fork = Wrench::default();
        for w in out_food.iter_mut() {
            *w = Wrench::default();
        }
        for (i, tp) in tines.iter().enumerate() {
            let next = self.step_tine(i, tp, fork_com, foods, out_food, &mut fork);
            self.tines[i] = next;
        }
        // The plate is rigid, but MuJoCo's soft contacts let a gram-scale
        // item sink when pressed with tens of newtons. The item only passes
        // the press on to the plate, so its downward share is scaled to at
        // most PRESS_CAP (keeping the direction, hence the ratio of sideways
        // push to plate friction).
        for w in out_food.iter_mut() {
            if w.force.z < -PRESS_CAP {
                let k = PRESS_CAP / -w.force.z;
                w.force *= k;
                w.torque *= k;
            }
        }
        let n = self.pierced_into(self.target);
        self.stats.max_pierced = self.stats.max_pierced.max(n);
        fork
    }

    fn step_tine(
        &mut self,
        i: usize,
        tp: &TinePose,
        fork_com: Vector3<f64>,
        foods: &[FoodView<'_>],
        out_food: &mut [Wrench],
        fork: &mut Wrench,
    ) -> TineState {
        let u = tp.dir;
        match self.tines[i] {
            TineState::Torn => TineState::Torn,
            TineState::Free => {
                for (k, f) in foods.iter().enumerate() {
                    let Some(props) = f.props else { continue };
                    if (tp.tip - f.pos).norm() > props.shape.bounding_radius() {
                        continue;
                    }
                    let local = f.rot.transpose() * (tp.tip - f.pos);
                    if props.shape.contains(&local) {
                        if !self.touched[i] {
                            self.touched[i] = true;
                            if k == self.target {
                                self.stats.touched += 1;
                            }
                        }
                        // A tip meeting the surface obliquely (a carrot's
                        // flank) skids along it instead of digging in.
                        let n = f.rot * props.shape.surface_normal(&local);
                        if (-u).dot(&n) < props.dig_in_angle.cos() {
                            continue;
                        }
                        return TineState::Indenting {
                            food: k,
                            entry: local,
                        };
                    }
                }
                TineState::Free
            }
            TineState::Indenting { food, mut entry } => {
                let f = &foods[food];
                let Some(props) = f.props else {
                    return TineState::Free;
                };
                let entry_w = f.pos + f.rot * entry;
                let rel = tp.tip - entry_w;
                let d = rel.dot(&u);
                if d < -0.0005 {
                    return TineState::Free;
                }
                let k = props.indent_stiffness.min(stable_stiffness(props.mass));
                let normal = k * d.max(0.0);
                if normal >= props.puncture_force {
                    // Anchor the item point that now lies on the tine line,
                    // `d` behind the tip, so the coupling starts relaxed.
                    let s = d.max(0.0);
                    let on_line = tp.tip - s * u;
                    return TineState::Pierced {
                        food,
                        anchor: f.rot.transpose() * (on_line - f.pos),
                        s,
                        prev: Vector3::zeros(),
                        cut: 0.0,
                        channel: f.rot.transpose() * u,
                        prev_tilt: Vector3::zeros(),
                    };
                }
                // Lateral: the tip drags the surface point by friction.
                let lat = rel - d * u;
                let k_lat = coupling_stiffness(props.mass);
                let mut f_lat = k_lat * lat;
                let cap = 0.5 * normal;
                if f_lat.norm() > cap {
                    // The tip slides over the surface: move the entry point.
                    let excess = lat - lat * (cap / f_lat.norm().max(1e-12));
                    entry += f.rot.transpose() * excess;
                    f_lat *= cap / f_lat.norm().max(1e-12);
                }
                let on_food = normal * u + f_lat;
                out_food[food].add_at(on_food, f.com, f.com);
                fork.add_at(-on_food, tp.tip, fork_com);
                TineState::Indenting { food, entry }
            }
            TineState::Pierced {
                food,
                mut anchor,
                mut s,
                prev,
                mut cut,
                mut channel,
                prev_tilt,
            } => {
                let f = &foods[food];
                let Some(props) = f.props else {
                    return TineState::Free;
                };
                let pt = tp.tip - s * u;
                let mut delta = f.pos + f.rot * anchor - pt;
                let k = coupling_stiffness(props.mass);
                let c = coupling_damping(props.mass);
                let embedded = embedded_length(tp, f, props);
                // Lateral: the flesh bears at most `yield_lat`; beyond it the
                // tine cuts sideways (the anchor moves with it). A slot longer
                // than the item's cut limit means the tine has torn out.
                let da = delta.dot(&u);
                let dl = delta - da * u;
                let yield_lat = props.tear_per_m * embedded.max(0.004);
                if k * dl.norm() > yield_lat {
                    let excess = dl * (1.0 - yield_lat / (k * dl.norm()));
                    cut += excess.norm();
                    anchor -= f.rot.transpose() * excess;
                    delta -= excess;
                    if cut > props.cut_limit {
                        self.stats.torn += 1;
                        return TineState::Torn;
                    }
                }
                let dl = delta - da * u;
                let vel = if prev == Vector3::zeros() {
                    Vector3::zeros()
                } else {
                    (delta - prev) / self.dt
                };
                let f_lat = -k * dl - c * (vel - vel.dot(&u) * u);
                let mut f_ax = -k * da - c * vel.dot(&u);
                // da > 0: the item moves towards the tip (sliding off);
                // da < 0: the tine advances into the item. Grip uses the
                // elastic lateral load (bearing pressure), not damping.
                let cap = if da > 0.0 {
                    props.grip_per_m * embedded + props.friction * k * dl.norm()
                } else {
                    props.cut_resistance
                };
                let mut da_new = da;
                let s_before = s;
                if f_ax.abs() > cap {
                    da_new = -f_ax.signum() * cap / k;
                    if food == self.target && da > da_new {
                        self.stats.slip_m += da - da_new;
                    }
                    s -= da - da_new;
                    f_ax = f_ax.signum() * cap;
                }
                if s < 0.0 {
                    self.stats.slid_off += 1;
                    return TineState::Free;
                }
                // An advancing tine cuts its channel along its own current
                // direction: the newly cut share of the embedded length
                // follows the tine, so a tine that turns while it pushes
                // in (an item shoved across the plate) leaves no bent
                // channel to spring back when the item comes free.
                let advanced = s - s_before;
                if advanced > 0.0 && embedded > 1e-4 {
                    let w = (advanced / embedded).min(1.0);
                    let local_u = f.rot.transpose() * u;
                    channel = (channel * (1.0 - w) + local_u * w).normalize();
                }
                if s > TINE_LENGTH {
                    // The item reached the tine root: the fork body pushes it.
                    s = TINE_LENGTH;
                }
                let on_food = f_ax * u + f_lat;
                // The flesh is held where the tine passes through it, so
                // the force acts at the anchor: several tines together
                // resist the item turning, as a real fork does. (Applied at
                // the centre of mass instead, a skewered item keeps the
                // spin it had at lift-off for ever, its anchors sweep
                // sideways through the flesh and it creeps off.)
                out_food[food].add_at(on_food, f.com, f.com);
                fork.add_at(-on_food, pt, fork_com);
                // An embedded tine is a line through the flesh, not a point:
                // it resists the item turning off its axis like a spring
                // spread along the embedded length L (stiffness k·L²/12),
                // which stops a skewered item swinging about its tines.
                let tilt = (f.rot * channel).cross(&u);
                let l2 = embedded * embedded / 12.0;
                let tilt_rate = if prev_tilt == Vector3::zeros() {
                    Vector3::zeros()
                } else {
                    (tilt - prev_tilt) / self.dt
                };
                let bend = k * l2 * tilt + c * l2 * tilt_rate;
                out_food[food].torque += bend;
                fork.torque -= bend;
                TineState::Pierced {
                    food,
                    anchor,
                    s,
                    prev: dl + da_new * u,
                    cut,
                    channel,
                    prev_tilt: tilt,
                }
            }
        }
    }
}

/// Largest downward force passed to an item pressed against the plate (N).
const PRESS_CAP: f64 = 1.0;
/// Per-tine coupling stiffness of a pierced tine, in units of m/REF_DT².
const COUPLING_STIFFNESS: f64 = 0.03;
/// Per-tine coupling damping of a pierced tine, in units of m/REF_DT.
const COUPLING_DAMPING: f64 = 0.05;

/// Per-tine coupling stiffness (N/m) for an item of mass `m`.
fn coupling_stiffness(m: f64) -> f64 {
    COUPLING_STIFFNESS * m / (REF_DT * REF_DT)
}

/// Per-tine coupling damping (N·s/m) for an item of mass `m`.
fn coupling_damping(m: f64) -> f64 {
    COUPLING_DAMPING * m / REF_DT
}

/// The largest per-tine indentation stiffness the explicit coupling of an
/// item of mass `m` tolerates at [`REF_DT`] with four tines engaged.
fn stable_stiffness(m: f64) -> f64 {
    0.1 * m / (REF_DT * REF_DT)
}

/// Length of the tine (tip back to root) inside the item.
fn embedded_length(tp: &TinePose, f: &FoodView<'_>, props: &FoodProps) -> f64 {
    let step = TINE_LENGTH / EMBED_SAMPLES as f64;
    let rt = f.rot.transpose();
    (0..EMBED_SAMPLES)
        .filter(|&j| {
            let p = tp.tip - (j as f64 + 0.5) * step * tp.dir;
            props.shape.contains(&(rt * (p - f.pos)))
        })
        .count() as f64
        * step
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::food::{FoodKind, FoodModel};
    use rand::SeedableRng;

    fn item(kind: FoodKind) -> FoodProps {
        FoodModel::default_for(kind).sample(&mut rand_chacha::ChaCha8Rng::seed_from_u64(4))
    }

    /// An item with its frame at the world origin.
    fn at_origin(props: &FoodProps) -> FoodView<'_> {
        FoodView {
            pos: Vector3::zeros(),
            rot: Matrix3::identity(),
            com: Vector3::zeros(),
            props: Some(props),
        }
    }

    fn press(props: &FoodProps, depth: f64) -> (SkewerModel, Wrench) {
        let mut m = SkewerModel::new(0);
        let top = props.shape.half_extents()[2];
        let foods = [at_origin(props)];
        let mut out = [Wrench::default()];
        let mut fork = Wrench::default();
        // Lower the tines in 0.1 mm steps from just above the surface.
        let n = ((depth + 0.001) / 0.0001) as usize;
        for k in 0..=n {
            let z = top + 0.001 - k as f64 * 0.0001;
            let tines = [-0.0068, -0.0025, 0.0025, 0.0068].map(|y| TinePose {
                tip: Vector3::new(0.0, y, z),
                dir: -Vector3::z(),
            });
            fork = m.step(
                REF_DT,
                &tines,
                Vector3::new(0.0, 0.0, 0.1),
                &foods,
                &mut out,
            );
        }
        (m, fork)
    }

    #[test]
    fn a_tine_glances_off_a_rounded_flank_but_digs_into_the_crest() {
        let carrot = item(FoodKind::Carrot);
        let r = carrot.shape.half_extents()[1];
        let foods = [at_origin(&carrot)];
        let mut out = [Wrench::default()];
        // Straight down, just inside the surface: at the crest (y = 0) and on
        // the flank 0.85 r off the axis (about 58° from the normal).
        let mut state = |y: f64| {
            let z = (r * r - y * y).sqrt() - 0.0002;
            let mut m = SkewerModel::new(0);
            let t = TinePose {
                tip: Vector3::new(0.0, y, z),
                dir: -Vector3::z(),
            };
            m.step(
                REF_DT,
                &[t; N_TINES],
                Vector3::new(0.0, 0.0, 0.1),
                &foods,
                &mut out,
            );
            m.tines()[0]
        };
        assert!(matches!(state(0.0), TineState::Indenting { .. }));
        assert_eq!(state(0.85 * r), TineState::Free);
    }

    #[test]
    fn a_tip_skids_on_a_carrots_skin_at_an_angle_that_digs_into_melon() {
        // TA's tines meet a flat top about 38° off the normal: past the
        // carrot's 30° dig-in angle, within the melon's 45°.
        let lean = 38f64.to_radians();
        let dir = Vector3::new(lean.sin(), 0.0, -lean.cos());
        for (kind, digs) in [(FoodKind::Carrot, false), (FoodKind::Cantaloupe, true)] {
            let props = item(kind);
            let top = props.shape.half_extents()[2];
            let foods = [at_origin(&props)];
            let mut m = SkewerModel::new(0);
            let t = TinePose {
                tip: Vector3::new(0.0, 0.0, top - 0.0002),
                dir,
            };
            m.step(
                REF_DT,
                &[t; N_TINES],
                Vector3::new(0.0, 0.0, 0.1),
                &foods,
                &mut [Wrench::default()],
            );
            let dug = matches!(m.tines()[0], TineState::Indenting { .. });
            assert_eq!(dug, digs, "{kind:?}: {:?}", m.tines()[0]);
        }
    }

    #[test]
    fn a_soft_item_is_pierced_before_a_hard_one() {
        let banana = item(FoodKind::Banana);
        let carrot = item(FoodKind::Carrot);
        let (mb, _) = press(&banana, 0.004);
        assert!(mb.pierced_into(0) >= 2, "{:?}", mb.tines());
        // 1 mm into a carrot is below its puncture depth: still indenting,
        // and the fork feels the surface push back.
        let (mc, fork) = press(&carrot, 0.0008);
        assert_eq!(mc.pierced_into(0), 0, "{:?}", mc.tines());
        assert!(fork.force.z > 1.0, "fork force {:?}", fork.force);
    }
}
