//! Gives the shared library its SONAME, `libfraccloth.so.MAJOR`, on ELF platforms, so that a
//! host records the ABI it was linked against and the install can keep several ABIs side by
//! side (`scripts/install.sh` makes the `libfraccloth.so.MAJOR` and `libfraccloth.so` links).
//! MAJOR changes only when the C ABI breaks; fields added by the `struct_size` rule do not
//! break it (include/fraccloth.h, `FcClothDesc`).

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if matches!(
        os.as_str(),
        "linux" | "android" | "freebsd" | "netbsd" | "openbsd" | "dragonfly"
    ) {
        let major = std::env::var("CARGO_PKG_VERSION_MAJOR").unwrap_or_else(|_| "0".into());
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libfraccloth.so.{major}");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
