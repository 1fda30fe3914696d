//! Study CSVs for the scaling benches: long conditions, which the paper's
//! design (3 or 5 queries per condition) never has, so that any work that
//! grows faster than the rows of a condition shows.

use hil_workload::study::COLUMNS;

/// A valid study CSV: for each `(participant, population)`, one baseline
/// survey, then `n` queries in one condition, a minute apart, with varied
/// kinds and answers.
pub fn long_condition_csv(participants: &[(&str, &str)], n: usize) -> String {
    let mut text = COLUMNS.join(",");
    text.push('\n');
    let kinds = ["easy,mcq", "hard,open_ended", "easy,bounding_box"];
    for (p, population) in participants {
        text.push_str(&format!("{p},{population},base,330,,,easy,,2,1,4,2,1,\n"));
        for i in 0..n {
            text.push_str(&format!(
                "{p},{population},c1,{},{},none,1,{},2,3,{},1,12.5\n",
                60 * (i + 1),
                kinds[i % 3],
                1 + i % 5,
                1 + (i / 5) % 5,
            ));
        }
    }
    text
}
