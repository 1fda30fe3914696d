//! The querying-workload study's published figures (Sec. IV and the
//! appendix).

use crate::MeanSd;

/// D1, participants without mobility limitations: querying workload.
pub const D1_WORKLOAD: MeanSd = MeanSd::new(0.36, 0.29);
/// D2, participants with mobility limitations and occupational
/// therapists: querying workload.
pub const D2_WORKLOAD: MeanSd = MeanSd::new(0.40, 0.28);
/// One-sided Mann-Whitney U p-value for D1 < D2.
pub const D1_BELOW_D2_P: f64 = 5.4e-5;
/// Unique query/workload pairs in D1.
pub const D1_PAIRS: usize = 4272;
/// Unique query/workload pairs in D2.
pub const D2_PAIRS: usize = 705;
/// Participants of D1.
pub const D1_PARTICIPANTS: usize = 89;
/// Participants of D2: 14 with mobility limitations and 3 occupational
/// therapists.
pub const D2_PARTICIPANTS: usize = 17;
/// Conditions per participant (difficulty × distraction × interval).
pub const CONDITIONS: usize = 12;
