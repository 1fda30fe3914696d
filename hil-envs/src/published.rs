//! The paper's published simulation results, transcribed as facts so that
//! reports can print them beside ours. Values are (mean, std) pairs over the
//! paper's 3 seeds (× 5 policy seeds for LinUCB-ExpDecay).

use crate::protocol::Family;

/// Appendix tables (one per workload model) and the main-text table
/// (w_task = 0.7): (model, w_task, policy, [r_task_avg, ±, M_wt, ±, f_q, ±]).
/// The main table prints "-" for LinUCB's f_q; it never queries, so 0 ± 0.
pub const BY_W_TASK: &[(&str, f64, Family, [f64; 6])] = &[
    (
        "f1_sim",
        0.2,
        Family::Linucb,
        [0.292, 0.113, 0.458, 0.023, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.2,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.365, 0.021, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.2,
        Family::LinucbExpDecay,
        [0.374, 0.143, 0.475, 0.029, 0.44, 0.15],
    ),
    (
        "f1_sim",
        0.2,
        Family::LinucbQg,
        [0.434, 0.049, 0.458, 0.049, 0.733, 0.094],
    ),
    (
        "f1_sim",
        0.3,
        Family::Linucb,
        [0.292, 0.113, 0.438, 0.034, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.3,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.41, 0.042, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.3,
        Family::LinucbExpDecay,
        [0.374, 0.143, 0.462, 0.043, 0.44, 0.15],
    ),
    (
        "f1_sim",
        0.3,
        Family::LinucbQg,
        [0.434, 0.049, 0.455, 0.048, 0.733, 0.094],
    ),
    (
        "f1_sim",
        0.4,
        Family::Linucb,
        [0.292, 0.113, 0.417, 0.045, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.4,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.455, 0.064, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.4,
        Family::LinucbExpDecay,
        [0.374, 0.143, 0.449, 0.057, 0.44, 0.15],
    ),
    (
        "f1_sim",
        0.4,
        Family::LinucbQg,
        [0.434, 0.049, 0.452, 0.047, 0.733, 0.094],
    ),
    (
        "f1_sim",
        0.5,
        Family::Linucb,
        [0.292, 0.113, 0.396, 0.056, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.5,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.501, 0.086, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.5,
        Family::LinucbExpDecay,
        [0.374, 0.143, 0.437, 0.071, 0.44, 0.15],
    ),
    (
        "f1_sim",
        0.5,
        Family::LinucbQg,
        [0.67, 0.237, 0.542, 0.059, 0.867, 0.189],
    ),
    (
        "f1_sim",
        0.6,
        Family::Linucb,
        [0.292, 0.113, 0.375, 0.068, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.6,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.546, 0.108, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.6,
        Family::LinucbExpDecay,
        [0.374, 0.143, 0.424, 0.086, 0.44, 0.15],
    ),
    (
        "f1_sim",
        0.6,
        Family::LinucbQg,
        [0.67, 0.237, 0.567, 0.094, 0.867, 0.189],
    ),
    (
        "f1_sim",
        0.8,
        Family::Linucb,
        [0.292, 0.113, 0.333, 0.09, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.8,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.636, 0.152, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.8,
        Family::LinucbExpDecay,
        [0.399, 0.129, 0.417, 0.103, 0.56, 0.15],
    ),
    (
        "f1_sim",
        0.8,
        Family::LinucbQg,
        [0.67, 0.237, 0.619, 0.166, 0.867, 0.189],
    ),
    (
        "f1_sim",
        0.9,
        Family::Linucb,
        [0.292, 0.113, 0.313, 0.101, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.9,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.682, 0.173, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.9,
        Family::LinucbExpDecay,
        [0.399, 0.129, 0.408, 0.116, 0.56, 0.15],
    ),
    (
        "f1_sim",
        0.9,
        Family::LinucbQg,
        [0.67, 0.237, 0.644, 0.201, 0.867, 0.189],
    ),
    (
        "f2_sim",
        0.2,
        Family::Linucb,
        [0.292, 0.113, 0.458, 0.023, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.2,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.255, 0.039, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.2,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.438, 0.084, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.2,
        Family::LinucbQg,
        [0.336, 0.069, 0.353, 0.088, 0.333, 0.094],
    ),
    (
        "f2_sim",
        0.3,
        Family::Linucb,
        [0.292, 0.113, 0.438, 0.034, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.3,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.132, 0.059, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.3,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.421, 0.076, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.3,
        Family::LinucbQg,
        [0.336, 0.069, 0.351, 0.083, 0.333, 0.094],
    ),
    (
        "f2_sim",
        0.4,
        Family::Linucb,
        [0.292, 0.113, 0.417, 0.045, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.4,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.009, 0.078, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.4,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.404, 0.072, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.4,
        Family::LinucbQg,
        [0.336, 0.069, 0.349, 0.078, 0.333, 0.094],
    ),
    (
        "f2_sim",
        0.5,
        Family::Linucb,
        [0.292, 0.113, 0.396, 0.056, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.5,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.113, 0.098, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.5,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.387, 0.071, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.5,
        Family::LinucbQg,
        [0.336, 0.069, 0.347, 0.074, 0.333, 0.094],
    ),
    (
        "f2_sim",
        0.6,
        Family::Linucb,
        [0.292, 0.113, 0.375, 0.068, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.6,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.236, 0.117, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.6,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.37, 0.075, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.6,
        Family::LinucbQg,
        [0.336, 0.069, 0.344, 0.071, 0.333, 0.094],
    ),
    (
        "f2_sim",
        0.8,
        Family::Linucb,
        [0.292, 0.113, 0.333, 0.09, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.8,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.481, 0.156, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.8,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.336, 0.091, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.8,
        Family::LinucbQg,
        [0.56, 0.051, 0.466, 0.037, 0.8, 0.163],
    ),
    (
        "f2_sim",
        0.9,
        Family::Linucb,
        [0.292, 0.113, 0.313, 0.101, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.9,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.604, 0.176, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.9,
        Family::LinucbExpDecay,
        [0.399, 0.129, 0.399, 0.112, 0.56, 0.15],
    ),
    (
        "f2_sim",
        0.9,
        Family::LinucbQg,
        [0.56, 0.051, 0.513, 0.044, 0.8, 0.163],
    ),
    (
        "f12_sim",
        0.2,
        Family::Linucb,
        [0.292, 0.113, 0.429, 0.023, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.2,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.255, 0.039, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.2,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.377, 0.188, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.2,
        Family::LinucbQg,
        [0.503, 0.041, 0.163, 0.33, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.3,
        Family::Linucb,
        [0.292, 0.113, 0.411, 0.034, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.3,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.132, 0.059, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.3,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.367, 0.164, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.3,
        Family::LinucbQg,
        [0.503, 0.041, 0.206, 0.289, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.4,
        Family::Linucb,
        [0.292, 0.113, 0.394, 0.045, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.4,
        Family::AlwaysQuery,
        [0.727, 0.195, -0.009, 0.078, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.4,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.358, 0.142, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.4,
        Family::LinucbQg,
        [0.503, 0.041, 0.248, 0.249, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.5,
        Family::Linucb,
        [0.292, 0.113, 0.377, 0.056, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.5,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.113, 0.098, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.5,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.349, 0.122, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.5,
        Family::LinucbQg,
        [0.503, 0.041, 0.291, 0.209, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.6,
        Family::Linucb,
        [0.292, 0.113, 0.36, 0.068, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.6,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.236, 0.117, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.6,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.34, 0.106, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.6,
        Family::LinucbQg,
        [0.503, 0.041, 0.333, 0.17, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.8,
        Family::Linucb,
        [0.292, 0.113, 0.326, 0.09, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.8,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.481, 0.156, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.8,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.321, 0.096, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.8,
        Family::LinucbQg,
        [0.503, 0.041, 0.418, 0.093, 0.667, 0.189],
    ),
    (
        "f12_sim",
        0.9,
        Family::Linucb,
        [0.292, 0.113, 0.309, 0.101, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.9,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.604, 0.176, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.9,
        Family::LinucbExpDecay,
        [0.399, 0.129, 0.383, 0.111, 0.56, 0.15],
    ),
    (
        "f12_sim",
        0.9,
        Family::LinucbQg,
        [0.503, 0.041, 0.461, 0.059, 0.667, 0.189],
    ),
    (
        "f1_sim",
        0.7,
        Family::Linucb,
        [0.292, 0.113, 0.354, 0.079, 0.0, 0.0],
    ),
    (
        "f1_sim",
        0.7,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.591, 0.13, 1.0, 0.0],
    ),
    (
        "f1_sim",
        0.7,
        Family::LinucbExpDecay,
        [0.399, 0.129, 0.425, 0.09, 0.56, 0.15],
    ),
    (
        "f1_sim",
        0.7,
        Family::LinucbQg,
        [0.67, 0.237, 0.593, 0.13, 0.867, 0.189],
    ),
    (
        "f2_sim",
        0.7,
        Family::Linucb,
        [0.292, 0.113, 0.354, 0.079, 0.0, 0.0],
    ),
    (
        "f2_sim",
        0.7,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.359, 0.137, 1.0, 0.0],
    ),
    (
        "f2_sim",
        0.7,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.353, 0.082, 0.16, 0.15],
    ),
    (
        "f2_sim",
        0.7,
        Family::LinucbQg,
        [0.336, 0.069, 0.342, 0.069, 0.333, 0.094],
    ),
    (
        "f12_sim",
        0.7,
        Family::Linucb,
        [0.292, 0.113, 0.343, 0.079, 0.0, 0.0],
    ),
    (
        "f12_sim",
        0.7,
        Family::AlwaysQuery,
        [0.727, 0.195, 0.359, 0.137, 1.0, 0.0],
    ),
    (
        "f12_sim",
        0.7,
        Family::LinucbExpDecay,
        [0.303, 0.116, 0.33, 0.097, 0.16, 0.15],
    ),
    (
        "f12_sim",
        0.7,
        Family::LinucbQg,
        [0.503, 0.041, 0.376, 0.131, 0.667, 0.189],
    ),
];

/// Additional convergence metrics (appendix; the caption says w_task = 0.7):
/// (model, policy, [ΔWL, ±, t_conv, ±, f_fail_food, ±, f_auto_food, ±]).
pub const CONVERGENCE: &[(&str, Family, [f64; 8])] = &[
    (
        "f1_sim",
        Family::Linucb,
        [-0.5, 0.0, 3.467, 1.087, 0.067, 0.094, 0.933, 0.094],
    ),
    (
        "f1_sim",
        Family::AlwaysQuery,
        [-0.274, 0.024, 1.467, 0.34, 0.0, 0.0, 0.0, 0.0],
    ),
    (
        "f1_sim",
        Family::LinucbExpDecay,
        [-0.485, 0.037, 2.413, 0.463, 0.04, 0.08, 0.4, 0.146],
    ),
    (
        "f1_sim",
        Family::LinucbQg,
        [-0.414, 0.122, 1.667, 0.499, 0.0, 0.0, 0.133, 0.189],
    ),
    (
        "f2_sim",
        Family::Linucb,
        [-0.5, 0.0, 3.467, 1.087, 0.067, 0.094, 0.933, 0.094],
    ),
    (
        "f2_sim",
        Family::AlwaysQuery,
        [0.5, 0.0, 1.467, 0.34, 0.0, 0.0, 0.0, 0.0],
    ),
    (
        "f2_sim",
        Family::LinucbExpDecay,
        [-0.471, 0.107, 3.297, 1.048, 0.067, 0.094, 0.773, 0.177],
    ),
    (
        "f2_sim",
        Family::LinucbQg,
        [-0.357, 0.101, 3.133, 0.754, 0.0, 0.0, 0.667, 0.094],
    ),
    (
        "f12_sim",
        Family::Linucb,
        [-0.463, 0.0, 3.467, 1.087, 0.067, 0.094, 0.933, 0.094],
    ),
    (
        "f12_sim",
        Family::AlwaysQuery,
        [0.5, 0.0, 1.467, 0.34, 0.0, 0.0, 0.0, 0.0],
    ),
    (
        "f12_sim",
        Family::LinucbExpDecay,
        [-0.395, 0.24, 3.297, 1.048, 0.067, 0.094, 0.773, 0.177],
    ),
    (
        "f12_sim",
        Family::LinucbQg,
        [-0.078, 0.411, 2.0, 0.163, 0.0, 0.0, 0.333, 0.189],
    ),
];

/// w_task of [`CONVERGENCE`].
pub const CONVERGENCE_W_TASK: f64 = 0.7;

/// Cross-data experiment at w_task = 0.4: (decide, score, [r_task_avg, ±,
/// ΔWL, ±, M_wt, ±, f_q, ±]).
pub const CROSS: &[(&str, &str, [f64; 8])] = &[
    (
        "f1_sim",
        "f2_sim",
        [0.434, 0.049, -0.159, 0.092, 0.269, 0.04, 0.733, 0.094],
    ),
    (
        "f12_sim",
        "f2_sim",
        [0.503, 0.041, -0.286, 0.159, 0.373, 0.108, 0.667, 0.189],
    ),
];

/// w_task of [`CROSS`].
pub const CROSS_W_TASK: f64 = 0.4;

/// The published (r_task_avg, M_wt, f_q) row, if the paper has it.
pub fn by_w_task(model: &str, w_task: f64, policy: Family) -> Option<[f64; 6]> {
    BY_W_TASK
        .iter()
        .find(|(m, w, p, _)| *m == model && (w - w_task).abs() < 1e-9 && *p == policy)
        .map(|r| r.3)
}

/// The published convergence row, if any.
pub fn convergence(model: &str, policy: Family) -> Option<[f64; 8]> {
    CONVERGENCE
        .iter()
        .find(|(m, p, _)| *m == model && *p == policy)
        .map(|r| r.2)
}

/// The published cross-data row, if any.
pub fn cross(decide: &str, score: &str) -> Option<[f64; 8]> {
    CROSS
        .iter()
        .find(|(d, s, _)| *d == decide && *s == score)
        .map(|r| r.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transcription_is_complete_and_consistent() {
        // 3 models × 8 w_task values × 4 policies.
        assert_eq!(BY_W_TASK.len(), 96);
        assert_eq!(CONVERGENCE.len(), 12);
        // M_wt = w·r − (1 − w)·ΔWL: LinUCB's published numbers satisfy it
        // with the published ΔWL (a check on the transcription).
        for (m, w, p, v) in BY_W_TASK {
            if *p == Family::Linucb {
                let dwl = convergence(m, *p).unwrap()[0];
                let mwt = w * v[0] - (1.0 - w) * dwl;
                assert!((mwt - v[2]).abs() < 0.0015, "{m} {w}: {mwt} vs {}", v[2]);
            }
        }
    }
}
