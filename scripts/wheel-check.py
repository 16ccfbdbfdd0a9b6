"""Checks a nigel_cosim wheel, of this platform or another, without that platform:
- its file name's tags equal those its .dist-info/WHEEL declares and the expected ones;
- RECORD lists every file of the wheel with its size and SHA-256 (the hash pip checks);
- its one native module nigel_cosim/_native.* (scripts/native_library.py reads it) is a library
  of the expected format and architecture(s) that exports the module's entry point
  PyInit__native and links only what every machine of that platform has: on Linux the
  libraries manylinux2014 allows, no symbol version newer than GLIBC_2.17; on Windows a DLL
  importing python3.dll (the stable ABI's, any CPython >= 3.10; no python3X.dll) and system
  DLLs only; on macOS a bundle or dylib per slice (x86-64 and arm64) for macOS 11 or earlier,
  linking system libraries only and taking Python's symbols by dynamic lookup from the
  interpreter that loads it (ld's `-undefined dynamic_lookup`; no libpython linked).
Prints one line saying what it checked. Usage: wheel-check.py WHEEL PLATFORM
(PLATFORM: linux-x86_64, linux-aarch64, windows-x86_64, macos-universal2, as scripts/python-wheel.sh)"""
import base64
import csv
import hashlib
import io
import sys
import zipfile

import native_library

SO = "nigel_cosim/_native.abi3.so"
# platform: (tags, native module, format, architecture of each slice)
EXPECTED = {
    "linux-x86_64": (["cp310-abi3-manylinux2014_x86_64", "cp310-abi3-manylinux_2_17_x86_64"], SO, "ELF", ["x86_64"]),
    "linux-aarch64": (["cp310-abi3-manylinux2014_aarch64", "cp310-abi3-manylinux_2_17_aarch64"], SO, "ELF", ["aarch64"]),
    "windows-x86_64": (["cp310-abi3-win_amd64"], "nigel_cosim/_native.pyd", "PE", ["x86_64"]),
    "macos-universal2": (["cp310-abi3-macosx_11_0_arm64", "cp310-abi3-macosx_11_0_universal2", "cp310-abi3-macosx_11_0_x86_64"], SO, "Mach-O", ["x86_64", "arm64"]),
}
ENTRY_POINT = "PyInit__native"
# PEP 599's manylinux2014 libraries (those our module can need) and its glibc
MANYLINUX2014_LIBRARIES = {"libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1", "libgcc_s.so.1", "ld-linux-x86-64.so.2", "ld-linux-aarch64.so.1"}
GLIBC_MAX = (2, 17)
# DLLs every 64-bit Windows (8.1 and later, Rust's own minimum) has in System32, and the
# API sets (api-ms-win-*) that map onto them
WINDOWS_SYSTEM_DLLS = {"kernel32.dll", "ntdll.dll", "msvcrt.dll", "userenv.dll", "ws2_32.dll", "bcrypt.dll", "bcryptprimitives.dll", "advapi32.dll", "secur32.dll", "shell32.dll", "ole32.dll", "user32.dll"}
MACOS_SYSTEM_PREFIXES = ("/usr/lib/", "/System/")
MACOS_MINIMUM = 11


def tags_of_name(name):
    # name-version-pythontag-abitag-platformtag.whl, each tag a dot-separated set
    python, abi, platform = name[: -len(".whl")].split("-")[2:5]
    return sorted(f"{p}-{a}-{q}" for p in python.split(".") for a in abi.split(".") for q in platform.split("."))


def record_problem(z):
    """None when RECORD lists every file of the wheel (itself without hash) with its size and
    urlsafe-base64 SHA-256, else what differs."""
    [record] = [n for n in z.namelist() if n.endswith(".dist-info/RECORD")]
    listed = {}
    for row in csv.reader(io.StringIO(z.read(record).decode())):
        if row:
            listed[row[0]] = row[1:]
    if sorted(listed) != sorted(z.namelist()):
        return f"RECORD lists {sorted(set(listed) ^ set(z.namelist()))} otherwise than the archive holds them"
    for name, (digest, size) in listed.items():
        if name == record:
            continue
        data = z.read(name)
        want = "sha256=" + base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        if digest != want or size != str(len(data)):
            return f"RECORD says {name} is {digest}, {size} bytes; it is {want}, {len(data)} bytes"
    return None


def glibc_version(name):
    return tuple(int(part) for part in name[len("GLIBC_") :].split("."))


def linking_problem(library):
    """None when `library` (one slice) links only what every machine of the platform has."""
    if library.format == "ELF":
        foreign = sorted(set(library.needed) - MANYLINUX2014_LIBRARIES)
        newest = max((v for v in library.versions if v.startswith("GLIBC_")), key=glibc_version, default="GLIBC_0")
        if foreign:
            return f"links {foreign}, outside manylinux2014's libraries"
        if glibc_version(newest) > GLIBC_MAX:
            return f"needs {newest}, newer than manylinux2014's glibc 2.17"
        return None
    if library.format == "PE":
        dlls = [d.lower() for d in library.needed]
        foreign = sorted(d for d in dlls if d not in WINDOWS_SYSTEM_DLLS and d != "python3.dll" and not d.startswith("api-ms-win-"))
        if not library.dll:
            return "a PE image that is not a DLL"
        if "python3.dll" not in dlls:
            return f"does not import python3.dll (imports {library.needed})"
        if foreign:
            return f"imports {foreign}, neither python3.dll nor Windows' own DLLs"
        return None
    if library.filetype not in (native_library.MH_DYLIB, native_library.MH_BUNDLE):
        return f"{library.arch}: Mach-O file type {library.filetype}, not a bundle or dylib"
    if library.platform != native_library.macho.PLATFORM_MACOS or library.minos is None or int(library.minos.split(".")[0]) > MACOS_MINIMUM:
        return f"{library.arch}: platform {library.platform}, minimum macOS {library.minos} (macOS 11 expected)"
    foreign = [d for d in library.needed if not d.startswith(MACOS_SYSTEM_PREFIXES)]
    if foreign:
        return f"{library.arch}: links {foreign}, not a system library"
    python = {name: source for name, source in library.lookup.items() if name.startswith("_Py")}
    bound = sorted(name for name, source in python.items() if source != "dynamic lookup")
    if not python or bound:
        return f"{library.arch}: Python's symbols {bound or 'none'} not taken by dynamic lookup"
    return None


def check(path, kind):
    tags, module, file_format, arches = EXPECTED[kind]
    name = path.rsplit("/", 1)[-1]
    if tags_of_name(name) != sorted(tags):
        return f"file name tags {tags_of_name(name)}, expected {sorted(tags)}"
    with zipfile.ZipFile(path) as z:
        problem = record_problem(z)
        if problem:
            return problem
        wheel_files = [n for n in z.namelist() if n.endswith(".dist-info/WHEEL")]
        declared = sorted(line.split(": ", 1)[1] for line in z.read(wheel_files[0]).decode().splitlines() if line.startswith("Tag: "))
        if declared != sorted(tags):
            return f"WHEEL declares {declared}, expected {sorted(tags)}"
        natives = [n for n in z.namelist() if n.startswith("nigel_cosim/_native") and not n.endswith(".pyi")]  # (its typing stub aside)
        if natives != [module]:
            return f"native module {natives}, expected [{module!r}]"
        try:
            libraries = native_library.read(z.read(module))
        except ValueError as error:
            return f"{module}: {error}"
    found = sorted((library.format, library.arch) for library in libraries)
    if found != sorted((file_format, arch) for arch in arches):
        return f"{module}: {found}, expected {file_format} {arches}"
    for library in libraries:
        # (Mach-O names C symbols with a leading underscore)
        if ENTRY_POINT not in library.exports and "_" + ENTRY_POINT not in library.exports:
            return f"{module}: {library.arch}: does not export {ENTRY_POINT}"
        problem = linking_problem(library)
        if problem:
            return f"{module}: {problem}"
    print(f"{name}: tags {', '.join(tags)}; RECORD's hashes; {module}: {file_format} {'+'.join(arches)}, {linked(libraries)}")
    return None


def linked(libraries):
    library = libraries[0]
    if library.format == "ELF":
        return f"manylinux2014 libraries, symbol versions up to {max((v for v in library.versions if v.startswith('GLIBC_')), key=glibc_version)}"
    if library.format == "PE":
        # (one DLL may stand in several import descriptors: rustc's raw-dylib writes its own)
        return f"a DLL exporting {ENTRY_POINT}, importing {', '.join(sorted({d.lower() for d in library.needed}))}"
    return f"macOS {max(l.minos for l in libraries)} or later, {', '.join(library.needed)}, Python's symbols by dynamic lookup"


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[2] not in EXPECTED:
        sys.exit(f"usage: wheel-check.py WHEEL {'|'.join(EXPECTED)}")
    problem = check(sys.argv[1], sys.argv[2])
    if problem:
        sys.exit(f"wheel-check: {sys.argv[1]}: {problem}")
