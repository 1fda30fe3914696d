//! A shared library that is not a hil plugin: it exports a function, but no
//! hil declaration.

/// Something to export.
#[unsafe(no_mangle)]
pub extern "C" fn not_a_hil_plugin() -> u32 {
    7
}
