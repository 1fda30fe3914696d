//! Captures the facts a plugin handshake compares (rustc version, target
//! triple, build profile) at build time, so a host and a plugin built
//! differently refuse each other instead of misreading each other's types.

use std::process::Command;

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(&rustc)
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown rustc".into());
    let target = std::env::var("TARGET").unwrap_or_else(|_| "unknown".into());
    let profile = std::env::var("PROFILE").unwrap_or_else(|_| "unknown".into());
    println!("cargo:rustc-env=HIL_PLUGIN_RUSTC_VERSION={version}");
    println!("cargo:rustc-env=HIL_PLUGIN_TARGET={target}");
    println!("cargo:rustc-env=HIL_PLUGIN_PROFILE={profile}");
    println!("cargo:rerun-if-env-changed=RUSTC");
    println!("cargo:rerun-if-changed=build.rs");
}
