//! # hil-plugin
//!
//! The plugin host of **hil**: policies, environments, workload models and
//! query channels shipped as shared libraries and loaded at run time. This
//! crate owns the plugin ABI, [`declare_plugin!`], the loader, the panic
//! guards, the registrar and the registry, and the config component
//! ([`PluginComponent`]) through which a config names a plugin type.
//!
//! Rust has no stable ABI, and typetag's registry does not cross a `dlopen`
//! boundary (each library carries its own copy). So a plugin is a `cdylib`
//! that exports one [`PluginDeclaration`] made by [`declare_plugin!`](crate::declare_plugin):
//!
//! 1. a header read before anything else is trusted: a magic tag and the
//!    [`ABI_VERSION`], then the panic strategy, hil-core version, rustc
//!    version, target triple, build profile and a fingerprint of the layouts
//!    of the types that cross the boundary, captured at build time. A
//!    plugin is refused, with both sides' values, unless all of them equal
//!    the host's;
//! 2. a `register` function that adds named factories to a host-owned
//!    registrar ([`Registrar`]), for any of the four traits. Factories take
//!    their parameters as a TOML or JSON text ([`Params`]) plus a context:
//!    a [`TaskContext`](hil_config::TaskContext) (the built environment's
//!    action space, context dimension and pretraining data, with the
//!    build context) for policies and query channels, a
//!    [`BuildContext`](hil_config::BuildContext) (base directory, seed,
//!    build memo) for environments and workload models.
//!
//! Every factory and every method of every object a plugin returns runs
//! under a panic guard compiled into the plugin ([`GuardedPolicy`] and
//! friends), so a panicking plugin yields a [`HilError::Plugin`](hil_core::HilError::Plugin) and the
//! host carries on. Libraries are never unloaded, so objects never outlive
//! their code; loading the same library twice is harmless.
//!
//! A plugin crate (`crate-type = ["cdylib", "rlib"]`):
//!
//! ```
//! use hil_plugin::{Params, Registrar};
//! use hil_conformance::fixtures::CountingWorkload;
//!
//! fn register(r: &mut Registrar<'_>) {
//!     r.workload_model("step_per_query", "WL_0 plus a step per query", |p: &Params, _ctx| {
//!         #[derive(serde::Deserialize)]
//!         #[serde(deny_unknown_fields)]
//!         struct P { step: f64 }
//!         let p: P = p.parse("step_per_query")?;
//!         Ok(Box::new(CountingWorkload::new(p.step)))
//!     });
//! }
//!
//! hil_plugin::declare_plugin!(register);
//! # fn main() {}
//! ```
//!
//! The host: [`load`] a library (or name it in an experiment's `plugins`),
//! then build its types by name, or write `type = "step_per_query"` in a
//! config section. See `PLUGINS.md` at the repository root for the whole
//! path from `cargo new` to `hil plugins check`.
//!
//! Constraints on plugins: built with the host's toolchain, hil-core
//! version and profile (checked), `panic = "unwind"` (checked), and the
//! default global allocator on both sides (objects allocated in the plugin
//! are freed by the host).

// Only the plugin loader may use `unsafe` (it allows it locally).
#![deny(unsafe_code)]

mod abi;
mod builtin;
mod component;
mod guard;
#[cfg(feature = "plugin-loader")]
mod loader;
mod registrar;
mod registry;

pub use abi::{
    ABI_VERSION, BuildFacts, DECLARATION_SYMBOL, FIXED_STR_LEN, FixedStr, MAGIC, PluginDeclaration,
    PluginHeader, RegisterFn, interface_layout,
};
pub use builtin::builtin_types;
pub use component::{KindOf, PluginComponent, component, optional_component};
pub use guard::{
    DropPanicSink, Guarded, GuardedChannel, GuardedEnvironment, GuardedPolicy, GuardedWorkload,
    call as call_guarded, panicked_in, report_drop_panic, take_destructor_panics,
    take_destructor_panics_on_this_thread,
};
pub use registrar::{
    ComponentKind, EnvironmentFactory, Factory, ParamFormat, Params, PluginRegistrar,
    PolicyFactory, QueryChannelFactory, Registrar, WorkloadModelFactory,
};
pub use registry::{
    ComponentInfo, PluginInfo, build_environment, build_policy, build_query_channel,
    build_workload_model, closest, components, is_registered, libraries, register_static,
};

#[doc(hidden)]
pub use registrar::run_register as __run_register;

pub use guard::panic_message;

use std::path::Path;

use hil_core::error::Result;

/// Loads the plugin library at `path` into this process (once; loading it
/// again returns the same [`PluginInfo`]) and registers its types.
///
/// Errors ([`HilError::Plugin`](hil_core::HilError::Plugin), naming the file):
/// the file is missing; it is not a shared library or exports no hil
/// declaration; its ABI version, hil-core version, rustc version, target or
/// build profile differs from the host's (both values named); it was built
/// with `panic = "abort"`; it registers a name that is already taken; its
/// registration panics.
///
/// ```
/// let e = hil_plugin::load(std::path::Path::new("no/such/libplugin.so")).unwrap_err();
/// assert!(e.to_string().contains("no such file"));
/// ```
pub fn load(path: &Path) -> Result<PluginInfo> {
    #[cfg(feature = "plugin-loader")]
    {
        loader::load(path)
    }
    #[cfg(not(feature = "plugin-loader"))]
    {
        Err(hil_core::HilError::Plugin {
            path: path.to_path_buf(),
            why:
                "this build of hil-plugin cannot load plugins (its `plugin-loader` feature is off)"
                    .into(),
        })
    }
}

/// Declares a plugin: exports the [`PluginDeclaration`] whose `register`
/// calls `$register` (a `fn(&mut Registrar<'_>)`) under a panic guard.
/// Use it once per `cdylib` crate.
#[macro_export]
macro_rules! declare_plugin {
    ($register:path) => {
        $crate::__declare_plugin_with!(
            $register,
            $crate::ABI_VERSION,
            $crate::BuildFacts::current()
        );
    };
}

/// [`declare_plugin!`] with explicit versions: only for testing that hosts
/// refuse mismatched plugins.
#[doc(hidden)]
#[macro_export]
macro_rules! __declare_plugin_with {
    ($register:path, $abi:expr, $build:expr) => {
        #[doc(hidden)]
        #[allow(unsafe_code)]
        #[unsafe(no_mangle)]
        pub static HIL_PLUGIN_DECLARATION: $crate::PluginDeclaration = {
            fn __hil_plugin_register(
                host: &mut dyn $crate::PluginRegistrar,
            ) -> ::std::result::Result<(), ::std::string::String> {
                $crate::__run_register(host, $register)
            }
            $crate::PluginDeclaration::with_versions(
                __hil_plugin_register,
                cfg!(panic = "unwind"),
                $abi,
                $build,
            )
        };
    };
}
