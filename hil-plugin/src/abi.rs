//! The declaration a plugin exports, and the build facts it is checked against.
//!
//! Layout rule: [`PluginHeader`] starts with a magic tag and the ABI version,
//! both plain `#[repr(C)]` integers, so that any host can read them from any
//! plugin, old or new. Everything after them may change from one ABI version
//! to the next and is only read once the versions agree.

use super::registrar::PluginRegistrar;

/// Version of the plugin ABI: the layout of [`PluginDeclaration`], the
/// [`PluginRegistrar`] trait and the factory signatures. Bumped on any change.
///
/// - 2: [`PluginRegistrar::drop_panic_sink`] (destructor panics reach the host);
/// - 1: the first.
pub const ABI_VERSION: u32 = 2;

// The header's first fields must never move: hosts of every ABI version read
// them from plugins of every other.
const _: () = assert!(std::mem::offset_of!(PluginHeader, magic) == 0);
const _: () = assert!(std::mem::offset_of!(PluginHeader, abi_version) == 8);

/// The symbol every plugin exports (see [`crate::declare_plugin!`]).
pub const DECLARATION_SYMBOL: &str = "HIL_PLUGIN_DECLARATION";

/// The first bytes of every declaration: tells a hil plugin from a library
/// that merely happens to export a symbol of the same name.
pub const MAGIC: [u8; 8] = *b"HILPLUG\0";

/// Capacity of a [`FixedStr`]; longer strings are truncated.
pub const FIXED_STR_LEN: usize = 120;

/// A string stored inline, NUL-padded: no pointers, so the declaration is a
/// plain constant readable before anything else is trusted.
#[derive(Clone, Copy)]
#[repr(C)]
pub struct FixedStr {
    bytes: [u8; FIXED_STR_LEN],
}

impl FixedStr {
    /// Stores `s` (truncated to [`FIXED_STR_LEN`] bytes). Usable in constants.
    pub const fn new(s: &str) -> Self {
        let src = s.as_bytes();
        let mut bytes = [0u8; FIXED_STR_LEN];
        let mut i = 0;
        while i < src.len() && i < FIXED_STR_LEN {
            bytes[i] = src[i];
            i += 1;
        }
        Self { bytes }
    }

    /// The stored text (up to the first NUL; invalid UTF-8 replaced).
    pub fn to_string_lossy(&self) -> String {
        let end = self
            .bytes
            .iter()
            .position(|b| *b == 0)
            .unwrap_or(FIXED_STR_LEN);
        String::from_utf8_lossy(&self.bytes[..end]).into_owned()
    }
}

impl std::fmt::Debug for FixedStr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.to_string_lossy())
    }
}

/// The version-independent head of a plugin declaration.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct PluginHeader {
    /// Always [`MAGIC`].
    pub magic: [u8; 8],
    /// The plugin's [`ABI_VERSION`]; checked before anything after it is read.
    pub abi_version: u32,
    /// Whether the plugin was compiled with `panic = "unwind"`: with `abort`
    /// a panic would kill the host before any guard could catch it.
    pub panic_unwind: u32,
    /// The rest of the build facts, in a layout fixed by `abi_version`.
    pub build: BuildFacts,
}

/// How a plugin (or the host) was built. Rust has no stable ABI, so a plugin
/// is only called when every one of these equals the host's.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct BuildFacts {
    /// Version of the hil-core crate the plugin was compiled against.
    pub hil_core_version: FixedStr,
    /// `rustc --version` of the compiler.
    pub rustc_version: FixedStr,
    /// Target triple.
    pub target: FixedStr,
    /// Cargo profile hil-plugin was built with (`debug` or `release`).
    pub profile: FixedStr,
    /// A fingerprint of the sizes and alignments of every type that crosses
    /// the boundary, see [`interface_layout`]. Catches a plugin whose
    /// dependencies (e.g. serde_json's version or features) lay those types
    /// out differently even though the versions above agree.
    pub interface_layout: u64,
}

/// FNV-1a over the size and alignment of every type passed between host
/// and plugin (arguments, results, errors, registrar values).
pub const fn interface_layout() -> u64 {
    use std::mem::{align_of, size_of};
    macro_rules! layouts {
        ($($t:ty),* $(,)?) => {
            [$((size_of::<$t>(), align_of::<$t>())),*]
        };
    }
    let layouts = layouts![
        hil_core::HilError,
        hil_core::Result<()>,
        serde_json::Value,
        hil_config::BuildContext,
        hil_config::TaskContext,
        hil_core::Context,
        hil_core::ActionSpace,
        hil_core::Item,
        hil_core::Query,
        hil_core::Response,
        hil_core::Decision,
        hil_core::Outcome,
        hil_core::DecisionInput<'static>,
        hil_core::Feedback<'static>,
        hil_core::QueryHistory,
        hil_core::QueryKind,
        hil_core::LabelledObservation,
        super::registrar::Params,
        super::registrar::Factory,
        Box<dyn hil_core::Policy>,
        std::path::PathBuf,
    ];
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut i = 0;
    while i < layouts.len() {
        let words = [layouts[i].0 as u64, layouts[i].1 as u64];
        let mut w = 0;
        while w < 2 {
            let mut b = 0;
            while b < 8 {
                hash ^= (words[w] >> (8 * b)) & 0xff;
                hash = hash.wrapping_mul(0x0100_0000_01b3);
                b += 1;
            }
            w += 1;
        }
        i += 1;
    }
    hash
}

impl BuildFacts {
    /// The facts of this build of hil-plugin (the host's, or a plugin's own copy).
    pub const fn current() -> Self {
        Self {
            hil_core_version: FixedStr::new(hil_core::VERSION),
            rustc_version: FixedStr::new(env!("HIL_PLUGIN_RUSTC_VERSION")),
            target: FixedStr::new(env!("HIL_PLUGIN_TARGET")),
            profile: FixedStr::new(env!("HIL_PLUGIN_PROFILE")),
            interface_layout: interface_layout(),
        }
    }

    /// The facts as `(name, value)` pairs, in the order they are checked.
    pub fn fields(&self) -> [(&'static str, String); 5] {
        [
            ("hil-core version", self.hil_core_version.to_string_lossy()),
            ("rustc version", self.rustc_version.to_string_lossy()),
            ("target", self.target.to_string_lossy()),
            ("build profile", self.profile.to_string_lossy()),
            (
                "interface layout",
                format!("{:016x}", self.interface_layout),
            ),
        ]
    }
}

/// The function a plugin's declaration points at: registers its factories.
/// Returns the panic message if registration panicked (caught plugin-side).
pub type RegisterFn = fn(&mut dyn PluginRegistrar) -> Result<(), String>;

/// What [`crate::declare_plugin!`] exports under [`DECLARATION_SYMBOL`].
#[derive(Clone, Copy)]
#[repr(C)]
pub struct PluginDeclaration {
    /// Read first, before anything else is trusted.
    pub header: PluginHeader,
    /// Called once, and only when the whole header matches the host.
    pub register: RegisterFn,
}

impl std::fmt::Debug for PluginDeclaration {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PluginDeclaration")
            .field("header", &self.header)
            .finish_non_exhaustive()
    }
}

impl PluginDeclaration {
    /// A declaration of this build, registering with `register`. Used by
    /// [`crate::declare_plugin!`].
    pub const fn new(register: RegisterFn, panic_unwind: bool) -> Self {
        Self::with_versions(register, panic_unwind, ABI_VERSION, BuildFacts::current())
    }

    /// A declaration with explicit versions. Only for testing how hosts
    /// refuse mismatched plugins.
    #[doc(hidden)]
    pub const fn with_versions(
        register: RegisterFn,
        panic_unwind: bool,
        abi_version: u32,
        build: BuildFacts,
    ) -> Self {
        Self {
            header: PluginHeader {
                magic: MAGIC,
                abi_version,
                panic_unwind: panic_unwind as u32,
                build,
            },
            register,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_strings_round_trip_and_truncate() {
        assert_eq!(FixedStr::new("1.2.3").to_string_lossy(), "1.2.3");
        let long = "x".repeat(FIXED_STR_LEN + 10);
        assert_eq!(FixedStr::new(&long).to_string_lossy().len(), FIXED_STR_LEN);
    }

    #[test]
    fn build_facts_are_captured() {
        let f = BuildFacts::current();
        assert_eq!(f.hil_core_version.to_string_lossy(), hil_core::VERSION);
        assert!(f.rustc_version.to_string_lossy().starts_with("rustc "));
        assert!(!f.target.to_string_lossy().is_empty());
        assert!(["debug", "release"].contains(&f.profile.to_string_lossy().as_str()));
    }
}
