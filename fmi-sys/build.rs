fn main() {
    println!("cargo:rerun-if-changed=csrc/logger.c");
    println!("cargo:rerun-if-changed=build.rs");
    // The logger shim is the importer's (feature `import`); an FMU links only the types.
    #[cfg(feature = "import")]
    cc::Build::new().file("csrc/logger.c").warnings(true).compile("fmi2_sys_logger");
}
