//! The simulated testbed's protocol, as the paper states it (Sec. V and
//! the appendix).

/// Attempts per item before it counts as failed.
pub const N_ATT: u32 = 10;
/// Initial workload WL_0 of every episode (a median initial workload).
pub const WL0: f64 = 0.5;
/// Seeds every published simulation figure is averaged over.
pub const SEEDS: usize = 3;
/// Extra policy seeds per seed of LinUCB-ExpDecay (a random policy).
pub const EXPDECAY_POLICY_SEEDS: usize = 5;
/// The workload model's timestep Δt, in seconds.
pub const TIMESTEP_SECONDS: f64 = 10.0;
/// The w_task of the main-text table and the convergence table.
pub const FIGURE_W_TASK: f64 = 0.7;
/// The w_task of the cross-data experiment (and of main-text Table I).
pub const CROSS_W_TASK: f64 = 0.4;
/// The w_task values of the appendix tables, 0.2 to 0.9.
pub const W_TASKS: [f64; 8] = [0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9];

/// The validation foods (hyperparameters are chosen on them).
pub const VALIDATION_FOODS: [&str; 2] = ["cantaloupe", "grape"];
/// The test foods (figures are reported on them).
pub const TEST_FOODS: [&str; 2] = ["banana", "carrot"];
/// The twelve pretraining foods: the data set's other foods.
pub const PRETRAIN_FOODS: [&str; 12] = [
    "apple",
    "bell_pepper",
    "broccoli",
    "cauliflower",
    "celery",
    "cherry_tomato",
    "honeydew",
    "kiwi",
    "strawberry",
    "lettuce",
    "spinach",
    "kale",
];
