"""scripts/wheel-check.py against wheels whose faults are known: the x86-64 Linux wheel the test
command built passes; a copy with one byte changed fails on RECORD, one renamed to another
platform's tags fails on its tags; a win_amd64 wheel around a DLL that mingw-w64's gcc and
dlltool link here (an independent writer of PE files: scripts/setup-cross.sh installs them)
passes when the DLL exports PyInit__native and imports python3.dll, and fails when it imports
a versioned python311.dll or lacks the entry point; a universal2 wheel around Mach-O modules
zig links here and llvm-lipo joins passes when both slices are for macOS 11 and take Python
by dynamic lookup, and fails with one slice, for macOS 12, or linking a libpython."""

import base64
import hashlib
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")
SCRIPT = REPO / "scripts" / "wheel-check.py"
LINUX_TAG = "manylinux2014_x86_64.manylinux_2_17_x86_64"


def linux_wheel():
    wheels = sorted((TARGET / "wheels").glob(f"nigel_cosim-*-cp310-abi3-{LINUX_TAG}.whl"))
    assert wheels, f"no x86-64 Linux wheel in {TARGET / 'wheels'}: the test command builds it first (scripts/python-venv-wheel.sh)"
    return wheels[-1]


def wheel_check(path, platform):
    return subprocess.run([sys.executable, str(SCRIPT), str(path), platform], capture_output=True, text=True)


def rewrite(source, dest, tag, replace=None, native=None):
    """`source`'s files into the wheel `dest` with the platform tag `tag` in WHEEL, the native
    module replaced by `native` = (name, bytes), the member `replace` = (name, bytes) replaced,
    and RECORD written anew (PEP 376/427: urlsafe base64 SHA-256 without padding, size)."""
    files = {}
    with zipfile.ZipFile(source) as z:
        for name in z.namelist():
            if name.startswith("nigel_cosim/_native") and not name.endswith(".pyi") and native:
                files[native[0]] = native[1]
            elif not name.endswith(".dist-info/RECORD"):
                files[name] = z.read(name)
        record = next(n for n in z.namelist() if n.endswith(".dist-info/RECORD"))
    wheel = next(n for n in files if n.endswith(".dist-info/WHEEL"))
    lines = [line for line in files[wheel].decode().splitlines() if not line.startswith("Tag: ")]
    files[wheel] = ("\n".join(lines + [f"Tag: cp310-abi3-{t}" for t in tag.split(".")]) + "\n").encode()
    rows = [f"{n},sha256={base64.urlsafe_b64encode(hashlib.sha256(d).digest()).rstrip(b'=').decode()},{len(d)}" for n, d in files.items()]
    files[record] = ("\n".join(rows + [f"{record},,"]) + "\n").encode()
    if replace:
        files[replace[0]] = replace[1]
    with zipfile.ZipFile(dest, "w") as z:
        for name, data in files.items():
            z.writestr(name, data)
    return dest


def test_the_linux_wheel_passes_and_a_changed_byte_or_another_tag_fails(tmp_path):
    wheel = linux_wheel()
    r = wheel_check(wheel, "linux-x86_64")
    assert r.returncode == 0, r.stderr
    assert r.stdout.endswith(": ELF x86_64, manylinux2014 libraries, symbol versions up to GLIBC_2.17\n"), r.stdout
    # (the wheel's own RECORD holds; a copy whose __init__.py lost its last byte does not)
    name = wheel.name
    with zipfile.ZipFile(wheel) as z:
        init = z.read("nigel_cosim/__init__.py")
    changed = rewrite(wheel, tmp_path / name, LINUX_TAG, replace=("nigel_cosim/__init__.py", init[:-1]))
    r = wheel_check(changed, "linux-x86_64")
    assert r.returncode == 1 and f"RECORD says nigel_cosim/__init__.py is" in r.stderr and f"{len(init) - 1} bytes" in r.stderr, r.stderr
    r = wheel_check(wheel, "linux-aarch64")
    assert r.returncode == 1 and "file name tags" in r.stderr, r.stderr
    aarch64_named = tmp_path / name.replace("x86_64", "aarch64")
    rewrite(wheel, aarch64_named, LINUX_TAG.replace("x86_64", "aarch64"))
    r = wheel_check(aarch64_named, "linux-aarch64")
    assert r.returncode == 1 and "[('ELF', 'x86_64')], expected ELF ['aarch64']" in r.stderr, r.stderr


def mingw_dll(folder, dlls, entry_point):
    """A DLL linked by mingw-w64 that exports `entry_point`, calling PyModule_Create2 of the
    first of `dlls` and a function of each other (through import libraries dlltool makes
    from .def files)."""
    calls, libraries = [], []
    for k, dll in enumerate(dlls):
        function = "PyModule_Create2" if k == 0 else f"function{k}"
        (folder / f"{k}.def").write_text(f"LIBRARY {dll}\nEXPORTS\n{function}\n")
        subprocess.run(["x86_64-w64-mingw32-dlltool", "-d", f"{k}.def", "-l", f"lib{k}.a"], cwd=folder, check=True)
        calls.append(function)
        libraries.append(f"lib{k}.a")
    declarations = "".join(f"void *{f}(void *, int);\n" for f in calls)
    body = " ".join(f"{f}(0, 1013);" for f in calls[1:])
    (folder / "module.c").write_text(f"{declarations}__declspec(dllexport) void *{entry_point}(void) {{ {body} return PyModule_Create2(0, 1013); }}\n")
    subprocess.run(["x86_64-w64-mingw32-gcc", "-shared", "-o", "module.pyd", "module.c", *libraries], cwd=folder, check=True)
    return (folder / "module.pyd").read_bytes()


@pytest.mark.parametrize(
    "dlls, entry_point, problem",
    [
        (["python3.dll"], "PyInit__native", None),
        (["python311.dll"], "PyInit__native", "does not import python3.dll (imports ['KERNEL32.dll', 'msvcrt.dll', 'python311.dll'])"),
        (["python3.dll", "libwinpthread-1.dll"], "PyInit__native", "imports ['libwinpthread-1.dll'], neither python3.dll nor Windows' own DLLs"),
        (["python3.dll"], "PyInit_other", "x86_64: does not export PyInit__native"),
    ],
)
def test_a_windows_wheel_around_a_dll_of_mingw(tmp_path, dlls, entry_point, problem):
    dll = mingw_dll(tmp_path, dlls, entry_point)
    wheel = linux_wheel()
    name = wheel.name.replace(LINUX_TAG, "win_amd64")
    r = wheel_check(rewrite(wheel, tmp_path / name, "win_amd64", native=("nigel_cosim/_native.pyd", dll)), "windows-x86_64")
    if problem is None:
        assert r.returncode == 0, r.stderr
        # (msvcrt.dll: mingw-w64's C runtime, a DLL of every Windows)
        assert r.stdout.endswith(": PE x86_64, a DLL exporting PyInit__native, importing kernel32.dll, msvcrt.dll, python3.dll\n"), r.stdout
    else:
        assert r.returncode == 1 and r.stderr.rstrip().endswith(problem), r.stderr


ZIG = [str(TARGET / "cross-venv" / "bin" / "python3"), "-m", "ziglang", "cc"]
LIPO = "/usr/lib/llvm-22/bin/llvm-lipo"


def zig_module(folder, arch, macos, link_libpython=False):
    """A Mach-O module zig links for `arch` and macOS `macos`, exporting PyInit__native and
    calling PyModule_Create2: taken by dynamic lookup, or from a libpython3.11.dylib
    (no C library: -nostdlib keeps zig from building one, a second's work)."""
    target = ["-target", f"{arch}-macos.{macos}", "-shared", "-nostdlib"]
    (folder / "module.c").write_text("void *PyModule_Create2(void *, int);\n__attribute__((visibility(\"default\"))) void *PyInit__native(void) { return PyModule_Create2(0, 1013); }\n")
    if link_libpython:
        (folder / "python.c").write_text("void *PyModule_Create2(void *m, int v) { return m; }\n")
        subprocess.run(ZIG + target + ["-o", "libpython3.11.dylib", "python.c"], cwd=folder, check=True)
        linking = ["-L.", "-lpython3.11"]
    else:
        linking = ["-undefined", "dynamic_lookup"]
    out = f"module-{arch}-{macos}.so"
    subprocess.run(ZIG + target + ["-o", out, "module.c"] + linking, cwd=folder, check=True)
    return folder / out


@pytest.mark.parametrize(
    "slices, link_libpython, problem",
    [
        ([("x86_64", "11.0"), ("aarch64", "11.0")], False, None),
        ([("x86_64", "11.0")], False, "[('Mach-O', 'x86_64')], expected Mach-O ['x86_64', 'arm64']"),
        ([("x86_64", "11.0"), ("aarch64", "12.0")], False, "arm64: platform 1, minimum macOS 12.0 (macOS 11 expected)"),
        ([("x86_64", "11.0"), ("aarch64", "11.0")], True, "x86_64: links ['libpython3.11.dylib'], not a system library"),
    ],
)
def test_a_macos_wheel_around_modules_of_zig(tmp_path, slices, link_libpython, problem):
    modules = [zig_module(tmp_path, arch, macos, link_libpython) for arch, macos in slices]
    subprocess.run([LIPO, "-create", *map(str, modules), "-output", str(tmp_path / "universal.so")], check=True)
    wheel = linux_wheel()
    tag = "macosx_11_0_arm64.macosx_11_0_universal2.macosx_11_0_x86_64"
    native = ("nigel_cosim/_native.abi3.so", (tmp_path / "universal.so").read_bytes())
    r = wheel_check(rewrite(wheel, tmp_path / wheel.name.replace(LINUX_TAG, tag), tag, native=native), "macos-universal2")
    if problem is None:
        assert r.returncode == 0, r.stderr
        assert r.stdout.endswith(": Mach-O x86_64+arm64, macOS 11.0 or later, /usr/lib/libSystem.B.dylib, Python's symbols by dynamic lookup\n"), r.stdout
    else:
        assert r.returncode == 1 and r.stderr.rstrip().endswith(problem), r.stderr
