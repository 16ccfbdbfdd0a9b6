"""Checks a nigel_cosim wheel built for another platform without that platform: the tags of its
file name equal those its .dist-info/WHEEL declares and the expected ones, and its native
module nigel_cosim/_native.* is a library of the expected format and architecture(s):
ELF 64-bit e_machine (EM_X86_64 62, EM_AARCH64 183), PE32+ COFF Machine (0x8664 AMD64), Mach-O
(CPU_TYPE_X86_64, CPU_TYPE_ARM64; universal: both slices), each slice a bundle or dylib for
macOS 11 or earlier.
Usage: wheel-check.py WHEEL linux-aarch64|windows-x86_64|macos-universal2"""
import importlib.util
import os
import struct
import sys
import zipfile

# the Mach-O reader of scripts/macho-check.py (a file name with a hyphen: loaded by path)
_spec = importlib.util.spec_from_file_location("macho_check", os.path.join(os.path.dirname(os.path.abspath(__file__)), "macho-check.py"))
macho = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(macho)

EXPECTED = {
    "linux-aarch64": (["cp310-abi3-manylinux2014_aarch64", "cp310-abi3-manylinux_2_17_aarch64"], "nigel_cosim/_native.abi3.so"),
    "windows-x86_64": (["cp310-abi3-win_amd64"], "nigel_cosim/_native.pyd"),
    "macos-universal2": (["cp310-abi3-macosx_11_0_universal2"], "nigel_cosim/_native.abi3.so"),
}
EM_AARCH64 = 183
IMAGE_FILE_MACHINE_AMD64 = 0x8664
CPU = {macho.CPU["x86_64"]: "x86_64", macho.CPU["aarch64"]: "arm64"}
FAT_MAGIC = 0xCAFEBABE
MH_DYLIB, MH_BUNDLE = 6, 8


def tags_of_name(name):
    # name-version-pythontag-abitag-platformtag.whl, each tag a dot-separated set
    python, abi, platform = name[: -len(".whl")].split("-")[2:5]
    return sorted(f"{p}-{a}-{q}" for p in python.split(".") for a in abi.split(".") for q in platform.split("."))


def macho_slice(data, at):
    header = macho.read_header(data, at)
    if header is None or header[1] not in (MH_DYLIB, MH_BUNDLE):
        return None, f"slice at {at}: not a 64-bit Mach-O bundle or dylib"
    cputype, _filetype, platform, minos, _dylibs = header
    if platform != macho.PLATFORM_MACOS or minos is None or int(minos.split(".")[0]) > 11:
        return None, f"slice at {at}: platform {platform}, minimum macOS {minos} (macOS 11 expected)"
    return CPU.get(cputype, hex(cputype)), None


def architecture(data):
    if data[:4] == b"\x7fELF":
        if data[4] != 2:
            return None, "a 32-bit ELF file"
        return {62: "x86_64", EM_AARCH64: "aarch64"}.get(struct.unpack_from("<H", data, 18)[0], "other ELF"), None
    if data[:2] == b"MZ":
        pe = struct.unpack_from("<I", data, 0x3C)[0]
        if data[pe : pe + 4] != b"PE\0\0":
            return None, "MZ header without a PE signature"
        machine = struct.unpack_from("<H", data, pe + 4)[0]
        return ("x86_64" if machine == IMAGE_FILE_MACHINE_AMD64 else hex(machine)), None
    if struct.unpack_from(">I", data, 0)[0] == FAT_MAGIC:
        arches = []
        for k in range(struct.unpack_from(">I", data, 4)[0]):
            cputype, _sub, offset = struct.unpack_from(">3I", data, 8 + 20 * k)
            arch, problem = macho_slice(data, offset)
            if problem:
                return None, problem
            if arch != CPU.get(cputype):
                return None, f"fat header says {CPU.get(cputype)}, its slice is {arch}"
            arches.append(arch)
        return "+".join(sorted(arches)), None
    return macho_slice(data, 0)


def check(path, kind):
    tags, module = EXPECTED[kind]
    want_arch = {"linux-aarch64": "aarch64", "windows-x86_64": "x86_64", "macos-universal2": "arm64+x86_64"}[kind]
    name = path.rsplit("/", 1)[-1]
    if tags_of_name(name) != sorted(tags):
        return f"file name tags {tags_of_name(name)}, expected {sorted(tags)}"
    with zipfile.ZipFile(path) as z:
        wheel_files = [n for n in z.namelist() if n.endswith(".dist-info/WHEEL")]
        declared = sorted(line.split(": ", 1)[1] for line in z.read(wheel_files[0]).decode().splitlines() if line.startswith("Tag: "))
        if declared != sorted(tags):
            return f"WHEEL declares {declared}, expected {sorted(tags)}"
        natives = [n for n in z.namelist() if n.startswith("nigel_cosim/_native") and not n.endswith(".pyi")]  # (its typing stub aside)
        if natives != [module]:
            return f"native module {natives}, expected [{module!r}]"
        arch, problem = architecture(z.read(module))
    if problem:
        return f"{module}: {problem}"
    if arch != want_arch:
        return f"{module}: architecture {arch}, expected {want_arch}"
    print(f"{name}: tags {', '.join(tags)}; {module} {arch}")
    return None


if __name__ == "__main__":
    problem = check(sys.argv[1], sys.argv[2])
    if problem:
        sys.exit(f"wheel-check: {sys.argv[1]}: {problem}")
