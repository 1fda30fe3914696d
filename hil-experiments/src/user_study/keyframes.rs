//! The study with PNG keyframes of its plates: when the study's
//! environment is the MuJoCo scene, every attempt of every study plate
//! (validation plates are not pictured) is recorded and written as
//! `rep<r>_<method>_...png`. Pictures are a by-product: when they cannot be
//! made (no `kinova_feeding` scene, no offscreen context, a failed write)
//! the study runs on without them and says why through `note`.

use std::path::{Path, PathBuf};

use hil_config::BuildContext;
use hil_core::Result;
use hil_kinova_mujoco::{KeyframeRecorder, KeyframeWriter, KinovaFeedingEnv, RenderingEnv};

use super::config::UserStudyConfig;
use super::run::{Plate, UserStudyResult};

/// The keyframes a study run wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Keyframes {
    /// Images written.
    pub written: usize,
    /// Where.
    pub dir: PathBuf,
}

/// A study run and the keyframes it wrote, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct PicturedStudy {
    /// The study's result (the same with or without pictures).
    pub result: UserStudyResult,
    /// The keyframes written (none when rendering was not possible).
    pub keyframes: Option<Keyframes>,
}

impl UserStudyConfig {
    /// Runs the study (as [`UserStudyConfig::run`]), writing PNG keyframes
    /// of its plates into `keyframes` when given and possible. `on_plate`
    /// sees every plate (validation plates too, with repetition 0) before
    /// it runs; `note` is told why pictures are not made.
    pub fn run_pictured(
        &self,
        base_dir: &Path,
        keyframes: Option<&Path>,
        on_plate: &mut dyn FnMut(&Plate),
        note: &mut dyn FnMut(&str),
    ) -> Result<PicturedStudy> {
        let ctx = BuildContext::new(base_dir, self.seed);
        let scene = match keyframes {
            Some(_) => KinovaFeedingEnv::from_component(self.environment.as_ref(), &ctx)?,
            None => None,
        };
        let (Some(dir), Some(mut env)) = (keyframes, scene) else {
            if keyframes.is_some() {
                note(
                    "rendering needs the `kinova_feeding` environment; continuing without pictures",
                );
            }
            let mut env = self.build_environment(base_dir)?;
            let mut study = self.prepare(base_dir, env.as_ref())?;
            let result = study.run_with(
                env.as_mut(),
                |plate, env, episode| {
                    on_plate(plate);
                    episode(env, &mut [])
                },
                |_| {},
            )?;
            return Ok(PicturedStudy {
                result,
                keyframes: None,
            });
        };
        let mut writer = match KeyframeWriter::new(dir, env.simulator()) {
            Ok(w) => Some(w),
            Err(why) => {
                note(&format!(
                    "rendering unavailable ({why}); continuing without pictures"
                ));
                None
            }
        };
        let mut recorder = KeyframeRecorder::default();
        let mut study = self.prepare(base_dir, &env)?;
        let result = study.run_with(
            &mut env,
            |plate, env, episode| {
                on_plate(plate);
                // Validation plates (repetition 0) are not pictured.
                let Some(w) = writer.as_mut().filter(|_| plate.repetition > 0) else {
                    return episode(env, &mut []);
                };
                recorder.set_prefix(format!("rep{}_{}", plate.repetition, slug(&plate.label)));
                let report = episode(&mut RenderingEnv::new(env, &mut recorder), &mut [])?;
                if let Err(why) = w.write(&mut recorder) {
                    note(&format!("{why}; continuing without pictures"));
                    writer = None;
                }
                Ok(report)
            },
            |_| {},
        )?;
        Ok(PicturedStudy {
            result,
            keyframes: writer.map(|w| Keyframes {
                written: w.written(),
                dir: w.dir().to_path_buf(),
            }),
        })
    }
}

/// A label as a file-name part: `LinUCB-QG` becomes `linucb_qg`.
fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slug_is_a_file_name_part() {
        assert_eq!(slug("LinUCB-QG"), "linucb_qg");
        assert_eq!(slug("AlwaysQuery"), "alwaysquery");
        assert_eq!(slug("a b/c"), "a_b_c");
    }
}
