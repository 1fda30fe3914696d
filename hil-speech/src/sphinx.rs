//! The offline recognizer: Debian's pocketsphinx (5prealpha) through a small
//! FFI, decoding an utterance restricted to the query's grammar (JSGF). The
//! best path is what was said (how sure the recognizer is comes from
//! comparing decodings: `crate::recognize`). (A free phone loop as a
//! second, out-of-grammar pass was tried: Debian's allphone search took
//! about 5 s of CPU per second of audio here, far over the latency budget.)

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::ptr::NonNull;

use hil_core::{HilError, Result};

#[allow(non_camel_case_types)]
type ps_decoder_t = c_void;
#[allow(non_camel_case_types)]
type cmd_ln_t = c_void;
#[allow(non_camel_case_types)]
type arg_t = c_void;

unsafe extern "C" {
    fn ps_args() -> *const arg_t;
    fn cmd_ln_parse_r(
        inout: *mut cmd_ln_t,
        defn: *const arg_t,
        argc: i32,
        argv: *mut *mut c_char,
        strict: i32,
    ) -> *mut cmd_ln_t;
    fn cmd_ln_free_r(cmdln: *mut cmd_ln_t) -> c_int;
    fn ps_init(config: *mut cmd_ln_t) -> *mut ps_decoder_t;
    fn ps_free(ps: *mut ps_decoder_t) -> c_int;
    fn ps_set_jsgf_string(ps: *mut ps_decoder_t, name: *const c_char, jsgf: *const c_char)
    -> c_int;
    fn ps_get_prob(ps: *mut ps_decoder_t) -> i32;
    fn ps_set_search(ps: *mut ps_decoder_t, name: *const c_char) -> c_int;
    fn ps_start_stream(ps: *mut ps_decoder_t) -> c_int;
    fn ps_start_utt(ps: *mut ps_decoder_t) -> c_int;
    fn ps_process_raw(
        ps: *mut ps_decoder_t,
        data: *const i16,
        n_samples: usize,
        no_search: c_int,
        full_utt: c_int,
    ) -> c_int;
    fn ps_end_utt(ps: *mut ps_decoder_t) -> c_int;
    fn ps_get_hyp(ps: *mut ps_decoder_t, out_best_score: *mut i32) -> *const c_char;
    fn ps_get_n_frames(ps: *mut ps_decoder_t) -> c_int;
    fn ps_get_feat(ps: *mut ps_decoder_t) -> *mut FeatHead;
    fn cmn_live_set(cmn: *mut CmnState, vec: *const f32);
}

/// The leading fields of sphinxbase's `feat_t` (feat.h, 5prealpha), up to
/// the CMN state: the decoder exposes no other way to reset it. `Sphinx::new`
/// checks the layout against what it must hold before using it.
#[repr(C)]
#[allow(dead_code)] // every field is there for the layout, few are read
struct FeatHead {
    refcount: c_int,
    name: *mut c_char,
    cepsize: i32,
    n_stream: i32,
    stream_len: *mut u32,
    window_size: i32,
    n_sv: i32,
    sv_len: *mut u32,
    subvecs: *mut *mut i32,
    sv_buf: *mut f32,
    sv_dim: i32,
    cmn: c_int,
    varnorm: i32,
    agc: c_int,
    compute_feat: *mut c_void,
    cmn_struct: *mut CmnState,
}

/// sphinxbase's `cmn_t` (cmn.h; `mfcc_t` is `float` in Debian's build).
#[repr(C)]
#[allow(dead_code)] // every field is there for the layout, few are read
struct CmnState {
    cmn_mean: *mut f32,
    cmn_var: *mut f32,
    sum: *mut f32,
    nframe: i32,
    veclen: i32,
}

/// sphinxbase's `cmn_type_t`: over the whole utterance, or running.
const CMN_BATCH: c_int = 1;
const CMN_LIVE: c_int = 2;

pub use crate::recognize::DEFAULT_MODEL_DIR;

/// The files of an acoustic model directory laid out as Debian's
/// `pocketsphinx-en-us` lays them out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelFiles {
    /// The acoustic model (a directory).
    pub hmm: PathBuf,
    /// The pronunciation dictionary.
    pub dict: PathBuf,
}

impl ModelFiles {
    /// The files under `dir`; an error naming the first one missing (and the
    /// setup script that installs them).
    pub fn in_dir(dir: &Path) -> Result<Self> {
        let files = Self {
            hmm: dir.join("en-us"),
            dict: dir.join("cmudict-en-us.dict"),
        };
        for p in [&files.hmm, &files.dict] {
            if !p.exists() {
                return Err(HilError::channel(
                    "speech",
                    format!(
                        "the recognizer's model file {} is missing (run scripts/setup-speech, \
                         which installs Debian's pocketsphinx-en-us)",
                        p.display()
                    ),
                ));
            }
        }
        Ok(files)
    }
}

/// One decoding: the grammar's words and their posterior.
#[derive(Clone, Debug, PartialEq)]
pub struct Decoded {
    /// The best hypothesis (empty when nothing matched).
    pub hypothesis: String,
    /// Its path score (log base 1.0001, pocketsphinx's units).
    pub score: i32,
    /// Its posterior probability in the lattice, in [0, 1].
    pub posterior: f64,
    /// Frames (10 ms) decoded.
    pub frames: usize,
}

/// A pocketsphinx decoder with one grammar search (replaced for each
/// query).
#[derive(Debug)]
pub struct Sphinx {
    ps: NonNull<ps_decoder_t>,
    config: NonNull<cmd_ln_t>,
    grammar: Option<String>,
    /// The cepstral mean the model starts from (its `-cmninit`), restored
    /// before every utterance.
    initial_mean: Vec<f32>,
}

// The decoder is used by one thread at a time (`&mut self`), and
// pocketsphinx keeps no thread-local state.
unsafe impl Send for Sphinx {}

const GRAMMAR: &CStr = c"grammar";

fn sphinx_error(what: impl Into<String>) -> HilError {
    HilError::channel("speech", what.into())
}

impl Sphinx {
    /// A decoder on the model files, with pocketsphinx's log silenced and
    /// `options` (pairs such as `["-dither", "yes"]`) after the model's.
    pub fn new(model: &ModelFiles, options: &[&str]) -> Result<Self> {
        let path = |p: &Path| p.to_string_lossy().into_owned();
        let mut args = vec![
            "hil".to_string(),
            "-hmm".into(),
            path(&model.hmm),
            "-dict".into(),
            path(&model.dict),
            "-logfn".into(),
            "/dev/null".into(),
            // pocketsphinx's own voice activity detector keeps its state
            // from one utterance to the next (so a decoding depended on the
            // ones before it); the channel finds the speech itself.
            "-remove_silence".into(),
            "no".into(),
        ];
        args.extend(options.iter().map(|o| o.to_string()));
        let c_args: Vec<CString> = args
            .iter()
            .map(|a| CString::new(a.as_str()).map_err(|_| sphinx_error("a NUL byte in a path")))
            .collect::<Result<_>>()?;
        let mut argv: Vec<*mut c_char> = c_args.iter().map(|a| a.as_ptr().cast_mut()).collect();
        // SAFETY: argv holds argc valid NUL-terminated strings that outlive
        // the call; ps_args() is pocketsphinx's static definition table.
        let config = unsafe {
            cmd_ln_parse_r(
                std::ptr::null_mut(),
                ps_args(),
                argv.len() as i32,
                argv.as_mut_ptr(),
                1,
            )
        };
        let config = NonNull::new(config)
            .ok_or_else(|| sphinx_error("pocketsphinx rejected its configuration"))?;
        // SAFETY: config is a valid cmd_ln_t; ps_init takes its own reference.
        let ps = unsafe { ps_init(config.as_ptr()) };
        let Some(ps) = NonNull::new(ps) else {
            // SAFETY: config came from cmd_ln_parse_r and is freed once.
            unsafe { cmd_ln_free_r(config.as_ptr()) };
            return Err(sphinx_error(format!(
                "pocketsphinx could not load the model in {}",
                model.hmm.display()
            )));
        };
        let mut sphinx = Self {
            ps,
            config,
            grammar: None,
            initial_mean: Vec::new(),
        };
        sphinx.initial_mean = sphinx.cmn_state()?.0;
        Ok(sphinx)
    }

    /// The feature computation's state: the current cepstral mean and
    /// where it lives. An error when the library's `feat_t` is not laid out
    /// as [`FeatHead`] says (another sphinxbase than Debian's 5prealpha).
    fn cmn_state(&mut self) -> Result<(Vec<f32>, NonNull<FeatHead>)> {
        let layout = || sphinx_error("this sphinxbase's feature state is not laid out as expected");
        // SAFETY: valid decoder; the feat_t it returns lives as long as it.
        let feat = NonNull::new(unsafe { ps_get_feat(self.ps.as_ptr()) }).ok_or_else(layout)?;
        // SAFETY: feat_t begins with FeatHead's fields (checked below before
        // any pointer in it is followed beyond the CMN state).
        let head = unsafe { feat.as_ref() };
        if head.cepsize != 13 || head.cmn_struct.is_null() {
            return Err(layout());
        }
        // SAFETY: non-null cmn_t of the decoder.
        let cmn = unsafe { &*head.cmn_struct };
        if cmn.veclen != head.cepsize || cmn.cmn_mean.is_null() {
            return Err(layout());
        }
        // SAFETY: cmn_mean holds veclen floats.
        let mean = unsafe { std::slice::from_raw_parts(cmn.cmn_mean, cmn.veclen as usize) };
        Ok((mean.to_vec(), feat))
    }

    /// Forgets what earlier utterances taught the feature computation:
    /// pocketsphinx carries its running cepstral mean from one utterance to
    /// the next (so the same audio decoded differently after a different
    /// history); it restarts from the model's initial mean instead, and
    /// normalises `whole` utterances over their own length (pocketsphinx
    /// switches the mode to running for good once it decodes live).
    /// (The front end's noise estimate is reset by `ps_start_stream` in
    /// `decode_as`; its voice activity detector is off: see `new`.)
    fn forget_history(&mut self, whole: bool) -> Result<()> {
        let (_, mut feat) = self.cmn_state()?;
        // SAFETY: checked layout; the decoder is not decoding now.
        unsafe {
            let head = feat.as_mut();
            head.cmn = if whole { CMN_BATCH } else { CMN_LIVE };
            cmn_live_set(head.cmn_struct, self.initial_mean.as_ptr());
        }
        Ok(())
    }

    /// Makes `jsgf` the grammar of the next decodings (kept when unchanged).
    pub fn set_grammar(&mut self, jsgf: &str) -> Result<()> {
        if self.grammar.as_deref() == Some(jsgf) {
            return Ok(());
        }
        let c = CString::new(jsgf).map_err(|_| sphinx_error("a NUL byte in the grammar"))?;
        // SAFETY: valid decoder and strings; pocketsphinx copies the grammar.
        if unsafe { ps_set_jsgf_string(self.ps.as_ptr(), GRAMMAR.as_ptr(), c.as_ptr()) } != 0 {
            self.grammar = None;
            return Err(sphinx_error(format!(
                "pocketsphinx rejected the grammar (a word missing from its dictionary?):\n{jsgf}"
            )));
        }
        self.grammar = Some(jsgf.to_string());
        Ok(())
    }

    /// Decodes 16 kHz mono samples with the grammar (set first).
    pub fn decode(&mut self, samples: &[i16]) -> Result<Decoded> {
        self.decode_as(samples, false)
    }

    /// Decodes as a live stream, or (`whole`) as one utterance, which
    /// pocketsphinx normalises over its whole length.
    pub fn decode_as(&mut self, samples: &[i16], whole: bool) -> Result<Decoded> {
        if self.grammar.is_none() {
            return Err(sphinx_error("no grammar was set before decoding"));
        }
        self.forget_history(whole)?;
        let ps = self.ps.as_ptr();
        let search = GRAMMAR;
        // Live (full_utt = 0): features are normalised as they come, as
        // pocketsphinx_continuous does; whole (full_utt = 1): over the whole
        // utterance. The recognizer decodes both ways and wants agreement.
        // SAFETY: valid decoder; `samples` is a live slice of its length.
        unsafe {
            // A new stream: the front end's noise estimate (`-remove_noise`)
            // starts afresh; `ps_start_utt` alone keeps it from the
            // utterances before.
            if ps_set_search(ps, search.as_ptr()) != 0
                || ps_start_stream(ps) != 0
                || ps_start_utt(ps) != 0
            {
                return Err(sphinx_error("pocketsphinx could not start an utterance"));
            }
            if ps_process_raw(ps, samples.as_ptr(), samples.len(), 0, c_int::from(whole)) < 0 {
                ps_end_utt(ps);
                return Err(sphinx_error("pocketsphinx failed to decode the audio"));
            }
            ps_end_utt(ps);
            let mut score = 0i32;
            let hyp = ps_get_hyp(ps, &mut score);
            let text = if hyp.is_null() {
                String::new()
            } else {
                CStr::from_ptr(hyp).to_string_lossy().into_owned()
            };
            let log_posterior = ps_get_prob(ps);
            let posterior = if text.is_empty() {
                0.0
            } else {
                (f64::from(log_posterior) * 1.0001_f64.ln())
                    .exp()
                    .clamp(0.0, 1.0)
            };
            Ok(Decoded {
                hypothesis: text,
                score,
                posterior,
                frames: ps_get_n_frames(ps).max(0) as usize,
            })
        }
    }
}

impl Drop for Sphinx {
    fn drop(&mut self) {
        // SAFETY: both were created in `new` and are freed once here.
        unsafe {
            ps_free(self.ps.as_ptr());
            cmd_ln_free_r(self.config.as_ptr());
        }
    }
}
