//! Links the binaries for QEMU's mps2-an386. `memory.x` sits in this folder, the working directory of the
//! linker when this workspace is built, so cortex-m-rt's `link.x` includes it.

use std::{env, path::PathBuf};

fn main() {
    let here = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    println!("cargo:rustc-link-search={}", here.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        println!("cargo:rustc-link-arg-bins=--nmagic");
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        // The controller links the firmware's tasks, which log through defmt.
        println!("cargo:rustc-link-arg-bin=ringpod-qemu-controller=-Tdefmt.x");
    }
}
