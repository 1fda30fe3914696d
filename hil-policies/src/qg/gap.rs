//! The query gap G of LinUCB-QG.

use hil_core::ArmId;

use crate::common::argmax;
use crate::estimator::ArmEstimate;

/// The query gap and the two arms it compares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryGap {
    /// a* = argmax θᵀx.
    pub best: ArmId,
    /// a⁻ = the runner-up by θᵀx.
    pub runner_up: ArmId,
    /// G = UCB(a⁻) − LCB(a*).
    pub gap: f64,
}

/// G = (θ_{a⁻}ᵀx + α·b_{a⁻}) − (θ_{a*}ᵀx − α·b_{a*}), or `None` with fewer
/// than two arms. Ties go to the lower arm index.
///
/// ```
/// use hil_policies::{ArmEstimate, query_gap};
/// let s = [ArmEstimate { estimate: 0.8, bonus: 0.1 }, ArmEstimate { estimate: 0.5, bonus: 0.2 }];
/// let g = query_gap(&s, 1.0).unwrap();
/// assert!((g.gap - ((0.5 + 0.2) - (0.8 - 0.1))).abs() < 1e-15);
/// ```
pub fn query_gap(scores: &[ArmEstimate], alpha: f64) -> Option<QueryGap> {
    if scores.len() < 2 {
        return None;
    }
    let best = argmax(scores, |s| s.estimate);
    let mut runner = if best == 0 { 1 } else { 0 };
    for (i, s) in scores.iter().enumerate() {
        if i != best && s.estimate > scores[runner].estimate {
            runner = i;
        }
    }
    let gap = scores[runner].ucb(alpha) - scores[best].lcb(alpha);
    Some(QueryGap {
        best: ArmId(best),
        runner_up: ArmId(runner),
        gap,
    })
}
