//! Simulated perception: what a camera over the plate would report about
//! the target, with noise, and its embedding into a context vector.
//!
//! Raw features (`RAW_DIM` = 16), all from noisy observations:
//! 0–2 mean colour (RGB), 3–5 extents along the major and minor axes and
//! height (cm), 6 elongation (major/minor), 7 fill ratio of the footprint's
//! bounding box (shape: disc ≈ 0.79, capsule ≈ 0.8–0.9, cube 1), 8 distance
//! of the item's edge to the plate rim (cm), 9 distance to the nearest other
//! item (cm, 15 when alone), 10 number of other items within 6 cm,
//! 11–12 cos 2φ and sin 2φ of the major axis yaw φ, 13 radial offset from
//! the plate centre (cm), 14 height of the item's underside above the plate
//! (cm, from depth: what it rests on), 15 share of green in a ring around
//! the item (a lettuce leaf under it).
//!
//! The embedding standardises them and maps them to the configured
//! dimension `d`: for `d ≤ 16` a fixed Gaussian random projection; for
//! larger `d` the 16 standardised features followed by `d − 16` random
//! Fourier features `√2·cos(w·z + b)` (w ~ N(0, 1/4), b ~ U[0, 2π)). The
//! projection is drawn from `embedding_seed`, so contexts are comparable
//! across runs.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::food::Shape;
use crate::sim::{PerceivedTarget, TruePose};

/// Number of raw perception features.
pub const RAW_DIM: usize = 16;
/// Radius of the plate's inner rim (m).
pub const RIM_RADIUS: f64 = 0.100;

/// Perception noise levels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerceptionNoise {
    /// Standard deviation of the perceived centre (m, per axis).
    pub position_m: f64,
    /// Standard deviation of the perceived major-axis yaw (rad).
    pub yaw_rad: f64,
    /// Relative standard deviation of perceived sizes.
    pub size_rel: f64,
    /// Standard deviation of perceived colour channels.
    pub colour: f64,
}

impl Default for PerceptionNoise {
    fn default() -> Self {
        Self {
            position_m: 0.002,
            yaw_rad: 0.12,
            size_rel: 0.08,
            colour: 0.03,
        }
    }
}

/// The controller's view of the target plus the raw features.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Observation {
    /// Perceived target pose.
    pub target: PerceivedTarget,
    /// Raw features (see the module docs).
    pub raw: [f64; RAW_DIM],
}

/// Perceives `target` among `poses` (the centre of the plate's top
/// surface at `plate`).
pub fn perceive(
    poses: &[TruePose],
    target: usize,
    shape: &Shape,
    colour: [f64; 3],
    plate: [f64; 3],
    noise: &PerceptionNoise,
    rng: &mut impl Rng,
) -> Observation {
    let n = Normal::new(0.0, 1.0).expect("unit normal");
    let mut g = || -> f64 { n.sample(rng) };
    let t = &poses[target];
    let centre = [
        t.centre[0] + noise.position_m * g(),
        t.centre[1] + noise.position_m * g(),
        t.centre[2],
    ];
    let yaw = t.yaw + noise.yaw_rad * g();
    let h: Vec<f64> = t
        .half_extents
        .iter()
        .map(|v| v * (1.0 + noise.size_rel * g()).max(0.3))
        .collect();
    let col: Vec<f64> = colour
        .iter()
        .map(|c| (c + noise.colour * g()).clamp(0.0, 1.0))
        .collect();
    let fill = match shape {
        Shape::Disc { .. } => PI / 4.0,
        Shape::Capsule {
            radius,
            half_length,
        } => {
            let l = 2.0 * (half_length + radius);
            (2.0 * radius * 2.0 * half_length + PI * radius * radius) / (l * 2.0 * radius)
        }
        Shape::Cuboid { .. } => 1.0,
    } * (1.0 + 0.03 * g());
    let dx = centre[0] - plate[0];
    let dy = centre[1] - plate[1];
    let radial = (dx * dx + dy * dy).sqrt();
    let rim = RIM_RADIUS - radial - h[0];
    let mut nearest = 0.15_f64;
    let mut near = 0.0;
    for (i, p) in poses.iter().enumerate() {
        if i == target {
            continue;
        }
        let d = ((p.centre[0] - centre[0]).powi(2) + (p.centre[1] - centre[1]).powi(2)).sqrt()
            - p.half_extents[0]
            - h[0];
        nearest = nearest.min(d.max(0.0));
        if d < 0.06 {
            near += 1.0;
        }
    }
    let raw = [
        col[0],
        col[1],
        col[2],
        200.0 * h[0],
        200.0 * h[1],
        200.0 * h[2],
        h[0] / h[1].max(1e-4),
        fill,
        100.0 * rim,
        100.0 * nearest,
        near,
        (2.0 * yaw).cos(),
        (2.0 * yaw).sin(),
        100.0 * radial,
        100.0 * (t.centre[2] - t.half_extents[2] - plate[2] + 0.001 * g()),
        (if t.on_leaf { 0.6 } else { 0.0 } + 0.05 * g()).clamp(0.0, 1.0),
    ];
    Observation {
        target: PerceivedTarget {
            centre,
            yaw,
            half_height: h[2],
        },
        raw,
    }
}

/// Centring and scale of each raw feature (typical value, typical spread).
const STANDARD: [(f64, f64); RAW_DIM] = [
    (0.95, 0.05),
    (0.7, 0.2),
    (0.4, 0.25),
    (2.5, 1.0),
    (2.0, 0.7),
    (1.3, 0.4),
    (1.5, 0.8),
    (0.85, 0.1),
    (3.0, 2.0),
    (5.0, 4.0),
    (0.7, 0.7),
    (0.0, 0.7),
    (0.0, 0.7),
    (4.0, 2.0),
    (0.1, 0.15),
    (0.2, 0.3),
];

/// A fixed map from raw features to contexts of dimension `dim`.
#[derive(Clone, Debug)]
pub struct Embedding {
    dim: usize,
    /// Rows of the projection (d ≤ RAW_DIM) or of the Fourier weights.
    weights: Vec<[f64; RAW_DIM]>,
    phases: Vec<f64>,
}

impl Embedding {
    /// A map into `dim` dimensions drawn from `seed`.
    pub fn new(dim: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6b69_6e6f_7661);
        let n = Normal::new(0.0, 1.0).expect("unit normal");
        let rows = if dim <= RAW_DIM { dim } else { dim - RAW_DIM };
        let scale = if dim <= RAW_DIM {
            1.0 / (RAW_DIM as f64).sqrt()
        } else {
            0.5
        };
        let weights = (0..rows)
            .map(|_| std::array::from_fn(|_| scale * n.sample(&mut rng)))
            .collect();
        let phases = (0..rows).map(|_| rng.random_range(0.0..2.0 * PI)).collect();
        Self {
            dim,
            weights,
            phases,
        }
    }

    /// Output dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Embeds raw features.
    pub fn embed(&self, raw: &[f64; RAW_DIM]) -> Vec<f64> {
        let z: [f64; RAW_DIM] = std::array::from_fn(|i| (raw[i] - STANDARD[i].0) / STANDARD[i].1);
        let dot = |w: &[f64; RAW_DIM]| w.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>();
        if self.dim <= RAW_DIM {
            self.weights.iter().map(dot).collect()
        } else {
            let mut out = z.to_vec();
            out.extend(
                self.weights
                    .iter()
                    .zip(&self.phases)
                    .map(|(w, b)| 2f64.sqrt() * (dot(w) + b).cos()),
            );
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedding_has_the_requested_dimension_and_is_fixed_by_its_seed() {
        let raw = [0.5; RAW_DIM];
        for d in [1, 5, 16, 17, 64] {
            let e = Embedding::new(d, 3).embed(&raw);
            assert_eq!(e.len(), d);
            assert!(e.iter().all(|v| v.is_finite()));
            assert_eq!(e, Embedding::new(d, 3).embed(&raw));
        }
        assert_ne!(
            Embedding::new(20, 3).embed(&raw),
            Embedding::new(20, 4).embed(&raw)
        );
    }
}
