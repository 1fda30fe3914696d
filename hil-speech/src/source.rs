//! Where the answer's audio comes from. Every source hands over raw
//! samples at its own rate; from there on ([`crate::listen`]) audio from a
//! microphone and audio from a file take the same path: resampling to
//! 16 kHz, finding the utterance, clipping checks, recognition.

use std::io::Read;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

use hil_core::{HilError, Query, Result};

use crate::audio::Audio;

/// A stream of samples for one answer (one turn of listening).
pub trait AudioStream: Send {
    /// Its sample rate.
    fn rate(&self) -> u32;
    /// The next samples (mono, [-1, 1]); `None` at the end of the stream.
    fn next_chunk(&mut self) -> Result<Option<Vec<f32>>>;
}

/// Opens a stream each time the channel listens for an answer.
pub trait AudioSource: Send + std::fmt::Debug {
    /// Starts listening for the answer to `query` (attempt 0 is the first
    /// ask). A device ignores both; a scripted listener (tests, the bench)
    /// answers from them.
    fn open(&mut self, query: &Query, attempt: usize) -> Result<Box<dyn AudioStream>>;
}

/// Audio held in memory, handed out in 20 ms chunks.
#[derive(Debug)]
pub struct MemoryStream {
    audio: Audio,
    at: usize,
}

impl MemoryStream {
    /// A stream of `audio`.
    pub fn new(audio: Audio) -> Self {
        Self { audio, at: 0 }
    }
}

impl AudioStream for MemoryStream {
    fn rate(&self) -> u32 {
        self.audio.rate
    }
    fn next_chunk(&mut self) -> Result<Option<Vec<f32>>> {
        if self.at >= self.audio.samples.len() {
            return Ok(None);
        }
        let n = (self.audio.rate as usize / 50).max(1);
        let end = (self.at + n).min(self.audio.samples.len());
        let chunk = self.audio.samples[self.at..end].to_vec();
        self.at = end;
        Ok(Some(chunk))
    }
}

/// Replays WAV files, one per turn, in order (a recorded session, a test).
/// When the files run out, each turn hears nothing. Each file is heard
/// after [`REPLAY_LEAD_S`] of silence: the detector learns the background
/// from the first frames, as it does from a microphone that was open
/// before the person spoke; a file that starts on its first word would
/// otherwise teach it that the word is the background.
#[derive(Debug)]
pub struct FileSource {
    files: std::collections::VecDeque<PathBuf>,
}

impl FileSource {
    /// A source that plays `files` in order.
    pub fn new(files: impl IntoIterator<Item = PathBuf>) -> Self {
        Self {
            files: files.into_iter().collect(),
        }
    }
}

/// Silence heard before each replayed file, in seconds.
pub const REPLAY_LEAD_S: f64 = 0.3;

impl AudioSource for FileSource {
    fn open(&mut self, _query: &Query, _attempt: usize) -> Result<Box<dyn AudioStream>> {
        let audio = match self.files.pop_front() {
            Some(path) => {
                let a = Audio::read_wav(&path)?;
                let mut samples = vec![0.0; (REPLAY_LEAD_S * f64::from(a.rate)) as usize];
                samples.extend_from_slice(&a.samples);
                Audio {
                    rate: a.rate,
                    samples,
                }
            }
            None => Audio {
                rate: crate::audio::RECOGNIZER_RATE,
                samples: Vec::new(),
            },
        };
        Ok(Box::new(MemoryStream::new(audio)))
    }
}

/// Captures from an ALSA device with `arecord` (Debian's `alsa-utils`):
/// 16-bit mono at `rate` Hz, for at most `seconds` per turn.
#[derive(Debug, Clone)]
pub struct DeviceSource {
    /// The ALSA capture device (`arecord -L` lists them), e.g. `default`
    /// or `plughw:1,0`.
    pub device: String,
    /// Capture rate (resampled to 16 kHz after capture).
    pub rate: u32,
    /// Longest turn, in seconds.
    pub seconds: u32,
}

/// The error of a device that cannot be opened: names it and says how to
/// list the devices.
pub fn device_error(device: &str, why: &str) -> HilError {
    HilError::channel(
        "speech",
        format!(
            "cannot open audio capture device `{device}`: {why} (list capture devices with \
             `arecord -L`, or `arecord -l` for hardware cards; set `device` in the [channel] \
             config)"
        ),
    )
}

struct DeviceStream {
    child: Child,
    rate: u32,
    device: String,
}

impl AudioStream for DeviceStream {
    fn rate(&self) -> u32 {
        self.rate
    }
    fn next_chunk(&mut self) -> Result<Option<Vec<f32>>> {
        let Some(out) = self.child.stdout.as_mut() else {
            return Ok(None);
        };
        let mut buf = vec![0u8; (self.rate as usize / 50) * 2];
        let mut filled = 0;
        while filled < buf.len() {
            match out.read(&mut buf[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(device_error(&self.device, &e.to_string())),
            }
        }
        if filled == 0 {
            return Ok(None);
        }
        Ok(Some(
            buf[..filled - filled % 2]
                .chunks_exact(2)
                .map(|b| f32::from(i16::from_le_bytes([b[0], b[1]])) / 32768.0)
                .collect(),
        ))
    }
}

impl Drop for DeviceStream {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl DeviceSource {
    /// `arecord` on the device: raw 16-bit mono at the capture rate, for at
    /// most `seconds`.
    fn arecord(&self, seconds: u32) -> Command {
        let mut c = Command::new("arecord");
        c.args([
            "-q",
            "-D",
            &self.device,
            "-f",
            "S16_LE",
            "-c",
            "1",
            "-t",
            "raw",
        ])
        .arg("-r")
        .arg(self.rate.to_string())
        .arg("-d")
        .arg(seconds.to_string());
        c
    }

    fn cannot_run(&self, e: std::io::Error) -> HilError {
        device_error(
            &self.device,
            &format!("cannot run arecord ({e}); run scripts/setup-speech"),
        )
    }

    /// Checks that the device opens (arecord records 0.1 s), so that a
    /// missing device is reported when the channel is built, not at the
    /// first question.
    pub fn probe(&self) -> Result<()> {
        let out = self
            .arecord(1)
            .arg("-s")
            .arg((self.rate / 10).to_string())
            .stdout(Stdio::null())
            .output()
            .map_err(|e| self.cannot_run(e))?;
        if !out.status.success() {
            return Err(device_error(
                &self.device,
                String::from_utf8_lossy(&out.stderr).trim(),
            ));
        }
        Ok(())
    }
}

impl AudioSource for DeviceSource {
    fn open(&mut self, _query: &Query, _attempt: usize) -> Result<Box<dyn AudioStream>> {
        let mut child = self
            .arecord(self.seconds)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| self.cannot_run(e))?;
        // A device that fails to open makes arecord exit at once, with
        // nothing on stdout: report its reason rather than silence.
        std::thread::sleep(std::time::Duration::from_millis(50));
        if let Ok(Some(status)) = child.try_wait()
            && !status.success()
        {
            let mut why = String::new();
            if let Some(e) = child.stderr.as_mut() {
                let _ = e.read_to_string(&mut why);
            }
            return Err(device_error(&self.device, why.trim()));
        }
        Ok(Box::new(DeviceStream {
            child,
            rate: self.rate,
            device: self.device.clone(),
        }))
    }
}
