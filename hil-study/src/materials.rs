//! The study's materials, all made here: food pictures drawn as SVG, the
//! robot queries built on them (with their correct answers), the addition
//! task's sums and the transcription passage. Everything is a pure
//! function of the study seed and where it is asked, so a resumed
//! participant sees exactly what they would have seen.

use hil_core::{BoundingBox, Difficulty, ResponseType};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// The foods the pictures show.
pub const FOODS: [&str; 10] = [
    "strawberry",
    "grape",
    "banana",
    "carrot",
    "broccoli",
    "cantaloupe",
    "tofu",
    "apple",
    "raspberry",
    "blueberry",
];

/// The default transcription passage (written for hil; a lab replaces it
/// with `passage.txt` in its materials folder).
pub const DEFAULT_PASSAGE: &str = include_str!("../assets/passage.txt");

/// The materials in use: the passage's words, its pace, the addends, the
/// lab's pictures.
#[derive(Debug)]
pub struct Materials {
    /// The transcription passage, word by word.
    pub passage: Vec<String>,
    /// Words revealed per study minute.
    pub words_per_min: f64,
    /// Largest addend.
    pub addition_max: u32,
    /// The lab's `images/` folder, if it has one.
    pub images: Option<std::path::PathBuf>,
}

impl Materials {
    /// Loads the lab's folder over the defaults.
    pub fn load(config: &crate::StudyConfig) -> hil_core::Result<Self> {
        let m = &config.materials;
        let mut passage = DEFAULT_PASSAGE.to_string();
        let mut images = None;
        if let Some(dir) = &m.dir {
            if !dir.is_dir() {
                return Err(hil_core::HilError::invalid_parameter(
                    "materials.dir",
                    dir.display(),
                    "is not a directory",
                ));
            }
            let p = dir.join("passage.txt");
            if p.exists() {
                passage = hil_core::files::read_text(&p, hil_core::files::limits::ASSET)?;
                if passage.split_whitespace().count() < 10 {
                    return Err(hil_textdata::data_error(
                        &p,
                        1,
                        "passage",
                        "needs at least 10 words",
                    ));
                }
            }
            let i = dir.join("images");
            if i.is_dir() {
                images = Some(i);
            }
        }
        Ok(Self {
            passage: passage.split_whitespace().map(str::to_string).collect(),
            words_per_min: m.transcription_words_per_min,
            addition_max: m.addition_max,
            images,
        })
    }

    /// Sum `index` of the addition task of condition `c` for participant
    /// number `number`.
    pub fn addition(
        &self,
        design: &crate::Design,
        number: usize,
        c: usize,
        index: usize,
    ) -> (u32, u32) {
        addition(
            design.config().seed,
            [number as u64, c as u64],
            index as u64,
            self.addition_max,
        )
    }
}

/// A random stream for one use of the materials: the study seed and the
/// place it is asked (participant, condition, item, purpose).
fn rng(seed: u64, parts: &[u64]) -> ChaCha8Rng {
    // FNV-1a over the parts: a fixed, portable mix (no std hasher, whose
    // output may change between Rust versions).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ seed;
    for p in parts {
        for b in p.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    ChaCha8Rng::seed_from_u64(h)
}

/// A food drawn in one cell of a 3 × 2 plate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placed {
    /// Index into [`FOODS`].
    pub food: usize,
    /// Cell 0..6, row-major.
    pub cell: usize,
}

/// A picture: foods on a plate, one of them maybe outlined.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Picture {
    /// What is on the plate.
    pub foods: Vec<Placed>,
    /// The index into `foods` of the outlined item, if any.
    pub outlined: Option<usize>,
}

/// Columns and rows of the plate's grid.
const COLS: usize = 3;
const ROWS: usize = 2;
/// Picture size in SVG units (3:2, as the box-drawing area).
const W: f64 = 600.0;
const H: f64 = 400.0;

/// The normalised box of grid cell `cell`, shrunk to the food's extent.
pub fn cell_box(cell: usize) -> BoundingBox {
    let (c, r) = ((cell % COLS) as f64, (cell / COLS) as f64);
    let (cw, ch) = (1.0 / COLS as f64, 1.0 / ROWS as f64);
    BoundingBox::new(
        (c + 0.15) * cw,
        (r + 0.15) * ch,
        (c + 0.85) * cw,
        (r + 0.85) * ch,
    )
}

/// Names a cell's place on the plate, as a hard question does.
fn place_name(cell: usize) -> &'static str {
    [
        "top left",
        "top middle",
        "top right",
        "bottom left",
        "bottom middle",
        "bottom right",
    ][cell]
}

/// One food, drawn in a 100 × 100 box at the origin.
fn food_svg(food: usize) -> &'static str {
    match FOODS[food] {
        "strawberry" => {
            r##"<path d="M50 92 C20 70 12 42 22 30 C32 20 68 20 78 30 C88 42 80 70 50 92Z" fill="#d1122b"/><path d="M30 26 L50 14 L70 26 L58 24 L50 32 L42 24Z" fill="#2e7d32"/><g fill="#ffe27a"><circle cx="40" cy="45" r="2"/><circle cx="58" cy="48" r="2"/><circle cx="48" cy="62" r="2"/><circle cx="36" cy="58" r="2"/><circle cx="62" cy="63" r="2"/></g>"##
        }
        "grape" => {
            r##"<g fill="#5b2a86" stroke="#3a1656" stroke-width="2"><circle cx="38" cy="35" r="13"/><circle cx="62" cy="35" r="13"/><circle cx="50" cy="55" r="13"/><circle cx="30" cy="58" r="12"/><circle cx="70" cy="58" r="12"/><circle cx="50" cy="77" r="12"/></g><path d="M50 22 L52 8" stroke="#5d4037" stroke-width="4"/>"##
        }
        "banana" => {
            r##"<path d="M12 30 C20 80 75 90 92 55 C70 72 35 62 22 26Z" fill="#f6d32d" stroke="#8a6d00" stroke-width="3"/>"##
        }
        "carrot" => {
            r##"<path d="M20 80 L78 28 L86 38 Z" fill="#ef6c00" stroke="#a84300" stroke-width="3"/><path d="M80 30 L95 12 M83 33 L98 24 M78 28 L84 8" stroke="#2e7d32" stroke-width="5"/>"##
        }
        "broccoli" => {
            r##"<rect x="42" y="55" width="16" height="38" fill="#8bc34a"/><g fill="#2e7d32"><circle cx="35" cy="40" r="17"/><circle cx="65" cy="40" r="17"/><circle cx="50" cy="28" r="17"/><circle cx="50" cy="50" r="15"/></g>"##
        }
        "cantaloupe" => {
            r##"<rect x="18" y="22" width="64" height="60" rx="6" fill="#f4a259"/><rect x="18" y="72" width="64" height="12" rx="4" fill="#a5c27a"/>"##
        }
        "tofu" => {
            r##"<rect x="20" y="24" width="60" height="56" rx="4" fill="#f7f2dc" stroke="#b0a57a" stroke-width="3"/><path d="M20 24 L32 14 L92 14 L80 24Z M80 24 L92 14 L92 70 L80 80Z" fill="#e6dfbd" stroke="#b0a57a" stroke-width="3"/>"##
        }
        "apple" => {
            r##"<circle cx="50" cy="58" r="32" fill="#c62828"/><path d="M50 28 L53 12" stroke="#5d4037" stroke-width="4"/><path d="M54 18 C64 8 76 12 78 16 C68 22 60 22 54 18Z" fill="#2e7d32"/>"##
        }
        "raspberry" => {
            r##"<g fill="#c2185b" stroke="#880e4f" stroke-width="2"><circle cx="40" cy="40" r="10"/><circle cx="60" cy="40" r="10"/><circle cx="50" cy="32" r="10"/><circle cx="35" cy="58" r="10"/><circle cx="50" cy="55" r="10"/><circle cx="65" cy="58" r="10"/><circle cx="43" cy="74" r="10"/><circle cx="58" cy="74" r="10"/></g>"##
        }
        _ => {
            r##"<circle cx="50" cy="52" r="30" fill="#283593" stroke="#1a1f5c" stroke-width="3"/><path d="M42 30 L50 22 L58 30" stroke="#9fa8da" stroke-width="4" fill="none"/>"##
        }
    }
}

/// The SVG of `picture`. It is made here from fixed shapes (no text from
/// anyone, no scripts), so it is safe to serve.
pub fn picture_svg(picture: &Picture) -> String {
    let (cw, ch) = (W / COLS as f64, H / ROWS as f64);
    let mut s = format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" height="{H}"><rect width="{W}" height="{H}" fill="#f4f1ea"/><ellipse cx="{}" cy="{}" rx="{}" ry="{}" fill="#ffffff" stroke="#9e9e9e" stroke-width="4"/>"##,
        W / 2.0,
        H / 2.0,
        W / 2.0 - 8.0,
        H / 2.0 - 8.0
    );
    for p in &picture.foods {
        let (c, r) = ((p.cell % COLS) as f64, (p.cell / COLS) as f64);
        let scale = ch * 0.7 / 100.0;
        let x = c * cw + (cw - 100.0 * scale) / 2.0;
        let y = r * ch + (ch - 100.0 * scale) / 2.0;
        s.push_str(&format!(
            r#"<g transform="translate({x:.1} {y:.1}) scale({scale:.3})">{}</g>"#,
            food_svg(p.food)
        ));
    }
    if let Some(i) = picture.outlined {
        let b = cell_box(picture.foods[i].cell);
        let (x, y, w, h) = (b.x0 * W, b.y0 * H, (b.x1 - b.x0) * W, (b.y1 - b.y0) * H);
        s.push_str(&format!(
            r##"<rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" fill="none" stroke="#ffd400" stroke-width="12"/><rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" fill="none" stroke="#000" stroke-width="5"/>"##
        ));
    }
    s.push_str("</svg>");
    s
}

/// A description of `picture` for screen readers. It does not name the
/// foods: that would give the answers away.
pub fn describe(picture: &Picture) -> String {
    let n = picture.foods.len();
    let mut s = format!(
        "A plate with {n} food item{}",
        if n == 1 { "" } else { "s" }
    );
    if let Some(i) = picture.outlined {
        s.push_str(&format!(
            "; the item at the {} is framed",
            place_name(picture.foods[i].cell)
        ));
    }
    s
}

/// What the participant is asked for.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Expected {
    /// One of `options` (as a label); `correct` is the right one.
    Choice {
        /// The choices, without "I don't know" (always offered).
        options: Vec<String>,
        /// The correct choice.
        correct: String,
    },
    /// A box; `truth` is the item's box.
    Box {
        /// The item's box.
        truth: BoundingBox,
    },
    /// Free text about the food (never about the participant).
    Text,
}

/// A robot query of the study: the question, its pictures and the answer
/// expected.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StudyQuery {
    /// The question as shown.
    pub question: String,
    /// The pictures shown with it (two for a hard multiple choice).
    pub pictures: Vec<Picture>,
    /// The food the question is about.
    pub food: String,
    /// What kind of answer is expected.
    pub expected: Expected,
}

/// Distinct foods drawn at random.
fn pick_foods(rng: &mut ChaCha8Rng, n: usize) -> Vec<usize> {
    let mut all: Vec<usize> = (0..FOODS.len()).collect();
    for i in 0..n {
        let j = rng.random_range(i..all.len());
        all.swap(i, j);
    }
    all.truncate(n);
    all
}

/// Distinct cells drawn at random.
fn pick_cells(rng: &mut ChaCha8Rng, n: usize) -> Vec<usize> {
    let mut all: Vec<usize> = (0..COLS * ROWS).collect();
    for i in 0..n {
        let j = rng.random_range(i..all.len());
        all.swap(i, j);
    }
    all.truncate(n);
    all
}

/// The query of a given kind asked at `place` (participant, condition,
/// query number) of a study with seed `seed`.
pub fn study_query(
    seed: u64,
    place: [u64; 3],
    difficulty: Difficulty,
    response: ResponseType,
) -> StudyQuery {
    let mut rng = rng(seed, &[place[0], place[1], place[2], 1]);
    let one = |food: usize| Picture {
        foods: vec![Placed { food, cell: 1 }],
        outlined: None,
    };
    match (response, difficulty) {
        (ResponseType::Mcq, Difficulty::Easy) => {
            let foods = pick_foods(&mut rng, 4);
            let cells = pick_cells(&mut rng, 3);
            let picture = Picture {
                foods: cells
                    .iter()
                    .zip(&foods)
                    .map(|(&cell, &food)| Placed { food, cell })
                    .collect(),
                outlined: Some(0),
            };
            let mut options: Vec<String> = foods.iter().map(|&f| FOODS[f].to_string()).collect();
            options.sort();
            StudyQuery {
                question: "Which food is marked with the yellow and black frame?".into(),
                pictures: vec![picture],
                food: FOODS[foods[0]].into(),
                expected: Expected::Choice {
                    options,
                    correct: FOODS[foods[0]].into(),
                },
            }
        }
        (ResponseType::Mcq, Difficulty::Hard) => {
            let foods = pick_foods(&mut rng, 2);
            let target_left = rng.random_bool(0.5);
            let (l, r) = if target_left {
                (foods[0], foods[1])
            } else {
                (foods[1], foods[0])
            };
            StudyQuery {
                question: format!("Which of the two pictures shows the {}?", FOODS[foods[0]]),
                pictures: vec![one(l), one(r)],
                food: FOODS[foods[0]].into(),
                expected: Expected::Choice {
                    options: vec!["left".into(), "right".into()],
                    correct: if target_left { "left" } else { "right" }.into(),
                },
            }
        }
        (ResponseType::BoundingBox, Difficulty::Easy) => {
            let foods = pick_foods(&mut rng, 3);
            let cells = pick_cells(&mut rng, 3);
            StudyQuery {
                question: format!("Draw a box around the {}.", FOODS[foods[0]]),
                pictures: vec![Picture {
                    foods: cells
                        .iter()
                        .zip(&foods)
                        .map(|(&cell, &food)| Placed { food, cell })
                        .collect(),
                    outlined: None,
                }],
                food: FOODS[foods[0]].into(),
                expected: Expected::Box {
                    truth: cell_box(cells[0]),
                },
            }
        }
        (ResponseType::BoundingBox, Difficulty::Hard) => {
            // Two of the same food: only the place tells them apart.
            let foods = pick_foods(&mut rng, 4);
            let cells = pick_cells(&mut rng, 5);
            let mut placed = vec![
                Placed {
                    food: foods[0],
                    cell: cells[0],
                },
                Placed {
                    food: foods[0],
                    cell: cells[1],
                },
            ];
            placed.extend(
                cells[2..]
                    .iter()
                    .zip(&foods[1..])
                    .map(|(&cell, &food)| Placed { food, cell }),
            );
            StudyQuery {
                question: format!(
                    "Draw a box around only the {} at the {} of the plate.",
                    FOODS[foods[0]],
                    place_name(cells[0])
                ),
                pictures: vec![Picture {
                    foods: placed,
                    outlined: None,
                }],
                food: FOODS[foods[0]].into(),
                expected: Expected::Box {
                    truth: cell_box(cells[0]),
                },
            }
        }
        (ResponseType::OpenEnded, d) => {
            let food = pick_foods(&mut rng, 1)[0];
            let question = match d {
                Difficulty::Easy => format!(
                    "The robot tried to pick up this {} and missed. What might have gone wrong?",
                    FOODS[food]
                ),
                Difficulty::Hard => format!(
                    "How would you pick up this {} with a fork? Say where and at what angle the fork should go in.",
                    FOODS[food]
                ),
            };
            StudyQuery {
                question,
                pictures: vec![one(food)],
                food: FOODS[food].into(),
                expected: Expected::Text,
            }
        }
    }
}

/// Intersection over union of two boxes (0 when they do not overlap).
pub fn iou(a: &BoundingBox, b: &BoundingBox) -> f64 {
    let w = (a.x1.min(b.x1) - a.x0.max(b.x0)).max(0.0);
    let h = (a.y1.min(b.y1) - a.y0.max(b.y0)).max(0.0);
    let inter = w * h;
    let area = |r: &BoundingBox| (r.x1 - r.x0).max(0.0) * (r.y1 - r.y0).max(0.0);
    let union = area(a) + area(b) - inter;
    if union > 0.0 { inter / union } else { 0.0 }
}

/// Sum number `index` of the addition task at `place` (participant,
/// condition): two addends from 10 to `max`.
pub fn addition(seed: u64, place: [u64; 2], index: u64, max: u32) -> (u32, u32) {
    let mut rng = rng(seed, &[place[0], place[1], index, 2]);
    (rng.random_range(10..=max), rng.random_range(10..=max))
}

/// How many words of the passage have been revealed after `task_s` study
/// seconds at `words_per_min` (the page wraps round to the start when the
/// passage runs out).
pub fn revealed_words(task_s: f64, words_per_min: f64) -> usize {
    (task_s.max(0.0) / 60.0 * words_per_min).floor() as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_are_reproducible_and_answerable() {
        for d in Difficulty::ALL {
            for r in ResponseType::ALL {
                for k in 0..20 {
                    let q = study_query(7, [1, 2, k], d, r);
                    assert_eq!(q, study_query(7, [1, 2, k], d, r));
                    if let Expected::Choice { options, correct } = &q.expected {
                        assert!(options.contains(correct));
                    }
                    if let Expected::Box { truth } = &q.expected {
                        assert!((iou(truth, truth) - 1.0).abs() < 1e-12);
                    }
                    for p in &q.pictures {
                        let svg = picture_svg(p);
                        assert!(svg.starts_with("<svg") && !svg.contains("script"));
                    }
                }
            }
        }
    }

    #[test]
    fn the_default_passage_is_long_enough() {
        assert!(DEFAULT_PASSAGE.split_whitespace().count() >= 150);
    }
}
