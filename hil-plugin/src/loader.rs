//! Opening a plugin library: the only `unsafe` code in hil.
//!
//! Loading runs the library's initialisers and reading its declaration
//! trusts that a symbol named [`DECLARATION_SYMBOL`] is a
//! [`PluginHeader`]. Everything after that is checked before it is used: the
//! magic tag and the ABI version first (their layout never changes), then
//! the panic strategy and the build facts, and only when all agree is the
//! rest of the declaration read and its `register` function called.
//!
//! Libraries are never unloaded: objects built by a plugin hold vtables and
//! code inside it, so the library must outlive them all, and leaking is the
//! simplest way to be sure it does.

use std::path::Path;

use super::abi::{
    ABI_VERSION, BuildFacts, DECLARATION_SYMBOL, MAGIC, PluginDeclaration, PluginHeader,
};
use super::registry::{self, HostRegistrar, PluginInfo};
use hil_core::error::{HilError, Result};

fn refuse(path: &Path, why: impl Into<String>) -> HilError {
    HilError::Plugin {
        path: path.to_path_buf(),
        why: why.into(),
    }
}

/// Loads the plugin at `path` into this process's registry, or returns
/// what it registered if it is already loaded (by canonical path).
pub fn load(path: &Path) -> Result<PluginInfo> {
    if !path.exists() {
        return Err(refuse(path, "no such file"));
    }
    let canonical = path
        .canonicalize()
        .map_err(|e| HilError::io("resolving", path, e))?;
    let _load = registry::LOAD_LOCK
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(info) = registry::loaded(&canonical) {
        return Ok(info);
    }
    let path = canonical.as_path();
    let library = open(path)?;
    // From here on the library stays mapped for the life of the process.
    let library: &'static libloading::Library = Box::leak(Box::new(library));
    let declaration = handshake(path, library)?;
    let mut host = HostRegistrar::new(path.to_path_buf());
    (declaration.register)(&mut host)
        .map_err(|msg| refuse(path, format!("registration panicked: {msg}")))?;
    host.commit(declaration.header.abi_version, &declaration.header.build)
}

#[allow(unsafe_code)]
fn open(path: &Path) -> Result<libloading::Library> {
    // SAFETY: loading runs the library's initialisers; a library named as a
    // plugin is trusted to that extent (as any dependency is). Nothing in it
    // is called until the handshake has passed.
    unsafe { libloading::Library::new(path) }
        .map_err(|e| refuse(path, format!("cannot be loaded as a shared library: {e}")))
}

/// Reads and checks the declaration, returning it once everything matches.
#[allow(unsafe_code)]
fn handshake(
    path: &Path,
    library: &'static libloading::Library,
) -> Result<&'static PluginDeclaration> {
    let not_plugin = || {
        refuse(
            path,
            format!(
                "not a hil plugin: it exports no `{DECLARATION_SYMBOL}` (declare one with hil_plugin::declare_plugin!)"
            ),
        )
    };
    // SAFETY: the symbol, if present, is the address of a static; we only
    // take its address here.
    let symbol = unsafe { library.get::<*const PluginHeader>(DECLARATION_SYMBOL.as_bytes()) }
        .map_err(|_| not_plugin())?;
    let header_ptr: *const PluginHeader = *symbol;
    if header_ptr.is_null() {
        return Err(not_plugin());
    }
    // SAFETY: the magic tag and ABI version are the first 12 bytes of every
    // declaration of every ABI version: reading them is valid for any hil
    // plugin, and the magic tag tells a hil plugin from a stranger.
    let (magic, abi) = unsafe {
        (
            std::ptr::addr_of!((*header_ptr).magic).read_unaligned(),
            std::ptr::addr_of!((*header_ptr).abi_version).read_unaligned(),
        )
    };
    if magic != MAGIC {
        return Err(refuse(
            path,
            format!(
                "not a hil plugin: `{DECLARATION_SYMBOL}` does not start with the hil magic tag"
            ),
        ));
    }
    if abi != ABI_VERSION {
        return Err(refuse(
            path,
            format!(
                "plugin ABI version mismatch: the plugin declares ABI version {abi}, this host speaks ABI version {ABI_VERSION}; rebuild the plugin against hil-core {}",
                hil_core::VERSION
            ),
        ));
    }
    // SAFETY: same ABI version, so the whole declaration has this layout.
    let declaration: &'static PluginDeclaration =
        unsafe { &*header_ptr.cast::<PluginDeclaration>() };
    check_header(path, &declaration.header)?;
    Ok(declaration)
}

/// Compares the build facts and the panic strategy with the host's.
fn check_header(path: &Path, header: &PluginHeader) -> Result<()> {
    if header.panic_unwind != 1 {
        return Err(refuse(
            path,
            "the plugin was built with panic = \"abort\": a panic in it would abort the host; build it with panic = \"unwind\"",
        ));
    }
    let host = BuildFacts::current().fields();
    let plugin = header.build.fields();
    let mismatches: Vec<String> = host
        .iter()
        .zip(plugin.iter())
        .filter(|(h, p)| h.1 != p.1)
        .map(|(h, p)| format!("{}: plugin {:?}, host {:?}", h.0, p.1, h.1))
        .collect();
    if mismatches.is_empty() {
        return Ok(());
    }
    let differs = |name: &str| {
        host.iter()
            .zip(plugin.iter())
            .any(|(h, p)| h.0 == name && h.1 != p.1)
    };
    let mut fixes = Vec::new();
    if differs("build profile") {
        let release = BuildFacts::current().profile.to_string_lossy() == "release";
        fixes.push(if release {
            "this host is a release build: build the plugin with `cargo build --release`"
        } else {
            "this host is a debug build: build the plugin with `cargo build` (no --release)"
        });
    }
    if differs("rustc version") {
        fixes.push("build the plugin with the host's rustc (see `rustup show`; pin it in rust-toolchain.toml)");
    }
    if differs("hil-core version") {
        fixes.push("depend on the host's hil-core (the same path or git revision)");
    }
    if differs("interface layout") {
        fixes.push(
            "the types that cross the boundary are laid out differently although the versions agree: the plugin resolved other versions or features of hil-core's dependencies (serde_json, ...); build it with the host's Cargo.lock (copy it next to the plugin's Cargo.toml) or inside the host's workspace",
        );
    }
    Err(refuse(
        path,
        format!(
            "version mismatch ({}); Rust has no stable ABI, so a plugin must be built exactly like its host: {}. `hil plugins abi` prints the host's build facts",
            mismatches.join("; "),
            fixes.join("; ")
        ),
    ))
}
