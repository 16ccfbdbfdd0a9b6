//! A check of a shared library's ELF structure before `dlopen`: the loader maps the
//! segments the headers declare, and touching a page past the end of a truncated file
//! raises SIGBUS inside `dlopen`, which kills the process. So every header, program
//! segment and section must lie within the file.

/// The `e_machine` of this build's target.
#[cfg(target_arch = "x86_64")]
const MACHINE: (u16, &str) = (62, "x86-64");
#[cfg(target_arch = "aarch64")]
const MACHINE: (u16, &str) = (183, "AArch64");
#[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
const MACHINE: (u16, &str) = (0, "this machine");

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap_or([0; 4]))
}
fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap_or([0; 8]))
}

/// Whether `[offset, offset + size)` lies within `len` bytes.
fn within(offset: u64, size: u64, len: u64) -> bool {
    offset.checked_add(size).is_some_and(|end| end <= len)
}

/// Checks that `bytes` is a 64-bit little-endian ELF shared object for this machine
/// whose ELF header, program headers, segments, section headers and sections all lie
/// within the file; otherwise says what is wrong.
pub fn check_shared_library(bytes: &[u8]) -> Result<(), String> {
    let len = bytes.len() as u64;
    if bytes.len() < 64 || &bytes[..4] != b"\x7fELF" {
        return Err(format!("not an ELF file ({len} bytes, no ELF header)"));
    }
    if bytes[4] != 2 {
        return Err("a 32-bit ELF file; a 64-bit library is needed".into());
    }
    if bytes[5] != 1 {
        return Err("a big-endian ELF file".into());
    }
    let (machine, ty) = (u16_at(bytes, 18), u16_at(bytes, 16));
    if machine != MACHINE.0 {
        return Err(format!("an ELF file for machine {machine}, not {} (e_machine {})", MACHINE.1, MACHINE.0));
    }
    if ty != 3 {
        return Err(format!("an ELF file of type {ty}, not a shared object (ET_DYN)"));
    }
    let (phoff, phentsize, phnum) = (u64_at(bytes, 32), u64::from(u16_at(bytes, 54)), u64::from(u16_at(bytes, 56)));
    let (shoff, shentsize, shnum) = (u64_at(bytes, 40), u64::from(u16_at(bytes, 58)), u64::from(u16_at(bytes, 60)));
    let truncated = |what: String| {
        Err(format!("{what} extends past the end of the file ({len} bytes): a truncated or corrupt library"))
    };
    if phnum == 0 || phentsize < 56 {
        return Err("an ELF file without program headers".into());
    }
    if !within(phoff, phentsize * phnum, len) {
        return truncated(format!("the program header table (bytes {phoff}..+{})", phentsize * phnum));
    }
    for k in 0..phnum {
        let h = (phoff + k * phentsize) as usize;
        let (p_type, offset, filesz, memsz) =
            (u32_at(bytes, h), u64_at(bytes, h + 8), u64_at(bytes, h + 32), u64_at(bytes, h + 40));
        if !within(offset, filesz, len) {
            return truncated(format!("segment {k} (type {p_type:#x}, bytes {offset}..+{filesz})"));
        }
        if p_type == 1 && filesz > memsz {
            return Err(format!("segment {k}: file size {filesz} larger than its memory size {memsz}"));
        }
    }
    if shoff != 0 && shnum != 0 {
        if shentsize < 64 || !within(shoff, shentsize * shnum, len) {
            return truncated(format!("the section header table (bytes {shoff}..+{})", shentsize * shnum));
        }
        for k in 0..shnum {
            let h = (shoff + k * shentsize) as usize;
            let (sh_type, offset, size) = (u32_at(bytes, h + 4), u64_at(bytes, h + 24), u64_at(bytes, h + 32));
            // SHT_NOBITS (.bss) occupies no bytes of the file
            if sh_type != 8 && !within(offset, size, len) {
                return truncated(format!("section {k} (bytes {offset}..+{size})"));
            }
        }
    }
    Ok(())
}

/// The names of the symbols `bytes` (a library [`check_shared_library`] accepted) defines
/// and exports: global or weak, default or protected visibility, from its dynamic symbol
/// table (`.dynsym`). `None` when the file has no section headers to find it by.
pub fn exported_symbols(bytes: &[u8]) -> Option<std::collections::HashSet<String>> {
    let len = bytes.len() as u64;
    let (shoff, shentsize, shnum) = (u64_at(bytes, 40), u64::from(u16_at(bytes, 58)), u64::from(u16_at(bytes, 60)));
    if shoff == 0 || shnum == 0 || shentsize < 64 || !within(shoff, shentsize * shnum, len) {
        return None;
    }
    let section = |k: u64| {
        let h = (shoff + k * shentsize) as usize;
        // (type, link, offset, size, entry size)
        (
            u32_at(bytes, h + 4),
            u32_at(bytes, h + 40),
            u64_at(bytes, h + 24),
            u64_at(bytes, h + 32),
            u64_at(bytes, h + 56),
        )
    };
    let (_, link, offset, size, entsize) = (0..shnum).map(section).find(|s| s.0 == 11)?; // SHT_DYNSYM
    if u64::from(link) >= shnum || entsize < 24 || !within(offset, size, len) {
        return None;
    }
    let (_, _, str_offset, str_size, _) = section(u64::from(link));
    if !within(str_offset, str_size, len) {
        return None;
    }
    let strings = &bytes[str_offset as usize..(str_offset + str_size) as usize];
    let mut out = std::collections::HashSet::new();
    for k in 1..size / entsize {
        let e = (offset + k * entsize) as usize;
        let (name, info, other, shndx) = (u32_at(bytes, e) as usize, bytes[e + 4], bytes[e + 5], u16_at(bytes, e + 6));
        let (bind, visibility) = (info >> 4, other & 3);
        // defined (not SHN_UNDEF), STB_GLOBAL or STB_WEAK, STV_DEFAULT or STV_PROTECTED
        if shndx == 0 || !(bind == 1 || bind == 2) || !(visibility == 0 || visibility == 3) || name >= strings.len() {
            continue;
        }
        let end = strings[name..].iter().position(|b| *b == 0).map_or(strings.len(), |p| name + p);
        out.insert(String::from_utf8_lossy(&strings[name..end]).into_owned());
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_test_binary_passes_its_prefixes_do_not() {
        // the running test executable is a PIE (ET_DYN) of this machine on Linux
        let me = std::fs::read("/proc/self/exe").unwrap();
        if u16_at(&me, 16) != 3 {
            return; // a non-PIE build: nothing to check against
        }
        assert_eq!(check_shared_library(&me), Ok(()));
        for cut in [me.len() - 1, me.len() / 2, 4096, 100] {
            let e = check_shared_library(&me[..cut]).unwrap_err();
            assert!(e.contains("past the end of the file"), "{cut}: {e}");
        }
        assert!(check_shared_library(b"not ELF").unwrap_err().contains("not an ELF file"));
    }

    #[test]
    fn the_exported_symbols_are_those_the_loader_finds() {
        // libc's own table, checked against dlsym on the same names
        let Some(path) = ["/lib/x86_64-linux-gnu/libc.so.6", "/usr/lib/x86_64-linux-gnu/libc.so.6"]
            .into_iter()
            .find(|p| std::path::Path::new(p).is_file())
        else {
            return;
        };
        let bytes = std::fs::read(path).unwrap();
        let symbols = exported_symbols(&bytes).unwrap();
        assert!(symbols.len() > 1000, "{} symbols", symbols.len());
        for name in ["malloc", "printf", "dlopen", "qsort"] {
            assert!(symbols.contains(name), "{name}");
            let c = std::ffi::CString::new(name).unwrap();
            // SAFETY: dlsym on the already-loaded libc, a lookup only
            assert!(!unsafe { libc::dlsym(libc::RTLD_DEFAULT, c.as_ptr()) }.is_null(), "{name}");
        }
        assert!(!symbols.contains("fmi2DoStep"));
    }
}
