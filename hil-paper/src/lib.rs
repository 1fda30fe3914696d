//! # hil-paper
//!
//! The facts of the paper hil implements ("To Ask or Not to Ask",
//! `shared/reference/paper-to-ask-or-not-to-ask.tex`) and of the published
//! work it builds on, as data in one place. Every crate that needs one of
//! them reads it from here, so a fact is stated once:
//!
//! - [`methods`]: the paper's four methods, the labels its tables use, the
//!   policy types that implement them and the grids hil tunes them over;
//! - [`simulation`]: the simulated testbed's protocol (N_att, WL_0, seeds,
//!   w_task values, the food split);
//! - [`workload_study`]: the querying-workload study's published figures
//!   (D1 and D2 sizes, means, the Mann-Whitney p);
//! - [`user_study`]: the real-robot study's protocol and its published
//!   objective table;
//! - [`food_data`]: facts of the food data set the paper simulates with
//!   (Feng et al. 2019): trials per setting and the success rule's hold.
//!
//! The crate is a leaf (no dependencies), so the feeding, workload and
//! physics crates can read it without depending on the protocol crate.
//! Where hil makes a choice the paper does not state (a grid, the UCB
//! weight α), the item says so: those are hil's, kept here beside the facts
//! they complete so that each is defined once.
//!
//! ```
//! use hil_paper::methods::PaperMethod;
//! assert_eq!(PaperMethod::LinUcbQg.label(), "LinUCB-QG");
//! assert_eq!(PaperMethod::from_label("AlwaysQuery"), Some(PaperMethod::AlwaysQuery));
//! assert_eq!(hil_paper::simulation::N_ATT, 10);
//! ```

pub mod food_data;
pub mod methods;
pub mod simulation;
pub mod user_study;
pub mod workload_study;

/// A published figure: the mean and standard deviation a paper table
/// prints (`0.68 ± 0.29`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanSd {
    /// The mean.
    pub mean: f64,
    /// The standard deviation (not an error of the mean).
    pub sd: f64,
}

impl MeanSd {
    /// `mean ± sd`.
    pub const fn new(mean: f64, sd: f64) -> Self {
        Self { mean, sd }
    }
}
