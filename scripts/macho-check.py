"""Checks a macOS program's Mach-O header without a Mac: a thin 64-bit executable of the
expected architecture, built for macOS (LC_BUILD_VERSION platform 1) no later than 11.0,
linking system libraries only (/usr/lib, /System), and on arm64 signed (LC_CODE_SIGNATURE: Apple
silicon kills an unsigned arm64 program at its start; an ad-hoc signature is enough).
Prints the libraries' names. Usage: macho-check.py PROGRAM x86_64|aarch64.
Layout: <mach-o/loader.h> (mach_header_64: magic, cputype, cpusubtype, filetype, ncmds,
sizeofcmds, flags, reserved; then the load commands, each cmd and cmdsize first).
scripts/wheel-check.py reads the wheels' native modules with read_header."""
import struct
import sys

CPU = {"x86_64": 0x01000007, "aarch64": 0x0100000C}
MH_MAGIC_64, MH_EXECUTE = 0xFEEDFACF, 2
LC_LOAD_DYLIB, LC_CODE_SIGNATURE, LC_BUILD_VERSION = 0xC, 0x1D, 0x32
PLATFORM_MACOS = 1


def read_header(data, at=0):
    """The thin 64-bit Mach-O file at offset `at` of `data`: (cputype, filetype, platform,
    minos, dylibs), platform and minos from LC_BUILD_VERSION (None without one), minos as
    "major.minor"; None when `at` holds no 64-bit Mach-O header."""
    magic, cputype, _sub, filetype, ncmds, _size, _flags, _res = struct.unpack_from("<8I", data, at)
    if magic != MH_MAGIC_64:
        return None
    pos, platform, minos, dylibs = at + 32, None, None, []
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, pos)
        if cmd == LC_BUILD_VERSION:
            platform, version = struct.unpack_from("<2I", data, pos + 8)
            minos = f"{version >> 16}.{(version >> 8) & 0xFF}"
        elif cmd == LC_LOAD_DYLIB:
            offset = struct.unpack_from("<I", data, pos + 8)[0]
            dylibs.append(data[pos + offset : pos + size].split(b"\0")[0].decode())
        pos += size
    return cputype, filetype, platform, minos, dylibs


def load_commands(data, at=0):
    """The load command types (cmd) of the thin 64-bit Mach-O file at offset `at` of `data`."""
    ncmds = struct.unpack_from("<I", data, at + 16)[0]
    pos, cmds = at + 32, []
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, pos)
        cmds.append(cmd)
        pos += size
    return cmds


def check(path, arch):
    data = open(path, "rb").read()
    header = read_header(data)
    if header is None:
        return f"not a thin 64-bit Mach-O file (magic {struct.unpack_from('<I', data)[0]:#x})"
    cputype, filetype, platform, minos, dylibs = header
    if cputype != CPU[arch]:
        return f"CPU type {cputype:#x}, not {arch}'s {CPU[arch]:#x}"
    if filetype != MH_EXECUTE:
        return f"file type {filetype}, not an executable (2)"
    if minos is None:
        return "no LC_BUILD_VERSION"
    if platform != PLATFORM_MACOS:
        return f"built for platform {platform}, not macOS (1)"
    if int(minos.split(".")[0]) > 11:
        return f"needs macOS {minos}, not 11"
    foreign = [d for d in dylibs if not d.startswith(("/usr/lib/", "/System/"))]
    if foreign:
        return f"links non-system libraries: {foreign}"
    if arch == "aarch64" and LC_CODE_SIGNATURE not in load_commands(data):
        return "no code signature (LC_CODE_SIGNATURE): macOS on Apple silicon would not start it"
    names = ", ".join(d.rsplit("/", 1)[-1] for d in dylibs)
    print(f"Mach-O {arch} executable, macOS {minos} or later, system libraries only ({names}): {path}")
    return None


if __name__ == "__main__":
    problem = check(sys.argv[1], sys.argv[2])
    if problem:
        sys.exit(f"macho-check: {sys.argv[1]}: {problem}")
