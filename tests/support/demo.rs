//! Test support shared by the suites that run demo sessions (`hil-cli`'s,
//! `hil-experiments`' and the workspace `tests/`): included by path
//! (`#[path = ".../tests/support/demo.rs"] mod demo;`), so that no crate
//! is needed for a config, a scratch folder and a log reader.
#![allow(dead_code)] // each suite uses part of it

use std::path::{Path, PathBuf};

/// A demo session (the demo plate, learner and counting workload: no file
/// and no person needed) as experiment TOML. Each field is the TOML text
/// of one place; `None` leaves `[session]` out.
#[derive(Clone, Copy, Debug)]
pub struct DemoSession<'a> {
    pub seed: u64,
    pub episodes: usize,
    pub n_att: Option<u32>,
    /// The `foods` array's items, e.g. `"banana", "carrot"`.
    pub foods: &'a str,
    pub repeat: usize,
    /// The `[policy]` lines after `type = "demo_learner"`.
    pub policy: &'a str,
    /// The `[channel]` table's body.
    pub channel: &'a str,
}

impl Default for DemoSession<'_> {
    fn default() -> Self {
        Self {
            seed: 5,
            episodes: 2,
            n_att: Some(3),
            foods: r#""banana", "carrot", "grape""#,
            repeat: 2,
            policy: "query_probability = 0.5\nepsilon = 0.2",
            channel: "type = \"simulated_expert\"\ndecline_rate = 0.2",
        }
    }
}

impl DemoSession<'_> {
    /// The config text.
    pub fn toml(&self) -> String {
        let session = self
            .n_att
            .map_or(String::new(), |n| format!("\n[session]\nn_att = {n}\n"));
        format!(
            "\nseed = {}\nepisodes = {}\n{session}\n[environment]\ntype = \"demo_plate\"\n\
             foods = [{}]\nrepeat = {}\n\n[policy]\ntype = \"demo_learner\"\n{}\n\n\
             [workload]\ntype = \"demo_counting\"\nincrement = 0.05\nwindow = 10\n\n\
             [channel]\n{}\n",
            self.seed, self.episodes, self.foods, self.repeat, self.policy, self.channel
        )
    }
}

/// A fresh, empty scratch folder `hil-{suite}-{name}-{pid}` under the
/// system's temporary folder.
pub fn scratch_dir(suite: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-{suite}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// An interaction log's lines without its `resumed` markers: what an
/// uninterrupted run writes.
pub fn lines_without_markers(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.contains(r#""record":"resumed""#))
        .map(String::from)
        .collect()
}
