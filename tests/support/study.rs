//! A user study on the cheap dataset environment, shared by the suites
//! that run one (`hil-cli`'s and `hil-experiments`'), included by path.
#![allow(dead_code)] // each suite uses part of it

/// User-study TOML: `repetitions` plates of 3 items drawn from `foods`
/// (the `foods` array's items, e.g. `"banana", "carrot"`) of the bundled
/// synthetic dataset, pretrained on three other foods; `rest` holds the
/// `[validation]`, `[[methods]]` and other tables.
pub fn food_replay_study(repetitions: usize, foods: &str, rest: &str) -> String {
    format!(
        "repetitions = {repetitions}\n[environment]\ntype = \"food_replay\"\nfoods = [{foods}]\n\
         pretrain_foods = [\"apple\", \"kiwi\", \"strawberry\"]\nitems_per_episode = 3\n{rest}"
    )
}
