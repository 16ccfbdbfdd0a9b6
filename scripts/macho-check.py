"""Checks a macOS program's Mach-O header without a Mac: a thin 64-bit executable of the
expected architecture, built for macOS (LC_BUILD_VERSION platform 1) no later than 11.0,
linking system libraries only (/usr/lib, /System). Usage: macho-check.py PROGRAM x86_64|aarch64.
Layout: <mach-o/loader.h> (mach_header_64: magic, cputype, cpusubtype, filetype, ncmds,
sizeofcmds, flags, reserved; then the load commands, each cmd and cmdsize first)."""
import struct
import sys

CPU = {"x86_64": 0x01000007, "aarch64": 0x0100000C}
MH_MAGIC_64, MH_EXECUTE = 0xFEEDFACF, 2
LC_LOAD_DYLIB, LC_BUILD_VERSION = 0xC, 0x32
PLATFORM_MACOS = 1


def check(path, arch):
    data = open(path, "rb").read()
    magic, cputype, _sub, filetype, ncmds, _size, _flags, _res = struct.unpack_from("<8I", data, 0)
    if magic != MH_MAGIC_64:
        return f"not a thin 64-bit Mach-O file (magic {magic:#x})"
    if cputype != CPU[arch]:
        return f"CPU type {cputype:#x}, not {arch}'s {CPU[arch]:#x}"
    if filetype != MH_EXECUTE:
        return f"file type {filetype}, not an executable (2)"
    at, minos, dylibs = 32, None, []
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, at)
        if cmd == LC_BUILD_VERSION:
            platform, minos = struct.unpack_from("<2I", data, at + 8)
            if platform != PLATFORM_MACOS:
                return f"built for platform {platform}, not macOS (1)"
        elif cmd == LC_LOAD_DYLIB:
            offset = struct.unpack_from("<I", data, at + 8)[0]
            dylibs.append(data[at + offset : at + size].split(b"\0")[0].decode())
        at += size
    if minos is None:
        return "no LC_BUILD_VERSION"
    version = f"{minos >> 16}.{(minos >> 8) & 0xFF}"
    if (minos >> 16) > 11:
        return f"needs macOS {version}, not 11"
    foreign = [d for d in dylibs if not d.startswith(("/usr/lib/", "/System/"))]
    if foreign:
        return f"links non-system libraries: {foreign}"
    print(f"Mach-O {arch} executable, macOS {version} or later, system libraries only: {path}")
    return None


if __name__ == "__main__":
    problem = check(sys.argv[1], sys.argv[2])
    if problem:
        sys.exit(f"macho-check: {sys.argv[1]}: {problem}")
