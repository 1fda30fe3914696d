//! What a person may say to a query: every phrase the recognizer accepts
//! and what it means. The choices are spoken as the query presents them
//! (the action's name, its number in the list) with short forms, plus the
//! three words every query accepts: "skip", "repeat" and "I don't know".

use hil_core::{Query, ResponseType};

/// What an accepted phrase means.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(tag = "type", content = "value", rename_all = "snake_case")]
pub enum Meaning {
    /// The action with this index (multiple-choice and open-ended queries).
    Choice(usize),
    /// A region of the camera picture (bounding-box queries): cell `row *
    /// 3 + column` of a 3 × 3 grid.
    Region(usize),
    /// "skip": the person passes on the query.
    Skip,
    /// "repeat": ask the query again.
    Repeat,
    /// "I don't know".
    DontKnow,
}

/// The nine regions a spoken bounding box names, row by row.
pub const REGIONS: [&str; 9] = [
    "top left",
    "top",
    "top right",
    "left",
    "center",
    "right",
    "bottom left",
    "bottom",
    "bottom right",
];

const SMALL: [&str; 20] = [
    "zero",
    "one",
    "two",
    "three",
    "four",
    "five",
    "six",
    "seven",
    "eight",
    "nine",
    "ten",
    "eleven",
    "twelve",
    "thirteen",
    "fourteen",
    "fifteen",
    "sixteen",
    "seventeen",
    "eighteen",
    "nineteen",
];
const TENS: [&str; 10] = [
    "", "", "twenty", "thirty", "forty", "fifty", "sixty", "seventy", "eighty", "ninety",
];

/// A whole number in English words, e.g. `90` → "ninety", `215` → "two
/// hundred fifteen"; digit by digit from 1000 on ("one two three four").
pub fn number_words(n: u64) -> String {
    match n {
        0..=19 => SMALL[n as usize].to_string(),
        20..=99 => {
            let tens = TENS[(n / 10) as usize];
            match n % 10 {
                0 => tens.to_string(),
                u => format!("{tens} {}", SMALL[u as usize]),
            }
        }
        100..=999 => match n % 100 {
            0 => format!("{} hundred", SMALL[(n / 100) as usize]),
            r => format!("{} hundred {}", SMALL[(n / 100) as usize], number_words(r)),
        },
        _ => n
            .to_string()
            .chars()
            .map(|d| SMALL[d.to_digit(10).unwrap_or(0) as usize])
            .collect::<Vec<_>>()
            .join(" "),
    }
}

/// How a name is said: runs of capitals are spelled letter by letter
/// ("VS" → "v s"), numbers are read as words, other words are kept, and
/// `_`/`-`/spaces separate words. `VS90` → "v s ninety", `left_side` →
/// "left side".
pub fn spoken_name(name: &str) -> String {
    let mut words: Vec<String> = Vec::new();
    let chars: Vec<char> = name.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_ascii_digit() {
            let start = i;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
            let digits: String = chars[start..i].iter().collect();
            words.push(match digits.parse::<u64>() {
                Ok(n) if digits.len() < 4 => number_words(n),
                _ => digits
                    .chars()
                    .map(|d| SMALL[d.to_digit(10).unwrap_or(0) as usize])
                    .collect::<Vec<_>>()
                    .join(" "),
            });
        } else if c.is_uppercase() {
            let start = i;
            while i < chars.len() && chars[i].is_uppercase() {
                i += 1;
            }
            // "Left" is a word with a capital, "VS" (or "VSx") is spelled.
            if i - start == 1 && i < chars.len() && chars[i].is_lowercase() {
                while i < chars.len() && chars[i].is_lowercase() {
                    i += 1;
                }
                words.push(chars[start..i].iter().collect::<String>().to_lowercase());
            } else {
                words.extend(chars[start..i].iter().map(|c| c.to_lowercase().to_string()));
            }
        } else if c.is_alphabetic() {
            let start = i;
            while i < chars.len() && chars[i].is_lowercase() {
                i += 1;
            }
            words.push(chars[start..i].iter().collect());
        } else {
            i += 1;
        }
    }
    words.join(" ")
}

/// The phrases of one query and their meanings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Grammar {
    phrases: Vec<(String, Meaning)>,
}

impl Grammar {
    /// The grammar of `query`: for a multiple-choice or open-ended query,
    /// each action by its spoken name, by its number ("two") and as
    /// "option two" / "number two"; for a bounding box, the nine
    /// [`REGIONS`]; for every query, "skip", "repeat" and "I don't know".
    /// A phrase two choices share is dropped (it would be a guess).
    pub fn for_query(query: &Query) -> Self {
        let mut phrases: Vec<(String, Meaning)> = Vec::new();
        match query.kind.response {
            ResponseType::Mcq | ResponseType::OpenEnded => {
                for (i, name) in query.actions.names().iter().enumerate() {
                    let number = number_words(i as u64 + 1);
                    let meaning = Meaning::Choice(i);
                    phrases.push((spoken_name(name), meaning));
                    phrases.push((number.clone(), meaning));
                    phrases.push((format!("option {number}"), meaning));
                    phrases.push((format!("number {number}"), meaning));
                }
            }
            ResponseType::BoundingBox => {
                for (i, r) in REGIONS.iter().enumerate() {
                    phrases.push((r.to_string(), Meaning::Region(i)));
                }
                phrases.push(("middle".into(), Meaning::Region(4)));
            }
        }
        phrases.push(("skip".into(), Meaning::Skip));
        phrases.push(("repeat".into(), Meaning::Repeat));
        phrases.push(("i don't know".into(), Meaning::DontKnow));
        // Drop every phrase that means two things.
        let ambiguous: Vec<String> = phrases
            .iter()
            .filter(|(p, m)| phrases.iter().any(|(q, n)| q == p && n != m))
            .map(|(p, _)| p.clone())
            .collect();
        phrases.retain(|(p, _)| !p.is_empty() && !ambiguous.contains(p));
        phrases.dedup();
        Self { phrases }
    }

    /// This grammar without the phrases meaning `meaning`: what is left for
    /// the best *different* answer (none when nothing would be left).
    pub fn without(&self, meaning: Meaning) -> Option<Self> {
        let phrases: Vec<(String, Meaning)> = self
            .phrases
            .iter()
            .filter(|(_, m)| *m != meaning)
            .cloned()
            .collect();
        (!phrases.is_empty()).then_some(Self { phrases })
    }

    /// Every phrase and its meaning.
    pub fn phrases(&self) -> &[(String, Meaning)] {
        &self.phrases
    }

    /// What a recognized phrase means (spacing and case ignored).
    pub fn meaning(&self, said: &str) -> Option<Meaning> {
        let said = said.split_whitespace().collect::<Vec<_>>().join(" ");
        let said = said.to_lowercase();
        self.phrases
            .iter()
            .find(|(p, _)| *p == said)
            .map(|(_, m)| *m)
    }

    /// The phrase that is said for `meaning` first (its canonical form).
    pub fn phrase_for(&self, meaning: Meaning) -> Option<&str> {
        self.phrases
            .iter()
            .find(|(_, m)| *m == meaning)
            .map(|(p, _)| p.as_str())
    }

    /// The grammar in JSGF, the form pocketsphinx reads.
    pub fn jsgf(&self) -> String {
        let alternatives: Vec<String> =
            self.phrases.iter().map(|(p, _)| format!("({p})")).collect();
        format!(
            "#JSGF V1.0;\ngrammar hil;\npublic <answer> = {};\n",
            alternatives.join(" | ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::{Context, Item, QueryKind};

    fn query(response: ResponseType, names: &[&str]) -> Query {
        Query::new(
            1,
            Item::new(0, "banana"),
            QueryKind {
                response,
                ..Default::default()
            },
            hil_core::ActionSpace::new(names.iter().copied()).unwrap(),
            Context::new(vec![0.0]).unwrap(),
        )
    }

    #[test]
    fn names_are_said_as_letters_and_number_words() {
        assert_eq!(spoken_name("VS90"), "v s ninety");
        assert_eq!(spoken_name("TA0"), "t a zero");
        assert_eq!(spoken_name("left_side"), "left side");
        assert_eq!(spoken_name("Left"), "left");
        assert_eq!(spoken_name("arm12345"), "arm one two three four five");
        assert_eq!(number_words(215), "two hundred fifteen");
        assert_eq!(number_words(40), "forty");
    }

    #[test]
    fn every_choice_has_its_name_number_and_short_forms() {
        let g = Grammar::for_query(&query(ResponseType::Mcq, &["VS0", "VS90", "TA0"]));
        assert_eq!(g.meaning("v s ninety"), Some(Meaning::Choice(1)));
        assert_eq!(g.meaning("  Option   three "), Some(Meaning::Choice(2)));
        assert_eq!(g.meaning("number one"), Some(Meaning::Choice(0)));
        assert_eq!(g.meaning("two"), Some(Meaning::Choice(1)));
        assert_eq!(g.meaning("i don't know"), Some(Meaning::DontKnow));
        assert_eq!(g.meaning("skip"), Some(Meaning::Skip));
        assert_eq!(g.meaning("repeat"), Some(Meaning::Repeat));
        assert_eq!(g.meaning("v s"), None);
        assert!(g.jsgf().contains("public <answer> = (v s zero) | (one)"));
    }

    #[test]
    fn a_phrase_two_choices_share_is_dropped() {
        // The action named "two" and the second action's number collide.
        let g = Grammar::for_query(&query(ResponseType::Mcq, &["two", "b"]));
        assert_eq!(g.meaning("two"), None);
        assert_eq!(g.meaning("option two"), Some(Meaning::Choice(1)));
        assert_eq!(g.meaning("option one"), Some(Meaning::Choice(0)));
    }

    #[test]
    fn a_box_is_named_by_its_region() {
        let g = Grammar::for_query(&query(ResponseType::BoundingBox, &["a", "b"]));
        assert_eq!(g.meaning("top right"), Some(Meaning::Region(2)));
        assert_eq!(g.meaning("middle"), Some(Meaning::Region(4)));
        assert_eq!(g.meaning("one"), None);
    }
}
